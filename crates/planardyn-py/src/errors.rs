//! The one place where Rust errors become Python exceptions (the classes: exceptions.rs).
//!
//! Which core error becomes which exception:
//!
//! ```text
//! PlanardynError(Exception)
//! ├── ModelError(PlanardynError, ValueError)   a model file or dict that is not a mechanism
//! ├── ArgumentError(PlanardynError, ValueError) an argument of the wrong shape or value
//! ├── DataError(PlanardynError, ValueError)    a data file or table that cannot be used
//! ├── AssemblyError                            KinematicsError::AssemblyFailed
//! ├── SingularityError                         KinematicsError::Singular, Error::BranchUndecided
//! └── SimulationError                          Error::Setting (but t_end's), Error::Options, Error::Drive
//! ```
//!
//! Pair friction that does not settle (`KinematicsError::FrictionUnsettled`: the mechanism
//! self-locks) is a `PlanardynError` with attributes `iterations` and `change`.
//!
//! A task motion's failures (`TaskError`) are `SingularityError` and `AssemblyError` too, with
//! the data of where the motion stopped as attributes. A failure at one row of a trajectory
//! (`Error::Row`) is its row's error, with attributes `row` and `t` and the row in the message.
//!
//! A setting that breaks its rule (`Error::Setting`) is a `SimulationError` "invalid option:
//! ...", but t_end's, an argument of every run, an `ArgumentError`.
//!
//! Shape and value errors in the arguments (`KinematicsError::BadArgument`, and the glue's own
//! shape and finiteness checks) are `ArgumentError`s, attribute `argument` naming it (None where
//! no one argument is at fault), and so are finite arguments whose results overflow
//! (`KinematicsError::Overflow`, attribute `quantity`). Both classes are also `ValueError`s, as
//! such errors were before they had their own class. `DataError` is raised by the Python side
//! (results files, measured motions, data that cannot identify). A core error of a kind added
//! later is a `PlanardynError`. A Rust panic never
//! reaches Python as `PanicException`: [`run`] catches it and raises `PlanardynError` asking
//! for a bug report.

use crate::convert::solution_dict;
use crate::exceptions::{
    argument_error, attr, model_error_type, set_attrs, with_attrs, AssemblyError, PlanardynError, SimulationError,
    SingularityError,
};
use planardyn::dynamics::task::{TaskError, TaskSolution};
use planardyn::error::{Setting, SettingError};
use planardyn::kinematics::EffectorError;
use planardyn::{Error, KinematicsError, ModelError as CoreModelError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// A core model error as `ModelError` with `.source` and `.path`.
pub fn model_error(py: Python<'_>, e: &CoreModelError) -> PyErr {
    let (source, path) = match e {
        CoreModelError::Parse { source_name, path, .. } | CoreModelError::Invalid { source_name, path, .. } => {
            (source_name.clone(), path.clone())
        }
        _ => (String::new(), e.path().to_string()),
    };
    let ty = match model_error_type(py) {
        Ok(t) => t.clone(),
        Err(err) => return err,
    };
    let err = PyErr::from_type(ty, e.to_string());
    let Ok(source) = source.into_pyobject(py);
    let Ok(path) = path.into_pyobject(py);
    with_attrs(py, err, &[("source", source.into_any().unbind()), ("path", path.into_any().unbind())])
}

/// A kinematics error as the matching exception.
pub fn kinematics_error(py: Python<'_>, e: &KinematicsError) -> PyErr {
    match e {
        KinematicsError::AssemblyFailed { residual, iterations } => {
            let Ok(r) = residual.into_pyobject(py);
            let Ok(i) = iterations.into_pyobject(py);
            let attrs = [("residual", r.into_any().unbind()), ("iterations", i.into_any().unbind())];
            with_attrs(py, AssemblyError::new_err(e.to_string()), &attrs)
        }
        KinematicsError::Singular { kind, sigma_min } => {
            let Ok(s) = sigma_min.into_pyobject(py);
            let Ok(k) = kind.name().into_pyobject(py);
            let attrs = [("kind", k.into_any().unbind()), ("sigma_min", s.into_any().unbind())];
            with_attrs(py, SingularityError::new_err(e.to_string()), &attrs)
        }
        KinematicsError::Overflow { what } => {
            let Ok(w) = what.into_pyobject(py);
            with_attrs(py, argument_error(None, e.to_string()), &[("quantity", w.into_any().unbind())])
        }
        KinematicsError::BadArgument { name, .. } => argument_error(Some(name), e.to_string()),
        KinematicsError::FrictionUnsettled { iterations, change } => {
            let Ok(i) = iterations.into_pyobject(py);
            let Ok(c) = change.into_pyobject(py);
            let attrs = [("iterations", i.into_any().unbind()), ("change", c.into_any().unbind())];
            with_attrs(py, PlanardynError::new_err(e.to_string()), &attrs)
        }
        _ => PlanardynError::new_err(e.to_string()),
    }
}

/// An inverse-kinematics failure: `AssemblyError` (attributes `X` the target, `residual`,
/// `iterations`) when Newton does not converge, else as its kinematics error.
pub fn effector_error(py: Python<'_>, e: &EffectorError) -> PyErr {
    match e {
        EffectorError::Kinematics(k) => kinematics_error(py, k),
        EffectorError::OutOfReach { target, residual, iterations } => {
            let attrs = vec![
                ("X", attr(py, target.clone())),
                ("residual", attr(py, *residual)),
                ("iterations", attr(py, *iterations)),
            ];
            set_attrs(py, AssemblyError::new_err(e.to_string()), attrs)
        }
        _ => PlanardynError::new_err(e.to_string()),
    }
}

/// A task motion that failed: `SingularityError` (attributes `kind` 'I' or 'II', `t` (s), `X`
/// (k,), `q` (m,), `sigma`, `tol`) or `AssemblyError` (attribute `t`), both with `partial_rows`,
/// the dict of the motion solved before the failure (see `convert::solution_dict`).
pub fn task_error(py: Python<'_>, e: &TaskError) -> PyErr {
    let partial = |p: &TaskSolution, m: usize| solution_dict(py, p.clone(), m).ok().map(|d| d.into_any().unbind());
    match e {
        TaskError::Core(core) => to_pyerr(py, core),
        TaskError::Singular { kind, t, x, q, sigma, tol, partial: p, .. } => {
            let attrs = vec![
                ("kind", attr(py, kind.label())),
                ("t", attr(py, *t)),
                ("X", attr(py, x.clone())),
                ("q", attr(py, q.clone())),
                ("sigma", attr(py, *sigma)),
                ("tol", attr(py, *tol)),
                ("partial_rows", partial(p, q.len())),
            ];
            set_attrs(py, SingularityError::new_err(e.to_string()), attrs)
        }
        TaskError::OutOfReach { t, partial: p, .. } => {
            let m = p.q.len().checked_div(p.len()).unwrap_or(0);
            let attrs = vec![("t", attr(py, *t)), ("partial_rows", partial(p, m))];
            set_attrs(py, AssemblyError::new_err(e.to_string()), attrs)
        }
        _ => PlanardynError::new_err(e.to_string()),
    }
}

/// A setting that breaks its rule: t_end (an argument of every run) an `ArgumentError`
/// naming it, a solver option a `SimulationError` "invalid option: ...".
pub fn setting_error(e: &SettingError) -> PyErr {
    match e.setting {
        Setting::TEnd => argument_error(Some(e.setting.name()), e.to_string()),
        _ => SimulationError::new_err(Error::Setting(e.clone()).to_string()),
    }
}

/// Any core error as a Python exception.
pub fn to_pyerr(py: Python<'_>, e: &Error) -> PyErr {
    match e {
        Error::Model(m) => model_error(py, m),
        Error::Kinematics(k) => kinematics_error(py, k),
        Error::Setting(s) => setting_error(s),
        Error::Options(_) | Error::Drive { .. } => SimulationError::new_err(e.to_string()),
        Error::BranchUndecided { row, sigma_min, .. } => {
            let attrs = vec![("kind", attr(py, "II")), ("row", attr(py, *row)), ("sigma_min", attr(py, *sigma_min))];
            set_attrs(py, SingularityError::new_err(e.to_string()), attrs)
        }
        // The row's own error class, its message prefixed with the row, attributes `row`, `t`.
        Error::Row { row, t, source } => {
            let err = to_pyerr(py, source);
            let attrs = vec![("args", attr(py, (e.to_string(),))), ("row", attr(py, *row)), ("t", attr(py, *t))];
            set_attrs(py, err, attrs)
        }
        _ => PlanardynError::new_err(e.to_string()),
    }
}

/// What a computation run by [`run`] can fail with.
pub enum Failure {
    Core(Error),
    /// Already a Python exception (a bad argument found inside, an exception from a callback).
    Py(PyErr),
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure::Core(e)
    }
}
impl From<KinematicsError> for Failure {
    fn from(e: KinematicsError) -> Self {
        Failure::Core(e.into())
    }
}
impl From<CoreModelError> for Failure {
    fn from(e: CoreModelError) -> Self {
        Failure::Core(e.into())
    }
}
impl From<PyErr> for Failure {
    fn from(e: PyErr) -> Self {
        Failure::Py(e)
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string())
}

/// Run a core computation with the GIL released (callbacks re-attach), turning its errors
/// into Python exceptions and a panic into `PlanardynError` (a bug to report).
pub fn run<T: Send>(py: Python<'_>, f: impl FnOnce() -> Result<T, Failure> + Send) -> PyResult<T> {
    let outcome = py.detach(|| catch_unwind(AssertUnwindSafe(f)));
    match outcome {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(Failure::Core(e))) => Err(to_pyerr(py, &e)),
        Ok(Err(Failure::Py(e))) => Err(e),
        Err(payload) => Err(PlanardynError::new_err(format!(
            "internal error in planardyn (a bug: please report it with the model and the call \
             that caused it): {}",
            panic_message(payload.as_ref())
        ))),
    }
}
