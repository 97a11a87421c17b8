//! A linear spring-damper between two body points: `type: spring`, tension
//! k (L - rest_length) + c dL/dt along the line between them (none at zero length, where the
//! direction is undefined). Its stiffness stores 1/2 k (L - rest_length)^2; its damper's power
//! is -c (dL/dt)^2.

use super::apply::{add_point_force_rate, point_velocity_rate, Point};
use super::{Load, LoadSpecType, LoadType};
use crate::model::checks::{body_point, Ctx, R};
use crate::model::pairs::frames::{point_velocity, world_point};
use crate::model::{Attachment, Mechanism};
use crate::units;
use serde::{Deserialize, Serialize};

/// A linear spring-damper between two body points, each given as [body, point]:
/// tension k (L - rest_length) + c dL/dt. `rest_length` defaults to the drawn length.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
// `expecting`: as `force::ForceSpec`'s.
#[serde(deny_unknown_fields, expecting = "struct variant LoadSpec::Spring")]
pub struct SpringSpec {
    pub between: [[String; 2]; 2],
    #[serde(deserialize_with = "units::stiffness")]
    pub stiffness: f64,
    #[serde(default, deserialize_with = "units::damping")]
    pub damping: f64,
    #[serde(default, deserialize_with = "units::length", skip_serializing_if = "Option::is_none")]
    pub rest_length: Option<f64>,
}

/// Linear spring-damper between two points: tension k (L - rest_length) + c L'.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    pub ends: [Attachment; 2],
    pub stiffness: f64,
    pub damping: f64,
    pub rest_length: f64,
}

impl LoadSpecType for SpringSpec {
    fn build(&self, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<Load>> {
        let between = &self.between;
        let e0 = body_point(ctx, mech, &format!("{path}.between[0]"), &between[0][0], &between[0][1])?;
        let e1 = body_point(ctx, mech, &format!("{path}.between[1]"), &between[1][0], &between[1][1])?;
        let (p0, p1) = (ctx.xy(path, &between[0][1])?, ctx.xy(path, &between[1][1])?);
        let drawn = length([p1[0] - p0[0], p1[1] - p0[1]]);
        Ok(Some(Load::Spring(Spring {
            ends: [e0, e1],
            stiffness: ctx.non_negative(&format!("{path}.stiffness"), self.stiffness)?,
            damping: ctx.non_negative(&format!("{path}.damping"), self.damping)?,
            rest_length: ctx.non_negative(&format!("{path}.rest_length"), self.rest_length.unwrap_or(drawn))?,
        })))
    }
}

/// |d| as the square root of its square (the squares' and the sum's roundings, 2 units of the
/// last place of the square, halve under the root: with the root's half, within 1.5 ulp of
/// |d|, as the library's hypot to an ulp), in place of hypot, which guards against overflow
/// beyond 1e154 m at about 55 instructions an evaluation. The drawn length takes it too, so
/// that the tension at the drawing is zero as before.
#[inline(always)]
fn length(d: [f64; 2]) -> f64 {
    (d[0] * d[0] + d[1] * d[1]).sqrt()
}

/// The spring's geometry at (x, xd) and its derivatives along t at fixed xd: length, unit
/// vector from end 0 to end 1, rate of extension.
struct SpringRates {
    len: f64,
    e: [f64; 2],
    dlen: f64,
    de: [f64; 2],
    rate: f64,
    drate: f64,
}

impl Spring {
    fn rates(&self, x: &[f64], xd: &[f64], t: &[f64]) -> Option<SpringRates> {
        let ends = &self.ends;
        let (p0, p1) = (world_point(ends[0].link, ends[0].s, x), world_point(ends[1].link, ends[1].s, x));
        let d = [p1[0] - p0[0], p1[1] - p0[1]];
        let len = length(d);
        if len == 0.0 {
            return None; // as in `add_force`: no force, no change
        }
        let e = [d[0] / len, d[1] / len];
        let (dp0, dp1) = (point_velocity(ends[0].link, ends[0].s, x, t), point_velocity(ends[1].link, ends[1].s, x, t));
        let dd = [dp1[0] - dp0[0], dp1[1] - dp0[1]];
        let dlen = e[0] * dd[0] + e[1] * dd[1];
        let de = [(dd[0] - e[0] * dlen) / len, (dd[1] - e[1] * dlen) / len];
        let (v0, v1) = (point_velocity(ends[0].link, ends[0].s, x, xd), point_velocity(ends[1].link, ends[1].s, x, xd));
        let (dv0, dv1) = (point_velocity_rate(&ends[0], x, xd, t), point_velocity_rate(&ends[1], x, xd, t));
        let dv = [v1[0] - v0[0], v1[1] - v0[1]];
        let rate = e[0] * dv[0] + e[1] * dv[1];
        let drate = de[0] * dv[0] + de[1] * dv[1] + e[0] * (dv1[0] - dv0[0]) + e[1] * (dv1[1] - dv0[1]);
        Some(SpringRates { len, e, dlen, de, rate, drate })
    }
}

impl LoadType for Spring {
    #[inline]
    fn add_force(&self, _mech: &Mechanism, x: &[f64], xd: &[f64], f: &mut [f64]) -> f64 {
        let (p0, p1) = (Point::at(&self.ends[0], x, xd), Point::at(&self.ends[1], x, xd));
        let d = [p1.p[0] - p0.p[0], p1.p[1] - p0.p[1]];
        let len = length(d);
        if len == 0.0 {
            return 0.0; // direction undefined; a spring of zero length exerts no force
        }
        let e = [d[0] / len, d[1] / len];
        let rate = e[0] * (p1.v[0] - p0.v[0]) + e[1] * (p1.v[1] - p0.v[1]);
        let tension = self.stiffness * (len - self.rest_length) + self.damping * rate;
        p0.add_force([tension * e[0], tension * e[1]], f);
        p1.add_force([-tension * e[0], -tension * e[1]], f);
        -(self.damping * rate * rate)
    }

    fn add_force_dx(&self, _: &Mechanism, x: &[f64], xd: &[f64], t: &[f64], df: &mut [f64], _: &mut [f64]) {
        let Some(SpringRates { len, e, dlen, de, rate, drate }) = self.rates(x, xd, t) else { return };
        let (k, c) = (self.stiffness, self.damping);
        let tension = k * (len - self.rest_length) + c * rate;
        let dtension = k * dlen + c * drate;
        let force = [tension * e[0], tension * e[1]];
        let dforce = [dtension * e[0] + tension * de[0], dtension * e[1] + tension * de[1]];
        add_point_force_rate(&self.ends[0], force, dforce, x, t, df);
        add_point_force_rate(&self.ends[1], force.map(|v| -v), dforce.map(|v| -v), x, t, df);
    }

    fn power_dx(&self, _mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64]) -> f64 {
        self.rates(x, xd, t).map_or(0.0, |s| -(2.0 * self.damping * s.rate * s.drate))
    }

    fn potential(&self, _mech: &Mechanism, x: &[f64]) -> f64 {
        let ends = &self.ends;
        let (p0, p1) = (world_point(ends[0].link, ends[0].s, x), world_point(ends[1].link, ends[1].s, x));
        0.5 * self.stiffness * (length([p1[0] - p0[0], p1[1] - p0[1]]) - self.rest_length).powi(2)
    }
}

#[cfg(test)]
mod tests {
    /// [`super::length`] is the library's hypot within 1.5 ulp of the length (its bound above,
    /// plus hypot's own half), over directions of the whole circle and lengths from 1e-9 m to
    /// 1e9 m; a zero vector's length is zero (the spring's no-force case).
    #[test]
    fn length_is_the_library_hypot_to_rounding() {
        for k in 0..40000 {
            let a = k as f64 * 0.7548776662466927;
            let r = 10f64.powf(18.0 * (k as f64 * 0.5698402909980532).sin().abs() - 9.0);
            let d = [r * a.cos(), r * a.sin()];
            let (mine, library) = (super::length(d), d[0].hypot(d[1]));
            assert!((mine - library).abs() <= 1.5 * f64::EPSILON * library, "d = {d:?}: {mine} vs {library}");
        }
        assert_eq!(super::length([0.0, -0.0]), 0.0);
    }
}
