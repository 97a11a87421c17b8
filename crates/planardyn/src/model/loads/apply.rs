//! Where a load acts, and how its force reaches f = [F_x, F_y, M] per body (docs/formulation.md,
//! eq. 26): at a point of a link (a force at R s from the centre adds the moment R s x F), or
//! on a pair's relative coordinate (an effort adds effort * grad, the virtual work of the
//! effort on the coordinate); and the rates of both along a direction t of x. The drives use
//! the pair efforts too (`dynamics::forces`).

use crate::linalg::Dense;
use crate::model::pairs::frames::{angle, link_state, perp, rotate};
use crate::model::pairs::{coordinate_gamma, coordinate_grad, coordinate_pattern};
use crate::model::{Attachment, Link, Mechanism};

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

/// A point of a link at (x, xd), with one sin_cos of its angle: its position, R s (from the
/// centre) and velocity, and the link's first column in x (None for the ground).
pub(super) struct Point {
    pub p: [f64; 2],
    arm: [f64; 2],
    pub v: [f64; 2],
    col: Option<usize>,
}

impl Point {
    pub fn at(at: &Attachment, x: &[f64], xd: &[f64]) -> Self {
        let l = link_state(at.link, x);
        let arm = l.rot(at.s);
        let (rd, w) = l.col.map_or(([0.0; 2], 0.0), |c| ([xd[c], xd[c + 1]], xd[c + 2]));
        let t = perp(arm);
        Point { p: [l.r[0] + arm[0], l.r[1] + arm[1]], arm, v: [rd[0] + w * t[0], rd[1] + w * t[1]], col: l.col }
    }

    /// Add a force (N, global) acting at the point; returns its power (W).
    pub fn add_force(&self, force: [f64; 2], f: &mut [f64]) -> f64 {
        let Some(c) = self.col else { return 0.0 };
        f[c] += force[0];
        f[c + 1] += force[1];
        f[c + 2] += cross(self.arm, force);
        force[0] * self.v[0] + force[1] * self.v[1]
    }
}

/// Add the change of a force `force` (N) at a point of a link when x moves along t and the
/// force changes by `dforce`: d[F, R s x F] = [dF, (E R s t_phi) x F + R s x dF].
pub(super) fn add_point_force_rate(
    at: &Attachment,
    force: [f64; 2],
    dforce: [f64; 2],
    x: &[f64],
    t: &[f64],
    df: &mut [f64],
) {
    let Link::Body(b) = at.link else { return };
    let c = 3 * b.0;
    let arm = rotate(x[c + 2], at.s);
    let darm = perp(arm).map(|v| v * t[c + 2]);
    df[c] += dforce[0];
    df[c + 1] += dforce[1];
    df[c + 2] += cross(darm, force) + cross(arm, dforce);
}

/// d/dx of a point's velocity v = r' + phi' E R s along t at fixed xd: -phi' t_phi R s.
pub(super) fn point_velocity_rate(at: &Attachment, x: &[f64], xd: &[f64], t: &[f64]) -> [f64; 2] {
    let k = -angle_rate(at.link, xd) * angle_rate(at.link, t);
    let p = rotate(angle(at.link, x), at.s);
    [k * p[0], k * p[1]]
}

/// Add d/dx of an effort on a pair's relative coordinate, f = effort grad(x), along t:
/// deffort grad + effort H t, H the coordinate's Hessian; `unit` is scratch (3n).
#[allow(clippy::too_many_arguments)]
pub(crate) fn pair_effort_rate(
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
        coordinate_grad(p, x, &mut Dense { j: unit, ncols: x.len() }, 0);
        df.iter_mut().zip(unit.iter()).for_each(|(d, g)| *d += deffort * g);
    }
    if effort != 0.0 {
        unit.fill(0.0);
        for i in coordinate_pattern(p) {
            unit[i] = 1.0;
            df[i] += effort * coordinate_gamma(p, x, unit, t);
            unit[i] = 0.0;
        }
    }
}
