//! Applied forces reduced to the centres of mass, f = [F_x, F_y, M] per body
//! (docs/formulation.md, eq. 26):
//! gravity, point forces, torques, springs and dampers, and the drive efforts mapped
//! through the coordinates' gradients (f += D_x^T tau, the virtual work of tau on q).

use crate::kinematics::constraints::{
    pair_coordinate, pair_coordinate_grad, pair_coordinate_rate, point_velocity, rotate, world_point, Dense,
};
use crate::model::{Attachment, Link, Load, Mechanism};

/// Drive efforts on the generalized coordinates (N m on angles, N on displacements).
pub trait Drives {
    /// Write the efforts at time t (s), coordinates q and rates qd into `tau`.
    fn efforts(&mut self, t: f64, q: &[f64], qd: &[f64], tau: &mut [f64]) -> Result<(), String>;
    /// Whether the efforts depend on t alone (not on q, qd): then the exact Jacobian of the
    /// equations of motion holds them fixed. The default, false, is always safe.
    fn time_only(&self) -> bool {
        false
    }
}

/// The drives written in the model file (constants and time tables; none is zero).
pub struct ModelDrives<'a>(pub &'a Mechanism);

impl Drives for ModelDrives<'_> {
    fn efforts(&mut self, t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        for (e, law) in tau.iter_mut().zip(&self.0.drives) {
            *e = law.as_ref().map_or(0.0, |l| l.effort(t));
        }
        Ok(())
    }
    fn time_only(&self) -> bool {
        true
    }
}

#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Add a force (N, global) acting at a point of a link; returns its power (W).
fn add_point_force(at: &Attachment, force: [f64; 2], x: &[f64], xd: &[f64], f: &mut [f64]) -> f64 {
    let Link::Body(b) = at.link else { return 0.0 };
    let c = 3 * b.0;
    let arm = rotate(x[c + 2], at.s);
    f[c] += force[0];
    f[c + 1] += force[1];
    f[c + 2] += cross(arm, force);
    let v = point_velocity(at.link, at.s, x, xd);
    force[0] * v[0] + force[1] * v[1]
}

/// Add `effort` acting on a pair's relative coordinate (f += effort * grad); `grad` is scratch.
fn add_pair_effort(mech: &Mechanism, pair: usize, effort: f64, x: &[f64], f: &mut [f64], grad: &mut [f64]) {
    grad.fill(0.0);
    pair_coordinate_grad(&mech.pairs[pair], x, &mut Dense { j: grad, ncols: x.len() }, 0);
    for (fi, g) in f.iter_mut().zip(grad.iter()) {
        *fi += effort * g;
    }
}

/// Fill `f` (3n) with every applied force at (x, xd) and drive efforts `tau`; `scratch` has
/// length 3n. Returns the power of the non-conservative forces (drives, dampers, point
/// forces and torques) in W; gravity and spring stiffness are counted in the potential.
pub fn applied_forces(mech: &Mechanism, x: &[f64], xd: &[f64], tau: &[f64], f: &mut [f64], scratch: &mut [f64]) -> f64 {
    f.fill(0.0);
    let g = mech.gravity;
    for (i, body) in mech.bodies.iter().enumerate() {
        f[3 * i] = body.mass * g[0];
        f[3 * i + 1] = body.mass * g[1];
    }
    let mut power = 0.0;
    for load in &mech.loads {
        match load {
            Load::Force { at, value } => power += add_point_force(at, *value, x, xd, f),
            Load::Torque { body, value } => {
                f[3 * body.0 + 2] += value;
                power += value * xd[3 * body.0 + 2];
            }
            Load::Spring { ends, stiffness, damping, rest_length } => {
                let (p0, p1) = (world_point(ends[0].link, ends[0].s, x), world_point(ends[1].link, ends[1].s, x));
                let d = [p1[0] - p0[0], p1[1] - p0[1]];
                let len = d[0].hypot(d[1]);
                if len == 0.0 {
                    continue; // direction undefined; a spring of zero length exerts no force
                }
                let e = [d[0] / len, d[1] / len];
                let (v0, v1) =
                    (point_velocity(ends[0].link, ends[0].s, x, xd), point_velocity(ends[1].link, ends[1].s, x, xd));
                let rate = e[0] * (v1[0] - v0[0]) + e[1] * (v1[1] - v0[1]);
                let tension = stiffness * (len - rest_length) + damping * rate;
                add_point_force(&ends[0], [tension * e[0], tension * e[1]], x, xd, f);
                add_point_force(&ends[1], [-tension * e[0], -tension * e[1]], x, xd, f);
                power -= damping * rate * rate;
            }
            Load::PairSpring { pair, stiffness, damping, rest } => {
                let p = &mech.pairs[pair.0];
                let rate = pair_coordinate_rate(p, x, xd);
                let effort = -stiffness * (pair_coordinate(p, x) - rest) - damping * rate;
                add_pair_effort(mech, pair.0, effort, x, f, scratch);
                power -= damping * rate * rate;
            }
        }
    }
    for (c, &t) in mech.coordinates.iter().zip(tau) {
        if t != 0.0 {
            add_pair_effort(mech, c.pair.0, t, x, f, scratch);
            power += t * pair_coordinate_rate(&mech.pairs[c.pair.0], x, xd);
        }
    }
    power
}
