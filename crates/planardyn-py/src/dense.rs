//! `planardyn._core.DenseOutput`: a run's continuous solution (the core's
//! `simulate::DenseOutput`), called with times to give q and qd there.

use crate::convert::{arr1, arr2, Floats, Values};
use crate::exceptions::argument_error;
use planardyn::simulate::DenseOutput;
use pyo3::prelude::*;

#[pyclass(frozen, module = "planardyn._core", name = "DenseOutput")]
pub struct PyDenseOutput {
    pub inner: DenseOutput,
}

#[pymethods]
impl PyDenseOutput {
    /// (q, qd) at time(s) t (s): (m,) each for a number, (K, m) each for (K,) times.
    fn __call__<'py>(&self, py: Python<'py>, t: Floats<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let v = Values::read(&t);
        if v.shape.len() > 1 {
            return Err(argument_error(
                Some("t"),
                format!("sol(t) takes a time or a 1-D array of times, got shape {:?}", v.shape),
            ));
        }
        let m = self.inner.m;
        let (mut q, mut qd) = (vec![0.0; v.data.len() * m], vec![0.0; v.data.len() * m]);
        for (k, &tk) in v.data.iter().enumerate() {
            self.inner
                .eval(tk, &mut q[k * m..(k + 1) * m], &mut qd[k * m..(k + 1) * m])
                .map_err(|e| argument_error(Some("t"), format!("sol(t): {e}")))?;
        }
        if v.shape.is_empty() {
            return Ok((arr1(py, q), arr1(py, qd)));
        }
        Ok((arr2(py, v.data.len(), m, q)?, arr2(py, v.data.len(), m, qd)?))
    }

    /// The time span [t_min, t_max] covered (s).
    #[getter]
    fn t_min(&self) -> f64 {
        self.inner.span().map_or(f64::NAN, |s| s.0)
    }

    #[getter]
    fn t_max(&self) -> f64 {
        self.inner.span().map_or(f64::NAN, |s| s.1)
    }

    /// Number of steps stored.
    #[getter]
    fn steps(&self) -> usize {
        self.inner.steps()
    }

    fn __repr__(&self) -> String {
        format!("<planardyn.DenseOutput over [{}, {}] s, {} steps>", self.t_min(), self.t_max(), self.inner.steps())
    }
}
