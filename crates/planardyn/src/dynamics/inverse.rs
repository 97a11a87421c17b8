//! Inverse dynamics: the drive efforts a motion needs, tau = A qdd - U^T (f - M c), with f
//! the applied forces without drives (docs/formulation.md, *Inverse dynamics*). Defined only where the user's
//! coordinates determine the mechanism (away from type II singularities).

use super::forces::applied_forces;
use super::forward::{bias, kinematic_stages, mass_matrix};
use super::losses::inverse_with_losses;
use crate::kinematics::Chart;
use crate::model::Mechanism;
use crate::workspace::Workspace;
use crate::KinematicsError;

/// Drive efforts (N m or N) into `ws.tau` for user coordinates q, rates qd and accelerations
/// qdd (joint-side: with the pairs' friction and the rotors' n^2 J qdd; the motor torques are
/// [`super::motor_torques`] of them), starting Newton from `ws.x` (use [`crate::kinematics::assemble_into`] first for a
/// distant q).
pub fn inverse(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    ws: &mut Workspace,
) -> Result<(), KinematicsError> {
    ws.chart = Chart::Inputs;
    kinematic_stages(mech, q, qd, ws)?;
    ws.tau.fill(0.0);
    applied_forces(mech, &ws.x, &ws.xd, &ws.tau, &mut ws.f, &mut ws.tmp);
    mass_matrix(mech, ws);
    bias(mech, ws);
    let m = q.len();
    for j in 0..m {
        ws.tau[j] = (0..m).map(|k| ws.a[j * m + k] * qdd[k]).sum::<f64>() - ws.b[j];
    }
    if mech.has_losses() {
        inverse_with_losses(mech, qdd, ws)?;
    }
    ws.qdd.copy_from_slice(qdd);
    super::finite("efforts tau", &ws.tau)?;
    Ok(())
}
