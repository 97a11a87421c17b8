//! The first step after a reset: bounded by the system where it asks (a chart switch), and what
//! that saves on the benchmark runs (benchmarks/mechanisms.py: the five-bar's fall, the 3-RRR).

mod common;
use common::*;
use planardyn::integrate::{Method, Options, Stepper};
use planardyn::simulate::{grid, simulate, Settings, Trajectory};
use planardyn::Mechanism;

/// The length of the first step of `method` from y = (1, 0) at rtol = atol = 1e-6, with the
/// system's bound `h_max` on it (None: no bound), after a first reset that was bounded at 1e-9
/// (a reset forgets that bound).
fn first_step(method: Method, h_max: Option<f64>) -> f64 {
    let mut stepper = Stepper::new(method, &Options::tol(1e-6, 1e-6), 2).unwrap();
    stepper.reset(&mut Oscillator, 0.0, &[1.0, 0.0]).unwrap();
    stepper.bound_first_step(1e-9);
    stepper.reset(&mut Oscillator, 0.0, &[1.0, 0.0]).unwrap();
    if let Some(h) = h_max {
        stepper.bound_first_step(h);
    }
    stepper.step(&mut Oscillator, 10.0).unwrap();
    stepper.t() - stepper.t_prev()
}

/// The bound caps the automatic first step (the starting-step rule's guess is accepted on the
/// oscillator, so the step taken is the guess), and a reset clears it.
#[test]
fn the_first_step_is_within_the_systems_bound() {
    for method in [Method::Dop853, Method::Dopri5, Method::Radau5] {
        let free = first_step(method, None);
        // 1e-3 s is well below the rule's guess here (0.01-0.1 s; checked below), so the bound decides.
        assert!(free > 1e-2, "{method}: unbounded first step {free} s");
        let bounded = first_step(method, Some(1e-3));
        assert_eq!(bounded, 1e-3, "{method}: bounded first step");
    }
}

/// The five-bar's fall (1 s, DOP853, rtol = atol), every accepted step or a 0.01 s grid.
fn fall(rtol: f64, every: Option<f64>) -> Trajectory {
    run_with(&shipped("five-bar-free-fall.yaml"), "dop853", 1.0, rtol, every)
}

fn run_with(mech: &Mechanism, method: &str, t_end: f64, rtol: f64, every: Option<f64>) -> Trajectory {
    let mut s = Settings::for_model(mech).unwrap();
    s.method = method.parse().unwrap();
    (s.t_end, s.options.rtol, s.options.atol) = (t_end, rtol, rtol);
    s.t_eval = every.map(|h| {
        let mut t = grid(s.t0, s.t_end, h);
        t.iter_mut().for_each(|v| *v = v.min(s.t_end));
        t.dedup();
        t
    });
    let tr = simulate(mech, &s, &mut planardyn::dynamics::ModelDrives(mech), None).unwrap();
    assert!(tr.success(), "{:?} {}", tr.status, tr.message);
    tr
}

/// At rtol 1e-6 the fall switches chart 11 times. Before the first step after a switch was
/// bounded (main 018029d) the starting guess there was rejected 2-3 times at 8 of them: 28
/// rejected steps in the run (1152 evaluations counted); bounded, 12 (1106). 14 leaves room
/// for one more switch's pair of rejections, not for the guess's.
#[test]
fn five_bar_first_steps_after_chart_switches_are_not_rejected() {
    let tr = fall(1e-6, None);
    assert_eq!(tr.stats.chart_switches, 11);
    let rejected = tr.stats.integrator.nreject;
    assert!(rejected <= 14, "{rejected} rejected steps (28 with the starting guess after each switch)");
}

/// The 3-RRR of the benchmark (examples/models/3-rrr.yaml without the time-table drive on th2,
/// as benchmarks/mechanisms.py's override), 0.8 s, DOP853 at rtol = atol = 1e-5, outputs every
/// 0.04 s: a step with outputs costs its 3 dense stages more than the every-step run's, no
/// more. Before (main 018029d) the outputs inside the first step (0 -> 0.131 s: 0.04, 0.08,
/// 0.12 s) were each a step of their own from its start (11 evaluations): 180 evaluations
/// against 123 + 3 x 9 = 150; now 147.
#[test]
fn three_rrr_outputs_cost_only_the_dense_stages() {
    let text =
        std::fs::read_to_string(format!("{}/../../examples/models/3-rrr.yaml", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let kept: Vec<&str> = text.lines().filter(|l| !l.contains("table:")).collect();
    let mech = yaml(&kept.join("\n"));
    let outputs = run_with(&mech, "dop853", 0.8, 1e-5, Some(0.04));
    let steps = run_with(&mech, "dop853", 0.8, 1e-5, None);
    assert_eq!(outputs.stats.integrator.naccept, steps.stats.integrator.naccept);
    let bound = steps.stats.integrator.nfev + 3 * steps.stats.integrator.naccept;
    let nfev = outputs.stats.integrator.nfev;
    assert!(nfev <= bound, "{nfev} evaluations with the grid > {bound} (every step's + 3 dense stages a step)");
}
