//! Dormand-Prince 5(4): explicit embedded Runge-Kutta pair, order 5 with a
//! 4th-order error estimate (local extrapolation), FSAL.
//!
//! References: J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta
//! formulae", J. Comput. Appl. Math. 6 (1980) 19-26; HNW I, II.5, Table 5.2
//! and Hairer's code DOPRI5; dense output of order 4 from L. F. Shampine,
//! "Some practical Runge-Kutta formulas", Math. Comp. 46 (1986) 135-150
//! (the coefficients `P` of scipy's `RK45`).
//!
//! Tableau (`C`, `A`, weights `B`; `E = B - B̂` for the 4th-order solution,
//! with a 7th entry for the FSAL stage `f(t + h, y_new)`):
//!
//! ```text
//!   0  |
//!  1/5 | 1/5
//! 3/10 | 3/40        9/40
//!  4/5 | 44/45      -56/15      32/9
//!  8/9 | 19372/6561 -25360/2187 64448/6561 -212/729
//!   1  | 9017/3168  -355/33     46732/5247  49/176  -5103/18656
//! -----+-----------------------------------------------------------------
//!   B  | 35/384      0          500/1113    125/192 -2187/6784   11/84
//! ```
//!
//! Cost: 6 `rhs` calls per step (7 stages, the last is the next step's first).
//! Dense output: `y(t_prev + s h) = y_prev + h sum_j (K_j^T P)_j s^j`, `j = 1..4`,
//! computed at each accepted step (`4 x n` values, no `rhs` call).

use super::control::{all_finite, combine, error_norm, explicit_step, scaled_sum, Core, ExplicitPair, Failure};
use super::{Integrator, OdeSystem, Options, StepError};
use crate::linalg::copy_small;

const C: [f64; 6] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0];

const A: [[f64; 5]; 6] = [
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0],
];

const B: [f64; 6] = [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0];

/// Error weights `B - B̂` (7 stages, the last is the FSAL stage).
const E: [f64; 7] =
    [-71.0 / 57600.0, 0.0, 71.0 / 16695.0, -71.0 / 1920.0, 17253.0 / 339200.0, -22.0 / 525.0, 1.0 / 40.0];

/// Dense output coefficients: row = stage, column = power of `s` (1..4).
const P: [[f64; 4]; 7] = [
    [1.0, -8048581381.0 / 2820520608.0, 8663915743.0 / 2820520608.0, -12715105075.0 / 11282082432.0],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 131558114200.0 / 32700410799.0, -68118460800.0 / 10900136933.0, 87487479700.0 / 32700410799.0],
    [0.0, -1754552775.0 / 470086768.0, 14199869525.0 / 1410260304.0, -10690763975.0 / 1880347072.0],
    [0.0, 127303824393.0 / 49829197408.0, -318862633887.0 / 49829197408.0, 701980252875.0 / 199316789632.0],
    [0.0, -282668133.0 / 205662961.0, 2019193451.0 / 616988883.0, -1453857185.0 / 822651844.0],
    [0.0, 40617522.0 / 29380423.0, -110615467.0 / 29380423.0, 69997945.0 / 29380423.0],
];

/// [`P`] transposed: row = power of `s`, column = stage (the weights of one power's sum).
const P_T: [[f64; 7]; 4] = {
    let mut t = [[0.0; 7]; 4];
    let mut j = 0;
    while j < 7 {
        let mut p = 0;
        while p < 4 {
            t[p][j] = P[j][p];
            p += 1;
        }
        j += 1;
    }
    t
};

/// Dormand-Prince 5(4) stepper. All buffers allocated in `new`.
pub struct Dopri5 {
    pub(crate) core: Core,
    /// Stages `K_0..K_6`, stage-major (`7 x n`); `K_0 = f(t, y)`, `K_6 = f(t + h, y_new)`.
    k: Vec<f64>,
    /// Dense output coefficients of the last accepted step, `4 x n` (`h` included).
    q: Vec<f64>,
    ytmp: Vec<f64>,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
    err: Vec<f64>,
    /// Step size of the last attempt (s).
    h: f64,
}

impl Integrator for Dopri5 {
    const NAME: &'static str = "dopri5";
    const ALIASES: &'static [&'static str] = &["rk45"];
    const ORDER: usize = 5;
    /// Quartic.
    const DENSE_ORDER: usize = 4;
    const ADAPTIVE: bool = true;
    const IMPLICIT: bool = false;
    const SEES_REACH: bool = false;

    fn new(opts: &Options, n: usize) -> Self {
        Dopri5 {
            core: Core::new(opts, n),
            k: vec![0.0; 7 * n],
            q: vec![0.0; 4 * n],
            ytmp: vec![0.0; n],
            y_new: vec![0.0; n],
            f_new: vec![0.0; n],
            err: vec![0.0; n],
            h: 0.0,
        }
    }

    /// 4th-order dense output on the last accepted step.
    fn interpolate<S: OdeSystem>(&mut self, _sys: &mut S, t: f64, out: &mut [f64]) {
        let c = &self.core;
        let n = c.n;
        let h = c.t - c.t_prev;
        let s = if h == 0.0 { 0.0 } else { (t - c.t_prev) / h };
        let q = |p: usize| &self.q[p * n..(p + 1) * n];
        for ((((q1, q2), q3), q4), (y, o)) in q(0).iter().zip(q(1)).zip(q(2)).zip(q(3)).zip(c.y_prev.iter().zip(out)) {
            // Horner in s: s (q1 + s (q2 + s (q3 + s q4))).
            *o = y + (q1 + (q2 + (q3 + q4 * s) * s) * s) * s;
        }
    }
}

impl Dopri5 {
    pub fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), StepError<S::Error>> {
        self.q.fill(0.0);
        self.core.reset(sys, t, y)
    }

    pub fn step<S: OdeSystem>(&mut self, sys: &mut S, t_stop: f64) -> Result<(), StepError<S::Error>> {
        explicit_step(self, sys, t_stop)
    }
}

impl ExplicitPair for Dopri5 {
    const ERROR_ORDER: usize = 4;

    fn core(&mut self) -> &mut Core {
        &mut self.core
    }

    fn scratch(&mut self) -> (&mut Core, &mut [f64], &mut [f64]) {
        (&mut self.core, &mut self.ytmp, &mut self.f_new)
    }

    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, h: f64) -> Result<f64, Failure<S::Error>> {
        self.h = h;
        let Dopri5 { core, k, ytmp, y_new, f_new, err, .. } = self;
        let (t, n) = (core.t, core.n);
        copy_small(&mut k[..n], &core.f);
        // Stage by stage with the index a constant, as DOP853's (`Dop853::stage_at`): each
        // row's sum is unrolled over its nonzero weights only.
        macro_rules! stages {
            ($($s:literal)*) => { $(
                combine(ytmp, &core.y, h, &A[$s][..$s], &k[..$s * n]);
                Core::eval(&mut core.stats, sys, t + C[$s] * h, ytmp, &mut k[$s * n..($s + 1) * n])?;
            )* };
        }
        stages!(1 2 3 4 5);
        combine(y_new, &core.y, h, &B, &k[..6 * n]);
        if !all_finite(y_new) {
            return Err(Failure::NonFinite);
        }
        Core::eval(&mut core.stats, sys, t + h, y_new, f_new)?;
        copy_small(&mut k[6 * n..], f_new);
        scaled_sum(err, h, &E, k);
        Ok(error_norm(err, &core.y, y_new, &core.opts))
    }

    fn accept<S: OdeSystem>(&mut self, _sys: &mut S, t_new: f64) {
        let (n, h) = (self.core.n, self.h);
        for (p, row) in self.q.chunks_exact_mut(n.max(1)).enumerate() {
            scaled_sum(row, h, &P_T[p], &self.k);
        }
        self.core.accept(t_new, &mut self.y_new, &mut self.f_new);
    }
}
