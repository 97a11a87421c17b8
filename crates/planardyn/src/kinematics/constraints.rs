//! The position equations F(x) = [Phi(x); D(x) - z] = 0 and their derivatives.
//!
//! The first rows are the independent pair constraints Phi (each pair kind has its own rows,
//! `model::pairs`; `Mechanism::row_slot` places them); the last m rows fix the chart's
//! coordinates z: the user's generalized coordinates D(x) (relative angles and displacements
//! of the input pairs), or m chosen components of x (generalized coordinate partitioning).
//! Per row we need the value, the gradient (a row of J) and the second derivative as a
//! bilinear form gamma(a, b) = sum_ij d2F/dx_i dx_j a_i b_j, which gives the convective term
//! (gamma(xd, xd)) and the acceleration analogues (gamma(u_j, u_k)).

pub use crate::linalg::{Dense, Sink};
use crate::model::pairs;
pub use crate::model::pairs::frames::{perp, point_acceleration, point_velocity, rotate, world_point};
pub use crate::model::pairs::{
    coordinate as pair_coordinate, coordinate_gamma as pair_coordinate_gamma, coordinate_grad as pair_coordinate_grad,
    coordinate_rate as pair_coordinate_rate,
};
use crate::model::{CoordinateKind, Mechanism, PairKind};
use crate::SingularityKind;

/// Which m functions of x are the independent coordinates.
#[derive(Debug, PartialEq, Eq)]
pub enum Chart {
    /// The user's generalized coordinates q.
    Inputs,
    /// Components of x (indices into the 3n body coordinates), chosen near a singularity
    /// of the actuated mechanism.
    Partition(Vec<usize>),
    /// The relative coordinates of m other pairs (indices into `Mechanism::pairs`; their raw
    /// `pairs::coordinate`, no drawn value added): another set of coordinates of the same
    /// mechanism, in closed form where the user's is singular (`kinematics::alt_charts`).
    Pairs(Vec<usize>),
}

impl Chart {
    /// What a singular J means in this chart: a type II singularity in the generalized
    /// coordinates, a rank loss of the pair constraints in a partition chart.
    pub(crate) fn singularity(&self) -> SingularityKind {
        match self {
            Chart::Inputs => SingularityKind::TypeII,
            Chart::Partition(_) => SingularityKind::Passive,
            Chart::Pairs(_) => SingularityKind::TypeII,
        }
    }
}

// By hand for `clone_from`: the factorisation records its chart at every evaluation, and a
// derived `clone_from` would allocate a new index list each time in a partition chart.
impl Clone for Chart {
    fn clone(&self) -> Self {
        match self {
            Chart::Inputs => Chart::Inputs,
            Chart::Partition(idx) => Chart::Partition(idx.clone()),
            Chart::Pairs(idx) => Chart::Pairs(idx.clone()),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        match (self, source) {
            (Chart::Partition(idx), Chart::Partition(from)) | (Chart::Pairs(idx), Chart::Pairs(from)) => {
                idx.clone_from(from)
            }
            (this, _) => *this = source.clone(),
        }
    }
}

/// [cos(phi), sin(phi)] of every body, computed once per configuration: the hot functions
/// below (residual, Jacobian, second derivatives) take it instead of calling sin_cos per pair.
pub fn body_trig(x: &[f64], trig: &mut [[f64; 2]]) {
    for (t, xi) in trig.iter_mut().zip(x.chunks_exact(3)) {
        let (s, c) = xi[2].sin_cos();
        *t = [c, s];
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

/// Write a pair's row values to their slots.
#[inline]
fn put(out: &mut [f64], s: [Option<usize>; 2], v: pairs::Rows) {
    for (slot, value) in s.into_iter().zip(v) {
        if let Some(i) = slot {
            out[i] = value;
        }
    }
}

/// F(x) for a chart with target values z: the independent pair rows, then the chart rows.
pub fn residual(mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]], z: &[f64], out: &mut [f64]) {
    let nc = mech.n_constraints;
    for (pair, slots) in mech.pairs.iter().zip(&mech.pair_slots) {
        put(out, *slots, pairs::residual(pair, x, trig));
    }
    match chart {
        Chart::Inputs => coordinates(mech, x, &mut out[nc..]),
        Chart::Partition(idx) => {
            for (o, &i) in out[nc..].iter_mut().zip(idx) {
                *o = x[i];
            }
        }
        Chart::Pairs(idx) => {
            for (o, &i) in out[nc..].iter_mut().zip(idx) {
                *o = pair_coordinate(&mech.pairs[i], x);
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
    for (pair, slots) in mech.pairs.iter().zip(&mech.pair_slots) {
        pairs::jacobian(pair, x, trig, sink, *slots);
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
        Chart::Pairs(idx) => {
            for (k, &i) in idx.iter().enumerate() {
                pair_coordinate_grad(&mech.pairs[i], x, sink, nc + k);
            }
        }
    }
}

/// The pair-constraint rows Phi_x (row-major, 3n columns) placed by `row_slot` (the
/// mechanism's independent rows, or `0..n_pair_rows()` for all of them); the rest of `j` is zeroed.
pub fn constraint_jacobian(mech: &Mechanism, x: &[f64], trig: &[[f64; 2]], row_slot: &[Option<usize>], j: &mut [f64]) {
    j.fill(0.0);
    let mut dense = Dense { j, ncols: x.len() };
    for (pair, slots) in mech.pairs.iter().zip(&mech.slots_by_pair(row_slot)) {
        pairs::jacobian(pair, x, trig, &mut dense, *slots);
    }
}

/// The columns where each row of J may be non-zero, for its block-triangular analysis: each
/// pair row's from its kind, a coordinate row's from its pair, a partition row its one
/// component.
pub fn jacobian_pattern(mech: &Mechanism, chart: &Chart) -> Vec<Vec<usize>> {
    let nc = mech.n_constraints;
    let mut pattern = vec![Vec::new(); mech.n_x()];
    for (pair, slots) in mech.pairs.iter().zip(&mech.pair_slots) {
        for (row, slot) in slots.iter().enumerate() {
            if let Some(i) = *slot {
                pattern[i] = pairs::pattern(pair, row);
            }
        }
    }
    for (k, row) in pattern[nc..].iter_mut().enumerate() {
        *row = match chart {
            Chart::Inputs => pairs::coordinate_pattern(&mech.pairs[mech.coordinates[k].pair.0]),
            Chart::Partition(idx) => vec![idx[k]],
            Chart::Pairs(idx) => pairs::coordinate_pattern(&mech.pairs[idx[k]]),
        };
    }
    pattern
}

/// gamma(u, v) = d2F/dx2 [u, v] for every row (the chart rows of a partition are linear).
pub fn gamma(mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], out: &mut [f64]) {
    let nc = mech.n_constraints;
    for (pair, slots) in mech.pairs.iter().zip(&mech.pair_slots) {
        put(out, *slots, pairs::gamma(pair, x, trig, u, v));
    }
    for (k, o) in out[nc..].iter_mut().enumerate() {
        *o = match chart {
            Chart::Inputs => pair_coordinate_gamma(&mech.pairs[mech.coordinates[k].pair.0], x, u, v),
            Chart::Partition(_) => 0.0,
            Chart::Pairs(idx) => pair_coordinate_gamma(&mech.pairs[idx[k]], x, u, v),
        };
    }
}

/// 1/L for rows measured in metres, 1 for rows measured in radians.
pub fn set_row_scale(mech: &Mechanism, chart: &Chart, rs: &mut [f64]) {
    fill_row_scale(mech, chart, 1.0 / mech.scale, rs)
}

/// `inv` for rows measured in metres, 1 for rows measured in radians.
pub fn fill_row_scale(mech: &Mechanism, chart: &Chart, inv: f64, rs: &mut [f64]) {
    for (pair, slots) in mech.pairs.iter().zip(&mech.pair_slots) {
        for (slot, scale) in slots.iter().zip(pairs::row_scales(pair, inv)) {
            if let Some(i) = *slot {
                rs[i] = scale;
            }
        }
    }
    let nc = mech.n_constraints;
    for (k, r) in rs[nc..].iter_mut().enumerate() {
        let angle = match chart {
            Chart::Inputs => mech.coordinates[k].kind == CoordinateKind::Angle,
            Chart::Partition(idx) => idx[k] % 3 == 2,
            Chart::Pairs(idx) => mech.pairs[idx[k]].kind == PairKind::Revolute,
        };
        *r = if angle { 1.0 } else { inv };
    }
}
