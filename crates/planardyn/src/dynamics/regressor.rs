//! The dynamics in linear form for identification (docs/identification.md): tau =
//! Y(q, qd, qdd) pi + tau_o, with pi the inertial parameters of every body, then the loss
//! parameters (*Losses* there), and tau_o the efforts of the loads that do not depend on them
//! (springs, external forces).
//!
//! Each body's parameters are taken in its own frame as the model defines it (origin at the
//! drawn centre of mass, axes turning with the body angle phi): [m, m cx, m cy, I_O], where
//! (cx, cy) is the centre of mass in that frame (0 in the model) and I_O the moment of
//! inertia about the frame's origin. The kinematics do not depend on pi, so a body whose
//! real centre of mass is elsewhere is the same Y with other numbers in pi. With a the
//! origin's acceleration, alpha = phidd, omega = phid and p = R(phi) (m cx, m cy), the body's
//! inertia and weight reduced to its origin are
//!   F = m (a - g) + alpha perp(p) - omega^2 p,   M = I_O alpha + p x (a - g),
//! linear in pi, and tau = sum over bodies of U_body^T [F, M] (Lagrange's equations with the
//! velocity analogues U of the origins). The loss columns are in [`super::loss_columns`].

use super::forces::applied_forces;
use super::inverse::inverse_at_rates;
use super::loss_columns::{self, LossLayout};
use crate::model::pairs::frames::rotate;
use crate::model::Mechanism;
use crate::workspace::Workspace;
use crate::KinematicsError;

/// Parameters per body: m (kg), m cx, m cy (kg m), I_O (kg m^2).
pub const BODY_PARAMETERS: usize = 4;

/// Number of parameters p: [`BODY_PARAMETERS`] per body, then the losses'.
pub fn n_parameters(mech: &Mechanism) -> usize {
    BODY_PARAMETERS * mech.bodies.len() + LossLayout::new(mech).len(mech)
}

/// The names of pi, in order: `m_<body>`, `mcx_<body>`, `mcy_<body>`, `I_<body>` per body,
/// then the losses' ([`loss_columns`]).
pub fn parameter_names(mech: &Mechanism) -> Vec<String> {
    let bodies = mech.bodies.iter().flat_map(|b| ["m", "mcx", "mcy", "I"].map(|p| format!("{p}_{}", b.name)));
    bodies.chain(LossLayout::new(mech).names(mech)).collect()
}

/// The model's own pi: [m, 0, 0, I about the centre of mass] per body, then the losses'.
pub fn parameters(mech: &Mechanism) -> Vec<f64> {
    let bodies = mech.bodies.iter().flat_map(|b| [b.mass, 0.0, 0.0, b.inertia]);
    bodies.chain(LossLayout::new(mech).values(mech)).collect()
}

/// Y (m x p, row-major, p = [`n_parameters`]) into `y` and tau_o (m) into `tau_o` at user
/// coordinates q, rates qd, accelerations qdd (and body rates `xd` when given, as
/// [`inverse_at_rates`]), Newton starting from `ws.x`, so that Y pi + tau_o with the
/// model's pi is its inverse dynamics: on a coordinate with an actuator the motor torque
/// ([`super::motor_torques`] of the joint-side effort), elsewhere the joint-side effort.
#[allow(clippy::too_many_arguments)]
pub fn regressor(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    xd: Option<&[f64]>,
    ws: &mut Workspace,
    y: &mut [f64],
    tau_o: &mut [f64],
) -> Result<(), KinematicsError> {
    // The model's own efforts: the reactions the pin friction's columns need, and the
    // transmissions' branch (motoring or generating).
    inverse_at_rates(mech, q, qd, qdd, xd, ws)?;
    let tau_model = ws.tau.clone();
    let (n, m, nb) = (ws.x.len(), qdd.len(), mech.bodies.len());
    let p = y.len() / m.max(1);
    // The loads other than gravity, without drives or friction.
    ws.tau.fill(0.0);
    applied_forces(mech, &ws.x, &ws.xd, &ws.tau, &mut ws.f);
    let g = mech.gravity;
    for (f, body) in ws.f.chunks_exact_mut(3).zip(&mech.bodies) {
        f[0] -= body.mass * g[0];
        f[1] -= body.mass * g[1];
    }
    tau_o.fill(0.0);
    for i in 0..nb {
        let (xd, xdd) = (&ws.xd[3 * i..3 * i + 3], &ws.xdd[3 * i..3 * i + 3]);
        let a = [xdd[0] - g[0], xdd[1] - g[1]];
        let (alpha, omega2) = (xdd[2], xd[2] * xd[2]);
        let phi = ws.x[3 * i + 2];
        // [F_x, F_y, M] per unit of each parameter.
        let per_first_moment =
            |p: [f64; 2]| [-alpha * p[1] - omega2 * p[0], alpha * p[0] - omega2 * p[1], p[0] * a[1] - p[1] * a[0]];
        let columns = [
            [a[0], a[1], 0.0],
            per_first_moment(rotate(phi, [1.0, 0.0])),
            per_first_moment(rotate(phi, [0.0, 1.0])),
            [0.0, 0.0, alpha],
        ];
        for j in 0..m {
            let u = &ws.u[j * n + 3 * i..j * n + 3 * i + 3];
            let row = &mut y[j * p + BODY_PARAMETERS * i..][..BODY_PARAMETERS];
            for (yk, col) in row.iter_mut().zip(&columns) {
                *yk = u[0] * col[0] + u[1] * col[1] + u[2] * col[2];
            }
            tau_o[j] -= u[0] * ws.f[3 * i] + u[1] * ws.f[3 * i + 1] + u[2] * ws.f[3 * i + 2];
        }
    }
    loss_columns::fill(mech, ws, qd, qdd, &tau_model, BODY_PARAMETERS * nb, y, tau_o)
}
