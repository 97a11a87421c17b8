//! Forward simulation: the whole loop in Rust. Integrates y = [z, zd, W] in the best chart,
//! writes outputs in the user's coordinates, and on any failure returns the trajectory
//! computed so far with a status saying why it stopped.

pub mod charts;
pub mod columns;
pub mod crossing;
pub mod dense;
pub mod events;
mod fold_watch;
mod gear_sides;
mod jacobian;
pub mod ode;
mod overrides;
mod prepared;
mod run;
mod start;
mod stop;
pub mod trajectory;

pub use dense::DenseOutput;
pub use events::{Event, EventFn, EventRecords, EVENT_XTOL};
pub use overrides::Overrides;
pub use prepared::Prepared;
pub use trajectory::{SimStats, Status, Trajectory};

use std::ops::ControlFlow;

use crate::dynamics::{Drives, Prescribed};
use crate::error::{Setting, Time};
use crate::integrate::{Method, Options};
use crate::model::{Mechanism, SimulateDefaults};
use crate::Error;
use run::{stopped_at_start, Run};

/// Relative tolerance of a model's run when its file gives none (docs/model-format.md,
/// `simulate`): tighter than [`Options::default`], as the run's energy balance is read as a
/// check of the model, in the 1e-9 J class on the validation benchmarks.
pub const MODEL_RTOL: f64 = 1e-9;
/// Absolute tolerance to go with [`MODEL_RTOL`] (units of q and qd).
pub const MODEL_ATOL: f64 = 1e-12;
/// A grid time within this fraction of h before t_end is dropped for t_end itself: the
/// round-off of t0 + k h must not leave a sliver of an output interval.
const GRID_END_SLACK: f64 = 1e-9;
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
        let mut s = Settings::without_outputs(mech)?;
        if let Some(h) = mech.simulate.output_dt {
            s.t_eval = Some(overrides::output_grid(s.t0, s.t_end, h)?);
        }
        Ok(s)
    }

    /// [`Settings::for_model`] without the file's output grid, which [`Overrides::settings`]
    /// builds from the run's own t_end (a file's 1e8 output times are not made for a 0.05 s run).
    fn without_outputs(mech: &Mechanism) -> Result<Settings, Error> {
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
        let t_end = d.t_end.unwrap_or(SimulateDefaults::T_END);
        Ok(Settings { t0: 0.0, t_end, method, options, t_eval: None, q0: None, qd0: None })
    }
}

/// Times t0, t0 + h, ... and t_end itself, never past t_end.
pub fn grid(t0: f64, t_end: f64, h: f64) -> Vec<f64> {
    let mut t: Vec<f64> = (0..).map(|k| t0 + k as f64 * h).take_while(|&t| t < t_end - GRID_END_SLACK * h).collect();
    t.push(t_end);
    t
}

/// The one check of a run's settings, whoever made them ([`Overrides::settings`] or a Rust
/// user): each numeric setting by its rule ([`Setting::check`], an [`Error::Setting`] naming
/// it), the start state's and output times' shapes.
fn check(settings: &Settings, mech: &Mechanism) -> Result<(), Error> {
    let bad = |m: String| Err(Error::Options(m));
    Setting::check_end(settings.t0, settings.t_end)?;
    settings.options.validate(settings.method)?;
    if let Some(dt) = settings.options.dt {
        Setting::check_fixed_steps(settings.t0, settings.t_end, dt, settings.options.max_steps)?;
    }
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
                Time(settings.t0),
                Time(settings.t_end)
            ));
        }
    }
    Ok(())
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
    progress: Option<&mut dyn FnMut(f64) -> bool>,
) -> Result<Trajectory, Error> {
    simulate_prepared(mech, &Prepared::new(mech), settings, drives, motion, observe, progress)
}

/// As [`simulate_observed`], the run's set-up from the model alone taken from `prepared`
/// ([`Prepared::new`] of `mech`, made once for all its runs): the same trajectory, to the
/// bit, without the Assur decomposition, J's structure analysis and the closed forms'
/// construction of each run. A `prepared` of another mechanism is an error.
pub fn simulate_prepared<'a>(
    mech: &'a Mechanism,
    prepared: &Prepared,
    settings: &Settings,
    drives: &'a mut dyn Drives,
    motion: &'a mut Prescribed<'a>,
    observe: Observe,
    progress: Option<&mut dyn FnMut(f64) -> bool>,
) -> Result<Trajectory, Error> {
    prepared.check(mech)?;
    check(settings, mech)?;
    check_events(&observe, mech)?;
    match Run::start(mech, prepared, settings, drives, motion, observe)? {
        ControlFlow::Continue(run) => Ok(run.run(progress)),
        ControlFlow::Break(stop) => Ok(stopped_at_start(mech, stop)),
    }
}

/// An event's coordinate must be one of the mechanism's, its value finite.
fn check_events(observe: &Observe, mech: &Mechanism) -> Result<(), Error> {
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
    Ok(())
}
