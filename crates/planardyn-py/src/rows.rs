//! `planardyn._core.Mechanism` along the rows of a motion: the named points' positions;
//! inverse dynamics, dissipated power, motor torques and the regressor on a branch
//! (`planardyn::batch`'s rows); body accelerations and reactions along a trajectory
//! (`planardyn::dynamics::along`); the named points' motion. The bodies of `Mechanism`'s
//! methods of these names: they check the rows' shapes, call the core and shape its result.

use crate::convert::{arr1, arr2, arr3, arr_dyn, rows, vector, Floats, Values};
use crate::errors::{run, to_pyerr};
use crate::exceptions::argument_error;
use planardyn::batch::{
    dissipation_rows, inverse_rows_checked, motor_torque_rows, regressor_rows, Branch, MotorTorqueRows,
};
use planardyn::dynamics::{self, query, Rows};
use planardyn::Error;
use planardyn::Mechanism;
use pyo3::prelude::*;
use pyo3::types::PyDict;

type ArrayArg<'py> = Floats<'py>;

/// What each coordinate's entry is, for messages.
pub fn coords_what(mech: &Mechanism) -> String {
    format!("one value per coordinate: {}", mech.coordinate_names().join(", "))
}

/// A motion as the rows methods take it: q, qd, qdd, each (m,) or (N, m), and the body
/// coordinates x, (3n,) or (N, 3n), and rates xd, of its branch, if given.
pub struct MotionArgs<'a, 'py> {
    pub q: &'a ArrayArg<'py>,
    pub qd: &'a ArrayArg<'py>,
    pub qdd: &'a ArrayArg<'py>,
    pub x: Option<&'a ArrayArg<'py>>,
    pub xd: Option<&'a ArrayArg<'py>>,
}

/// A motion's rows, checked: q, qd, qdd of one shape, x and xd of one shape.
struct Motion {
    q: Values,
    qd: Values,
    qdd: Values,
    x: Option<Values>,
    xd: Option<Values>,
}

impl MotionArgs<'_, '_> {
    fn checked(self, mech: &Mechanism) -> PyResult<Motion> {
        let x = self.x.map(|a| rows("x", a, mech.n_x(), "body coordinates [X, Y, phi] per body")).transpose()?;
        let xd = self.xd.map(|a| rows("xd", a, mech.n_x(), "body rates [Xd, Yd, phid] per body")).transpose()?;
        if let Some(xd) = &xd {
            if x.as_ref().map(|x| &x.shape) != Some(&xd.shape) {
                let x_shape = x.as_ref().map(|x| format!("{:?}", x.shape)).unwrap_or_else(|| "none".into());
                return Err(argument_error(
                    Some("xd"),
                    format!("xd needs x of the same rows (a result's x and xd), got xd {:?} and x {x_shape}", xd.shape),
                ));
            }
        }
        let (m, what) = (mech.dof(), coords_what(mech));
        let (q, qd, qdd) =
            (rows("q", self.q, m, &what)?, rows("qd", self.qd, m, &what)?, rows("qdd", self.qdd, m, &what)?);
        if qd.shape != q.shape || qdd.shape != q.shape {
            return Err(argument_error(
                None,
                format!(
                    "q, qd and qdd must have the same shape, got {:?}, {:?} and {:?}",
                    q.shape, qd.shape, qdd.shape
                ),
            ));
        }
        Ok(Motion { q, qd, qdd, x, xd })
    }
}

impl Motion {
    /// The branch: the drawn one, from the first row's body coordinates (3n,), or every
    /// row's (N, 3n); with body rates (x's shape) every row's.
    fn branch(&self) -> Branch<'_> {
        match (&self.x, &self.xd) {
            (None, _) => Branch::Drawing,
            (Some(x), Some(xd)) => Branch::Rows(&x.data, Some(&xd.data)),
            (Some(x), None) if x.shape.len() == 1 => Branch::From(&x.data),
            (Some(x), None) => Branch::Rows(&x.data, None),
        }
    }

    /// `f(branch, q, qd, qdd)`, a core computation along the rows, with the GIL released.
    fn run<T: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(Branch<'_>, &[f64], &[f64], &[f64]) -> Result<T, Error> + Send,
    ) -> PyResult<T> {
        run(py, || Ok(f(self.branch(), &self.q.data, &self.qd.data, &self.qdd.data)?))
    }
}

/// `Mechanism.point_positions` (the method's doc there).
pub fn point_positions<'py>(py: Python<'py>, mech: &Mechanism, x: &ArrayArg<'py>) -> PyResult<Bound<'py, PyAny>> {
    let nx = mech.n_x();
    let v = rows("x", x, nx, "body coordinates [X, Y, phi] per body")?;
    let p = mech.points.len();
    let out: Vec<f64> = (0..v.rows()).flat_map(|k| query::point_positions(mech, v.row(k, nx))).collect();
    if v.shape.len() == 1 {
        arr2(py, p, 2, out)
    } else {
        arr3(py, (v.rows(), p, 2), out)
    }
}

/// `Mechanism.inverse_dynamics` (the method's doc there).
pub fn inverse_dynamics<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    motion: MotionArgs<'_, 'py>,
    allow_singular: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let motion = motion.checked(mech)?;
    let tau = motion.run(py, |branch, q, qd, qdd| inverse_rows_checked(mech, branch, q, qd, qdd, allow_singular))?;
    arr_dyn(py, &motion.q.shape, tau)
}

/// `Mechanism.dissipated_power` (the method's doc there).
pub fn dissipated_power<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    motion: MotionArgs<'_, 'py>,
    allow_singular: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let motion = motion.checked(mech)?;
    let p = motion.run(py, |branch, q, qd, qdd| dissipation_rows(mech, branch, q, qd, qdd, allow_singular))?;
    if motion.q.shape.len() == 1 {
        return Ok(p[0].into_pyobject(py)?.into_any());
    }
    Ok(arr1(py, p))
}

/// `Mechanism.motor_torques` (the method's doc there); `recorded`: x and xd are a run's own
/// rows ([`Branch::recorded`]). A row without motor torques fails the call with its error.
pub fn motor_torques<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    motion: MotionArgs<'_, 'py>,
    tau: Option<&ArrayArg<'py>>,
    allow_singular: bool,
    recorded: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (shape, t_m) = motor_torque_query(py, mech, motion, tau, allow_singular, recorded)?;
    arr_dyn(py, &shape, t_m.into_values().map_err(|e| to_pyerr(py, &e))?)
}

/// `Mechanism.run_motor_torques` (the method's doc there): a run's rows' motor torques, NaN
/// on the rows without, and the core's note of those rows at their times `t`.
pub fn run_motor_torques<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    t: &ArrayArg<'py>,
    motion: MotionArgs<'_, 'py>,
    tau: &ArrayArg<'py>,
) -> PyResult<(Bound<'py, PyAny>, Option<String>)> {
    let (shape, t_m) = motor_torque_query(py, mech, motion, Some(tau), true, true)?;
    let t = vector("t", t, shape[..shape.len() - 1].iter().product(), "one time (s) per row")?;
    let note = t_m.note(&t);
    Ok((arr_dyn(py, &shape, t_m.values)?, note))
}

/// The core's motor torques of `motion` ([`motor_torques`]' arguments) and their shape.
fn motor_torque_query<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    motion: MotionArgs<'_, 'py>,
    tau: Option<&ArrayArg<'py>>,
    allow_singular: bool,
    recorded: bool,
) -> PyResult<(Vec<usize>, MotorTorqueRows)> {
    let motion = motion.checked(mech)?;
    let q = &motion.q;
    let n_a = mech.n_actuators();
    let tau = match &tau {
        Some(tau) => {
            let (w, what) = if tau.as_array().shape().last() == Some(&n_a) {
                (n_a, format!("one per actuator: {}", mech.actuator_names().join(", ")))
            } else {
                (mech.dof(), coords_what(mech))
            };
            let tau = rows("tau", tau, w, &what)?;
            if tau.shape[..tau.shape.len() - 1] != q.shape[..q.shape.len() - 1] {
                return Err(argument_error(
                    Some("tau"),
                    format!("tau must have q's rows, got tau {:?} and q {:?}", tau.shape, q.shape),
                ));
            }
            Some((tau, w))
        }
        None => None,
    };
    let mut shape = q.shape.clone();
    if let Some((_, w)) = &tau {
        *shape.last_mut().expect("rows have a last axis") = *w;
    }
    let t_m = motion.run(py, |branch, q, qd, qdd| {
        let given = tau.as_ref().map(|(t, w)| (&t.data[..], *w));
        let branch = if recorded { branch.recorded() } else { branch };
        motor_torque_rows(mech, branch, q, qd, qdd, given, allow_singular)
    })?;
    Ok((shape, t_m))
}

/// `Mechanism.regressor` (the method's doc there).
pub fn regressor<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    motion: MotionArgs<'_, 'py>,
    allow_singular: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let motion = motion.checked(mech)?;
    let (m, p) = (mech.dof(), planardyn::dynamics::regressor::n_parameters(mech));
    let (y, tau_o) = motion.run(py, |branch, q, qd, qdd| regressor_rows(mech, branch, q, qd, qdd, allow_singular))?;
    let q = &motion.q;
    let n = q.rows();
    let d = PyDict::new(py);
    if q.shape.len() == 1 {
        d.set_item("Y", arr2(py, m, p, y)?)?;
        d.set_item("tau_o", arr1(py, tau_o))?;
    } else {
        d.set_item("Y", arr3(py, (n, m, p), y)?)?;
        d.set_item("tau_o", arr2(py, n, m, tau_o)?)?;
    }
    Ok(d)
}

/// `Mechanism.along` (the method's doc there).
#[allow(clippy::too_many_arguments)]
pub fn along<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    t: &ArrayArg<'py>,
    x: &ArrayArg<'py>,
    q: &ArrayArg<'py>,
    qd: &ArrayArg<'py>,
    tau: &ArrayArg<'py>,
    allow_singular: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (m, nx, p) = (mech.dof(), mech.n_x(), mech.pairs.len());
    let what = coords_what(mech);
    let x = rows("x", x, nx, "body coordinates [X, Y, phi] per body")?;
    let (q, qd, tau) = (rows("q", q, m, &what)?, rows("qd", qd, m, &what)?, rows("tau", tau, m, &what)?);
    let t = Values::read(t);
    let out = run(py, || {
        let r = Rows { t: &t.data, x: &x.data, q: &q.data, qd: &qd.data, tau: &tau.data };
        Ok(dynamics::along(mech, r, allow_singular)?)
    })?;
    let n = out.xdd.len() / nx;
    let d = PyDict::new(py);
    d.set_item("xdd", arr2(py, n, nx, out.xdd)?)?;
    d.set_item("reactions", arr3(py, (n, p, 3), out.reactions)?)?;
    Ok(d)
}

/// `Mechanism.point_motion` (the method's doc there).
pub fn point_motion<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    x: &ArrayArg<'py>,
    xd: &ArrayArg<'py>,
    xdd: &ArrayArg<'py>,
) -> PyResult<Bound<'py, PyDict>> {
    let nx = mech.n_x();
    let what = "body coordinates [X, Y, phi] per body";
    let (x, xd, xdd) = (rows("x", x, nx, what)?, rows("xd", xd, nx, what)?, rows("xdd", xdd, nx, what)?);
    if xd.data.len() != x.data.len() || xdd.data.len() != x.data.len() {
        return Err(argument_error(
            None,
            format!("x, xd and xdd must have the same shape, got {:?}, {:?} and {:?}", x.shape, xd.shape, xdd.shape),
        ));
    }
    let names: Vec<&str> = dynamics::carried_points(mech).iter().map(|(p, _)| mech.points[p.0].0.as_str()).collect();
    let [pos, vel, acc] = dynamics::point_motion(mech, &x.data, &xd.data, &xdd.data);
    let shape = (x.rows(), names.len(), 2);
    let d = PyDict::new(py);
    d.set_item("names", names)?;
    d.set_item("position", arr3(py, shape, pos)?)?;
    d.set_item("velocity", arr3(py, shape, vel)?)?;
    d.set_item("acceleration", arr3(py, shape, acc)?)?;
    Ok(d)
}
