//! `planardyn._core.Run`: a run's trajectory kept native, each entry (`t`, `q`, ..., `stats`)
//! made into Python values at its first read and kept (issue 25 item 4: a short run's result
//! is read in part or not at all, and building all 13 arrays and dicts up front cost more than
//! the run; a result read not at all makes not even its dict, nor its status). It reads as the
//! dict `to_dict` makes for the batch.

use crate::convert::{arr1, arr2};
use crate::exceptions::PlanardynError;
use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::ToPyArray;
use planardyn::simulate::columns::{self, Column, Shape, COLUMNS};
use planardyn::simulate::{Status, Trajectory};
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyList, PyString};
use std::sync::{Mutex, MutexGuard};

/// The entries besides the output columns, in a dict's order.
const OTHER_KEYS: [&str; 8] =
    ["t_events", "q_events", "qd_events", "sol", "change_points", "stats", "status", "message"];

/// A run's result: `run[key]` (`key` an output column, `t_events`, `q_events`, `qd_events`,
/// `sol`, `change_points`, `status`, `message`, `stats`, and `interrupt` after a Ctrl-C), made
/// from the trajectory at the first read and the same object after.
#[pyclass(frozen, module = "planardyn._core", name = "Run")]
pub struct PyRun {
    /// The trajectory; `sol` moves its dense output out at its first read.
    traj: Mutex<Trajectory>,
    /// A cancellation's reason, the message in place of the trajectory's.
    cancel_reason: Option<String>,
    /// The entries read (or set) so far, made at the first.
    values: PyOnceLock<Py<PyDict>>,
}

impl PyRun {
    /// The run's result; a cancellation's reason, if given, replaces the message.
    pub fn new(traj: Trajectory, cancel_reason: Option<String>) -> PyRun {
        PyRun { traj: Mutex::new(traj), cancel_reason, values: PyOnceLock::new() }
    }

    /// Set an entry (the status, message and interrupt of a run stopped by Ctrl-C).
    pub fn set<'py>(&self, py: Python<'py>, key: &str, value: impl IntoPyObject<'py>) -> PyResult<()> {
        self.values(py).set_item(key, value)
    }

    fn values<'py>(&self, py: Python<'py>) -> &Bound<'py, PyDict> {
        self.values.get_or_init(py, || PyDict::new(py).unbind()).bind(py)
    }

    fn trajectory(&self) -> MutexGuard<'_, Trajectory> {
        // Nothing panics while holding it; a poisoned lock still holds the whole trajectory.
        self.traj.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

#[pymethods]
impl PyRun {
    // The key as the caller's string object, looked up as it is (its hash kept), made into
    // a Rust string only for an entry not read before.
    fn __getitem__<'py>(&self, py: Python<'py>, key: &Bound<'py, PyString>) -> PyResult<Bound<'py, PyAny>> {
        let values = self.values(py);
        if let Some(v) = values.get_item(key)? {
            return Ok(v);
        }
        let made = entry(py, key.to_str()?, &mut self.trajectory(), self.cancel_reason.as_deref())?;
        let v = made.ok_or_else(|| PyKeyError::new_err(key.clone().unbind()))?;
        values.set_item(key, &v)?;
        Ok(v)
    }

    #[pyo3(signature = (key, default=None))]
    fn get<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyString>,
        default: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        match self.__getitem__(py, key) {
            Err(e) if e.is_instance_of::<PyKeyError>(py) => Ok(default.unwrap_or_else(|| py.None().into_bound(py))),
            v => v,
        }
    }

    fn __contains__<'py>(&self, py: Python<'py>, key: &Bound<'py, PyString>) -> PyResult<bool> {
        let set = self.values.get(py).map(|v| v.bind(py).contains(key)).transpose()?;
        Ok(set == Some(true) || is_entry(key.to_str()?))
    }

    fn __repr__(&self) -> String {
        let t = self.trajectory();
        format!("<planardyn._core.Run {}: {} rows>", t.status.name(), t.len())
    }
}

fn is_entry(key: &str) -> bool {
    COLUMNS.iter().any(|c| c.name == key) || OTHER_KEYS.contains(&key)
}

fn message<'a>(t: &'a Trajectory, cancel_reason: Option<&'a str>) -> &'a str {
    match (t.status, cancel_reason) {
        (Status::Cancelled, Some(reason)) => reason,
        _ => &t.message,
    }
}

/// The trajectory as a dict of every entry (arrays time-major), as the batch returns it; a
/// cancellation's reason, if given, replaces the message.
pub(crate) fn to_dict(py: Python<'_>, mut t: Trajectory, cancel_reason: Option<String>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    for key in COLUMNS.iter().map(|c| c.name).chain(OTHER_KEYS) {
        d.set_item(key, entry(py, key, &mut t, cancel_reason.as_deref())?)?;
    }
    Ok(d)
}

/// Entry `key` of a run's result (None for no such entry; `sol` moves the dense output out), a
/// cancellation's reason, if given, the message.
fn entry<'py>(
    py: Python<'py>,
    key: &str,
    t: &mut Trajectory,
    cancel_reason: Option<&str>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    if let Some(c) = COLUMNS.iter().find(|c| c.name == key) {
        return column_array(py, c, t).map(Some);
    }
    let m = t.m;
    let event_rows = |rows: &[Vec<f64>]| -> PyResult<Bound<'py, PyAny>> {
        let arrays = rows.iter().map(|r| arr2(py, r.len() / m.max(1), m, r.clone())).collect::<PyResult<Vec<_>>>()?;
        Ok(PyList::new(py, arrays)?.into_any())
    };
    let ev = &t.events;
    Ok(Some(match key {
        "t_events" => PyList::new(py, ev.t.iter().map(|r| arr1(py, r.clone())))?.into_any(),
        "q_events" => event_rows(&ev.q)?,
        "qd_events" => event_rows(&ev.qd)?,
        "sol" => t.dense.take().map(|inner| crate::dense::PyDenseOutput { inner }).into_pyobject(py)?.into_any(),
        "change_points" => change_points(py, t)?.into_any(),
        "stats" => stats(py, t)?.into_any(),
        "status" => PyString::new(py, t.status.name()).into_any(),
        "message" => PyString::new(py, message(t, cancel_reason)).into_any(),
        _ => return Ok(None),
    }))
}

fn change_points<'py>(py: Python<'py>, t: &Trajectory) -> PyResult<Bound<'py, PyList>> {
    let points = PyList::empty(py);
    for p in &t.change_points {
        let c = PyDict::new(py);
        c.set_item("t", p.t)?;
        c.set_item("q", arr1(py, p.q.clone()))?;
        c.set_item("x", arr1(py, p.x.clone()))?;
        c.set_item("rank_drop", p.rank_drop)?;
        points.append(c)?;
    }
    Ok(points)
}

fn stats<'py>(py: Python<'py>, t: &Trajectory) -> PyResult<Bound<'py, PyDict>> {
    let st = &t.stats;
    let stats = PyDict::new(py);
    stats.set_item("nfev", st.integrator.nfev)?;
    stats.set_item("naccept", st.integrator.naccept)?;
    stats.set_item("nreject", st.integrator.nreject)?;
    stats.set_item("njev", st.integrator.njev)?;
    stats.set_item("nlu", st.integrator.nlu)?;
    stats.set_item("chart_switches", st.chart_switches)?;
    stats.set_item("partition_steps", st.partition_steps)?;
    stats.set_item("alt_steps", st.alt_steps)?;
    stats.set_item("max_residual", st.max_residual)?;
    // A run that failed before measuring anything has no least measure: None, not inf.
    stats.set_item("min_sigma", Some(st.min_sigma).filter(|s| s.is_finite()))?;
    stats.set_item("min_passive_sigma", Some(st.min_passive_sigma).filter(|s| s.is_finite()))?;
    stats.set_item("energy_drift", st.energy_drift)?;
    stats.set_item("failed_evaluations", st.failed_evaluations)?;
    Ok(stats)
}

/// Column `c` of `traj` as a numpy array (a copy): (N,) for a scalar, (N,) of bool for a flag,
/// (N, width) for a row per output.
fn column_array<'py>(py: Python<'py>, c: &Column, traj: &Trajectory) -> PyResult<Bound<'py, PyAny>> {
    match ((c.values)(traj), c.shape) {
        (columns::Values::Numbers(v), Shape::Coordinates | Shape::BodyPoses) => {
            let shape = (traj.len(), c.shape.width(traj.m, traj.nx));
            let rows = ArrayView2::from_shape(shape, v)
                .map_err(|e| PlanardynError::new_err(format!("output column {}: {e}", c.name)))?;
            Ok(rows.to_pyarray(py).into_any())
        }
        (columns::Values::Numbers(v), Shape::Scalar | Shape::Flag) => Ok(ArrayView1::from(v).to_pyarray(py).into_any()),
        (columns::Values::Flags(v), _) => Ok(ArrayView1::from(v).to_pyarray(py).into_any()),
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyRun>()
}
