//! A run's settings as the caller finally gives them, and the messages about them: the model
//! file's output grid is built only for the run's own t_end, a fixed step that cannot reach
//! t_end within max_steps is refused before the first step, and times print short (found by
//! the s15 sweep, notes/s15-sweep.md F3, F4 and its defect 4).

mod common;
use common::*;
use planardyn::dynamics::{ModelDrives, Prescribed};
use planardyn::error::{Setting, Time};
use planardyn::simulate::{simulate, simulate_observed, Observe, Overrides, Settings};

/// A model file at the output limit (1e8 times) or, built in Rust, past it: a caller's
/// `t_end=0.05` gets the 0.05 s run's 6 outputs, not the file's grid (which aborted the
/// process past the limit, and took 800 MB at it, before the caller's t_end replaced it).
#[test]
fn the_file_output_grid_is_built_for_the_callers_t_end_only() {
    let mut mech = shipped("five-bar.yaml");
    mech.simulate.t_end = Some(1e31);
    mech.simulate.output_dt = Some(0.01);
    let s = Overrides { t_end: Some(0.05), ..Default::default() }.settings(&mech).unwrap();
    assert_eq!(s.t_eval.as_deref(), Some(&[0.0, 0.01, 0.02, 0.03, 0.04, 0.05][..]));
    // The file's own settings name the output_dt that cannot fit.
    let e = Settings::for_model(&mech).unwrap_err();
    assert!(matches!(&e, planardyn::Error::Setting(s) if s.setting == Setting::OutputDt), "{e:?}");
}

/// `--dt 1e-300` ran 10,000 steps and then blamed the efforts; t_end / dt is known up front.
#[test]
fn a_fixed_step_that_cannot_reach_t_end_is_refused_naming_dt() {
    let mech = shipped("five-bar.yaml");
    for method in ["rk4", "dopri5"] {
        let o = Overrides { t_end: Some(0.05), method: Some(method.into()), dt: Some(1e-300), ..Default::default() };
        let e = o.settings(&mech).unwrap_err();
        assert!(matches!(&e, planardyn::Error::Setting(s) if s.setting == Setting::Dt), "{e:?}");
        let m = e.to_string();
        for part in ["dt = 1e-300", "5.000e298 steps", "t_end = 0.05 s", "max_steps = 10000", "use a larger dt"] {
            assert!(m.contains(part), "{part:?} not in {m}");
        }
        // Exactly max_steps steps is allowed: 0.05 s / 5e-6 s = 10,000.
        let o = Overrides { dt: Some(5e-6), ..o };
        assert!(o.settings(&mech).is_ok());
    }
}

/// Shortest round-trip decimals, in scientific notation for huge and tiny times.
#[test]
fn times_print_short_and_read_back_exactly() {
    for (t, text) in [
        (1e300, "1e300"),
        (-1e-300, "-1e-300"),
        (0.05, "0.05"),
        (1.0, "1"),
        (0.0, "0"),
        (123456.789, "123456.789"),
        (1e16, "1e16"),
        (1.5e-5, "0.000015"),
        (1e-6, "1e-6"),
        (0.1 + 0.2, "0.30000000000000004"),
    ] {
        let s = Time(t).to_string();
        assert_eq!(s, text);
        assert_eq!(s.parse::<f64>().unwrap().to_bits(), t.to_bits(), "{s}");
    }
}

/// The messages of a run's end and of its dense output carry a huge or tiny time in a few
/// characters (t_end = 1e300 printed 301 digits, sol(-1e-300) 300 zeros).
#[test]
fn messages_print_extreme_times_short() {
    let mech = shipped("five-bar.yaml");
    let mut s = Overrides { t_end: Some(0.01), ..Default::default() }.settings(&mech).unwrap();
    let observe = Observe { dense_output: true, ..Default::default() };
    let mut drives = ModelDrives(&mech);
    let mut motion = Prescribed::from_model(&mech);
    let tr = simulate_observed(&mech, &s, &mut drives, &mut motion, observe, None).unwrap();
    let (mut q, mut qd) = (vec![0.0; 2], vec![0.0; 2]);
    let m = tr.dense.as_ref().unwrap().eval(-1e-300, &mut q, &mut qd).unwrap_err();
    assert!(m.starts_with("t = -1e-300 s is outside the run [0, 0.01"), "{m}");
    // t_end = 1e300 s: the run cannot make progress, and says so with t_end in 5 characters.
    s.t_end = 1e300;
    s.t_eval = None;
    let tr = simulate(&mech, &s, &mut ModelDrives(&mech), None).unwrap();
    assert!(tr.message.contains("to t_end = 1e300 s within"), "{}", tr.message);
    assert!(tr.message.len() < 600, "{} characters: {}", tr.message.len(), tr.message);
}
