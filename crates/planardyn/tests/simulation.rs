//! Whole simulations checked without outside software: energy balance of the benchmark
//! mechanisms (figures from tests/data/benchmarks, see tests/data/PROVENANCE.md), a published
//! reference solution (Andrews' squeezer), the exact pendulum period, and invariance to the
//! frame of the drawing.

mod common;
use common::*;

fn energy(tr: &planardyn::simulate::Trajectory, k: usize) -> f64 {
    tr.kinetic[k] + tr.potential[k] - tr.work[k]
}

#[test]
fn passive_four_bar_keeps_its_energy_for_10_s() {
    let mech = shipped("four-bar-gravity.yaml");
    let tr = run(&mech, "dop853", 10.0, 1e-11, None);
    // Total energy from the benchmark file: 13.770736975732 J (T = 0 at release).
    assert!((energy(&tr, 0) - 13.770736975732).abs() < 1e-9, "E0 = {}", energy(&tr, 0));
    // Minimal coordinates: no constraint drift; the energy error is the integrator's alone.
    assert!(tr.stats.energy_drift < 1e-7, "energy drift {} J", tr.stats.energy_drift);
    assert!(tr.stats.max_residual < 1e-11, "loop closure {}", tr.stats.max_residual);
    // "The crank swings between +60 deg and about -232.7 deg" (benchmark file).
    let (lo, hi) = tr.q.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    assert!((hi.to_degrees() - 60.0).abs() < 1e-6, "max {}", hi.to_degrees());
    assert!((lo.to_degrees() + 232.7).abs() < 0.05, "min {}", lo.to_degrees());
}

#[test]
fn andrews_squeezer_matches_the_ivp_test_set_reference() {
    let mech = shipped("andrews-squeezer.yaml");
    let tr = run(&mech, "dop853", 0.03, 1e-12, None);
    let n = tr.len() - 1;
    // Energy balance T + V_spring - 0.033 (beta - beta0): "about 1.43580 J" (benchmark file).
    assert!((energy(&tr, 0) - 1.43580).abs() < 5e-6, "E0 = {}", energy(&tr, 0));
    assert!(tr.stats.energy_drift < 1e-9, "energy drift {} J", tr.stats.energy_drift);
    // beta(0.03 s) of the reference solution of the 'andrews' problem, Test Set for IVP
    // Solvers (Mazzia & Magherini, release 2.4), computed there with RADAU5 at tol 1e-14.
    let beta = tr.q[n];
    assert!((beta - 15.81077119629904).abs() < 1e-6, "beta(0.03) = {beta}");
}

#[test]
fn five_bar_free_fall_crosses_type_ii_singularities_with_its_energy() {
    let mech = shipped("five-bar-free-fall.yaml");
    let tr = run(&mech, "dop853", 5.0, 1e-11, None);
    // Total energy from the benchmark file: 1.874338473780 J.
    assert!((energy(&tr, 0) - 1.874338473780).abs() < 1e-9, "E0 = {}", energy(&tr, 0));
    assert!(tr.stats.energy_drift < 1e-6, "energy drift {} J", tr.stats.energy_drift);
    // Distal links collinear "first near t = 0.17 s": the integrator must have left the
    // actuated coordinates there, and come back.
    assert!(tr.stats.chart_switches >= 2, "switches {}", tr.stats.chart_switches);
    assert!(tr.stats.min_sigma < 0.05, "min sigma {}", tr.stats.min_sigma);
    let first = tr.t.iter().zip(&tr.partitioned).find(|(_, &p)| p).map(|(t, _)| *t).unwrap();
    assert!((0.1..0.2).contains(&first), "first partition at {first} s");
}

#[test]
fn pendulum_period_at_large_amplitude_is_exact() {
    // Physical pendulum released from rest at 1 rad from the vertical: period
    // 4 sqrt(I_O / (m g l)) K(sin(theta0/2)) (exact, Landau & Lifshitz sec. 11).
    let text = PENDULUM
        .replace("{name: theta, pair: O, value: 0.0}", "{name: theta, pair: O, value: 0.0, q0: -0.5707963267948966}");
    let mech = yaml(&text);
    let (m, l, g) = (2.0_f64, 0.8_f64, 9.81_f64);
    let omega = (m * g * (l / 2.0) / (m * l * l / 3.0)).sqrt();
    let k = (0.5_f64).sin();
    let period = 4.0 / omega * std::f64::consts::PI / (2.0 * agm(1.0, (1.0 - k * k).sqrt()));
    let tr = run(&mech, "dop853", period, 1e-12, Some(vec![0.0, period / 2.0, period]));
    assert!((tr.q[2] - tr.q[0]).abs() < 1e-8, "q(T) - q0 = {}", tr.q[2] - tr.q[0]);
    assert!(tr.qd[2].abs() < 1e-8, "qd(T) = {}", tr.qd[2]);
    // Half a period later it is at the other extreme, -pi/2 - 1.
    assert!((tr.q[1] + std::f64::consts::FRAC_PI_2 + 1.0).abs() < 1e-8, "q(T/2) = {}", tr.q[1]);
}

/// The four-bar drawn in another frame: points rotated by `a` and shifted, gravity rotated
/// with them, the crank's stated angle increased by `a`.
fn four_bar_in_frame(a: f64, shift: [f64; 2]) -> planardyn::Mechanism {
    let mut spec = shipped("four-bar-gravity.yaml").spec;
    let (c, s) = (a.cos(), a.sin());
    let tf = |p: [f64; 2]| [c * p[0] - s * p[1] + shift[0], s * p[0] + c * p[1] + shift[1]];
    for p in spec.points.0.values_mut() {
        *p = tf(*p);
    }
    for b in spec.bodies.0.values_mut() {
        if let Some(planardyn::model::spec::Location::Coords(x)) = &mut b.com {
            *x = tf(*x);
        }
    }
    let g = spec.gravity;
    spec.gravity = [c * g[0] - s * g[1], s * g[0] + c * g[1]];
    spec.coordinates[0].value += a;
    planardyn::build(spec, "<rotated>").unwrap()
}

#[test]
fn motion_does_not_depend_on_the_frame_of_the_drawing() {
    let times: Vec<f64> = (0..=20).map(|k| 0.1 * k as f64).collect();
    let base = run(&four_bar_in_frame(0.0, [0.0, 0.0]), "dop853", 2.0, 1e-11, Some(times.clone()));
    let a = 0.7;
    let moved = run(&four_bar_in_frame(a, [3.0, -1.5]), "dop853", 2.0, 1e-11, Some(times));
    for k in 0..base.len() {
        // Same physics up to the integrator's tolerance (rtol 1e-11 over 2 s).
        assert!((moved.q[k] - a - base.q[k]).abs() < 1e-8, "t = {}: {} vs {}", base.t[k], moved.q[k] - a, base.q[k]);
    }
}

#[test]
fn every_method_gives_the_same_motion() {
    let mech = shipped("four-bar-gravity.yaml");
    let reference = run(&mech, "dop853", 1.0, 1e-12, Some(vec![1.0]));
    for (method, rtol, tol) in [("dopri5", 1e-11, 1e-8), ("radau5", 1e-10, 1e-7)] {
        let tr = run(&mech, method, 1.0, rtol, Some(vec![1.0]));
        assert!((tr.q[0] - reference.q[0]).abs() < tol, "{method}: {} vs {}", tr.q[0], reference.q[0]);
    }
    let mut s = planardyn::simulate::Settings::for_model(&mech).unwrap();
    s.method = planardyn::integrate::Method::Rk4;
    s.options.dt = Some(1e-3);
    s.t_end = 1.0;
    s.t_eval = Some(vec![1.0]);
    let tr = planardyn::simulate::simulate(&mech, &s, &mut planardyn::dynamics::ModelDrives(&mech), None).unwrap();
    // RK4 at dt = 1 ms: global error ~ C dt^4, about 1e-9 here.
    assert!((tr.q[0] - reference.q[0]).abs() < 1e-7, "rk4: {} vs {}", tr.q[0], reference.q[0]);
}

/// DOPRI5 at loose tolerance once followed the five-bar onto its other assembly branch near
/// the type II singularity at t ~ 0.53 s (a Newton start extrapolated past the fold): -1.8 J
/// of 1.87 J in one step; with outputs on a grid the run stopped with assembly_failed. The
/// local error is 1e-4 relative per step here, on O(1 J) energies, over ~100 steps: a drift
/// of a few 1e-3 J is the method's; anything near 1e-2 J or more is a branch jump.
#[test]
fn five_bar_stays_on_its_branch_at_loose_tolerance() {
    let mech = shipped("five-bar-free-fall.yaml");
    for (rtol, grid) in [(1e-6, false), (1e-4, false), (1e-4, true)] {
        let mut s = planardyn::simulate::Settings::for_model(&mech).unwrap();
        s.method = "dopri5".parse().unwrap();
        s.t_end = 1.0;
        s.options.rtol = rtol;
        s.options.atol = 1e-6;
        s.t_eval = grid.then(|| planardyn::simulate::grid(0.0, 1.0, 0.01));
        let tr = planardyn::simulate::simulate(&mech, &s, &mut planardyn::dynamics::ModelDrives(&mech), None).unwrap();
        assert!(tr.success(), "rtol {rtol} grid {grid}: {:?} {}", tr.status, tr.message);
        assert!(tr.stats.energy_drift < 1e-2, "rtol {rtol} grid {grid}: energy drift {} J", tr.stats.energy_drift);
    }
}

/// Constant efforts on every coordinate, ignoring the model's drives.
struct Constant(f64);

impl planardyn::dynamics::Drives for Constant {
    fn efforts(&mut self, _t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.fill(self.0);
        Ok(())
    }
}

#[test]
fn hopeless_run_stops_early_and_keeps_its_last_state() {
    use planardyn::simulate::{grid, simulate, Settings, Status};
    let mech = shipped("five-bar.yaml");
    let mut s = Settings::for_model(&mech).unwrap();
    s.t_end = 1.0;
    s.t_eval = Some(grid(0.0, 1.0, 0.01));
    let tr = simulate(&mech, &s, &mut Constant(1e12), None).unwrap();
    assert_eq!(tr.status, Status::StepSizeTooSmall, "{}", tr.message);
    assert!(tr.message.contains("efforts or rates are too large"), "{}", tr.message);
    // Judged at the first accepted step past 10,000 attempts (mean step ~1e-9 s, below
    // 1 s / (10 * 1e7)), where it ran into the budget of 1e7 attempts (293 s) before.
    let st = tr.stats.integrator;
    let attempts = st.naccept + st.nreject;
    assert!((10_000..10_100).contains(&attempts), "{attempts} attempts");
    // The file's DOPRI5 (FSAL): 6 evaluations per attempt, 2 more at each (re)start.
    let starts = 1 + tr.stats.chart_switches;
    assert!(st.nfev <= 6 * attempts + 2 * starts, "{} evaluations", st.nfev);
    // The 0.01 s grid is not reached: the rows are t = 0 and the last accepted state.
    assert_eq!(tr.len(), 2);
    let (t, n) = (tr.t[1], tr.len() - 1);
    assert!(t > 0.0 && t < 1e-8 * attempts as f64, "last t = {t}");
    assert!(tr.q[2 * n..].iter().chain(&tr.qd[2 * n..]).all(|v| v.is_finite()));
    // The energy balance of that row is the one reported, a small fraction of the work done
    // for the file's rtol 1e-8 over 1e4 steps (measured: 1.1e-6 of 6.8e13 J).
    let drift = (energy(&tr, n) - energy(&tr, 0)).abs();
    assert_eq!(tr.stats.energy_drift, drift);
    assert!(tr.work[n] > 1e12 && drift < 1e-5 * tr.work[n], "drift {drift} J, work {} J", tr.work[n]);
}

/// atol = 0 gave "NaN or infinity in the solution" when the five-bar's W (or a rate at rest)
/// passed through 0; it is refused up front, naming the option, as the loader refuses it.
#[test]
fn zero_atol_is_refused_before_the_run() {
    let mech = shipped("five-bar.yaml");
    let mut s = planardyn::simulate::Settings::for_model(&mech).unwrap();
    s.options.atol = 0.0;
    let e = planardyn::simulate::simulate(&mech, &s, &mut planardyn::dynamics::ModelDrives(&mech), None).unwrap_err();
    assert!(matches!(&e, planardyn::Error::Setting(s) if s.setting == planardyn::error::Setting::Atol), "{e:?}");
    assert!(e.to_string().contains("atol = 0 must be a finite number > 0"), "{e}");
}
