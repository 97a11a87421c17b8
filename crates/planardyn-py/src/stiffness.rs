//! Stiffness and vibration (`planardyn.stiffness`): the core's `planardyn::elastic` results
//! as dicts of numpy arrays; names (bodies, points, actuators) resolved to the core's ids.

use crate::convert::{arr1, arr2, vector, Floats};
use crate::errors::{kinematics_error, run, Failure};
use crate::exceptions::argument_error;
use crate::mechanism::PyMechanism;
use planardyn::elastic::{self, CartesianStiffness, Load, Modes, Output};
use planardyn::integrate::{Method, Options};
use planardyn::model::BodyId;
use planardyn::{Mechanism, Workspace};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::HashMap;

type ArrayArg<'py> = Floats<'py>;

fn coords(mech: &Mechanism, name: &str, a: &ArrayArg<'_>) -> PyResult<Vec<f64>> {
    let what = format!("one value per coordinate: {}", mech.coordinate_names().join(", "));
    vector(name, a, mech.dof(), &what)
}

fn body(mech: &Mechanism, name: &str) -> PyResult<BodyId> {
    mech.body_id(name).ok_or_else(|| {
        argument_error(Some("body"), format!("unknown body '{name}'; bodies are: {}", mech.body_names().join(", ")))
    })
}

/// The output: a body's point (default: its centre of mass).
fn output(mech: &Mechanism, body_name: &str, point: Option<&str>) -> PyResult<Output> {
    let b = body(mech, body_name)?;
    let point = point
        .map(|p| {
            let id = mech.point_id(p).filter(|id| mech.bodies[b.0].points.iter().any(|(q, _)| q == id));
            id.ok_or_else(|| {
                let names: Vec<&str> =
                    mech.bodies[b.0].points.iter().map(|(q, _)| mech.points[q.0].0.as_str()).collect();
                argument_error(
                    Some("point"),
                    format!("body '{body_name}' does not carry point '{p}'; its points are: {}", names.join(", ")),
                )
            })
        })
        .transpose()?;
    Ok(Output { body: b, point })
}

fn load(
    py: Python<'_>,
    mech: &Mechanism,
    wrench: Option<ArrayArg<'_>>,
    preload: Option<HashMap<String, f64>>,
    gravity: bool,
) -> PyResult<Load> {
    let w = match wrench {
        Some(w) => vector("wrench", &w, 3, "[F_x, F_y, M] in N, N, N m")?,
        None => vec![0.0; 3],
    };
    Load::named(mech, [w[0], w[1], w[2]], preload.unwrap_or_default(), gravity).map_err(|e| kinematics_error(py, &e))
}

fn cartesian<'py>(py: Python<'py>, s: &CartesianStiffness) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let flat3 = |m: &[[f64; 3]; 3]| m.iter().flatten().copied().collect::<Vec<_>>();
    d.set_item("pose", arr1(py, s.pose.to_vec()))?;
    d.set_item("compliance", arr2(py, 3, 3, flat3(&s.compliance))?)?;
    d.set_item("stiffness", s.stiffness.as_ref().map(|k| arr2(py, 3, 3, flat3(k))).transpose()?)?;
    let flat2 = |m: &[[f64; 2]; 2]| m.iter().flatten().copied().collect::<Vec<_>>();
    d.set_item("translational", s.translational.as_ref().map(|k| arr2(py, 2, 2, flat2(k))).transpose()?)?;
    d.set_item("freedoms", s.freedoms)?;
    let w = elastic::weakest_direction(s, None);
    d.set_item("weakest_direction", arr1(py, w.direction[..2].to_vec()))?;
    d.set_item("weakest_stiffness", w.stiffness)?;
    Ok(d)
}

/// The Cartesian compliance and stiffness of `body`'s `point` (default its centre of mass) at
/// coordinates q, in equilibrium with `wrench` [F_x, F_y, M] (N, N, N m) at the point and the
/// `preload` efforts of elastic drives by actuator name, and (`gravity`) the model's gravity
/// (geometric terms included).
#[pyfunction]
#[pyo3(signature = (mech, q, body, point=None, wrench=None, preload=None, gravity=false))]
#[allow(clippy::too_many_arguments)]
pub fn stiffness<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    q: ArrayArg<'py>,
    body: &str,
    point: Option<&str>,
    wrench: Option<ArrayArg<'py>>,
    preload: Option<HashMap<String, f64>>,
    gravity: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let (q, out, load) = (coords(m, "q", &q)?, output(m, body, point)?, load(py, m, wrench, preload, gravity)?);
    let s = run(py, || Ok::<_, Failure>(elastic::stiffness(m, &q, out, &load, &mut Workspace::new(m))?))?;
    cartesian(py, &s)
}

/// The direction in which a compliance (3, 3) gives most, rotations scaled by `length` (m):
/// (direction [d_x, d_y, d_phi], stiffness N/m).
#[pyfunction]
pub fn weakest_direction<'py>(
    py: Python<'py>,
    compliance: ArrayArg<'py>,
    length: f64,
) -> PyResult<(Bound<'py, PyAny>, f64)> {
    let c = vector("compliance", &compliance, 9, "a (3, 3) compliance, row-major")?;
    if !length.is_finite() || length <= 0.0 {
        return Err(argument_error(Some("length"), format!("the characteristic length must be > 0 m, got {length}")));
    }
    let s = CartesianStiffness {
        pose: [0.0; 3],
        compliance: std::array::from_fn(|i| std::array::from_fn(|j| c[3 * i + j])),
        stiffness: None,
        translational: None,
        freedoms: 3,
    };
    let w = elastic::weakest_direction(&s, Some(length));
    Ok((arr1(py, w.direction.to_vec()), w.stiffness))
}

/// The deflection of `body`'s `point` under `wrench` and (`gravity`) the model's gravity,
/// linear and non-linear (in `steps` load increments), with the tangent compliance at the
/// loaded equilibrium.
#[pyfunction]
#[pyo3(signature = (mech, q, body, wrench, point=None, steps=10, preload=None, gravity=false))]
#[allow(clippy::too_many_arguments)]
pub fn deflection<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    q: ArrayArg<'py>,
    body: &str,
    wrench: ArrayArg<'py>,
    point: Option<&str>,
    steps: usize,
    preload: Option<HashMap<String, f64>>,
    gravity: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let (q, out, load) = (coords(m, "q", &q)?, output(m, body, point)?, load(py, m, Some(wrench), preload, gravity)?);
    if !(1..=10_000).contains(&steps) {
        return Err(argument_error(Some("steps"), format!("steps must be 1 to 10000, got {steps}")));
    }
    let d = run(py, || Ok::<_, Failure>(elastic::deflection(m, &q, out, &load, steps, &mut Workspace::new(m))?))?;
    let out = PyDict::new(py);
    out.set_item("linear", arr1(py, d.linear.to_vec()))?;
    out.set_item("nonlinear", arr1(py, d.nonlinear.to_vec()))?;
    out.set_item("tangent", cartesian(py, &d.tangent)?)?;
    out.set_item("x", arr1(py, d.x))?;
    Ok(out)
}

fn modes_dict<'py>(py: Python<'py>, modes: Modes, width: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = modes.omega2.len();
    d.set_item("omega", arr1(py, modes.omega()))?;
    d.set_item("omega2", arr1(py, modes.omega2))?;
    d.set_item("damping_ratio", arr1(py, modes.damping_ratio))?;
    d.set_item("shapes", arr2(py, n, width, modes.shapes.concat())?)?;
    Ok(d)
}

/// Natural modes of the compliant mechanism about q: `omega` (rad/s), `omega2`,
/// `damping_ratio`, `shapes` (k, 3n) body displacements; rotors held or free; with `gravity`
/// about the pose as the equilibrium under the model's gravity.
#[pyfunction]
#[pyo3(signature = (mech, q, free_rotors=false, gravity=false))]
pub fn modes<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    q: ArrayArg<'py>,
    free_rotors: bool,
    gravity: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let q = coords(m, "q", &q)?;
    let modes = run(py, || Ok::<_, Failure>(elastic::modes(m, &q, free_rotors, gravity, &mut Workspace::new(m))?))?;
    modes_dict(py, modes, m.n_x())
}

/// Small oscillations of a passive mechanism about q: as `modes`, shapes (k, m) in coordinates.
#[pyfunction]
pub fn small_oscillations<'py>(py: Python<'py>, mech: &PyMechanism, q: ArrayArg<'py>) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let q = coords(m, "q", &q)?;
    let modes = run(py, || Ok::<_, Failure>(elastic::small_oscillations(m, &q, &mut Workspace::new(m))?))?;
    modes_dict(py, modes, m.dof())
}

/// The equilibrium of a passive mechanism nearest q_start (m,).
#[pyfunction]
pub fn equilibrium<'py>(py: Python<'py>, mech: &PyMechanism, q_start: ArrayArg<'py>) -> PyResult<Bound<'py, PyAny>> {
    let m = &*mech.inner;
    let q = coords(m, "q_start", &q_start)?;
    let q = run(py, || Ok::<_, Failure>(elastic::equilibrium(m, &q, &mut Workspace::new(m))?))?;
    Ok(arr1(py, q))
}

/// The linearised state-space model (A, B, C, D) at (q, qd) with efforts tau; outputs the
/// coordinates, then each (body, point)'s [x, y].
#[pyfunction]
#[pyo3(signature = (mech, q, qd, tau, points=Vec::new()))]
pub fn state_space<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    q: ArrayArg<'py>,
    qd: ArrayArg<'py>,
    tau: ArrayArg<'py>,
    points: Vec<(String, String)>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let (q, qd, tau) = (coords(m, "q", &q)?, coords(m, "qd", &qd)?, coords(m, "tau", &tau)?);
    let mut pts = Vec::new();
    for (b, p) in &points {
        let out = output(m, b, Some(p))?;
        let id = out.point.expect("given");
        let s = m.bodies[out.body.0].points.iter().find(|(q, _)| *q == id).map(|x| x.1).expect("carried");
        pts.push((out.body, s));
    }
    let ss = run(py, || Ok::<_, Failure>(elastic::linearize(m, &q, &qd, &tau, &pts, &mut Workspace::new(m))?))?;
    state_space_dict(py, ss)
}

fn state_space_dict(py: Python<'_>, ss: elastic::StateSpace) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("A", arr2(py, ss.n_states, ss.n_states, ss.a)?)?;
    d.set_item("B", arr2(py, ss.n_states, ss.n_inputs, ss.b)?)?;
    d.set_item("C", arr2(py, ss.n_outputs, ss.n_states, ss.c)?)?;
    d.set_item("D", arr2(py, ss.n_outputs, ss.n_inputs, ss.d)?)?;
    Ok(d)
}

/// The linearised state-space model (A, B, C, D) of the compliant mechanism with its rotors
/// free about q as its equilibrium (under the model's gravity with `gravity`): inputs the
/// motor torques of the elastic drives with a rotor; outputs the coordinates, then each
/// (body, point)'s [x, y].
#[pyfunction]
#[pyo3(signature = (mech, q, points=Vec::new(), gravity=false))]
pub fn compliant_state_space<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    q: ArrayArg<'py>,
    points: Vec<(String, String)>,
    gravity: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let q = coords(m, "q", &q)?;
    let outs = points.iter().map(|(b, p)| output(m, b, Some(p))).collect::<PyResult<Vec<_>>>()?;
    let ss =
        run(py, || Ok::<_, Failure>(elastic::linearize_compliant(m, &q, gravity, &outs, &mut Workspace::new(m))?))?;
    state_space_dict(py, ss)
}

/// The flexible-joint simulation (elastic drives' rotors as coordinates of their own) from the
/// model's start to `t_end` (s), output every `output_dt` (s): `t` (N,), `q`, `qd` (N, m),
/// `theta`, `thetad` (N, r) the rotors joint side, `energy`, `work` (the motors'),
/// `dissipated` (the transmission dampers') (N,) J.
#[pyfunction]
#[pyo3(signature = (mech, t_end, output_dt, method="dop853", rtol=1e-9, atol=1e-12))]
pub fn simulate_flexible<'py>(
    py: Python<'py>,
    mech: &PyMechanism,
    t_end: f64,
    output_dt: f64,
    method: &str,
    rtol: f64,
    atol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &*mech.inner;
    let method: Method = method.parse().map_err(|e: String| argument_error(Some("method"), e))?;
    let options = Options::tol(rtol, atol);
    let run = run(py, || Ok::<_, Failure>(elastic::simulate_flexible(m, t_end, output_dt, method, &options)?))?;
    let n = run.t.len();
    let width = |rows: &[Vec<f64>]| rows.first().map_or(0, Vec::len);
    let d = PyDict::new(py);
    d.set_item("q", arr2(py, n, width(&run.q), run.q.concat())?)?;
    d.set_item("qd", arr2(py, n, width(&run.qd), run.qd.concat())?)?;
    d.set_item("theta", arr2(py, n, width(&run.theta), run.theta.concat())?)?;
    d.set_item("thetad", arr2(py, n, width(&run.thetad), run.thetad.concat())?)?;
    d.set_item("t", arr1(py, run.t))?;
    d.set_item("energy", arr1(py, run.energy))?;
    d.set_item("work", arr1(py, run.work))?;
    d.set_item("dissipated", arr1(py, run.dissipated))?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate_flexible, m)?)?;
    m.add_function(wrap_pyfunction!(stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(weakest_direction, m)?)?;
    m.add_function(wrap_pyfunction!(deflection, m)?)?;
    m.add_function(wrap_pyfunction!(modes, m)?)?;
    m.add_function(wrap_pyfunction!(small_oscillations, m)?)?;
    m.add_function(wrap_pyfunction!(equilibrium, m)?)?;
    m.add_function(wrap_pyfunction!(state_space, m)?)?;
    m.add_function(wrap_pyfunction!(compliant_state_space, m)?)
}
