//! Derivatives of the applied forces f(x, xd, tau) (`forces`): along a direction t of the
//! body coordinates x at fixed xd and tau, and in xd, where f is affine (dampers are linear
//! in the rates, everything else does not depend on them).

use super::forces::applied_forces;
use crate::kinematics::constraints::{
    pair_coordinate_gamma, pair_coordinate_grad, pair_coordinate_rate, perp, point_velocity, rotate, world_point, Dense,
};
use crate::model::pairs::{coordinate_pattern, frames::angle};
use crate::model::{Attachment, Link, Load, Mechanism};

#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

#[inline]
fn angle_rate(link: Link, v: &[f64]) -> f64 {
    match link {
        Link::Ground => 0.0,
        Link::Body(b) => v[3 * b.0 + 2],
    }
}

/// Add the change of a force `force` (N) at a point of a link when x moves along t and the
/// force changes by `dforce`: d[F, R s x F] = [dF, (E R s t_phi) x F + R s x dF].
fn add_point_force_rate(at: &Attachment, force: [f64; 2], dforce: [f64; 2], x: &[f64], t: &[f64], df: &mut [f64]) {
    let Link::Body(b) = at.link else { return };
    let c = 3 * b.0;
    let arm = rotate(x[c + 2], at.s);
    let darm = perp(arm).map(|v| v * t[c + 2]);
    df[c] += dforce[0];
    df[c + 1] += dforce[1];
    df[c + 2] += cross(darm, force) + cross(arm, dforce);
}

/// d/dx of a point's velocity v = r' + phi' E R s along t at fixed xd: -phi' t_phi R s.
fn point_velocity_rate(at: &Attachment, x: &[f64], xd: &[f64], t: &[f64]) -> [f64; 2] {
    let k = -angle_rate(at.link, xd) * angle_rate(at.link, t);
    let p = rotate(angle(at.link, x), at.s);
    [k * p[0], k * p[1]]
}

/// A spring-damper's geometry at (x, xd) and its derivatives along t at fixed xd: length,
/// unit vector from end 0 to end 1, rate of extension.
struct SpringRates {
    len: f64,
    e: [f64; 2],
    dlen: f64,
    de: [f64; 2],
    rate: f64,
    drate: f64,
}

fn spring_rates(ends: &[Attachment; 2], x: &[f64], xd: &[f64], t: &[f64]) -> Option<SpringRates> {
    let (p0, p1) = (world_point(ends[0].link, ends[0].s, x), world_point(ends[1].link, ends[1].s, x));
    let d = [p1[0] - p0[0], p1[1] - p0[1]];
    let len = d[0].hypot(d[1]);
    if len == 0.0 {
        return None; // as in `applied_forces`: no force, no change
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

/// Add d/dx of a spring-damper's end forces along t.
#[allow(clippy::too_many_arguments)]
fn spring_rate(ends: &[Attachment; 2], k: f64, c: f64, rest: f64, x: &[f64], xd: &[f64], t: &[f64], df: &mut [f64]) {
    let Some(SpringRates { len, e, dlen, de, rate, drate }) = spring_rates(ends, x, xd, t) else { return };
    let tension = k * (len - rest) + c * rate;
    let dtension = k * dlen + c * drate;
    let force = [tension * e[0], tension * e[1]];
    let dforce = [dtension * e[0] + tension * de[0], dtension * e[1] + tension * de[1]];
    add_point_force_rate(&ends[0], force, dforce, x, t, df);
    add_point_force_rate(&ends[1], force.map(|v| -v), dforce.map(|v| -v), x, t, df);
}

/// d/dx . t at fixed xd of the power of the loads (point forces, torques, dampers; drives
/// left out), the value `applied_forces` returns.
pub fn load_power_dx(mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64]) -> f64 {
    let mut dp = 0.0;
    for load in &mech.loads {
        match load {
            Load::Force { at, value } => {
                let dv = point_velocity_rate(at, x, xd, t);
                dp += value[0] * dv[0] + value[1] * dv[1];
            }
            Load::Torque { .. } => {}
            Load::Spring { ends, damping, .. } => {
                if let Some(s) = spring_rates(ends, x, xd, t) {
                    dp -= 2.0 * damping * s.rate * s.drate;
                }
            }
            Load::PairSpring { pair, damping, .. } => {
                let p = &mech.pairs[pair.0];
                dp -= 2.0 * damping * pair_coordinate_rate(p, x, xd) * pair_coordinate_gamma(p, x, xd, t);
            }
        }
    }
    dp
}

/// Add d/dx of an effort on a pair's relative coordinate, f = effort grad(x), along t:
/// deffort grad + effort H t, H the coordinate's Hessian; `unit` is scratch (3n).
#[allow(clippy::too_many_arguments)]
fn pair_effort_rate(
    mech: &Mechanism,
    pair: usize,
    effort: f64,
    deffort: f64,
    x: &[f64],
    t: &[f64],
    df: &mut [f64],
    unit: &mut [f64],
) {
    let p = &mech.pairs[pair];
    if deffort != 0.0 {
        unit.fill(0.0);
        pair_coordinate_grad(p, x, &mut Dense { j: unit, ncols: x.len() }, 0);
        df.iter_mut().zip(unit.iter()).for_each(|(d, g)| *d += deffort * g);
    }
    if effort != 0.0 {
        unit.fill(0.0);
        for i in coordinate_pattern(p) {
            unit[i] = 1.0;
            df[i] += effort * pair_coordinate_gamma(p, x, unit, t);
            unit[i] = 0.0;
        }
    }
}

/// df/dx . t (3n) into `df` at (x, xd) with drive efforts `tau`, xd and tau held fixed;
/// `scratch` has length 3n.
pub fn applied_forces_dx(
    mech: &Mechanism,
    x: &[f64],
    xd: &[f64],
    tau: &[f64],
    t: &[f64],
    df: &mut [f64],
    scratch: &mut [f64],
) {
    df.fill(0.0);
    for load in &mech.loads {
        match load {
            Load::Force { at, value } => add_point_force_rate(at, *value, [0.0; 2], x, t, df),
            Load::Torque { .. } => {}
            Load::Spring { ends, stiffness, damping, rest_length } => {
                spring_rate(ends, *stiffness, *damping, *rest_length, x, xd, t, df)
            }
            Load::PairSpring { pair, stiffness, damping, rest } => {
                let p = &mech.pairs[pair.0];
                let rate = pair_coordinate_rate(p, x, xd);
                let effort = -stiffness * (crate::model::pairs::coordinate(p, x) - rest) - damping * rate;
                let deffort = -stiffness * pair_coordinate_rate(p, x, t) - damping * pair_coordinate_gamma(p, x, xd, t);
                pair_effort_rate(mech, pair.0, effort, deffort, x, t, df, scratch);
            }
        }
    }
    for (c, &effort) in mech.coordinates.iter().zip(tau) {
        pair_effort_rate(mech, c.pair.0, effort, 0.0, x, t, df, scratch);
    }
}

/// Buffers for [`applied_forces_dxd`] and [`load_power_dxd`] at one configuration x:
/// f(x, 0) without drives (3n), zero efforts (m), and scratch.
pub struct RateScratch {
    base: Vec<f64>,
    tau0: Vec<f64>,
    shifted: Vec<f64>,
    out: Vec<f64>,
}

impl RateScratch {
    /// The buffers at body coordinates x (3n).
    pub fn at(mech: &Mechanism, x: &[f64]) -> Self {
        let (n, m) = (mech.n_x(), mech.dof());
        let mut s = RateScratch { base: vec![0.0; n], tau0: vec![0.0; m], shifted: vec![0.0; n], out: vec![0.0; n] };
        s.shifted.fill(0.0);
        applied_forces(mech, x, &s.shifted, &s.tau0, &mut s.base);
        s
    }
}

/// df/dxd . v (3n) into `df` at the x of `s`, drives left out: f(x, v) - f(x, 0), exact
/// because f is affine in xd.
pub fn applied_forces_dxd(mech: &Mechanism, x: &[f64], v: &[f64], df: &mut [f64], s: &mut RateScratch) {
    applied_forces(mech, x, v, &s.tau0, df);
    df.iter_mut().zip(&s.base).for_each(|(d, b)| *d -= b);
}

/// d/dxd . v of the power of the loads at (x, xd): a central difference, exact because the
/// power is quadratic in xd (dampers) or linear (forces, torques).
pub fn load_power_dxd(mech: &Mechanism, x: &[f64], xd: &[f64], v: &[f64], s: &mut RateScratch) -> f64 {
    let power = |sign: f64, s: &mut RateScratch| {
        s.shifted.iter_mut().zip(xd.iter().zip(v)).for_each(|(o, (a, b))| *o = a + sign * b);
        applied_forces(mech, x, &s.shifted, &s.tau0, &mut s.out)
    };
    0.5 * (power(1.0, s) - power(-1.0, s))
}
