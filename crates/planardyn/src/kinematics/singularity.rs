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
    at_trig(mech, x, |trig| sys.group_sigma_exact(mech, chart, x, trig))
}

/// Whether [`sigma_min_with`] is below `t` (> 0): the same answer, most often without the
/// blocks' SVDs (`System::group_sigma_below`).
pub fn sigma_min_below_with(sys: &mut System, mech: &Mechanism, chart: &Chart, x: &[f64], t: f64) -> bool {
    if x.is_empty() {
        return false;
    }
    at_trig(mech, x, |trig| sys.group_sigma_below(mech, chart, x, trig, t))
}

/// `measure` given the bodies' (cos, sin) at x.
fn at_trig<T>(mech: &Mechanism, x: &[f64], measure: impl FnOnce(&[[f64; 2]]) -> T) -> T {
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    measure(&trig)
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

/// Whether [`passive_sigma_min_with`] is below `t` (> 0): both charts' measures are, each
/// decided as [`sigma_min_below_with`] decides it (the partition's not asked where the user's
/// chart's is not below).
pub fn passive_sigma_below_with(inputs_sys: &mut System, mech: &Mechanism, x: &[f64], t: f64) -> bool {
    if mech.n_constraints == 0 {
        return false;
    }
    sigma_min_below_with(inputs_sys, mech, &Chart::Inputs, x, t) && partition_sigma_below_with(inputs_sys, mech, x, t)
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

/// Whether [`partition_sigma_min_with`] is below `t` (> 0): the same answer, most often without
/// the blocks' SVDs ([`sigma_min_below_with`]).
pub fn partition_sigma_below_with(inputs_sys: &mut System, mech: &Mechanism, x: &[f64], t: f64) -> bool {
    if mech.n_constraints == 0 {
        return false;
    }
    let partition = Chart::Partition(select_partition(mech, x));
    sigma_min_below_with(inputs_sys.other_chart(mech, &partition), mech, &partition, x, t)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::phi_pivots::tests::a02_folded;

    /// `sigma_min_below_with` gives `sigma_min_with(..) < t` (the same answer) for the user's
    /// chart and the partition `select_partition` chooses, at thresholds from half to twice the
    /// exact measure and within 1e-13 of it either side (where the Cholesky tests cannot decide
    /// and the block's SVD does), at the drawings and 40 moved configurations of four models,
    /// and at A02's change point (measure at round-off: thresholds at its own size, where the
    /// band is wide, and the monitors' 1e-6); thresholds that are 0, negative or NaN are never
    /// above a measure.
    #[test]
    fn below_is_the_exact_measures_comparison() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/models/");
        let mut cases: Vec<(Mechanism, Vec<f64>)> = Vec::new();
        for file in ["five-bar-free-fall", "3-rrr", "andrews-squeezer", "slider-crank"] {
            let mech = crate::load(format!("{root}{file}.yaml")).expect(file);
            for k in 0..=40 {
                let size = 0.01 * f64::from(k);
                let x: Vec<f64> = mech.x0.iter().map(|v| v + size * next()).collect();
                cases.push((mech.clone(), x));
            }
        }
        cases.push(a02_folded());
        let (mut decided, mut least) = (0, f64::INFINITY);
        for (mech, x) in &cases {
            for chart in [Chart::Inputs, Chart::Partition(select_partition(mech, x))] {
                let mut sys = System::for_chart(mech, &chart);
                let exact = sigma_min_with(&mut sys, mech, &chart, x);
                least = least.min(exact);
                let ratios = [0.5, 0.9, 1.0 - 1e-13, 1.0, 1.0 + 1e-13, 1.1, 2.0];
                let thresholds = ratios.map(|ratio| ratio * exact);
                for t in thresholds.into_iter().chain([1e-6, 0.0, -1.0, f64::NAN]) {
                    let below = sigma_min_below_with(&mut sys, mech, &chart, x, t);
                    assert_eq!(below, exact < t, "{} {chart:?}: {exact} against {t}", mech.name);
                    decided += 1;
                }
            }
        }
        assert!(decided == 3630 && least < 1e-12, "{decided} decisions, least measure {least}");
    }
}
