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

use crate::kinematics::constraints::pair_coordinate_gamma;
use crate::model::{Actuator, Mechanism, PairId};
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

/// The rotor's inertia reflected to the driven coordinate, n^2 J (kg m^2, or kg on a
/// sliding coordinate).
pub fn reflected_inertia(a: &Actuator) -> f64 {
    a.ratio * a.ratio * a.rotor_inertia
}

/// The motor torque (N m) that gives joint-side effort `tau` at rate qd: the inverse of
/// [`joint_effort`].
pub fn motor_torque(a: &Actuator, tau: f64, qd: f64) -> f64 {
    let gear = if tau * qd >= 0.0 { tau / (a.ratio * a.efficiency) } else { tau * a.efficiency / a.ratio };
    gear + motor_friction(a, qd)
}

/// Every actuator's motor, in actuator order: the coordinates', then the pair actuators'
/// (`None`: an ideal effort source).
pub fn motors(mech: &Mechanism) -> impl Iterator<Item = Option<&Actuator>> {
    mech.actuators.iter().map(Option::as_ref).chain(mech.pair_actuators.iter().map(|a| a.drive.as_ref()))
}

/// The pair whose relative coordinate actuator `k` drives.
pub(crate) fn actuator_pair(mech: &Mechanism, k: usize) -> PairId {
    let m = mech.dof();
    if k < m {
        mech.coordinates[k].pair
    } else {
        mech.pair_actuators[k - m].pair
    }
}

/// Each actuator's n^2 J (0 without a rotor), in actuator order.
pub(crate) fn rotor_inertias(mech: &Mechanism) -> Vec<f64> {
    motors(mech).map(|a| a.map_or(0.0, reflected_inertia)).collect()
}

/// Motor torques (N m; the joint effort where an actuator has no motor) into `t_m` for
/// joint-side efforts `tau` at rates `qd`: the first `tau.len()` actuators (the coordinates',
/// then the pair actuators', whose rates are B^T qd).
pub fn motor_torques(mech: &Mechanism, qd: &[f64], tau: &[f64], t_m: &mut [f64]) {
    for (k, (slot, (&tau, &qd))) in motors(mech).zip(tau.iter().zip(qd)).enumerate() {
        t_m[k] = slot.map_or(tau, |a| motor_torque(a, tau, qd));
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

/// h_k = grad_k . c + gamma_k(xd, xd) of every actuator k with a rotor (`inertia[k]` > 0),
/// so that qdd_k = g_k . zdd + h_k; `grad` holds the actuators' pair gradients (n_a x 3n).
pub(crate) fn rotor_terms(mech: &Mechanism, ws: &Workspace, inertia: &[f64], grad: &[f64], h: &mut [f64]) {
    let n = ws.x.len();
    for (k, ((h, g), &j)) in h.iter_mut().zip(grad.chunks_exact(n)).zip(inertia).enumerate() {
        if j > 0.0 {
            let pair = &mech.pairs[actuator_pair(mech, k).0];
            *h = g.iter().zip(&ws.c).map(|(a, b)| a * b).sum::<f64>()
                + pair_coordinate_gamma(pair, &ws.x, &ws.xd, &ws.xd);
        }
    }
}

/// A += n^2 J g_k g_k^T and b -= n^2 J h_k g_k for every actuator k (`inertia[k]` = n^2 J,
/// 0 without a rotor; `g` n_a x m, row k = dq_k/dz, q_k the actuator's pair coordinate): the
/// rotors' kinetic energy 1/2 n^2 J qd_k^2.
pub(crate) fn add_rotor_inertia(inertia: &[f64], g: &[f64], h: &[f64], a: &mut [f64], b: &mut [f64]) {
    let m = b.len();
    for ((&j, g), &h) in inertia.iter().zip(g.chunks_exact(m)).zip(h).filter(|((j, _), _)| **j > 0.0) {
        for r in 0..m {
            b[r] -= j * h * g[r];
            for c in 0..m {
                a[r * m + c] += j * g[r] * g[c];
            }
        }
    }
}
