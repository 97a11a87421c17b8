//! `planardyn._core.simulate_batch`: many variants in one call, on a rayon pool of Rust
//! threads with the GIL released (no Python in the loop). Each variant is a native
//! `Mechanism` and a dict of overrides; each result is a trajectory dict (as
//! `Mechanism.simulate` returns) or, for a variant that failed, the pair
//! (exception type name, message) that `Mechanism.simulate` would have raised. Given a
//! callable `finish(k, outcome)`, its return value takes the place of variant k's outcome.
//!
//! Each worker converts its own outcome (and calls `finish`), holding the GIL only for that:
//! the conversion of one run overlaps the next runs on the other threads, and the calling
//! thread only collects the results (it did every conversion, a quarter of a short batch's
//! CPU time, while the workers waited).
//!
//! `planardyn._core.inverse_batch` does the same for inverse dynamics: each variant a
//! native `Mechanism` and a motion dict, either coordinate rows (`q`, `qd`, `qdd`) or a
//! sampled end-effector path (`t`, `X`, `Xd`, `Xdd`, `point`, ...), on the same pool.

use crate::convert::{arr2, solution_dict};
use crate::errors::{run, task_error, to_pyerr, Failure};
use crate::exceptions::{argument_error, PlanardynError};
use crate::mechanism::PyMechanism;
use crate::simulate::{motion_entries, MotionEntry, SIGNAL_INTERVAL};
use planardyn::batch::task::{TaskError, TaskPath};
use planardyn::batch::{map_many_until, Efforts, InverseVariant, Motion, Overrides, Variant};
use planardyn::simulate::Prepared;
use planardyn::Mechanism;
use pyo3::ffi;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};

/// Keys a variant's overrides dict may have (the keyword arguments of `Mechanism.simulate`
/// that need no Python callback).
const KEYS: [&str; 11] =
    ["t_end", "method", "rtol", "atol", "dt", "t_eval", "output_dt", "q0", "qd0", "max_steps", "motion"];

/// Keys of an inverse-dynamics motion dict: coordinate rows, or a sampled task path.
const MOTION_KEYS: [&str; 11] = ["q", "qd", "qdd", "t", "X", "Xd", "Xdd", "point", "body", "q_start", "singular_tol"];

fn get<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, k: &str) -> PyResult<Option<T>> {
    match d.get_item(k)? {
        Some(v) if !v.is_none() => {
            Ok(Some(v.extract::<T>().map_err(|e| argument_error(Some(k), format!("{k}: {}", Into::<PyErr>::into(e))))?))
        }
        _ => Ok(None),
    }
}

fn require<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, k: &str) -> PyResult<T> {
    get(d, k)?.ok_or_else(|| argument_error(Some(k), format!("the motion needs {k:?}")))
}

fn check_keys(d: &Bound<'_, PyDict>, keys: &[&str], what: &str) -> PyResult<()> {
    for k in d.keys() {
        let k: String = k.extract()?;
        if !keys.contains(&k.as_str()) {
            return Err(argument_error(Some(&k), format!("unknown {what} {k:?}; expected one of {}", keys.join(", "))));
        }
    }
    Ok(())
}

fn overrides(mech: &Mechanism, d: &Bound<'_, PyDict>) -> PyResult<Overrides> {
    check_keys(d, &KEYS, "simulation setting")?;
    // A batch runs without the GIL: its motions are laws (speeds, tables), not callables.
    let motion = motion_entries(mech, get(d, "motion")?.unwrap_or_default())?
        .into_iter()
        .map(|(k, entry)| match entry {
            MotionEntry::Law(law) => Ok((k, law)),
            MotionEntry::Function(_) => Err(argument_error(
                Some("motion"),
                "a batch's motions are speeds or tables; a Python function runs only in Mechanism.simulate",
            )),
        })
        .collect::<PyResult<Vec<_>>>()?;
    Ok(Overrides {
        t_end: get(d, "t_end")?,
        method: get(d, "method")?,
        rtol: get(d, "rtol")?,
        atol: get(d, "atol")?,
        dt: get(d, "dt")?,
        t_eval: get(d, "t_eval")?,
        output_dt: get(d, "output_dt")?,
        q0: get(d, "q0")?,
        qd0: get(d, "qd0")?,
        max_steps: get(d, "max_steps")?,
        motion,
    })
}

/// `f(stop)` on a worker thread with the GIL released, while this thread checks for Ctrl-C
/// every `SIGNAL_INTERVAL`: on one, `stop` is set (the work winds down and returns what it
/// has) and the KeyboardInterrupt is handed back with the result.
fn run_until_interrupt<T: Send>(
    py: Python<'_>,
    f: impl FnOnce(&AtomicBool) -> Result<T, Failure> + Send,
) -> PyResult<(T, Option<PyErr>)> {
    let stop = AtomicBool::new(false);
    let mut interrupt = None;
    let out = run(py, || {
        std::thread::scope(|s| {
            let (tx, rx) = mpsc::channel();
            let stop = &stop;
            // A panic in the worker is re-raised by the scope, where `run` catches it.
            s.spawn(move || tx.send(f(stop)));
            loop {
                match rx.recv_timeout(SIGNAL_INTERVAL) {
                    Ok(done) => return done,
                    Err(mpsc::RecvTimeoutError::Timeout) if interrupt.is_none() => {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            interrupt = Some(e);
                            stop.store(true, Ordering::Relaxed);
                        }
                    }
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                    Err(mpsc::RecvTimeoutError::Disconnected) => {
                        return Err(PlanardynError::new_err("the batch worker stopped without a result").into());
                    }
                }
            }
        })
    })?;
    Ok((out, interrupt))
}

/// The native variants (`make` from each pair), solved by `solve` on the batch pool with
/// the GIL released; each outcome turned into a Python object by `out`, then by `finish`
/// (called with the variant's index and that object) when given, in the worker that solved
/// it; in input order. The first error `out` or `finish` raised, in input order, is raised.
/// On Ctrl-C the KeyboardInterrupt is raised with the list as its attribute `partial`: the
/// variants finished, those stopped on the way (`solve` sees the stop flag), and
/// ("Cancelled", reason) for the rest.
fn run_batch<'py, V: Sync, R>(
    py: Python<'py>,
    variants: &[(Bound<'py, PyMechanism>, Bound<'py, PyDict>)],
    threads: Option<usize>,
    finish: Option<Py<PyAny>>,
    make: impl Fn(&Bound<'py, PyMechanism>, &Bound<'py, PyDict>) -> PyResult<V>,
    solve: impl Fn(&V, &AtomicBool) -> R + Sync + Send,
    out: impl Fn(Python<'_>, R, &V) -> PyResult<Py<PyAny>> + Sync + Send,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let vs = variants.iter().map(|(m, d)| make(m, d)).collect::<PyResult<Vec<_>>>()?;
    let items: Vec<(usize, V)> = vs.into_iter().enumerate().collect();
    let one = |(k, v): &(usize, V), stop: &AtomicBool| {
        let r = solve(v, stop);
        Python::attach(|py| match &finish {
            Some(f) => Ok(f.bind(py).call1((*k, out(py, r, v)?))?.unbind()),
            None => out(py, r, v),
        })
    };
    let (done, interrupt) = run_until_interrupt(py, |stop| {
        map_many_until(&items, threads, stop, one, (keep_thread_state, drop_thread_state)).map_err(Failure::from)
    })?;
    let results = done
        .into_iter()
        .map(|r| match r {
            Some(r) => r.map(|o| o.into_bound(py)),
            None => Ok(PyTuple::new(py, ["Cancelled", INTERRUPTED])?.into_any()),
        })
        .collect::<PyResult<Vec<_>>>()?;
    match interrupt {
        Some(e) => {
            e.value(py).setattr("partial", results)?;
            Err(e)
        }
        None => Ok(results),
    }
}

std::thread_local! {
    /// The interpreter state a batch thread keeps from [`keep_thread_state`] to
    /// [`drop_thread_state`], with its GIL-state token.
    static KEPT: Cell<Option<(*mut ffi::PyThreadState, ffi::PyGILState_STATE)>> = const { Cell::new(None) };
}

/// Give this batch thread an interpreter state for the whole batch, detached (the GIL not
/// held). Without one each variant's `Python::attach` made a state and freed it again
/// (`PyGILState_Ensure` / `Release` on a thread Python does not know), with its 16 KB frame
/// stack mapped and unmapped each time: an unmap in a process with two threads running flushes
/// the other core's TLB, and a batch of 20000 four-bar runs of 0.1 s spent a tenth of its time
/// there (perf), two threads only 1.16x as fast as one. With a kept state an attach only takes
/// the GIL. Made with `PyGILState_Ensure`, the state the GIL-state calls of `Python::attach`
/// find and reuse (one made otherwise they would not know), then detached by
/// `PyEval_SaveThread`; as pants' executor keeps its threads' (pantsbuild/pants #23489).
fn keep_thread_state() {
    // SAFETY: a pool thread starts a batch with no Python state (the last batch's
    // `drop_thread_state` released it) and without the GIL; `PyGILState_Ensure` makes its
    // state and takes the GIL, `PyEval_SaveThread` releases it, and both stay valid until the
    // paired calls in `drop_thread_state` on this same thread.
    unsafe {
        let gil = ffi::PyGILState_Ensure();
        KEPT.set(Some((ffi::PyEval_SaveThread(), gil)));
    }
}

/// Release the state [`keep_thread_state`] gave this thread: attached again, the last
/// GIL-state reference released, which has Python clear and free it.
fn drop_thread_state() {
    if let Some((state, gil)) = KEPT.take() {
        // SAFETY: `state` and `gil` come from `keep_thread_state` on this thread, which is
        // detached here (every variant's attach was released); the calling thread waits in the
        // batch call, so the interpreter is alive.
        unsafe {
            ffi::PyEval_RestoreThread(state);
            ffi::PyGILState_Release(gil);
        }
    }
}

/// Why a variant was not run, or stopped.
const INTERRUPTED: &str = "not run: interrupted (Ctrl-C)";

/// Simulate `(mechanism, overrides)` pairs on `threads` threads (None: all cores); results
/// (or `finish(k, outcome)`) in input order.
#[pyfunction]
#[pyo3(signature = (variants, threads=None, finish=None))]
fn simulate_batch<'py>(
    py: Python<'py>,
    variants: Vec<(Bound<'py, PyMechanism>, Bound<'py, PyDict>)>,
    threads: Option<usize>,
    finish: Option<Py<PyAny>>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    // Each variant runs from its mechanism's prepared set-up, made once for all its runs.
    let make = |m: &Bound<'py, PyMechanism>, d: &Bound<'py, PyDict>| {
        let (mech, prepared) = (m.get(), m.get().prepared(py).clone());
        Ok((Variant { model: mech.inner.clone(), overrides: overrides(&mech.inner, d)? }, prepared))
    };
    let solve = |(v, prepared): &(Variant, Arc<Prepared>), stop: &AtomicBool| v.simulate_prepared(prepared, stop);
    run_batch(py, &variants, threads, finish, make, solve, |py, r, _| match r {
        // A batch's runs are cancelled only by Ctrl-C.
        Ok(traj) => Ok(crate::run::to_dict(py, traj, Some("interrupted (Ctrl-C)".to_string()))?.into_any().unbind()),
        Err(e) => error_pair(py, to_pyerr(py, &e), e.to_string()),
    })
}

/// A motion dict: `q`, `qd`, `qdd` (flat rows), or `t`, `X`, `Xd`, `Xdd` (flat rows) with
/// `point` and optionally `body`, `q_start`, `singular_tol`.
fn motion(d: &Bound<'_, PyDict>) -> PyResult<Motion> {
    check_keys(d, &MOTION_KEYS, "motion key")?;
    if d.contains("t")? {
        return Ok(Motion::Task(TaskPath {
            t: require(d, "t")?,
            x: require(d, "X")?,
            xd: require(d, "Xd")?,
            xdd: require(d, "Xdd")?,
            point: require(d, "point")?,
            body: get(d, "body")?,
            q_start: get(d, "q_start")?,
            singular_tol: require(d, "singular_tol")?,
        }));
    }
    Ok(Motion::Coordinates { q: require(d, "q")?, qd: require(d, "qd")?, qdd: require(d, "qdd")? })
}

fn efforts_dict<'py>(py: Python<'py>, e: Efforts, m: usize) -> PyResult<Bound<'py, PyAny>> {
    let d = PyDict::new(py);
    let rows = |v: Vec<f64>| arr2(py, v.len() / m.max(1), m, v);
    match e {
        Efforts::Coordinates(tau) => d.set_item("tau", rows(tau)?)?,
        Efforts::Task(s) => return Ok(solution_dict(py, s, m)?.into_any()),
    }
    Ok(d.into_any())
}

/// (exception type name, message) of a failed variant, as the serial call would raise.
fn failure(py: Python<'_>, e: &TaskError) -> PyResult<Py<PyAny>> {
    error_pair(py, task_error(py, e), e.to_string())
}

/// The pair (exception type name, message) that reports a failed variant.
fn error_pair(py: Python<'_>, err: PyErr, message: String) -> PyResult<Py<PyAny>> {
    let name = err.get_type(py).name()?.to_string();
    Ok(PyTuple::new(py, [name, message])?.into_any().unbind())
}

/// Inverse dynamics of `(mechanism, motion)` pairs on `threads` threads (None: all cores);
/// results (dicts of arrays, or `finish(k, outcome)`) in input order.
#[pyfunction]
#[pyo3(signature = (variants, threads=None, finish=None))]
fn inverse_batch<'py>(
    py: Python<'py>,
    variants: Vec<(Bound<'py, PyMechanism>, Bound<'py, PyDict>)>,
    threads: Option<usize>,
    finish: Option<Py<PyAny>>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let make = |m: &Bound<'py, PyMechanism>, d: &Bound<'py, PyDict>| {
        Ok(InverseVariant { model: m.get().inner.clone(), motion: motion(d)? })
    };
    run_batch(
        py,
        &variants,
        threads,
        finish,
        make,
        |v, _| v.solve(),
        |py, r, v| match r {
            Ok(e) => Ok(efforts_dict(py, e, v.model.dof())?.unbind()),
            Err(e) => failure(py, &e),
        },
    )
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate_batch, m)?)?;
    m.add_function(wrap_pyfunction!(inverse_batch, m)?)
}
