//! A group's rows on a local copy of the links it touches (its one or two bodies first, then
//! at most three links solved before it), from the pair kinds' own modules (`pairs`): the
//! rows' Jacobian and gamma, so the group's rates and accelerations are one solve with its
//! block of J, and its type II measure is the smallest singular value of that block's fine
//! diagonal blocks, as `group_sigma` takes them from the block-triangular form of J.
//!
//! Where each body's angle is fixed by one row alone and the other rows are then affine in the
//! bodies' positions (the class I groups, `one_link`, and the PRP dyad, `prp`), one Newton step
//! from any start is exact ([`Local::affine`]): the angles from their rows, then the positions
//! from the rest. Other groups place their bodies by their own closed form ([`Local::store`]).

use crate::linalg::{BlockLu, Dense};
use crate::model::pairs;
use crate::model::pairs::gear::Mesh;
use crate::model::{BodyId, Link, Mechanism, Pair, PairId, PairKind};
use crate::{KinematicsError, SingularityKind};
use nalgebra::{Matrix3, Matrix4, Matrix5, Matrix6};

/// Links of the local copy: the group's bodies and the links solved before it.
const LINKS: usize = 5;
const COLS: usize = 3 * LINKS;
/// The most rows (and unknowns) of a group: two bodies.
const ROWS: usize = 6;

#[derive(Debug, Clone)]
pub struct Local {
    bodies: [usize; 2],
    n_bodies: usize,
    /// The pairs on the local links, and each one's first row.
    pairs: Vec<Pair>,
    first_row: Vec<usize>,
    /// The global body of each known local link (numbered after the group's bodies).
    known: [usize; LINKS],
    n_known: usize,
    /// Per body, the row that fixes its angle alone and its constant coefficient there (for
    /// `affine`), and the rows that then fix the positions.
    angle_rows: [(usize, f64); 2],
    position_rows: [usize; 4],
    /// The fine diagonal blocks of the group's block (group columns), their rows and columns;
    /// and which rows are in metres (scaled by 1/L_k in `sigma`).
    blocks: Vec<(Vec<usize>, Vec<usize>)>,
    metres: [bool; ROWS],
    /// At the last positions: the local coordinates and [cos, sin], the rows' Jacobian (rows x
    /// COLS, the group's columns first) and the inverse of its group block.
    pub x: [f64; COLS],
    pub trig: [[f64; 2]; LINKS],
    j: [f64; ROWS * COLS],
    inv: [[f64; ROWS]; ROWS],
}

/// Per row of a pair, whether it fixes a group body's angle alone (true) or is affine in the
/// bodies' positions once the angles are known (false); None if a row is neither.
fn roles(pair: &Pair, in_group: impl Fn(Link) -> bool) -> Option<[bool; 2]> {
    match &pair.kind {
        PairKind::Revolute | PairKind::Slot(_) => Some([false; 2]),
        PairKind::Prismatic { .. } => Some([in_group(pair.a) != in_group(pair.b), false]),
        PairKind::Gear(g) if in_group(g.carrier) => None,
        PairKind::Gear(g) => match g.mesh {
            Mesh::Gear { .. } => Some([true, false]),
            Mesh::Rack { .. } => Some([in_group(pair.a), false]),
        },
    }
}

impl Local {
    /// The rows of the group of `bodies` (one or two) and `pairs`, their 3 x bodies rows in
    /// all; None if they touch more links than the copy holds or a pair's rows are not all in J.
    pub fn new(mech: &Mechanism, bodies: &[usize], pair_ids: &[PairId]) -> Option<Self> {
        let n_bodies = bodies.len();
        if !(1..=2).contains(&n_bodies) {
            return None;
        }
        let mut known = [usize::MAX; LINKS];
        let mut n_known = 0;
        let mut local = |link: Link| -> Option<Link> {
            let Link::Body(b) = link else { return Some(Link::Ground) };
            if let Some(i) = bodies.iter().position(|&g| g == b.0) {
                return Some(Link::Body(BodyId(i)));
            }
            let i = match known[..n_known].iter().position(|&k| k == b.0) {
                Some(i) => i,
                None if n_bodies + n_known < LINKS => {
                    known[n_known] = b.0;
                    n_known += 1;
                    n_known - 1
                }
                None => return None,
            };
            Some(Link::Body(BodyId(n_bodies + i)))
        };
        let (mut pairs, mut first_row, mut n_rows) = (Vec::new(), Vec::new(), 0);
        for k in pair_ids {
            let pair = &mech.pairs[k.0];
            if mech.pair_slots[k.0].iter().take(pairs::n_rows(&pair.kind)).any(Option::is_none) {
                return None;
            }
            let mut p = pair.clone();
            (p.a, p.b) = (local(pair.a)?, local(pair.b)?);
            if let PairKind::Gear(g) = &mut p.kind {
                g.carrier = local(g.carrier)?;
            }
            first_row.push(n_rows);
            n_rows += pairs::n_rows(&pair.kind);
            pairs.push(p);
        }
        if n_rows != 3 * n_bodies {
            return None;
        }
        let group_of = |b: usize| bodies.iter().position(|&g| g == b);
        // The fine blocks of the group's columns, from the pairs' patterns as J's are.
        let mut pattern = Vec::new();
        let mut metres = [false; ROWS];
        for (k, p) in pair_ids.iter().zip(&pairs) {
            let pair = &mech.pairs[k.0];
            for r in 0..pairs::n_rows(&pair.kind) {
                let cols = pairs::pattern(pair, r).into_iter();
                pattern.push(cols.filter_map(|c| group_of(c / 3).map(|g| 3 * g + c % 3)).collect::<Vec<_>>());
                metres[pattern.len() - 1] = pairs::row_scales(p, 0.0)[r] == 0.0;
            }
        }
        let blocks = BlockLu::new(&pattern).blocks().collect();
        let mut group = Local {
            bodies: [bodies[0], bodies[n_bodies - 1]],
            n_bodies,
            pairs,
            first_row,
            known,
            n_known,
            angle_rows: [(usize::MAX, 0.0); 2],
            position_rows: [usize::MAX; 4],
            blocks,
            metres,
            x: [0.0; COLS],
            trig: [[1.0, 0.0]; LINKS],
            j: [0.0; ROWS * COLS],
            inv: [[0.0; ROWS]; ROWS],
        };
        // The rows that fix an angle alone are linear in it with a constant coefficient.
        let in_group = |l: Link| matches!(l, Link::Body(b) if b.0 < n_bodies);
        let mut angle = [false; ROWS];
        for (p, &r0) in group.pairs.iter().zip(&group.first_row) {
            let role = roles(p, in_group);
            for r in 0..pairs::n_rows(&p.kind) {
                angle[r0 + r] = role.is_some_and(|role| role[r]);
            }
        }
        group.jacobian();
        let mut n_angles = 0;
        for r in (0..n_rows).filter(|&r| angle[r]) {
            let coefficients: Vec<usize> = (0..n_bodies).filter(|&b| group.j[r * COLS + 3 * b + 2] != 0.0).collect();
            let &[b] = coefficients.as_slice() else { continue };
            if group.angle_rows[b].0 == usize::MAX {
                group.angle_rows[b] = (r, group.j[r * COLS + 3 * b + 2]);
                n_angles += 1;
            }
        }
        if n_angles == n_bodies {
            let rest: Vec<usize> =
                (0..n_rows).filter(|&r| !group.angle_rows[..n_bodies].iter().any(|a| a.0 == r)).collect();
            group.position_rows[..rest.len()].copy_from_slice(&rest);
        }
        Some(group)
    }

    /// Whether [`Local::affine`] places the group: each body's angle fixed by one row alone.
    pub fn is_affine(&self) -> bool {
        self.position_rows[0] != usize::MAX
    }

    /// The group's bodies.
    pub fn bodies(&self) -> &[usize] {
        &self.bodies[..self.n_bodies]
    }

    fn rows(&self) -> usize {
        3 * self.n_bodies
    }

    fn residual(&self) -> [f64; ROWS] {
        let mut res = [0.0; ROWS];
        for (p, &r0) in self.pairs.iter().zip(&self.first_row) {
            let r = pairs::residual(p, &self.x, &self.trig);
            res[r0] = r[0];
            if pairs::n_rows(&p.kind) == 2 {
                res[r0 + 1] = r[1];
            }
        }
        res
    }

    /// The rows' Jacobian at the local coordinates, into `j`.
    fn jacobian(&mut self) {
        self.j.fill(0.0);
        let mut sink = Dense { j: &mut self.j, ncols: COLS };
        for (p, &r0) in self.pairs.iter().zip(&self.first_row) {
            let two = pairs::n_rows(&p.kind) == 2;
            pairs::jacobian(p, &self.x, &self.trig, &mut sink, [Some(r0), two.then_some(r0 + 1)]);
        }
    }

    /// Copy the known links' poses from x and trig into the local copy.
    #[inline]
    pub fn load(&mut self, x: &[f64], trig: &[[f64; 2]]) {
        for (i, &b) in self.known[..self.n_known].iter().enumerate() {
            let l = self.n_bodies + i;
            self.x[3 * l..3 * l + 3].copy_from_slice(&x[3 * b..3 * b + 3]);
            self.trig[l] = trig[b];
        }
    }

    /// The group's bodies' poses (x and trig) for an affine group, the links before it solved.
    /// Inlined into `ClosedForm::place` (see there): a call of its own cost the gear train 49
    /// instructions an evaluation (icount 9279 -> 9328) and the scotch yoke 14.
    #[inline(always)]
    pub fn affine(&mut self, x: &mut [f64], trig: &mut [[f64; 2]]) -> Result<(), KinematicsError> {
        self.load(x, trig);
        let nb = self.n_bodies;
        // The angles: each angle row is affine in its body's, and blind to the positions.
        self.x[..3 * nb].fill(0.0);
        self.trig[..nb].fill([1.0, 0.0]);
        let res = self.residual();
        for b in 0..nb {
            let (r, coefficient) = self.angle_rows[b];
            let phi = -res[r] / coefficient;
            let (s, c) = phi.sin_cos();
            (self.x[3 * b + 2], self.trig[b]) = (phi, [c, s]);
        }
        // The positions: the other rows are affine in them.
        let res = self.residual();
        self.jacobian();
        let n = 2 * nb;
        let mut m = [[0.0; ROWS]; ROWS];
        let mut rhs = [[0.0; ROWS]; 1];
        for (i, &r) in self.position_rows[..n].iter().enumerate() {
            for b in 0..nb {
                m[i][2 * b] = self.j[r * COLS + 3 * b];
                m[i][2 * b + 1] = self.j[r * COLS + 3 * b + 1];
            }
            rhs[0][i] = -res[r];
        }
        // One body: Cramer's rule on the 2 x 2 (cheaper than the reduction).
        if n == 2 {
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            let r = rhs[0];
            rhs[0][..2]
                .copy_from_slice(&[(m[1][1] * r[0] - m[0][1] * r[1]) / det, (m[0][0] * r[1] - m[1][0] * r[0]) / det]);
        } else {
            solve(m, n, &mut rhs);
        }
        let p = rhs[0];
        if p[..n].iter().any(|v| !v.is_finite()) {
            // The lines (or a line and a pivot's rows) do not cross: J's block is singular.
            return Err(KinematicsError::singular(SingularityKind::TypeII));
        }
        for b in 0..nb {
            self.x[3 * b..3 * b + 2].copy_from_slice(&p[2 * b..2 * b + 2]);
        }
        self.store(x, trig);
        Ok(())
    }

    /// Take the group's bodies' poses from the local copy into x and trig, and the rows'
    /// Jacobian and its group block's inverse there.
    #[inline]
    pub fn store(&mut self, x: &mut [f64], trig: &mut [[f64; 2]]) {
        for (b, &g) in self.bodies().iter().enumerate() {
            x[3 * g..3 * g + 3].copy_from_slice(&self.x[3 * b..3 * b + 3]);
            trig[g] = self.trig[b];
        }
        self.jacobian();
        let n = self.rows();
        if n == 3 {
            // One body: the 3 x 3 inverse by cofactors (cheaper than the reduction).
            let inv = invert3([0, 1, 2].map(|r| [0, 1, 2].map(|c| self.j[r * COLS + c])));
            for (row, inv) in self.inv.iter_mut().zip(inv) {
                row[..3].copy_from_slice(&inv);
            }
            return;
        }
        let mut m = [[0.0; ROWS]; ROWS];
        let mut columns = [[0.0; ROWS]; ROWS];
        for r in 0..n {
            m[r][..n].copy_from_slice(&self.j[r * COLS..r * COLS + n]);
            columns[r][r] = 1.0;
        }
        // Columns of the inverse, transposed back into rows.
        solve(m, n, &mut columns[..n]);
        for (r, inv) in self.inv.iter_mut().enumerate().take(n) {
            for (c, v) in inv.iter_mut().enumerate().take(n) {
                *v = columns[c][r];
            }
        }
    }

    /// The group's rates (or accelerations) y solving block y = -(J_known t_known + extra),
    /// with the known links' rates (or accelerations) in t, into t. Fixed width: the rows of
    /// `j`, `inv` and `extra` past the group's are zero.
    #[inline]
    fn solve_rates(&self, t: &mut [f64], extra: [f64; ROWS]) {
        let n = self.rows();
        let mut rhs = extra;
        for (i, &b) in self.known[..self.n_known].iter().enumerate() {
            let l = self.n_bodies + i;
            for (r, rhs) in rhs.iter_mut().enumerate() {
                let row = &self.j[r * COLS + 3 * l..r * COLS + 3 * l + 3];
                *rhs += row[0] * t[3 * b] + row[1] * t[3 * b + 1] + row[2] * t[3 * b + 2];
            }
        }
        for (i, inv) in self.inv.iter().enumerate().take(n) {
            let y = -inv.iter().zip(&rhs).map(|(a, b)| a * b).sum::<f64>();
            t[3 * self.bodies[i / 3] + i % 3] = y;
        }
    }

    /// The group's rates, those of the links before it in v.
    #[inline]
    pub fn velocity(&self, v: &mut [f64]) {
        self.solve_rates(v, [0.0; ROWS]);
    }

    /// The group's accelerations, from the rates v and the accelerations of the links before it
    /// in a: the rows' gamma at v, on the local links.
    #[inline]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        let mut w = [0.0; COLS];
        for (b, &g) in self.bodies().iter().enumerate() {
            w[3 * b..3 * b + 3].copy_from_slice(&v[3 * g..3 * g + 3]);
        }
        for (i, &b) in self.known[..self.n_known].iter().enumerate() {
            let l = self.n_bodies + i;
            w[3 * l..3 * l + 3].copy_from_slice(&v[3 * b..3 * b + 3]);
        }
        let mut extra = [0.0; ROWS];
        for (p, &r0) in self.pairs.iter().zip(&self.first_row) {
            let g = pairs::gamma(p, &self.x, &self.trig, &w, &w);
            extra[r0] = g[0];
            if pairs::n_rows(&p.kind) == 2 {
                extra[r0 + 1] = g[1];
            }
        }
        self.solve_rates(a, extra);
    }

    /// The type II measure at the last positions, 1 / L_k its group's inverse length: the
    /// smallest singular value of the fine blocks of its block, rows in metres by 1/L_k and
    /// translation columns by L_k.
    pub fn sigma(&self, inv_length: f64) -> f64 {
        let entry = |r: usize, c: usize| {
            let row = if self.metres[r] { inv_length } else { 1.0 };
            let col = if c % 3 < 2 { 1.0 / inv_length } else { 1.0 };
            self.j[r * COLS + c] * row * col
        };
        let mut best = f64::INFINITY;
        for (rows, cols) in &self.blocks {
            let sigma = match (rows.as_slice(), cols.as_slice()) {
                ([r], [c]) => entry(*r, *c).abs(),
                ([r0, r1], [c0, c1]) => {
                    sigma_2x2([[entry(*r0, *c0), entry(*r0, *c1)], [entry(*r1, *c0), entry(*r1, *c1)]])
                }
                _ => {
                    let m = |i: usize, j: usize| entry(rows[i], cols[j]);
                    // Fixed sizes: no allocation.
                    match rows.len() {
                        3 => Matrix3::from_fn(m).singular_values().min(),
                        4 => Matrix4::from_fn(m).singular_values().min(),
                        5 => Matrix5::from_fn(m).singular_values().min(),
                        _ => Matrix6::from_fn(m).singular_values().min(),
                    }
                }
            };
            best = best.min(sigma);
        }
        best
    }
}

/// The smaller singular value of a 2 x 2 matrix: |det| over the larger, which is half the sum
/// of the norms of its conformal and anticonformal parts.
fn sigma_2x2(m: [[f64; 2]; 2]) -> f64 {
    let [[a, b], [c, d]] = m;
    let largest = 0.5 * ((a + d).hypot(c - b) + (a - d).hypot(c + b));
    if largest > 0.0 {
        (a * d - b * c).abs() / largest
    } else {
        0.0
    }
}

/// The inverse of a 3 x 3 matrix by its cofactors (infinite where it is singular).
fn invert3(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| c(j, i) / det))
}

/// The solutions of m y = b, in place, for the right-hand sides b (each of the first n
/// entries), the n x n system reduced with partial pivoting; infinite or NaN where m is
/// singular.
fn solve(mut m: [[f64; ROWS]; ROWS], n: usize, b: &mut [[f64; ROWS]]) {
    for k in 0..n {
        let p = (k..n).max_by(|&i, &j| m[i][k].abs().total_cmp(&m[j][k].abs())).unwrap_or(k);
        m.swap(k, p);
        b.iter_mut().for_each(|b| b.swap(k, p));
        for i in k + 1..n {
            let (pivot, f) = (m[k], m[i][k] / m[k][k]);
            m[i][k..n].iter_mut().zip(&pivot[k..n]).for_each(|(v, p)| *v -= f * p);
            b.iter_mut().for_each(|b| b[i] -= f * b[k]);
        }
    }
    for b in b.iter_mut() {
        for k in (0..n).rev() {
            let s: f64 = (k + 1..n).map(|c| m[k][c] * b[c]).sum();
            b[k] = (b[k] - s) / m[k][k];
        }
    }
}
