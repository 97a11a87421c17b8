//! A constant force at a point of a body: `type: force`, [F_x, F_y] (N, global frame). Its
//! power is F . v of the point; it stores no energy.

use super::apply::{add_point_force_rate, point_velocity_rate, Point};
use super::{mobile_body, Load, LoadSpecType, LoadType};
use crate::model::checks::{body_point, Ctx, R};
use crate::model::{Attachment, Mechanism};
use crate::units;
use serde::{Deserialize, Serialize};

/// A constant force [F_x, F_y] (N, global frame) at a point of a body.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
// `expecting`: the words serde gave the load's fields when a load was a struct variant, which
// the parse errors explain (a load written as a list).
#[serde(deny_unknown_fields, expecting = "struct variant LoadSpec::Force")]
pub struct ForceSpec {
    pub body: String,
    pub at: String,
    #[serde(deserialize_with = "units::force")]
    pub value: [f64; 2],
}

/// Constant global force `value` (N) at a point of a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Force {
    pub at: Attachment,
    pub value: [f64; 2],
}

impl LoadSpecType for ForceSpec {
    fn build(&self, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<Load>> {
        mobile_body(ctx, path, &self.body)?;
        let value = format!("{path}.value");
        Ok(Some(Load::Force(Force {
            at: body_point(ctx, mech, path, &self.body, &self.at)?,
            value: [ctx.finite(&value, self.value[0])?, ctx.finite(&value, self.value[1])?],
        })))
    }
}

impl LoadType for Force {
    #[inline]
    fn add_force(&self, _mech: &Mechanism, x: &[f64], xd: &[f64], f: &mut [f64]) -> f64 {
        Point::at(&self.at, x, xd).add_force(self.value, f)
    }

    fn add_force_dx(&self, _: &Mechanism, x: &[f64], _xd: &[f64], t: &[f64], df: &mut [f64], _: &mut [f64]) {
        add_point_force_rate(&self.at, self.value, [0.0; 2], x, t, df)
    }

    fn power_dx(&self, _mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64]) -> f64 {
        let dv = point_velocity_rate(&self.at, x, xd, t);
        self.value[0] * dv[0] + self.value[1] * dv[1]
    }

    fn potential(&self, _mech: &Mechanism, _x: &[f64]) -> f64 {
        0.0
    }
}
