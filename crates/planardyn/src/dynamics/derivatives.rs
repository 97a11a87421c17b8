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

use super::force_rates::{applied_forces_dx, applied_forces_dxd, load_power_dx, load_power_dxd, RateScratch};
use super::forces::applied_forces;
use super::inverse::inverse;
use super::stages::{
    body_accelerations, factor_mass_matrix, kinematic_stages, lossless_mass_matrix_and_bias, mass_matrix,
};
use super::workspace::Workspace;
use crate::kinematics::third::convective_derivative;
use crate::kinematics::{acceleration_analogues, Chart};
use crate::linalg::cholesky_solve;
use crate::model::Mechanism;
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

/// The derivatives are written for ideal joints and drives: transmissions (reflected rotor
/// inertia, efficiency, motor friction) and pair friction are refused rather than left out.
fn lossless(mech: &Mechanism) -> Result<(), KinematicsError> {
    if mech.has_losses() {
        return Err(KinematicsError::BadArgument {
            name: "mechanism",
            expected: "one without actuator transmissions or pair friction (exact derivatives cover ideal \
                       joints and drives; difference forward_dynamics for a mechanism with losses)"
                .into(),
            got: "actuators or friction loads in the model".into(),
        });
    }
    Ok(())
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
    lossless(mech)?;
    inverse(mech, q, qd, qdd, ws)?;
    // dtau/dqdd = A, which inverse dynamics does not form.
    mass_matrix(mech, ws);
    let w = acceleration_analogues(mech, ws);
    let mut rs = RateScratch::at(mech, &ws.x);
    let jac = effort_jacobians(mech, qd, qdd, &w, ws, &mut rs);
    super::finite("effort derivatives", &jac.dq)?;
    super::finite("effort derivatives", &jac.dqd)?;
    Ok(jac)
}

/// The Jacobians of the efforts from `ws` analysed in the input chart at (q, qd) (x, U, xd,
/// c, A unfactored, f without drives), with the acceleration analogues w.
fn effort_jacobians(
    mech: &Mechanism,
    qd: &[f64],
    qdd: &[f64],
    w: &[f64],
    ws: &mut Workspace,
    rs: &mut RateScratch,
) -> Jacobians {
    let (n, m) = (ws.x.len(), qd.len());
    body_accelerations(&ws.frame.u, &ws.frame.c, qdd, ws.frame.sys.u_support(), &mut ws.xdd);
    // r = M xdd - f.
    let mut r = vec![0.0; n];
    for (i, body) in mech.bodies.iter().enumerate() {
        let mi = [body.mass, body.mass, body.inertia];
        for k in 0..3 {
            r[3 * i + k] = mi[k] * ws.xdd[3 * i + k] - ws.f[3 * i + k];
        }
    }
    let tau0 = vec![0.0; m];
    let mut buf = vec![0.0; 7 * n];
    let (uk, rest) = buf.split_at_mut(n);
    let (v, rest) = rest.split_at_mut(n);
    let (a_k, rest) = rest.split_at_mut(n);
    let (dc, rest) = rest.split_at_mut(n);
    let (dfx, rest) = rest.split_at_mut(n);
    let (dfv, scratch) = rest.split_at_mut(n);
    let mut jac = Jacobians { dq: vec![0.0; m * m], dqd: vec![0.0; m * m], dthird: ws.a.clone() };
    for k in 0..m {
        uk.copy_from_slice(ws.u_col(k));
        // Rates: dxdd/dqd_k = 2 v_k, and f changes by df/dxd u_k.
        contract(w, k, qd, v);
        applied_forces_dxd(mech, &ws.x, uk, dfv, rs);
        for i in 0..m {
            let ui = ws.u_col(i);
            jac.dqd[i * m + k] = 2.0 * m_dot(mech, ui, v) - dot(ui, dfv);
        }
        // Coordinates: dxdd/dq_k = sum_l w_kl qdd_l + dc/dq_k.
        convective_derivative(mech, ws, uk, v, dc, scratch);
        contract(w, k, qdd, a_k);
        a_k.iter_mut().zip(dc.iter()).for_each(|(a, d)| *a += d);
        applied_forces_dx(mech, &ws.x, &ws.xd, &tau0, uk, dfx, scratch);
        applied_forces_dxd(mech, &ws.x, v, dfv, rs);
        for j in 0..m {
            let wjk = &w[(j * m + k) * n..(j * m + k + 1) * n];
            let uj = ws.u_col(j);
            jac.dq[j * m + k] = dot(wjk, &r) + m_dot(mech, uj, a_k) - dot(uj, dfx) - dot(uj, dfv);
        }
    }
    jac
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
    let (qdd, jac, _) = accelerations_and_jacobians(mech, q, qd, tau, ws)?;
    Ok((qdd, jac))
}

/// [`forward_derivatives`] and the derivatives of the power of the non-conservative forces
/// P = tau . qd + P_loads(x, xd): what the equations of motion with their work need. One
/// position solve: qdd = A^-1 b, b of the forces with the drives' efforts (input chart), as the
/// forward evaluation makes it.
pub fn motion_derivatives(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    ws: &mut Workspace,
) -> Result<(Vec<f64>, Jacobians, PowerRates), Error> {
    let (qdd, jac, w) = accelerations_and_jacobians(mech, q, qd, tau, ws)?;
    let power = power_rates(mech, ws, &w, qd, tau, &mut RateScratch::at(mech, &ws.x));
    Ok((qdd, jac, power))
}

/// qdd and its Jacobians, with the acceleration analogues w; `ws` left analysed at (q, qd).
fn accelerations_and_jacobians(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    ws: &mut Workspace,
) -> Result<(Vec<f64>, Jacobians, Vec<f64>), Error> {
    lossless(mech)?;
    ws.chart = Chart::Inputs;
    kinematic_stages(mech, q, qd, ws)?;
    // qdd as the forward evaluation makes it, to the bit (`forward_dynamics`' own): the drives'
    // efforts among the forces, A and b summed by its function.
    ws.tau.copy_from_slice(tau);
    applied_forces(mech, &ws.frame.x, &ws.frame.xd, &ws.tau, &mut ws.f);
    lossless_mass_matrix_and_bias(mech, ws);
    let a = ws.a.clone();
    factor_mass_matrix(ws)?;
    let m = q.len();
    let mut qdd = ws.b.clone();
    cholesky_solve(&ws.a, m, &mut qdd);
    super::finite("accelerations qdd", &qdd)?;
    let factor = std::mem::replace(&mut ws.a, a);
    // The efforts' Jacobians take f without the drives (r = M xdd - f): ws.tau zeroed for it,
    // then the drives' efforts again (as the forward evaluation leaves them).
    ws.tau.fill(0.0);
    applied_forces(mech, &ws.frame.x, &ws.frame.xd, &ws.tau, &mut ws.f);
    ws.tau.copy_from_slice(tau);
    ws.qdd.copy_from_slice(&qdd);
    let w = acceleration_analogues(mech, ws);
    let mut rs = RateScratch::at(mech, &ws.x);
    let mut jac = effort_jacobians(mech, qd, &qdd, &w, ws, &mut rs);
    solve_columns(&factor, m, &mut jac.dq, -1.0);
    solve_columns(&factor, m, &mut jac.dqd, -1.0);
    jac.dthird.fill(0.0);
    jac.dthird.iter_mut().step_by(m + 1).for_each(|v| *v = 1.0);
    solve_columns(&factor, m, &mut jac.dthird, 1.0);
    super::finite("acceleration derivatives", &jac.dq)?;
    super::finite("acceleration derivatives", &jac.dqd)?;
    ws.a = factor;
    Ok((qdd, jac, w))
}

/// dP/dq_k = P_x u_k + P_xd v_k and dP/dqd_k = tau_k + P_xd u_k (in the input chart
/// tau . D_x xd = tau . qd), from the analysed `ws` and the acceleration analogues w.
fn power_rates(
    mech: &Mechanism,
    ws: &Workspace,
    w: &[f64],
    qd: &[f64],
    tau: &[f64],
    rs: &mut RateScratch,
) -> PowerRates {
    let (n, m) = (ws.x.len(), qd.len());
    let mut v = vec![0.0; n];
    let mut power = PowerRates { dq: vec![0.0; m], dqd: vec![0.0; m] };
    for (k, tau_k) in tau.iter().enumerate() {
        let uk = ws.u_col(k);
        contract(w, k, qd, &mut v);
        power.dq[k] = load_power_dx(mech, &ws.x, &ws.xd, uk) + load_power_dxd(mech, &ws.x, &ws.xd, &v, rs);
        power.dqd[k] = tau_k + load_power_dxd(mech, &ws.x, &ws.xd, uk, rs);
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
