//! Conversions between numpy arrays (float64, C order, time-major) and the core's slices,
//! with shape checks whose messages name the argument, the expected shape and its meaning.

use crate::exceptions::{argument_error, PlanardynError};
use numpy::ndarray::{Array1, Array2, Array3, ArrayD, IxDyn};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLikeDyn, PyUntypedArrayMethods};
use planardyn::dynamics::task::TaskSolution;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::ops::Deref;

/// An array argument read as float64 (numpy's conversion of any array-like). Something numpy
/// cannot read as numbers (a string, a ragged list) is a `TypeError`, as an argument of the
/// wrong type is everywhere else, where numpy raises `ValueError`; pyo3 prefixes it with the
/// argument's name.
pub struct Floats<'py>(PyArrayLikeDyn<'py, f64, AllowTypeChange>);

impl<'a, 'py> FromPyObject<'a, 'py> for Floats<'py> {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let py = ob.py();
        <PyArrayLikeDyn<'py, f64, AllowTypeChange> as FromPyObject<'a, 'py>>::extract(ob).map(Floats).map_err(|e| {
            if e.is_instance_of::<PyValueError>(py) {
                PyTypeError::new_err(format!("an array of numbers is needed ({})", e.value(py)))
            } else {
                e
            }
        })
    }
}

impl<'py> Deref for Floats<'py> {
    type Target = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

/// An argument read as float64 values in C order, with its shape.
pub struct Values {
    pub data: Vec<f64>,
    pub shape: Vec<usize>,
}

impl Values {
    pub fn read(a: &PyArrayLikeDyn<'_, f64, AllowTypeChange>) -> Values {
        Values { shape: a.shape().to_vec(), data: a.as_array().iter().copied().collect() }
    }
    /// Number of rows: 1 for a vector, N for an (N, k) array.
    pub fn rows(&self) -> usize {
        if self.shape.len() == 2 {
            self.shape[0]
        } else {
            1
        }
    }
    pub fn row(&self, k: usize, len: usize) -> &[f64] {
        &self.data[k * len..(k + 1) * len]
    }
}

fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

/// Check a 1-D argument of length `len`; `what` says what its entries are.
pub fn vector(name: &str, a: &PyArrayLikeDyn<'_, f64, AllowTypeChange>, len: usize, what: &str) -> PyResult<Vec<f64>> {
    let v = Values::read(a);
    if v.shape != [len] {
        return Err(argument_error(
            Some(name),
            format!("{name} must have shape ({len},) ({what}), got shape {}", shape_str(&v.shape)),
        ));
    }
    finite(name, &v.data)?;
    Ok(v.data)
}

/// Check a (len,) or (N, len) argument.
pub fn rows(name: &str, a: &PyArrayLikeDyn<'_, f64, AllowTypeChange>, len: usize, what: &str) -> PyResult<Values> {
    let v = Values::read(a);
    let ok = match v.shape.as_slice() {
        [n] => *n == len,
        [_, n] => *n == len,
        _ => false,
    };
    if !ok {
        return Err(argument_error(
            Some(name),
            format!("{name} must have shape ({len},) or (N, {len}) ({what}), got shape {}", shape_str(&v.shape)),
        ));
    }
    finite(name, &v.data)?;
    Ok(v)
}

pub fn finite(name: &str, data: &[f64]) -> PyResult<()> {
    match data.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(argument_error(Some(name), format!("{name}[{i}] = {} is not a finite number", data[i]))),
        None => Ok(()),
    }
}

pub fn arr1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    Array1::from_vec(v).into_pyarray(py).into_any()
}

/// An (rows, cols) array from row-major data.
pub fn arr2<'py>(py: Python<'py>, rows: usize, cols: usize, v: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    let a = Array2::from_shape_vec((rows, cols), v).map_err(|e| PlanardynError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

pub fn arr3<'py>(py: Python<'py>, shape: (usize, usize, usize), v: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    let a = Array3::from_shape_vec(shape, v).map_err(|e| PlanardynError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

pub fn arr_dyn<'py>(py: Python<'py>, shape: &[usize], v: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    let a = ArrayD::from_shape_vec(IxDyn(shape), v).map_err(|e| PlanardynError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

/// A solved motion (or the part of one before a failure) as a dict of time-major arrays:
/// `q`, `qd`, `qdd`, `tau`, `tau_motor` (N, m), `sigma_I`, `sigma_II`, `condition` (N,).
pub fn solution_dict<'py>(py: Python<'py>, s: TaskSolution, m: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let TaskSolution { q, qd, qdd, tau, tau_motor, sigma_i, sigma_ii, condition } = s;
    for (k, v) in [("q", q), ("qd", qd), ("qdd", qdd), ("tau", tau), ("tau_motor", tau_motor)] {
        d.set_item(k, arr2(py, v.len() / m.max(1), m, v)?)?;
    }
    for (k, v) in [("sigma_I", sigma_i), ("sigma_II", sigma_ii), ("condition", condition)] {
        d.set_item(k, arr1(py, v))?;
    }
    Ok(d)
}
