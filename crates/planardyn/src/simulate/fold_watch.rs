//! A prescribed motion that runs into a fold of its driven coordinates: their measure falls
//! like sqrt(t* - t), the steps shrink towards t* without passing it, and past it the mechanism
//! does not assemble at the prescribed coordinates. [`FoldWatch`] predicts t* from the
//! measure's square, linear in t near it, to stop such a run (`Stop::Fold`) and to say why a
//! run failed at it (`Near::fold`).

use std::collections::VecDeque;

use super::charts::NEAR_PASSIVE_SINGULAR;

/// Accepted points in the fold's fit: two secants of [`FOLD_SPAN`] steps each.
const FOLD_SPAN: usize = 4;

/// The fold's prediction may move by this fraction of the time the run advanced. Near a fold
/// the measure's square is k (t* - t), and t* stays put (the repro of tests/test_prescribed_fold.py:
/// |dt*/dt| < 0.04 over its last 2 ms). A motion that passes close to it and turns back has
/// sigma^2 ~ k (d + c (t - t_m)^2), whose secants predict a t* that moves at least half as fast
/// as t (measured: 0.53 ... 0.85 at d = 1e-4 and 1e-6 s before its minimum, more after).
const FOLD_DRIFT: f64 = 0.25;

/// A step shorter than this fraction of the predicted time left to the fold no longer
/// advances towards it: the steps close in geometrically while the integrator resolves the
/// approach (about 0.2 of the time left each step, in the repro), and stall at the
/// tolerance's resolution of the fold (4e-4 there, 2e-13 s steps 5e-10 s before t*, for
/// thousands of steps).
const FOLD_ADVANCE: f64 = 0.01;

/// A failed run stalled before a fold when its last step was below this fraction of the time
/// left to it: five-bar-robot's steps shrank to 2.4e-7 of it (4e-12 s, 1.7e-5 s before its fold).
/// The ordinary small steps of a 3-RRR pass-by, where sigma^2 is nearly linear and its secant
/// reaches 0 far ahead (RADAU5 at rtol 1e-12, rk4 at dt 1e-4), come to 2.3e-3 of it and more
/// (a sweep of the shipped models' failed runs); [`FOLD_ADVANCE`] let those count as stalls.
const FOLD_STALL: f64 = 1e-4;

/// A failed step's fold must lie within this many steps of the last accepted point, and the
/// secant that predicts it end as near before it: the steps that fail at a fold are those that
/// try to pass it, or (fixed steps: rk4, or `dt`) the ones after the step that passed it.
const FOLD_REACH: f64 = 2.0;

/// Where the measure still fell at the last accepted point, its fold must lie within this
/// fraction of the last step after it: a run fails at a fold only once its steps, shrunk or
/// refined as far as they go, can no longer approach it, so the fold is then closer than the
/// step that failed (measured up to 0.20 of it: rk4 at dt 5e-4 into the 3-RRR's fold, refined to
/// 3e-14 s steps). A pass-by's secant at ordinary steps reaches 0 about a step ahead (0.8 to 1.9
/// of it over a sweep of the shipped models' runs), where FOLD_REACH named a fold.
const FOLD_AHEAD: f64 = 0.5;

/// The driven coordinates' measure (their scaled smallest singular value, `sigma`) at the
/// last accepted points, while it is below [`NEAR_PASSIVE_SINGULAR`], the threshold of their
/// diagnosis. Near a fold of the driven coordinates sigma^2 falls linearly in t to 0 at t*.
#[derive(Default)]
pub struct FoldWatch {
    /// (t, sigma^2), the oldest first; at most 2 FOLD_SPAN + 1.
    points: VecDeque<(f64, f64)>,
    /// When the measure last fell below [`NEAR_PASSIVE_SINGULAR`] (the first of `points`).
    entered: f64,
    /// (t, sigma^2) at the last accepted point where the measure was taken (at any value), and
    /// the last two such successive points where it fell.
    last: Option<(f64, f64)>,
    fell: Option<[(f64, f64); 2]>,
    /// Since when the measure has fallen at every accepted point, up to the last one.
    falling_since: Option<f64>,
    /// (t, t*): the fold the secants predicted at two points of that fall, the older first, the
    /// newer taken at least half the time left after the older (a fold's t* stays put, a
    /// pass-by's moves on with t: [`FOLD_DRIFT`]).
    predicted: Option<[(f64, f64); 2]>,
}

impl FoldWatch {
    /// Keep the point accepted at t (measure `sigma`, after a step of h); the fold's time when
    /// the run steps towards it without reaching it: two successive secants of sigma^2 over
    /// t both fall and predict the same t* (within [`FOLD_DRIFT`] of the time between them),
    /// and the step h is below [`FOLD_ADVANCE`] of the time left to it, which is shorter than
    /// the time the measure has been below [`NEAR_PASSIVE_SINGULAR`]. On sigma^2 = k (t* - t)
    /// the latter holds once sigma is below 1/sqrt(2) of that threshold. A pass-by near its
    /// closest approach (a flat sigma^2) has a far t*: at DOP853 rtol 1e-12, 1e-7 s from the
    /// 3-RRR's fold, rounding in its 4e-11 s steps made the secants agree on a fold 0.0104 s
    /// ahead after 23 000 steps, 2.8e-3 s after the measure fell below the threshold.
    pub fn zeno(&mut self, t: f64, sigma: f64, h: f64) -> Option<f64> {
        let point = (t, sigma * sigma);
        match self.last.filter(|_| sigma.is_finite()) {
            Some(before) if point.1 < before.1 => {
                self.fell = Some([before, point]);
                if self.falling_since.is_none() {
                    (self.falling_since, self.predicted) = (Some(before.0), None);
                }
                self.predict(t, root(before, point));
            }
            Some(_) => (self.falling_since, self.predicted) = (None, None),
            None => (self.fell, self.falling_since, self.predicted) = (None, None, None),
        }
        self.last = sigma.is_finite().then_some(point);
        if sigma >= NEAR_PASSIVE_SINGULAR {
            self.points.clear();
            return None;
        }
        if self.points.is_empty() {
            self.entered = t;
        }
        if self.points.len() > 2 * FOLD_SPAN {
            self.points.pop_front();
        }
        self.points.push_back((t, sigma * sigma));
        if self.points.len() <= 2 * FOLD_SPAN {
            return None;
        }
        let (first, mid, last) = (self.points[0], self.points[FOLD_SPAN], self.points[2 * FOLD_SPAN]);
        let (before, now) = (root(first, mid)?, root(mid, last)?);
        let fixed = (now - before).abs() < FOLD_DRIFT * (last.0 - mid.0);
        (fixed && h < FOLD_ADVANCE * (now - t) && now - t < t - self.entered).then_some(now)
    }

    /// The fold a run that failed at t, after a step of h, was running into: the last secant
    /// of sigma^2 that fell, ending within [`FOLD_REACH`] steps of h before t, reaches 0
    /// within as many after t, or within [`FOLD_AHEAD`] of h where it ends at t. A fixed step
    /// (no error control) can pass the fold: the measures of the points it accepts past it rise
    /// again, or are not taken. Or the steps
    /// stalled before it: the measure fell at every point up to t, h is below [`FOLD_STALL`] of
    /// the time left, that is shorter than the time it has been falling, and the fold predicted
    /// earlier in the fall is the same (within [`FOLD_DRIFT`] of the time since): a pass-by's
    /// secants reach 0 ahead of its closest approach too, at a t* that moves on with t. A step that fails for another reason near the fold
    /// (the friction efforts' fixed point, which J's near-singularity makes stiff) shrinks the
    /// steps to nothing there: five-bar-robot, cranks at +1 / -1 rad/s, failed 1.7e-5 s before
    /// its fold after steps of 4e-12 s, at a measure of 1.5e-3.
    pub fn ahead(&self, t: f64, h: f64) -> Option<f64> {
        let [before, last] = self.fell?;
        let t_star = root(before, last)?;
        let ahead = if last.0 < t { FOLD_REACH } else { FOLD_AHEAD };
        let reach = t - last.0 <= FOLD_REACH * h && t_star < t + ahead * h;
        let fixed = self.predicted.is_some_and(|[(t0, t0_star), _]| (t_star - t0_star).abs() < FOLD_DRIFT * (t - t0));
        let stalled = self
            .falling_since
            .is_some_and(|since| last.0 == t && h < FOLD_STALL * (t_star - t) && t_star - t < t - since && fixed);
        (reach || stalled).then_some(t_star)
    }

    /// Keep the fold `t_star` predicted at t (falling): the newer prediction once half the
    /// time left has passed since it, the one it replaces the older.
    fn predict(&mut self, t: f64, t_star: Option<f64>) {
        let Some(t_star) = t_star else { return };
        self.predicted = match self.predicted {
            None => Some([(t, t_star); 2]),
            Some([_, newer]) if t - newer.0 >= 0.5 * (t_star - t) => Some([newer, (t, t_star)]),
            kept => kept,
        };
    }
}

/// Where the line through two points (t, sigma^2) reaches 0, if it falls.
fn root((t0, s0): (f64, f64), (t1, s1): (f64, f64)) -> Option<f64> {
    (s1 < s0).then(|| t1 + s1 * (t1 - t0) / (s0 - s1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::charts::SWITCH_TO_PARTITION;

    /// The 3-RRR's fold (tests/test_prescribed_fold.py): sigma^2 = K (T_STAR - t).
    const K: f64 = 0.0112;
    const T_STAR: f64 = 0.1107510027;

    #[test]
    fn a_run_that_stalls_before_the_fold_is_stopped_there() {
        // Steps of 0.2 of the time left from where the measure falls below the threshold,
        // then steps of 2e-13 s 5e-10 s before T_STAR (the repro's stall).
        let mut watch = FoldWatch::default();
        let mut t = T_STAR - 0.99 * NEAR_PASSIVE_SINGULAR.powi(2) / K;
        let mut stop = None;
        for k in 0..200 {
            let h = if T_STAR - t > 5e-10 { 0.2 * (T_STAR - t) } else { 2e-13 };
            t += h;
            stop = watch.zeno(t, (K * (T_STAR - t)).sqrt(), h);
            if stop.is_some() {
                assert!(k > 10, "stopped after {k} steps at {t}");
                break;
            }
        }
        let t_star = stop.expect("a stop at the fold");
        assert!((t_star - T_STAR).abs() < 1e-12, "{t_star}");
    }

    #[test]
    fn a_run_that_fails_in_tiny_steps_before_the_fold_names_it() {
        // five-bar-robot, cranks at +1 / -1 rad/s (fold at 0.4478739031 s, k = 0.126 / s):
        // steps of 0.2 of the time left from 0.3 s, then the friction efforts stop settling
        // 1.7e-5 s before the fold, and the steps shrink to 4e-12 s (DOP853 rtol 1e-9).
        const KR: f64 = 0.126;
        const TR: f64 = 0.4478739031;
        let mut watch = FoldWatch::default();
        let mut t = 0.3;
        while TR - t > 1.7e-5 {
            let h = (0.2 * (TR - t)).min(1e-3);
            t += h;
            assert_eq!(watch.zeno(t, (KR * (TR - t)).sqrt(), h), None, "{t}");
        }
        let h = 4e-12;
        for _ in 0..3 {
            t += h;
            watch.zeno(t, (KR * (TR - t)).sqrt(), h);
        }
        let t_star = watch.ahead(t, h).expect("the fold named");
        assert!((t_star - TR).abs() < 1e-9, "{t_star}");
        // Not when the measure stopped falling (a pass-by's closest approach).
        watch.zeno(t + h, (KR * (TR - t)).sqrt(), h);
        assert_eq!(watch.ahead(t + h, h), None);
    }

    #[test]
    fn a_pass_by_at_ordinary_steps_is_not_a_fold() {
        // A pass-by 1e-4 s from the fold, K (1e-4 + C (t - tm)^2), at steps of 0.02 s (DOP853 at
        // rtol 1e-5 on the 3-RRR's takes such steps, s20-review's sweep): the secant from
        // tm - 0.076 to tm - 0.056 s reaches 0 1.2 steps ahead. On main a step failing there
        // named that a fold (FOLD_REACH alone).
        const C: f64 = 11.1;
        let (d, tm, h) = (1e-4, T_STAR, 0.02);
        let sigma = |t: f64| (K * (d + C * (t - tm) * (t - tm))).sqrt();
        let mut watch = FoldWatch::default();
        let mut t = tm - 0.096;
        for _ in 0..3 {
            assert!(sigma(t) < SWITCH_TO_PARTITION && sigma(t) > NEAR_PASSIVE_SINGULAR, "{t}");
            assert_eq!(watch.zeno(t, sigma(t), h), None);
            t += h;
        }
        let t = t - h;
        let t_star = root((t - h, sigma(t - h).powi(2)), (t, sigma(t).powi(2))).unwrap();
        assert!(t_star - t > FOLD_AHEAD * h && t_star - t < FOLD_REACH * h, "{}", (t_star - t) / h);
        assert_eq!(watch.ahead(t, h), None);
    }

    #[test]
    fn a_fixed_step_that_fails_just_before_the_fold_names_it() {
        // Steps of 1e-3 s on K (T_STAR - t) up to 2e-4 s before it (0.2 of a step: the largest
        // measured, rk4 at dt 5e-4 into the 3-RRR's fold), where the next step fails.
        let h = 1e-3;
        let mut watch = FoldWatch::default();
        for k in (0..6).rev() {
            let t = T_STAR - 2e-4 - k as f64 * h;
            watch.zeno(t, (K * (T_STAR - t)).sqrt(), h);
        }
        let t_star = watch.ahead(T_STAR - 2e-4, h).expect("the fold named");
        assert!((t_star - T_STAR).abs() < 1e-12, "{t_star}");
    }

    #[test]
    fn a_pass_by_ground_to_tiny_steps_is_not_a_fold() {
        // A pass-by 1e-7 s from the fold, K (1e-7 + C (t - tm)^2) (C from the motion's turn),
        // below the threshold from 2.8e-3 s before its closest approach at tm; then steps of
        // 4e-11 s at 4.3e-7 s before tm (DOP853 at rtol 1e-12 on it). Over a few steps the
        // measure's square is linear to rounding: its secants agree on a t* 0.0104 s ahead.
        const C: f64 = 11.1;
        let (d, tm) = (1e-7, T_STAR);
        let sigma = |t: f64| (K * (d + C * (t - tm) * (t - tm))).sqrt();
        let mut watch = FoldWatch::default();
        let t_in = tm - 2.8e-3;
        assert!(sigma(t_in) < NEAR_PASSIVE_SINGULAR);
        assert_eq!(watch.zeno(t_in, sigma(t_in), 1e-4), None);
        let (t0, h) = (tm - 4.3e-7, 4e-11);
        let slope = 2.0 * K * C * (t0 - tm);
        for k in 0..20 {
            let t = t0 + k as f64 * h;
            let s2 = sigma(t0).powi(2) + slope * (t - t0);
            assert_eq!(watch.zeno(t, s2.sqrt(), h), None, "step {k} at {t}");
        }
    }

    #[test]
    fn a_pass_by_that_stalls_before_its_closest_approach_is_not_named_a_fold() {
        // A pass-by 1e-4 s from the fold, K (1e-4 + C (t - tm)^2), falling from tm - 0.11 s (the
        // sweep's law from t = 0): its measure stays above the threshold (1.06e-3 at tm), where
        // a failed run's fold is named, and its secants reach 0 ahead of tm. On main a step
        // failing on it named a fold: after ordinary steps of 1e-5 s 1.5e-3 s before tm (2.7e-3
        // of the time left to the secant's root; DOPRI5 at rtol 1e-12 in s19-review's sweep),
        // and after steps stalled to 4e-12 s 5e-5 s before tm (its root 0.09 s ahead; RADAU5 at
        // rtol 1e-12 stalled to 4.6e-5 of the time left).
        const C: f64 = 11.1;
        let (d, tm) = (1e-4, T_STAR);
        let sigma = |t: f64| (K * (d + C * (t - tm) * (t - tm))).sqrt();
        let mut watch = FoldWatch::default();
        let (mut t, h) = (tm - 0.11, 1e-5);
        let step = |watch: &mut FoldWatch, t: &mut f64, h: f64| {
            *t += h;
            watch.zeno(*t, sigma(*t), h);
        };
        while t < tm - 1.5e-3 {
            step(&mut watch, &mut t, h);
        }
        assert_eq!(watch.ahead(t, h), None, "ordinary steps at {t}");
        while t < tm - 5e-5 {
            step(&mut watch, &mut t, h);
        }
        for _ in 0..3 {
            step(&mut watch, &mut t, 4e-12);
        }
        assert!(sigma(t) > NEAR_PASSIVE_SINGULAR);
        assert_eq!(watch.ahead(t, 4e-12), None, "stalled steps at {t}");
    }
}
