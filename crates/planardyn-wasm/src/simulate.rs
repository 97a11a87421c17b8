//! `Mechanism.simulate` in JavaScript: the options of a run read from a JS object (the model
//! file's defaults changed by them, `planardyn::simulate::Overrides`, as the Python package
//! applies its arguments), the whole run in the core, and the trajectory as typed arrays.

use crate::convert::{array, f64s, Obj};
use crate::errors::{argument_error, js};
use js_sys::Uint8Array;
use planardyn::dynamics::ModelDrives;
use planardyn::model::spec::SimulateSpec;
use planardyn::model::MotionLaw;
use planardyn::simulate::columns::{Values, COLUMNS};
use planardyn::simulate::{simulate_observed, Event, Observe, Overrides, Trajectory};
use planardyn::Mechanism;
use serde::Deserialize;
use wasm_bindgen::prelude::*;

/// A coordinate driven at a constant speed (rad/s or m/s) from its start value.
#[derive(Debug, Deserialize)]
pub struct MotionOption {
    pub coordinate: usize,
    pub speed: f64,
}

/// A coordinate crossing `value` (rad or m); `direction` +1 rising only, -1 falling only, 0
/// both; a `terminal` event stops the run.
#[derive(Debug, Deserialize)]
pub struct EventOption {
    pub coordinate: usize,
    pub value: f64,
    #[serde(default)]
    pub terminal: bool,
    #[serde(default)]
    pub direction: f64,
}

/// The options of a run, each `undefined` for the model file's (times in s): the fields of the
/// model file's `simulate` section by its names (t_end, method, rtol, atol, dt, output_dt; an
/// unknown name is refused there), and the start and the motions.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub struct SimulateOptions {
    #[serde(flatten)]
    pub settings: SimulateSpec,
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
    #[serde(rename = "maxSteps")]
    pub max_steps: Option<usize>,
    pub motion: Vec<MotionOption>,
    pub events: Vec<EventOption>,
}

/// Run a simulation of `mech` with `options`; the model's drives act on the coordinates not
/// driven by motion.
pub fn run(mech: &Mechanism, options: SimulateOptions) -> Result<JsValue, JsValue> {
    let names = mech.coordinate_names();
    let coordinate = |k: usize, what: &str| {
        if k < names.len() {
            Ok(k)
        } else {
            Err(argument_error(
                Some(what),
                format!("{what}: no coordinate {k} (the coordinates: {})", names.join(", ")),
            ))
        }
    };
    let motion = options
        .motion
        .iter()
        .map(|m| Ok((coordinate(m.coordinate, "motion")?, MotionLaw::Speed(m.speed))))
        .collect::<Result<Vec<_>, JsValue>>()?;
    let events = options
        .events
        .iter()
        .map(|e| Ok(Event::coordinate(coordinate(e.coordinate, "events")?, e.value, e.terminal, e.direction)))
        .collect::<Result<Vec<_>, JsValue>>()?;
    let overrides = Overrides {
        t_end: options.settings.t_end,
        method: options.settings.method,
        rtol: options.settings.rtol,
        atol: options.settings.atol,
        dt: options.settings.dt,
        t_eval: None,
        output_dt: options.settings.output_dt,
        q0: options.q0,
        qd0: options.qd0,
        max_steps: options.max_steps,
        motion,
    };
    let settings = js(overrides.settings(mech))?;
    let mut prescribed = js(overrides.prescribed(mech))?;
    let mut drives = ModelDrives(mech);
    let observe = Observe { events, dense_output: false };
    let traj = js(simulate_observed(mech, &settings, &mut drives, &mut prescribed, observe, None))?;
    Ok(trajectory(traj))
}

/// The trajectory as `{<column> ..., tEvents, qEvents (per event), status, message, stats}`:
/// every output column of `planardyn::simulate::columns::COLUMNS` by its name, row-major
/// (t, kinetic, ... (N); q, qd, qdd, tau (N x m); x, xd (N x 3n)), a flag (partitioned) as 0/1
/// bytes.
fn trajectory(t: Trajectory) -> JsValue {
    let st = &t.stats;
    let stats = Obj::new()
        .set("nfev", st.integrator.nfev as f64)
        .set("naccept", st.integrator.naccept as f64)
        .set("nreject", st.integrator.nreject as f64)
        .set("chartSwitches", st.chart_switches as f64)
        .set("maxResidual", st.max_residual)
        .set("minSigma", st.min_sigma)
        .set("energyDrift", st.energy_drift);
    COLUMNS
        .iter()
        .fold(Obj::new(), |obj, c| match (c.values)(&t) {
            Values::Numbers(v) => obj.f64s(c.name, v),
            Values::Flags(v) => {
                obj.set(c.name, Uint8Array::from(&v.iter().map(|&f| u8::from(f)).collect::<Vec<_>>()[..]))
            }
        })
        .set("tEvents", array(t.events.t.iter().map(|r| f64s(r).into())))
        .set("qEvents", array(t.events.q.iter().map(|r| f64s(r).into())))
        .set("status", t.status.name())
        .set("message", t.message)
        .set("stats", stats.build())
        .build()
}
