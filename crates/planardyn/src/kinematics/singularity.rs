//! Singularity measures and the choice of independent coordinates near them.
//!
//! Both measures are singular values of the scaled (dimensionless, see `system.rs`) Jacobian:
//! - type II (parallel): the smallest singular value of J = [Phi_x; D_x] with the inputs
//!   fixed. It is 0 where the actuated mechanism gains an uncontrolled motion.
//! - passive: the smallest singular value of Phi_x alone (2p x 3n). It is 0 where the
//!   mechanism without its drives changes mobility (a folded four-bar, a change point).
//!
//! Near a type II singularity the integrator changes to m components of x chosen by Gaussian
//! elimination with complete pivoting on Phi_x (Wehage & Haug 1982, generalized coordinate
//! partitioning): the columns left without a pivot are the best-conditioned independent set.

use super::constraints::{body_trig, Chart};
use super::system::System;
use crate::model::Mechanism;
use nalgebra::DMatrix;

/// Relative singular value below which the constraints count as dependent (rank test).
pub const RANK_TOL: f64 = 1e-9;

fn singular_values(rows: usize, cols: usize, data: &[f64]) -> Vec<f64> {
    let mat = DMatrix::from_row_slice(rows, cols, &data[..rows * cols]);
    let mut sv: Vec<f64> = mat.singular_values().iter().copied().collect();
    sv.sort_by(|a, b| a.total_cmp(b));
    sv
}

fn scaled(mech: &Mechanism, chart: &Chart, x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut sys = System::new(mech);
    let mut j = vec![0.0; n * n];
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    sys.scaled_jacobian(mech, chart, x, &trig, &mut j);
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

/// Smallest singular value of the scaled pair-constraint Jacobian Phi_x (passive measure).
pub fn passive_sigma_min(mech: &Mechanism, x: &[f64]) -> f64 {
    let (n, rows) = (x.len(), 2 * mech.pairs.len());
    if rows == 0 {
        return f64::INFINITY;
    }
    singular_values(rows, n, &scaled(mech, &Chart::Inputs, x))[0]
}

/// Numerical rank of Phi_x in the drawing, and its number of rows 2p.
pub fn constraint_rank(mech: &Mechanism) -> (usize, usize) {
    let (n, rows) = (mech.n_x(), 2 * mech.pairs.len());
    if rows == 0 {
        return (0, 0);
    }
    let sv = singular_values(rows, n, &scaled(mech, &Chart::Inputs, &mech.x0));
    let top = sv.last().copied().unwrap_or(0.0);
    (sv.iter().filter(|&&s| s > RANK_TOL * top.max(1.0)).count(), rows)
}

/// The m best independent components of x at x: the columns of the scaled Phi_x left
/// without a pivot by complete-pivoting elimination. Sorted ascending.
pub fn select_partition(mech: &Mechanism, x: &[f64]) -> Vec<usize> {
    let (n, rows) = (x.len(), 2 * mech.pairs.len());
    let mut a = scaled(mech, &Chart::Inputs, x);
    let mut free: Vec<usize> = (0..n).collect();
    for k in 0..rows {
        // Complete pivoting over the remaining rows k.. and free columns.
        let (mut pr, mut pc, mut best) = (k, 0, -1.0);
        for r in k..rows {
            for (ci, &c) in free.iter().enumerate() {
                let v = a[r * n + c].abs();
                if v > best {
                    (pr, pc, best) = (r, ci, v);
                }
            }
        }
        if best <= 0.0 {
            break;
        }
        let col = free.remove(pc);
        for j in 0..n {
            a.swap(k * n + j, pr * n + j);
        }
        for r in k + 1..rows {
            let l = a[r * n + col] / a[k * n + col];
            for j in 0..n {
                a[r * n + j] -= l * a[k * n + j];
            }
        }
    }
    free.truncate(mech.dof());
    free
}
