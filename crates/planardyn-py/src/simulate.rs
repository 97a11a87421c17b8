//! `Mechanism.simulate`: settings from the model file's defaults and the caller's
//! overrides, Python callables as drives, motions and progress callback, and the trajectory
//! as a `Run` (`run.rs`: time-major numpy arrays made at their first read). The whole loop runs in Rust with the GIL released;
//! callbacks re-attach to the interpreter for the duration of each call.

use crate::convert::Values;
use crate::errors::run;
use crate::exceptions::argument_error;
use crate::run::PyRun;
use numpy::{AllowTypeChange, PyArray1, PyArrayLikeDyn};
use planardyn::dynamics::{Drives, ModelDrives, Motion, MotionFunction, Prescribed};
use planardyn::model::{MotionLaw, Spline};
use planardyn::simulate::columns::COLUMNS;
use planardyn::simulate::{simulate_prepared, Event, EventFn, Observe, Overrides, Prepared, Settings};
use planardyn::Mechanism;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The progress callback runs each time t has advanced by this fraction of the run: at most
/// about 100 times.
const PROGRESS_FRACTION: f64 = 0.01;

/// Ctrl-C is also checked at least this often in wall time, so a slow run answers it at once
/// whatever its progress in t.
pub(crate) const SIGNAL_INTERVAL: Duration = Duration::from_millis(100);

/// What a Python callback's exception becomes, the one rule for drives, motions, events and
/// progress: its repr, for the run's message; and a BaseException that is not an Exception
/// (KeyboardInterrupt, SystemExit) kept in `fatal`, so that the run stops at once and it is
/// raised again at the end.
fn callback_error(py: Python<'_>, e: PyErr, fatal: &mut Option<PyErr>) -> String {
    let text = e.value(py).repr().map(|r| r.to_string()).unwrap_or_else(|_| e.to_string());
    if !e.is_instance_of::<PyException>(py) {
        *fatal = Some(e);
    }
    text
}

/// A Python callable `f(t, q, qd) -> (m,)` as drive efforts.
struct PyDrives {
    f: Py<PyAny>,
    m: usize,
    /// A BaseException that is not an Exception (KeyboardInterrupt, SystemExit): the run
    /// stops at once and it is raised again at the end.
    fatal: Option<PyErr>,
}

impl Drives for PyDrives {
    fn efforts(&mut self, t: f64, q: &[f64], qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        if self.fatal.is_some() {
            return Err("interrupted".to_string());
        }
        Python::attach(|py| {
            let args = (t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, qd));
            let out = self.f.bind(py).call1(args).and_then(|r| {
                let a: PyArrayLikeDyn<'_, f64, AllowTypeChange> = r.extract()?;
                Ok(Values::read(&a))
            });
            match out {
                Ok(v) if v.data.len() == self.m && v.shape.len() <= 1 => {
                    tau.copy_from_slice(&v.data);
                    Ok(())
                }
                Ok(v) => Err(format!(
                    "the drive function returned shape {:?}; expected ({},), one effort per coordinate",
                    v.shape, self.m
                )),
                Err(e) => Err(format!("the drive function raised {}", callback_error(py, e, &mut self.fatal))),
            }
        })
    }
}

/// The motion of one coordinate as `Mechanism.simulate` passes it: a speed (rad/s or m/s),
/// a table (times in s, positions in rad or m), or a callable `f(t) -> (q, qd, qdd)`.
#[derive(FromPyObject)]
pub enum MotionArg {
    Speed(f64),
    Table(Vec<f64>, Vec<f64>),
    Function(Py<PyAny>),
}

/// A Python callable `f(t) -> (q, qd, qdd)` as the motion of one coordinate.
pub(crate) struct PyMotion {
    f: Py<PyAny>,
    name: String,
    /// As `PyDrives::fatal`.
    fatal: Option<PyErr>,
}

impl MotionFunction for PyMotion {
    fn motion(&mut self, t: f64) -> Result<[f64; 3], String> {
        if self.fatal.is_some() {
            return Err("interrupted".to_string());
        }
        Python::attach(|py| match self.f.bind(py).call1((t,)).and_then(|r| r.extract::<(f64, f64, f64)>()) {
            Ok((q, qd, qdd)) => Ok([q, qd, qdd]),
            Err(e) => Err(format!(
                "the motion function of '{}' must return (q, qd, qdd), three numbers; it raised {}",
                self.name,
                callback_error(py, e, &mut self.fatal)
            )),
        })
    }
}

/// An event as `Mechanism.simulate` passes it: a coordinate crossing a value
/// (index, value in rad or m, terminal, direction), or a callable `g(t, q, qd) -> float`
/// (g, terminal, direction).
#[derive(FromPyObject)]
pub enum EventArg {
    Coordinate(usize, f64, bool, f64),
    Function(Py<PyAny>, bool, f64),
}

/// The core's events for `args`. A BaseException that is not an Exception raised in an
/// event function goes to `fatal` (as `PyDrives::fatal`).
fn core_events<'e>(args: &'e [EventArg], fatal: &'e Mutex<Option<PyErr>>) -> Vec<Event<'e>> {
    args.iter()
        .map(|a| match a {
            EventArg::Coordinate(k, value, terminal, direction) => Event::coordinate(*k, *value, *terminal, *direction),
            EventArg::Function(f, terminal, direction) => Event {
                g: EventFn::Function(Box::new(move |t, q, qd| call_event(f, fatal, t, q, qd))),
                terminal: *terminal,
                direction: *direction,
            },
        })
        .collect()
}

fn call_event(f: &Py<PyAny>, fatal: &Mutex<Option<PyErr>>, t: f64, q: &[f64], qd: &[f64]) -> Result<f64, String> {
    let mut fatal = fatal.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    if fatal.is_some() {
        return Err("interrupted".to_string());
    }
    Python::attach(|py| {
        let args = (t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, qd));
        match f.bind(py).call1(args).and_then(|r| r.extract::<f64>()) {
            Ok(g) => Ok(g),
            Err(e) => {
                Err(format!("the event function must return a number; it raised {}", callback_error(py, e, &mut fatal)))
            }
        }
    })
}

/// A motion ready for the core: a law, or a Python function.
pub(crate) enum MotionEntry {
    Law(MotionLaw),
    Function(PyMotion),
}

/// The caller's motions by coordinate index, checked (a table's spline built).
pub(crate) fn motion_entries(mech: &Mechanism, motion: Vec<(usize, MotionArg)>) -> PyResult<Vec<(usize, MotionEntry)>> {
    let names = mech.coordinate_names();
    motion
        .into_iter()
        .map(|(k, arg)| {
            let name =
                names.get(k).ok_or_else(|| argument_error(Some("motion"), format!("motion: no coordinate {k}")))?;
            let entry = match arg {
                MotionArg::Speed(w) if w.is_finite() => MotionEntry::Law(MotionLaw::Speed(w)),
                MotionArg::Speed(w) => {
                    return Err(argument_error(Some("motion"), format!("motion of '{name}': speed {w} must be finite")))
                }
                MotionArg::Table(t, q) => MotionEntry::Law(MotionLaw::Table(
                    Spline::new(&t, &q)
                        .map_err(|e| argument_error(Some("motion"), format!("motion table of '{name}': {e}")))?,
                )),
                MotionArg::Function(f) => MotionEntry::Function(PyMotion { f, name: name.to_string(), fatal: None }),
            };
            Ok((k, entry))
        })
        .collect()
}

/// The settings of a mechanism's last run with the overrides they were made from: a loop of
/// runs with the same arguments (an optimisation's) makes them once (issue 25 item 4: they
/// were a tenth of a short run's fixed cost). The mechanism is immutable, so they stay right.
#[derive(Default)]
pub struct LastSettings(Mutex<Option<(Overrides, Arc<Settings>)>>);

impl LastSettings {
    /// The settings of a run of `mech` with `args` (`Overrides::settings`), the last run's
    /// when its overrides were the same.
    fn settings(&self, mech: &Mechanism, args: Overrides) -> Result<Arc<Settings>, planardyn::Error> {
        // Nothing panics while holding it; a poisoned lock still holds whole settings.
        let mut last = self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some((_, s)) = last.as_ref().filter(|(given, _)| *given == args) {
            return Ok(Arc::clone(s));
        }
        let s = Arc::new(args.settings(mech)?);
        *last = Some((args, Arc::clone(&s)));
        Ok(s)
    }
}

/// Run a simulation from `mech`'s `prepared` set-up and return its result, read as a dict (see
/// `planardyn.SimulationResult`), its values made at their first read.
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    prepared: &Prepared,
    last: &LastSettings,
    args: Overrides,
    drives: Option<Py<PyAny>>,
    motion: Vec<(usize, MotionArg)>,
    progress: Option<Py<PyAny>>,
    events: Vec<EventArg>,
    dense_output: bool,
) -> PyResult<PyRun> {
    let event_fatal = Mutex::new(None);
    let m = mech.dof();
    let mut py_drives = drives.map(|f| PyDrives { f, m, fatal: None });
    let mut motions = motion_entries(mech, motion)?;
    let mut fatal: Option<PyErr> = None;
    let mut cancel_reason: Option<String> = None;
    let traj = run(py, || {
        let s = last.settings(mech, args)?;
        let step = PROGRESS_FRACTION * (s.t_end - s.t0);
        let mut next = s.t0 + step;
        let mut last_check = Instant::now();
        let mut on_step = |t: f64| -> bool {
            let due = t >= next;
            if !due && last_check.elapsed() < SIGNAL_INTERVAL {
                return true;
            }
            last_check = Instant::now();
            Python::attach(|py| {
                if let Err(e) = py.check_signals() {
                    fatal = Some(e);
                    return false;
                }
                if !due {
                    return true;
                }
                next = t + step;
                let Some(cb) = &progress else { return true };
                match cb.bind(py).call1((t,)) {
                    Ok(r) => r.is_none() || r.is_truthy().unwrap_or(true),
                    Err(e) => {
                        let text = callback_error(py, e, &mut fatal);
                        cancel_reason = Some(format!("the progress callback raised {text} at t = {t} s"));
                        false
                    }
                }
            })
        };
        let mut model_drives = ModelDrives(mech);
        let d: &mut dyn Drives = match py_drives.as_mut() {
            Some(d) => d,
            None => &mut model_drives,
        };
        let mut prescribed = Prescribed::from_model(mech);
        for (k, entry) in motions.iter_mut() {
            let motion = match entry {
                MotionEntry::Law(law) => Motion::Law(law.clone()),
                MotionEntry::Function(f) => Motion::Function(f),
            };
            prescribed.set(*k, motion).map_err(|e| argument_error(Some("motion"), e))?;
        }
        let observe = Observe { events: core_events(&events, &event_fatal), dense_output };
        Ok(simulate_prepared(mech, prepared, &s, d, &mut prescribed, observe, Some(&mut on_step))?)
    })?;
    let motion_fatal = motions.into_iter().find_map(|(_, e)| match e {
        MotionEntry::Function(f) => f.fatal,
        MotionEntry::Law(_) => None,
    });
    let event_fatal = event_fatal.into_inner().unwrap_or_else(|poisoned| poisoned.into_inner());
    let fatal = fatal.or_else(|| py_drives.and_then(|d| d.fatal)).or(motion_fatal).or(event_fatal);
    match fatal {
        // Ctrl-C keeps the trajectory so far: `Mechanism.simulate` raises the interrupt with
        // it attached (`SimulationInterrupted.result`).
        Some(e) if e.is_instance_of::<PyKeyboardInterrupt>(py) => {
            let at = traj.t.last().copied().unwrap_or(0.0);
            let reason = format!("interrupted (KeyboardInterrupt) at t = {at} s");
            // Whether it came in the progress check or inside a drive callable, it is a cancel.
            let run = PyRun::new(traj, None);
            run.set(py, "status", planardyn::simulate::Status::Cancelled.name())?;
            run.set(py, "message", reason)?;
            run.set(py, "interrupt", e.value(py))?;
            Ok(run)
        }
        Some(e) => Err(e),
        None => Ok(PyRun::new(traj, cancel_reason)),
    }
}

/// The output columns of a simulation, as the core declares them
/// (`planardyn::simulate::columns::COLUMNS`), in a results file's order: (name, shape, unit,
/// doc, heading) each; the Python package's result, results files and their reading follow it.
#[pyfunction]
fn output_columns() -> Vec<(&'static str, &'static str, &'static str, &'static str, &'static str)> {
    COLUMNS.iter().map(|c| (c.name, c.shape.name(), c.unit, c.doc, c.heading)).collect()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(output_columns, m)?)
}
