//! The model's data on `planardyn._core.Mechanism`: names, sizes, the drawing, inertia, the
//! pairs and their geometry, the actuators and the parameters, the file's `simulate`
//! defaults, as Python values: the bodies of `Mechanism`'s getters and methods of these names.

use crate::convert::{arr2, arr_dyn, vector, Floats, Values};
use crate::exceptions::argument_error;
use planardyn::dynamics;
use planardyn::model::pairs::{self, Relative};
use planardyn::model::{CoordinateKind, PairId};
use planardyn::Mechanism;
use pyo3::prelude::*;
use pyo3::types::PyDict;

type ArrayArg<'py> = Floats<'py>;

/// `Mechanism.actuator_kinds` (the getter's doc there).
pub fn actuator_kinds(mech: &Mechanism) -> Vec<&'static str> {
    let pairs = mech.coordinates.iter().map(|c| c.pair).chain(mech.pair_actuators.iter().map(|a| a.pair));
    pairs.map(|p| pairs::coordinate_kind(&mech.pairs[p.0]).map_or("displacement", CoordinateKind::name)).collect()
}

/// `Mechanism.body_points` (the getter's doc there).
pub fn body_points(mech: &Mechanism) -> Vec<Vec<(String, (f64, f64))>> {
    mech.bodies
        .iter()
        .map(|b| b.points.iter().map(|(p, s)| (mech.points[p.0].0.clone(), (s[0], s[1]))).collect())
        .collect()
}

/// `Mechanism.pairs` (the getter's doc there).
pub fn pairs<'py>(py: Python<'py>, mech: &Mechanism) -> PyResult<Vec<Bound<'py, PyDict>>> {
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

/// `Mechanism.pair_geometry` (the method's doc there).
pub fn pair_geometry<'py>(py: Python<'py>, mech: &Mechanism, x: &ArrayArg<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let x = vector("x", x, mech.n_x(), "body coordinates [X, Y, phi] per body")?;
    let pt = |p: [f64; 2]| (p[0], p[1]);
    mech.pairs
        .iter()
        .zip(pairs::pair_geometry(mech, &x))
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

/// `Mechanism.simulate_defaults` (the getter's doc there).
pub fn simulate_defaults<'py>(py: Python<'py>, mech: &Mechanism) -> PyResult<Bound<'py, PyDict>> {
    let s = &mech.simulate;
    let d = PyDict::new(py);
    d.set_item("t_end", s.t_end)?;
    d.set_item("method", s.method.clone())?;
    d.set_item("rtol", s.rtol)?;
    d.set_item("atol", s.atol)?;
    d.set_item("dt", s.dt)?;
    d.set_item("output_dt", s.output_dt)?;
    Ok(d)
}

/// `Mechanism.actuators` (the getter's doc there).
pub fn actuators<'py>(py: Python<'py>, mech: &Mechanism) -> PyResult<Vec<Option<Bound<'py, PyDict>>>> {
    dynamics::transmission::motors(mech)
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

/// `Mechanism.available_torque` (the method's doc there).
pub fn available_torque<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    coordinate: usize,
    speed: &ArrayArg<'py>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let Some(slot) = dynamics::transmission::motors(mech).nth(coordinate) else {
        return Err(argument_error(
            Some("coordinate"),
            format!("actuator {coordinate} out of range: the model has {} actuators", mech.n_actuators()),
        ));
    };
    let Some(a) = slot else { return Ok(None) };
    let v = Values::read(speed);
    let out: Option<Vec<f64>> = v.data.iter().map(|&w| a.limits.available_torque(w)).collect();
    out.map(|t| arr_dyn(py, &v.shape, t)).transpose()
}
