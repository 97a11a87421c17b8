//! Choosing the integration chart: the user's coordinates q while they determine the
//! mechanism well, m components of x (generalized coordinate partitioning) near a type II
//! singularity, and back again once past it. Decisions are taken between accepted steps.

use super::ode::{MechanismOde, CLOSED_FORM_SIGMA};
use crate::integrate::Method;
use crate::kinematics::constraints::{pair_coordinate, pair_coordinate_rate};
use crate::kinematics::{passive_sigma_min_with, select_partition, sigma_min_with, Chart};

/// Below this scaled type II measure the integrator leaves the user's coordinates. The scaled
/// J has O(1) entries; at 0.05 the position solve still loses under 2 digits, and a step of
/// an adaptive method rarely jumps from there into the singularity itself.
pub const SWITCH_TO_PARTITION: f64 = 0.05;
/// Above this it returns to them (hysteresis, so that it does not switch back and forth).
pub const SWITCH_TO_INPUTS: f64 = 0.1;
/// The smallest own measure of an alternative chart (`kinematics::alt_charts`) to take it
/// instead of a partition: as clear of its singularity as the user's chart must be to return
/// to it, so that its closed forms are in use (above `CLOSED_FORM_SIGMA`, 0.07).
pub const ALT_CLEAR: f64 = SWITCH_TO_INPUTS;
/// Below this scaled measure the passive mechanism is singular: the simulation stops.
pub const PASSIVE_SINGULAR: f64 = 1e-8;
/// A failed step this close to a passive singularity is reported as one.
pub const NEAR_PASSIVE_SINGULAR: f64 = 1e-3;

/// Largest move of the body coordinates x over the first step in a new chart, as a fraction of
/// the chart's own measure there (scaled by each group's length, as the Newton bounds of
/// `MechanismOde::limit_correction` are: a correction may take half the measure). The
/// starting-step rule sees only f and its change along f: on the five-bar at DOP853 rtol 1e-6
/// its guess after a switch was rejected 2-3 times at 8 of the 11 switches (20 of the run's 28
/// rejections); the first steps accepted then moved x by 0.3-2 times the measure, and one of
/// 47 ms at rtol 3.98e-8 (8-13 ms before it) left its outputs 25x the steps' energy error.
/// With 0.3, over rtol = atol = 1e-4 ... 1e-8 (81 values): rejections 19-34 -> 5-16 a run,
/// evaluations -14 %, rows within 2.35x the steps' drift (was 5x), and the drift above 1e-4 J
/// only from 5.0e-5 up (was up to 2.8e-6; 0.13 J at 8.9e-5). The motion is chaotic and single
/// settings scatter: 0.28 and 0.5 cut as many evaluations but each lost 0.8-1.8 J at one
/// of 21 settings (as 0.13 J at 8.9e-5 before), 0.25 left rows 2.03x the steps at 3.98e-8.
const FIRST_STEP_MOVE: f64 = 0.3;

/// Largest step in the user's chart while its type II measure falls, as a fraction of the time
/// the measure takes to reach 0 (`fall_step_bound`). The chart's equations of motion vary like
/// 1/sigma^2, singular where sigma^2, about linear in t, reaches 0: the solution's Taylor series
/// about a step's start converges only out to that time T, its terms falling like (h / T)^p.
/// An embedded error estimate is the difference of two truncations of it, and it bounds the
/// error of the solution propagated only while each term is below half the one before, h < T / 2
/// (at h = rho T it sees (1 - rho) of the lower order's error, the propagated one being rho of
/// it). Where the singularity is in the solution this replaces [`SMOOTH_FALL`] (the end's
/// measure no lower than 0.35 sigma, h up to 0.88 T), under which the five-bar fall
/// (DOPRI5, rtol = atol 1.0965e-6, 1 s) stepped from 0.0746 to 0.0458 (h = 0.62 T) and gained
/// 5.7e-4 J in that step, the steps around it 1e-8 to 6e-5 J (tolerances 1.096e-6 and
/// 1.063e-6 on either side: 6.5e-4 and 7.7e-5 J). The same bound, h < T / 2 with T the time to
/// the nearest complex singularity, removed every outlier of DOP853 on the Scotch yoke's
/// equations written out (scipy, rtol = 10^(-k/20), k = 20 ... 200).
const USER_FALL: f64 = 0.5;

/// Smallest ratio of the type II measure at a step's end to its start that a step in the
/// user's chart may aim for, below [`SWITCH_TO_PARTITION`], where the measure falls but the
/// accelerations do not grow like 1 / sigma (`fall_step_bound`): a change point on a branch
/// the motion passes analytically (A02), whose equations are singular only as 0 / 0. The
/// bound applied everywhere before [`USER_FALL`] (2e54c44); [`USER_FALL`] there took A02 (N = 40, rtol 1e-12)
/// from 2.4e-9 to 1.03e-8 rad off the reduction (tests/change_points.rs: 1e-8).
const SMOOTH_FALL: f64 = 0.35;

/// What the monitor found at an accepted point.
#[derive(Debug, Clone, Copy)]
pub struct Measures {
    /// Type II measure: smallest scaled singular value of the blocks of [Phi_x; D_x] (`group_sigma`).
    pub sigma: f64,
    /// Passive measure (`kinematics::passive_sigma_min`, with the partition in use where there
    /// is one), computed only near a type II singularity; elsewhere `sigma` bounds it from below.
    pub passive: f64,
}

/// Measure the point analysed in `ode.ws`. In the user's chart the type II measure is the
/// chart's own ([`MechanismOde::own_sigma`]: from the closed forms or the factorisation in the
/// workspace); near a singularity, where a partition is in use, it is exact
/// (an SVD of each block of the user's chart, linear in the bodies), and the passive measure
/// an SVD of the whole Phi_x (at the few steps near a type II singularity only).
pub fn measure(ode: &mut MechanismOde) -> Measures {
    let sigma = match ode.ws.chart {
        Chart::Inputs => ode.own_sigma(),
        Chart::Partition(_) => sigma_min_with(&mut ode.inputs_sys, ode.mech, &Chart::Inputs, &ode.ws.x),
        Chart::Pairs(_) => ode.user_sigma(),
    };
    // Passive: the better of the user's chart and the partition in use (its factorisation is
    // in the workspace), else the partition complete pivoting would choose.
    let passive = if sigma >= SWITCH_TO_PARTITION {
        sigma
    } else {
        let own = match ode.ws.chart {
            Chart::Partition(_) => ode.ws.sys.sigma_min_estimate(),
            // Where another chart's J is regular, so are the pair constraints.
            Chart::Pairs(_) => Some(ode.own_sigma()),
            Chart::Inputs => None,
        };
        own.map_or_else(|| passive_sigma_min_with(&mut ode.inputs_sys, ode.mech, &ode.ws.x), |own| own.max(sigma))
    };
    Measures { sigma, passive }
}

/// The measure of the current chart's J at the point in `ode.ws` (smallest singular value of
/// its blocks at their own lengths), given the type II measure `sigma` there (which it is in
/// the user's chart; in a partition it is estimated from the factorisation in the workspace).
pub fn chart_sigma(ode: &mut MechanismOde, sigma: f64) -> f64 {
    match &ode.ws.chart {
        Chart::Inputs => sigma,
        Chart::Partition(_) | Chart::Pairs(_) => ode.own_sigma(),
    }
}

/// The chart to integrate in next, if it should change, from the measures at the current
/// point and the current chart's own measure `own` ([`chart_sigma`]): another chart when q is
/// near-singular, back to q when clear of it, and a fresh one when the current one degrades;
/// with its own measure at this point where that is known already (the user's chart's, and
/// an alternative chart's from its choice, exact to round-off: `AltCharts::best`), so that
/// the switch need not estimate it from the new chart's first factorisation ([`chart_sigma`]).
pub fn next_chart(ode: &mut MechanismOde, m: &Measures, own: f64) -> Option<(Chart, Option<f64>)> {
    match &ode.ws.chart {
        Chart::Inputs if m.sigma < SWITCH_TO_PARTITION => Some(other_chart(ode)),
        Chart::Inputs if m.sigma < CLOSED_FORM_SIGMA => clear_alt_chart(ode).map(|(c, s)| (c, Some(s))),
        Chart::Inputs => None,
        Chart::Partition(_) | Chart::Pairs(_) if m.sigma > SWITCH_TO_INPUTS => Some((Chart::Inputs, Some(m.sigma))),
        Chart::Partition(_) if own >= SWITCH_TO_PARTITION => None,
        Chart::Pairs(_) if own >= ALT_CLEAR => None,
        Chart::Partition(_) | Chart::Pairs(_) => {
            let best = other_chart(ode);
            (best.0 != ode.ws.chart).then_some(best)
        }
    }
}

/// The chart to leave the user's for at the point in `ode.ws`, with its measure there if known:
/// the alternative chart of largest own measure where that is clear of its singularity
/// ([`ALT_CLEAR`]; none with a prescribed motion, whose coordinates are the user's), else the
/// partition complete pivoting chooses.
fn other_chart(ode: &mut MechanismOde) -> (Chart, Option<f64>) {
    match clear_alt_chart(ode) {
        Some((chart, sigma)) => (chart, Some(sigma)),
        None => (Chart::Partition(select_partition(ode.mech, &ode.ws.x)), None),
    }
}

/// The alternative chart of largest own measure at the point in `ode.ws` where that is clear
/// of its singularity ([`ALT_CLEAR`]; none with a prescribed motion), and that measure. Taken
/// from the user's chart below `CLOSED_FORM_SIGMA` already, where the user's chart leaves its
/// closed forms for Newton: the alternative chart's are in use there.
fn clear_alt_chart(ode: &mut MechanismOde) -> Option<(Chart, f64)> {
    if ode.motion.is_some() {
        return None;
    }
    ode.best_alt_chart().filter(|(_, sigma)| *sigma >= ALT_CLEAR)
}

/// The longest first step in the chart of the point held by `ode.ws`, whose own measure is
/// `own` ([`chart_sigma`]): at its body rates xd (scaled), the step that moves x by
/// [`FIRST_STEP_MOVE`] of the measure (s; infinite at rest, where no step moves x).
pub fn first_step_bound(ode: &MechanismOde, own: f64) -> f64 {
    let rate = ode.scaled_body_rate();
    if rate > 0.0 {
        FIRST_STEP_MOVE * own / rate
    } else {
        f64::INFINITY
    }
}

/// How fast the accelerations grow against 1 / sigma from `last` to `now` (t, sigma, |qdd|):
/// d|qdd| / d(1 / sigma). Where the user's chart's singularity is in the solution, the
/// accelerations have a part like 1 / sigma^k, k >= 1, and this growth does not die out as
/// sigma falls; where the motion passes the point analytically (a change point on the branch
/// it follows, A02's), |qdd| tends to a finite limit and the growth falls towards 0 (measured:
/// five-bar fall, DOPRI5 at 1.0965e-6, sigma 0.21 -> 0.10: 14, 26, 28 (s^-2); A02, N = 40,
/// DOP853 at 1e-12, sigma 0.24 -> 0.055: 1.75, 1.26, 0.82, 0.46, 0.20, 0.055).
fn acceleration_growth(last: (f64, f64, f64), now: (f64, f64, f64)) -> f64 {
    (now.2 - last.2) / (1.0 / now.1 - 1.0 / last.1)
}

/// The longest next step in the user's chart from (t, sigma) at the last accepted point
/// (`now`) and at the one before (`last`), with sigma^2 linear in t (a generic passage by a
/// type II singularity): where the chart's singularity is in the solution (`singular`: the
/// accelerations' growth against 1 / sigma, [`acceleration_growth`], rises, or was not seen to
/// fall at a point of this fall below the run's PREDICT_BELOW), the step covers at most
/// [`USER_FALL`] of the time to it; elsewhere it ends no lower than
/// [`SMOOTH_FALL`] times the measure or [`SWITCH_TO_PARTITION`] (s; infinite where the measure
/// does not fall).
fn fall_step_bound(last: (f64, f64, f64), now: (f64, f64, f64), singular: bool) -> f64 {
    let fall_rate = (last.1 * last.1 - now.1 * now.1) / (now.0 - last.0);
    if !(now.0 > last.0 && fall_rate > 0.0) {
        return f64::INFINITY;
    }
    if singular {
        USER_FALL * now.1 * now.1 / fall_rate
    } else {
        let end = (SMOOTH_FALL * now.1).min(SWITCH_TO_PARTITION);
        (now.1 * now.1 - end * end).max(0.0) / fall_rate
    }
}

/// The time from `now` to where sigma^2, the parabola in t through the last three accepted
/// points' (`before`, `last`, `now`: (t, sigma)), reaches 0, where it is concave (s; infinite
/// elsewhere): a fall that starts at a peak of the measure, which the two points' slope does
/// not see (five-bar fall, DOPRI5 at rtol = atol 0.0501: from sigma 0.3005, 0.3009 a step of
/// 28 ms fell to 0.126 and gained 0.50 J; bounded to half of it, the
/// sweep rtol = 10^(-k/20), k = 20 ... 200, has its worst 0.508 -> 0.126 J for +1.6 %
/// evaluations).
fn curved_fall_time(before: (f64, f64), last: (f64, f64, f64), now: (f64, f64, f64)) -> f64 {
    let (a, b, c) = (before.1 * before.1, last.1 * last.1, now.1 * now.1);
    let (d1, d2) = ((b - a) / (last.0 - before.0), (c - b) / (now.0 - last.0));
    let dd = (d2 - d1) / (now.0 - before.0);
    if dd.is_nan() || dd >= 0.0 {
        return f64::INFINITY;
    }
    let g = d2 + dd * (now.0 - last.0);
    (g + (g * g - 4.0 * dd * c).sqrt()) / (-2.0 * dd)
}

/// The user's chart's type II falls, accepted point by accepted point: what [`fall_step_bound`]
/// needs of the points before, and whether the fall under way is singular in the solution.
#[derive(Debug, Clone)]
pub struct FallWatch {
    /// Whether the run bounds a fall by [`USER_FALL`] at all: not for a method whose estimate
    /// sees the step's reach itself (DOP853: with the bound, 0 of 751 rtols from 1e-4 to 1e-9
    /// over 1e-4 J either way, the worst 1.4e-5 -> 1.5e-5 J, for +6 % evaluations).
    bounds: bool,
    /// (t, sigma, |qdd|) at the last accepted point, if in a watched chart.
    last: Option<(f64, f64, f64)>,
    /// (t, sigma) at the accepted point before `last`, in the same chart.
    before: Option<(f64, f64)>,
    /// The accelerations' growth into that point ([`acceleration_growth`]; NaN where unknown).
    growth: f64,
    /// This fall was taken to be singular in the solution, latched while the measure falls.
    singular: bool,
}

impl FallWatch {
    /// Before the run's first point, for a run by `method`.
    pub fn new(method: Method) -> Self {
        FallWatch { bounds: !method.sees_reach(), last: None, before: None, growth: f64::NAN, singular: false }
    }

    /// Whether [`FallWatch::next_step_bound`] reads |qdd| (only where falls are bounded).
    pub fn wants_accelerations(&self) -> bool {
        self.bounds
    }

    /// Take the accepted point `now` = (t, sigma, |qdd|) in `chart`, sigma and qdd the chart's
    /// own (`continued`: the point before was in the same chart; `low`: sigma below the run's
    /// PREDICT_BELOW) and return the bound on the next step, if any. The user's chart is
    /// watched; an alternative (pairs') chart only where falls are bounded, so that DOP853's
    /// steps there keep no smooth-fall bound they did not have; a partition is not watched.
    ///
    /// An alternative chart's equations are singular as the user's are where its own measure
    /// reaches 0, and its steps fall into it alike: the five-bar fall, DOPRI5 at rtol = atol
    /// 4.47e-4, stepped in the pairs' chart from own measure 0.103 to 0.080 in 5.9 ms (more
    /// than the time to its singularity, sigma^2 extrapolated) and gained 5.7e-3 J in that
    /// step, the runs on either side 4.1e-4 and 5.3e-4 J in all.
    ///
    /// Wherever the measure falls, above PREDICT_BELOW too where the accelerations' growth
    /// against 1 / sigma rises (the five-bar fall with DOP853 at rtol = atol 3.55e-4, before its
    /// estimate saw the step's reach, stepped from 0.255 to 0.093 in 25 ms, 0.87 of the time to
    /// the singularity, and lost 2.8e-4 J in it; the runs on either side 2.6e-5 and 3.5e-5 J).
    /// Below PREDICT_BELOW the singularity is in the solution unless the growth is seen to fall
    /// towards a finite limit, positive and below the last (A02, N = 40, rtol 1e-12: at every
    /// point of a fall from sigma 0.39 down, 7.8 ... 1.75 ... 0.055): waiting for it to rise
    /// missed a fall's first steps, where the accelerations' regular part falls (five-bar fall,
    /// DOP853 at 1e-6 with the bound: growth -183 then -55 at sigma 0.29 and 0.23, and the next
    /// step, to 0.14, covered 0.82 of the time to the singularity, its dense output 5.8e-7 J off
    /// mid-step). Latched for the rest of the fall: the growth from point to point is noisy
    /// where the steps are long (five-bar fall, DOPRI5 rtol 9.5e-5: 27.1 then 25.7 at sigma
    /// 0.106 and 0.085, and the next step, unbounded by T/2, took 0.085 to 0.050 and gained
    /// 1.0e-3 J).
    pub fn next_step_bound(&mut self, chart: &Chart, continued: bool, low: bool, now: (f64, f64, f64)) -> Option<f64> {
        let watched = match chart {
            Chart::Inputs => true,
            Chart::Pairs(_) => self.bounds,
            Chart::Partition(_) => false,
        };
        let last = self.last.filter(|_| watched && continued);
        let growth = last.map_or(f64::NAN, |last| acceleration_growth(last, now));
        let (rising, analytic) = (growth > 0.0 && growth >= self.growth, growth > 0.0 && growth < self.growth);
        let falling = last.is_some_and(|last| now.1 < last.1);
        self.singular = self.bounds && falling && (self.singular || (low && !analytic));
        let singular = self.bounds && (rising || self.singular);
        let before = self.before.filter(|_| self.bounds && last.is_some());
        let curved =
            before.zip(last).map_or(f64::INFINITY, |(before, last)| USER_FALL * curved_fall_time(before, last, now));
        self.before = last.map(|last| (last.0, last.1));
        (self.last, self.growth) = (watched.then_some(now), growth);
        let bound = last.filter(|_| low || singular).map(|last| fall_step_bound(last, now, singular));
        match bound {
            Some(h) => Some(h.min(curved)),
            None => curved.is_finite().then_some(curved),
        }
    }
}

/// The state y = [z, zd, W] of `ode.ws`'s current point expressed in `chart`.
pub fn state_in(ode: &MechanismOde, chart: &Chart, work: f64, y: &mut [f64]) {
    let m = ode.m();
    match chart {
        Chart::Inputs => {
            y[..m].copy_from_slice(&ode.ws.q);
            y[m..2 * m].copy_from_slice(&ode.ws.qd);
        }
        Chart::Partition(idx) => {
            for (k, &i) in idx.iter().enumerate() {
                y[k] = ode.ws.x[i];
                y[m + k] = ode.ws.xd[i];
            }
        }
        Chart::Pairs(idx) => {
            for (k, &i) in idx.iter().enumerate() {
                let pair = &ode.mech.pairs[i];
                y[k] = pair_coordinate(pair, &ode.ws.x);
                y[m + k] = pair_coordinate_rate(pair, &ode.ws.x, &ode.ws.xd);
            }
        }
    }
    y[2 * m] = work;
}
