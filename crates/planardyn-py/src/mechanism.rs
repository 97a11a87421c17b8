//! `planardyn._core.Mechanism`: an immutable, validated mechanism (an `Arc` of the core's)
//! and its kinematics and dynamics at given coordinates. The methods check and convert their
//! arguments, call the core's queries (`planardyn::dynamics::query` at one state,
//! `planardyn::batch`'s rows along a motion), and convert the typed results; each query makes
//! its own buffers, so calls are reproducible (positions come by continuation from the
//! drawing) and thread-safe; the GIL is released while the core computes.

use crate::convert::{arr1, arr2, arr3, arr_dyn, rows, vector, Floats, Values};
use crate::errors::run;
use crate::exceptions::{argument_error, PlanardynError};
use planardyn::batch::{dissipation_rows, inverse_rows_checked, motor_torque_rows, regressor_rows, Branch};
use planardyn::dynamics::query::{self, Derivatives, ForwardState};
use planardyn::dynamics::{self, Rows};
use planardyn::model::pairs::{self, pair_geometry, Relative};
use planardyn::model::{CoordinateKind, PairId};
use planardyn::Mechanism;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

type ArrayArg<'py> = Floats<'py>;

/// A validated planar mechanism (immutable). Made by `load`/`loads`.
#[pyclass(frozen, module = "planardyn._core", name = "Mechanism")]
pub struct PyMechanism {
    pub inner: Arc<Mechanism>,
}

impl PyMechanism {
    pub fn new(mech: Mechanism) -> Self {
        PyMechanism { inner: Arc::new(mech) }
    }

    fn m(&self) -> usize {
        self.inner.dof()
    }

    fn coords_what(&self) -> String {
        format!("one value per coordinate: {}", self.inner.coordinate_names().join(", "))
    }

    fn q_arg(&self, name: &str, a: &ArrayArg<'_>) -> PyResult<Vec<f64>> {
        vector(name, a, self.m(), &self.coords_what())
    }

    /// Body coordinates (3n,) given as a continuation start.
    fn x_arg(&self, a: &ArrayArg<'_>) -> PyResult<Vec<f64>> {
        vector("x_start", a, self.inner.n_x(), "body coordinates [X, Y, phi] per body")
    }

    /// q, qd, qdd of one shape, (m,) or (N, m), and the branch's body coordinates x, (3n,)
    /// or (N, 3n), if given.
    fn motion_rows(
        &self,
        q: &ArrayArg<'_>,
        qd: &ArrayArg<'_>,
        qdd: &ArrayArg<'_>,
        x: Option<&ArrayArg<'_>>,
        xd: Option<&ArrayArg<'_>>,
    ) -> PyResult<MotionRows> {
        let x = x.map(|a| rows("x", a, self.inner.n_x(), "body coordinates [X, Y, phi] per body")).transpose()?;
        let xd = xd.map(|a| rows("xd", a, self.inner.n_x(), "body rates [Xd, Yd, phid] per body")).transpose()?;
        if let Some(xd) = &xd {
            if x.as_ref().map(|x| &x.shape) != Some(&xd.shape) {
                let x_shape = x.as_ref().map(|x| format!("{:?}", x.shape)).unwrap_or_else(|| "none".into());
                return Err(argument_error(
                    Some("xd"),
                    format!("xd needs x of the same rows (a result's x and xd), got xd {:?} and x {x_shape}", xd.shape),
                ));
            }
        }
        let (m, what) = (self.m(), self.coords_what());
        let (q, qd, qdd) = (rows("q", q, m, &what)?, rows("qd", qd, m, &what)?, rows("qdd", qdd, m, &what)?);
        if qd.shape != q.shape || qdd.shape != q.shape {
            return Err(argument_error(
                None,
                format!(
                    "q, qd and qdd must have the same shape, got {:?}, {:?} and {:?}",
                    q.shape, qd.shape, qdd.shape
                ),
            ));
        }
        Ok((q, qd, qdd, x, xd))
    }

    /// A dict of the named value and the three Jacobians, the third under `third`.
    fn jacobians<'py>(&self, py: Python<'py>, d: Derivatives, names: [&str; 2]) -> PyResult<Bound<'py, PyDict>> {
        let (m, jac) = (self.m(), d.jacobians);
        let out = PyDict::new(py);
        out.set_item(names[0], arr1(py, d.value))?;
        out.set_item("dq", arr2(py, m, m, jac.dq)?)?;
        out.set_item("dqd", arr2(py, m, m, jac.dqd)?)?;
        out.set_item(names[1], arr2(py, m, m, jac.dthird)?)?;
        Ok(out)
    }
}

#[pymethods]
impl PyMechanism {
    /// The model's name.
    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }
    /// Where it was loaded from (a path or '<string>').
    #[getter]
    fn source(&self) -> &str {
        &self.inner.source
    }

    /// What a user should know about the model (redundant constraints...).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }
    /// Degrees of freedom m (= number of generalized coordinates).
    #[getter]
    fn dof(&self) -> usize {
        self.m()
    }
    /// Number of mobile bodies n.
    #[getter]
    fn n_bodies(&self) -> usize {
        self.inner.n_bodies()
    }
    #[getter]
    fn coordinate_names(&self) -> Vec<String> {
        self.inner.coordinates.iter().map(|c| c.name.clone()).collect()
    }
    /// 'angle' (rad) or 'displacement' (m) for each coordinate.
    #[getter]
    fn coordinate_kinds(&self) -> Vec<&'static str> {
        self.inner.coordinates.iter().map(|c| c.kind.name()).collect()
    }
    /// "angle" or "displacement" per actuator (`actuator_names`): what its effort turns.
    #[getter]
    fn actuator_kinds(&self) -> Vec<&'static str> {
        let mech = &self.inner;
        let pairs = mech.coordinates.iter().map(|c| c.pair).chain(mech.pair_actuators.iter().map(|a| a.pair));
        pairs.map(|p| pairs::coordinate_kind(&mech.pairs[p.0]).map_or("displacement", CoordinateKind::name)).collect()
    }
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.inner.bodies.iter().map(|b| b.name.clone()).collect()
    }
    #[getter]
    fn pair_names(&self) -> Vec<String> {
        self.inner.pairs.iter().map(|p| p.name.clone()).collect()
    }
    #[getter]
    fn point_names(&self) -> Vec<String> {
        self.inner.points.iter().map(|p| p.0.clone()).collect()
    }
    /// Names of the points the ground carries.
    #[getter]
    fn ground_points(&self) -> Vec<String> {
        self.inner.ground_points.iter().map(|p| self.inner.points[p.0].0.clone()).collect()
    }
    /// (m,) start coordinates (rad or m).
    #[getter]
    fn q0<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arr1(py, self.inner.initial_state().0)
    }
    /// (m,) start rates (rad/s or m/s).
    #[getter]
    fn qd0<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arr1(py, self.inner.initial_state().1)
    }
    /// (m,) coordinates in the drawing (rad or m).
    #[getter]
    fn drawn_q<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arr1(py, self.inner.drawn_q())
    }
    /// (3n,) body coordinates [X, Y, phi] per body in the drawing (m, rad).
    #[getter]
    fn x0<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arr1(py, self.inner.x0.clone())
    }
    /// (n,) body masses (kg).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arr1(py, self.inner.bodies.iter().map(|b| b.mass).collect())
    }
    /// (n,) moments of inertia about the centres of mass (kg m^2).
    #[getter]
    fn inertias<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arr1(py, self.inner.bodies.iter().map(|b| b.inertia).collect())
    }
    /// Characteristic length L (m): the largest distance between two drawn points.
    #[getter]
    fn scale(&self) -> f64 {
        self.inner.scale
    }
    /// (2,) gravity [g_x, g_y] (m/s^2).
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arr1(py, self.inner.gravity.to_vec())
    }
    /// For each body, its points as (name, (s_x, s_y)) in the body frame (m): origin at the
    /// centre of mass, rotated by the body angle phi.
    #[getter]
    fn body_points(&self) -> Vec<Vec<(String, (f64, f64))>> {
        let mech = &self.inner;
        mech.bodies
            .iter()
            .map(|b| b.points.iter().map(|(p, s)| (mech.points[p.0].0.clone(), (s[0], s[1]))).collect())
            .collect()
    }
    /// The pairs as dicts: name, kind ('revolute' | 'prismatic' | 'gear' | 'slot'), bodies
    /// (a, b) by name ('ground' for the fixed body), point (name; a gear's first centre),
    /// axis (the guide or slot direction in a's frame, or None), rows (start, stop): the
    /// pair's rows among the pair-constraint rows (`structure.constraint_jacobian`).
    #[getter]
    fn pairs<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mech = &self.inner;
        mech.pairs
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let d = PyDict::new(py);
                d.set_item("name", &p.name)?;
                let axis = match pairs::relative(p) {
                    Some(Relative::Along { axis }) => Some((axis[0], axis[1])),
                    _ => None,
                };
                d.set_item("kind", pairs::kind_name(p))?;
                d.set_item("bodies", (mech.link_name(p.a), mech.link_name(p.b)))?;
                d.set_item("point", &mech.points[p.point.0].0)?;
                d.set_item("axis", axis)?;
                let rows = mech.pair_rows(PairId(k));
                d.set_item("rows", (rows.start, rows.end))?;
                Ok(d)
            })
            .collect()
    }
    /// What the drawings show of each pair at body coordinates x (3n,), in world
    /// coordinates (m): a dict per pair with name, kind, pins [(x, y)] (pin joints),
    /// blocks [(x, y)] (sliding blocks), lines [((x, y), (x, y))] (guides, slots, rack pitch
    /// lines) and circles [((x, y), r)] (pitch circles).
    fn pair_geometry<'py>(&self, py: Python<'py>, x: ArrayArg<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let x = self.x_arg(&x)?;
        let pt = |p: [f64; 2]| (p[0], p[1]);
        self.inner
            .pairs
            .iter()
            .zip(pair_geometry(&self.inner, &x))
            .map(|(p, g)| {
                let d = PyDict::new(py);
                d.set_item("name", &p.name)?;
                d.set_item("kind", g.kind)?;
                d.set_item("pins", g.pins.iter().map(|&p| pt(p)).collect::<Vec<_>>())?;
                d.set_item("blocks", g.blocks.iter().map(|&p| pt(p)).collect::<Vec<_>>())?;
                d.set_item("lines", g.lines.iter().map(|l| (pt(l[0]), pt(l[1]))).collect::<Vec<_>>())?;
                d.set_item("circles", g.circles.iter().map(|&(c, r)| (pt(c), r)).collect::<Vec<_>>())?;
                Ok(d)
            })
            .collect()
    }
    /// The model file's `simulate` defaults (None where not given).
    #[getter]
    fn simulate_defaults<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.inner.simulate;
        let d = PyDict::new(py);
        d.set_item("t_end", s.t_end)?;
        d.set_item("method", s.method.clone())?;
        d.set_item("rtol", s.rtol)?;
        d.set_item("atol", s.atol)?;
        d.set_item("dt", s.dt)?;
        d.set_item("output_dt", s.output_dt)?;
        Ok(d)
    }

    /// The specification the mechanism was built from, as JSON text (`loads(..., 'json')`
    /// gives the same mechanism back).
    fn spec_json(&self) -> PyResult<String> {
        planardyn_spec_json(&self.inner)
    }

    /// Body coordinates x (3n,) at coordinates q (m,), by continuation from the drawing
    /// (the assembly branch drawn), or from body coordinates `x_start` on the wanted branch.
    #[pyo3(signature = (q, x_start=None))]
    fn assemble<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let q = self.q_arg("q", &q)?;
        let x_start = x_start.map(|a| self.x_arg(&a)).transpose()?;
        let mech = self.inner.clone();
        let x = run(py, move || Ok(query::assemble(&mech, &q, x_start.as_deref())?))?;
        Ok(arr1(py, x))
    }

    /// World positions of every named point: (P, 2) for x of shape (3n,), (N, P, 2) for (N, 3n).
    fn point_positions<'py>(&self, py: Python<'py>, x: ArrayArg<'py>) -> PyResult<Bound<'py, PyAny>> {
        let nx = self.inner.n_x();
        let v = rows("x", &x, nx, "body coordinates [X, Y, phi] per body")?;
        let p = self.inner.points.len();
        let mut out = Vec::with_capacity(v.rows() * p * 2);
        for k in 0..v.rows() {
            out.extend(query::point_positions(&self.inner, v.row(k, nx)));
        }
        if v.shape.len() == 1 {
            arr2(py, p, 2, out)
        } else {
            arr3(py, (v.rows(), p, 2), out)
        }
    }

    /// Positions and analogues at q (and velocities with qd); see the Python docstring.
    #[pyo3(signature = (q, qd=None, x_start=None))]
    fn kinematics<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: Option<ArrayArg<'py>>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = self.q_arg("q", &q)?;
        let qd = qd.map(|a| self.q_arg("qd", &a)).transpose()?;
        let x_start = x_start.map(|a| self.x_arg(&a)).transpose()?;
        let mech = self.inner.clone();
        let (n, m, p) = (mech.n_bodies(), mech.dof(), mech.points.len());
        let k = run(py, move || Ok(query::kinematics(&mech, &q, qd.as_deref(), x_start.as_deref())?))?;
        let d = PyDict::new(py);
        d.set_item("x", arr1(py, k.x.clone()))?;
        d.set_item("poses", arr2(py, n, 3, k.x)?)?;
        d.set_item("u", arr_dyn(py, &[n, 3, m], k.u)?)?;
        d.set_item("w", arr_dyn(py, &[n, 3, m, m], k.w)?)?;
        d.set_item("points", arr2(py, p, 2, k.points)?)?;
        if let Some(r) = k.rates {
            d.set_item("xd", arr1(py, r.xd))?;
            d.set_item("c", arr1(py, r.c))?;
            d.set_item("point_velocities", arr2(py, p, 2, r.point_velocities)?)?;
        }
        d.set_item("sigma_min", k.sigma_min)?;
        d.set_item("sigma_passive", k.sigma_passive)?;
        d.set_item("residual", k.residual)?;
        Ok(d)
    }

    /// Mass matrix A = U^T M U (m, m) at q.
    #[pyo3(signature = (q, allow_singular=false))]
    fn mass_matrix<'py>(&self, py: Python<'py>, q: ArrayArg<'py>, allow_singular: bool) -> PyResult<Bound<'py, PyAny>> {
        let q = self.q_arg("q", &q)?;
        let mech = self.inner.clone();
        let m = mech.dof();
        let a = run(py, move || Ok(query::mass_matrix(&mech, &q, allow_singular)?))?;
        arr2(py, m, m, a)
    }

    /// Accelerations qdd (m,) at (q, qd), time t (s), efforts tau (m,) or the model's drives.
    #[pyo3(signature = (q, qd, t=0.0, tau=None, allow_singular=false))]
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        t: f64,
        tau: Option<ArrayArg<'py>>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?);
        let tau = tau.map(|a| self.q_arg("tau", &a)).transpose()?;
        check_time(t)?;
        let mech = &*self.inner;
        let qdd = run(py, || {
            Ok(query::forward_dynamics(mech, ForwardState { q: &q, qd: &qd, t, tau: tau.as_deref(), allow_singular })?)
        })?;
        Ok(arr1(py, qdd))
    }

    /// Exact first derivatives of forward dynamics at (q, qd), time t (s), with efforts tau
    /// (m,) or the model's drives held fixed: a dict of `qdd` (m,) and `dq`, `dqd`, `dtau`
    /// (m, m), entry [i, k] = d qdd_i / d (q, qd, tau)_k.
    #[pyo3(signature = (q, qd, t=0.0, tau=None, allow_singular=false))]
    fn forward_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        t: f64,
        tau: Option<ArrayArg<'py>>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (q, qd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?);
        let tau = tau.map(|a| self.q_arg("tau", &a)).transpose()?;
        check_time(t)?;
        let mech = &*self.inner;
        let d = run(py, || {
            Ok(query::forward_derivatives(
                mech,
                ForwardState { q: &q, qd: &qd, t, tau: tau.as_deref(), allow_singular },
            )?)
        })?;
        self.jacobians(py, d, ["qdd", "dtau"])
    }

    /// Exact first derivatives of inverse dynamics at (q, qd, qdd), each (m,): a dict of
    /// `tau` (m,) and `dq`, `dqd`, `dqdd` (m, m), entry [i, k] = d tau_i / d (q, qd, qdd)_k.
    #[pyo3(signature = (q, qd, qdd, allow_singular=false))]
    fn inverse_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        qdd: ArrayArg<'py>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (q, qd, qdd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?, self.q_arg("qdd", &qdd)?);
        let mech = &*self.inner;
        let d = run(py, || Ok(query::inverse_derivatives(mech, &q, &qd, &qdd, allow_singular)?))?;
        self.jacobians(py, d, ["tau", "dqdd"])
    }

    /// Efforts tau for (q, qd, qdd), each (m,) or (N, m), on the branch of the body
    /// coordinates `x`: (3n,) at the first row, or (N, 3n) at every row; else the drawn one
    /// (`planardyn::batch::Branch`). `xd`, the body rates of x's rows, replaces the rates
    /// solved from qd.
    #[pyo3(signature = (q, qd, qdd, x=None, xd=None, allow_singular=false))]
    #[allow(clippy::too_many_arguments)]
    fn inverse_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        qdd: ArrayArg<'py>,
        x: Option<ArrayArg<'py>>,
        xd: Option<ArrayArg<'py>>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, qdd, x, xd) = self.motion_rows(&q, &qd, &qdd, x.as_ref(), xd.as_ref())?;
        let mech = self.inner.clone();
        let shape = q.shape.clone();
        let tau = run(py, move || {
            let branch = branch_of(x.as_ref(), xd.as_ref());
            Ok(inverse_rows_checked(&mech, branch, &q.data, &qd.data, &qdd.data, allow_singular)?)
        })?;
        arr_dyn(py, &shape, tau)
    }

    /// Power (W, >= 0) dissipated by the pairs' Coulomb friction along (q, qd, qdd), each
    /// (m,) or (N, m): a float or (N,), on the branch of x (and with the rates xd) as
    /// `inverse_dynamics`.
    #[pyo3(signature = (q, qd, qdd, x=None, xd=None, allow_singular=false))]
    #[allow(clippy::too_many_arguments)]
    fn dissipated_power<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        qdd: ArrayArg<'py>,
        x: Option<ArrayArg<'py>>,
        xd: Option<ArrayArg<'py>>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, qdd, x, xd) = self.motion_rows(&q, &qd, &qdd, x.as_ref(), xd.as_ref())?;
        let mech = self.inner.clone();
        let single = q.shape.len() == 1;
        let p = run(py, move || {
            let branch = branch_of(x.as_ref(), xd.as_ref());
            Ok(dissipation_rows(&mech, branch, &q.data, &qd.data, &qdd.data, allow_singular)?)
        })?;
        if single {
            return Ok(p[0].into_pyobject(py)?.into_any());
        }
        Ok(arr1(py, p))
    }

    /// Motor torques (N m, motor side) along (q, qd, qdd), each (m,) or (N, m), on the branch
    /// of x (and with the rates xd) as `inverse_dynamics`: of the joint-side efforts `tau`,
    /// (m,) / (N, m) or every actuator's (n_a,) / (N, n_a), or of the motion's own inverse
    /// dynamics without `tau`; on an actuator without a motor, the effort itself.
    #[pyo3(signature = (q, qd, qdd, tau=None, x=None, xd=None, allow_singular=false))]
    #[allow(clippy::too_many_arguments)]
    fn motor_torques<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        qdd: ArrayArg<'py>,
        tau: Option<ArrayArg<'py>>,
        x: Option<ArrayArg<'py>>,
        xd: Option<ArrayArg<'py>>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, qdd, x, xd) = self.motion_rows(&q, &qd, &qdd, x.as_ref(), xd.as_ref())?;
        let n_a = self.inner.n_actuators();
        let tau = match &tau {
            Some(tau) => {
                let (w, what) = if tau.as_array().shape().last() == Some(&n_a) {
                    (n_a, format!("one per actuator: {}", self.inner.actuator_names().join(", ")))
                } else {
                    (self.m(), self.coords_what())
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
        let mech = self.inner.clone();
        let t_m = run(py, move || {
            let branch = branch_of(x.as_ref(), xd.as_ref());
            let given = tau.as_ref().map(|(t, w)| (&t.data[..], *w));
            let t_m = motor_torque_rows(&mech, branch, &q.data, &qd.data, &qdd.data, given, allow_singular)?;
            Ok(dynamics::finite("motor torques", t_m)?)
        })?;
        arr_dyn(py, &shape, t_m)
    }

    /// The actuators, one entry per actuator (the coordinates', then the pair actuators';
    /// None: an ideal effort source): dicts of
    /// name, gear_ratio, efficiency, backdrive_efficiency, rotor_inertia (kg m^2), viscous,
    /// coulomb, stiction_speed
    /// and the limits peak_torque, continuous_torque (N m), max_speed (rad/s) (None when not
    /// given) and envelope ((k, 2) [speed, torque] points).
    #[getter]
    fn actuators<'py>(&self, py: Python<'py>) -> PyResult<Vec<Option<Bound<'py, PyDict>>>> {
        dynamics::transmission::motors(&self.inner)
            .map(|slot| {
                slot.map(|a| {
                    let d = PyDict::new(py);
                    d.set_item("name", &a.name)?;
                    d.set_item("gear_ratio", a.ratio)?;
                    d.set_item("efficiency", a.efficiency)?;
                    d.set_item("backdrive_efficiency", a.backdrive_efficiency)?;
                    d.set_item("rotor_inertia", a.rotor_inertia)?;
                    d.set_item("viscous", a.viscous)?;
                    d.set_item("coulomb", a.coulomb)?;
                    d.set_item("stiction_speed", a.stiction_speed)?;
                    d.set_item("peak_torque", a.limits.peak_torque)?;
                    d.set_item("continuous_torque", a.limits.continuous_torque)?;
                    d.set_item("max_speed", a.limits.max_speed)?;
                    let env = &a.limits.envelope;
                    d.set_item("envelope", arr2(py, env.len(), 2, env.as_flattened().to_vec())?)?;
                    Ok(d)
                })
                .transpose()
            })
            .collect()
    }

    /// The torque (N m) actuator `coordinate`'s motor can give at motor speeds `speed`
    /// (rad/s, any shape): its envelope, else its peak torque; None without limits.
    fn available_torque<'py>(
        &self,
        py: Python<'py>,
        coordinate: usize,
        speed: ArrayArg<'py>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        let Some(slot) = dynamics::transmission::motors(&self.inner).nth(coordinate) else {
            return Err(argument_error(
                Some("coordinate"),
                format!("actuator {coordinate} out of range: the model has {} actuators", self.inner.n_actuators()),
            ));
        };
        let Some(a) = slot else { return Ok(None) };
        let v = Values::read(&speed);
        let out: Option<Vec<f64>> = v.data.iter().map(|&w| a.limits.available_torque(w)).collect();
        out.map(|t| arr_dyn(py, &v.shape, t)).transpose()
    }

    /// The actuators' names: the coordinates', then the redundant actuators' on pairs.
    #[getter]
    fn actuator_names(&self) -> Vec<String> {
        self.inner.actuator_names()
    }

    /// Every actuator's effort (n_a,) for (q, qd, qdd), each (m,), shared by `method`
    /// ("min_norm", "min_max" or "preload" with `preload` one value per internal force),
    /// with the actuation matrix `B` (m, n_a) and the internal forces (r, n_a).
    #[pyo3(signature = (q, qd, qdd, method="min_norm", preload=None, x_start=None))]
    #[allow(clippy::too_many_arguments)]
    fn distribute_efforts<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        qdd: ArrayArg<'py>,
        method: &str,
        preload: Option<Vec<f64>>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        use dynamics::redundant::Distribution;
        let (q, qd, qdd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?, self.q_arg("qdd", &qdd)?);
        let x_start = x_start.map(|a| self.x_arg(&a)).transpose()?;
        let how = match (method, preload) {
            ("min_norm", None) => Distribution::MinNorm,
            ("min_max", None) => Distribution::MinMax,
            ("preload", Some(p)) => Distribution::Preload(p),
            _ => {
                return Err(argument_error(
                    Some("method"),
                    format!(
                        "method {method:?}: use \"min_norm\", \"min_max\", or \"preload\" with preload=[one value \
                     per internal force] (and preload only with it)"
                    ),
                ))
            }
        };
        let mech = self.inner.clone();
        let s = run(py, move || Ok(query::distribute_efforts(&mech, &q, &qd, &qdd, &how, x_start.as_deref())?))?;
        let act = &s.actuation;
        let d = PyDict::new(py);
        d.set_item("efforts", arr1(py, s.efforts))?;
        d.set_item("motor_torques", arr1(py, s.motor_torques))?;
        d.set_item("B", arr2(py, act.m, act.n_a, act.b.clone())?)?;
        d.set_item("internal", arr2(py, act.internal.len(), act.n_a, act.internal.concat())?)?;
        Ok(d)
    }

    /// Accelerations qdd (m,) at (q, qd) and time t (s) under every actuator's effort
    /// `efforts` (n_a,: the coordinates' first, as drive efforts (motor torques where a motor
    /// is), then the pair actuators').
    #[pyo3(signature = (q, qd, efforts, t=0.0))]
    fn forward_dynamics_actuated<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        efforts: ArrayArg<'py>,
        t: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?);
        let n_a = self.inner.n_actuators();
        let efforts = vector("efforts", &efforts, n_a, "one value per actuator (actuator_names)")?;
        check_time(t)?;
        let mech = self.inner.clone();
        let qdd = run(py, move || Ok(query::forward_actuated(&mech, &q, &qd, &efforts, t)?))?;
        Ok(arr1(py, qdd))
    }

    /// The regressor form along rows of a motion, on the branch of x (and with the body rates
    /// xd) as `inverse_dynamics`: `Y` (m, p) or (N, m, p), `tau_o` (m,) or (N, m) with
    /// efforts = Y pi + tau_o.
    #[pyo3(signature = (q, qd, qdd, x=None, xd=None, allow_singular=false))]
    #[allow(clippy::too_many_arguments)]
    fn regressor<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        qdd: ArrayArg<'py>,
        x: Option<ArrayArg<'py>>,
        xd: Option<ArrayArg<'py>>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (q, qd, qdd, x, xd) = self.motion_rows(&q, &qd, &qdd, x.as_ref(), xd.as_ref())?;
        let mech = self.inner.clone();
        let (m, p) = (self.m(), planardyn::dynamics::regressor::n_parameters(&mech));
        let (y, tau_o) = run(py, || {
            let branch = branch_of(x.as_ref(), xd.as_ref());
            Ok(regressor_rows(&mech, branch, &q.data, &qd.data, &qdd.data, allow_singular)?)
        })?;
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

    /// The model's parameters pi (4 per body: m, m cx, m cy, I_O; then the losses') and their
    /// names, in the order of the regressor's columns.
    #[getter]
    fn parameters(&self) -> (Vec<f64>, Vec<String>) {
        use planardyn::dynamics::regressor::{parameter_names, parameters};
        (parameters(&self.inner), parameter_names(&self.inner))
    }

    /// Pair reactions (p, 3): [F_x, F_y, M] that body a exerts on body b (N, N m).
    #[pyo3(signature = (q, qd, t=0.0, tau=None, allow_singular=false))]
    fn reactions<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        t: f64,
        tau: Option<ArrayArg<'py>>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?);
        let tau = tau.map(|a| self.q_arg("tau", &a)).transpose()?;
        check_time(t)?;
        let mech = self.inner.clone();
        let r = run(py, || {
            Ok(query::reactions(&mech, ForwardState { q: &q, qd: &qd, t, tau: tau.as_deref(), allow_singular })?)
        })?;
        arr2(py, r.len(), 3, r.concat())
    }

    /// Body accelerations (N, 3n) and pair reactions (N, p, 3) along a trajectory's rows, each
    /// on its own body coordinates x (`planardyn::dynamics::along`).
    #[pyo3(signature = (t, x, q, qd, tau, allow_singular=false))]
    #[allow(clippy::too_many_arguments)]
    fn along<'py>(
        &self,
        py: Python<'py>,
        t: ArrayArg<'py>,
        x: ArrayArg<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        tau: ArrayArg<'py>,
        allow_singular: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (m, nx, p) = (self.m(), self.inner.n_x(), self.inner.pairs.len());
        let what = self.coords_what();
        let x = rows("x", &x, nx, "body coordinates [X, Y, phi] per body")?;
        let (q, qd, tau) = (rows("q", &q, m, &what)?, rows("qd", &qd, m, &what)?, rows("tau", &tau, m, &what)?);
        let t = Values::read(&t);
        let mech = self.inner.clone();
        let out = run(py, || {
            let r = Rows { t: &t.data, x: &x.data, q: &q.data, qd: &qd.data, tau: &tau.data };
            Ok(dynamics::along(&mech, r, allow_singular)?)
        })?;
        let n = out.xdd.len() / nx;
        let d = PyDict::new(py);
        d.set_item("xdd", arr2(py, n, nx, out.xdd)?)?;
        d.set_item("reactions", arr3(py, (n, p, 3), out.reactions)?)?;
        Ok(d)
    }

    /// Positions, velocities and accelerations (N, P, 2) of the named points a link carries
    /// (`names`), for rows of x, xd, xdd (N, 3n).
    fn point_motion<'py>(
        &self,
        py: Python<'py>,
        x: ArrayArg<'py>,
        xd: ArrayArg<'py>,
        xdd: ArrayArg<'py>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let nx = self.inner.n_x();
        let what = "body coordinates [X, Y, phi] per body";
        let (x, xd, xdd) = (rows("x", &x, nx, what)?, rows("xd", &xd, nx, what)?, rows("xdd", &xdd, nx, what)?);
        if xd.data.len() != x.data.len() || xdd.data.len() != x.data.len() {
            return Err(argument_error(
                None,
                format!(
                    "x, xd and xdd must have the same shape, got {:?}, {:?} and {:?}",
                    x.shape, xd.shape, xdd.shape
                ),
            ));
        }
        let mech = &self.inner;
        let names: Vec<&str> =
            dynamics::carried_points(mech).iter().map(|(p, _)| mech.points[p.0].0.as_str()).collect();
        let [pos, vel, acc] = dynamics::point_motion(mech, &x.data, &xd.data, &xdd.data);
        let shape = (x.rows(), names.len(), 2);
        let d = PyDict::new(py);
        d.set_item("names", names)?;
        d.set_item("position", arr3(py, shape, pos)?)?;
        d.set_item("velocity", arr3(py, shape, vel)?)?;
        d.set_item("acceleration", arr3(py, shape, acc)?)?;
        Ok(d)
    }

    /// Kinetic and potential energy (J) at (q, qd), reached from `x_start` (else the drawing).
    #[pyo3(signature = (q, qd, x_start=None))]
    fn energy(
        &self,
        py: Python<'_>,
        q: ArrayArg<'_>,
        qd: ArrayArg<'_>,
        x_start: Option<ArrayArg<'_>>,
    ) -> PyResult<(f64, f64)> {
        let (q, qd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?);
        let x_start = x_start.map(|a| self.x_arg(&a)).transpose()?;
        let mech = self.inner.clone();
        let e = run(py, move || Ok(query::energy(&mech, &q, &qd, x_start.as_deref())?))?;
        Ok((e.kinetic, e.potential))
    }

    /// Simulate; see `planardyn.Mechanism.simulate` for the arguments.
    #[pyo3(signature = (t_end=None, method=None, rtol=None, atol=None, dt=None, t_eval=None, output_dt=None, q0=None, qd0=None, drives=None, progress=None, max_steps=None, motion=None, events=Vec::new(), dense_output=false))]
    #[allow(clippy::too_many_arguments)]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        t_end: Option<f64>,
        method: Option<String>,
        rtol: Option<f64>,
        atol: Option<f64>,
        dt: Option<f64>,
        t_eval: Option<ArrayArg<'py>>,
        output_dt: Option<f64>,
        q0: Option<ArrayArg<'py>>,
        qd0: Option<ArrayArg<'py>>,
        drives: Option<Py<PyAny>>,
        progress: Option<Py<PyAny>>,
        max_steps: Option<usize>,
        motion: Option<Vec<(usize, crate::simulate::MotionArg)>>,
        events: Vec<crate::simulate::EventArg>,
        dense_output: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let t_eval = t_eval
            .map(|a| {
                let v = Values::read(&a);
                if v.shape.len() != 1 {
                    return Err(argument_error(
                        Some("t_eval"),
                        format!("t_eval must be 1-D (output times in s), got shape {:?}", v.shape),
                    ));
                }
                crate::convert::finite("t_eval", &v.data)?;
                Ok(v.data)
            })
            .transpose()?;
        let args = planardyn::simulate::Overrides {
            t_end,
            method,
            rtol,
            atol,
            dt,
            t_eval,
            output_dt,
            q0: q0.map(|a| self.q_arg("q0", &a)).transpose()?,
            qd0: qd0.map(|a| self.q_arg("qd0", &a)).transpose()?,
            max_steps,
            // The caller's motions go to the run with its callables (`simulate::simulate`).
            motion: Vec::new(),
        };
        crate::simulate::simulate(
            py,
            &self.inner,
            args,
            drives,
            motion.unwrap_or_default(),
            progress,
            events,
            dense_output,
        )
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "<planardyn.Mechanism {:?}: {} bodies, {} pairs, {} dof ({}) from {}>",
            m.name,
            m.n_bodies(),
            m.pairs.len(),
            m.dof(),
            m.coordinate_names().join(", "),
            m.source
        )
    }
}

fn check_time(t: f64) -> PyResult<()> {
    if t.is_finite() {
        Ok(())
    } else {
        Err(argument_error(Some("t"), format!("t = {t} must be a finite time (s)")))
    }
}

fn planardyn_spec_json(mech: &Mechanism) -> PyResult<String> {
    serde_json::to_string(&mech.spec)
        .map_err(|e| PlanardynError::new_err(format!("cannot write the model as JSON: {e}")))
}

/// A motion's q, qd, qdd rows and the optional body coordinates x and rates xd of its rows.
type MotionRows = (Values, Values, Values, Option<Values>, Option<Values>);

/// The branch of a motion: the drawn one, from the first row's body coordinates (3n,), or
/// every row's (N, 3n); with body rates (x's shape, checked by `motion_rows`) every row's.
fn branch_of<'a>(x: Option<&'a Values>, xd: Option<&'a Values>) -> Branch<'a> {
    match (x, xd) {
        (None, _) => Branch::Drawing,
        (Some(x), Some(xd)) => Branch::Rows(&x.data, Some(&xd.data)),
        (Some(x), None) if x.shape.len() == 1 => Branch::From(&x.data),
        (Some(x), None) => Branch::Rows(&x.data, None),
    }
}
