//! The position equations F(x) = [Phi(x); D(x) - z] = 0 and their derivatives.
//!
//! Rows 0..2p are the pair constraints Phi (two per pair); rows 2p..2p+m fix the chart's
//! coordinates z: the user's generalized coordinates D(x) (relative angles and displacements
//! of the input pairs), or m chosen components of x (generalized coordinate partitioning).
//! Per row we need the value, the gradient (a row of J) and the second derivative as a
//! bilinear form gamma(a, b) = sum_ij d2F/dx_i dx_j a_i b_j, which gives the convective term
//! (gamma(xd, xd)) and the acceleration analogues (gamma(u_j, u_k)).

pub use crate::linalg::{Dense, Sink};
use crate::model::{Link, Mechanism, Pair, PairKind};

/// Which m functions of x are the independent coordinates.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Chart {
    /// The user's generalized coordinates q.
    Inputs,
    /// Components of x (indices into the 3n body coordinates), chosen near a singularity
    /// of the actuated mechanism.
    Partition(Vec<usize>),
}

/// [cos(phi), sin(phi)] of every body, computed once per configuration: the hot functions
/// below (residual, Jacobian, second derivatives) take it instead of calling sin_cos per pair.
pub fn body_trig(x: &[f64], trig: &mut [[f64; 2]]) {
    for (t, xi) in trig.iter_mut().zip(x.chunks_exact(3)) {
        let (s, c) = xi[2].sin_cos();
        *t = [c, s];
    }
}

/// Pose of a link in x: centre (m), [cos, sin] of its angle, and its first column in x
/// (None for ground).
#[derive(Clone, Copy)]
struct LinkState {
    r: [f64; 2],
    cs: [f64; 2],
    col: Option<usize>,
}

impl LinkState {
    /// R(phi) s.
    #[inline]
    fn rot(&self, s: [f64; 2]) -> [f64; 2] {
        rot(self.cs, s)
    }
}

#[inline]
fn rot(cs: [f64; 2], s: [f64; 2]) -> [f64; 2] {
    [cs[0] * s[0] - cs[1] * s[1], cs[1] * s[0] + cs[0] * s[1]]
}

/// Link pose with the angle's cos/sin taken from `trig`.
#[inline]
fn link_state_t(link: Link, x: &[f64], trig: &[[f64; 2]]) -> LinkState {
    match link {
        Link::Ground => LinkState { r: [0.0; 2], cs: [1.0, 0.0], col: None },
        Link::Body(b) => {
            let c = 3 * b.0;
            LinkState { r: [x[c], x[c + 1]], cs: trig[b.0], col: Some(c) }
        }
    }
}

/// Link pose computing the angle's cos/sin (for the occasional single evaluation).
fn link_state(link: Link, x: &[f64]) -> LinkState {
    match link {
        Link::Ground => LinkState { r: [0.0; 2], cs: [1.0, 0.0], col: None },
        Link::Body(b) => {
            let c = 3 * b.0;
            let (s, co) = x[c + 2].sin_cos();
            LinkState { r: [x[c], x[c + 1]], cs: [co, s], col: Some(c) }
        }
    }
}

/// R(phi) s.
#[inline]
pub fn rotate(phi: f64, s: [f64; 2]) -> [f64; 2] {
    let (sn, cs) = phi.sin_cos();
    rot([cs, sn], s)
}

/// E v: v turned by +90 degrees.
#[inline]
pub fn perp(v: [f64; 2]) -> [f64; 2] {
    [-v[1], v[0]]
}

#[inline]
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Components (dr_x, dr_y, dphi) of a direction vector for a link (zeros for ground).
#[inline]
fn part(link: &LinkState, v: &[f64]) -> ([f64; 2], f64) {
    match link.col {
        Some(c) => ([v[c], v[c + 1]], v[c + 2]),
        None => ([0.0; 2], 0.0),
    }
}

/// Add `g = [d/dr_x, d/dr_y, d/dphi]` of a link to row `row` of `j`; a zero entry is left
/// out (the patterns of `jacobian_pattern` need not include it).
#[inline]
fn add_grad<S: Sink>(j: &mut S, row: usize, link: &LinkState, g: [f64; 3]) {
    if let Some(c) = link.col {
        for (k, v) in g.into_iter().enumerate() {
            if v != 0.0 {
                j.add(row, c + k, v);
            }
        }
    }
}

/// A projection row g = (R_a d0) . (p_b - p_a) with d0 a unit vector fixed in body a: the
/// normal row of a prismatic pair (d0 = normal) and its displacement (d0 = axis).
struct Projection {
    a: LinkState,
    b: LinkState,
    /// d = R_a d0 (global).
    d: [f64; 2],
    /// w = r_b + R_b s_b - r_a.
    w: [f64; 2],
    /// R_b s_b.
    rbsb: [f64; 2],
    /// d0 . s_a, so that g = d . w - offset.
    offset: f64,
}

impl Projection {
    fn new(pair: &Pair, d0: [f64; 2], a: LinkState, b: LinkState) -> Self {
        let rbsb = b.rot(pair.sb);
        let w = [b.r[0] + rbsb[0] - a.r[0], b.r[1] + rbsb[1] - a.r[1]];
        Projection { a, b, d: a.rot(d0), w, rbsb, offset: dot(d0, pair.sa) }
    }
    fn value(&self) -> f64 {
        dot(self.d, self.w) - self.offset
    }
    fn grad<S: Sink>(&self, j: &mut S, row: usize) {
        let ed = perp(self.d);
        add_grad(j, row, &self.a, [-self.d[0], -self.d[1], dot(ed, self.w)]);
        add_grad(j, row, &self.b, [self.d[0], self.d[1], dot(self.d, perp(self.rbsb))]);
    }
    /// Bilinear second derivative (see the module doc), from the Hessian entries
    /// d2/dphi_a2 = -d.w, d2/dphi_a dr_b = E d = -d2/dphi_a dr_a,
    /// d2/dphi_a dphi_b = d.R_b s_b = -d2/dphi_b2.
    fn gamma(&self, u: &[f64], v: &[f64]) -> f64 {
        let (ura, upa) = part(&self.a, u);
        let (urb, upb) = part(&self.b, u);
        let (vra, vpa) = part(&self.a, v);
        let (vrb, vpb) = part(&self.b, v);
        let ed = perp(self.d);
        let h = dot(self.d, self.rbsb);
        -dot(self.d, self.w) * upa * vpa
            + dot(ed, [vrb[0] - vra[0], vrb[1] - vra[1]]) * upa
            + dot(ed, [urb[0] - ura[0], urb[1] - ura[1]]) * vpa
            + h * (upa * vpb + upb * vpa - upb * vpb)
    }
}

/// Residual of the two rows of a pair.
fn pair_residual(pair: &Pair, x: &[f64], trig: &[[f64; 2]]) -> [f64; 2] {
    let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
    match pair.kind {
        PairKind::Revolute => {
            let (pa, pb) = (a.rot(pair.sa), b.rot(pair.sb));
            [a.r[0] + pa[0] - b.r[0] - pb[0], a.r[1] + pa[1] - b.r[1] - pb[1]]
        }
        PairKind::Prismatic { axis } => {
            [angle(pair.b, x) - angle(pair.a, x) - pair.rel_angle0, Projection::new(pair, perp(axis), a, b).value()]
        }
    }
}

/// The angle of a link (0 for ground).
#[inline]
fn angle(link: Link, x: &[f64]) -> f64 {
    match link {
        Link::Ground => 0.0,
        Link::Body(b) => x[3 * b.0 + 2],
    }
}

fn pair_jacobian<S: Sink>(pair: &Pair, x: &[f64], trig: &[[f64; 2]], j: &mut S, rows: [Option<usize>; 2]) {
    let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
    match pair.kind {
        PairKind::Revolute => {
            let (ta, tb) = (perp(a.rot(pair.sa)), perp(b.rot(pair.sb)));
            if let Some(row) = rows[0] {
                add_grad(j, row, &a, [1.0, 0.0, ta[0]]);
                add_grad(j, row, &b, [-1.0, 0.0, -tb[0]]);
            }
            if let Some(row) = rows[1] {
                add_grad(j, row, &a, [0.0, 1.0, ta[1]]);
                add_grad(j, row, &b, [0.0, -1.0, -tb[1]]);
            }
        }
        PairKind::Prismatic { axis } => {
            if let Some(row) = rows[0] {
                add_grad(j, row, &a, [0.0, 0.0, -1.0]);
                add_grad(j, row, &b, [0.0, 0.0, 1.0]);
            }
            if let Some(row) = rows[1] {
                Projection::new(pair, perp(axis), a, b).grad(j, row);
            }
        }
    }
}

fn pair_gamma(pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> [f64; 2] {
    let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
    match pair.kind {
        PairKind::Revolute => {
            // d2(R(phi) s)/dphi2 = -R(phi) s; only the angle-angle entries are non-zero.
            let (pa, pb) = (a.rot(pair.sa), b.rot(pair.sb));
            let (ka, kb) = (part(&a, u).1 * part(&a, v).1, part(&b, u).1 * part(&b, v).1);
            [-pa[0] * ka + pb[0] * kb, -pa[1] * ka + pb[1] * kb]
        }
        PairKind::Prismatic { axis } => [0.0, Projection::new(pair, perp(axis), a, b).gamma(u, v)],
    }
}

/// The projection along `d0` (fixed in a) of a pair at x.
fn projection(pair: &Pair, d0: [f64; 2], x: &[f64]) -> Projection {
    Projection::new(pair, d0, link_state(pair.a, x), link_state(pair.b, x))
}

/// Relative coordinate of a pair from the drawing: angle (rad) or displacement (m).
pub fn pair_coordinate(pair: &Pair, x: &[f64]) -> f64 {
    match pair.kind {
        PairKind::Revolute => angle(pair.b, x) - angle(pair.a, x) - pair.rel_angle0,
        PairKind::Prismatic { axis } => projection(pair, axis, x).value(),
    }
}

/// Gradient of [`pair_coordinate`], added into row `row` of `j`.
pub fn pair_coordinate_grad<S: Sink>(pair: &Pair, x: &[f64], j: &mut S, row: usize) {
    match pair.kind {
        PairKind::Revolute => {
            add_grad(j, row, &link_state(pair.a, x), [0.0, 0.0, -1.0]);
            add_grad(j, row, &link_state(pair.b, x), [0.0, 0.0, 1.0]);
        }
        PairKind::Prismatic { axis } => projection(pair, axis, x).grad(j, row),
    }
}

/// Second derivative of [`pair_coordinate`] as a bilinear form.
pub fn pair_coordinate_gamma(pair: &Pair, x: &[f64], u: &[f64], v: &[f64]) -> f64 {
    match pair.kind {
        PairKind::Revolute => 0.0,
        PairKind::Prismatic { axis } => projection(pair, axis, x).gamma(u, v),
    }
}

/// Rate of a pair's relative coordinate: its gradient times xd.
pub fn pair_coordinate_rate(pair: &Pair, x: &[f64], xd: &[f64]) -> f64 {
    match pair.kind {
        PairKind::Revolute => part(&link_state(pair.b, x), xd).1 - part(&link_state(pair.a, x), xd).1,
        PairKind::Prismatic { axis } => {
            let p = projection(pair, axis, x);
            let (ra, pa) = part(&p.a, xd);
            let (rb, pb) = part(&p.b, xd);
            dot(p.d, [rb[0] - ra[0], rb[1] - ra[1]]) + dot(perp(p.d), p.w) * pa + dot(p.d, perp(p.rbsb)) * pb
        }
    }
}

/// The user's generalized coordinates q = D(x).
pub fn coordinates(mech: &Mechanism, x: &[f64], q: &mut [f64]) {
    for (qk, c) in q.iter_mut().zip(&mech.coordinates) {
        *qk = pair_coordinate(&mech.pairs[c.pair.0], x) + c.value;
    }
}

/// Rates qd = D_x xd.
pub fn coordinate_rates(mech: &Mechanism, x: &[f64], xd: &[f64], qd: &mut [f64]) {
    for (qk, c) in qd.iter_mut().zip(&mech.coordinates) {
        *qk = pair_coordinate_rate(&mech.pairs[c.pair.0], x, xd);
    }
}

/// Where the two rows of pair k go in F (None: a redundant row, left out).
#[inline]
fn slots(row_slot: &[Option<usize>], k: usize) -> [Option<usize>; 2] {
    [row_slot[2 * k], row_slot[2 * k + 1]]
}

/// Write a pair's two row values to their slots.
#[inline]
fn put(out: &mut [f64], s: [Option<usize>; 2], v: [f64; 2]) {
    for (slot, value) in s.into_iter().zip(v) {
        if let Some(i) = slot {
            out[i] = value;
        }
    }
}

/// F(x) for a chart with target values z: the independent pair rows, then the chart rows.
pub fn residual(mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]], z: &[f64], out: &mut [f64]) {
    let nc = mech.n_constraints;
    for (k, pair) in mech.pairs.iter().enumerate() {
        put(out, slots(&mech.row_slot, k), pair_residual(pair, x, trig));
    }
    match chart {
        Chart::Inputs => coordinates(mech, x, &mut out[nc..]),
        Chart::Partition(idx) => {
            for (o, &i) in out[nc..].iter_mut().zip(idx) {
                *o = x[i];
            }
        }
    }
    for (o, zk) in out[nc..].iter_mut().zip(z) {
        *o -= zk;
    }
}

/// J = dF/dx for a chart, written (overwritten) into the row-major 3n x 3n buffer `j`.
pub fn jacobian(mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]], j: &mut [f64]) {
    j.fill(0.0);
    jacobian_into(mech, chart, x, trig, &mut Dense { j, ncols: x.len() });
}

/// The entries of J = dF/dx for a chart, added into `sink` (which starts at zero).
pub fn jacobian_into<S: Sink>(mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]], sink: &mut S) {
    for (k, pair) in mech.pairs.iter().enumerate() {
        pair_jacobian(pair, x, trig, sink, slots(&mech.row_slot, k));
    }
    let nc = mech.n_constraints;
    match chart {
        Chart::Inputs => {
            for (k, c) in mech.coordinates.iter().enumerate() {
                pair_coordinate_grad(&mech.pairs[c.pair.0], x, sink, nc + k);
            }
        }
        Chart::Partition(idx) => {
            for (k, &i) in idx.iter().enumerate() {
                sink.add(nc + k, i, 1.0);
            }
        }
    }
}

/// The pair-constraint rows Phi_x (row-major, 3n columns) placed by `row_slot` (the
/// mechanism's independent rows, or `0..2p` for all of them); the rest of `j` is zeroed.
pub fn constraint_jacobian(mech: &Mechanism, x: &[f64], trig: &[[f64; 2]], row_slot: &[Option<usize>], j: &mut [f64]) {
    j.fill(0.0);
    let mut dense = Dense { j, ncols: x.len() };
    for (k, pair) in mech.pairs.iter().enumerate() {
        pair_jacobian(pair, x, trig, &mut dense, slots(row_slot, k));
    }
}

/// The columns where each row of J may be non-zero, for its block-triangular analysis: a
/// pair's rows use both its bodies' three columns, a revolute pair's coordinate row only
/// their angles, a partition row its one component.
pub fn jacobian_pattern(mech: &Mechanism, chart: &Chart) -> Vec<Vec<usize>> {
    let columns = |links: [Link; 2], angles_only: bool| -> Vec<usize> {
        let mut cols: Vec<usize> = links
            .iter()
            .filter_map(|l| match l {
                Link::Ground => None,
                Link::Body(b) => Some(b.0),
            })
            .flat_map(|b| if angles_only { 3 * b + 2..3 * b + 3 } else { 3 * b..3 * b + 3 })
            .collect();
        cols.sort_unstable();
        cols
    };
    let nc = mech.n_constraints;
    let mut pattern = vec![Vec::new(); mech.n_x()];
    for (k, pair) in mech.pairs.iter().enumerate() {
        for slot in slots(&mech.row_slot, k).into_iter().flatten() {
            pattern[slot] = columns([pair.a, pair.b], false);
        }
    }
    for (k, row) in pattern[nc..].iter_mut().enumerate() {
        *row = match chart {
            Chart::Inputs => {
                let pair = &mech.pairs[mech.coordinates[k].pair.0];
                columns([pair.a, pair.b], pair.kind == PairKind::Revolute)
            }
            Chart::Partition(idx) => vec![idx[k]],
        };
    }
    pattern
}

/// gamma(u, v) = d2F/dx2 [u, v] for every row (the chart rows of a partition are linear).
pub fn gamma(mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], out: &mut [f64]) {
    let nc = mech.n_constraints;
    for (k, pair) in mech.pairs.iter().enumerate() {
        put(out, slots(&mech.row_slot, k), pair_gamma(pair, x, trig, u, v));
    }
    for (k, o) in out[nc..].iter_mut().enumerate() {
        *o = match chart {
            Chart::Inputs => pair_coordinate_gamma(&mech.pairs[mech.coordinates[k].pair.0], x, u, v),
            Chart::Partition(_) => 0.0,
        };
    }
}

/// World position of a point of a link.
pub fn world_point(link: Link, s: [f64; 2], x: &[f64]) -> [f64; 2] {
    let l = link_state(link, x);
    let p = l.rot(s);
    [l.r[0] + p[0], l.r[1] + p[1]]
}

/// Velocity of a point of a link for body rates xd.
pub fn point_velocity(link: Link, s: [f64; 2], x: &[f64], xd: &[f64]) -> [f64; 2] {
    let l = link_state(link, x);
    let (v, w) = part(&l, xd);
    let t = perp(l.rot(s));
    [v[0] + w * t[0], v[1] + w * t[1]]
}

/// Acceleration of a point of a link for body rates xd and accelerations xdd.
pub fn point_acceleration(link: Link, s: [f64; 2], x: &[f64], xd: &[f64], xdd: &[f64]) -> [f64; 2] {
    let l = link_state(link, x);
    let (_, w) = part(&l, xd);
    let (a, al) = part(&l, xdd);
    let p = l.rot(s);
    let t = perp(p);
    [a[0] + al * t[0] - w * w * p[0], a[1] + al * t[1] - w * w * p[1]]
}
