//! `planardyn._core.simulate_batch`: many variants in one call, on a rayon pool of Rust
//! threads with the GIL released (no Python in the loop). Each variant is a native
//! `Mechanism` and a dict of overrides; each result is a trajectory dict (as
//! `Mechanism.simulate` returns) or, for a variant that failed, the pair
//! (exception type name, message) that `Mechanism.simulate` would have raised.

use crate::errors::{run, to_pyerr, Failure};
use crate::mechanism::PyMechanism;
use planardyn::batch::{simulate_many, Model, Overrides, Variant};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// Keys a variant's overrides dict may have (the keyword arguments of `Mechanism.simulate`
/// that need no Python callback).
const KEYS: [&str; 10] = ["t_end", "method", "rtol", "atol", "dt", "t_eval", "output_dt", "q0", "qd0", "max_steps"];

fn overrides(d: &Bound<'_, PyDict>) -> PyResult<Overrides> {
    for k in d.keys() {
        let k: String = k.extract()?;
        if !KEYS.contains(&k.as_str()) {
            return Err(PyValueError::new_err(format!("unknown simulation setting {k:?}; expected one of {}", KEYS.join(", "))));
        }
    }
    fn get<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, k: &str) -> PyResult<Option<T>> {
        match d.get_item(k)? {
            Some(v) if !v.is_none() => Ok(Some(v.extract::<T>().map_err(|e| PyValueError::new_err(format!("{k}: {}", Into::<PyErr>::into(e))))?)),
            _ => Ok(None),
        }
    }
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
    })
}

/// Simulate `(mechanism, overrides)` pairs on `threads` threads (None: all cores); results
/// in input order.
#[pyfunction]
#[pyo3(signature = (variants, threads=None))]
fn simulate_batch<'py>(py: Python<'py>, variants: Vec<(Bound<'py, PyMechanism>, Bound<'py, PyDict>)>, threads: Option<usize>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let vs = variants
        .iter()
        .map(|(m, d)| Ok(Variant { model: Model::Built(m.get().inner.clone()), overrides: overrides(d)? }))
        .collect::<PyResult<Vec<_>>>()?;
    let out = run(py, || simulate_many(&vs, threads).map_err(Failure::from))?;
    out.into_iter()
        .map(|r| match r {
            Ok(traj) => Ok(crate::simulate::to_dict(py, traj, None)?.into_any()),
            Err(e) => {
                let err = to_pyerr(py, &e);
                let name = err.get_type(py).name()?.to_string();
                Ok(PyTuple::new(py, [name, e.to_string()])?.into_any())
            }
        })
        .collect()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate_batch, m)?)
}
