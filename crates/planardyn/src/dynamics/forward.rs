//! Forward dynamics, docs/formulation.md eqs. 29-31 in the workspace's chart z:
//!   positions -> analogues U -> convective term c -> forces f -> A = U^T M U,
//!   b = U^T (f - M c) -> zdd = A^-1 b -> xdd = U zdd + c, qdd
//! as a list of the stages of `dynamics::stages`.

use super::forces::{applied_forces, Drives};
use super::losses::forward_with_losses;
use super::stages::{
    accelerations, apply_pair_efforts, drive_efforts, factor_mass_matrix, fixed_dynamics, kinematic_stages,
    mass_matrix_and_bias, solve_mass_matrix, FIXED_M,
};
use super::workspace::Workspace;
use crate::model::Mechanism;
use crate::Error;

/// One forward-dynamics evaluation at time t (s) and chart state (z, zd): fills every
/// buffer of `ws`; the chart accelerations zdd are left in `ws.zdd`, the user's in `ws.qdd`.
/// On a coordinate with an actuator the drive's effort is the motor torque (N m, motor
/// side); `ws.tau` ends with the joint-side efforts.
pub fn forward(
    mech: &Mechanism,
    t: f64,
    z: &[f64],
    zd: &[f64],
    drives: &mut dyn Drives,
    ws: &mut Workspace,
) -> Result<(), Error> {
    kinematic_stages(mech, z, zd, ws)?;
    dynamic_stages(mech, t, drives, ws)
}

/// The stages of [`forward`] after the kinematic ones (whose results `ws` holds): forces,
/// A, b, zdd, xdd and the user's accelerations.
pub fn dynamic_stages(mech: &Mechanism, t: f64, drives: &mut dyn Drives, ws: &mut Workspace) -> Result<(), Error> {
    drive_efforts(t, drives, ws)?;
    ws.losses.take_motor_torques(&mut ws.tau, &ws.pair_tau);
    ws.power = applied_forces(mech, &ws.frame.x, &ws.frame.xd, &ws.tau, &mut ws.f);
    ws.power += apply_pair_efforts(mech, ws);
    if !mech.has_losses() {
        match ws.b.len() {
            1 => return Ok(fixed_dynamics::<1>(mech, ws)?),
            2 => return Ok(fixed_dynamics::<2>(mech, ws)?),
            3 => return Ok(fixed_dynamics::<3>(mech, ws)?),
            FIXED_M => return Ok(fixed_dynamics::<FIXED_M>(mech, ws)?),
            _ => {}
        }
    }
    mass_matrix_and_bias(mech, ws);
    if mech.has_losses() {
        return Ok(forward_with_losses(mech, ws)?);
    }
    factor_mass_matrix(ws)?;
    solve_mass_matrix(ws);
    accelerations(mech, ws);
    Ok(())
}
