//! `planardyn._core.Mechanism`: an immutable, validated mechanism (an `Arc` of the core's)
//! and its kinematics and dynamics at one state. The methods check and convert their
//! arguments, call one of the core's queries (`planardyn::dynamics::query`) with the GIL
//! released, and convert its typed result (`crate::query`); each query makes its own
//! buffers, so calls are reproducible (positions come by continuation from the drawing) and
//! thread-safe. The bodies of the larger model getters are in `model.rs`, those of the methods
//! along the rows of a motion in `rows.rs`.

use crate::convert::{arr1, arr2, vector, Floats, Values};
use crate::errors::{run, Failure};
use crate::exceptions::{argument_error, PlanardynError};
use crate::model;
use crate::query::{Named, ToPython};
use crate::rows::{self, MotionArgs};
use planardyn::dynamics::query::{self, ForwardState};
use planardyn::dynamics::redundant::Distribution;
use planardyn::simulate::Prepared;
use planardyn::Mechanism;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Arc, OnceLock};

type ArrayArg<'py> = Floats<'py>;

/// A validated planar mechanism (immutable). Made by `load`/`loads`.
#[pyclass(frozen, module = "planardyn._core", name = "Mechanism")]
pub struct PyMechanism {
    pub inner: Arc<Mechanism>,
    /// The set-up of its runs, made at the first and shared by every `simulate` and batch
    /// run after (`planardyn::simulate::Prepared`).
    prepared: OnceLock<Arc<Prepared>>,
    /// The settings of its last `simulate`, for the next with the same arguments.
    last_settings: crate::simulate::LastSettings,
}

/// Coordinates q and rates qd (m,), the efforts tau (m,) if given: where forward dynamics is asked.
type ForwardArgs = (Vec<f64>, Vec<f64>, Option<Vec<f64>>);

impl PyMechanism {
    pub fn new(mech: Mechanism) -> Self {
        PyMechanism { inner: Arc::new(mech), prepared: OnceLock::new(), last_settings: Default::default() }
    }

    /// The set-up of this mechanism's runs, made at the first call with the GIL released.
    pub fn prepared(&self, py: Python<'_>) -> &Arc<Prepared> {
        self.prepared.get_or_init(|| py.detach(|| Arc::new(Prepared::new(&self.inner))))
    }

    fn m(&self) -> usize {
        self.inner.dof()
    }

    fn q_arg(&self, name: &str, a: &ArrayArg<'_>) -> PyResult<Vec<f64>> {
        vector(name, a, self.m(), &rows::coords_what(&self.inner))
    }

    /// Body coordinates (3n,) on the wanted branch, where a continuation starts.
    fn x_start(&self, a: Option<ArrayArg<'_>>) -> PyResult<Option<Vec<f64>>> {
        a.map(|a| vector("x_start", &a, self.inner.n_x(), "body coordinates [X, Y, phi] per body")).transpose()
    }

    /// The arguments of a forward query, checked: q, qd, tau (m,), a finite time t (s).
    fn forward_args(
        &self,
        q: &ArrayArg<'_>,
        qd: &ArrayArg<'_>,
        t: f64,
        tau: Option<&ArrayArg<'_>>,
    ) -> PyResult<ForwardArgs> {
        let (q, qd) = (self.q_arg("q", q)?, self.q_arg("qd", qd)?);
        let tau = tau.map(|a| self.q_arg("tau", a)).transpose()?;
        check_time(t)?;
        Ok((q, qd, tau))
    }

    /// A core query run with the GIL released, its result converted.
    fn query<'py, T: ToPython + Send, E: Into<Failure>>(
        &self,
        py: Python<'py>,
        f: impl FnOnce(&Mechanism) -> Result<T, E> + Send,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mech = &*self.inner;
        run(py, || f(mech).map_err(Into::into))?.to_python(py, mech)
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
    /// "angle" or "displacement" per actuator (`actuator_names`): what its effort turns.
    #[getter]
    fn actuator_kinds(&self) -> Vec<&'static str> {
        model::actuator_kinds(&self.inner)
    }
    /// For each body, its points as (name, (s_x, s_y)) in the body frame (m): origin at the
    /// centre of mass, rotated by the body angle phi.
    #[getter]
    fn body_points(&self) -> Vec<Vec<(String, (f64, f64))>> {
        model::body_points(&self.inner)
    }
    /// The pairs as dicts: name, kind ('revolute' | 'prismatic' | 'gear' | 'slot'), bodies
    /// (a, b) by name ('ground' for the fixed body), point (name; a gear's first centre),
    /// axis (the guide or slot direction in a's frame, or None), rows (start, stop): the
    /// pair's rows among the pair-constraint rows (`structure.constraint_jacobian`).
    #[getter]
    fn pairs<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        model::pairs(py, &self.inner)
    }
    /// What the drawings show of each pair at body coordinates x (3n,), in world
    /// coordinates (m): a dict per pair with name, kind, pins [(x, y)] (pin joints),
    /// blocks [(x, y)] (sliding blocks), lines [((x, y), (x, y))] (guides, slots, rack pitch
    /// lines) and circles [((x, y), r)] (pitch circles).
    fn pair_geometry<'py>(&self, py: Python<'py>, x: ArrayArg<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        model::pair_geometry(py, &self.inner, &x)
    }
    /// The model file's `simulate` defaults (None where not given).
    #[getter]
    fn simulate_defaults<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        model::simulate_defaults(py, &self.inner)
    }

    /// The specification the mechanism was built from, as JSON text (`loads(..., 'json')`
    /// gives the same mechanism back).
    fn spec_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner.spec)
            .map_err(|e| PlanardynError::new_err(format!("cannot write the model as JSON: {e}")))
    }

    /// The actuators, one entry per actuator (the coordinates', then the pair actuators';
    /// None: an ideal effort source): dicts of
    /// name, gear_ratio, efficiency, backdrive_efficiency, rotor_inertia (kg m^2), viscous,
    /// coulomb, stiction_speed
    /// and the limits peak_torque, continuous_torque (N m), max_speed (rad/s) (None when not
    /// given) and envelope ((k, 2) [speed, torque] points).
    #[getter]
    fn actuators<'py>(&self, py: Python<'py>) -> PyResult<Vec<Option<Bound<'py, PyDict>>>> {
        model::actuators(py, &self.inner)
    }

    /// The torque (N m) actuator `coordinate`'s motor can give at motor speeds `speed`
    /// (rad/s, any shape): its envelope, else its peak torque; None without limits.
    fn available_torque<'py>(
        &self,
        py: Python<'py>,
        coordinate: usize,
        speed: ArrayArg<'py>,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        model::available_torque(py, &self.inner, coordinate, &speed)
    }

    /// The actuators' names: the coordinates', then the redundant actuators' on pairs.
    #[getter]
    fn actuator_names(&self) -> Vec<String> {
        self.inner.actuator_names()
    }

    /// The model's parameters pi (4 per body: m, m cx, m cy, I_O; then the losses') and their
    /// names, in the order of the regressor's columns.
    #[getter]
    fn parameters(&self) -> (Vec<f64>, Vec<String>) {
        use planardyn::dynamics::regressor::{parameter_names, parameters};
        (parameters(&self.inner), parameter_names(&self.inner))
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
        let (q, x_start) = (self.q_arg("q", &q)?, self.x_start(x_start)?);
        self.query(py, |mech| query::assemble(mech, &q, x_start.as_deref()))
    }

    /// World positions of every named point: (P, 2) for x of shape (3n,), (N, P, 2) for (N, 3n).
    fn point_positions<'py>(&self, py: Python<'py>, x: ArrayArg<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows::point_positions(py, &self.inner, &x)
    }

    /// Positions and analogues at q (and velocities with qd); see the Python docstring.
    #[pyo3(signature = (q, qd=None, x_start=None))]
    fn kinematics<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: Option<ArrayArg<'py>>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let q = self.q_arg("q", &q)?;
        let qd = qd.map(|a| self.q_arg("qd", &a)).transpose()?;
        let x_start = self.x_start(x_start)?;
        self.query(py, |mech| query::kinematics(mech, &q, qd.as_deref(), x_start.as_deref()))
    }

    /// Mass matrix A = U^T M U (m, m) at q, on the branch of x_start (else the drawn one).
    #[pyo3(signature = (q, allow_singular=false, x_start=None))]
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        allow_singular: bool,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, x_start) = (self.q_arg("q", &q)?, self.x_start(x_start)?);
        let a = run(py, || Ok(query::mass_matrix(&self.inner, &q, x_start.as_deref(), allow_singular)?))?;
        arr2(py, self.m(), self.m(), a)
    }

    /// Accelerations qdd (m,) at (q, qd), time t (s), efforts tau (m,) or the model's drives.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (q, qd, t=0.0, tau=None, allow_singular=false, x_start=None))]
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        t: f64,
        tau: Option<ArrayArg<'py>>,
        allow_singular: bool,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, tau) = self.forward_args(&q, &qd, t, tau.as_ref())?;
        let x_start = self.x_start(x_start)?;
        let at = ForwardState { q: &q, qd: &qd, t, tau: tau.as_deref(), allow_singular, x_start: x_start.as_deref() };
        self.query(py, |mech| query::forward_dynamics(mech, at))
    }

    /// Exact first derivatives of forward dynamics at (q, qd), time t (s), with efforts tau
    /// (m,) or the model's drives held fixed: a dict of `qdd` (m,) and `dq`, `dqd`, `dtau`
    /// (m, m), entry [i, k] = d qdd_i / d (q, qd, tau)_k.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (q, qd, t=0.0, tau=None, allow_singular=false, x_start=None))]
    fn forward_dynamics_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        t: f64,
        tau: Option<ArrayArg<'py>>,
        allow_singular: bool,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, tau) = self.forward_args(&q, &qd, t, tau.as_ref())?;
        let x_start = self.x_start(x_start)?;
        let at = ForwardState { q: &q, qd: &qd, t, tau: tau.as_deref(), allow_singular, x_start: x_start.as_deref() };
        self.query(py, |mech| query::forward_derivatives(mech, at).map(|d| Named(d, ["qdd", "dtau"])))
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
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, qdd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?, self.q_arg("qdd", &qdd)?);
        self.query(py, |mech| {
            query::inverse_derivatives(mech, &q, &qd, &qdd, allow_singular).map(|d| Named(d, ["tau", "dqdd"]))
        })
    }

    /// Pair reactions (p, 3): [F_x, F_y, M] that body a exerts on body b (N, N m).
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (q, qd, t=0.0, tau=None, allow_singular=false, x_start=None))]
    fn reactions<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        t: f64,
        tau: Option<ArrayArg<'py>>,
        allow_singular: bool,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, tau) = self.forward_args(&q, &qd, t, tau.as_ref())?;
        let x_start = self.x_start(x_start)?;
        let at = ForwardState { q: &q, qd: &qd, t, tau: tau.as_deref(), allow_singular, x_start: x_start.as_deref() };
        self.query(py, |mech| query::reactions(mech, at))
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
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, qdd) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?, self.q_arg("qdd", &qdd)?);
        let x_start = self.x_start(x_start)?;
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
        self.query(py, |mech| query::distribute_efforts(mech, &q, &qd, &qdd, &how, x_start.as_deref()))
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
        self.query(py, |mech| query::forward_actuated(mech, &q, &qd, &efforts, t))
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
        let motion = MotionArgs { q: &q, qd: &qd, qdd: &qdd, x: x.as_ref(), xd: xd.as_ref() };
        rows::inverse_dynamics(py, &self.inner, motion, allow_singular)
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
        let motion = MotionArgs { q: &q, qd: &qd, qdd: &qdd, x: x.as_ref(), xd: xd.as_ref() };
        rows::dissipated_power(py, &self.inner, motion, allow_singular)
    }

    /// Motor torques (N m, motor side) along (q, qd, qdd), each (m,) or (N, m), on the branch
    /// of x (and with the rates xd) as `inverse_dynamics`: of the joint-side efforts `tau`,
    /// (m,) / (N, m) or every actuator's (n_a,) / (N, n_a), or of the motion's own inverse
    /// dynamics without `tau`; on an actuator without a motor, the effort itself. `recorded`:
    /// x and xd are a run's own rows (a result's), its state: the rates are not checked
    /// against qd (`Branch::Run`).
    #[pyo3(signature = (q, qd, qdd, tau=None, x=None, xd=None, allow_singular=false, recorded=false))]
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
        recorded: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let motion = MotionArgs { q: &q, qd: &qd, qdd: &qdd, x: x.as_ref(), xd: xd.as_ref() };
        rows::motor_torques(py, &self.inner, motion, tau.as_ref(), allow_singular, recorded)
    }

    /// A run's motor torques (N m) along its rows (t (N,), q, qd, qdd, tau (N, m), x, xd (N, 3n):
    /// a result's, `recorded` and singular rows allowed, as `motor_torques`), each row's outcome
    /// kept: NaN on a row whose losses fail (its friction efforts do not settle, its gears
    /// jam), and what the run's message says of those rows (the core's note, None without).
    #[allow(clippy::too_many_arguments)]
    fn run_motor_torques<'py>(
        &self,
        py: Python<'py>,
        t: ArrayArg<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        qdd: ArrayArg<'py>,
        tau: ArrayArg<'py>,
        x: ArrayArg<'py>,
        xd: ArrayArg<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Option<String>)> {
        let motion = MotionArgs { q: &q, qd: &qd, qdd: &qdd, x: Some(&x), xd: Some(&xd) };
        rows::run_motor_torques(py, &self.inner, &t, motion, &tau)
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
        let motion = MotionArgs { q: &q, qd: &qd, qdd: &qdd, x: x.as_ref(), xd: xd.as_ref() };
        rows::regressor(py, &self.inner, motion, allow_singular)
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
        rows::along(py, &self.inner, &t, &x, &q, &qd, &tau, allow_singular)
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
        rows::point_motion(py, &self.inner, &x, &xd, &xdd)
    }

    /// Kinetic and potential energy (J) at (q, qd), reached from `x_start` (else the drawing).
    #[pyo3(signature = (q, qd, x_start=None))]
    fn energy<'py>(
        &self,
        py: Python<'py>,
        q: ArrayArg<'py>,
        qd: ArrayArg<'py>,
        x_start: Option<ArrayArg<'py>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (q, qd, x_start) = (self.q_arg("q", &q)?, self.q_arg("qd", &qd)?, self.x_start(x_start)?);
        self.query(py, |mech| query::energy(mech, &q, &qd, x_start.as_deref()))
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
    ) -> PyResult<crate::run::PyRun> {
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
            self.prepared(py),
            &self.last_settings,
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
