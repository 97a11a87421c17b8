//! Derivatives of the applied forces f(x, xd, tau) (`forces`): along a direction t of the
//! body coordinates x at fixed xd and tau (each load kind's own, `model::loads`), and in xd,
//! where f is affine (dampers are linear in the rates, everything else does not depend on them).

use super::forces::applied_forces;
use crate::model::loads::{self, apply::pair_effort_rate};
use crate::model::Mechanism;

/// d/dx . t at fixed xd of the power of the loads (point forces, torques, dampers; drives
/// left out), the value `applied_forces` returns.
pub fn load_power_dx(mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64]) -> f64 {
    let mut dp = 0.0;
    for load in &mech.loads {
        dp += loads::power_dx(load, mech, x, xd, t);
    }
    dp
}

/// df/dx . t (3n) into `df` at (x, xd) with drive efforts `tau`, xd and tau held fixed;
/// `scratch` has length 3n.
pub fn applied_forces_dx(
    mech: &Mechanism,
    x: &[f64],
    xd: &[f64],
    tau: &[f64],
    t: &[f64],
    df: &mut [f64],
    scratch: &mut [f64],
) {
    df.fill(0.0);
    for load in &mech.loads {
        loads::add_force_dx(load, mech, x, xd, t, df, scratch);
    }
    for (c, &effort) in mech.coordinates.iter().zip(tau) {
        pair_effort_rate(mech, c.pair.0, effort, 0.0, x, t, df, scratch);
    }
}

/// Buffers for [`applied_forces_dxd`] and [`load_power_dxd`] at one configuration x:
/// f(x, 0) without drives (3n), zero efforts (m), and scratch.
pub struct RateScratch {
    base: Vec<f64>,
    tau0: Vec<f64>,
    shifted: Vec<f64>,
    out: Vec<f64>,
}

impl RateScratch {
    /// The buffers at body coordinates x (3n).
    pub fn at(mech: &Mechanism, x: &[f64]) -> Self {
        let (n, m) = (mech.n_x(), mech.dof());
        let mut s = RateScratch { base: vec![0.0; n], tau0: vec![0.0; m], shifted: vec![0.0; n], out: vec![0.0; n] };
        s.shifted.fill(0.0);
        applied_forces(mech, x, &s.shifted, &s.tau0, &mut s.base);
        s
    }
}

/// df/dxd . v (3n) into `df` at the x of `s`, drives left out: f(x, v) - f(x, 0), exact
/// because f is affine in xd.
pub fn applied_forces_dxd(mech: &Mechanism, x: &[f64], v: &[f64], df: &mut [f64], s: &mut RateScratch) {
    applied_forces(mech, x, v, &s.tau0, df);
    df.iter_mut().zip(&s.base).for_each(|(d, b)| *d -= b);
}

/// d/dxd . v of the power of the loads at (x, xd): a central difference, exact because the
/// power is quadratic in xd (dampers) or linear (forces, torques).
pub fn load_power_dxd(mech: &Mechanism, x: &[f64], xd: &[f64], v: &[f64], s: &mut RateScratch) -> f64 {
    let power = |sign: f64, s: &mut RateScratch| {
        s.shifted.iter_mut().zip(xd.iter().zip(v)).for_each(|(o, (a, b))| *o = a + sign * b);
        applied_forces(mech, x, &s.shifted, &s.tau0, &mut s.out)
    };
    0.5 * (power(1.0, s) - power(-1.0, s))
}
