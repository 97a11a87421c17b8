//! Inverse dynamics: the drive efforts a motion needs, tau = U^T (M xdd - f), with f the
//! applied forces without drives (docs/formulation.md, *Inverse dynamics*). Defined only where
//! the user's coordinates determine the mechanism (away from type II singularities).

use super::forces::applied_forces;
use super::losses::inverse_with_losses;
use super::stages::{kinematic_stages, m_dot};
use super::workspace::Workspace;
use crate::kinematics::constraints::{gamma, jacobian};
use crate::kinematics::Chart;
use crate::model::Mechanism;
use crate::KinematicsError;

/// Drive efforts (N m or N) into `ws.tau` for user coordinates q, rates qd and accelerations
/// qdd (joint-side: with the pairs' friction and the rotors' n^2 J qdd; the motor torques are
/// [`super::motor_torques`] of them), starting Newton from `ws.x` (use [`crate::kinematics::assemble_into`] first for a
/// distant q). Leaves the body rates and accelerations in `ws.xd`, `ws.xdd`.
pub fn inverse(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    ws: &mut Workspace,
) -> Result<(), KinematicsError> {
    inverse_at_rates(mech, q, qd, qdd, None, ws)
}

/// [`inverse`], with `xd` the body rates of the same state (3n, e.g. a result's row; see
/// [`rates_mismatch`]) used instead of solving J xd = [0; qd] when given: near a type II
/// singularity one rounding unit of qd moves that solution, and the efforts, by eps/sigma.
pub fn inverse_at_rates(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    xd: Option<&[f64]>,
    ws: &mut Workspace,
) -> Result<(), KinematicsError> {
    ws.chart = Chart::Inputs;
    kinematic_stages(mech, q, qd, ws)?;
    body_motion(mech, qd, qdd, xd, ws);
    ws.tau.fill(0.0);
    applied_forces(mech, &ws.frame.x, &ws.frame.xd, &ws.tau, &mut ws.f);
    // tau = A qdd - b, formed as U^T (M xdd - f): M xdd - f is the constraint reaction,
    // of the motion's own size, where A qdd and b are each of size 1/sigma^2.
    let n = ws.x.len();
    for (j, tau) in ws.tau.iter_mut().enumerate() {
        let u = &ws.frame.u[j * n..(j + 1) * n];
        let support = ws.frame.sys.u_support();
        *tau = m_dot(mech, u, &ws.xdd, support.runs(j)) - support.dot(j, u, &ws.f);
    }
    if mech.has_losses() {
        inverse_with_losses(mech, qdd, ws)?;
    }
    ws.qdd.copy_from_slice(qdd);
    super::finite("efforts tau", &ws.tau)?;
    Ok(())
}

/// Body rates and accelerations of rates qd and accelerations qdd in the user's chart, each
/// from one solve with the factorised J (the rates only when `given` is `None`):
///   J xd = [0; qd],   J xdd = -gamma(xd, xd) + [0; qdd].
/// Near a type II singularity U qd and U qdd + c add columns of size 1/sigma into a vector
/// of size 1, each carrying its solve's error eps/sigma^2; one solve of the summed
/// right-hand side errs by eps/sigma only.
fn body_motion(mech: &Mechanism, qd: &[f64], qdd: &[f64], given: Option<&[f64]>, ws: &mut Workspace) {
    let nc = mech.n_constraints;
    if let Some(xd) = given {
        ws.xd.copy_from_slice(xd);
    } else {
        ws.xd.fill(0.0);
        ws.xd[nc..].copy_from_slice(qd);
        ws.frame.sys.solve(&mut ws.frame.xd);
    }
    gamma(mech, &ws.frame.chart, &ws.frame.x, &ws.frame.trig, &ws.frame.xd, &ws.frame.xd, &mut ws.xdd);
    for (i, a) in ws.xdd.iter_mut().enumerate() {
        let drive = if i >= nc { qdd[i - nc] } else { 0.0 };
        *a = drive - *a;
    }
    ws.frame.sys.solve(&mut ws.xdd);
}

/// How far body rates xd are from being the rates of user rates qd at the positions in `ws`
/// (`ws.x`, `ws.trig`): the largest row of |J xd - [0; qd]| relative to that row's size at the
/// rates' own scale, sum_i |J_ki| s_i + |[0; qd]_k|, with s_i the largest translational or
/// angular rate of xd (the kind of component i). A product and a subtraction, so independent
/// of J's conditioning: round-off gives a few eps, rates of another state O(1). Not each term's
/// own |J_ki xd_i|: a rate that is 0 in exact arithmetic carries the round-off of the others
/// (the slider-crank through its dead centre, DOP853 rtol 1e-10: its slider's vertical rate
/// -9.0e-16 m/s, which alone made its guide's row 1.0 "relative" and refused the run's own xd).
/// `j` is a 3n x 3n scratch buffer.
pub fn rates_mismatch(mech: &Mechanism, ws: &Workspace, qd: &[f64], xd: &[f64], j: &mut [f64]) -> f64 {
    let (n, nc) = (xd.len(), mech.n_constraints);
    jacobian(mech, &Chart::Inputs, &ws.x, &ws.trig, j);
    // Body coordinates are (x, y, angle) per body.
    let scale = |angular: bool| {
        xd.iter().enumerate().filter(|(i, _)| (i % 3 == 2) == angular).map(|(_, v)| v.abs()).fold(0.0, f64::max)
    };
    let (linear, angular) = (scale(false), scale(true));
    (0..n)
        .map(|k| {
            let rhs = if k >= nc { qd[k - nc] } else { 0.0 };
            let row = &j[k * n..(k + 1) * n];
            let jxd: f64 = row.iter().zip(xd).map(|(a, v)| a * v).sum();
            let size: f64 =
                row.iter().enumerate().map(|(i, a)| a.abs() * if i % 3 == 2 { angular } else { linear }).sum::<f64>()
                    + rhs.abs();
            if size > 0.0 {
                (jxd - rhs).abs() / size
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}
