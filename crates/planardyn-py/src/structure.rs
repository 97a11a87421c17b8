//! Structural analysis support (`planardyn.structure`): the pair-constraint Jacobian Phi_x
//! at given body coordinates and its singular values. The Python side finds the mobility
//! from its rank and the redundant pairs from the null space of Phi_x^T.

use crate::convert::{arr1, arr2, vector};
use crate::mechanism::PyMechanism;
use numpy::{AllowTypeChange, PyArrayLikeDyn};
use planardyn::kinematics::constraints::{body_trig, constraint_jacobian as phi_x};
use planardyn::kinematics::pairs::{n_rows, row_scales};
use planardyn::Mechanism;
use pyo3::prelude::*;

type ArrayArg<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// Phi_x (all pair rows x 3n, row-major) at x; `scaled`: rows in metres divided by the mechanism's
/// length L and translation columns multiplied by L, so that entries are dimensionless
/// (the scaling of the core's singularity measures, `kinematics::system`).
fn jacobian(mech: &Mechanism, x: &[f64], scaled: bool) -> Vec<f64> {
    let (rows, cols) = (mech.n_pair_rows(), mech.n_x());
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    // Every pair row, in pair order (`Mechanism::pair_rows`), also the ones the core drops
    // as redundant.
    let all_rows: Vec<Option<usize>> = (0..rows).map(Some).collect();
    let mut j = vec![0.0; rows * cols];
    phi_x(mech, x, &trig, &all_rows, &mut j);
    if scaled {
        let inv = 1.0 / mech.scale;
        let rs: Vec<f64> =
            mech.pairs.iter().flat_map(|p| row_scales(p, inv).into_iter().take(n_rows(&p.kind))).collect();
        for r in 0..rows {
            for c in 0..cols {
                j[r * cols + c] *= rs[r] * if c % 3 == 2 { 1.0 } else { mech.scale };
            }
        }
    }
    j
}

/// Singular values of a (rows x cols) row-major matrix, ascending, by one-sided Jacobi
/// rotations (Hestenes 1958) on the columns of A^T (rows <= a few dozen here, so O(n^3) is fine).
fn singular_values(rows: usize, cols: usize, a: &[f64]) -> Vec<f64> {
    // Work on the rows of A as vectors: orthogonalise them pairwise; their norms are the
    // singular values (min(rows, cols) of them are meaningful, the rest are zero).
    let mut v: Vec<Vec<f64>> = (0..rows).map(|r| a[r * cols..(r + 1) * cols].to_vec()).collect();
    for _sweep in 0..60 {
        let mut rotated = false;
        for i in 0..rows {
            for k in i + 1..rows {
                let (alpha, beta, gamma) =
                    v[i].iter().zip(&v[k]).fold((0.0, 0.0, 0.0), |(a, b, g), (x, y)| (a + x * x, b + y * y, g + x * y));
                if gamma.abs() <= 1e-15 * (alpha * beta).sqrt() || gamma == 0.0 {
                    continue;
                }
                rotated = true;
                let zeta = (beta - alpha) / (2.0 * gamma);
                let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                let t = if zeta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = c * t;
                let (lo, hi) = v.split_at_mut(k);
                for (x, y) in lo[i].iter_mut().zip(hi[0].iter_mut()) {
                    let (xi, yk) = (*x, *y);
                    *x = c * xi - s * yk;
                    *y = s * xi + c * yk;
                }
            }
        }
        if !rotated {
            break;
        }
    }
    let mut sv: Vec<f64> = v.iter().map(|r| r.iter().map(|x| x * x).sum::<f64>().sqrt()).collect();
    sv.sort_by(|a, b| b.total_cmp(a));
    sv.truncate(rows.min(cols));
    sv.reverse();
    sv
}

/// The pair-constraint Jacobian Phi_x = dPhi/dx at body coordinates x: shape (rows, 3n),
/// the pairs' rows in the order of `pair_names`, pair k's at `Mechanism.pairs[k]['rows']`
/// (a revolute pair: the x and y components of the gap between its two copies of the point,
/// m; a prismatic pair: the relative angle, rad, then the normal offset from the guide, m;
/// a gear pair: the rolling condition, m; a slot pair: the pin's offset from the slot, m), three columns per body
/// (X, Y in m, phi in rad). `scaled=True` makes it dimensionless (metre rows / L,
/// translation columns * L, L = `Mechanism.scale`), the form whose singular values the
/// core's rank test and singularity measures use.
#[pyfunction]
#[pyo3(signature = (mech, x, scaled=false))]
pub fn constraint_jacobian<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    x: ArrayArg<'py>,
    scaled: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &*mech.inner;
    let x = vector("x", &x, m.n_x(), "body coordinates [X, Y, phi] per body")?;
    arr2(py, m.n_pair_rows(), m.n_x(), jacobian(m, &x, scaled))
}

/// Singular values of the scaled Phi_x at x, ascending: min(rows, 3n) of them.
#[pyfunction]
pub fn constraint_singular_values<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    x: ArrayArg<'py>,
) -> PyResult<Bound<'py, PyAny>> {
    let m = &*mech.inner;
    let x = vector("x", &x, m.n_x(), "body coordinates [X, Y, phi] per body")?;
    let (rows, cols) = (m.n_pair_rows(), m.n_x());
    let j = jacobian(m, &x, true);
    Ok(arr1(py, singular_values(rows, cols, &j)))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(constraint_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(constraint_singular_values, m)?)?;
    Ok(())
}
