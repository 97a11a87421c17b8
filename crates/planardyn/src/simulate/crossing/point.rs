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
/// The bracket within which the point is located, as a fraction of the crossing's (or step's)
/// length: 0.618^40, that of the 40 golden-section steps the location took before (42
/// evaluations of Phi_x's pivots a location; `locate` took 81 for the five-bar free fall's 4,
/// DOPRI5 rtol 7.59e-7: about 10 where the least is at an end, 29 at an interior minimum).
const LOCATE_BRACKET: f64 = 4.37e-9;
/// At most this many steps of the search a location: Brent's method falls back to golden-section steps
/// where the parabolas do not shrink the bracket, which 40 of reach [`LOCATE_BRACKET`]; a
/// bound, never reached in the tests.
const LOCATE_EVALUATIONS: usize = 100;
/// Within this fraction of the interval from one of its ends, the search asks whether the
/// least is at that end (2 evaluations instead of about 30 golden-section steps to it).
const END_NEAR: f64 = 1.0 / 16.0;
/// Rounding of a scaled pivot of Phi_x (entries O(1), a few eliminations' sums): 16 ulps of 1.
const PIVOT_ROUNDING: f64 = 16.0 * f64::EPSILON;

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
    // The location ends within LOCATE_BRACKET / 2 of an end where the pivot only falls.
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
/// regular pivots (0 at the point, growing as |t - t*| on either side) is least, by Brent's
/// minimisation (golden section and parabolic steps) of its square, which is smooth across the
/// point as the pivot is not, so that the parabolas fit it there. The time returned is within
/// half of [`LOCATE_BRACKET`] of the interval's length from the least pivot (the final
/// bracket's guarantee), as the 40 golden-section steps this replaces left their bracket's
/// midpoint. The passive measure's own V is not symmetric enough (the partition chosen on
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
            let least = p.iter().fold(f64::INFINITY, |m: f64, &v| m.min(v));
            least * least
        }
    };
    // Brent (1973), `localmin`, with an absolute tolerance: it ends when the bracket [a, b]
    // lies within tol2 of the best point t. Written here rather than taken from argmin's
    // BrentOpt: the end test and the stop at the pivot's rounding (`resolution`) are this
    // search's own, and the core would take on an optimisation framework for 60 lines. A
    // golden-section step is taken where a parabola's would not shrink the bracket fast enough.
    let golden = (3.0 - 5f64.sqrt()) / 2.0;
    let (bracket, widest) = (LOCATE_BRACKET * (b - a) / 4.0, f64::EPSILON.sqrt() * (b - a));
    let mut t = a + golden * (b - a);
    let (mut w, mut v) = (t, t);
    let mut ft = f(t);
    let (mut fw, mut fv) = (ft, ft);
    let (mut d, mut e) = (0.0_f64, 0.0_f64);
    let (a0, b0, end) = (a, b, LOCATE_BRACKET * (b - a));
    let mut ends_asked = [false; 2];
    for _ in 0..LOCATE_EVALUATIONS {
        // Near an end the search still has (the pivot only falling towards it), whether the
        // least is within `end` of it: rising from it over that distance, it is (the pivot has
        // one minimum in [a, b], as the search assumes), and the midpoint is the located time,
        // as the golden-section steps ended within that bracket of it. Else the search goes on.
        for (k, (edge, inward)) in [(a0, end), (b0, -end)].into_iter().enumerate() {
            let open = if k == 0 { a == a0 } else { b == b0 };
            if open && !ends_asked[k] && (t - edge).abs() < END_NEAR * (b0 - a0) {
                ends_asked[k] = true;
                if f(edge + inward) > f(edge) {
                    return edge + 0.5 * inward;
                }
            }
        }
        let mid = 0.5 * (a + b);
        let tol1 = bracket.max(resolution([(t, ft), (w, fw), (v, fv)]).min(widest));
        let tol2 = 2.0 * tol1;
        if (t - mid).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut parabolic = false;
        if e.abs() > tol1 {
            // The parabola through (t, w, v): its vertex at t + p / q.
            let r = (t - w) * (ft - fv);
            let s = (t - v) * (ft - fw);
            let (mut p, mut q) = ((t - v) * s - (t - w) * r, 2.0 * (s - r));
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let last = e;
            e = d;
            if p.abs() < (0.5 * q * last).abs() && p > q * (a - t) && p < q * (b - t) {
                d = p / q;
                let u = t + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol1.copysign(mid - t);
                }
                parabolic = true;
            }
        }
        if !parabolic {
            e = if t >= mid { a - t } else { b - t };
            d = golden * e;
        }
        let u = if d.abs() >= tol1 { t + d } else { t + tol1.copysign(d) };
        let fu = f(u);
        if fu <= ft {
            if u >= t {
                a = t;
            } else {
                b = t;
            }
            (v, fv, w, fw, t, ft) = (w, fw, t, ft, u, fu);
        } else {
            if u < t {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == t {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == t || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    t
}

/// How close to the least of a smooth positive minimum the squared pivot can tell, through the
/// parabola of its three best points (the best first): where it rises from its vertex by less
/// than its rounding ([`PIVOT_ROUNDING`] in the pivot), the comparisons of the search are
/// rounding, not the pivot's shape. 0 where the points do not give a convex parabola. At a
/// change point the pivot's square falls to rounding level, and so does this resolution.
fn resolution([(t, ft), (w, fw), (v, fv)]: [(f64, f64); 3]) -> f64 {
    if t == w || t == v || w == v {
        return 0.0;
    }
    let curvature = ((fw - ft) / (w - t) - (fv - ft) / (v - t)) / (w - v);
    if curvature > 0.0 {
        (2.0 * ft.sqrt() * PIVOT_ROUNDING / curvature).sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::phi_pivots::tests::a02_folded;

    /// A straight line in x through A02's change point at `T_STAR` (from its drawn pose).
    struct Line {
        fold: Vec<f64>,
        dx: Vec<f64>,
    }

    const T_STAR: f64 = 0.37;

    impl Path for Line {
        fn at(&self, t: f64, x: &mut [f64], xd: &mut [f64], xdd: &mut [f64]) {
            for (i, (f, d)) in self.fold.iter().zip(&self.dx).enumerate() {
                (x[i], xd[i], xdd[i]) = (f + (t - T_STAR) * d, *d, 0.0);
            }
        }
    }

    #[test]
    fn a_change_point_is_located_within_its_bracket() {
        // Phi_x loses rank 2 at T_STAR only; its least regular pivot grows as |t - T_STAR|
        // on either side. Located within LOCATE_BRACKET / 2 of each interval's length from
        // it (the stated tolerance), or from the interval's end nearer to it when outside.
        let (mech, fold) = a02_folded();
        let dx: Vec<f64> = fold.iter().zip(&mech.x0).map(|(f, x0)| f - x0).collect();
        let line = Line { fold, dx };
        for (a, b) in [(0.07, 0.47), (0.32, 0.57), (0.3699, 0.5), (0.38, 0.6), (0.1, 0.36)] {
            let point = located(&mech, &line, a, b);
            let expected = T_STAR.clamp(a, b);
            // At an end the located time is the end bracket's midpoint, exactly that far
            // from it: a few ulps of t for the rounding of the bracket's ends.
            let tolerance = 0.5 * LOCATE_BRACKET * (b - a) + 4.0 * f64::EPSILON * b;
            assert!((point.t - expected).abs() <= tolerance, "[{a}, {b}]: {} vs {expected}", point.t);
            assert_eq!(point.rank_drop, if expected == T_STAR { 2 } else { 0 }, "[{a}, {b}]");
        }
    }

    #[test]
    fn a_change_point_at_either_end_is_located_within_its_bracket() {
        // T_STAR inside [a, b], `at` end brackets (LOCATE_BRACKET (b - a)) from a or from b:
        // on the end itself, inside the end's bracket (the end check answers), just past it
        // and 2 brackets in (the search goes on). Each within the stated tolerance of T_STAR.
        let (mech, fold) = a02_folded();
        let dx: Vec<f64> = fold.iter().zip(&mech.x0).map(|(f, x0)| f - x0).collect();
        let line = Line { fold, dx };
        for len in [0.2, 0.013] {
            let end = LOCATE_BRACKET * len;
            for at in [0.0, 0.3, 0.5, 0.99, 1.01, 2.0] {
                let from_a = T_STAR - at * end;
                let from_b = T_STAR + at * end;
                for (a, b) in [(from_a, from_a + len), (from_b - len, from_b)] {
                    let point = located(&mech, &line, a, b);
                    let tolerance = 0.5 * end + 4.0 * f64::EPSILON * b;
                    let miss = (point.t - T_STAR).abs();
                    assert!(miss <= tolerance, "[{a}, {b}] at {at}: {} off by {miss:e} > {tolerance:e}", point.t);
                    assert_eq!(point.rank_drop, 2, "[{a}, {b}] at {at}");
                }
            }
        }
    }
}
