//! Classic fourth-order Runge-Kutta, fixed step.
//!
//! Tableau (Kutta 1901; HNW I, II.1, Table 1.2):
//!
//! ```text
//!  0  |
//! 1/2 | 1/2
//! 1/2 |  0   1/2
//!  1  |  0    0    1
//! ----+--------------------
//!     | 1/6  1/3  1/3  1/6
//! ```
//!
//! Order 4. Steps of [`Options::dt`](super::Options::dt) seconds; the last
//! step before `t_stop` is shortened to end exactly on it. `f(t + h, y_new)` is
//! evaluated at each accepted step (it is the next step's first stage, so a
//! step costs 4 `rhs` calls) and gives `dy()` and the dense output: the cubic
//! Hermite polynomial through `(y, f)` at both ends of the step (order 3, local
//! error `O(h^4)`).
//!
//! **On `rhs` failure** (or a NaN) the step cannot rely on error control, so it
//! falls back to the adaptive behaviour of the other methods: the trial step is
//! shrunk by a factor 0.25 (counted as a rejection) and retried, down to
//! `h_min`, where [`StepError::Rhs`](super::StepError) is returned. The step
//! after a shortened one is `dt` again.

use super::control::{explicit_step, Core, ExplicitPair, Failure};
use super::{Integrator, OdeSystem, Options, StepError};

/// Fixed-step RK4 with cubic Hermite dense output. All buffers allocated in `new`.
pub struct Rk4 {
    pub(crate) core: Core,
    /// Stages k2, k3, k4 (k1 is `core.f`), each of length n.
    k: [Vec<f64>; 3],
    ytmp: Vec<f64>,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
}

impl Integrator for Rk4 {
    const NAME: &'static str = "rk4";
    const ALIASES: &'static [&'static str] = &[];
    const ORDER: usize = 4;
    /// Cubic Hermite.
    const DENSE_ORDER: usize = 3;
    const ADAPTIVE: bool = false;
    const IMPLICIT: bool = false;
    const SEES_REACH: bool = false;

    fn new(opts: &Options, n: usize) -> Self {
        Rk4 {
            core: Core::new(opts, n),
            k: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            ytmp: vec![0.0; n],
            y_new: vec![0.0; n],
            f_new: vec![0.0; n],
        }
    }

    /// Cubic Hermite interpolation on the last step (see the module doc).
    fn interpolate<S: OdeSystem>(&mut self, _sys: &mut S, t: f64, out: &mut [f64]) {
        hermite(&self.core, t, out);
    }
}

impl Rk4 {
    pub fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), StepError<S::Error>> {
        self.core.reset(sys, t, y)
    }

    pub fn step<S: OdeSystem>(&mut self, sys: &mut S, t_stop: f64) -> Result<(), StepError<S::Error>> {
        explicit_step(self, sys, t_stop)
    }
}

/// Cubic Hermite interpolant through `(y_prev, f_prev)` at `t_prev` and `(y, f)` at `t`.
pub(crate) fn hermite(c: &Core, t: f64, out: &mut [f64]) {
    let h = c.t - c.t_prev;
    if h == 0.0 {
        out.copy_from_slice(&c.y);
        return;
    }
    let s = (t - c.t_prev) / h;
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    for i in 0..c.n {
        out[i] = h00 * c.y_prev[i] + h * h10 * c.f_prev[i] + h01 * c.y[i] + h * h11 * c.f[i];
    }
}

impl ExplicitPair for Rk4 {
    /// Unused: RK4 runs only with a fixed step.
    const ERROR_ORDER: usize = 3;

    fn core(&mut self) -> &mut Core {
        &mut self.core
    }

    fn scratch(&mut self) -> (&mut Core, &mut [f64], &mut [f64]) {
        (&mut self.core, &mut self.ytmp, &mut self.f_new)
    }

    /// One RK4 step; returns an error norm of 0 (no estimate).
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> Result<f64, Failure<S::Error>> {
        let Rk4 { core, k, ytmp, y_new, f_new } = self;
        let (t, n) = (core.t, core.n);
        let [k2, k3, k4] = k;
        for i in 0..n {
            ytmp[i] = core.y[i] + 0.5 * h * core.f[i];
        }
        Core::eval(&mut core.stats, sys, t + 0.5 * h, ytmp, k2)?;
        for i in 0..n {
            ytmp[i] = core.y[i] + 0.5 * h * k2[i];
        }
        Core::eval(&mut core.stats, sys, t + 0.5 * h, ytmp, k3)?;
        for i in 0..n {
            ytmp[i] = core.y[i] + h * k3[i];
        }
        Core::eval(&mut core.stats, sys, t + h, ytmp, k4)?;
        for i in 0..n {
            y_new[i] = core.y[i] + h / 6.0 * (core.f[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        Core::eval(&mut core.stats, sys, t + h, y_new, f_new)?;
        if !super::control::all_finite(y_new) {
            return Err(Failure::NonFinite);
        }
        Ok(0.0)
    }

    fn accept<S: OdeSystem>(&mut self, _sys: &mut S, t_new: f64) {
        self.core.accept(t_new, &mut self.y_new, &mut self.f_new);
    }
}
