//! Motors and their transmissions (docs/actuators.md): the motor torque t_m (N m, motor side)
//! and the joint-side effort tau (N m or N on the coordinate) of a transmission of ratio n
//! and efficiency eta, with motor-side viscous and regularised Coulomb friction:
//!
//!   tau = n eta^s (t_m - c n qd - T_c sgn_v(n qd)),
//!
//! s = +1 while motoring (the torque the motor hands to the gears does positive work,
//! (t_m - losses) qd >= 0; at rest too), s = -1 while generating (the load drives the motor).
//! The rotor's inertia J adds n^2 J to A on the driven coordinate; its torque n^2 J qdd is
//! part of the joint-side effort (the efficiency is applied to the whole gear torque except
//! that of the rotor, which keeps A linear: docs/actuators.md states it).

use crate::kinematics::constraints::{pair_coordinate_gamma, pair_coordinate_grad, Dense};
use crate::model::{Actuator, Mechanism};
use crate::workspace::Workspace;

/// tanh(v / v_s): the sign function regularised over speed v_s > 0.
#[inline]
pub fn smooth_sign(v: f64, v_s: f64) -> f64 {
    (v / v_s).tanh()
}

/// The motor's own friction torque (N m, motor side) at coordinate rate qd.
fn motor_friction(a: &Actuator, qd: f64) -> f64 {
    let w = a.ratio * qd;
    a.viscous * w + a.coulomb * smooth_sign(w, a.stiction_speed)
}

/// The joint-side effort (N m or N) of motor torque `t_m` (N m) at coordinate rate qd.
pub fn joint_effort(a: &Actuator, t_m: f64, qd: f64) -> f64 {
    let gear = t_m - motor_friction(a, qd);
    if gear * qd >= 0.0 {
        a.ratio * a.efficiency * gear
    } else {
        a.ratio * gear / a.efficiency
    }
}

/// The motor torque (N m) that gives joint-side effort `tau` at rate qd: the inverse of
/// [`joint_effort`].
pub fn motor_torque(a: &Actuator, tau: f64, qd: f64) -> f64 {
    let gear = if tau * qd >= 0.0 { tau / (a.ratio * a.efficiency) } else { tau * a.efficiency / a.ratio };
    gear + motor_friction(a, qd)
}

/// Motor torques (N m; the joint effort where a coordinate has no actuator) into `t_m` for
/// joint-side efforts `tau` at rates `qd`.
pub fn motor_torques(mech: &Mechanism, qd: &[f64], tau: &[f64], t_m: &mut [f64]) {
    for (k, slot) in mech.actuators.iter().enumerate() {
        t_m[k] = slot.as_ref().map_or(tau[k], |a| motor_torque(a, tau[k], qd[k]));
    }
}

/// `ws.tau` from motor torques to joint-side efforts, at the rates `ws.qd`.
pub(crate) fn to_joint_efforts(mech: &Mechanism, ws: &mut Workspace) {
    for (a, (tau, &qd)) in mech.actuators.iter().zip(ws.tau.iter_mut().zip(&ws.qd)) {
        if let Some(a) = a {
            *tau = joint_effort(a, *tau, qd);
        }
    }
}

/// A rotor seen in the chart z: qdd_k = g . zdd + h, inertia n^2 J.
pub(crate) struct Rotor {
    pub coordinate: usize,
    pub inertia: f64,
    pub g: Vec<f64>,
    pub h: f64,
}

/// The rotors of `mech` at the point in `ws` (after the kinematic stages); `grad` is 3n scratch.
pub(crate) fn rotors(mech: &Mechanism, ws: &Workspace, grad: &mut [f64]) -> Vec<Rotor> {
    let n = ws.x.len();
    mech.actuators
        .iter()
        .flatten()
        .filter(|a| a.rotor_inertia > 0.0)
        .map(|a| {
            let pair = &mech.pairs[mech.coordinates[a.coordinate].pair.0];
            grad.fill(0.0);
            pair_coordinate_grad(pair, &ws.x, &mut Dense { j: grad, ncols: n }, 0);
            let dot = |v: &[f64]| grad.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
            Rotor {
                coordinate: a.coordinate,
                inertia: a.ratio * a.ratio * a.rotor_inertia,
                g: ws.u.chunks_exact(n).map(dot).collect(),
                h: dot(&ws.c) + pair_coordinate_gamma(pair, &ws.x, &ws.xd, &ws.xd),
            }
        })
        .collect()
}

/// A += n^2 J g g^T and b -= n^2 J h g: the rotors' kinetic energy 1/2 n^2 J qd_k^2.
pub(crate) fn add_rotor_inertia(rotors: &[Rotor], a: &mut [f64], b: &mut [f64]) {
    let m = b.len();
    for r in rotors {
        for j in 0..m {
            b[j] -= r.inertia * r.h * r.g[j];
            for k in 0..m {
                a[j * m + k] += r.inertia * r.g[j] * r.g[k];
            }
        }
    }
}
