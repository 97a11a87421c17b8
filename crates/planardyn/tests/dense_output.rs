//! Outputs interpolated inside a step that passes a type II singularity of the user's chart
//! between its stages, or inside the first step after a chart switch: as accurate as the
//! steps, and on the step's assembly branch.

mod common;
use common::*;
use planardyn::simulate::{grid, simulate, Settings, Trajectory};

/// rtol = atol = 10^-6.9: at this setting DOP853's step 0.6152 -> 0.6270 s of the five-bar's
/// fall, in the user's chart, passes the type II singularity where the cranks' ends C1, C2
/// meet (C1x - C2x from -59 to +14.6 mm), and its dense stage at 7/9 of the step falls right
/// there (-0.6 mm).
/// Before the fix (commit 0c75a35) that stage's qdd was (-116.9, 96.6) rad/s^2 where the path
/// has (-107, 107), and the output at t = 0.62 s was 5.8e-5 J and 2.35e-2 rad/s off (below).
const RTOL: f64 = 1.2589254117941673e-7;

/// The benchmark's run (benchmarks/mechanisms.py): 1 s, DOP853, rtol = atol, outputs every
/// 0.01 s or (None) at every step.
fn fall(every: Option<f64>, rtol: f64) -> Trajectory {
    fall_stepping(every, rtol).0
}

/// [`fall`], with the times of its accepted steps (from the progress callback).
fn fall_stepping(every: Option<f64>, rtol: f64) -> (Trajectory, Vec<f64>) {
    let mech = shipped("five-bar-free-fall.yaml");
    let mut s = Settings::for_model(&mech).unwrap();
    s.method = "dop853".parse().unwrap();
    (s.t_end, s.options.rtol, s.options.atol) = (1.0, rtol, rtol);
    s.t_eval = every.map(|h| {
        let mut t = grid(s.t0, s.t_end, h);
        t.iter_mut().for_each(|v| *v = v.min(s.t_end));
        t.dedup();
        t
    });
    let mut steps = Vec::new();
    let mut progress = |t: f64| {
        steps.push(t);
        true
    };
    let tr = simulate(&mech, &s, &mut planardyn::dynamics::ModelDrives(&mech), Some(&mut progress)).unwrap();
    assert!(tr.success(), "{:?} {}", tr.status, tr.message);
    (tr, steps)
}

/// Largest |qd1 + qd2| (rad/s) up to 0.7 s: the fall is symmetric about the y axis (the
/// point mass sits on the joint P, on the axis), so theta1 + theta2 = pi and qd1 = -qd2 along
/// the exact motion; past 0.7 s the motion amplifies the integration error's asymmetry.
fn asymmetry(tr: &Trajectory) -> f64 {
    (0..tr.len()).filter(|&k| tr.t[k] <= 0.7).map(|k| (tr.qd[2 * k] + tr.qd[2 * k + 1]).abs()).fold(0.0, f64::max)
}

/// The outputs may be up to twice as far off as the steps: the interpolant is of order 7
/// where the steps are of order 8, and the grid's times are not the steps'. Measured: grid
/// 4.63e-7 J and 1.71e-4 rad/s, steps 4.58e-7 J and 1.82e-4 rad/s (before the fix: 5.76e-5 J,
/// 2.35e-2 rad/s at t = 0.62 s).
const OUTPUT_MARGIN: f64 = 2.0;

#[test]
fn five_bar_outputs_are_as_accurate_as_its_steps_past_a_singularity_between_stages() {
    let (outputs, steps) = (fall(Some(0.01), RTOL), fall(None, RTOL));
    assert_eq!(outputs.len(), 101);
    let (drift, bound) = (outputs.stats.energy_drift, OUTPUT_MARGIN * steps.stats.energy_drift);
    assert!(drift <= bound, "outputs' energy drift {drift:e} J > {bound:e} J (twice the steps')");
    let (asym, bound) = (asymmetry(&outputs), OUTPUT_MARGIN * asymmetry(&steps));
    assert!(asym <= bound, "outputs' |qd1 + qd2| {asym:e} rad/s > {bound:e} rad/s (twice the steps')");
}

/// rtol = atol = 3.98e-8 (the sweep's 10^-7.4 rounded to 3 digits, as benchmarks/output_rows.py
/// prints it; at 10^-7.4 itself the grid run's steps differed from the every-step run's until
/// the step's end was set aside from the outputs, see [`TRAJECTORY_RTOLS`]): DOP853's first step after the five-bar's chart switch back to the
/// user's chart at 0.3371 s is 0.0473 s long (the starting guess's size; the steps before it
/// in the partition were 8-13 ms) and passes the error test, its end 1.2e-7 J off the start's
/// energy. Its degree-7 interpolant is of one order less than the step and its error is not
/// estimated: before the fix (commit 2d36019) the rows at 0.34-0.38 s were up to 3.3e-6 J off
/// (at 0.36 s) where the steps were at most 1.3e-7 J; after it 1.30e-7 J, the steps'.
const FIRST_STEP_RTOL: f64 = 3.98e-8;

#[test]
fn five_bar_outputs_are_as_accurate_as_its_steps_in_the_first_step_after_a_chart_switch() {
    let (outputs, steps) = (fall(Some(0.01), FIRST_STEP_RTOL), fall(None, FIRST_STEP_RTOL));
    let (drift, bound) = (outputs.stats.energy_drift, OUTPUT_MARGIN * steps.stats.energy_drift);
    assert!(drift <= bound, "outputs' energy drift {drift:e} J > {bound:e} J (twice the steps')");
}

/// Settings of benchmarks/output_rows.py's sweep at which the outputs changed the five-bar's
/// integration before the step's end was set aside from them (commit 522dfe5): the grid run's
/// accepted step times differed from the every-step run's at all four. At 10^-7.4 exactly the
/// grid run took 102 steps (22 in a partition chart) where the every-step run took 101 (20),
/// and its rows were 6.9e-7 J off where the steps were 1.3e-7 J.
const TRAJECTORY_RTOLS: [f64; 4] = [3.981071705534973e-8, 1e-6, 1e-8, 1e-4];

/// The outputs leave the integration alone: the grid run takes the every-step run's steps,
/// to the bit (the outputs are evaluated aside from the step's end, which the next step starts
/// from; `MechanismOde::set_aside`), in the same charts.
#[test]
fn five_bar_outputs_do_not_change_the_steps() {
    for rtol in TRAJECTORY_RTOLS {
        let ((outputs, grid_steps), (steps, every_steps)) =
            (fall_stepping(Some(0.01), rtol), fall_stepping(None, rtol));
        assert_eq!(grid_steps, every_steps, "rtol {rtol:e}: accepted step times with and without the grid");
        assert_eq!(outputs.stats.partition_steps, steps.stats.partition_steps, "rtol {rtol:e}: partition steps");
    }
}

/// Settings of benchmarks/output_rows.py's sweep at which the rows were more than twice the
/// steps' energy error after the fixes above (main 018029d): 2.32x at 1e-6 (rows 3.30e-6 J,
/// steps 1.43e-6 J), 2.89x at 1e-4 (4.37e-4 J, 1.51e-4 J). Both were the steps around the
/// chart switches, which the starting guess made long or rejected (`charts::FIRST_STEP_MOVE`):
/// with the first step after a switch bounded, 1.00x and 1.20x.
const SWITCH_RTOLS: [f64; 2] = [1e-6, 1e-4];

#[test]
fn five_bar_outputs_are_as_accurate_as_its_steps_around_chart_switches() {
    for rtol in SWITCH_RTOLS {
        let (outputs, steps) = (fall(Some(0.01), rtol), fall(None, rtol));
        let (drift, bound) = (outputs.stats.energy_drift, OUTPUT_MARGIN * steps.stats.energy_drift);
        assert!(drift <= bound, "rtol {rtol:e}: outputs' energy drift {drift:e} J > {bound:e} J (twice the steps')");
    }
}
