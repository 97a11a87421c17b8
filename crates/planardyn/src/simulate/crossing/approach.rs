//! The way to a change point: the accepted points kept near it (their accelerations are the
//! crossing's nodes before the point), the time left to it, and the steps aimed at the grid
//! on which the crossing wants those nodes.

use std::collections::VecDeque;

use super::{APPROACH_CAP, CROSS_BELOW, CROSS_START, NODES, SPACING};
use crate::simulate::ode::MechanismOde;

/// Accepted points kept: the crossing's [`NODES`] before the point are chosen among them (at
/// the tightest tolerances the integrator takes up to a few dozen steps over their span).
const KEPT: usize = 48;

/// An accepted point on the way: time (s), passive measure, body coordinates x, rates xd and
/// accelerations xdd (3n each), and the power of the non-conservative forces (W).
#[derive(Debug, Clone)]
pub struct Passed {
    pub t: f64,
    pub passive: f64,
    pub x: Vec<f64>,
    pub xd: Vec<f64>,
    pub xdd: Vec<f64>,
    pub power: f64,
}

impl Passed {
    /// The point evaluated in `ode.ws`, at time t with passive measure `passive`.
    pub fn of(ode: &MechanismOde, t: f64, passive: f64) -> Self {
        let ws = &ode.ws;
        Passed { t, passive, x: ws.x.clone(), xd: ws.xd.clone(), xdd: ws.xdd.clone(), power: ws.power }
    }
}

/// The last [`KEPT`] accepted points, newest last (since the last change point crossed), and
/// the points evaluated inside long steps of the approach ([`Approach::fill`]).
#[derive(Debug, Clone, Default)]
pub struct Approach {
    passed: VecDeque<Passed>,
    filled: VecDeque<Passed>,
}

/// Where a change point ahead is expected: at `t_star` (s); the crossing starts `tau` (s)
/// before it, where the passive measure is [`CROSS_BELOW`], and wants its nodes before it at
/// `t_star - tau - j h`, j = 1 .. [`NODES`].
#[derive(Debug, Clone, Copy)]
pub struct Grid {
    pub t_star: f64,
    pub tau: f64,
    pub h: f64,
}

impl Grid {
    /// The node times j = 1 .. NODES, latest first.
    pub fn nodes(&self) -> impl DoubleEndedIterator<Item = f64> + '_ {
        (1..=NODES).map(|j| self.t_star - self.tau - j as f64 * self.h)
    }
}

impl Approach {
    /// Remember the point held by `ode.ws`, accepted at t with passive measure `passive`.
    pub fn keep(&mut self, ode: &MechanismOde, t: f64, passive: f64) {
        push(&mut self.passed, ode, t, passive);
    }

    /// Add the point held by `ode.ws`, evaluated at t inside the step just accepted (before
    /// the point kept next; its passive measure is not asked for).
    pub fn fill(&mut self, ode: &MechanismOde, t: f64) {
        push(&mut self.filled, ode, t, f64::NAN);
    }

    /// Forget the way (after a crossing: the points before it are on the other side).
    pub fn clear(&mut self) {
        self.passed.clear();
        self.filled.clear();
    }

    /// The newest point kept.
    pub fn last(&self) -> Option<&Passed> {
        self.passed.back()
    }

    /// Up to [`NODES`] points before `t`, newest first, each at least 3/4 `spacing` before
    /// the next and all within `NODES + 1/2` spacings: about the approach's grid (see
    /// [`Approach::step_limit`]), whatever steps the integrator took between its times.
    pub fn samples(&self, t: f64, spacing: f64) -> Vec<&Passed> {
        let span = (NODES as f64 + 0.5) * spacing;
        let mut all: Vec<&Passed> = self.passed.iter().chain(&self.filled).filter(|p| p.t < t).collect();
        all.sort_by(|a, b| b.t.total_cmp(&a.t));
        let mut out: Vec<&Passed> = Vec::new();
        for p in all.into_iter().take_while(|p| t - p.t <= span) {
            if out.len() < NODES && out.last().map_or(t, |q| q.t) - p.t >= 0.75 * spacing {
                out.push(p);
            }
        }
        out
    }

    /// The time from the point accepted at `t` (passive measure `passive`) to the change
    /// point ahead: where the parabola through t and the two points kept before it reaches 0
    /// (the line through the one before, if only one is kept). Near the point the measure falls
    /// linearly (a transversal crossing); farther it is curved (A02's rises to a maximum at the
    /// upright pose and falls again: the secant through one point over that maximum made the
    /// time left 2.6 times too long). None unless it is falling towards 0: a parabola whose
    /// least value is above [`CROSS_START`] passes a singularity of the user's coordinates
    /// (the five-bar's), not a change point.
    pub fn time_to_point(&self, t: f64, passive: f64) -> Option<f64> {
        let mut before = self.passed.iter().rev().filter(|p| p.t < t);
        let p1 = before.next()?;
        let secant = (passive - p1.passive) / (t - p1.t);
        // passive + slope s + curvature s^2 for s = time ahead.
        let (slope, curvature) = match before.next() {
            Some(p2) => {
                let curvature = (secant - (p1.passive - p2.passive) / (p1.t - p2.t)) / (t - p2.t);
                (secant + curvature * (t - p1.t), curvature)
            }
            None => (secant, 0.0),
        };
        let discriminant = slope * slope - 4.0 * curvature * passive;
        let least = if curvature > 0.0 { passive - slope * slope / (4.0 * curvature) } else { f64::NEG_INFINITY };
        if !(slope < 0.0 && discriminant >= 0.0 && least < CROSS_START) {
            return None;
        }
        let to_point = 2.0 * passive / (discriminant.sqrt() - slope);
        to_point.is_finite().then_some(to_point)
    }

    /// The change point ahead of the point accepted at `t` (passive measure `passive`, kept
    /// last) and the crossing's grid before it, if the measure is falling towards 0.
    pub fn grid(&self, t: f64, passive: f64) -> Option<Grid> {
        let to_point = self.time_to_point(t, passive)?;
        let tau = to_point * CROSS_BELOW / passive;
        Some(Grid { t_star: t + to_point, tau, h: SPACING * tau })
    }

    /// The latest time the step after the point accepted at `t` (passive measure `passive`,
    /// kept last) may end at, while a change point is ahead: on the grid's next time once
    /// within it (the last step ends at the crossing's start, t* - tau), a third of the way to
    /// the point before. The integrator's stages then stay where the evaluations are accurate;
    /// grid times it stepped over are filled from its interpolant ([`Approach::fill`]).
    pub fn step_limit(&self, t: f64, passive: f64) -> Option<f64> {
        let Grid { t_star, tau, h } = self.grid(t, passive)?;
        let to_point = t_star - t;
        // How many spacings from the crossing's start t* - tau.
        let away = (to_point - tau) / h;
        Some(if away > NODES as f64 + 0.5 {
            t + APPROACH_CAP * to_point
        } else {
            t + to_point - tau - (away - 0.5).floor().max(0.0) * h
        })
    }
}

/// Append the point held by `ode.ws` (at t, passive measure `passive`) to `points`, the
/// oldest's buffers reused once [`KEPT`] are held (no allocation then).
fn push(points: &mut VecDeque<Passed>, ode: &MechanismOde, t: f64, passive: f64) {
    let ws = &ode.ws;
    let recycled = if points.len() >= KEPT { points.pop_front() } else { None };
    match recycled {
        Some(mut p) => {
            (p.t, p.passive, p.power) = (t, passive, ws.power);
            p.x.copy_from_slice(&ws.x);
            p.xd.copy_from_slice(&ws.xd);
            p.xdd.copy_from_slice(&ws.xdd);
            points.push_back(p);
        }
        None => points.push_back(Passed::of(ode, t, passive)),
    }
}
