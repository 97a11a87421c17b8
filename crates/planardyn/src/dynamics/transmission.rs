//! Motors and their transmissions (docs/actuators.md): the motor torque t_m (N m, motor side)
//! of a drive whose gear of ratio n delivers the joint-side effort tau (N m or N on its pair's
//! coordinate q). The rotor (inertia J) sits before the gear, turning at
//! omega_r = omega_h + n qd (omega_h its housing's rate: the pair's first body for an angle,
//! 0 for a sliding pair, whose screw turns about an axis in the plane). With the motor's own
//! friction f(n qd) = c n qd + T_c tanh(n qd / v_m), the torque the rotor hands to the gear is
//!
//!   t = t_m - f - J omega_r',
//!
//! and the gear passes it on with its efficiency in the direction the power flows: motoring
//! (the gear's input power t qd >= 0) tau = n eta t; back-driven (the load drives the rotor)
//! eta_b tau = n t, eta_b the back-drive efficiency (0: a self-locking gear, t = 0, which holds
//! any load). Forward dynamics solves these with the accelerations (`dynamics::gears`); here
//! the motor torque of a known motion (`dynamics::motor_torques` reads the last evaluation's).

use crate::model::pairs::{self, Relative};
use crate::model::{Actuator, Link, Mechanism, PairId};

/// tanh(v / v_s): the sign function regularised over speed v_s > 0.
#[inline]
pub fn smooth_sign(v: f64, v_s: f64) -> f64 {
    (v / v_s).tanh()
}

/// The motor's own friction torque f (N m, motor side) at coordinate rate qd.
pub(crate) fn motor_friction(a: &Actuator, qd: f64) -> f64 {
    let w = a.ratio * qd;
    a.viscous * w + a.coulomb * smooth_sign(w, a.stiction_speed)
}

/// A stuck gear whose coordinate still turns within its at-rest band ([`at_rest`]) comes to
/// rest with this time constant (s): qdd = -qd / T. It then creeps at most v_m T / n
/// (3.3e-6 rad behind a 30:1 gear at the default v_m = 1e-2 rad/s), and the decay rate
/// 1 / T = 100 /s is far below what an explicit integrator's steps resolve anyway.
pub(crate) const STUCK_DECAY: f64 = 1e-2;

/// Whether actuator `a`'s gear counts as at rest at coordinate rate qd: its motor turns slower
/// than its stiction speed v_m, the band where its Coulomb torque fades too. At rest a gear
/// can stick (`dynamics::gears`), where an exact qd = 0 would make an integrator chatter
/// across it (a sliding mode).
pub(crate) fn at_rest(a: &Actuator, qd: f64) -> bool {
    (a.ratio * qd).abs() <= a.stiction_speed
}

/// The direction of actuator `a`'s relative motion that decides its gear's branch: qd; at rest
/// ([`at_rest`]) the way it slips from sticking, qdd - (-qd / T) ([`STUCK_DECAY`]): qdd at
/// qd = 0, and positive, zero or negative as the gear slips forward, sticks or slips back.
pub(crate) fn direction(a: &Actuator, qd: f64, qdd: f64) -> f64 {
    Band::of(a, qd).direction(qd, qdd)
}

/// The side of its at-rest band ([`at_rest`]) whose law a gear follows. Chosen afresh from qd
/// at every evaluation, the law jumps where qd enters the band and the gear sticks there
/// (qdd from the moving solution to -qd / T), inside an integrator's step; a run holds each
/// gear's side through its steps (`dynamics::gears`, `simulate::gear_sides`), and the law of
/// a side extends past its edge smoothly: moving, the direction's sign is held (so qd may pass
/// 0 under it), at rest the band's law applies at any qd.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Band {
    AtRest,
    /// Moving with qd of this sign (+1 or -1).
    Moving(f64),
}

impl Band {
    /// The side qd is on.
    pub fn of(a: &Actuator, qd: f64) -> Band {
        if at_rest(a, qd) {
            Band::AtRest
        } else {
            Band::Moving(if qd > 0.0 { 1.0 } else { -1.0 })
        }
    }

    /// [`direction`] on this side: qd (its sign held) moving, qdd + qd / T at rest.
    pub fn direction(self, qd: f64, qdd: f64) -> f64 {
        match self {
            Band::AtRest => qdd + qd / STUCK_DECAY,
            Band::Moving(s) => s * qd.abs(),
        }
    }

    /// The switching function of this side at qd, positive while the gear keeps to it:
    /// moving, n s qd - v_m (qd entering the band); at rest, (1 + `exit`) v_m - |n qd| (qd
    /// leaving the band `exit` (a fraction) past its edge: a hysteresis against chattering).
    pub fn switching(self, a: &Actuator, qd: f64, exit: f64) -> f64 {
        match self {
            Band::AtRest => (1.0 + exit) * a.stiction_speed - (a.ratio * qd).abs(),
            Band::Moving(s) => s * a.ratio * qd - a.stiction_speed,
        }
    }
}

/// Whether the gear of actuator `a` whose output effort is `tau` moves power from the motor
/// to the load: tau along the [`direction`] of the motion. Held still (at rest, qdd = 0) it
/// counts as motoring: the motor torque that holds a load is then any between the two
/// branches' values, and the motoring one, which would start to move the load along tau, is
/// the one reported.
pub(crate) fn motoring(a: &Actuator, tau: f64, qd: f64, qdd: f64) -> bool {
    let d = direction(a, qd, qdd);
    tau * if d == 0.0 { tau } else { d } >= 0.0
}

/// The gear's input torque t (N m, motor side) for its output effort `tau`: tau / (n eta)
/// motoring, tau eta_b / n back-driven.
pub(crate) fn gear_input(a: &Actuator, tau: f64, motoring: bool) -> f64 {
    if motoring {
        tau / (a.ratio * a.efficiency)
    } else {
        tau * a.backdrive_efficiency / a.ratio
    }
}

/// The motor torque (N m) that gives joint-side effort `tau` (N m or N) at coordinate rate qd
/// and acceleration qdd (of the actuator's pair), its rotor accelerating at `rotor_acc`
/// (rad/s^2, absolute): t_m = J omega_r' + f + t, t the gear's input ([`gear_input`] on the
/// branch [`motoring`] gives).
pub fn motor_torque(a: &Actuator, tau: f64, qd: f64, qdd: f64, rotor_acc: f64) -> f64 {
    a.rotor_inertia * rotor_acc + motor_friction(a, qd) + gear_input(a, tau, motoring(a, tau, qd, qdd))
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

/// The body (index) whose rate the rotor of actuator `k` turns with: the first body of an
/// angle pair when it is not the ground; `None` for the ground and for sliding pairs.
pub(crate) fn housing(mech: &Mechanism, k: usize) -> Option<usize> {
    let pair = &mech.pairs[actuator_pair(mech, k).0];
    match (pairs::relative(pair), pair.a) {
        (Some(Relative::Angle), Link::Body(b)) => Some(b.0),
        _ => None,
    }
}
