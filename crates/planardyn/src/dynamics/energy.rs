//! Kinetic and potential energy (J). With no damping, no drive and no external force
//! their sum is constant: the first check of the whole chain.

use crate::model::loads;
use crate::model::Mechanism;

/// T = 1/2 sum_i (m_i |v_i|^2 + I_i omega_i^2) for body velocities xd.
pub fn kinetic_energy(mech: &Mechanism, xd: &[f64]) -> f64 {
    mech.bodies
        .iter()
        .enumerate()
        .map(|(i, b)| 0.5 * (b.mass * (xd[3 * i].powi(2) + xd[3 * i + 1].powi(2)) + b.inertia * xd[3 * i + 2].powi(2)))
        .sum()
}

/// V = -sum_i m_i g . r_i + the loads' potentials (1/2 k (L - L0)^2 of springs and pair springs).
pub fn potential_energy(mech: &Mechanism, x: &[f64]) -> f64 {
    let g = mech.gravity;
    let gravity: f64 =
        mech.bodies.iter().enumerate().map(|(i, b)| -b.mass * (g[0] * x[3 * i] + g[1] * x[3 * i + 1])).sum();
    let elastic: f64 = mech.loads.iter().map(|load| loads::potential(load, mech, x)).sum();
    gravity + elastic
}
