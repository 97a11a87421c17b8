//! Coulomb friction from the pairs' loads (docs/actuators.md, *Friction from the joint loads*).
//!
//! The friction effort on a pair's relative coordinate (N m at a revolute pair, N along a
//! sliding one) is e = -arm * N * mu(s), with s = arm * rate the slip speed (m/s) and N the
//! load: |F| at a revolute pair (the pin of radius arm carries the reaction force F), the
//! normal force along a slot, and max(|N|, 2|M|/L) along a prismatic pair of length L, whose
//! normal force N and couple M are carried at the slider's two ends (contact forces
//! N/2 +- M/L, each rubbing mu times its magnitude). At a gear mesh the slip speed is the
//! pitch speed (arm 1: the lever is the driver's pitch-line travel, `dynamics::losses`) and
//! N = F_t / cos(alpha), F_t the tangential tooth force and alpha the pressure angle; mu is
//! then the mesh coefficient referred to the pitch speed. The regularised Coulomb/Stribeck law
//!
//!   mu(s) = [mu_k + (mu_s - mu_k) exp(-(s / v_str)^2)] tanh(s / v_st)
//!
//! replaces the sign of s by a slope of mu_s / v_st through zero: a pair the load would hold
//! ("sticking") creeps at a slip speed below v_st instead of stopping exactly.

use crate::model::pairs::contact_load;
use crate::model::{JointFriction, Mechanism};

/// The signed friction coefficient mu(s) at slip speed s (m/s).
pub fn coefficient(fr: &JointFriction, s: f64) -> f64 {
    let stribeck = (fr.mu_static - fr.mu) * (-(s / fr.stribeck_speed).powi(2)).exp();
    (fr.mu + stribeck) * (s / fr.stiction_speed).tanh()
}

/// The load N (N) that presses a pair's surfaces together, from its reaction [F_x, F_y, M]:
/// its kind's [`crate::model::pairs::PairType::contact_load`].
pub fn normal_load(mech: &Mechanism, fr: &JointFriction, reaction: [f64; 3]) -> f64 {
    contact_load(&mech.pairs[fr.pair.0], fr, reaction)
}

/// The friction effort (N m or N) on the pair's relative coordinate, moving at `rate`
/// (rad/s or m/s) under reaction `reaction`.
pub fn effort(mech: &Mechanism, fr: &JointFriction, reaction: [f64; 3], rate: f64) -> f64 {
    -fr.arm * normal_load(mech, fr, reaction) * coefficient(fr, fr.arm * rate)
}
