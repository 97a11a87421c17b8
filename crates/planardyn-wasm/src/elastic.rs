//! The compliant mechanism's analyses in JavaScript (`planardyn::elastic`), methods of
//! `Mechanism`: its natural modes, a point's stiffness under a load, and the maps of both over
//! two coordinates (`planardyn::elastic::map_rows`, the singularity map's grid and branch).

use crate::convert::{from_js, Obj};
use crate::errors::{argument_error, js};
use crate::mechanism::WasmMechanism;
use planardyn::dynamics::query;
use planardyn::dynamics::MapGrid;
use planardyn::elastic::{self, Load, MapValue, Output};
use planardyn::model::{BodyId, Link, PointId};
use planardyn::Mechanism;
use serde::Deserialize;
use std::collections::BTreeMap;
use wasm_bindgen::prelude::*;

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

/// The core's load of a `LoadOption` (unknown actuators and non-finite values refused).
fn load(m: &Mechanism, option: LoadOption) -> Result<Load, JsValue> {
    let wrench = option.wrench.unwrap_or_default();
    if wrench.iter().any(|v| !v.is_finite()) {
        return Err(argument_error(
            Some("wrench"),
            format!("wrench {wrench:?} must be [F_x, F_y, M], finite (N, N, N m)"),
        ));
    }
    let names = m.actuator_names();
    let mut out = Load { wrench, preload: Vec::new(), gravity: option.gravity };
    for (name, tau) in option.preload {
        let k = names.iter().position(|n| *n == name).ok_or_else(|| {
            argument_error(Some("preload"), format!("unknown actuator '{name}'; actuators are: {}", names.join(", ")))
        })?;
        if !tau.is_finite() {
            return Err(argument_error(Some("preload"), format!("preload['{name}'] = {tau} is not a finite number")));
        }
        out.preload.push((k, tau));
    }
    Ok(out)
}

#[wasm_bindgen(js_class = Mechanism)]
impl WasmMechanism {
    /// The natural modes of the compliant mechanism about coordinates q (its rigid pose, on the
    /// branch of `xStart`; `planardyn::elastic::modes`), each elastic drive's rotor held
    /// (`freeRotors` false) or free: `{omega (rad/s), omega2 (rad^2/s^2), dampingRatio, shapes
    /// (modes x 3n: mass-normalised body displacements [X, Y, phi]), x (3n: the pose)}`, by
    /// increasing frequency, about the pose without gravity's load (as the Python API's
    /// default: a drawn pose need not be an equilibrium). A model without a `compliance:`
    /// section throws an ArgumentError.
    pub fn modes(&self, q: &[f64], free_rotors: bool, x_start: Option<Vec<f64>>) -> Result<JsValue, JsValue> {
        self.start_args(q, x_start.as_deref())?;
        let mut ws = js(query::assembled(&self.inner, q, x_start.as_deref()))?;
        let modes = js(elastic::modes(&self.inner, q, free_rotors, false, &mut ws))?;
        Ok(Obj::new()
            .f64s("omega", &modes.omega())
            .f64s("omega2", &modes.omega2)
            .f64s("dampingRatio", &modes.damping_ratio)
            .f64s("shapes", &modes.shapes.concat())
            .f64s("x", &ws.x)
            .build())
    }

    /// The stiffness of the point `point` (on the first body that carries it) at coordinates q
    /// (its rigid pose, on the branch of `xStart`; `planardyn::elastic::stiffness`), in
    /// equilibrium with `load` (`LoadOption`: a wrench at the point, preload efforts of elastic
    /// drives by actuator name, gravity; none if absent) with its geometric term: `{weakest (N/m:
    /// the translational stiffness in its weakest direction), direction ([d_x, d_y], unit),
    /// compliance (3 x 3 of [x, y, phi]; m/N, m/(N m), rad/N, rad/(N m)), x (3n: the pose)}`,
    /// as the Python API's `stiffness(mech, q, body=, point=, wrench=, preload=, gravity=)`. A
    /// model without a `compliance:` section throws an ArgumentError.
    pub fn stiffness(
        &self,
        q: &[f64],
        point: &str,
        x_start: Option<Vec<f64>>,
        load_option: JsValue,
    ) -> Result<JsValue, JsValue> {
        self.start_args(q, x_start.as_deref())?;
        let m = &self.inner;
        let out = output(m, point)?;
        let load = load(m, from_js("load", load_option)?)?;
        let mut ws = js(query::assembled(m, q, x_start.as_deref()))?;
        let c = js(elastic::stiffness(m, q, out, &load, &mut ws))?;
        let w = elastic::weakest_direction(&c, None);
        Ok(Obj::new()
            .set("weakest", w.stiffness)
            .f64s("direction", &w.direction[..2])
            .f64s("compliance", c.compliance.as_flattened())
            .f64s("x", &ws.x)
            .build())
    }

    /// Rows of an elastic map (`MapOption`: the first natural frequency, Hz, or a point's
    /// weakest stiffness under a load, N/m) over coordinates k1 and k2 as `sigmaRows`' (same
    /// grid, rows, branch; `planardyn::elastic::map_rows`): `{values (rows x axis1.length, NaN
    /// where it does not assemble or has no value), x (where the next rows continue)}`.
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
        self.start_args(q, None)?;
        let m = &self.inner;
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
        let rows: Vec<usize> = rows.iter().map(|&j| j as usize).collect();
        let grid = js(MapGrid::new(m, [k1, k2], [axis1, axis2], i0, &rows, x_start))?;
        let out = js(elastic::map_rows(m, q, &grid, &value))?;
        Ok(Obj::new().f64s("values", &out.values).f64s("x", &out.x).build())
    }
}
