//! Kinetic and potential energy (J). With no damping, no drive and no external force
//! their sum is constant: the first check of the whole chain.

use crate::kinematics::constraints::{pair_coordinate, world_point};
use crate::model::{Load, Mechanism};

/// T = 1/2 sum_i (m_i |v_i|^2 + I_i omega_i^2) for body velocities xd.
pub fn kinetic_energy(mech: &Mechanism, xd: &[f64]) -> f64 {
    mech.bodies
        .iter()
        .enumerate()
        .map(|(i, b)| 0.5 * (b.mass * (xd[3 * i].powi(2) + xd[3 * i + 1].powi(2)) + b.inertia * xd[3 * i + 2].powi(2)))
        .sum()
}

/// V = -sum_i m_i g . r_i + sum 1/2 k (L - L0)^2 over springs and pair springs.
pub fn potential_energy(mech: &Mechanism, x: &[f64]) -> f64 {
    let g = mech.gravity;
    let gravity: f64 =
        mech.bodies.iter().enumerate().map(|(i, b)| -b.mass * (g[0] * x[3 * i] + g[1] * x[3 * i + 1])).sum();
    let elastic: f64 = mech
        .loads
        .iter()
        .map(|load| match load {
            Load::Spring { ends, stiffness, rest_length, .. } => {
                let (p0, p1) = (world_point(ends[0].link, ends[0].s, x), world_point(ends[1].link, ends[1].s, x));
                0.5 * stiffness * ((p1[0] - p0[0]).hypot(p1[1] - p0[1]) - rest_length).powi(2)
            }
            Load::PairSpring { pair, stiffness, rest, .. } => {
                0.5 * stiffness * (pair_coordinate(&mech.pairs[pair.0], x) - rest).powi(2)
            }
            Load::Force { .. } | Load::Torque { .. } => 0.0,
        })
        .sum();
    gravity + elastic
}
