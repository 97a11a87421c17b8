//! Velocity analogues U = dx/dz, acceleration analogues w_jk = d2x/dz_j dz_k and the
//! convective term c = sum_jl zd_j zd_l w_jl, from the factorised J
//! (docs/formulation.md, eqs. 6-9, 13-14 and 24):
//!   J U = [0; I_m],   J w_jk = -gamma(u_j, u_k),   J c = -gamma(xd, xd) with xd = U zd.

use super::constraints::gamma;
use super::frame::Frame;
use super::u_support::USupport;
use crate::model::Mechanism;
use crate::KinematicsError;

/// Fill `ws.u` (column j = u_j) from J factorised at `ws.x`. Each column is solved and
/// written on the blocks its coordinate reaches only (`System::u_support`); U is cleared
/// whole only when the supports change (a new chart's pattern), so its other entries hold
/// the zeros of that clearing: a step costs the reached blocks, not 3n per coordinate.
pub fn velocity_analogues(ws: &mut Frame) -> Result<(), KinematicsError> {
    if !ws.sys.is_factored() {
        // The analogues are undefined where J is singular (no factorisation of it).
        return Err(KinematicsError::singular(ws.chart.singularity()));
    }
    if ws.u_zeros_for != ws.sys.supports_id() {
        ws.u.fill(0.0);
        ws.u_zeros_for = ws.sys.supports_id();
    }
    ws.sys.solve_unit_columns(&mut ws.u);
    Ok(())
}

/// `out = start + sum_j dz(j) u_j` over each column's runs of bodies (`supports`, from
/// `System::u_support`: U is zero outside them), for U column-major (3n per column);
/// `start(i, out_i)` the value entry i starts from (`out_i` itself to add, zero or another
/// vector's entry to write `out` whole): for a few columns in the one pass of [`add_columns`]
/// (no clearing or copy of `out` before, which costs a library call a stage at this size),
/// else over the runs.
#[inline]
pub(crate) fn u_times_from(
    u: &[f64],
    supports: &USupport,
    dz: impl Fn(usize) -> f64,
    start: impl Fn(usize, f64) -> f64,
    out: &mut [f64],
) {
    let n = out.len();
    match supports.len() {
        1 => return add_columns::<1>(u, std::array::from_fn(dz), start, out),
        2 => return add_columns::<2>(u, std::array::from_fn(dz), start, out),
        3 => return add_columns::<3>(u, std::array::from_fn(dz), start, out),
        4 => return add_columns::<4>(u, std::array::from_fn(dz), start, out),
        _ => {}
    }
    out.iter_mut().enumerate().for_each(|(i, v)| *v = start(i, *v));
    for (j, u) in u.chunks_exact(n).enumerate().take(supports.len()) {
        let r = dz(j);
        for &(first, end) in supports.runs(j) {
            for (v, u) in out[3 * first..3 * end].iter_mut().zip(&u[3 * first..3 * end]) {
                *v += u * r;
            }
        }
    }
}

/// [`u_times_from`] for M (a few) columns, over every row in one pass with no supports'
/// bookkeeping: U is zero outside its supports, and adding a zero term leaves a non-zero sum's
/// bits as they are, so `out` is the same but for the sign of a zero `out` entry. Each entry's
/// sum starts from `start` and adds the columns' terms in order, as a copy (or clearing) of
/// `out` followed by the additions does: the same bits.
#[inline(always)]
fn add_columns<const M: usize>(u: &[f64], dz: [f64; M], start: impl Fn(usize, f64) -> f64, out: &mut [f64]) {
    let n = out.len();
    let u: [&[f64]; M] = std::array::from_fn(|j| &u[j * n..(j + 1) * n]);
    for (i, v) in out.iter_mut().enumerate() {
        let mut s = start(i, *v);
        for j in 0..M {
            s += u[j][i] * dz[j];
        }
        *v = s;
    }
}

/// Body velocities `ws.xd = U zd`, from `ws.u`.
#[inline]
pub(crate) fn body_rates(zd: &[f64], ws: &mut Frame) {
    u_times_from(&ws.u, ws.sys.u_support(), |j| zd[j], |_, _| 0.0, &mut ws.xd);
}

/// Body velocities `ws.xd = U zd` and the convective term `ws.c`, from `ws.u`.
pub fn convective(mech: &Mechanism, zd: &[f64], ws: &mut Frame) {
    body_rates(zd, ws);
    gamma(mech, &ws.chart, &ws.x, &ws.trig, &ws.xd, &ws.xd, &mut ws.c);
    for v in ws.c.iter_mut() {
        *v = -*v;
    }
    ws.sys.solve(&mut ws.c);
}

/// Acceleration analogues w (3n x m x m): `w[(j*m + k)*3n + i]` = d2 x_i / dz_j dz_k.
/// Needs `ws.u` filled.
pub fn acceleration_analogues(mech: &Mechanism, ws: &mut Frame) -> Vec<f64> {
    let n = ws.x.len();
    let m = ws.u.len() / n.max(1);
    let mut w = vec![0.0; n * m * m];
    for j in 0..m {
        for k in j..m {
            let mut col = vec![0.0; n];
            gamma(mech, &ws.chart, &ws.x, &ws.trig, ws.u_col(j), ws.u_col(k), &mut col);
            col.iter_mut().for_each(|v| *v = -*v);
            ws.sys.solve(&mut col);
            w[(j * m + k) * n..(j * m + k + 1) * n].copy_from_slice(&col);
            w[(k * m + j) * n..(k * m + j + 1) * n].copy_from_slice(&col);
        }
    }
    w
}
