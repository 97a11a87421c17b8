//! The compliant mechanism's analyses in JavaScript (`planardyn::elastic`), the bodies of
//! `Mechanism`'s methods: its natural modes, a point's stiffness under a load, and the maps of
//! both over two coordinates (`planardyn::elastic::map_rows`, the singularity map's grid and
//! branch).

use crate::convert::{from_js, Obj};
use crate::errors::{argument_error, js};
use planardyn::dynamics::query;
use planardyn::dynamics::MapGrid;
use planardyn::elastic::{self, Load, MapValue, Output};
use planardyn::model::{BodyId, Link, PointId};
use planardyn::Mechanism;
use serde::Deserialize;
use std::collections::BTreeMap;
use wasm_bindgen::JsValue;

/// A load on a point (`stiffness`'s and the stiffness map's): `wrench` [F_x, F_y, M] (N, N,
/// N m) at the point, `preload` efforts (N m or N) of elastic drives by actuator name, and
/// (`gravity`) the model's gravity; each absent for none.
#[derive(Debug, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LoadOption {
    pub wrench: Option<[f64; 3]>,
    pub preload: BTreeMap<String, f64>,
    pub gravity: bool,
}

/// What an elastic map shows: `kind` "frequency" (the first natural frequency, Hz; rotors held
/// unless `freeRotors`) or "stiffness" (the weakest translational stiffness of `point`, N/m,
/// under `load`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub struct MapOption {
    pub kind: String,
    #[serde(default)]
    pub free_rotors: bool,
    pub point: Option<String>,
    pub load: Option<LoadOption>,
}

/// The output of `point`: the point on the first body that carries it.
fn output(m: &Mechanism, point: &str) -> Result<Output, JsValue> {
    let on_body = |id: PointId| (0..m.n_bodies()).map(BodyId).find(|&b| m.attachment(Link::Body(b), id).is_some());
    let Some((id, body)) = m.point_id(point).and_then(|id| on_body(id).map(|b| (id, b))) else {
        let names: Vec<&str> =
            (0..m.points.len()).filter(|&p| on_body(PointId(p)).is_some()).map(|p| m.points[p].0.as_str()).collect();
        return Err(argument_error(
            Some("point"),
            format!("no body carries a point '{point}'; the bodies' points are: {}", names.join(", ")),
        ));
    };
    Ok(Output { body, point: Some(id) })
}

/// The core's load of a `LoadOption` (`Load::named` checks it).
fn load(m: &Mechanism, option: LoadOption) -> Result<Load, JsValue> {
    js(Load::named(m, option.wrench.unwrap_or_default(), option.preload, option.gravity))
}

/// `Mechanism.modes` (see there): the modes about q on the branch of `x_start`.
pub fn modes(m: &Mechanism, q: &[f64], free_rotors: bool, x_start: Option<&[f64]>) -> Result<JsValue, JsValue> {
    let ws = js(query::assembled(m, q, x_start))?;
    let modes = js(elastic::modes_about(m, &ws.x, free_rotors, false))?;
    Ok(Obj::new()
        .f64s("omega", &modes.omega())
        .f64s("omega2", &modes.omega2)
        .f64s("dampingRatio", &modes.damping_ratio)
        .f64s("shapes", &modes.shapes.concat())
        .f64s("x", &ws.x)
        .build())
}

/// `Mechanism.stiffness` (see there): `point`'s stiffness at q under `load_option`.
pub fn stiffness(
    m: &Mechanism,
    q: &[f64],
    point: &str,
    x_start: Option<&[f64]>,
    load_option: JsValue,
) -> Result<JsValue, JsValue> {
    let out = output(m, point)?;
    let load = load(m, from_js("load", load_option)?)?;
    let ws = js(query::assembled(m, q, x_start))?;
    let c = js(elastic::stiffness_about(m, &ws.x, out, &load))?;
    let w = elastic::weakest_direction(&c, None);
    Ok(Obj::new()
        .set("weakest", w.stiffness)
        .f64s("direction", &w.direction[..2])
        .f64s("compliance", c.compliance.as_flattened())
        .f64s("x", &ws.x)
        .build())
}

/// `Mechanism.elasticRows` (see there): the rows of the map `value` (a `MapOption`) over `grid`.
pub fn elastic_rows(m: &Mechanism, q: &[f64], grid: &MapGrid<'_>, value: JsValue) -> Result<JsValue, JsValue> {
    let option: MapOption = from_js("value", value)?;
    let value = match (option.kind.as_str(), option.point) {
        ("frequency", _) => MapValue::FirstFrequency { free_rotors: option.free_rotors },
        ("stiffness", Some(point)) => {
            MapValue::Weakest { out: output(m, &point)?, load: load(m, option.load.unwrap_or_default())? }
        }
        (kind, _) => {
            let what = format!("value.kind {kind:?}: \"frequency\", or \"stiffness\" with a point");
            return Err(argument_error(Some("value"), what));
        }
    };
    let out = js(elastic::map_rows(m, q, grid, &value))?;
    Ok(Obj::new().f64s("values", &out.values).f64s("x", &out.x).build())
}
