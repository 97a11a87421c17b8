//! Singularity measures and the choice of independent coordinates near them
//! (docs/formulation.md, *Singularities* and *Charts*).
//!
//! Both measures are singular values of the scaled (dimensionless, see `system.rs`) Jacobian:
//! - type II (parallel): the smallest singular value of the blocks of J = [Phi_x; D_x] with the
//!   inputs fixed (its input links and Assur groups), each at its own length (`group_sigma`).
//!   It is 0 where the actuated mechanism gains an uncontrolled motion, and means the same
//!   whatever the size of the mechanism around the group.
//! - passive: the type II measure of the better of two charts, the user's coordinates and the
//!   partition below. It is 0 where Phi_x alone (its independent rows x 3n) loses rank, i.e.
//!   where the mechanism without its drives changes mobility (a folded four-bar, a change point).
//!
//! Near a type II singularity the integrator changes to m components of x chosen by Gaussian
//! elimination with complete pivoting on Phi_x (Wehage & Haug 1982, generalized coordinate
//! partitioning): the columns left without a pivot are the best-conditioned independent set.

use super::constraints::{body_trig, Chart};
use super::phi_pivots::phi_x_pivots;
use super::system::System;
use crate::model::Mechanism;

/// Smallest singular value of the blocks of the scaled J of a chart at x, each at its own
/// length (type II measure for `Inputs`; `group_sigma`). Cost linear in the bodies.
pub fn sigma_min(mech: &Mechanism, chart: &Chart, x: &[f64]) -> f64 {
    sigma_min_with(&mut System::for_chart(mech, chart), mech, chart, x)
}

/// [`sigma_min`] with the blocks of a `sys` kept by the caller (analysed once per chart,
/// not at each call); its factorisation is left invalid.
pub fn sigma_min_with(sys: &mut System, mech: &Mechanism, chart: &Chart, x: &[f64]) -> f64 {
    if x.is_empty() {
        return f64::INFINITY;
    }
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    sys.group_sigma_exact(mech, chart, x, &trig)
}

/// Passive measure: the better of the type II measures of the two charts the integrator
/// can use at x, the user's coordinates and the partition [`select_partition`] chooses. Phi_x
/// loses rank exactly where every chart's J is singular, so it is 0 at a singularity of the
/// passive mechanism; elsewhere it is at least the type II measure, in the same units.
pub fn passive_sigma_min(mech: &Mechanism, x: &[f64]) -> f64 {
    if mech.n_constraints == 0 {
        return f64::INFINITY;
    }
    passive_sigma_min_with(&mut System::new(mech), mech, x)
}

/// [`passive_sigma_min`] with the blocks of the user's chart kept by the caller (`inputs_sys`,
/// a `System::new` analysed once, as [`sigma_min_with`] takes it), and those of the partition
/// kept with it (`System::other_chart`): the same value without analysing either chart's
/// structure again while the partition stays (a run's change-point check: about 40k of a short
/// four-bar run's 384k instructions). Its factorisation is left invalid.
pub fn passive_sigma_min_with(inputs_sys: &mut System, mech: &Mechanism, x: &[f64]) -> f64 {
    if mech.n_constraints == 0 {
        return f64::INFINITY;
    }
    let inputs = sigma_min_with(inputs_sys, mech, &Chart::Inputs, x);
    inputs.max(partition_sigma_min_with(inputs_sys, mech, x))
}

/// The partition's half of [`passive_sigma_min_with`]: the type II measure of the partition
/// [`select_partition`] chooses at x (infinite without constraints), not the user's chart's,
/// with its blocks kept in `inputs_sys` (`System::other_chart`).
pub fn partition_sigma_min_with(inputs_sys: &mut System, mech: &Mechanism, x: &[f64]) -> f64 {
    if mech.n_constraints == 0 {
        return f64::INFINITY;
    }
    let partition = Chart::Partition(select_partition(mech, x));
    sigma_min_with(inputs_sys.other_chart(mech, &partition), mech, &partition, x)
}

/// The m best independent components of x at x: the columns of the scaled Phi_x (its
/// independent rows) left without a pivot by complete-pivoting elimination. Ascending.
pub fn select_partition(mech: &Mechanism, x: &[f64]) -> Vec<usize> {
    let mut free = vec![true; x.len()];
    phi_x_pivots(mech, x).iter().for_each(|&(c, _)| free[c] = false);
    let mut free: Vec<usize> = (0..x.len()).filter(|&c| free[c]).collect();
    free.truncate(mech.dof());
    free
}
