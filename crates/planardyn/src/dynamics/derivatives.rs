//! Exact first derivatives of inverse and forward dynamics in the user's coordinates
//! (docs/formulation.md, *Derivatives*), analytic from the analogues:
//!
//!   tau_j = u_j . r,  r = M xdd - f(x, xd),  xdd = U qdd + c,  xd = U qd,
//!   dtau/dqdd = A,
//!   dtau_i/dqd_j = u_i . (2 M v_j - df/dxd u_j),                       v_j = sum_l w_jl qd_l,
//!   dtau_j/dq_k  = w_jk . r + u_j . (M (sum_l w_kl qdd_l + dc/dq_k) - df/dx u_k - df/dxd v_k),
//!
//! with dc/dq_k from the third-order analogues (`kinematics::third`). Forward dynamics
//! A qdd = tau + U^T (f - M c) has the same residual, so at qdd = FD(q, qd, tau):
//! dqdd/dtau = A^-1, dqdd/dq = -A^-1 dtau/dq, dqdd/dqd = -A^-1 dtau/dqd.

use super::along::FixedDrives;
use super::force_rates::{applied_forces_dx, applied_forces_dxd, load_power_dx, load_power_dxd, RateScratch};
use super::forward::{body_accelerations, factor_mass_matrix, forward};
use super::inverse::inverse;
use crate::kinematics::third::convective_derivative;
use crate::kinematics::{acceleration_analogues, Chart};
use crate::linalg::cholesky_solve;
use crate::model::Mechanism;
use crate::workspace::Workspace;
use crate::{Error, KinematicsError};

/// Three m x m Jacobians (row-major, entry [i*m + k] = d out_i / d in_k) of a dynamics map.
#[derive(Debug, Clone, PartialEq)]
pub struct Jacobians {
    /// With respect to the coordinates q.
    pub dq: Vec<f64>,
    /// With respect to the rates qd.
    pub dqd: Vec<f64>,
    /// With respect to the third argument: qdd (inverse dynamics) or tau (forward).
    pub dthird: Vec<f64>,
}

/// sum_i M_ii a_i b_i, M = blockdiag(m, m, I) per body.
fn m_dot(mech: &Mechanism, a: &[f64], b: &[f64]) -> f64 {
    mech.bodies
        .iter()
        .zip(a.chunks_exact(3).zip(b.chunks_exact(3)))
        .map(|(body, (a, b))| body.mass * (a[0] * b[0] + a[1] * b[1]) + body.inertia * a[2] * b[2])
        .sum()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// sum_l w_kl s_l (3n) into `out`, w as from `acceleration_analogues`.
fn contract(w: &[f64], k: usize, s: &[f64], out: &mut [f64]) {
    let n = out.len();
    let m = s.len();
    out.fill(0.0);
    for (l, &sl) in s.iter().enumerate() {
        let wkl = &w[(k * m + l) * n..(k * m + l + 1) * n];
        out.iter_mut().zip(wkl).for_each(|(o, w)| *o += w * sl);
    }
}

/// The derivatives of the power P of the non-conservative forces (W), drives included.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerRates {
    /// dP/dq (m).
    pub dq: Vec<f64>,
    /// dP/dqd (m).
    pub dqd: Vec<f64>,
}

/// dtau/dq, dtau/dqd, dtau/dqdd of inverse dynamics at (q, qd, qdd) (each m, SI units per
/// coordinate), starting Newton from `ws.x`; leaves `ws` as [`inverse`] does.
pub fn inverse_derivatives(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    ws: &mut Workspace,
) -> Result<Jacobians, KinematicsError> {
    Ok(inverse_derivatives_with(mech, q, qd, qdd, ws)?.0)
}

/// [`inverse_derivatives`] and the acceleration analogues w it computed.
fn inverse_derivatives_with(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    ws: &mut Workspace,
) -> Result<(Jacobians, Vec<f64>), KinematicsError> {
    inverse(mech, q, qd, qdd, ws)?;
    let (n, m) = (ws.x.len(), q.len());
    let w = acceleration_analogues(mech, ws);
    body_accelerations(&ws.u, &ws.c, qdd, &mut ws.xdd);
    // r = M xdd - f, stored as the 3n vector M xdd - f.
    let mut r = vec![0.0; n];
    for (i, body) in mech.bodies.iter().enumerate() {
        let mi = [body.mass, body.mass, body.inertia];
        for k in 0..3 {
            r[3 * i + k] = mi[k] * ws.xdd[3 * i + k] - ws.f[3 * i + k];
        }
    }
    let tau0 = vec![0.0; m];
    let mut rs = RateScratch::new(mech);
    let (mut v, mut a_k, mut dc, mut dfx, mut dfv, mut scratch) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut jac = Jacobians { dq: vec![0.0; m * m], dqd: vec![0.0; m * m], dthird: ws.a.clone() };
    for k in 0..m {
        let uk = ws.u_col(k).to_vec();
        // Rates: dxdd/dqd_k = 2 v_k, and f changes by df/dxd u_k.
        contract(&w, k, qd, &mut v);
        applied_forces_dxd(mech, &ws.x, &uk, &mut dfv, &mut rs);
        for i in 0..m {
            let ui = ws.u_col(i);
            jac.dqd[i * m + k] = 2.0 * m_dot(mech, ui, &v) - dot(ui, &dfv);
        }
        // Coordinates: dxdd/dq_k = sum_l w_kl qdd_l + dc/dq_k.
        convective_derivative(mech, ws, &uk, &v, &mut dc, &mut scratch);
        contract(&w, k, qdd, &mut a_k);
        a_k.iter_mut().zip(&dc).for_each(|(a, d)| *a += d);
        applied_forces_dx(mech, &ws.x, &ws.xd, &tau0, &uk, &mut dfx, &mut scratch);
        applied_forces_dxd(mech, &ws.x, &v, &mut dfv, &mut rs);
        for j in 0..m {
            let wjk = &w[(j * m + k) * n..(j * m + k + 1) * n];
            let uj = ws.u_col(j);
            jac.dq[j * m + k] = dot(wjk, &r) + m_dot(mech, uj, &a_k) - dot(uj, &dfx) - dot(uj, &dfv);
        }
    }
    super::finite("effort derivatives", &jac.dq)?;
    super::finite("effort derivatives", &jac.dqd)?;
    Ok((jac, w))
}

/// dqdd/dq, dqdd/dqd, dqdd/dtau of forward dynamics at (q, qd) with efforts `tau` held
/// fixed (each m), in the user's coordinates; returns them with qdd. Starts Newton from `ws.x`.
pub fn forward_derivatives(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    ws: &mut Workspace,
) -> Result<(Vec<f64>, Jacobians), Error> {
    let (qdd, jac, _) = motion_derivatives(mech, q, qd, tau, ws)?;
    Ok((qdd, jac))
}

/// [`forward_derivatives`] and the derivatives of the power of the non-conservative forces
/// P = tau . qd + P_loads(x, xd): what the equations of motion with their work need.
pub fn motion_derivatives(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    ws: &mut Workspace,
) -> Result<(Vec<f64>, Jacobians, PowerRates), Error> {
    ws.chart = Chart::Inputs;
    forward(mech, 0.0, q, qd, &mut FixedDrives(tau), ws)?;
    let qdd = ws.qdd.clone();
    let (mut jac, w) = inverse_derivatives_with(mech, q, qd, &qdd, ws)?;
    let power = power_rates(mech, ws, &w, qd, tau);
    let m = q.len();
    factor_mass_matrix(ws)?;
    solve_columns(&ws.a, m, &mut jac.dq, -1.0);
    solve_columns(&ws.a, m, &mut jac.dqd, -1.0);
    jac.dthird.fill(0.0);
    jac.dthird.iter_mut().step_by(m + 1).for_each(|v| *v = 1.0);
    solve_columns(&ws.a, m, &mut jac.dthird, 1.0);
    Ok((qdd, jac, power))
}

/// dP/dq_k = P_x u_k + P_xd v_k and dP/dqd_k = tau_k + P_xd u_k (in the input chart
/// tau . D_x xd = tau . qd), from the analysed `ws` and the acceleration analogues w.
fn power_rates(mech: &Mechanism, ws: &Workspace, w: &[f64], qd: &[f64], tau: &[f64]) -> PowerRates {
    let (n, m) = (ws.x.len(), qd.len());
    let mut rs = RateScratch::new(mech);
    let mut v = vec![0.0; n];
    let mut power = PowerRates { dq: vec![0.0; m], dqd: vec![0.0; m] };
    for (k, tau_k) in tau.iter().enumerate() {
        let uk = ws.u_col(k);
        contract(w, k, qd, &mut v);
        power.dq[k] = load_power_dx(mech, &ws.x, &ws.xd, uk) + load_power_dxd(mech, &ws.x, &ws.xd, &v, &mut rs);
        power.dqd[k] = tau_k + load_power_dxd(mech, &ws.x, &ws.xd, uk, &mut rs);
    }
    power
}

/// X <- sign A^-1 X for the m x m row-major X, A given by its Cholesky factor.
fn solve_columns(factor: &[f64], m: usize, x: &mut [f64], sign: f64) {
    let mut col = vec![0.0; m];
    for k in 0..m {
        col.iter_mut().enumerate().for_each(|(i, c)| *c = sign * x[i * m + k]);
        cholesky_solve(factor, m, &mut col);
        col.iter().enumerate().for_each(|(i, c)| x[i * m + k] = *c);
    }
}
