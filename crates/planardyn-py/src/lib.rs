//! PyO3 glue for planardyn: the native module `planardyn._core`. Conversions live in
//! `convert.rs`, the mapping of errors to Python exceptions in `errors.rs` (the only place; the
//! exception classes in `exceptions.rs`),
//! the `Mechanism` class in `mechanism.rs` (its model data in `model.rs`, its methods along
//! the rows of a motion in `rows.rs`; the core's typed query results converted in `query.rs`),
//! the end effector and task-space motions in `effector.rs`, the simulation entry point in
//! `simulate.rs` (its dense output in `dense.rs`) and the rule of each setting in `settings.rs`.
//! The typed Python face is the package `python/planardyn`; its stub `_core.pyi` mirrors
//! this module.

mod batch;
mod convert;
mod dense;
mod effector;
mod errors;
mod exceptions;
mod mechanism;
mod model;
mod query;
mod rows;
mod run;
mod settings;
mod simulate;
mod stiffness;
mod structure;

use errors::model_error;
use exceptions::{argument_error, PlanardynError};
use mechanism::PyMechanism;
use planardyn::Format;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

fn built(
    py: Python<'_>,
    result: std::thread::Result<Result<planardyn::Mechanism, planardyn::ModelError>>,
) -> PyResult<PyMechanism> {
    match result {
        Ok(Ok(m)) => Ok(PyMechanism::new(m)),
        Ok(Err(e)) => Err(model_error(py, &e)),
        Err(_) => Err(PlanardynError::new_err(
            "internal error in planardyn while building the model (a bug: please report it with the model file)",
        )),
    }
}

/// Load a model file (.yaml, .yml or .json; anything else is read as YAML).
#[pyfunction]
fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<PyMechanism> {
    let r = py.detach(|| catch_unwind(AssertUnwindSafe(|| planardyn::load(&path))));
    built(py, r)
}

/// Build a mechanism from model text; `format` is "yaml" or "json", `source` names it in messages.
#[pyfunction]
#[pyo3(signature = (text, format="yaml", source="<string>"))]
fn loads(py: Python<'_>, text: &str, format: &str, source: &str) -> PyResult<PyMechanism> {
    let format = format_arg(format)?;
    let (text, source) = (text.to_owned(), source.to_owned());
    let r = py.detach(|| catch_unwind(AssertUnwindSafe(|| planardyn::loads(&text, format, &source))));
    built(py, r)
}

/// Model text as the model holds it, as JSON text, not validated (quantities in SI, the points
/// given by construction at their coordinates, coordinate values as numbers), and the names
/// of the points the text gives by construction.
#[pyfunction]
#[pyo3(signature = (text, format="yaml", source="<string>"))]
fn resolve_model(py: Python<'_>, text: &str, format: &str, source: &str) -> PyResult<(String, Vec<String>)> {
    let (spec, constructed) = planardyn::loader::parse_spec_constructed(text, format_arg(format)?, source)
        .map_err(|e| model_error(py, &e))?;
    let json = serde_json::to_string(&spec)
        .map_err(|e| PlanardynError::new_err(format!("cannot write the model as JSON: {e}")))?;
    Ok((json, constructed))
}

fn format_arg(format: &str) -> PyResult<Format> {
    match format.to_ascii_lowercase().as_str() {
        "yaml" | "yml" => Ok(Format::Yaml),
        "json" => Ok(Format::Json),
        // A model given as a dict, as JSON: errors by field path, no line (from_dict).
        "data" => Ok(Format::Data),
        other => Err(argument_error(
            Some("format"),
            format!("format must be 'yaml', 'json' or 'data' (JSON of a model given as a dict), got {other:?}"),
        )),
    }
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyMechanism>()?;
    m.add_class::<dense::PyDenseOutput>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(loads, m)?)?;
    m.add_function(wrap_pyfunction!(resolve_model, m)?)?;
    exceptions::register(m)?;
    structure::register(m)?;
    batch::register(m)?;
    simulate::register(m)?;
    run::register(m)?;
    effector::register(m)?;
    stiffness::register(m)?;
    settings::register(m)?;
    Ok(())
}
