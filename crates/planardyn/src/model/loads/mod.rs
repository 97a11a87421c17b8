//! Load kinds: the external loads and force elements, one file a kind (as the pair kinds in
//! `model::pairs`). A kind owns its entry in the model file (a spec struct, `type:` its
//! snake-case name), the validation of that entry into the model's load, and what the load
//! does: its forces at (x, xd), their derivative along a direction t of x, the derivative of
//! its power, and its potential energy. `dynamics::forces`, `force_rates` and `energy` walk
//! the loads and ask them through the functions below; only this file's `dispatch!` and
//! `dispatch_spec!` look at the kind, calling the kind's module statically.
//!
//! Adding a kind: a file here with its spec struct (`LoadSpecType`) and its load
//! ([`LoadType`]), a variant of [`LoadSpec`] (and its name in [`LoadSpec::NAMES`]) and of
//! [`Load`] with an arm in each dispatch, the schema (`schema/planardyn-model.schema.json`)
//! and `docs/model-format.md`.

pub(crate) mod apply;
pub mod force;
pub mod friction;
pub mod pair_spring;
pub mod spring;
pub mod torque;

use crate::model::actuators::JointFriction;
use crate::model::checks::{Ctx, R};
use crate::model::{BodyId, Link, Mechanism};
use serde::{Deserialize, Serialize};

/// An external load or a force element, as the model file gives it.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum LoadSpec {
    Force(force::ForceSpec),
    Torque(torque::TorqueSpec),
    Spring(spring::SpringSpec),
    TorsionalSpring(pair_spring::TorsionalSpringSpec),
    Friction(friction::FrictionSpec),
}

impl LoadSpec {
    /// The kinds' names in a model file (`type:`), in the order of the variants (for messages).
    pub const NAMES: [&'static str; 5] = ["force", "torque", "spring", "torsional_spring", "friction"];
}

/// An external load or force element of the model.
#[derive(Debug, Clone, PartialEq)]
pub enum Load {
    Force(force::Force),
    Torque(torque::Torque),
    Spring(spring::Spring),
    PairSpring(pair_spring::PairSpring),
}

/// What a load kind's entry in the model file gives the model; `path` names the entry
/// (`loads[k]`) in messages.
pub(crate) trait LoadSpecType {
    /// The load it adds to `Mechanism::loads`, its fields checked (None: it adds none).
    fn build(&self, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<Load>>;
    /// The Coulomb friction it puts on a pair (`Mechanism::friction`), checked after every
    /// load is built; none by default.
    fn friction(&self, _ctx: &Ctx, _mech: &Mechanism, _path: &str) -> R<Option<JointFriction>> {
        Ok(None)
    }
}

/// What a load does at body coordinates x (3n) and body rates xd (3n).
pub trait LoadType {
    /// Add its forces and moments at the centres of mass into `f` (3n); return its power (W)
    /// but for the part counted in the potential energy (a spring's stiffness).
    fn add_force(&self, mech: &Mechanism, x: &[f64], xd: &[f64], f: &mut [f64]) -> f64;
    /// Add d/dx . t of its forces at fixed xd into `df` (3n); `scratch` (3n) is free to use.
    fn add_force_dx(&self, mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64], df: &mut [f64], scratch: &mut [f64]);
    /// d/dx . t at fixed xd of the power `add_force` returns.
    fn power_dx(&self, mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64]) -> f64;
    /// Its potential energy (J).
    fn potential(&self, mech: &Mechanism, x: &[f64]) -> f64;
}

/// Call `$body` with `$t` bound to the load's [`LoadType`] value.
macro_rules! dispatch {
    ($load:expr, $t:ident => $body:expr) => {
        match $load {
            Load::Force($t) => $body,
            Load::Torque($t) => $body,
            Load::Spring($t) => $body,
            Load::PairSpring($t) => $body,
        }
    };
}

/// Call `$body` with `$t` bound to the entry's [`LoadSpecType`] value.
macro_rules! dispatch_spec {
    ($spec:expr, $t:ident => $body:expr) => {
        match $spec {
            LoadSpec::Force($t) => $body,
            LoadSpec::Torque($t) => $body,
            LoadSpec::Spring($t) => $body,
            LoadSpec::TorsionalSpring($t) => $body,
            LoadSpec::Friction($t) => $body,
        }
    };
}

/// Add a load's forces into `f` (3n) at (x, xd); returns its power (W), see [`LoadType::add_force`].
#[inline]
pub fn add_force(load: &Load, mech: &Mechanism, x: &[f64], xd: &[f64], f: &mut [f64]) -> f64 {
    dispatch!(load, t => t.add_force(mech, x, xd, f))
}

/// Add d/dx . t of a load's forces into `df` (3n); `scratch` has length 3n.
pub fn add_force_dx(
    load: &Load,
    mech: &Mechanism,
    x: &[f64],
    xd: &[f64],
    t: &[f64],
    df: &mut [f64],
    scratch: &mut [f64],
) {
    dispatch!(load, k => k.add_force_dx(mech, x, xd, t, df, scratch))
}

/// d/dx . t of a load's power at fixed xd.
pub fn power_dx(load: &Load, mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64]) -> f64 {
    dispatch!(load, k => k.power_dx(mech, x, xd, t))
}

/// A load's potential energy (J) at x.
pub fn potential(load: &Load, mech: &Mechanism, x: &[f64]) -> f64 {
    dispatch!(load, t => t.potential(mech, x))
}

/// The model's load of an entry, if it gives one.
pub(crate) fn build(spec: &LoadSpec, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<Load>> {
    dispatch_spec!(spec, t => t.build(ctx, mech, path))
}

/// The Coulomb friction of an entry, if it gives one.
pub(crate) fn friction(spec: &LoadSpec, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<JointFriction>> {
    dispatch_spec!(spec, t => t.friction(ctx, mech, path))
}

/// The mobile body a load on a body names (a load on the ground does nothing).
fn mobile_body(ctx: &Ctx, path: &str, name: &str) -> R<BodyId> {
    match ctx.link(&format!("{path}.body"), name)? {
        Link::Body(b) => Ok(b),
        Link::Ground => Err(ctx.err(format!("{path}.body"), "a load on the ground does nothing; name a mobile body")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_names_are_the_kinds_serde_reads() {
        // serde lists the kinds it knows when a `type` is unknown.
        let e = serde_json::from_str::<LoadSpec>(r#"{"type": "cam"}"#).unwrap_err().to_string();
        let listed = LoadSpec::NAMES.map(|n| format!("`{n}`")).join(", ");
        assert!(e.contains(&format!("expected one of {listed}")), "{e}");
    }
}
