//! Radau IIA of order 5 (3 stages): implicit, L-stable, for stiff systems
//! (stiff springs and dampers in a mechanism).
//!
//! References: E. Hairer, G. Wanner, *Solving ODE II*, 2nd ed., IV.8 and
//! Hairer's code RADAU5; the structure (Newton, error estimate, step control,
//! dense output) follows scipy's `integrate/_ivp/radau.py`, whose constants are
//! used here.
//!
//! Tableau (`c = ((4 - √6)/10, (4 + √6)/10, 1)`, collocation at the Radau
//! points), order 5 at the step ends, stage order 3:
//!
//! ```text
//! (4-√6)/10 | (88-7√6)/360     (296-169√6)/1800  (-2+3√6)/225
//! (4+√6)/10 | (296+169√6)/1800 (88+7√6)/360      (-2-3√6)/225
//!     1     | (16-√6)/36       (16+√6)/36        1/9
//! ```
//!
//! * **Newton**: simplified Newton on the stage increments `Z`, decoupled by
//!   the eigen-decomposition `A⁻¹ = T Λ T⁻¹` into one real `n x n` system
//!   `(μ_r/h I - J)` and one complex one `(μ_c/h I - J)` (HW II, IV.8,
//!   (8.15)-(8.18)); at most 6 iterations, stopped early when the contraction
//!   rate predicts failure. Tolerance `max(10 eps/rtol, min(0.03, √rtol))`.
//! * **Jacobian**: the system's exact one ([`OdeSystem::jacobian`]) where it has
//!   one; else forward differences of `rhs`, column `j` perturbed by
//!   `δ_j = sqrt(eps max(1e-5, |y_j|))` (RADAU5's choice), `n` `rhs` calls. It
//!   is kept across steps and only recomputed when Newton converges slowly
//!   (more than 2 iterations and rate > 1e-3) or fails with a stale one. If a
//!   perturbed evaluation fails, the backward difference is tried.
//! * **Error**: `err = (μ_r/h I - J)⁻¹ (f(t,y) + Zᵀ E / h)` (HW II, IV.8,
//!   (8.19)-(8.20)), stabilised by one more solve after a rejection.
//! * **Step control**: Gustafsson's predictive controller, exponent `-1/4`,
//!   safety `0.9 (2·6+1)/(2·6+n_iter)`, factor in `[0.2, 10]`, step kept when
//!   the factor is below 1.2 (saves LU decompositions). A failed `rhs` or a
//!   NaN shrinks the step by 0.25, a Newton failure with a fresh Jacobian by 0.5.
//! * **Dense output**: the collocation cubic through the stages,
//!   `y(t_prev + s h) = y_prev + Σ_k Q_k s^k`, `k = 1..3` (order 3); it also
//!   gives the Newton starting guess for the next step.
//!
//! With `Options::dt`, the error test is skipped (steps of `dt`), which is used
//! to measure the order.

// T and TI keep the 17 digits of scipy's table.
#![allow(clippy::excessive_precision)]

use super::control::{all_finite, initial_step, stretch, Core, Failure, FAIL_FACTOR, MAX_FACTOR, MIN_FACTOR};
use super::{Integrator, OdeSystem, Options, StepError};
use crate::linalg::{lu_factor, lu_solve, LuError};
use nalgebra::Complex;

type C64 = Complex<f64>;

/// Newton iterations allowed per step.
const NEWTON_MAXITER: usize = 6;
/// Floor of |y_j| in the finite-difference increment sqrt(eps * max(|y_j|, floor)) (RADAU5's
/// DELT): a component near 0 still gets an increment well above round-off.
const FD_SCALE_FLOOR: f64 = 1e-5;
/// Newton contraction rate above which the Jacobian is refreshed after an accepted step
/// (RADAU5's THET; scipy's rule): a slower Newton means a stale J.
const JAC_REUSE_RATE: f64 = 1e-3;

/// The transformed tableau: scipy's `radau.py` constants.
struct Tableau {
    c: [f64; 3],
    e: [f64; 3],
    mu_real: f64,
    mu_complex: C64,
    t: [[f64; 3]; 3],
    ti: [[f64; 3]; 3],
    p: [[f64; 3]; 3],
}

impl Tableau {
    fn new() -> Self {
        let s6 = 6f64.sqrt();
        let cbrt3 = 3f64.cbrt();
        Tableau {
            c: [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0],
            e: [(-13.0 - 7.0 * s6) / 3.0, (-13.0 + 7.0 * s6) / 3.0, -1.0 / 3.0],
            mu_real: 3.0 + cbrt3 * cbrt3 - cbrt3,
            mu_complex: Complex::new(
                3.0 + 0.5 * (cbrt3 - cbrt3 * cbrt3),
                -0.5 * (3f64.powf(5.0 / 6.0) + 3f64.powf(7.0 / 6.0)),
            ),
            t: [
                [0.09443876248897524, -0.14125529502095421, 0.03002919410514742],
                [0.25021312296533332, 0.20412935229379994, -0.38294211275726192],
                [1.0, 1.0, 0.0],
            ],
            ti: [
                [4.17871859155190428, 0.32768282076106237, 0.52337644549944951],
                [-4.17871859155190428, -0.32768282076106237, 0.47662355450055044],
                [0.50287263494578682, -2.57192694985560522, 0.59603920482822492],
            ],
            p: [
                [13.0 / 3.0 + 7.0 * s6 / 3.0, -23.0 / 3.0 - 22.0 * s6 / 3.0, 10.0 / 3.0 + 5.0 * s6],
                [13.0 / 3.0 - 7.0 * s6 / 3.0, -23.0 / 3.0 + 22.0 * s6 / 3.0, 10.0 / 3.0 - 5.0 * s6],
                [1.0 / 3.0, -8.0 / 3.0, 10.0 / 3.0],
            ],
        }
    }
}

/// Outcome of a converged Newton solve.
struct Newton {
    iterations: usize,
    rate: f64,
}

/// Radau IIA (order 5) stepper. All buffers allocated in `new`.
pub struct Radau5 {
    pub(crate) core: Core,
    tab: Tableau,
    newton_tol: f64,
    /// Jacobian `∂f/∂y` at some past point, row-major `n x n`.
    jac: Vec<f64>,
    jac_valid: bool,
    /// True when `jac` was evaluated at the current point.
    jac_current: bool,
    lu_real: Vec<f64>,
    piv_real: Vec<usize>,
    lu_complex: Vec<C64>,
    piv_complex: Vec<usize>,
    /// Step size the LU factors were computed for (s); 0 when invalid.
    lu_h: f64,
    /// Stage increments `Z` and transformed `W`, stage-major (`3 x n`); `F` the stage derivatives.
    z: Vec<f64>,
    w: Vec<f64>,
    fz: Vec<f64>,
    b_real: Vec<f64>,
    b_complex: Vec<C64>,
    /// Dense output `Q` of the last accepted step (`3 x n`) and whether it exists.
    q: Vec<f64>,
    have_dense: bool,
    ytmp: Vec<f64>,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
    err: Vec<f64>,
    /// Previous step size and error norm, for the predictive controller.
    h_old: Option<f64>,
    err_old: Option<f64>,
}

impl Integrator for Radau5 {
    const NAME: &'static str = "radau5";
    const ALIASES: &'static [&'static str] = &["radau"];
    const ORDER: usize = 5;
    /// The collocation cubic.
    const DENSE_ORDER: usize = 3;
    const ADAPTIVE: bool = true;
    const IMPLICIT: bool = true;
    const SEES_REACH: bool = false;

    fn new(opts: &Options, n: usize) -> Self {
        let eps = f64::EPSILON;
        Radau5 {
            core: Core::new(opts, n),
            tab: Tableau::new(),
            newton_tol: (10.0 * eps / opts.rtol).max(0.03f64.min(opts.rtol.sqrt())),
            jac: vec![0.0; n * n],
            jac_valid: false,
            jac_current: false,
            lu_real: vec![0.0; n * n],
            piv_real: vec![0; n],
            lu_complex: vec![C64::new(0.0, 0.0); n * n],
            piv_complex: vec![0; n],
            lu_h: 0.0,
            z: vec![0.0; 3 * n],
            w: vec![0.0; 3 * n],
            fz: vec![0.0; 3 * n],
            b_real: vec![0.0; n],
            b_complex: vec![C64::new(0.0, 0.0); n],
            q: vec![0.0; 3 * n],
            have_dense: false,
            ytmp: vec![0.0; n],
            y_new: vec![0.0; n],
            f_new: vec![0.0; n],
            err: vec![0.0; n],
            h_old: None,
            err_old: None,
        }
    }

    /// Collocation-polynomial dense output on the last accepted step.
    fn interpolate<S: OdeSystem>(&mut self, _sys: &mut S, t: f64, out: &mut [f64]) {
        let c = &self.core;
        let h = c.t - c.t_prev;
        let s = if h == 0.0 { 0.0 } else { (t - c.t_prev) / h };
        eval_dense(&self.q, &c.y_prev, s, out);
    }
}

impl Radau5 {
    pub fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), StepError<S::Error>> {
        self.jac_valid = false;
        self.jac_current = false;
        self.lu_h = 0.0;
        self.have_dense = false;
        self.q.fill(0.0);
        self.h_old = None;
        self.err_old = None;
        self.core.reset(sys, t, y)
    }

    /// The Jacobian at the current point: exact, or by forward differences (module doc).
    fn compute_jacobian<S: OdeSystem>(&mut self, sys: &mut S) -> Result<(), S::Error> {
        let n = self.core.n;
        let t = self.core.t;
        self.core.stats.njev += 1;
        if let Some(exact) = sys.jacobian(t, &self.core.y, &mut self.jac) {
            exact?;
            self.jac_valid = true;
            self.jac_current = true;
            self.lu_h = 0.0;
            return Ok(());
        }
        self.ytmp.copy_from_slice(&self.core.y);
        for j in 0..n {
            let yj = self.core.y[j];
            let mut delta = (f64::EPSILON * yj.abs().max(FD_SCALE_FLOOR)).sqrt();
            self.ytmp[j] = yj + delta;
            self.core.stats.nfev += 1;
            if sys.rhs(t, &self.ytmp, &mut self.f_new).is_err() || !all_finite(&self.f_new) {
                delta = -delta;
                self.ytmp[j] = yj + delta;
                self.core.stats.nfev += 1;
                sys.rhs(t, &self.ytmp, &mut self.f_new)?;
            }
            self.ytmp[j] = yj;
            let delta = (yj + delta) - yj; // the step actually represented
            for i in 0..n {
                self.jac[i * n + j] = (self.f_new[i] - self.core.f[i]) / delta;
            }
        }
        self.jac_valid = true;
        self.jac_current = true;
        self.lu_h = 0.0;
        Ok(())
    }

    /// Factor `μ_r/h I - J` and `μ_c/h I - J`.
    fn factorize(&mut self, h: f64) -> Result<(), LuError> {
        let n = self.core.n;
        let (mr, mc) = (self.tab.mu_real / h, self.tab.mu_complex / h);
        for i in 0..n {
            for j in 0..n {
                let d = if i == j { 1.0 } else { 0.0 };
                self.lu_real[i * n + j] = mr * d - self.jac[i * n + j];
                self.lu_complex[i * n + j] = mc * d - self.jac[i * n + j];
            }
        }
        self.core.stats.nlu += 2;
        self.lu_h = 0.0;
        lu_factor(&mut self.lu_real, n, &mut self.piv_real, 0.0)?;
        lu_factor(&mut self.lu_complex, n, &mut self.piv_complex, 0.0)?;
        self.lu_h = h;
        Ok(())
    }

    /// Starting guess for `Z`: the previous collocation polynomial, extrapolated
    /// to `t + c_k h` (zero right after a reset).
    fn predict(&mut self, h: f64) {
        let n = self.core.n;
        if !self.have_dense {
            self.z.fill(0.0);
            return;
        }
        let c = &self.core;
        let h_prev = c.t - c.t_prev;
        for k in 0..3 {
            let s = (c.t + self.tab.c[k] * h - c.t_prev) / h_prev;
            let zk = &mut self.z[k * n..(k + 1) * n];
            eval_dense(&self.q, &c.y_prev, s, zk);
            for (z, y) in zk.iter_mut().zip(&c.y) {
                *z -= y;
            }
        }
    }

    /// Simplified Newton iteration for the collocation system (scipy
    /// `solve_collocation_system`). `Ok(None)`: did not converge.
    fn newton<S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> Result<Option<Newton>, Failure<S::Error>> {
        let n = self.core.n;
        let tab = &self.tab;
        let (mr, mc) = (tab.mu_real / h, tab.mu_complex / h);
        // W = TI Z
        for k in 0..3 {
            for i in 0..n {
                self.w[k * n + i] = (0..3).map(|m| tab.ti[k][m] * self.z[m * n + i]).sum();
            }
        }
        let mut dw_norm_old: Option<f64> = None;
        let mut rate = 0.0;
        for iter in 0..NEWTON_MAXITER {
            for k in 0..3 {
                for i in 0..n {
                    self.ytmp[i] = self.core.y[i] + self.z[k * n + i];
                }
                let fk = &mut self.fz[k * n..(k + 1) * n];
                Core::eval(&mut self.core.stats, sys, self.core.t + tab.c[k] * h, &self.ytmp, fk)?;
            }
            for i in 0..n {
                let f = |k: usize| self.fz[k * n + i];
                let w = |k: usize| self.w[k * n + i];
                let fr: f64 = (0..3).map(|m| tab.ti[0][m] * f(m)).sum();
                let f1: f64 = (0..3).map(|m| tab.ti[1][m] * f(m)).sum();
                let f2: f64 = (0..3).map(|m| tab.ti[2][m] * f(m)).sum();
                self.b_real[i] = fr - mr * w(0);
                self.b_complex[i] = C64::new(f1, f2) - mc * C64::new(w(1), w(2));
            }
            lu_solve(&self.lu_real, n, &self.piv_real, &mut self.b_real);
            lu_solve(&self.lu_complex, n, &self.piv_complex, &mut self.b_complex);
            // dW = (b_real, Re b_complex, Im b_complex); its scaled RMS norm over 3n.
            let mut sum = 0.0;
            for i in 0..n {
                let sc = self.core.opts.atol + self.core.opts.rtol * self.core.y[i].abs();
                let bc = self.b_complex[i];
                sum += (self.b_real[i] / sc).powi(2) + (bc.re / sc).powi(2) + (bc.im / sc).powi(2);
            }
            let dw_norm = (sum / (3 * n).max(1) as f64).sqrt();
            if !dw_norm.is_finite() {
                return Err(Failure::NonFinite);
            }
            if let Some(old) = dw_norm_old {
                rate = dw_norm / old;
                let remaining = (NEWTON_MAXITER - iter) as i32;
                if rate >= 1.0 || rate.powi(remaining) / (1.0 - rate) * dw_norm > self.newton_tol {
                    return Ok(None);
                }
            }
            for i in 0..n {
                self.w[i] += self.b_real[i];
                self.w[n + i] += self.b_complex[i].re;
                self.w[2 * n + i] += self.b_complex[i].im;
            }
            for k in 0..3 {
                for i in 0..n {
                    self.z[k * n + i] = (0..3).map(|m| tab.t[k][m] * self.w[m * n + i]).sum();
                }
            }
            let converged =
                dw_norm == 0.0 || (dw_norm_old.is_some() && rate / (1.0 - rate) * dw_norm < self.newton_tol);
            if converged {
                return Ok(Some(Newton { iterations: iter + 1, rate }));
            }
            dw_norm_old = Some(dw_norm);
        }
        Ok(None)
    }

    /// Local error estimate of the step `h` (whose `Z` and `y_new` are computed);
    /// stabilised by one more `rhs` call and solve when `stabilise`.
    fn error_estimate<S: OdeSystem>(&mut self, sys: &mut S, h: f64, stabilise: bool) -> f64 {
        let n = self.core.n;
        // ZE = Z^T E / h, kept in fz[0..n] (the stage derivatives are no longer needed).
        for i in 0..n {
            let ze: f64 = (0..3).map(|k| self.tab.e[k] * self.z[k * n + i]).sum::<f64>() / h;
            self.fz[i] = ze;
            self.err[i] = self.core.f[i] + ze;
        }
        lu_solve(&self.lu_real, n, &self.piv_real, &mut self.err);
        let mut norm = super::control::error_norm(&self.err, &self.core.y, &self.y_new, &self.core.opts);
        if stabilise && norm > 1.0 {
            for i in 0..n {
                self.ytmp[i] = self.core.y[i] + self.err[i];
            }
            let t = self.core.t;
            if Core::eval(&mut self.core.stats, sys, t, &self.ytmp, &mut self.err).is_ok() {
                for i in 0..n {
                    self.err[i] += self.fz[i];
                }
                lu_solve(&self.lu_real, n, &self.piv_real, &mut self.err);
                norm = super::control::error_norm(&self.err, &self.core.y, &self.y_new, &self.core.opts);
            }
        }
        norm
    }

    /// One accepted step; see the module doc for the logic.
    pub fn step<S: OdeSystem>(&mut self, sys: &mut S, t_stop: f64) -> Result<(), StepError<S::Error>> {
        self.core.assert_started();
        if t_stop.is_nan() || t_stop <= self.core.t {
            return Ok(());
        }
        if !self.jac_valid {
            self.compute_jacobian(sys).map_err(|error| StepError::Rhs { t: self.core.t, error })?;
        }
        let fixed = self.core.opts.dt;
        let mut h = match (fixed, self.core.opts.h0) {
            (Some(dt), _) => dt,
            _ if self.core.h_next > 0.0 => self.core.h_next,
            (None, Some(h0)) => h0,
            (None, None) => initial_step(sys, &mut self.core, t_stop, 3, &mut self.ytmp, &mut self.f_new),
        };
        let h_start = h;
        let (mut h_old, mut err_old) = (self.h_old, self.err_old);
        if h > self.core.opts.h_max {
            (h_old, err_old) = (None, None);
        }
        let stretch = stretch(fixed);
        let mut rejected = false;
        let mut last_failure: Option<Failure<S::Error>> = None;
        let (newton, err_norm, h_planned, h, t_new) = loop {
            let (h_try, t_new) = self.core.next_try(h, t_stop, stretch, rejected, &mut last_failure)?;
            match self.attempt(sys, h_try) {
                Ok(newton) => {
                    let err = if fixed.is_some() { 0.0 } else { self.error_estimate(sys, h_try, rejected) };
                    if err <= 1.0 {
                        break (newton, err, h, h_try, t_new);
                    }
                    let safety =
                        0.9 * (2 * NEWTON_MAXITER + 1) as f64 / (2 * NEWTON_MAXITER + newton.iterations) as f64;
                    let factor = predict_factor(h_try, h_old, err, err_old);
                    h = h_try * (safety * factor).max(MIN_FACTOR);
                    last_failure = None;
                }
                Err(f) => {
                    h = h_try * if matches!(f, Failure::Newton) { 0.5 } else { FAIL_FACTOR };
                    last_failure = Some(f);
                }
            }
            self.lu_h = 0.0;
            rejected = true;
            self.core.stats.nreject += 1;
        };
        // Accepted: choose the next step and whether to refresh J (scipy's rules).
        let recompute_jac = newton.iterations > 2 && newton.rate > JAC_REUSE_RATE;
        let safety = 0.9 * (2 * NEWTON_MAXITER + 1) as f64 / (2 * NEWTON_MAXITER + newton.iterations) as f64;
        let mut factor = (safety * predict_factor(h, h_old, err_norm, err_old)).min(MAX_FACTOR);
        if !recompute_jac && factor < 1.2 {
            factor = 1.0;
        } else {
            self.lu_h = 0.0;
        }
        self.accept(t_new);
        self.jac_current = false;
        if recompute_jac && self.compute_jacobian(sys).is_err() {
            self.jac_current = false; // keep the old, stale Jacobian
        }
        self.h_old = Some(h_start);
        self.err_old = Some(err_norm);
        self.core.h_next = match fixed {
            Some(dt) => dt,
            None => self.core.propose(h, factor, h_planned, t_stop),
        };
        Ok(())
    }

    /// Try a step of size `h`: Newton (refreshing J once if stale), then `y_new`
    /// and `f_new`. On success the LU factors match `h`.
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> Result<Newton, Failure<S::Error>> {
        self.predict(h);
        let newton = loop {
            if self.lu_h != h && self.factorize(h).is_err() {
                return Err(Failure::Newton);
            }
            if let Some(newton) = self.newton(sys, h)? {
                break newton;
            }
            if self.jac_current {
                return Err(Failure::Newton);
            }
            self.compute_jacobian(sys).map_err(Failure::Rhs)?;
            self.predict(h);
        };
        let n = self.core.n;
        for i in 0..n {
            self.y_new[i] = self.core.y[i] + self.z[2 * n + i];
        }
        if !all_finite(&self.y_new) {
            return Err(Failure::NonFinite);
        }
        let t_new = self.core.t + h;
        Core::eval(&mut self.core.stats, sys, t_new, &self.y_new, &mut self.f_new)?;
        Ok(newton)
    }

    /// Store the dense output of the accepted step and move to its end.
    fn accept(&mut self, t_new: f64) {
        let n = self.core.n;
        for j in 0..3 {
            for i in 0..n {
                self.q[j * n + i] = (0..3).map(|k| self.z[k * n + i] * self.tab.p[k][j]).sum();
            }
        }
        self.have_dense = true;
        self.core.accept(t_new, &mut self.y_new, &mut self.f_new);
    }
}

/// `y_prev + Σ_k Q_k s^k`, `k = 1..3`, with `Q` stage-major (`3 x n`).
fn eval_dense(q: &[f64], y_prev: &[f64], s: f64, out: &mut [f64]) {
    let n = y_prev.len();
    for i in 0..n {
        out[i] = y_prev[i] + s * (q[i] + s * (q[n + i] + s * q[2 * n + i]));
    }
}

/// Gustafsson's predictive step factor (HW II, IV.8 (8.25); scipy `predict_factor`),
/// before the safety factor.
fn predict_factor(h: f64, h_old: Option<f64>, err: f64, err_old: Option<f64>) -> f64 {
    let multiplier = match (h_old, err_old) {
        (Some(h_old), Some(err_old)) if err != 0.0 => h / h_old * (err_old / err).powf(0.25),
        _ => 1.0,
    };
    if err == 0.0 {
        return MAX_FACTOR;
    }
    multiplier.min(1.0) * err.powf(-0.25)
}
