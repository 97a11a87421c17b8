//! The class I groups: one body held by two outer pairs of three rows in all, one of which
//! fixes its angle alone and two of which are then affine in its position. They are
//! - 1R1G, a wheel on a revolute pivot meshing with a solved gear (or a pinion with a solved
//!   rack): the gear row fixes the angle, the pivot's rows the position;
//! - 1P1G, a rack on a guide meshing with a solved pinion: the guide's angle row, then its
//!   normal row and the rack's travel;
//! - 1P1S, a yoke on a guide with a solved pin in its slot (or a pin on a guide in a solved
//!   slot): the guide's angle row, then its normal row and the slot's.
//!
//! Each row being affine in the unknown it solves, one Newton step from any start is exact:
//! the angle from the angle row, then the position from the other two (a 2 x 2 solve). The
//! rows, their Jacobian and gamma come from the pair kinds' own modules (`pairs`), evaluated on
//! a local copy of the few links the group touches (the body first), so the rates and
//! accelerations are one 3 x 3 solve with the group's block of J, and its type II measure is
//! the smallest singular value of that block's fine diagonal blocks, as `group_sigma` takes
//! them from the block-triangular form of J.

use crate::kinematics::pairs::gear::Mesh;
use crate::kinematics::pairs::{self, Rows};
use crate::linalg::{BlockLu, Dense};
use crate::model::{BodyId, Link, Mechanism, Pair, PairId, PairKind};
use crate::{KinematicsError, SingularityKind};
use nalgebra::Matrix3;

/// Links of the local copy: the body and at most three solved links (the pairs' other links
/// and a gear's carrier).
const LINKS: usize = 4;
const COLS: usize = 3 * LINKS;

#[derive(Debug, Clone)]
pub struct OneLink {
    pub body: usize,
    /// The two pairs on the local links (the body is local body 0), and the global body of
    /// each other local link.
    pairs: [Pair; 2],
    known: [usize; LINKS - 1],
    n_known: usize,
    /// The local row (pair 0's rows first) that fixes the angle, its constant coefficient in
    /// the angle, and the two rows that then fix the position.
    angle_row: usize,
    angle_coefficient: f64,
    position_rows: [usize; 2],
    /// The fine diagonal blocks of the group's block (columns x, y, phi of the body), their
    /// rows and columns; and which rows are in metres (scaled by 1/L_k in `sigma`).
    blocks: Vec<(Vec<usize>, Vec<usize>)>,
    metres: [bool; 3],
    /// At the last positions: the local coordinates and [cos, sin], the rows' Jacobian (3 x
    /// COLS, the body's columns first) and the inverse of its body block.
    x: [f64; COLS],
    trig: [[f64; 2]; LINKS],
    j: [f64; 3 * COLS],
    inv: [[f64; 3]; 3],
}

/// Per row of a pair, whether it fixes the body's angle alone (true) or is affine in the body's
/// position once the angle is known (false); None if a row is neither.
fn roles(pair: &Pair, body: Link) -> Option<[bool; 2]> {
    match &pair.kind {
        PairKind::Revolute | PairKind::Slot(_) => Some([false; 2]),
        PairKind::Prismatic { .. } => Some([true, false]),
        PairKind::Gear(g) if g.carrier == body => None,
        PairKind::Gear(g) => match g.mesh {
            Mesh::Gear { .. } => Some([true, false]),
            Mesh::Rack { .. } => Some([pair.a == body, false]),
        },
    }
}

impl OneLink {
    /// The group of `body` held by the outer pairs `outer`, if its rows are of the kinds above.
    pub fn new(mech: &Mechanism, body: usize, outer: [PairId; 2]) -> Option<Self> {
        let own = Link::Body(BodyId(body));
        let mut known = [usize::MAX; LINKS - 1];
        let mut n_known = 0;
        // The local link of a link, the known ones numbered as they come.
        let mut local = |link: Link| -> Option<Link> {
            let Link::Body(b) = link else { return Some(Link::Ground) };
            if b.0 == body {
                return Some(Link::Body(BodyId(0)));
            }
            let i = match known[..n_known].iter().position(|&k| k == b.0) {
                Some(i) => i,
                None if n_known < known.len() => {
                    known[n_known] = b.0;
                    n_known += 1;
                    n_known - 1
                }
                None => return None,
            };
            Some(Link::Body(BodyId(i + 1)))
        };
        let mut rows = Vec::new();
        let mut pairs_local = Vec::new();
        for k in outer {
            let pair = &mech.pairs[k.0];
            if mech.pair_slots[k.0].iter().take(pairs::n_rows(&pair.kind)).any(Option::is_none) {
                return None;
            }
            let role = roles(pair, own)?;
            rows.extend(role.into_iter().take(pairs::n_rows(&pair.kind)));
            let mut p = pair.clone();
            (p.a, p.b) = (local(pair.a)?, local(pair.b)?);
            if let PairKind::Gear(g) = &mut p.kind {
                g.carrier = local(g.carrier)?;
            }
            pairs_local.push(p);
        }
        let angles: Vec<usize> = (0..rows.len()).filter(|&r| rows[r]).collect();
        let (&[angle_row], 3) = (angles.as_slice(), rows.len()) else { return None };
        let position_rows = [(angle_row + 1) % 3, (angle_row + 2) % 3];
        // The fine blocks of the body's columns, from the pairs' patterns as J's are.
        let local_rows = |k: usize, r: usize| -> Vec<usize> {
            pairs::pattern(&mech.pairs[outer[k].0], r).into_iter().filter(|c| c / 3 == body).map(|c| c % 3).collect()
        };
        let n0 = pairs::n_rows(&mech.pairs[outer[0].0].kind);
        let pattern: Vec<Vec<usize>> =
            (0..3).map(|r| if r < n0 { local_rows(0, r) } else { local_rows(1, r - n0) }).collect();
        let blocks = BlockLu::new(&pattern).blocks().collect();
        let metres = [0, 1, 2].map(|r| {
            let (p, i) = if r < n0 { (&pairs_local[0], r) } else { (&pairs_local[1], r - n0) };
            pairs::row_scales(p, 0.0)[i] == 0.0
        });
        let pairs: [Pair; 2] = pairs_local.try_into().ok()?;
        let mut group = OneLink {
            body,
            pairs,
            known,
            n_known,
            angle_row,
            angle_coefficient: 0.0,
            position_rows,
            blocks,
            metres,
            x: [0.0; COLS],
            trig: [[1.0, 0.0]; LINKS],
            j: [0.0; 3 * COLS],
            inv: [[0.0; 3]; 3],
        };
        // The angle row is linear in the angle with a constant coefficient.
        group.jacobian();
        group.angle_coefficient = group.j[angle_row * COLS + 2];
        (group.angle_coefficient != 0.0).then_some(group)
    }

    /// The group's body.
    pub fn bodies(&self) -> &[usize] {
        std::slice::from_ref(&self.body)
    }

    fn residual(&self) -> [f64; 3] {
        let n0 = pairs::n_rows(&self.pairs[0].kind);
        let (r0, r1): (Rows, Rows) = (
            pairs::residual(&self.pairs[0], &self.x, &self.trig),
            pairs::residual(&self.pairs[1], &self.x, &self.trig),
        );
        [0, 1, 2].map(|r| if r < n0 { r0[r] } else { r1[r - n0] })
    }

    /// The rows' Jacobian at the local coordinates, into `j`.
    fn jacobian(&mut self) {
        self.j.fill(0.0);
        let n0 = pairs::n_rows(&self.pairs[0].kind);
        let mut sink = Dense { j: &mut self.j, ncols: COLS };
        // Pair 0's rows are 0..n0, pair 1's n0..3.
        pairs::jacobian(&self.pairs[0], &self.x, &self.trig, &mut sink, [Some(0), (n0 == 2).then_some(1)]);
        pairs::jacobian(&self.pairs[1], &self.x, &self.trig, &mut sink, [Some(n0), (n0 == 1).then_some(2)]);
    }

    /// The body's pose (x and trig), the links before it solved.
    #[inline]
    pub fn position(&mut self, x: &mut [f64], trig: &mut [[f64; 2]]) -> Result<(), KinematicsError> {
        for (i, &b) in self.known[..self.n_known].iter().enumerate() {
            self.x[3 * i + 3..3 * i + 6].copy_from_slice(&x[3 * b..3 * b + 3]);
            self.trig[i + 1] = trig[b];
        }
        // The angle: the angle row is affine in it, and blind to the position.
        self.x[..3].fill(0.0);
        self.trig[0] = [1.0, 0.0];
        let phi = -self.residual()[self.angle_row] / self.angle_coefficient;
        let (s, c) = phi.sin_cos();
        (self.x[2], self.trig[0]) = (phi, [c, s]);
        // The position: the other two rows are affine in it.
        let res = self.residual();
        self.jacobian();
        let [p, q] = self.position_rows.map(|r| [self.j[r * COLS], self.j[r * COLS + 1]]);
        let det = p[0] * q[1] - p[1] * q[0];
        let (rp, rq) = (res[self.position_rows[0]], res[self.position_rows[1]]);
        let r = [(p[1] * rq - q[1] * rp) / det, (q[0] * rp - p[0] * rq) / det];
        if !(r[0].is_finite() && r[1].is_finite()) {
            // The two lines (or a line and the pivot's rows) do not cross: J's block is singular.
            return Err(KinematicsError::singular(SingularityKind::TypeII));
        }
        self.x[..2].copy_from_slice(&r);
        self.jacobian();
        self.inv = invert(self.block());
        x[3 * self.body..3 * self.body + 3].copy_from_slice(&self.x[..3]);
        trig[self.body] = self.trig[0];
        Ok(())
    }

    /// The group's block of J (its rows, the body's columns).
    fn block(&self) -> [[f64; 3]; 3] {
        [0, 1, 2].map(|r| [0, 1, 2].map(|c| self.j[r * COLS + c]))
    }

    /// The body's rates (or accelerations) y solving block y = -(J_known t_known + extra),
    /// with the known links' rates (or accelerations) in t, into t.
    #[inline]
    fn solve(&self, t: &mut [f64], extra: [f64; 3]) {
        let mut rhs = extra;
        for (i, &b) in self.known[..self.n_known].iter().enumerate() {
            for (r, rhs) in rhs.iter_mut().enumerate() {
                let row = &self.j[r * COLS + 3 * i + 3..r * COLS + 3 * i + 6];
                *rhs += row[0] * t[3 * b] + row[1] * t[3 * b + 1] + row[2] * t[3 * b + 2];
            }
        }
        let k = 3 * self.body;
        for (i, inv) in self.inv.iter().enumerate() {
            t[k + i] = -(inv[0] * rhs[0] + inv[1] * rhs[1] + inv[2] * rhs[2]);
        }
    }

    /// The body's rates, those of the links before it in v.
    #[inline]
    pub fn velocity(&self, v: &mut [f64]) {
        self.solve(v, [0.0; 3]);
    }

    /// The body's accelerations, from the rates v and the accelerations of the links before it
    /// in a: the rows' gamma at v, on the local links.
    #[inline]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        let mut w = [0.0; COLS];
        w[..3].copy_from_slice(&v[3 * self.body..3 * self.body + 3]);
        for (i, &b) in self.known[..self.n_known].iter().enumerate() {
            w[3 * i + 3..3 * i + 6].copy_from_slice(&v[3 * b..3 * b + 3]);
        }
        let n0 = pairs::n_rows(&self.pairs[0].kind);
        let g0 = pairs::gamma(&self.pairs[0], &self.x, &self.trig, &w, &w);
        let g1 = pairs::gamma(&self.pairs[1], &self.x, &self.trig, &w, &w);
        self.solve(a, [0, 1, 2].map(|r| if r < n0 { g0[r] } else { g1[r - n0] }));
    }

    /// The type II measure at the last positions, 1 / L_k its group's inverse length: the
    /// smallest singular value of the fine blocks of its block, rows in metres by 1/L_k and
    /// translation columns by L_k.
    pub fn sigma(&self, inv_length: f64) -> f64 {
        let b = self.block();
        let entry = |r: usize, c: usize| {
            let row = if self.metres[r] { inv_length } else { 1.0 };
            let col = if c < 2 { 1.0 / inv_length } else { 1.0 };
            b[r][c] * row * col
        };
        let mut best = f64::INFINITY;
        for (rows, cols) in &self.blocks {
            let sigma = match (rows.as_slice(), cols.as_slice()) {
                ([r], [c]) => entry(*r, *c).abs(),
                ([r0, r1], [c0, c1]) => {
                    sigma_2x2([[entry(*r0, *c0), entry(*r0, *c1)], [entry(*r1, *c0), entry(*r1, *c1)]])
                }
                _ => Matrix3::from_fn(|i, j| entry(rows[i], cols[j])).singular_values().min(),
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
fn invert(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| c(j, i) / det))
}
