//! Pieces shared by the integrators: the state common to all of them ([`Core`]),
//! Hairer's error norm, the automatic initial step, the step-size controller and
//! the step loop of the explicit embedded pairs (Dopri5, Dop853).
//!
//! Reference: E. Hairer, S. P. Nørsett, G. Wanner, *Solving ODE I*, 2nd ed.,
//! II.4 ("Automatic step size control", "Starting step size"); scipy
//! `integrate/_ivp/common.py` (`norm`, `select_initial_step`) and `rk.py`
//! (`RungeKutta._step_impl`), whose constants are used here.

use super::{OdeSystem, Options, Stats, StepError};

/// Safety factor of the step-size controller.
pub(crate) const SAFETY: f64 = 0.9;
/// Smallest factor by which a rejected step is shrunk by the error control.
pub(crate) const MIN_FACTOR: f64 = 0.2;
/// Largest factor by which an accepted step may grow.
pub(crate) const MAX_FACTOR: f64 = 10.0;
/// Factor by which the step is shrunk after a failed `rhs` or a NaN/inf.
pub(crate) const FAIL_FACTOR: f64 = 0.25;

/// How far past `t_stop` an adaptive step may reach, as a fraction of h, and still be cut
/// to land on it: stretching by 1 % is cheaper than a sliver of a last step.
const ADAPTIVE_STRETCH: f64 = 0.01;
/// The same for a fixed step: only the round-off of summing dt (steps of 1e-10 dt or less
/// would be noise).
const FIXED_STRETCH: f64 = 1e-10;

/// The stretch allowed to land on `t_stop` with the fixed step `dt` (None: adaptive).
pub(crate) fn stretch(dt: Option<f64>) -> f64 {
    if dt.is_some() {
        FIXED_STRETCH
    } else {
        ADAPTIVE_STRETCH
    }
}

// The starting-step rule of HNW I, II.4 (scipy's `select_initial_step`), with its constants.
/// Scaled norms of y or f below this count as zero: no scale to take h0 from.
const START_NORM_FLOOR: f64 = 1e-5;
/// The first guess h0 when y or f is (nearly) zero.
const START_H_FALLBACK: f64 = 1e-6;
/// Scaled derivative norms below this count as zero: the second guess is not from them.
const START_DERIVATIVE_FLOOR: f64 = 1e-15;
/// The second guess from h0 when both derivatives are (nearly) zero: h0 * 1e-3, at least 1e-6.
const START_H_SHRINK: f64 = 1e-3;

/// Why a trial step was rejected without an error estimate.
pub(crate) enum Failure<E> {
    /// `rhs` returned an error.
    Rhs(E),
    /// NaN or infinity in a stage or in the new state.
    NonFinite,
    /// Radau5: the simplified Newton iteration did not converge.
    Newton,
}

impl<E> Failure<E> {
    /// The error to return when the step cannot shrink any more.
    pub(crate) fn into_error(self, t: f64, h: f64) -> StepError<E> {
        match self {
            Failure::Rhs(error) => StepError::Rhs { t, error },
            Failure::NonFinite => StepError::NonFinite { t },
            Failure::Newton => StepError::StepSizeUnderflow { t, h },
        }
    }
}

/// State that every stepper keeps: the current and previous point, the
/// derivative at both, the proposed next step and the counters.
pub(crate) struct Core {
    pub(crate) opts: Options,
    pub(crate) n: usize,
    /// Current time (s) and the start of the last accepted step.
    pub(crate) t: f64,
    pub(crate) t_prev: f64,
    /// State and derivative at `t` and at `t_prev` (length `n`).
    pub(crate) y: Vec<f64>,
    pub(crate) f: Vec<f64>,
    pub(crate) y_prev: Vec<f64>,
    pub(crate) f_prev: Vec<f64>,
    /// Next trial step (s); 0 after `reset` (then chosen on the first step).
    pub(crate) h_next: f64,
    /// Error norm of the last accepted step (the PI controller's memory; 1 after `reset`).
    pub(crate) err_prev: f64,
    /// (h, error norm) of the last two accepted steps of an explicit pair since `reset`, the
    /// newer first, and that pair's error order: the error's trend that
    /// [`Core::predict_next_step`] extrapolates.
    pub(crate) accepted: [Option<(f64, f64)>; 2],
    pub(crate) error_order: usize,
    /// Largest automatic first step after `reset` (s): the system's own bound
    /// ([`crate::integrate::Stepper::bound_first_step`]); infinite unless set.
    pub(crate) first_step_max: f64,
    pub(crate) stats: Stats,
    pub(crate) started: bool,
}

impl Core {
    pub(crate) fn new(opts: &Options, n: usize) -> Self {
        Core {
            opts: opts.clone(),
            n,
            t: 0.0,
            t_prev: 0.0,
            y: vec![0.0; n],
            f: vec![0.0; n],
            y_prev: vec![0.0; n],
            f_prev: vec![0.0; n],
            h_next: 0.0,
            err_prev: 1.0,
            accepted: [None; 2],
            error_order: 0,
            first_step_max: f64::INFINITY,
            stats: Stats::default(),
            started: false,
        }
    }

    /// Set the state to (t, y) and evaluate f(t, y).
    pub(crate) fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), StepError<S::Error>> {
        assert_eq!(y.len(), self.n, "Stepper::reset: y has the wrong length");
        self.started = false;
        if !t.is_finite() || !all_finite(y) {
            return Err(StepError::NonFinite { t });
        }
        self.y.copy_from_slice(y);
        self.stats.nfev += 1;
        sys.rhs(t, &self.y, &mut self.f).map_err(|error| StepError::Rhs { t, error })?;
        if !all_finite(&self.f) {
            return Err(StepError::NonFinite { t });
        }
        self.t = t;
        self.t_prev = t;
        self.y_prev.copy_from_slice(&self.y);
        self.f_prev.copy_from_slice(&self.f);
        self.h_next = 0.0;
        self.err_prev = 1.0;
        self.accepted = [None; 2];
        self.first_step_max = f64::INFINITY;
        self.started = true;
        Ok(())
    }

    /// Bound the next trial step by `h_max` (see `Stepper::bound_next_step`).
    pub(crate) fn bound_next_step(&mut self, h_max: f64) {
        if self.opts.dt.is_some() {
            return;
        }
        if self.h_next > 0.0 {
            self.h_next = self.h_next.min(h_max);
        } else {
            self.first_step_max = self.first_step_max.min(h_max);
        }
    }

    /// Bound the next trial step by the error's trend over the last two accepted steps
    /// (see `Stepper::predict_next_step`): Gustafsson's predictive controller, as Hairer's
    /// RADAU5 takes it, the smaller of its step and the controller's.
    pub(crate) fn predict_next_step(&mut self) {
        let [Some((h1, e1)), Some((h0, e0))] = self.accepted else { return };
        if self.opts.dt.is_some() || self.h_next <= 0.0 {
            return;
        }
        let k = self.error_order as f64 + 1.0;
        let (e1, e0) = (e1.max(ERR_FLOOR), e0.max(ERR_FLOOR));
        let factor = (SAFETY * (h1 / h0) * (e0 / (e1 * e1)).powf(1.0 / k)).clamp(MIN_FACTOR, MAX_FACTOR);
        self.h_next = self.h_next.min(h1 * factor);
    }

    /// Evaluate `rhs`, counting it, and map an error to a [`Failure`].
    pub(crate) fn eval<S: OdeSystem>(
        stats: &mut Stats,
        sys: &mut S,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
    ) -> Result<(), Failure<S::Error>> {
        stats.nfev += 1;
        finite(sys.rhs(t, y, dy), dy)
    }

    /// As [`Core::eval`], through [`OdeSystem::rhs_dense`].
    pub(crate) fn eval_dense<S: OdeSystem>(
        stats: &mut Stats,
        sys: &mut S,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
    ) -> Result<(), Failure<S::Error>> {
        stats.nfev += 1;
        finite(sys.rhs_dense(t, y, dy), dy)
    }

    /// Smallest allowed trial step at the current time (s), see [`Options::h_min`].
    pub(crate) fn h_min(&self) -> f64 {
        let ulp = (self.t.abs() * f64::EPSILON).max(f64::MIN_POSITIVE);
        (self.opts.h_min * self.t.abs().max(1.0)).max(10.0 * ulp)
    }

    /// Err when the attempt budget is used up.
    pub(crate) fn check_budget<E>(&self) -> Result<(), StepError<E>> {
        let steps = self.stats.naccept + self.stats.nreject;
        if steps >= self.opts.max_steps {
            Err(StepError::TooManySteps { t: self.t, steps })
        } else {
            Ok(())
        }
    }

    /// Clip a trial step `h` to `h_max` and to end exactly on `t_stop`; returns
    /// `(h, t_new)`. A step within `stretch` (relative) of `t_stop`, or leaving
    /// less than `h_min` before it, is stretched to land on it, as in Hairer's
    /// codes (1 % for adaptive steps).
    pub(crate) fn clip(&self, h: f64, t_stop: f64, stretch: f64) -> (f64, f64) {
        let h = h.min(self.opts.h_max);
        let t = self.t;
        if t + h * (1.0 + stretch) >= t_stop || t_stop - (t + h) < self.h_min() {
            (t_stop - t, t_stop)
        } else {
            (h, t + h)
        }
    }

    /// The next trial: checks the attempt budget, clips `h` (see [`Core::clip`])
    /// and, after a rejection, ends with an error when the step fell below
    /// `h_min` (reporting the last failure). A first try that is tiny only
    /// because `t_stop` is close is allowed.
    pub(crate) fn next_try<E>(
        &self,
        h: f64,
        t_stop: f64,
        stretch: f64,
        rejected: bool,
        last_failure: &mut Option<Failure<E>>,
    ) -> Result<(f64, f64), StepError<E>> {
        self.check_budget()?;
        let (h_try, t_new) = self.clip(h, t_stop, stretch);
        if rejected && h_try < self.h_min() {
            let t = self.t;
            return Err(match last_failure.take() {
                Some(failure) => failure.into_error(t, h_try),
                None => StepError::StepSizeUnderflow { t, h: h_try },
            });
        }
        Ok((h_try, t_new))
    }

    /// Proposal for the step after an accepted step `h_try` grown by `factor`.
    /// A step cut short to land on `t_stop` does not shrink the step `h_planned`
    /// it was cut from, so that stopping at many close `t_stop` stays cheap.
    pub(crate) fn propose(&self, h_try: f64, factor: f64, h_planned: f64, t_stop: f64) -> f64 {
        let h = h_try * factor;
        if self.t == t_stop {
            h.max(h_planned.min(self.opts.h_max))
        } else {
            h
        }
    }

    /// Make (t_new, y_new, f_new) the current point; the old one becomes the
    /// previous point. Buffers are swapped, not copied: `y_new`/`f_new` receive
    /// the stale previous-point buffers.
    pub(crate) fn accept(&mut self, t_new: f64, y_new: &mut Vec<f64>, f_new: &mut Vec<f64>) {
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.y, y_new);
        std::mem::swap(&mut self.f_prev, &mut self.f);
        std::mem::swap(&mut self.f, f_new);
        self.t_prev = self.t;
        self.t = t_new;
        self.stats.naccept += 1;
    }

    /// Panic with a clear message when `step` is called before `reset`.
    pub(crate) fn assert_started(&self) {
        assert!(self.started, "Stepper::step called before a successful Stepper::reset");
    }
}

/// An evaluation's outcome, NaN or infinity in `dy` counting as a failure.
fn finite<E>(outcome: Result<(), E>, dy: &[f64]) -> Result<(), Failure<E>> {
    outcome.map_err(Failure::Rhs)?;
    if all_finite(dy) {
        Ok(())
    } else {
        Err(Failure::NonFinite)
    }
}

/// Whether every entry is finite. A mechanism's state of 3, 5 or 7 coordinates (see
/// [`weighted_sum`]) is tested whole, without a branch per entry: every stage's derivative is
/// tested (`Core::eval`), and the loop that stops at the first non-finite entry cost the
/// four-bar's DOP853 stage 31 instructions for its 3, the fixed-size test 12.
pub(crate) fn all_finite(v: &[f64]) -> bool {
    match v.len() {
        3 => all_finite_fixed::<3>(v),
        5 => all_finite_fixed::<5>(v),
        7 => all_finite_fixed::<7>(v),
        _ => v.iter().all(|x| x.is_finite()),
    }
}

/// [`all_finite`] for `v.len() == N`: `0 x` is a zero for a finite x and NaN for an infinite
/// or NaN one, and their sum is a zero exactly when every term is.
fn all_finite_fixed<const N: usize>(v: &[f64]) -> bool {
    v.as_chunks::<N>().0[0].iter().fold(0.0, |s, x| s + 0.0 * x) == 0.0
}

/// `out_i = sum_j w_j K_ji` over the stages `K_j` (the rows of `k`, each `out.len()` long)
/// whose weight is not zero, added in j's order from -0.0 as `Iterator::sum` does: the tableau
/// row's sum as written, bit for bit (a zero weight adds nothing, and the stages are finite), at
/// the cost of its nonzero weights only (DOP853's rows are a quarter zeros). Each weight scales
/// a whole row, with no bounds checks; a mechanism's state of 3, 5 or 7 coordinates (`2 m + 1`
/// for 1 to 3 degrees of freedom, the last its work) gets a fixed-size path, unrolled, whose
/// sums stay in registers. Hand-written: a BLAS `gemv` would neither keep the order of the sum
/// nor skip the zeros, and its call costs more than the whole sum for so small a state.
/// Inlined, with [`combine`]: where the weights are a constant row (DOP853's stages,
/// `Dop853::stage_at`) the zero ones are dropped at compile time. `k` holds at least `w.len()`
/// rows.
#[inline(always)]
pub(crate) fn weighted_sum(out: &mut [f64], w: &[f64], k: &[f64]) {
    match out.len() {
        0 => {}
        3 => weighted_sum_fixed::<3>(out, w, k),
        5 => weighted_sum_fixed::<5>(out, w, k),
        7 => weighted_sum_fixed::<7>(out, w, k),
        n => {
            out.fill(-0.0);
            for (&wj, kj) in w.iter().zip(k.chunks_exact(n)) {
                if wj != 0.0 {
                    out.iter_mut().zip(kj).for_each(|(o, x)| *o += wj * x);
                }
            }
        }
    }
}

/// [`weighted_sum`] for `out.len() == N`. The rows taken are `w.len()`, a constant where the
/// weights are: the loop is then unrolled (zipped with all of `k`'s rows, its length was not
/// known and it was not).
#[inline(always)]
fn weighted_sum_fixed<const N: usize>(out: &mut [f64], w: &[f64], k: &[f64]) {
    let mut acc = [-0.0; N];
    for (&wj, kj) in w.iter().zip(&k.as_chunks::<N>().0[..w.len()]) {
        if wj != 0.0 {
            acc.iter_mut().zip(kj).for_each(|(a, x)| *a += wj * x);
        }
    }
    out.copy_from_slice(&acc);
}

/// `out_i = h sum_j w_j K_ji`, the sum as [`weighted_sum`]'s.
pub(crate) fn scaled_sum(out: &mut [f64], h: f64, w: &[f64], k: &[f64]) {
    weighted_sum(out, w, k);
    out.iter_mut().for_each(|o| *o *= h);
}

/// `out_i = y_i + h sum_j w_j K_ji`, the sum as [`weighted_sum`]'s.
#[inline(always)]
pub(crate) fn combine(out: &mut [f64], y: &[f64], h: f64, w: &[f64], k: &[f64]) {
    weighted_sum(out, w, k);
    out.iter_mut().zip(y).for_each(|(o, yi)| *o = yi + h * *o);
}

/// Hairer's RMS norm of `err` scaled by `sc_i = atol + rtol * max(|y_i|, |ynew_i|)`.
pub(crate) fn error_norm(err: &[f64], y: &[f64], y_new: &[f64], opts: &Options) -> f64 {
    let n = err.len().max(1) as f64;
    let sum: f64 = err
        .iter()
        .zip(y.iter().zip(y_new))
        .map(|(e, (a, b))| {
            let sc = opts.atol + opts.rtol * a.abs().max(b.abs());
            (e / sc).powi(2)
        })
        .sum();
    (sum / n).sqrt()
}

/// RMS norm of `v_i / (atol + rtol |y_i|)`.
fn scaled_norm(v: &[f64], y: &[f64], opts: &Options) -> f64 {
    error_norm(v, y, y, opts)
}

/// Hairer's automatic initial step (HNW I, II.4, p. 169; scipy `select_initial_step`)
/// for a method whose error estimate is of order `order`, bounded by `t_stop - t`,
/// `h_max` and the system's own bound (`Core::first_step_max`). Uses `y1`, `f1` as scratch and one `rhs` evaluation; if that
/// evaluation fails, the first guess `h0` is returned.
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_step<S: OdeSystem>(
    sys: &mut S,
    core: &mut Core,
    t_stop: f64,
    order: usize,
    y1: &mut [f64],
    f1: &mut [f64],
) -> f64 {
    let (t, opts) = (core.t, &core.opts);
    let cap = (t_stop - t).max(0.0).min(opts.h_max).min(core.first_step_max);
    if core.n == 0 {
        return cap;
    }
    let d0 = scaled_norm(&core.y, &core.y, opts);
    let d1 = scaled_norm(&core.f, &core.y, opts);
    let h0 = if d0 < START_NORM_FLOOR || d1 < START_NORM_FLOOR { START_H_FALLBACK } else { 0.01 * d0 / d1 };
    let h0 = h0.min(cap);
    for i in 0..core.n {
        y1[i] = core.y[i] + h0 * core.f[i];
    }
    core.stats.nfev += 1;
    if sys.rhs(t + h0, y1, f1).is_err() || !all_finite(f1) {
        return h0;
    }
    for i in 0..core.n {
        f1[i] -= core.f[i];
    }
    let d2 = scaled_norm(f1, &core.y, opts) / h0;
    let h1 = if d1 <= START_DERIVATIVE_FLOOR && d2 <= START_DERIVATIVE_FLOOR {
        (h0 * START_H_SHRINK).max(START_H_FALLBACK)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / (order as f64 + 1.0))
    };
    (100.0 * h0).min(h1).min(cap)
}

/// Step factor after an accepted step with error norm `err <= 1`, from a PI controller
/// (Gustafsson; HNW II, IV.2, eq. 2.43c; Söderlind's PI.4.2):
/// `SAFETY * err^(-0.7/k) * err_prev^(0.4/k)` with k = q + 1, bounded by [`MAX_FACTOR`] and
/// not above 1 right after a rejection. Compared with the elementary `err^(-1/k)` it damps the
/// step-size oscillations that make every third or fourth step fail where the motion speeds
/// up and slows down (a swinging four-bar: DOP853 rejections 25 % -> under 10 %).
pub(crate) fn factor_accept(err: f64, err_prev: f64, error_order: usize, after_reject: bool) -> f64 {
    let k = error_order as f64 + 1.0;
    let mut factor = if err == 0.0 {
        MAX_FACTOR
    } else {
        (SAFETY * err.powf(-0.7 / k) * err_prev.max(ERR_FLOOR).powf(0.4 / k)).min(MAX_FACTOR)
    };
    if after_reject {
        factor = factor.min(1.0);
    }
    factor
}

/// Smallest error norm the PI controller remembers, so that one very accurate step does not
/// hold the next one back (Hairer's DOPRI5 uses 1e-4 the same way).
const ERR_FLOOR: f64 = 1e-4;

/// Step factor after a rejected step with error norm `err > 1`.
pub(crate) fn factor_reject(err: f64, error_order: usize) -> f64 {
    (SAFETY * err.powf(-1.0 / (error_order as f64 + 1.0))).max(MIN_FACTOR)
}

/// An explicit embedded Runge-Kutta pair, driven by [`explicit_step`].
pub(crate) trait ExplicitPair {
    /// Order of the error estimate (the exponent is `-1/(ERROR_ORDER + 1)`).
    const ERROR_ORDER: usize;
    fn core(&mut self) -> &mut Core;
    /// Scratch vectors of length `n` for the initial-step selection.
    fn scratch(&mut self) -> (&mut Core, &mut [f64], &mut [f64]);
    /// Try a step of size `h` from the current point: fill the new state and
    /// derivative and return the error norm.
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> Result<f64, Failure<S::Error>>;
    /// Accept the tried step, ending at `t_new` (dense output, then `Core::accept`).
    fn accept<S: OdeSystem>(&mut self, sys: &mut S, t_new: f64);
}

/// One accepted step of an explicit pair: retry with smaller steps after an
/// error estimate above 1 (factor from the controller), an `rhs` failure or a
/// NaN ([`FAIL_FACTOR`]), until accepted or below `h_min`. With `Options::dt`
/// the error estimate is ignored and the step is `dt`.
pub(crate) fn explicit_step<P: ExplicitPair, S: OdeSystem>(
    p: &mut P,
    sys: &mut S,
    t_stop: f64,
) -> Result<(), StepError<S::Error>> {
    let core = p.core();
    core.assert_started();
    if t_stop.is_nan() || t_stop <= core.t {
        return Ok(());
    }
    let fixed = core.opts.dt;
    let mut h = match fixed {
        Some(dt) => dt,
        None if core.h_next > 0.0 => core.h_next,
        None => match core.opts.h0 {
            Some(h0) => h0,
            None => {
                let (core, y1, f1) = p.scratch();
                initial_step(sys, core, t_stop, P::ERROR_ORDER, y1, f1)
            }
        },
    };
    let stretch = stretch(fixed);
    let mut rejected = false;
    let mut last_failure: Option<Failure<S::Error>> = None;
    loop {
        let (h_try, t_new) = p.core().next_try(h, t_stop, stretch, rejected, &mut last_failure)?;
        match p.attempt(sys, h_try) {
            Ok(err) if fixed.is_some() || err <= 1.0 => {
                p.accept(sys, t_new);
                let core = p.core();
                core.h_next = match fixed {
                    Some(dt) => dt,
                    None => {
                        let factor = factor_accept(err, core.err_prev, P::ERROR_ORDER, rejected);
                        core.err_prev = err;
                        core.accepted = [Some((h_try, err)), core.accepted[0]];
                        core.error_order = P::ERROR_ORDER;
                        core.propose(h_try, factor, h, t_stop)
                    }
                };
                return Ok(());
            }
            Ok(err) => {
                // NaN error norm counts as non-finite.
                h = if err.is_finite() {
                    last_failure = None;
                    h_try * factor_reject(err, P::ERROR_ORDER)
                } else {
                    last_failure = Some(Failure::NonFinite);
                    h_try * FAIL_FACTOR
                };
            }
            Err(failure) => {
                last_failure = Some(failure);
                h = h_try * FAIL_FACTOR;
            }
        }
        rejected = true;
        p.core().stats.nreject += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::all_finite;

    /// The fixed-size test (3, 5, 7 entries) and the general one (any other length) refuse a
    /// NaN or an infinity of either sign at every position, and accept finite values at the
    /// ends of the range (the largest, a subnormal, both zeros), where `0 x` must stay a zero.
    #[test]
    fn all_finite_refuses_each_non_finite_entry_at_every_length() {
        let finite = [f64::MAX, -f64::MAX, 5e-324, -0.0, 0.0, 1.0, -3.5, f64::MIN_POSITIVE];
        for n in 1..=8 {
            let v: Vec<f64> = finite[..n].to_vec();
            assert!(all_finite(&v), "n = {n}: {v:?}");
            for i in 0..n {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut w = v.clone();
                    w[i] = bad;
                    assert!(!all_finite(&w), "n = {n}, {bad} at {i}");
                }
            }
        }
        assert!(all_finite(&[]));
    }
}
