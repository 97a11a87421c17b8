//! The Python exception classes of planardyn (all importable from `planardyn`: `PlanardynError`
//! and below it `ModelError`, `ArgumentError`, `DataError`, `AssemblyError`, `SingularityError`,
//! `SimulationError`; the tree and which core error becomes which: errors.rs), and the
//! `ArgumentError` of a bad argument. The bottom of the glue: convert.rs raises these on a bad
//! array, errors.rs maps the core's errors to them (with the motion solved so far as
//! convert.rs's arrays), so neither references the other's layer back.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};
use pyo3::IntoPyObjectExt;

create_exception!(planardyn, PlanardynError, PyException, "Base class of every error planardyn raises.");
create_exception!(
    planardyn,
    AssemblyError,
    PlanardynError,
    "The position analysis did not converge: the mechanism cannot be assembled at these \
     coordinates (attributes `residual`, `iterations`)."
);
create_exception!(
    planardyn,
    SingularityError,
    PlanardynError,
    "The mechanism is singular at this configuration (attributes `kind`: which matrix lost rank, \
     e.g. 'type_ii' or 'passive'; `sigma_min`: the smallest scaled singular value, None where \
     a failed factorisation measured none)."
);
create_exception!(
    planardyn,
    SimulationError,
    PlanardynError,
    "Invalid simulation options, or a run that could not start."
);

/// The classes that are both a `PlanardynError` and a `ValueError`, made with `type(...)`
/// (`create_exception!` takes one base): their name and docstring.
const MODEL_ERROR_DOC: &str = "A model that cannot be built: malformed YAML/JSON, a wrong field, or a drawing \
     that is not a mechanism. The message names the source and the field path; attributes `source` (file or \
     '<string>') and `path` (e.g. 'bodies.crank.mass', or 'line 3 column 5' where no field can be named).";
const ARGUMENT_ERROR_DOC: &str = "An argument planardyn cannot compute with: the wrong shape, a NaN or an infinity, \
     a value out of its range (zero, negative, too large), or finite values whose result overflows. The message \
     names the argument and says what it must be; attribute `argument` (its name, or None).";
const DATA_ERROR_DOC: &str = "Data planardyn cannot use: a results file or motion table that is damaged or not \
     one, a measured motion with a NaN, too few rows, or rows that cannot identify the parameters. The message \
     names the file (or the argument) and says what to change; attribute `path` (the file, or None).";

static MODEL_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static ARGUMENT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static DATA_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn value_error_type<'py>(
    py: Python<'py>,
    cell: &'static PyOnceLock<Py<PyType>>,
    name: &str,
    doc: &str,
) -> PyResult<&'py Bound<'py, PyType>> {
    cell.get_or_try_init(py, || {
        let bases = PyTuple::new(py, [py.get_type::<PlanardynError>(), py.get_type::<PyValueError>()])?;
        let ns = PyDict::new(py);
        ns.set_item("__module__", "planardyn")?;
        ns.set_item("__doc__", doc)?;
        let ty = py.get_type::<PyType>().call1((name, bases, ns))?;
        Ok::<_, PyErr>(ty.cast_into::<PyType>()?.unbind())
    })
    .map(|t| t.bind(py))
}

/// `ModelError(PlanardynError, ValueError)`, attributes `source` and `path`.
pub fn model_error_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    value_error_type(py, &MODEL_ERROR, "ModelError", MODEL_ERROR_DOC)
}

/// `ArgumentError(PlanardynError, ValueError)`, attribute `argument`.
pub fn argument_error_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    value_error_type(py, &ARGUMENT_ERROR, "ArgumentError", ARGUMENT_ERROR_DOC)
}

/// `DataError(PlanardynError, ValueError)`, attribute `path`.
pub fn data_error_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    value_error_type(py, &DATA_ERROR, "DataError", DATA_ERROR_DOC)
}

/// An `ArgumentError` for argument `name` (None: no one argument) with `message`.
pub fn argument_error(name: Option<&str>, message: impl Into<String>) -> PyErr {
    let message = message.into();
    Python::attach(|py| {
        let ty = match argument_error_type(py) {
            Ok(t) => t.clone(),
            Err(err) => return err,
        };
        let err = PyErr::from_type(ty, message);
        set_attrs(py, err, vec![("argument", attr(py, name))])
    })
}

/// Register the exception classes in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("PlanardynError", py.get_type::<PlanardynError>())?;
    m.add("ModelError", model_error_type(py)?)?;
    m.add("ArgumentError", argument_error_type(py)?)?;
    m.add("DataError", data_error_type(py)?)?;
    m.add("AssemblyError", py.get_type::<AssemblyError>())?;
    m.add("SingularityError", py.get_type::<SingularityError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    Ok(())
}

/// `err` with attributes set on its value.
pub fn with_attrs(py: Python<'_>, err: PyErr, attrs: &[(&str, Py<PyAny>)]) -> PyErr {
    let value = err.value(py);
    for (name, v) in attrs {
        // An attribute that cannot be set only loses detail: the message has it all.
        let _ = value.setattr(*name, v.bind(py));
    }
    err
}

/// A value as a Python object for an attribute (None if it cannot be converted).
pub fn attr<'py, T: IntoPyObject<'py>>(py: Python<'py>, v: T) -> Option<Py<PyAny>> {
    v.into_py_any(py).ok()
}

/// `err` with the attributes that could be converted set on its value.
pub fn set_attrs(py: Python<'_>, err: PyErr, attrs: Vec<(&str, Option<Py<PyAny>>)>) -> PyErr {
    let attrs: Vec<(&str, Py<PyAny>)> = attrs.into_iter().filter_map(|(k, v)| v.map(|v| (k, v))).collect();
    with_attrs(py, err, &attrs)
}
