//! A change point on a path: where it is (the least regular pivot of Phi_x), what rank Phi_x
//! loses there, and whether an integrator step went over one.

use super::approach::{Approach, Passed};
use super::bridge::{Path, Quintic};
use super::WATCH_BELOW;
use crate::kinematics::coordinates;
use crate::kinematics::phi_pivots::phi_x_pivots;
use crate::model::Mechanism;
use crate::simulate::charts::Measures;
use crate::simulate::ode::MechanismOde;

/// A scaled pivot of Phi_x below this at the change point counts as a lost rank.
const LOST_PIVOT: f64 = 1e-4;
/// Golden-section steps locating the point within a crossing (0.618^40 of its length).
const LOCATE_ITERATIONS: usize = 40;

/// One crossing of a change point, as the result reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct ChangePoint {
    /// Time of the crossing (s), where Phi_x's least regular pivot is least on its path.
    pub t: f64,
    /// Body coordinates (3n) and the user's coordinates (m) there.
    pub x: Vec<f64>,
    pub q: Vec<f64>,
    /// Rank Phi_x loses there: the mobility jumps by this much.
    pub rank_drop: usize,
}

/// The change point on `path` between a and b (s).
pub fn located(mech: &Mechanism, path: &dyn Path, a: f64, b: f64) -> ChangePoint {
    let t = locate(mech, path, a, b);
    let n = mech.n_x();
    let (mut x, mut xd, mut xdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    path.at(t, &mut x, &mut xd, &mut xdd);
    let mut q = vec![0.0; mech.dof()];
    coordinates(mech, &x, &mut q);
    ChangePoint { t, rank_drop: rank_drop(mech, &x), x, q }
}

/// Whether the step from the last point kept to the one accepted at `t` (held by `ode.ws`,
/// passive measure `passive`) went over a change point, and the point, located on the
/// quintic through the step's two ends. From a point near it (below [`WATCH_BELOW`]) the
/// measure fell towards 0 before it and rose after it as |t - t*| does (a V), not as past a
/// minimum above 0 (the V's linear extrapolation only tells that it is there: at its time
/// Phi_x's pivots can still be above [`LOST_PIVOT`]). A step from farther away can land past
/// the point anywhere in the watched range (below [`WATCH_BELOW`]), the measure still
/// falling as seen from before it; only the path between tells: Phi_x loses rank inside the
/// step. With the approach's steps aimed at the crossing (`Approach::step_limit`) this is a
/// safety net: no A02 run of the benchmark's sweep needs it.
pub fn stepped_over(ode: &MechanismOde, approach: &Approach, t: f64, passive: f64) -> Option<ChangePoint> {
    let last = approach.last().filter(|p| p.t < t)?;
    let near = last.passive < WATCH_BELOW;
    if near {
        let to_point = approach.time_to_point(last.t, &Measures { sigma: last.sigma, passive: last.passive })?;
        let t_star = last.t + to_point;
        let expected = last.passive / to_point * (t - t_star);
        if !(t_star < t && passive > 0.5 * expected && passive < 2.0 * expected) {
            return None;
        }
    } else if passive >= WATCH_BELOW {
        return None;
    }
    let point = located_in_step(ode, last, t);
    (near || strictly_inside(&point, last.t, t)).then_some(point)
}

/// Whether Phi_x loses rank on the quintic from the point `last` to the point held by `ode.ws`
/// at `t` (strictly inside: a point located at the step's end is still ahead).
pub fn inside_step(ode: &MechanismOde, last: &Passed, t: f64) -> bool {
    strictly_inside(&located_in_step(ode, last, t), last.t, t)
}

/// The change point located on the quintic from the point `last` to the point held by
/// `ode.ws` at `t`.
fn located_in_step(ode: &MechanismOde, last: &Passed, t: f64) -> ChangePoint {
    let ws = &ode.ws;
    let path = Quintic::new(last, (&ws.x, &ws.xd, &ws.xdd), t);
    located(ode.mech, &path, last.t, t)
}

/// Whether `point`, located in the step from t0 to t, lost rank strictly inside it.
fn strictly_inside(point: &ChangePoint, t0: f64, t: f64) -> bool {
    // Golden section ends within 0.618^40 of an end where the pivot only falls.
    point.rank_drop > 0 && point.t < t - 1e-6 * (t - t0)
}

/// The scaled pivots of complete pivoting on Phi_x at x, in pivot order (fewer than its
/// rows where one is exactly 0).
fn pivots(mech: &Mechanism, x: &[f64]) -> Vec<f64> {
    phi_x_pivots(mech, x).into_iter().map(|(_, p)| p).collect()
}

/// Rank Phi_x has lost at x against a regular point (3n - m).
fn rank_drop(mech: &Mechanism, x: &[f64]) -> usize {
    let rank = pivots(mech, x).iter().filter(|&&p| p > LOST_PIVOT).count();
    (x.len() - mech.dof()).saturating_sub(rank)
}

/// The time in [a, b] where `path` passes the change point: where the smallest of Phi_x's
/// regular pivots (0 at the point, growing as |t - t*| on either side) is least, by golden
/// section. The passive measure's own V is not symmetric enough (the partition chosen on
/// either side differs): located from it, A02's point was 3e-6 rad off.
fn locate(mech: &Mechanism, path: &dyn Path, mut a: f64, mut b: f64) -> f64 {
    let n = mech.n_x();
    let regular = n - mech.dof();
    let (mut x, mut xd, mut xdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut f = |t: f64| {
        path.at(t, &mut x, &mut xd, &mut xdd);
        let p = pivots(mech, &x);
        if p.len() < regular {
            0.0
        } else {
            p.iter().fold(f64::INFINITY, |m: f64, &v| m.min(v))
        }
    };
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..LOCATE_ITERATIONS {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - r * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    (a + b) / 2.0
}
