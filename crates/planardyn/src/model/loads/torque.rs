//! A constant torque on a body: `type: torque`, value (N m). Its power is the torque times
//! the body's angular rate; it stores no energy and does not depend on x.

use super::{mobile_body, Load, LoadSpecType, LoadType};
use crate::model::checks::{Ctx, R};
use crate::model::{BodyId, Mechanism};
use crate::units;
use serde::{Deserialize, Serialize};

/// A constant torque (N m) on a body.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
// `expecting`: as `force::ForceSpec`'s.
#[serde(deny_unknown_fields, expecting = "struct variant LoadSpec::Torque")]
pub struct TorqueSpec {
    pub body: String,
    #[serde(deserialize_with = "units::torque")]
    pub value: f64,
}

/// Constant torque `value` (N m) on a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Torque {
    pub body: BodyId,
    pub value: f64,
}

impl LoadSpecType for TorqueSpec {
    fn build(&self, ctx: &Ctx, _mech: &Mechanism, path: &str) -> R<Option<Load>> {
        let body = mobile_body(ctx, path, &self.body)?;
        Ok(Some(Load::Torque(Torque { body, value: ctx.finite(&format!("{path}.value"), self.value)? })))
    }
}

impl LoadType for Torque {
    #[inline]
    fn add_force(&self, _mech: &Mechanism, _x: &[f64], xd: &[f64], f: &mut [f64]) -> f64 {
        f[3 * self.body.0 + 2] += self.value;
        self.value * xd[3 * self.body.0 + 2]
    }

    fn add_force_dx(&self, _: &Mechanism, _x: &[f64], _xd: &[f64], _t: &[f64], _df: &mut [f64], _: &mut [f64]) {}

    fn power_dx(&self, _mech: &Mechanism, _x: &[f64], _xd: &[f64], _t: &[f64]) -> f64 {
        0.0
    }

    fn potential(&self, _mech: &Mechanism, _x: &[f64]) -> f64 {
        0.0
    }
}
