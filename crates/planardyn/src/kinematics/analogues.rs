//! Velocity analogues U = dx/dz, acceleration analogues w_jk = d2x/dz_j dz_k and the
//! convective term c = sum_jl zd_j zd_l w_jl, from the factorised J
//! (docs/formulation.md, eqs. 6-9, 13-14 and 24):
//!   J U = [0; I_m],   J w_jk = -gamma(u_j, u_k),   J c = -gamma(xd, xd) with xd = U zd.

use super::constraints::gamma;
use super::position::chart_singularity;
use crate::model::Mechanism;
use crate::workspace::Workspace;
use crate::KinematicsError;

/// Fill `ws.u` (column j = u_j) from J factorised at `ws.x`.
pub fn velocity_analogues(ws: &mut Workspace) -> Result<(), KinematicsError> {
    if !ws.sys.is_factored() {
        // The analogues are undefined where J is singular (no factorisation of it).
        return Err(KinematicsError::singular(chart_singularity(&ws.chart)));
    }
    let n = ws.x.len();
    let m = ws.u.len() / n.max(1);
    ws.u.fill(0.0);
    for j in 0..m {
        ws.u[j * n + n - m + j] = 1.0;
    }
    ws.sys.solve_unit_columns(&mut ws.u);
    Ok(())
}

/// Body velocities `ws.xd = U zd`, from `ws.u`.
pub(crate) fn body_rates(zd: &[f64], ws: &mut Workspace) {
    let n = ws.x.len();
    ws.xd.fill(0.0);
    for (j, &r) in zd.iter().enumerate() {
        for (v, u) in ws.xd.iter_mut().zip(&ws.u[j * n..(j + 1) * n]) {
            *v += u * r;
        }
    }
}

/// Body velocities `ws.xd = U zd` and the convective term `ws.c`, from `ws.u`.
pub fn convective(mech: &Mechanism, zd: &[f64], ws: &mut Workspace) {
    body_rates(zd, ws);
    gamma(mech, &ws.chart, &ws.x, &ws.trig, &ws.xd, &ws.xd, &mut ws.c);
    for v in ws.c.iter_mut() {
        *v = -*v;
    }
    ws.sys.solve(&mut ws.c);
}

/// Acceleration analogues w (3n x m x m): `w[(j*m + k)*3n + i]` = d2 x_i / dz_j dz_k.
/// Needs `ws.u` filled.
pub fn acceleration_analogues(mech: &Mechanism, ws: &mut Workspace) -> Vec<f64> {
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
