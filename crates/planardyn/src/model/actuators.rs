//! Motors with their transmissions, and Coulomb friction from the pairs' loads, as the model
//! holds them once validated (docs/actuators.md). The mechanics that use them are in
//! `dynamics::transmission` and `dynamics::friction`.

use super::PairId;

/// A motor driving an actuator's relative coordinate q through a transmission of ratio n:
/// motor angle n q (rad) relative to its housing, motor speed n qd (rad/s). The housing is
/// the pair's first body (for a sliding pair the rotor's axis lies in the plane).
#[derive(Debug, Clone, PartialEq)]
pub struct Actuator {
    pub name: String,
    /// Transmission ratio n (> 0).
    pub ratio: f64,
    /// Transmission efficiency eta in (0, 1] while motoring (the rotor drives the load).
    pub efficiency: f64,
    /// Back-drive efficiency eta_b in [0, 1], while the load drives the rotor (default eta);
    /// 0: a self-locking gear (a worm drive), which holds its load.
    pub backdrive_efficiency: f64,
    /// Rotor inertia J (kg m^2, motor side).
    pub rotor_inertia: f64,
    /// Motor-side viscous friction (N m s/rad).
    pub viscous: f64,
    /// Motor-side Coulomb friction torque (N m).
    pub coulomb: f64,
    /// Motor speed (rad/s) of the Coulomb torque's regularisation.
    pub stiction_speed: f64,
    pub limits: Limits,
}

/// A motor's limits (motor side; N m and rad/s); `None`: not given, not checked.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Limits {
    pub peak_torque: Option<f64>,
    pub continuous_torque: Option<f64>,
    pub max_speed: Option<f64>,
    /// The torque-speed envelope as points [speed, torque], speeds increasing from 0; empty
    /// when none is given (then the peak torque holds at every speed up to the maximum).
    pub envelope: Vec<[f64; 2]>,
}

impl Limits {
    /// The torque (N m) available at motor speed `speed` (rad/s, either sign): the envelope
    /// interpolated linearly (0 beyond its last point), else the peak torque; `None` when
    /// neither is given.
    pub fn available_torque(&self, speed: f64) -> Option<f64> {
        let w = speed.abs();
        if self.envelope.is_empty() {
            return self.peak_torque.map(|t| if self.max_speed.is_some_and(|m| w > m) { 0.0 } else { t });
        }
        let e = &self.envelope;
        let k = e.partition_point(|p| p[0] <= w);
        Some(match k {
            0 => e[0][1],
            k if k == e.len() => {
                if w == e[k - 1][0] {
                    e[k - 1][1]
                } else {
                    0.0
                }
            }
            k => e[k - 1][1] + (w - e[k - 1][0]) / (e[k][0] - e[k - 1][0]) * (e[k][1] - e[k - 1][1]),
        })
    }
}

/// Coulomb friction at a pair from its reaction (the viscous part is a `Load::PairSpring`).
#[derive(Debug, Clone, PartialEq)]
pub struct JointFriction {
    pub pair: PairId,
    /// Sliding coefficient mu and static coefficient mu_s (>= 0).
    pub mu: f64,
    pub mu_static: f64,
    /// Friction arm (m): the pin radius of a revolute pair, 1 for a sliding pair (whose
    /// coordinate is the slip itself).
    pub arm: f64,
    /// Slider length L (m) over which a prismatic pair carries its couple (0: couple ignored).
    pub length: f64,
    /// Slip speeds (m/s) of the regularisation and of the Stribeck fall.
    pub stiction_speed: f64,
    pub stribeck_speed: f64,
    /// A gear mesh's pressure angle alpha (rad): its teeth press with N = F_t / cos(alpha)
    /// (0 for the other pairs).
    pub pressure_angle: f64,
}

/// A redundant actuator on the relative coordinate of a pair that is not a generalized
/// coordinate's (docs/actuators.md, *Redundant actuation*): a motor with its transmission, or
/// (`drive` None) an ideal effort source.
#[derive(Debug, Clone, PartialEq)]
pub struct PairActuator {
    pub name: String,
    pub pair: PairId,
    pub drive: Option<Actuator>,
}
