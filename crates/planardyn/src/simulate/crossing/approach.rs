//! The way to a change point: the accepted points kept near it (their accelerations are the
//! crossing's nodes before the point), the time left to it, and the steps aimed at the grid
//! on which the crossing wants those nodes.

use std::collections::VecDeque;

use super::{APPROACH_CAP, CHANGE_POINT_RATIO, CROSS_BELOW, CROSS_DISTANCE, CROSS_START, NODES, SPACING};
use crate::model::Mechanism;
use crate::simulate::charts::Measures;
use crate::simulate::ode::MechanismOde;

/// Accepted points kept: the crossing's [`NODES`] before the point are chosen among them (at
/// the tightest tolerances the integrator takes up to a few dozen steps over their span).
const KEPT: usize = 48;
/// Nodes of a crossing at least after the first point kept (see [`Approach::grid`]). Over
/// benchmarks/change_point_sweep.py's double parallelograms (40 drawings x 6 runs, seeds 1 and
/// 2), 3 left 19 and 29 runs failing, 5: 15 and 24 (the others a first crossing soon after a
/// start at rest, or a slow one where the motion turns).
const FIRST_NODES: f64 = 5.0;

/// An accepted point on the way: time (s), passive and type II measures (the type II one NaN
/// but at the points kept), body coordinates x, rates xd and accelerations xdd (3n each, in one
/// buffer: a point kept is one allocation, not three), the power of the non-conservative forces
/// (W), and the scaled speed ([`scaled_speed`], 1/s).
#[derive(Debug, Clone)]
pub struct Passed {
    pub t: f64,
    pub passive: f64,
    pub sigma: f64,
    /// [x, xd, xdd].
    state: Vec<f64>,
    pub power: f64,
    pub speed: f64,
}

impl Passed {
    /// The point evaluated in `ode.ws`, at time t with passive measure `passive`.
    pub fn of(ode: &MechanismOde, t: f64, passive: f64) -> Self {
        let state = vec![0.0; 3 * ode.ws.x.len()];
        let mut p = Passed { t, passive, sigma: f64::NAN, state, power: 0.0, speed: 0.0 };
        p.renew(ode, t, passive);
        p
    }

    /// Body coordinates x (3n).
    pub fn x(&self) -> &[f64] {
        &self.state[..self.state.len() / 3]
    }

    /// Body rates xd (3n).
    pub fn xd(&self) -> &[f64] {
        let n = self.state.len() / 3;
        &self.state[n..2 * n]
    }

    /// Body accelerations xdd (3n).
    pub fn xdd(&self) -> &[f64] {
        &self.state[2 * self.state.len() / 3..]
    }

    /// Take the point evaluated in `ode.ws` into this one's buffer (of its size).
    fn renew(&mut self, ode: &MechanismOde, t: f64, passive: f64) {
        let ws = &ode.ws;
        (self.t, self.passive, self.sigma, self.power, self.speed) =
            (t, passive, f64::NAN, ws.power, scaled_speed(ode.mech, &ws.xd));
        // `max(1)`: chunks of 0 panic, and a state of no bodies has none to copy.
        for (dest, part) in self.state.chunks_exact_mut(ws.x.len().max(1)).zip([&ws.x, &ws.xd, &ws.xdd]) {
            dest.copy_from_slice(part);
        }
    }
}

/// The largest rate of the body coordinates xd, translations per the characteristic length L
/// (the units of `kinematics::scaled_distance` with `col_scales`).
pub fn scaled_speed(mech: &Mechanism, xd: &[f64]) -> f64 {
    xd.chunks_exact(3).fold(0.0, |s: f64, v| s.max(v[0].abs().max(v[1].abs()) / mech.scale).max(v[2].abs()))
}

/// The last [`KEPT`] accepted points, newest last (since the last change point crossed), and
/// the points evaluated inside long steps of the approach ([`Approach::fill`]).
#[derive(Debug, Clone, Default)]
pub struct Approach {
    passed: VecDeque<Passed>,
    filled: VecDeque<Passed>,
    /// The time of the first point kept (the run's start, or the last landing).
    since: f64,
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
    /// Remember the point held by `ode.ws`, accepted at t with measures `meas`.
    pub fn keep(&mut self, ode: &MechanismOde, t: f64, meas: &Measures) {
        if self.passed.is_empty() {
            self.since = t;
        }
        push(&mut self.passed, ode, t, meas);
    }

    /// Add the point held by `ode.ws`, evaluated at t inside the step just accepted (before
    /// the point kept next; its passive measure is not asked for).
    pub fn fill(&mut self, ode: &MechanismOde, t: f64) {
        push(&mut self.filled, ode, t, &Measures { sigma: f64::NAN, passive: f64::NAN });
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
    /// point ahead: where the parabola through t and the two points kept before it reaches 0.
    /// With one point kept before, the line through it, or the parabola flat there if the
    /// motion started at rest there (a run started near the point: the line through its start
    /// put a drawing 0.084 rad from it 16.8 s away, and the crossing's prediction 9.1e3 from
    /// any branch). Near the point the measure falls
    /// linearly (a transversal crossing); farther it is curved (A02's rises to a maximum at the
    /// upright pose and falls again: the secant through one point over that maximum made the
    /// time left 2.6 times too long). None unless it is falling towards 0: a parabola whose
    /// least value is above [`CROSS_START`] passes a singularity of the user's coordinates
    /// (the five-bar's), not a change point.
    pub fn time_to_point(&self, t: f64, meas: &Measures) -> Option<f64> {
        // The type II measure where the passive one is about it (both heading to 0, as at a
        // change point): it is smooth, where the passive one is the better of the partition
        // in use and it, and the partition changes from step to step near the point (the
        // double parallelogram's three equal cranks: 0.0325, 0.0312, 0.0276, 0.0303, 0.0268 at
        // five accepted points while the type II measure fell as 0.0294, 0.0282, 0.0276,
        // 0.0274, 0.0268;
        // the parabola through such points put the point 1-4 ms ahead instead of 30 ms).
        let of_sigma = meas.passive <= CHANGE_POINT_RATIO * meas.sigma;
        let level = |passive: f64, sigma: f64| if of_sigma { sigma } else { passive };
        let passive = level(meas.passive, meas.sigma);
        let mut before =
            self.passed.iter().rev().filter(|p| p.t < t).map(|p| (p.t, level(p.passive, p.sigma), p.speed));
        let p1 = before.next()?;
        let secant = (passive - p1.1) / (t - p1.0);
        // passive + slope s + curvature s^2 for s = time ahead.
        let (slope, curvature) = match before.next() {
            Some(p2) => {
                let curvature = (secant - (p1.1 - p2.1) / (p1.0 - p2.0)) / (t - p2.0);
                (secant + curvature * (t - p1.0), curvature)
            }
            // From rest: p1's level + curvature (s + t - p1.t)^2.
            None if p1.2 == 0.0 => {
                let curvature = secant / (t - p1.0);
                (2.0 * curvature * (t - p1.0), curvature)
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

    /// The change point ahead of the point accepted at `t` (measures `meas`) and the
    /// crossing's grid before it, if the measure is falling towards 0: the crossing starts
    /// where the passive measure is [`CROSS_BELOW`] or, nearer, at [`CROSS_DISTANCE`] from the
    /// point at the speed of the newest point kept, and late enough for [`FIRST_NODES`] of its
    /// nodes to follow the first point kept (a run started at rest 0.03 rad from a change
    /// point crossed at its first step, from the start's acceleration alone: 6.0e-2 off the
    /// branch's tangent).
    pub fn grid(&self, t: f64, meas: &Measures) -> Option<Grid> {
        let to_point = self.time_to_point(t, meas)?;
        let speed = self.passed.back().map_or(0.0, |p| p.speed);
        let history = (t + to_point - self.since) / (1.0 + FIRST_NODES * SPACING);
        let tau = (to_point * CROSS_BELOW / meas.passive).min(CROSS_DISTANCE / speed).min(history);
        Some(Grid { t_star: t + to_point, tau, h: SPACING * tau })
    }

    /// The latest time the step after the point accepted at `t` (passive measure `passive`,
    /// kept last) may end at, while a change point is ahead: on the grid's next time once
    /// within it (the last step ends at the crossing's start, t* - tau), a third of the way to
    /// the point before. The integrator's stages then stay where the evaluations are accurate;
    /// grid times it stepped over are filled from its interpolant ([`Approach::fill`]).
    pub fn step_limit(&self, t: f64, meas: &Measures) -> Option<f64> {
        let Grid { t_star, tau, h } = self.grid(t, meas)?;
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
fn push(points: &mut VecDeque<Passed>, ode: &MechanismOde, t: f64, meas: &Measures) {
    let recycled = if points.len() >= KEPT { points.pop_front() } else { None };
    let mut p = match recycled {
        Some(mut p) => {
            p.renew(ode, t, meas.passive);
            p
        }
        None => Passed::of(ode, t, meas.passive),
    };
    p.sigma = meas.sigma;
    if points.capacity() == 0 {
        // At most KEPT, never grown (and copied) on the way there.
        points.reserve_exact(KEPT);
    }
    points.push_back(p);
}
