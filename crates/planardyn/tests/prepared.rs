//! The prepared model (`simulate::Prepared`): runs that share one equal, to the bit, runs that
//! each make their own set-up, whatever ran from it before; a prepared model of another
//! mechanism is refused.

mod common;
use common::*;
use planardyn::dynamics::{ModelDrives, Prescribed};
use planardyn::simulate::{grid, simulate, simulate_prepared, Observe, Prepared, Settings, Trajectory};
use planardyn::{Error, Mechanism};

/// Every output array and counter of two runs, compared exactly (bit for bit: `==` on f64,
/// and no NaN in a successful run's rows).
fn same(a: &Trajectory, b: &Trajectory, what: &str) {
    let rows = |t: &Trajectory| {
        [&t.t, &t.q, &t.qd, &t.qdd, &t.tau, &t.x, &t.xd, &t.kinetic, &t.potential, &t.work, &t.sigma, &t.residual]
            .map(|v| v.clone())
    };
    assert_eq!(rows(a), rows(b), "{what}: rows differ");
    assert_eq!(a.partitioned, b.partitioned, "{what}");
    assert_eq!((a.status, &a.message), (b.status, &b.message), "{what}");
    let counters = |t: &Trajectory| {
        let s = &t.stats;
        (s.integrator.nfev, s.integrator.naccept, s.integrator.nreject, s.chart_switches, s.failed_evaluations)
    };
    assert_eq!(counters(a), counters(b), "{what}");
    assert_eq!(a.stats.energy_drift.to_bits(), b.stats.energy_drift.to_bits(), "{what}");
}

/// The model's settings over `t_end`, an output every 10 ms, starting at `q0` if given.
fn settings(mech: &Mechanism, t_end: f64, q0: Option<Vec<f64>>) -> Settings {
    Settings { t_end, q0, t_eval: Some(grid(0.0, t_end, 0.01)), ..Settings::for_model(mech).unwrap() }
}

fn run_prepared(mech: &Mechanism, prepared: &Prepared, s: &Settings) -> Result<Trajectory, Error> {
    let mut motion = Prescribed::from_model(mech);
    simulate_prepared(mech, prepared, s, &mut ModelDrives(mech), &mut motion, Observe::default(), None)
}

#[test]
fn runs_from_one_prepared_model_equal_runs_that_prepare_their_own() {
    // The shipped models with closed forms (four-bar, 3-RRR), chart switches near type II
    // singularities (the five-bar's free fall), prismatic pairs and gears, and the inline ones.
    for mech in every_model() {
        let prepared = Prepared::new(&mech);
        let (q_test, _) = test_state(&mech);
        // A run from another state first (one that cannot start changes nothing): what it
        // changed must not reach the next runs.
        let _other = run_prepared(&mech, &prepared, &settings(&mech, 0.05, Some(q_test)));
        let s = settings(&mech, 0.2, None);
        let own = simulate(&mech, &s, &mut ModelDrives(&mech), None).unwrap();
        let shared = run_prepared(&mech, &prepared, &s).unwrap();
        assert!(own.len() > 1, "{}: {}", mech.name, own.message);
        same(&own, &shared, &mech.name);
    }
}

#[test]
fn a_prepared_model_of_another_mechanism_is_refused() {
    let (four_bar, five_bar) = (yaml(FOUR_BAR), shipped("five-bar.yaml"));
    let prepared = Prepared::new(&five_bar);
    let s = settings(&four_bar, 0.01, None);
    let mut motion = Prescribed::from_model(&four_bar);
    let e =
        simulate_prepared(&four_bar, &prepared, &s, &mut ModelDrives(&four_bar), &mut motion, Observe::default(), None)
            .unwrap_err();
    assert!(matches!(&e, Error::Options(m) if m.contains("another mechanism")), "{e}");
}
