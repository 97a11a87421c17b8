//! Everything a view of the mechanism shows at one state (q, qd, qdd), in one call: the body
//! motion, the drive efforts that make it, the pair reactions under those efforts, the
//! singularity measures and the energies. The entry point of an interactive view (the browser
//! app draws a frame from one [`evaluate`]), so that a binding converts and does not assemble
//! the pipeline itself.

use super::{forward, inverse, kinetic_energy, motor_torques, potential_energy, reactions, FixedDrives};
use crate::kinematics::{assemble_from, assemble_into, passive_sigma_min, sigma_min, Chart};
use crate::model::Mechanism;
use crate::workspace::Workspace;
use crate::Error;

/// One state's quantities; shapes with n bodies, m coordinates, p pairs.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Body coordinates [X, Y, phi] per body (3n; m, rad), on the branch reached.
    pub x: Vec<f64>,
    /// Body rates (3n; m/s, rad/s).
    pub xd: Vec<f64>,
    /// Body accelerations (3n; m/s^2, rad/s^2) of the forward evaluation under `tau`.
    pub xdd: Vec<f64>,
    /// Joint-side drive efforts (m; N m or N) giving the accelerations qdd (inverse dynamics).
    pub tau: Vec<f64>,
    /// Per pair, [F_x, F_y, M] that body a exerts on body b (N, N m) under `tau`.
    pub reactions: Vec<[f64; 3]>,
    /// Smallest scaled singular value of J in the input chart (type II measure; 0 at a
    /// singularity), and of the passive mechanism's constraints.
    pub sigma: f64,
    pub sigma_passive: f64,
    /// Kinetic and potential energy (J).
    pub kinetic: f64,
    pub potential: f64,
    /// Loop-closure residual of the assembly (m).
    pub residual: f64,
}

/// The quantities at coordinates q, rates qd and accelerations qdd (m each; rad or m, per s,
/// per s^2), assembled by continuation from `x_start` (3n, a neighbouring state on the wanted
/// branch) or else from the drawing. Stages: positions -> inverse dynamics (tau) -> forward
/// dynamics under tau as motor torques (so the reactions are those of this motion) ->
/// reactions -> measures and energies. Fails where the mechanism cannot be assembled or is
/// singular (type II: the forward evaluation has no unique accelerations).
pub fn evaluate(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    x_start: Option<&[f64]>,
) -> Result<Evaluation, Error> {
    let mut ws = Workspace::new(mech);
    match x_start {
        Some(x) => assemble_from(mech, x, q, &mut ws)?,
        None => assemble_into(mech, q, &mut ws)?,
    }
    inverse(mech, q, qd, qdd, &mut ws)?;
    let tau = ws.tau.clone();
    let mut motor = vec![0.0; tau.len()];
    motor_torques(mech, qd, &tau, &mut motor);
    forward(mech, 0.0, q, qd, &mut FixedDrives(motor), &mut ws)?;
    let reactions = reactions(mech, &mut ws);
    super::finite("reactions", reactions.as_flattened())?;
    let [kinetic, potential] =
        super::finite("energies", [kinetic_energy(mech, &ws.xd), potential_energy(mech, &ws.x)])?;
    Ok(Evaluation {
        sigma: sigma_min(mech, &Chart::Inputs, &ws.x),
        sigma_passive: passive_sigma_min(mech, &ws.x),
        residual: ws.residual,
        x: ws.x,
        xd: ws.xd,
        xdd: ws.xdd,
        tau,
        reactions,
        kinetic,
        potential,
    })
}
