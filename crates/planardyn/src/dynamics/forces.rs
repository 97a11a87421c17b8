//! Applied forces reduced to the centres of mass, f = [F_x, F_y, M] per body
//! (docs/formulation.md, eq. 26):
//! gravity, point forces, torques, springs and dampers, and the drive efforts mapped
//! through the coordinates' gradients (f += D_x^T tau, the virtual work of tau on q).

use crate::kinematics::constraints::{pair_coordinate, pair_coordinate_grad, pair_coordinate_rate, Sink};
use crate::model::pairs::frames::{link_state, perp};
use crate::model::{Attachment, Load, Mechanism};

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

/// A point of a link at (x, xd), with one sin_cos of its angle: its position, R s (from the
/// centre) and velocity, and the link's first column in x (None for the ground).
struct Point {
    p: [f64; 2],
    arm: [f64; 2],
    v: [f64; 2],
    col: Option<usize>,
}

impl Point {
    fn at(at: &Attachment, x: &[f64], xd: &[f64]) -> Self {
        let l = link_state(at.link, x);
        let arm = l.rot(at.s);
        let (rd, w) = l.col.map_or(([0.0; 2], 0.0), |c| ([xd[c], xd[c + 1]], xd[c + 2]));
        let t = perp(arm);
        Point { p: [l.r[0] + arm[0], l.r[1] + arm[1]], arm, v: [rd[0] + w * t[0], rd[1] + w * t[1]], col: l.col }
    }

    /// Add a force (N, global) acting at the point; returns its power (W).
    fn add_force(&self, force: [f64; 2], f: &mut [f64]) -> f64 {
        let Some(c) = self.col else { return 0.0 };
        f[c] += force[0];
        f[c + 1] += force[1];
        f[c + 2] += cross(self.arm, force);
        force[0] * self.v[0] + force[1] * self.v[1]
    }
}

/// f += effort * (a pair coordinate's gradient), as the gradient's entries are written.
struct Effort<'a> {
    f: &'a mut [f64],
    effort: f64,
}

impl Sink for Effort<'_> {
    #[inline]
    fn add(&mut self, _row: usize, col: usize, v: f64) {
        self.f[col] += self.effort * v;
    }
}

/// Add `effort` acting on a pair's relative coordinate (f += effort * grad).
fn add_pair_effort(mech: &Mechanism, pair: usize, effort: f64, x: &[f64], f: &mut [f64]) {
    pair_coordinate_grad(&mech.pairs[pair], x, &mut Effort { f, effort }, 0);
}

/// Fill `f` (3n) with every applied force at (x, xd) and drive efforts `tau`. Returns the power of the non-conservative forces (drives, dampers, point
/// forces and torques) in W; gravity and spring stiffness are counted in the potential.
pub fn applied_forces(mech: &Mechanism, x: &[f64], xd: &[f64], tau: &[f64], f: &mut [f64]) -> f64 {
    f.fill(0.0);
    let g = mech.gravity;
    for (i, body) in mech.bodies.iter().enumerate() {
        f[3 * i] = body.mass * g[0];
        f[3 * i + 1] = body.mass * g[1];
    }
    let mut power = 0.0;
    for load in &mech.loads {
        match load {
            Load::Force { at, value } => power += Point::at(at, x, xd).add_force(*value, f),
            Load::Torque { body, value } => {
                f[3 * body.0 + 2] += value;
                power += value * xd[3 * body.0 + 2];
            }
            Load::Spring { ends, stiffness, damping, rest_length } => {
                let (p0, p1) = (Point::at(&ends[0], x, xd), Point::at(&ends[1], x, xd));
                let d = [p1.p[0] - p0.p[0], p1.p[1] - p0.p[1]];
                let len = d[0].hypot(d[1]);
                if len == 0.0 {
                    continue; // direction undefined; a spring of zero length exerts no force
                }
                let e = [d[0] / len, d[1] / len];
                let rate = e[0] * (p1.v[0] - p0.v[0]) + e[1] * (p1.v[1] - p0.v[1]);
                let tension = stiffness * (len - rest_length) + damping * rate;
                p0.add_force([tension * e[0], tension * e[1]], f);
                p1.add_force([-tension * e[0], -tension * e[1]], f);
                power -= damping * rate * rate;
            }
            Load::PairSpring { pair, stiffness, damping, rest } => {
                let p = &mech.pairs[pair.0];
                let rate = pair_coordinate_rate(p, x, xd);
                let effort = -stiffness * (pair_coordinate(p, x) - rest) - damping * rate;
                add_pair_effort(mech, pair.0, effort, x, f);
                power -= damping * rate * rate;
            }
        }
    }
    for (c, &t) in mech.coordinates.iter().zip(tau) {
        if t != 0.0 {
            add_pair_effort(mech, c.pair.0, t, x, f);
            power += t * pair_coordinate_rate(&mech.pairs[c.pair.0], x, xd);
        }
    }
    power
}
