//! The rule of each simulation setting given as a number, the core's (`planardyn::error::Setting`),
//! for the Python package's own check (`planardyn.settings`: the API, the batch runner, the CLI).

use crate::errors::setting_error;
use crate::exceptions::argument_error;
use planardyn::error::{Setting, MAX_STEPS, MIN_RTOL};
use pyo3::prelude::*;

/// `value` if it keeps the rule of the setting `name` (t_end, rtol, atol, dt, output_dt,
/// max_steps), else the error naming it: `ArgumentError` for t_end, `SimulationError`
/// "invalid option: ..." for a solver option.
#[pyfunction]
fn check_setting(name: &str, value: f64) -> PyResult<f64> {
    let setting = Setting::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Setting::ALL.iter().map(|s| s.name()).collect();
        argument_error(Some("name"), format!("no setting {name:?}: use one of {}", names.join(", ")))
    })?;
    setting.check(value).map_err(|e| setting_error(&e))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MIN_RTOL", MIN_RTOL)?;
    m.add("MAX_STEPS", MAX_STEPS as u64)?;
    m.add_function(wrap_pyfunction!(check_setting, m)?)
}
