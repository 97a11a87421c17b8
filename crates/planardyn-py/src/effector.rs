//! `planardyn._core.Effector`: the core's end effector (`kinematics::effector`) and its
//! task-space inverse dynamics (`dynamics::task`) on a native `Mechanism`. The methods check
//! and convert their arguments, call the core (each call makes its own kinematic frame,
//! started at the body coordinates `x_start` when given, else at the drawing) and convert
//! the result.

use crate::convert::{arr1, arr2, finite, rows, solution_dict, vector, Floats, Values};
use crate::errors::{effector_error, run, task_error};
use crate::exceptions::argument_error;
use crate::mechanism::PyMechanism;
use crate::query::ToPython;
use planardyn::dynamics::task::{self, TaskPath};
use planardyn::kinematics::effector::{Effector, EffectorError, Reached};
use planardyn::kinematics::{self as kin};
use planardyn::Mechanism;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

type ArrayArg<'py> = Floats<'py>;

/// A point of a body (k = 2) or its body's pose (k = 3) as task coordinates.
#[pyclass(frozen, module = "planardyn._core", name = "Effector")]
pub struct PyEffector {
    mech: Arc<Mechanism>,
    ee: Effector,
}

impl PyEffector {
    fn m(&self) -> usize {
        self.mech.dof()
    }

    fn q_arg(&self, name: &str, a: &ArrayArg<'_>) -> PyResult<Vec<f64>> {
        vector(name, a, self.m(), "one value per coordinate")
    }

    fn task_arg(&self, name: &str, a: &ArrayArg<'_>) -> PyResult<Vec<f64>> {
        vector(name, a, self.ee.dim, "the task coordinates x, y[, psi] (m, m[, rad])")
    }

    fn x_arg(&self, a: &ArrayArg<'_>) -> PyResult<Vec<f64>> {
        vector("x", a, self.mech.n_x(), "body coordinates [X, Y, phi] per body")
    }

    /// An inverse-kinematics solve run by the core, as its dict.
    fn reached<'py>(
        &self,
        py: Python<'py>,
        f: impl FnOnce() -> Result<Reached, EffectorError> + Send,
    ) -> PyResult<Bound<'py, PyAny>> {
        let r = run(py, || Ok(f()))?;
        r.map_err(|e| effector_error(py, &e))?.to_python(py, &self.mech)
    }
}

#[pymethods]
impl PyEffector {
    #[new]
    #[pyo3(signature = (mech, point, body=None))]
    fn new(mech: &Bound<'_, PyMechanism>, point: &str, body: Option<&str>) -> PyResult<Self> {
        let mech = mech.get().inner.clone();
        let ee = Effector::new(&mech, point, body).map_err(|e| argument_error(Some("point"), e.to_string()))?;
        Ok(PyEffector { mech, ee })
    }

    /// The body carrying the point.
    #[getter]
    fn body(&self) -> String {
        self.mech.bodies[self.ee.body.0].name.clone()
    }

    /// k: 2 (a point) or 3 (a pose).
    #[getter]
    fn dim(&self) -> usize {
        self.ee.dim
    }

    /// The end effector at inputs q, reached by continuation from `x_start` (else the drawing).
    #[pyo3(signature = (q, x_start=None))]
    fn state<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let q = self.q_arg("q", &q)?;
        let x_start = x_start.map(|a| self.x_arg(&a)).transpose()?;
        let r = run(py, || Ok(self.ee.state_from(&self.mech, &q, x_start.as_deref())?))?;
        r.to_python(py, &self.mech)
    }

    /// Task coordinates (k,) at body coordinates x (3n,).
    fn pose<'py>(&self, py: Python<'py>, x: ArrayArg<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(arr1(py, self.ee.pose(&self.x_arg(&x)?)))
    }

    /// J_t (k, m) at body coordinates x (3n,).
    fn jacobian<'py>(&self, py: Python<'py>, x: ArrayArg<'py>) -> PyResult<Bound<'py, PyAny>> {
        let x = self.x_arg(&x)?;
        let (st, _) = run(py, || Ok(self.ee.state_at(&self.mech, &x)?))?;
        arr2(py, self.ee.dim, self.m(), st.jt)
    }

    /// J_t' qd (k,) at body coordinates x (3n,) and rates qd (m,).
    fn convective<'py>(&self, py: Python<'py>, x: ArrayArg<'py>, qd: ArrayArg<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (x, qd) = (self.x_arg(&x)?, self.q_arg("qd", &qd)?);
        Ok(arr1(py, run(py, || Ok(self.ee.convective_at(&self.mech, &x, &qd)?))?))
    }

    /// (sigma_I, condition number) of a task Jacobian J (k, m), scaled dimensionless.
    fn measures(&self, jt: ArrayArg<'_>) -> PyResult<(f64, f64)> {
        let v = Values::read(&jt);
        if v.shape != [self.ee.dim, self.m()] {
            return Err(argument_error(
                Some("jt"),
                format!("J must have shape ({}, {}), got {:?}", self.ee.dim, self.m(), v.shape),
            ));
        }
        Ok(self.ee.measures(&v.data))
    }

    /// Inverse kinematics by Newton from `q_guess`, on the branch of `x_start` (else the drawing).
    #[pyo3(signature = (target, q_guess, x_start=None))]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        target: ArrayArg<'py>,
        q_guess: ArrayArg<'py>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (target, guess) = (self.task_arg("X", &target)?, self.q_arg("q_guess", &q_guess)?);
        let x_start = x_start.map(|a| self.x_arg(&a)).transpose()?;
        self.reached(py, || self.ee.solve_from(&self.mech, &target, &guess, x_start.as_deref()))
    }

    /// Inverse kinematics by continuation in task space from the end effector at `q_start`
    /// (default the drawing; reached from `x_start` when given).
    #[pyo3(signature = (target, q_start=None, x_start=None))]
    fn reach<'py>(
        &self,
        py: Python<'py>,
        target: ArrayArg<'py>,
        q_start: Option<ArrayArg<'py>>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let target = self.task_arg("X", &target)?;
        let q_start = q_start.map(|a| self.q_arg("q_start", &a)).transpose()?;
        let x_start = x_start.map(|a| self.x_arg(&a)).transpose()?;
        self.reached(py, || self.ee.reach_from(&self.mech, &target, q_start.as_deref(), x_start.as_deref()))
    }

    /// Inputs and drive efforts along a sampled path: t (N,) s, X, Xd, Xdd (N, k).
    #[pyo3(signature = (t, x, xd, xdd, q_start=None, singular_tol=kin::SINGULAR_TOL))]
    #[allow(clippy::too_many_arguments)]
    fn motion<'py>(
        &self,
        py: Python<'py>,
        t: ArrayArg<'py>,
        x: ArrayArg<'py>,
        xd: ArrayArg<'py>,
        xdd: ArrayArg<'py>,
        q_start: Option<ArrayArg<'py>>,
        singular_tol: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let k = self.ee.dim;
        let what = "task coordinates per sample";
        let t = Values::read(&t).data;
        finite("t", &t)?;
        let (x, xd, xdd) = (rows("X", &x, k, what)?, rows("Xd", &xd, k, what)?, rows("Xdd", &xdd, k, what)?);
        let path = TaskPath {
            t,
            x: x.data,
            xd: xd.data,
            xdd: xdd.data,
            point: self.ee.point.clone(),
            body: Some(self.body()),
            q_start: q_start.map(|a| self.q_arg("q_start", &a)).transpose()?,
            singular_tol,
        };
        let r = run(py, || Ok(task::solve(&self.mech, &path)))?;
        let sol = r.map_err(|e| task_error(py, &e))?;
        solution_dict(py, sol, self.m())
    }

    fn __repr__(&self) -> String {
        let what = if self.ee.dim == 2 { "position" } else { "pose" };
        format!("Effector({what} of point {:?} on {:?})", self.ee.point, self.body())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SINGULAR_TOL", kin::SINGULAR_TOL)?;
    m.add("JUMP_TOL", task::JUMP_TOL)?;
    m.add_class::<PyEffector>()
}
