//! Every figure holds: a run's energy drift follows its tolerance, with no isolated tolerance
//! far worse than its neighbours. DOP853's combined error estimate is not an error bound for a
//! step that reaches beyond the solution's radius of convergence (`integrate::dop853::REACH_E3`).
//!
//! The cases are the worst such outliers of a sweep of rtol = atol = 10^(-k/20), k = 20..200,
//! 1 s, DOP853 (benchmarks/drift_outliers.py: drift over 10x the geometric mean of the runs at
//! k - 1 and k + 1), before the bound (d231ebd), drift in J at k - 1, k, k + 1:
//! - Scotch yoke k = 119 (1.122e-6): 4.06e-5, **6.19e-3**, 1.64e-5 (240x);
//! - four-bar with gravity k = 83 (7.08e-5): 1.24e-4, **1.19e-2**, 5.65e-5 (142x), one step of
//!   0.097 s (0.192 -> 0.288 s) gains 1.19e-2 J;
//! - hydraulic boom k = 89 (3.55e-5): 9.87e-6, **0.129**, 1.98e-6 (29175x), 9 steps in 1 s.
//!
//! With the reach bound: 1.51e-5, 1.28e-5, 6.02e-6; 7.13e-6, 3.51e-6, 3.51e-6; 4.02e-5,
//! 1.32e-5, 2.23e-5.

use planardyn::dynamics::ModelDrives;
use planardyn::simulate::{simulate, Overrides};

/// The outlier test of the sweep: a drift over this many times the geometric mean of its two
/// neighbours' is an outlier (benchmarks/drift_outliers.py's default).
const OUTLIER: f64 = 10.0;

fn drift(model: &str, k: i32) -> f64 {
    let path = format!("{}/../../examples/models/{model}", env!("CARGO_MANIFEST_DIR"));
    let mech = planardyn::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let tol = 10f64.powf(-k as f64 / 20.0);
    let over = Overrides {
        t_end: Some(1.0),
        method: Some("dop853".into()),
        rtol: Some(tol),
        atol: Some(tol),
        ..Overrides::default()
    };
    let traj = simulate(&mech, &over.settings(&mech).unwrap(), &mut ModelDrives(&mech), None).unwrap();
    assert!(traj.success(), "{model} k = {k}: {}", traj.message);
    traj.stats.energy_drift
}

#[test]
fn dop853_drift_at_the_sweeps_worst_tolerances_is_within_10x_of_its_neighbours() {
    for (model, k) in [("scotch-yoke.yaml", 119), ("four-bar-gravity.yaml", 83), ("hydraulic-boom.yaml", 89)] {
        let [before, at, after] = [k - 1, k, k + 1].map(|k| drift(model, k));
        let ratio = at / (before * after).sqrt();
        assert!(
            ratio < OUTLIER,
            "{model} k = {k}: drift {at:.3e} J against {before:.3e} and {after:.3e} J at k -+ 1 ({ratio:.0}x)"
        );
    }
}
