//! `Mechanism` in JavaScript: an immutable, validated mechanism (the core's) and its
//! kinematics and dynamics at given coordinates. Every call checks its arguments and calls
//! one of the core's queries (`planardyn::dynamics::query`, `evaluate`, `along`), as the
//! Python glue's do; each makes its own buffers, so calls are reproducible: positions come by
//! continuation from the drawing, or from the body coordinates `xStart` of a neighbouring
//! state on the wanted branch.

use crate::convert::{array, rows, strings, vector, Obj};
use crate::elastic;
use crate::errors::{argument_error, js};
use crate::simulate::{run, SimulateOptions};
use planardyn::dynamics::query::{self, ForwardState};
use planardyn::dynamics::{self, carried_points, MapGrid, Rows};
use planardyn::kinematics::{self as kin, Chart};
use planardyn::model::pairs::{self, pair_geometry};
use planardyn::model::{PairId, PointId};
use planardyn::Mechanism;
use wasm_bindgen::prelude::*;

/// A validated planar mechanism (immutable). Made by `load`.
#[wasm_bindgen(js_name = Mechanism)]
pub struct WasmMechanism {
    inner: Mechanism,
}

impl WasmMechanism {
    pub fn new(inner: Mechanism) -> Self {
        WasmMechanism { inner }
    }

    fn coords_what(&self) -> String {
        format!("one value per coordinate: {}", self.inner.coordinate_names().join(", "))
    }

    fn q_arg(&self, name: &str, v: &[f64]) -> Result<(), JsValue> {
        vector(name, v, self.inner.dof(), &self.coords_what())
    }

    fn x_arg(&self, name: &str, v: &[f64]) -> Result<(), JsValue> {
        vector(name, v, self.inner.n_x(), "body coordinates [X, Y, phi] per body")
    }

    /// The arguments of an assembly checked: q (m), and `x_start` (3n) when given.
    fn start_args(&self, q: &[f64], x_start: Option<&[f64]>) -> Result<(), JsValue> {
        self.q_arg("q", q)?;
        x_start.map_or(Ok(()), |x| self.x_arg("xStart", x))
    }

    /// Positions, velocities, accelerations (rows of P x 2) of the carried points.
    fn point_rows(&self, obj: Obj, x: &[f64], xd: &[f64], xdd: &[f64]) -> Obj {
        let [pos, vel, acc] = dynamics::point_motion(&self.inner, x, xd, xdd);
        obj.f64s("points", &pos).f64s("pointVelocities", &vel).f64s("pointAccelerations", &acc)
    }
}

#[wasm_bindgen(js_class = Mechanism)]
impl WasmMechanism {
    /// What the page needs to know of the model: names, kinds, sizes, the drawing, the
    /// defaults of a run. `points` are the names of the points a link carries, in the order
    /// of every point array the engine returns; `bodies[i]` lists body i's points by name.
    pub fn info(&self) -> JsValue {
        let m = &self.inner;
        let (q0, qd0) = m.initial_state();
        let point = |p: PointId| m.points[p.0].0.as_str();
        let bodies = m.bodies.iter().map(|b| strings(b.points.iter().map(|(p, _)| point(*p))).into());
        let pair_list = m.pairs.iter().enumerate().map(|(k, p)| {
            let rows = m.pair_rows(PairId(k));
            Obj::new()
                .set("name", p.name.as_str())
                .set("kind", pairs::kind_name(p))
                .set("bodies", strings([m.link_name(p.a), m.link_name(p.b)]))
                .set("point", point(p.point))
                .set("rows", (rows.end - rows.start) as f64)
                .build()
        });
        let s = &m.simulate;
        let defaults = Obj::new()
            .set("tEnd", s.t_end)
            .set("method", s.method.clone())
            .set("rtol", s.rtol)
            .set("atol", s.atol)
            .set("dt", s.dt)
            .set("outputDt", s.output_dt);
        Obj::new()
            .set("name", m.name.as_str())
            .set("source", m.source.as_str())
            .set("warnings", strings(&m.warnings))
            .set("dof", m.dof() as f64)
            .set("coordinateNames", strings(m.coordinate_names()))
            .set("coordinateKinds", strings(m.coordinates.iter().map(|c| c.kind.name())))
            .set("driven", array(m.drives.iter().map(|d| d.is_some().into())))
            .set("actuators", strings(m.actuator_names()))
            .set("prescribed", array(m.motions.iter().map(|d| d.is_some().into())))
            .set("bodyNames", strings(m.body_names()))
            .set("bodies", array(bodies))
            .set("pairs", array(pair_list))
            .set("points", strings(carried_points(m).iter().map(|(p, _)| point(*p))))
            .set("groundPoints", strings(m.ground_points.iter().map(|p| point(*p))))
            .f64s("q0", &q0)
            .f64s("qd0", &qd0)
            .f64s("drawnQ", &m.drawn_q())
            .f64s("x0", &m.x0)
            .f64s("masses", &m.bodies.iter().map(|b| b.mass).collect::<Vec<_>>())
            .f64s("gravity", &m.gravity)
            .set("scale", m.scale)
            .set("compliant", !m.compliance.is_empty())
            .set("simulate", defaults.build())
            .build()
    }

    /// The specification the mechanism was built from, as JSON text (`load` of it gives the
    /// same mechanism back).
    #[wasm_bindgen(js_name = specJson)]
    pub fn spec_json(&self) -> Result<String, JsValue> {
        serde_json::to_string_pretty(&self.inner.spec)
            .map_err(|e| argument_error(None, format!("cannot write the model as JSON: {e}")))
    }

    /// Body coordinates x (3n; m, rad) at coordinates q (m; rad or m).
    pub fn assemble(&self, q: &[f64], x_start: Option<Vec<f64>>) -> Result<Vec<f64>, JsValue> {
        self.start_args(q, x_start.as_deref())?;
        js(query::assemble(&self.inner, q, x_start.as_deref()))
    }

    /// Rows of carried-point positions (P x 2 each; m) for rows of body coordinates x (3n).
    pub fn points(&self, x: &[f64]) -> Result<Vec<f64>, JsValue> {
        rows("x", x, self.inner.n_x(), "body coordinates [X, Y, phi] per body")?;
        let zeros = vec![0.0; x.len()];
        let [pos, _, _] = dynamics::point_motion(&self.inner, x, &zeros, &zeros);
        Ok(pos)
    }

    /// What a drawing shows of each pair at body coordinates x (3n), in world coordinates (m):
    /// per pair `{name, kind, pins: [x, y, ...], blocks: [x, y, ...], lines: [x0, y0, x1, y1,
    /// ...], circles: [x, y, r, ...]}`.
    #[wasm_bindgen(js_name = pairGeometry)]
    pub fn pair_geometry(&self, x: &[f64]) -> Result<JsValue, JsValue> {
        self.x_arg("x", x)?;
        let out = self.inner.pairs.iter().zip(pair_geometry(&self.inner, x)).map(|(p, g)| {
            let lines: Vec<f64> = g.lines.iter().flat_map(|l| [l[0][0], l[0][1], l[1][0], l[1][1]]).collect();
            let circles: Vec<f64> = g.circles.iter().flat_map(|(c, r)| [c[0], c[1], *r]).collect();
            Obj::new()
                .set("name", p.name.as_str())
                .set("kind", g.kind)
                .f64s("pins", g.pins.as_flattened())
                .f64s("blocks", g.blocks.as_flattened())
                .f64s("lines", &lines)
                .f64s("circles", &circles)
                .build()
        });
        Ok(array(out).into())
    }

    /// Everything a frame shows at (q, qd, qdd) (`planardyn::dynamics::evaluate`): x, xd, xdd
    /// (3n), tau (m), reactions (p x 3: F_x, F_y, M that body a exerts on b; N, N m), sigma
    /// and sigmaPassive, kinetic and potential (J), residual (m), and the carried points'
    /// positions, velocities and accelerations (P x 2).
    pub fn evaluate(&self, q: &[f64], qd: &[f64], qdd: &[f64], x_start: Option<Vec<f64>>) -> Result<JsValue, JsValue> {
        self.q_arg("q", q)?;
        self.q_arg("qd", qd)?;
        self.q_arg("qdd", qdd)?;
        if let Some(x) = &x_start {
            self.x_arg("xStart", x)?;
        }
        let e = js(dynamics::evaluate(&self.inner, q, qd, qdd, x_start.as_deref()))?;
        let obj = Obj::new()
            .f64s("x", &e.x)
            .f64s("xd", &e.xd)
            .f64s("xdd", &e.xdd)
            .f64s("tau", &e.tau)
            .f64s("reactions", e.reactions.as_flattened())
            .set("sigma", e.sigma)
            .set("sigmaPassive", e.sigma_passive)
            .set("kinetic", e.kinetic)
            .set("potential", e.potential)
            .set("residual", e.residual);
        Ok(self.point_rows(obj, &e.x, &e.xd, &e.xdd).build())
    }

    /// Singularity measures at body coordinates x (3n): `{sigma, sigmaPassive}` (smallest
    /// scaled singular values of J in the input chart and of the passive constraints).
    pub fn measures(&self, x: &[f64]) -> Result<JsValue, JsValue> {
        self.x_arg("x", x)?;
        let m = &self.inner;
        let sigma = kin::sigma_min(m, &Chart::Inputs, x);
        Ok(Obj::new().set("sigma", sigma).set("sigmaPassive", kin::passive_sigma_min(m, x)).build())
    }

    /// Rows `rows` (in that order) of the type II measure over coordinates k1 (columns, values
    /// `axis1`) and k2 (rows, `axis2`), the others as in q, on the branch of `xStart`
    /// (`planardyn::dynamics::sigma_rows`; which branch: `planardyn::dynamics::MapRows`, rows
    /// walked from column `i0` where it is by continuation): `{sigma (rows x axis1.length, NaN
    /// where it does not assemble), x (where the next rows continue)}`.
    #[wasm_bindgen(js_name = sigmaRows)]
    #[allow(clippy::too_many_arguments)]
    pub fn sigma_rows(
        &self,
        q: &[f64],
        k1: usize,
        k2: usize,
        axis1: &[f64],
        axis2: &[f64],
        i0: usize,
        rows: &[u32],
        x_start: &[f64],
    ) -> Result<JsValue, JsValue> {
        self.q_arg("q", q)?;
        let rows: Vec<usize> = rows.iter().map(|&j| j as usize).collect();
        let out = js(dynamics::sigma_rows(&self.inner, q, [k1, k2], [axis1, axis2], i0, &rows, x_start))?;
        Ok(Obj::new().f64s("sigma", &out.values).f64s("x", &out.x).build())
    }

    /// The natural modes of the compliant mechanism about coordinates q (its rigid pose, on the
    /// branch of `xStart`; `planardyn::elastic::modes_about`), each elastic drive's rotor held
    /// (`freeRotors` false) or free: `{omega (rad/s), omega2 (rad^2/s^2), dampingRatio, shapes
    /// (modes x 3n: mass-normalised body displacements [X, Y, phi]), x (3n: the pose)}`, by
    /// increasing frequency, about the pose without gravity's load (as the Python API's
    /// default: a drawn pose need not be an equilibrium). A model without a `compliance:`
    /// section throws an ArgumentError.
    pub fn modes(&self, q: &[f64], free_rotors: bool, x_start: Option<Vec<f64>>) -> Result<JsValue, JsValue> {
        self.start_args(q, x_start.as_deref())?;
        elastic::modes(&self.inner, q, free_rotors, x_start.as_deref())
    }

    /// The stiffness of the point `point` (on the first body that carries it) at coordinates q
    /// (its rigid pose, on the branch of `xStart`; `planardyn::elastic::stiffness_about`), in
    /// equilibrium with `load` (`LoadOption`: `{wrench: [F_x, F_y, M] (N, N, N m) at the point,
    /// preload: {actuator name: effort (N m or N)} of elastic drives, gravity}`, each absent for
    /// none) with its geometric terms: `{weakest (N/m: the translational stiffness in its
    /// weakest direction), direction ([d_x, d_y], unit), compliance (3 x 3 of [x, y, phi]; m/N,
    /// m/(N m), rad/N, rad/(N m)), x (3n: the pose)}`, as the Python API's `stiffness(mech, q,
    /// body=, point=, wrench=, preload=, gravity=)`. A model without a `compliance:` section
    /// throws an ArgumentError.
    pub fn stiffness(
        &self,
        q: &[f64],
        point: &str,
        x_start: Option<Vec<f64>>,
        load: JsValue,
    ) -> Result<JsValue, JsValue> {
        self.start_args(q, x_start.as_deref())?;
        elastic::stiffness(&self.inner, q, point, x_start.as_deref(), load)
    }

    /// Rows of an elastic map over coordinates k1 and k2 as `sigmaRows`' (the same grid, rows and
    /// branch; `planardyn::elastic::map_rows`), `value` a `MapOption`: `{kind: "frequency"}`
    /// (the first natural frequency, Hz; `freeRotors`) or `{kind: "stiffness", point, load}`
    /// (the weakest translational stiffness of `point`, N/m, under `load` as `stiffness`'s):
    /// `{values (rows x axis1.length, NaN where it does not assemble or has no value), x (where
    /// the next rows continue)}`.
    #[wasm_bindgen(js_name = elasticRows)]
    #[allow(clippy::too_many_arguments)]
    pub fn elastic_rows(
        &self,
        q: &[f64],
        k1: usize,
        k2: usize,
        axis1: &[f64],
        axis2: &[f64],
        i0: usize,
        rows: &[u32],
        x_start: &[f64],
        value: JsValue,
    ) -> Result<JsValue, JsValue> {
        self.q_arg("q", q)?;
        let rows: Vec<usize> = rows.iter().map(|&j| j as usize).collect();
        let grid = js(MapGrid::new(&self.inner, [k1, k2], [axis1, axis2], i0, &rows, x_start))?;
        elastic::elastic_rows(&self.inner, q, &grid, value)
    }

    /// Drive efforts tau (m; N m or N) for (q, qd, qdd).
    #[wasm_bindgen(js_name = inverseDynamics)]
    pub fn inverse_dynamics(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        x_start: Option<Vec<f64>>,
    ) -> Result<Vec<f64>, JsValue> {
        self.q_arg("qd", qd)?;
        self.q_arg("qdd", qdd)?;
        self.start_args(q, x_start.as_deref())?;
        js(query::inverse_dynamics(&self.inner, q, qd, qdd, x_start.as_deref()))
    }

    /// Accelerations qdd (m) at (q, qd) and time t (s) under efforts `tau` (m), else the
    /// model's drives; refused at a type II singularity.
    #[wasm_bindgen(js_name = forwardDynamics)]
    pub fn forward_dynamics(&self, q: &[f64], qd: &[f64], t: f64, tau: Option<Vec<f64>>) -> Result<Vec<f64>, JsValue> {
        self.forward_args(q, qd, t, tau.as_deref())?;
        js(query::forward_dynamics(
            &self.inner,
            ForwardState { q, qd, t, tau: tau.as_deref(), allow_singular: false, x_start: None },
        ))
    }

    /// Pair reactions (p x 3: F_x, F_y, M that body a exerts on b; N, N m) at (q, qd), time t
    /// (s), under efforts `tau` (m), else the model's drives.
    pub fn reactions(&self, q: &[f64], qd: &[f64], t: f64, tau: Option<Vec<f64>>) -> Result<Vec<f64>, JsValue> {
        self.forward_args(q, qd, t, tau.as_deref())?;
        Ok(js(query::reactions(
            &self.inner,
            ForwardState { q, qd, t, tau: tau.as_deref(), allow_singular: false, x_start: None },
        ))?
        .concat())
    }

    /// Body accelerations and pair reactions along rows of a run (t (N), x and xd (N x 3n),
    /// q, qd, tau (N x m)), each row on its own branch (`planardyn::dynamics::along`), with the
    /// carried points' positions, velocities and accelerations: `{xdd, reactions (N x p x 3),
    /// points, pointVelocities, pointAccelerations (N x P x 2)}`.
    pub fn along(
        &self,
        t: &[f64],
        x: &[f64],
        xd: &[f64],
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
    ) -> Result<JsValue, JsValue> {
        let (m, nx, what) = (self.inner.dof(), self.inner.n_x(), self.coords_what());
        let n = rows("x", x, nx, "body coordinates [X, Y, phi] per body")?;
        if rows("xd", xd, nx, "body rates per body")? != n {
            return Err(argument_error(Some("xd"), format!("xd needs {n} rows, as x has")));
        }
        for (name, v) in [("q", q), ("qd", qd), ("tau", tau)] {
            if rows(name, v, m, &what)? != n {
                return Err(argument_error(Some(name), format!("{name} needs {n} rows, as x has")));
            }
        }
        if t.len() != n {
            return Err(argument_error(Some("t"), format!("t needs {n} times, as x has rows")));
        }
        let out = js(dynamics::along(&self.inner, Rows { t, x, q, qd, tau }, true))?;
        let obj = Obj::new().f64s("xdd", &out.xdd).f64s("reactions", &out.reactions);
        Ok(self.point_rows(obj, x, xd, &out.xdd).build())
    }

    /// Simulate from the model's defaults changed by `options` (`SimulateOptions`: the model
    /// file's t_end, method, rtol, atol, dt, output_dt; q0, qd0, maxSteps, motion (speeds of
    /// driven coordinates), events); the run as typed arrays, as `Mechanism.simulate` in Python.
    pub fn simulate(&self, options: JsValue) -> Result<JsValue, JsValue> {
        let options: SimulateOptions = crate::convert::from_js("options", options)?;
        run(&self.inner, options)
    }
}

impl WasmMechanism {
    /// The arguments of a forward evaluation checked: q, qd and tau (m each), a finite t.
    fn forward_args(&self, q: &[f64], qd: &[f64], t: f64, tau: Option<&[f64]>) -> Result<(), JsValue> {
        self.q_arg("qd", qd)?;
        if !t.is_finite() {
            return Err(argument_error(Some("t"), format!("t = {t} must be a finite time (s)")));
        }
        self.q_arg("q", q)?;
        tau.map_or(Ok(()), |tau| self.q_arg("tau", tau))
    }
}
