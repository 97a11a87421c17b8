//! Forward simulation: the whole loop in Rust. Integrates y = [z, zd, W] in the best chart,
//! writes outputs in the user's coordinates, and on any failure returns the trajectory
//! computed so far with a status saying why it stopped.

pub mod charts;
pub mod crossing;
pub mod dense;
pub mod events;
mod jacobian;
pub mod ode;
mod overrides;
pub mod trajectory;

pub use dense::DenseOutput;
pub use events::{Event, EventFn, EventRecords, EVENT_XTOL};
pub use overrides::Overrides;
pub use trajectory::{SimStats, Status, Trajectory};

use crate::dynamics::{prescribed_sigma_min, Drives, Prescribed};
use crate::integrate::{Method, Options, StepError, Stepper};
use crate::kinematics::{assemble_into, passive_sigma_min, velocity_analogues, Chart};
use crate::model::Mechanism;
use crate::Workspace;
use crate::{Error, KinematicsError, SingularityKind};
use charts::{chart_sigma, measure, next_chart, state_in, NEAR_PASSIVE_SINGULAR, PASSIVE_SINGULAR};
use crossing::{
    cross, stepped_over, user_state, Approach, Landing, Path, Quintic, APPROACH_FRACTION, CROSS_BELOW, WATCH_BELOW,
};
use events::Watch;
use ode::MechanismOde;

/// Relative tolerance of a model's run when its file gives none (docs/model-format.md,
/// `simulate`): tighter than [`Options::default`], as the run's energy balance is read as a
/// check of the model, in the 1e-9 J class on the validation benchmarks.
pub const MODEL_RTOL: f64 = 1e-9;
/// Absolute tolerance to go with [`MODEL_RTOL`] (units of q and qd).
pub const MODEL_ATOL: f64 = 1e-12;
/// A grid time within this fraction of h before t_end is dropped for t_end itself: the
/// round-off of t0 + k h must not leave a sliver of an output interval.
const GRID_END_SLACK: f64 = 1e-9;
/// Step attempts before a run's rate of progress is judged: an early transient of small
/// steps (a stiff start, a chart switch) must not stop a run that would finish.
const PROGRESS_MIN_STEPS: usize = 10_000;
/// A run whose mean step so far would need this many times its step budget to reach t_end
/// is stopped: it cannot finish, and waiting for the budget costs this many times more work.
const PROGRESS_MARGIN: f64 = 10.0;

/// What to simulate and how. Times in s.
#[derive(Debug, Clone)]
pub struct Settings {
    pub t0: f64,
    pub t_end: f64,
    pub method: Method,
    /// Integrator options (tolerances, fixed step `dt`, step limits).
    pub options: Options,
    /// Output times, increasing, within [t0, t_end]; `None`: t0 and every accepted step.
    pub t_eval: Option<Vec<f64>>,
    /// Start coordinates and rates; `None`: the model's.
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
}

impl Settings {
    /// Defaults for a mechanism: its file's `simulate` section, else DOP853 with
    /// rtol 1e-9, atol 1e-12 over 1 s.
    pub fn for_model(mech: &Mechanism) -> Result<Settings, Error> {
        let d = &mech.simulate;
        let method = match &d.method {
            Some(name) => name.parse().map_err(Error::Options)?,
            None => Method::Dop853,
        };
        let options = Options {
            rtol: d.rtol.unwrap_or(MODEL_RTOL),
            atol: d.atol.unwrap_or(MODEL_ATOL),
            dt: d.dt,
            ..Options::default()
        };
        let t_end = d.t_end.unwrap_or(1.0);
        let t_eval = d.output_dt.map(|h| grid(0.0, t_end, h));
        Ok(Settings { t0: 0.0, t_end, method, options, t_eval, q0: None, qd0: None })
    }
}

/// Times t0, t0 + h, ... and t_end itself, never past t_end.
pub fn grid(t0: f64, t_end: f64, h: f64) -> Vec<f64> {
    let mut t: Vec<f64> = (0..).map(|k| t0 + k as f64 * h).take_while(|&t| t < t_end - GRID_END_SLACK * h).collect();
    t.push(t_end);
    t
}

fn check(settings: &Settings, mech: &Mechanism) -> Result<(), Error> {
    let bad = |m: String| Err(Error::Options(m));
    if !(settings.t_end > settings.t0) || !settings.t_end.is_finite() || !settings.t0.is_finite() {
        return bad(format!("t_end = {} must be finite and after t0 = {}", settings.t_end, settings.t0));
    }
    settings.options.validate(settings.method).map_err(Error::Options)?;
    for (name, v) in [("q0", &settings.q0), ("qd0", &settings.qd0)] {
        if let Some(v) = v {
            if v.len() != mech.dof() || v.iter().any(|x| !x.is_finite()) {
                return bad(format!(
                    "{name} needs {} finite values ({}), got {v:?}",
                    mech.dof(),
                    mech.coordinate_names().join(", ")
                ));
            }
        }
    }
    if let Some(te) = &settings.t_eval {
        if te.windows(2).any(|w| !(w[1] > w[0]))
            || te.first().is_some_and(|&t| t < settings.t0)
            || te.last().is_some_and(|&t| t > settings.t_end)
        {
            return bad(format!(
                "t_eval must increase strictly within [t0, t_end] = [{}, {}]",
                settings.t0, settings.t_end
            ));
        }
    }
    Ok(())
}

/// The start: assembled at q0, in the user's chart unless it is near-singular there.
/// Coordinates driven by motion start where their motion is at t0 (a `speed` counts from q0).
fn start<'a>(
    mech: &'a Mechanism,
    s: &Settings,
    drives: &'a mut dyn Drives,
    motion: &'a mut Prescribed<'a>,
) -> Result<(MechanismOde<'a>, Vec<f64>), Error> {
    let (q0m, qd0m) = mech.initial_state();
    let mut q0 = s.q0.clone().unwrap_or(q0m);
    let mut qd0 = s.qd0.clone().unwrap_or(qd0m);
    if !motion.is_empty() {
        motion.start(s.t0, s.t_end, &q0).map_err(Error::Options)?;
        motion.eval(s.t0).map_err(|message| Error::Drive { t: s.t0, message })?;
        for (i, &k) in motion.p.iter().enumerate() {
            (q0[k], qd0[k]) = (motion.q[i], motion.qd[i]);
        }
    }
    let mut ws = Workspace::new(mech);
    assemble_into(mech, &q0, &mut ws)?;
    // Body velocities from qd0 need U in the user's chart, i.e. a regular start; at rest a
    // singular start is fine (xd = 0).
    ws.xd.fill(0.0);
    if qd0.iter().any(|&v| v != 0.0) {
        velocity_analogues(&mut ws).map_err(|_| KinematicsError::singular(SingularityKind::TypeIIStartInMotion))?;
        for (j, r) in qd0.iter().enumerate() {
            let n = ws.x.len();
            for i in 0..n {
                ws.xd[i] += ws.u[j * n + i] * r;
            }
        }
    }
    ws.q.copy_from_slice(&q0);
    ws.qd.copy_from_slice(&qd0);
    let mut ode = MechanismOde::new(mech, ws, drives).with_motion(motion);
    let m0 = measure(&mut ode);
    if m0.passive < PASSIVE_SINGULAR {
        return Err(
            KinematicsError::Singular { kind: SingularityKind::PassiveAtStart, sigma_min: Some(m0.passive) }.into()
        );
    }
    let chart = next_chart(&ode, &m0, m0.sigma).unwrap_or(Chart::Inputs);
    let m = mech.dof();
    let mut y = vec![0.0; 2 * m + 1];
    state_in(&ode, &chart, 0.0, &mut y);
    ode.set_chart(chart, s.t0, &y)?;
    let own = chart_sigma(&mut ode, m0.sigma);
    ode.limit_correction(own);
    Ok((ode, y))
}

/// Status and message for a failed step.
fn failure(e: &StepError<Error>) -> (Status, String) {
    let status = match e {
        StepError::StepSizeUnderflow { .. } => Status::StepSizeUnderflow,
        StepError::NonFinite { .. } => Status::NonFinite,
        StepError::TooManySteps { .. } => Status::TooManySteps,
        StepError::Rhs { error: Error::Drive { .. }, .. } => Status::DriveFailed,
        StepError::Rhs { .. } => Status::AssemblyFailed,
    };
    let message = match e {
        StepError::Rhs { t, error } => format!("at t = {t} s, even with the smallest step: {error}"),
        other => other.to_string(),
    };
    (status, message)
}

/// Status and message when the run cannot reach t_end at its present rate: after
/// [`PROGRESS_MIN_STEPS`] attempts, its mean step is below `(t_end - t0) / (PROGRESS_MARGIN
/// max_steps)`. The steps of such runs shrink as they go (efforts of 1e12 N m on the five-bar:
/// 10 million steps for 0.35 % of 1 s), so waiting for `max_steps` only wastes the work.
fn hopeless(settings: &Settings, stepper: &Stepper) -> Option<(Status, String)> {
    let stats = stepper.stats();
    let attempts = stats.naccept + stats.nreject;
    let (t0, t, t_end) = (settings.t0, stepper.t(), settings.t_end);
    let max_steps = settings.options.max_steps as f64;
    let floor = (t_end - t0) / (PROGRESS_MARGIN * max_steps);
    let mean = (t - t0) / attempts as f64;
    if attempts < PROGRESS_MIN_STEPS || mean >= floor {
        return None;
    }
    let message = format!(
        "step size too small at t = {t:e} s: after {attempts} steps the mean step is {mean:.2e} s \
         (last {:.2e} s), below (t_end - t0) / ({PROGRESS_MARGIN} max_steps) = {floor:.2e} s, so the run \
         cannot make progress to t_end = {t_end} s within max_steps = {}. The efforts are too large for \
         the model or the tolerances too tight: lower the efforts, loosen rtol/atol, shorten t_end, \
         or raise max_steps",
        t - stepper.t_prev(),
        settings.options.max_steps
    );
    Some((Status::StepSizeTooSmall, message))
}

/// Record the stepper's last accepted state as the final row (a stopped run keeps it when
/// the output grid did not reach it). Evaluated from its own anchor, so Newton starts at the
/// answer; if even that fails, the rows already recorded stand.
fn keep_last_state(ode: &mut MechanismOde, stepper: &Stepper, traj: &mut Trajectory) {
    let (t, y) = (stepper.t(), stepper.y());
    ode.restart_from_anchor();
    if ode.accept(t, y).is_ok() {
        let sigma = measure(ode).sigma;
        traj.record(ode, t, y[y.len() - 1], sigma);
    }
}

/// Evaluate the dense output of the step just taken at `t_out` into `yi` (walking there
/// from the step's start if a direct evaluation is refused).
fn evaluate_output(ode: &mut MechanismOde, stepper: &mut Stepper, t_out: f64, yi: &mut [f64]) -> Result<(), Error> {
    stepper.interpolate(ode, t_out, yi);
    ode.evaluate_walking(t_out, yi)
}

/// What a run watches besides its output rows: events, located on each step's interpolant
/// (their zeros in the trajectory's `events`; a terminal one ends the run with status
/// `Event`, its time the last row's), and whether to keep that interpolant as the
/// trajectory's `dense` output. Either costs, in each step, the interpolant at p + 1 nodes
/// (p its degree), and for DOP853 its 3 dense-output stages.
#[derive(Default)]
pub struct Observe<'e> {
    pub events: Vec<Event<'e>>,
    pub dense_output: bool,
}

impl Observe<'_> {
    fn is_empty(&self) -> bool {
        self.events.is_empty() && !self.dense_output
    }
}

/// Append the step just taken to `dense`: the user's q and qd at its nodes, from the step's
/// interpolant. In the user's chart that is the interpolant itself, the coordinates driven by
/// motion following it; in a partition chart, the point assembled at the interpolated chart
/// values (the interpolant of q through those points is then as accurate as the step's own).
fn sample_step(
    ode: &mut MechanismOde,
    stepper: &mut Stepper,
    dense: &mut DenseOutput,
    yi: &mut [f64],
    rows: &mut Vec<f64>,
) -> Result<(), Error> {
    let m = ode.m();
    let (t0, t1) = (stepper.t_prev(), stepper.t());
    rows.clear();
    ode.restart_from_anchor();
    for j in 0..dense.nodes {
        let t = t0 + dense::node(j, dense.nodes) * (t1 - t0);
        if j + 1 == dense.nodes {
            yi.copy_from_slice(stepper.y());
        } else {
            stepper.interpolate(ode, t, yi);
        }
        if ode.ws.chart == Chart::Inputs {
            if let Some(motion) = ode.motion.as_deref_mut() {
                motion.eval(t).map_err(|message| Error::Drive { t, message })?;
                motion.overwrite(m, yi);
            }
            rows.extend_from_slice(&yi[..2 * m]);
        } else {
            ode.evaluate_walking(t, yi)?;
            rows.extend_from_slice(&ode.ws.q);
            rows.extend_from_slice(&ode.ws.qd);
        }
    }
    dense.push(t0, t1, rows);
    Ok(())
}

/// The last row of a run ended by a terminal event at `t_star`, within the step just taken
/// (unless the outputs already hold it).
fn end_at_event(
    ode: &mut MechanismOde,
    stepper: &mut Stepper,
    t_star: f64,
    yi: &mut [f64],
    traj: &mut Trajectory,
) -> Result<(), Error> {
    if traj.t.last() == Some(&t_star) {
        return Ok(());
    }
    ode.restart_from_anchor();
    evaluate_output(ode, stepper, t_star, yi)?;
    let sigma = measure(ode).sigma;
    traj.record(ode, t_star, yi[yi.len() - 1], sigma);
    Ok(())
}

/// The output grid and where the run is in it.
struct Outputs<'t> {
    t_eval: Option<&'t [f64]>,
    next: usize,
}

/// Cross the change point ahead of the point accepted at t (held by `ode.ws`, type II and
/// passive measures `sigma`, `passive`, work `work`), `approach` the points before it, and
/// restart the stepper past it. Outputs inside the crossing come from the quintic through its
/// ends (from its Taylor step if t_end is inside it); without a grid the point past it is
/// recorded. Returns whether t_end was reached inside
/// the crossing; Err says why the motion cannot be continued.
fn cross_change_point(
    ode: &mut MechanismOde,
    stepper: &mut Stepper,
    traj: &mut Trajectory,
    out: &mut Outputs,
    (t, sigma, passive, work): (f64, f64, f64, f64),
    approach: &mut Approach,
    t_end: f64,
) -> Result<bool, String> {
    let landing: Landing = cross(ode, t, passive, work, approach)?;
    traj.change_points.push(landing.point.clone());
    let inside = |s: f64, end: f64| s < end || s == t_end && end >= t_end;
    if landing.t >= t_end {
        // Ends inside the crossing: the rest from its Taylor step.
        let rows: Vec<f64> = match out.t_eval {
            Some(te) => te[out.next..].iter().copied().take_while(|&s| inside(s, t_end)).collect(),
            None => vec![t_end],
        };
        for s in rows {
            path_row(ode, traj, &landing.path, s, work, sigma);
        }
        out.next = out.t_eval.map_or(0, <[f64]>::len);
        return Ok(true);
    }
    ode.ws.x.copy_from_slice(&landing.x);
    ode.set_chart(landing.chart.clone(), landing.t, &landing.y).map_err(|e| format!("past the change point: {e}"))?;
    stepper.reset(ode, landing.t, &landing.y).map_err(|e| format!("restarting past the change point: {e}"))?;
    traj.stats.chart_switches += 1;
    let meas = measure(ode);
    let own = chart_sigma(ode, meas.sigma);
    ode.limit_correction(own);
    approach.clear();
    approach.keep(ode, landing.t, meas.passive, landing.y[landing.y.len() - 1]);
    match out.t_eval {
        None => traj.record(ode, landing.t, landing.y[landing.y.len() - 1], meas.sigma),
        Some(te) => {
            // Outputs inside the crossing: the quintic through its two ends (x, xd, xdd), an
            // interpolation, where the Taylor step's own error grows towards its end.
            let ws = &ode.ws;
            let path = Quintic::new(&landing.start, (&ws.x, &ws.xd, &ws.xdd), landing.t);
            while out.next < te.len() && inside(te[out.next], landing.t) {
                path_row(ode, traj, &path, te[out.next], work, sigma);
                out.next += 1;
            }
            ode.restart_from_anchor();
        }
    }
    Ok(false)
}

/// Record the row at time s inside a crossing, from `path`.
fn path_row(ode: &mut MechanismOde, traj: &mut Trajectory, path: &dyn Path, s: f64, work: f64, sigma: f64) {
    let ws = &mut ode.ws;
    path.at(s, &mut ws.frame.x, &mut ws.frame.xd, &mut ws.xdd);
    user_state(ode);
    traj.record(ode, s, work, sigma);
}

/// Simulate from the model's (or the given) initial state, the coordinates the model drives
/// by motion following it. `progress(t)` is called after each accepted step and may return
/// false to stop. Errors in the settings or at the start return Err; anything after the
/// start returns the partial trajectory with a status.
pub fn simulate(
    mech: &Mechanism,
    settings: &Settings,
    drives: &mut dyn Drives,
    progress: Option<&mut dyn FnMut(f64) -> bool>,
) -> Result<Trajectory, Error> {
    simulate_prescribed(mech, settings, drives, &mut Prescribed::from_model(mech), progress)
}

/// As [`simulate`], with the coordinates of `motion` driven by it (instead of the model's
/// motions; start from [`Prescribed::from_model`] to keep them) and given the efforts their
/// motion needs, reported in the trajectory's `tau`; their work is part of `work`. The
/// drives' efforts on them are not applied. The state integrated is that of all m
/// coordinates, the prescribed ones replaced by their motion at every evaluation (in the
/// user's chart; in a partition chart, near a type II singularity, they follow it to the
/// integrator's accuracy). With every coordinate prescribed this is kinematics and inverse
/// dynamics at each output, the integrator computing only the work.
pub fn simulate_prescribed<'a>(
    mech: &'a Mechanism,
    settings: &Settings,
    drives: &'a mut dyn Drives,
    motion: &'a mut Prescribed<'a>,
    progress: Option<&mut dyn FnMut(f64) -> bool>,
) -> Result<Trajectory, Error> {
    simulate_observed(mech, settings, drives, motion, Observe::default(), progress)
}

/// As [`simulate_prescribed`], watching `observe`'s events and keeping the dense output if
/// asked. Event coordinates are checked here: an index past m is an error in the settings.
pub fn simulate_observed<'a>(
    mech: &'a Mechanism,
    settings: &Settings,
    drives: &'a mut dyn Drives,
    motion: &'a mut Prescribed<'a>,
    observe: Observe,
    mut progress: Option<&mut dyn FnMut(f64) -> bool>,
) -> Result<Trajectory, Error> {
    check(settings, mech)?;
    for e in &observe.events {
        if let EventFn::Coordinate { index, value } = e.g {
            if index >= mech.dof() || !value.is_finite() {
                return Err(Error::Options(format!(
                    "an event's coordinate {index} and value {value}: the coordinate must be one of {} ({}) \
                     and the value finite",
                    mech.dof(),
                    mech.coordinate_names().join(", ")
                )));
            }
        }
    }
    let m = mech.dof();
    let mut traj = Trajectory::new(m, mech.n_x());
    let (mut ode, y0) = match start(mech, settings, drives, motion) {
        Ok(started) => started,
        // A drive that fails at once is a failed run, not bad input: say so in the status.
        Err(e @ Error::Drive { .. }) => {
            (traj.status, traj.message) = (Status::DriveFailed, e.to_string());
            return Ok(traj);
        }
        Err(e) => return Err(e),
    };
    // Dense output is only needed to interpolate at requested times, and for events and the
    // kept interpolant (DOP853 pays 3 extra evaluations in each step that uses it).
    let (observing, keep_dense) = (!observe.is_empty(), observe.dense_output);
    let options = Options { dense_output: settings.t_eval.is_some() || observing, ..settings.options.clone() };
    let mut stepper = Stepper::new(settings.method, &options, 2 * m + 1).map_err(Error::Options)?;
    let mut y = y0;
    if let Err(e) = stepper.reset(&mut ode, settings.t0, &y) {
        (traj.status, traj.message) = failure(&e);
        return Ok(traj);
    }
    let t_eval = settings.t_eval.as_deref();
    let mut out = Outputs { t_eval, next: 0 };
    let mut approach = Approach::default();
    // The start counts in the least measures, so that a run of no step reports its start's.
    let first = measure(&mut ode);
    (traj.stats.min_sigma, traj.stats.min_passive_sigma) = (first.sigma, first.passive);
    approach.keep(&ode, settings.t0, first.passive, y[2 * m]);
    if t_eval.is_none_or(|te| te.first() == Some(&settings.t0)) {
        traj.record(&ode, settings.t0, y[2 * m], first.sigma);
        out.next = 1;
    }
    let mut yi = vec![0.0; 2 * m + 1];
    let (mut status, mut message) = (Status::Success, String::new());
    let mut dense = observing.then(|| DenseOutput::new(m, settings.method.dense_order()));
    let mut watch = Watch::new(observe.events, m);
    let mut rows = Vec::new();
    if let Err(e) = watch.start(settings.t0, &ode.ws.q, &ode.ws.qd) {
        (status, message) = (Status::EventFailed, format!("at t = {} s: {e}", settings.t0));
    }
    // Whether a stop leaves the last accepted state in the stepper's chart, to be kept as
    // the final row when the output grid did not reach it.
    let mut keep_last = false;
    while status == Status::Success && stepper.t() < settings.t_end {
        if let Err(e) = stepper.step(&mut ode, settings.t_end) {
            (status, message) = failure(&e);
            keep_last = true;
            // Steps that shrink to nothing before a change point: cross it from the last
            // accepted point when it is near enough.
            let (t, y) = (stepper.t(), stepper.y().to_vec());
            ode.restart_from_anchor();
            if ode.motion.is_none() && approach.last().is_some_and(|p| p.t == t) && ode.accept(t, &y).is_ok() {
                let meas = measure(&mut ode);
                if meas.passive < NEAR_PASSIVE_SINGULAR {
                    let at = (t, meas.sigma, meas.passive, y[2 * m]);
                    match cross_change_point(
                        &mut ode,
                        &mut stepper,
                        &mut traj,
                        &mut out,
                        at,
                        &mut approach,
                        settings.t_end,
                    ) {
                        Ok(false) => {
                            (status, message, keep_last) = (Status::Success, String::new(), false);
                            continue;
                        }
                        Ok(true) => {
                            (status, message, keep_last) = (Status::Success, String::new(), false);
                        }
                        Err(why) => message = format!("{message}; {why}"),
                    }
                }
            }
            break;
        }
        let t = stepper.t();
        y.copy_from_slice(stepper.y());
        if ode.ws.chart != Chart::Inputs {
            traj.stats.partition_steps += 1;
        }
        // The end of the run within this step: t, or a terminal event's time.
        let mut stop: Option<(f64, usize)> = None;
        if let Some(dense) = dense.as_mut() {
            if let Err(e) = sample_step(&mut ode, &mut stepper, dense, &mut yi, &mut rows) {
                let kind = if matches!(e, Error::Drive { .. }) { Status::DriveFailed } else { Status::AssemblyFailed };
                (status, message, keep_last) = (kind, format!("dense output of the step to t = {t} s: {e}"), true);
                break;
            }
            match watch.step(dense) {
                Ok(found) => stop = found,
                Err(e) => {
                    (status, message, keep_last) =
                        (Status::EventFailed, format!("in the step to t = {t} s: {e}"), true);
                    break;
                }
            }
        }
        let t_last = stop.map_or(t, |(t_star, _)| t_star);
        if let Some(te) = t_eval {
            if out.next < te.len() && te[out.next] <= t_last {
                // DOP853's dense-output stages (at 0.1, 0.2 and 7/9 of the step, evaluated by
                // the first interpolation) are predicted from the step's start, not its end.
                ode.restart_from_anchor();
            }
            while out.next < te.len() && te[out.next] <= t_last {
                if let Err(e) = evaluate_output(&mut ode, &mut stepper, te[out.next], &mut yi) {
                    (status, message) = (Status::AssemblyFailed, format!("output at t = {}: {e}", te[out.next]));
                    break;
                }
                let sigma = measure(&mut ode).sigma;
                traj.record(&ode, te[out.next], yi[2 * m], sigma);
                out.next += 1;
            }
            if status != Status::Success {
                break;
            }
        }
        if let Some((t_star, i)) = stop {
            if let Err(e) = end_at_event(&mut ode, &mut stepper, t_star, &mut yi, &mut traj) {
                (status, message) =
                    (Status::AssemblyFailed, format!("the state at terminal event {i}, t = {t_star} s: {e}"));
                break;
            }
            if let Some(d) = dense.as_mut() {
                d.truncate(t_star);
            }
            (status, message) = (Status::Event, format!("terminal event {i} at t = {t_star} s"));
            break;
        }
        // Outputs and the dense output moved the evaluation away from the step's end; if going
        // straight back is refused, come back along the interpolant as they did.
        let accepted = ode.accept(t, &y).or_else(|e| {
            if t_eval.is_none() && !observing {
                return Err(e);
            }
            evaluate_output(&mut ode, &mut stepper, t, &mut yi)?;
            ode.accept(t, &y)
        });
        if let Err(e) = accepted {
            (status, message) = (Status::AssemblyFailed, format!("at t = {t}: {e}"));
            break;
        }
        let meas = measure(&mut ode);
        if t_eval.is_none() {
            traj.record(&ode, t, y[2 * m], meas.sigma);
        }
        traj.stats.min_sigma = traj.stats.min_sigma.min(meas.sigma);
        traj.stats.min_passive_sigma = traj.stats.min_passive_sigma.min(meas.passive);
        let falling = approach.last().is_some_and(|p| meas.passive < p.passive);
        let over = stepped_over(&ode, &approach, t, meas.passive);
        if over.is_none() && meas.passive < CROSS_BELOW && falling && ode.motion.is_none() {
            let at = (t, meas.sigma, meas.passive, y[2 * m]);
            match cross_change_point(&mut ode, &mut stepper, &mut traj, &mut out, at, &mut approach, settings.t_end) {
                Ok(false) => continue,
                Ok(true) => break,
                Err(why) => {
                    let m = format!(
                        "the passive mechanism is singular at t = {t} s (scaled measure {:.2e}) and {why}",
                        meas.passive
                    );
                    (status, message) = (Status::PassiveSingularity, m);
                    break;
                }
            }
        }
        if let Some(point) = over {
            traj.change_points.push(point);
            // The points kept are on the other side of it.
            approach.clear();
        }
        if let Some(scale) = approach.restore(&ode, meas.passive, y[2 * m]) {
            y[m..2 * m].iter_mut().for_each(|v| *v *= scale);
            let restored = stepper.reset(&mut ode, t, &y).map_err(|e| e.to_string());
            if let Err(e) = restored.and_then(|()| ode.accept(t, &y).map_err(|e| e.to_string())) {
                (status, message) = (Status::AssemblyFailed, format!("restoring the energy at t = {t} s: {e}"));
                break;
            }
        }
        approach.keep(&ode, t, meas.passive, y[2 * m]);
        if meas.passive < PASSIVE_SINGULAR {
            (status, message) = (Status::PassiveSingularity, format!("the passive mechanism is singular at t = {t} s (scaled measure {:.2e}): its pair constraints lose rank and the motion is not determined beyond", meas.passive));
            break;
        }
        if let Some(stop) = hopeless(settings, &stepper) {
            (status, message) = stop;
            keep_last = true;
            break;
        }
        let mut own = chart_sigma(&mut ode, meas.sigma);
        if let Some(chart) = next_chart(&ode, &meas, own) {
            state_in(&ode, &chart, y[2 * m], &mut y);
            traj.stats.chart_switches += 1;
            let switched = ode.set_chart(chart, t, &y).map_err(|e| e.to_string());
            if let Err(e) = switched.and_then(|_| stepper.reset(&mut ode, t, &y).map_err(|e| e.to_string())) {
                (status, message) = (Status::AssemblyFailed, format!("changing coordinates at t = {t} s: {e}"));
                break;
            }
            own = chart_sigma(&mut ode, meas.sigma);
        }
        ode.limit_correction(own);
        // In the user's chart the passive measure is only bounded by sigma_II (it is
        // measured in a partition, which the integrator takes below 0.05).
        if meas.passive < WATCH_BELOW && ode.motion.is_none() && ode.ws.chart != Chart::Inputs {
            ode.limit_move(APPROACH_FRACTION * meas.passive);
        }
        if let Some(cb) = progress.as_mut() {
            if !cb(t) {
                (status, message) =
                    (Status::Cancelled, format!("cancelled at t = {t} s: the progress callback asked to stop"));
                keep_last = true;
                break;
            }
        }
    }
    if keep_last && traj.t.last().is_none_or(|&t| t < stepper.t()) {
        keep_last_state(&mut ode, &stepper, &mut traj);
    }
    traj.stats.integrator = stepper.stats();
    traj.stats.failed_evaluations = ode.failed_evaluations;
    traj.events = watch.records;
    // Events alone need the dense output only while the run lasts.
    traj.dense = dense.filter(|_| keep_dense);
    if matches!(status, Status::StepSizeUnderflow | Status::AssemblyFailed | Status::NonFinite) {
        // Steps that shrink to nothing usually mean the passive mechanism is at a change
        // point (a parallelogram folding flat): say so when it is.
        let passive = passive_sigma_min(mech, ode.anchor_x());
        let driven = ode.motion.as_ref().map_or(f64::INFINITY, |p| prescribed_sigma_min(mech, &p.p, ode.anchor_x()));
        if passive < NEAR_PASSIVE_SINGULAR {
            status = Status::PassiveSingularity;
            message = format!(
                "{message}; the passive mechanism is near-singular there (scaled measure {passive:.2e}): \
                 a change point where its motion is not determined"
            );
        } else if driven < NEAR_PASSIVE_SINGULAR {
            message = format!(
                "{message}; the coordinates driven by motion are near a singularity of their own there (scaled \
                 measure {driven:.2e}): they stop determining their part of the mechanism, and the efforts their \
                 motion needs grow without bound. Change the motion so that it avoids this configuration"
            );
        }
    }
    if status == Status::Success {
        message = format!("reached t_end = {} s", settings.t_end);
    }
    traj.status = status;
    traj.message = message;
    Ok(traj)
}
