//! The core's typed query results (`planardyn::dynamics::query`, the end effector's states) as
//! the Python values the API returns: one conversion per result type, shaped by the
//! mechanism (n bodies, m coordinates, P named points), arrays time-major and row-major.

use crate::convert::{arr1, arr2, arr_dyn};
use planardyn::dynamics::query::{Derivatives, Energies, KinematicsReport, SharedEfforts};
use planardyn::kinematics::effector::Reached;
use planardyn::Mechanism;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A query result as its Python value.
pub trait ToPython {
    fn to_python<'py>(self, py: Python<'py>, mech: &Mechanism) -> PyResult<Bound<'py, PyAny>>;
}

/// A vector: x (3n,), qdd or tau (m,)...
impl ToPython for Vec<f64> {
    fn to_python<'py>(self, py: Python<'py>, _: &Mechanism) -> PyResult<Bound<'py, PyAny>> {
        Ok(arr1(py, self))
    }
}

/// Pair reactions (p, 3).
impl ToPython for Vec<[f64; 3]> {
    fn to_python<'py>(self, py: Python<'py>, _: &Mechanism) -> PyResult<Bound<'py, PyAny>> {
        arr2(py, self.len(), 3, self.concat())
    }
}

/// (kinetic, potential) in J.
impl ToPython for Energies {
    fn to_python<'py>(self, py: Python<'py>, _: &Mechanism) -> PyResult<Bound<'py, PyAny>> {
        Ok((self.kinetic, self.potential).into_pyobject(py)?.into_any())
    }
}

/// x (3n,), poses (n, 3), u (n, 3, m), w (n, 3, m, m), points (P, 2), with qd also xd (3n,),
/// c (3n,), point_velocities (P, 2); sigma_min, sigma_passive, residual.
impl ToPython for KinematicsReport {
    fn to_python<'py>(self, py: Python<'py>, mech: &Mechanism) -> PyResult<Bound<'py, PyAny>> {
        let (n, m, p) = (mech.n_bodies(), mech.dof(), mech.points.len());
        let d = PyDict::new(py);
        d.set_item("x", arr1(py, self.x.clone()))?;
        d.set_item("poses", arr2(py, n, 3, self.x)?)?;
        d.set_item("u", arr_dyn(py, &[n, 3, m], self.u)?)?;
        d.set_item("w", arr_dyn(py, &[n, 3, m, m], self.w)?)?;
        d.set_item("points", arr2(py, p, 2, self.points)?)?;
        if let Some(r) = self.rates {
            d.set_item("xd", arr1(py, r.xd))?;
            d.set_item("c", arr1(py, r.c))?;
            d.set_item("point_velocities", arr2(py, p, 2, r.point_velocities)?)?;
        }
        d.set_item("sigma_min", self.sigma_min)?;
        d.set_item("sigma_passive", self.sigma_passive)?;
        d.set_item("residual", self.residual)?;
        Ok(d.into_any())
    }
}

/// A value and its Jacobians, named: forward dynamics `qdd`, `dq`, `dqd`, `dtau`; inverse
/// dynamics `tau`, `dq`, `dqd`, `dqdd` (the value (m,), the Jacobians (m, m)).
pub struct Named(pub Derivatives, pub [&'static str; 2]);

impl ToPython for Named {
    fn to_python<'py>(self, py: Python<'py>, mech: &Mechanism) -> PyResult<Bound<'py, PyAny>> {
        let (Named(d, [value, third]), m) = (self, mech.dof());
        let jac = d.jacobians;
        let out = PyDict::new(py);
        out.set_item(value, arr1(py, d.value))?;
        out.set_item("dq", arr2(py, m, m, jac.dq)?)?;
        out.set_item("dqd", arr2(py, m, m, jac.dqd)?)?;
        out.set_item(third, arr2(py, m, m, jac.dthird)?)?;
        Ok(out.into_any())
    }
}

/// efforts, motor_torques (n_a,), B (m, n_a), internal (r, n_a).
impl ToPython for SharedEfforts {
    fn to_python<'py>(self, py: Python<'py>, _: &Mechanism) -> PyResult<Bound<'py, PyAny>> {
        let act = &self.actuation;
        let d = PyDict::new(py);
        d.set_item("efforts", arr1(py, self.efforts))?;
        d.set_item("motor_torques", arr1(py, self.motor_torques))?;
        d.set_item("B", arr2(py, act.m, act.n_a, act.b.clone())?)?;
        d.set_item("internal", arr2(py, act.internal.len(), act.n_a, act.internal.concat())?)?;
        Ok(d.into_any())
    }
}

/// The end effector reached: q (m,), X (k,), J (k, m), sigma_I, condition, x (3n,); k = m.
impl ToPython for Reached {
    fn to_python<'py>(self, py: Python<'py>, mech: &Mechanism) -> PyResult<Bound<'py, PyAny>> {
        let (st, m) = (self.state, mech.dof());
        let d = PyDict::new(py);
        d.set_item("q", arr1(py, st.q))?;
        d.set_item("X", arr1(py, st.pose))?;
        d.set_item("J", arr2(py, st.jt.len() / m.max(1), m, st.jt)?)?;
        d.set_item("sigma_I", st.sigma_i)?;
        d.set_item("condition", st.condition)?;
        d.set_item("x", arr1(py, self.x))?;
        Ok(d.into_any())
    }
}
