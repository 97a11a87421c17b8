//! Singularity measures and the choice of independent coordinates near them.
//!
//! Both measures are singular values of the scaled (dimensionless, see `system.rs`) Jacobian:
//! - type II (parallel): the smallest singular value of J = [Phi_x; D_x] with the inputs
//!   fixed. It is 0 where the actuated mechanism gains an uncontrolled motion.
//! - passive: the smallest singular value of Phi_x alone (its independent rows x 3n). It is 0 where the
//!   mechanism without its drives changes mobility (a folded four-bar, a change point).
//!
//! Near a type II singularity the integrator changes to m components of x chosen by Gaussian
//! elimination with complete pivoting on Phi_x (Wehage & Haug 1982, generalized coordinate
//! partitioning): the columns left without a pivot are the best-conditioned independent set.

use super::constraints::{body_trig, constraint_jacobian, Chart};
use super::pairs;
use super::system::{col_scales, scaled_jacobian};
use crate::model::Mechanism;
use nalgebra::DMatrix;

/// Relative singular value below which the constraints count as dependent (rank test).
pub const RANK_TOL: f64 = 1e-9;

fn singular_values(rows: usize, cols: usize, data: &[f64]) -> Vec<f64> {
    // The SVD iteration need not end on non-finite entries: such a matrix is singular.
    if data[..rows * cols].iter().any(|v| !v.is_finite()) {
        return vec![0.0; rows.min(cols)];
    }
    let mat = DMatrix::from_row_slice(rows, cols, &data[..rows * cols]);
    let mut sv: Vec<f64> = mat.singular_values().iter().copied().collect();
    sv.sort_by(|a, b| a.total_cmp(b));
    sv
}

fn scaled(mech: &Mechanism, chart: &Chart, x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut j = vec![0.0; n * n];
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    scaled_jacobian(mech, chart, x, &trig, &mut vec![1.0; n], &col_scales(mech), &mut j);
    j
}

/// Smallest singular value of the scaled J of a chart at x (type II measure for `Inputs`).
pub fn sigma_min(mech: &Mechanism, chart: &Chart, x: &[f64]) -> f64 {
    let n = x.len();
    if n == 0 {
        return f64::INFINITY;
    }
    singular_values(n, n, &scaled(mech, chart, x))[0]
}

/// Smallest singular value of the scaled pair-constraint Jacobian Phi_x, its independent
/// rows only (passive measure).
pub fn passive_sigma_min(mech: &Mechanism, x: &[f64]) -> f64 {
    let (n, rows) = (x.len(), mech.n_constraints);
    if rows == 0 {
        return f64::INFINITY;
    }
    singular_values(rows, n, &scaled(mech, &Chart::Inputs, x))[0]
}

/// The rank structure of all pair constraints at x.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintRank {
    /// Numerical rank of Phi_x (relative tolerance [`RANK_TOL`]).
    pub rank: usize,
    /// A maximal set of independent rows (indices into 0..n_pair_rows()), ascending.
    pub independent: Vec<usize>,
    /// The pairs taking part in each dependency among the rows (from the left null space).
    pub dependencies: Vec<Vec<usize>>,
}

/// Rank, independent rows and dependencies of all pair-constraint rows at x.
pub fn constraint_rank(mech: &Mechanism, x: &[f64]) -> ConstraintRank {
    let (n, rows) = (x.len(), mech.n_pair_rows());
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    let all: Vec<Option<usize>> = (0..rows).map(Some).collect();
    let mut j = vec![0.0; rows * n];
    constraint_jacobian(mech, x, &trig, &all, &mut j);
    if rows == 0 {
        return ConstraintRank { rank: 0, independent: vec![], dependencies: vec![] };
    }
    // Scaled as the solver's J: length rows by 1/L, translation columns by L.
    let rs: Vec<f64> = mech
        .pairs
        .iter()
        .flat_map(|p| pairs::row_scales(p, 1.0 / mech.scale).into_iter().take(pairs::n_rows(&p.kind)))
        .collect();
    for r in 0..rows {
        for c in 0..n {
            j[r * n + c] *= rs[r] * if c % 3 == 2 { 1.0 } else { mech.scale };
        }
    }
    let svd = DMatrix::from_row_slice(rows, n, &j).svd(true, false);
    let top = svd.singular_values.max();
    let tol = RANK_TOL * top.max(1.0);
    let rank = svd.singular_values.iter().filter(|&&s| s > tol).count();
    let u = svd.u.expect("requested");
    let dependencies = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] <= tol)
        .chain(svd.singular_values.len()..rows)
        .filter(|&i| i < u.ncols())
        .map(|i| {
            let mut pairs: Vec<usize> =
                (0..rows).filter(|&r| u[(r, i)].abs() > 1e-6).map(|r| mech.row_pair(r).0).collect();
            pairs.dedup();
            pairs
        })
        .collect();
    // Independent rows: the pivot columns of Phi_x^T under complete pivoting.
    let mut t = vec![0.0; n * rows];
    for r in 0..rows {
        for c in 0..n {
            t[c * rows + r] = j[r * n + c];
        }
    }
    let mut independent = pivot_columns(&mut t, n, rows, rank);
    independent.sort_unstable();
    ConstraintRank { rank, independent, dependencies }
}

/// Gaussian elimination with complete pivoting on the row-major `rows x cols` matrix `a`
/// (destroyed); returns the first `count` pivot columns in pivot order.
fn pivot_columns(a: &mut [f64], rows: usize, cols: usize, count: usize) -> Vec<usize> {
    let mut free: Vec<usize> = (0..cols).collect();
    let mut pivots = Vec::new();
    for k in 0..rows.min(count) {
        let (mut pr, mut pc, mut best) = (k, 0, 0.0);
        for r in k..rows {
            for (ci, &c) in free.iter().enumerate() {
                let v = a[r * cols + c].abs();
                if v > best {
                    (pr, pc, best) = (r, ci, v);
                }
            }
        }
        if best == 0.0 {
            break;
        }
        let col = free.remove(pc);
        pivots.push(col);
        for j in 0..cols {
            a.swap(k * cols + j, pr * cols + j);
        }
        for r in k + 1..rows {
            let l = a[r * cols + col] / a[k * cols + col];
            for j in 0..cols {
                a[r * cols + j] -= l * a[k * cols + j];
            }
        }
    }
    pivots
}

/// The m best independent components of x at x: the columns of the scaled Phi_x (its
/// independent rows) left without a pivot by complete-pivoting elimination. Ascending.
pub fn select_partition(mech: &Mechanism, x: &[f64]) -> Vec<usize> {
    let (n, rows) = (x.len(), mech.n_constraints);
    let mut a = scaled(mech, &Chart::Inputs, x);
    let pivots = pivot_columns(&mut a[..rows * n], rows, n, rows);
    let mut free: Vec<usize> = (0..n).filter(|c| !pivots.contains(c)).collect();
    free.truncate(mech.dof());
    free
}
