//! `planardyn._core.simulate_batch`: many variants in one call, on a rayon pool of Rust
//! threads with the GIL released (no Python in the loop). Each variant is a native
//! `Mechanism` and a dict of overrides; each result is a trajectory dict (as
//! `Mechanism.simulate` returns) or, for a variant that failed, the pair
//! (exception type name, message) that `Mechanism.simulate` would have raised.

use crate::errors::{run, to_pyerr, Failure};
use crate::mechanism::PyMechanism;
use planardyn::batch::{simulate_many, Model, Overrides, Variant};
use planardyn::simulate::Trajectory;
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
            Ok(traj) => Ok(to_dict(py, traj)?.into_any()),
            Err(e) => {
                let err = to_pyerr(py, &e);
                let name = err.get_type(py).name()?.to_string();
                Ok(PyTuple::new(py, [name, e.to_string()])?.into_any())
            }
        })
        .collect()
}

/// The trajectory as `Mechanism.simulate`'s dict (see `simulate.rs`, whose keys it mirrors).
fn to_dict(py: Python<'_>, t: Trajectory) -> PyResult<Bound<'_, PyDict>> {
    use crate::convert::{arr1, arr2, bool1};
    let (n, m, nx) = (t.len(), t.m, t.nx);
    let d = PyDict::new(py);
    d.set_item("t", arr1(py, t.t))?;
    d.set_item("q", arr2(py, n, m, t.q)?)?;
    d.set_item("qd", arr2(py, n, m, t.qd)?)?;
    d.set_item("qdd", arr2(py, n, m, t.qdd)?)?;
    d.set_item("tau", arr2(py, n, m, t.tau)?)?;
    d.set_item("x", arr2(py, n, nx, t.x)?)?;
    d.set_item("xd", arr2(py, n, nx, t.xd)?)?;
    d.set_item("kinetic", arr1(py, t.kinetic))?;
    d.set_item("potential", arr1(py, t.potential))?;
    d.set_item("work", arr1(py, t.work))?;
    d.set_item("sigma", arr1(py, t.sigma))?;
    d.set_item("residual", arr1(py, t.residual))?;
    d.set_item("partitioned", bool1(py, t.partitioned))?;
    d.set_item("status", t.status.name())?;
    d.set_item("message", t.message)?;
    let st = &t.stats;
    let stats = PyDict::new(py);
    stats.set_item("nfev", st.integrator.nfev)?;
    stats.set_item("naccept", st.integrator.naccept)?;
    stats.set_item("nreject", st.integrator.nreject)?;
    stats.set_item("njev", st.integrator.njev)?;
    stats.set_item("nlu", st.integrator.nlu)?;
    stats.set_item("chart_switches", st.chart_switches)?;
    stats.set_item("partition_steps", st.partition_steps)?;
    stats.set_item("max_residual", st.max_residual)?;
    stats.set_item("min_sigma", st.min_sigma)?;
    stats.set_item("min_passive_sigma", st.min_passive_sigma)?;
    stats.set_item("energy_drift", st.energy_drift)?;
    d.set_item("stats", stats)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate_batch, m)?)
}
