//! ODE integrators for the equations of motion `y' = f(t, y)`, with `y = (q, qd)`.
//!
//! Four one-step methods, one file each:
//!
//! | [`Method`] | file | order | step | dense output |
//! |---|---|---|---|---|
//! | `Rk4` | [`rk4`] | 4 | fixed `dt` | cubic Hermite (order 3) |
//! | `Dopri5` | [`dopri5`] | 5(4) | adaptive | quartic (order 4) |
//! | `Dop853` | [`dop853`] | 8(5,3) | adaptive | degree 7 (order 7) |
//! | `Radau5` | [`radau5`] | 5, implicit, stiff | adaptive | collocation cubic (order 3) |
//!
//! The shared pieces (error norm, initial step, step-size controller, the
//! explicit-pair step loop) live in `control`; Radau5's LU is `crate::linalg`'s.
//! Each file declares its integrator's name, orders and kind ([`Integrator`]); adding a
//! method is a file and a line of the registration table (`integrators!`).
//!
//! # Why hand-written
//!
//! The crates on crates.io (`ode_solvers`, ...) do not fit a closed-chain simulator:
//!
//! 1. The right-hand side can **fail**: evaluating `f` needs the position analysis
//!    of the closed chain (a Newton solve), which may not converge for a large
//!    trial step. Here [`OdeSystem::rhs`] returns a `Result`, and an `Err` rejects
//!    the trial step, which is retried with a smaller one (see [`StepError::Rhs`]).
//! 2. The driver **switches coordinate charts** between steps (near a singular
//!    configuration it changes the independent coordinates) and restarts the
//!    integrator from the new state: [`Stepper::reset`], while the caller keeps
//!    control of the loop, one [`Stepper::step`] at a time.
//! 3. **No heap allocation per step**: every buffer is sized in [`Stepper::new`];
//!    `reset`, `step` and `interpolate` only reuse them (checked by a counting
//!    allocator in `tests/integrators.rs`).
//!
//! # Conventions
//!
//! Time `t` in seconds, `y` in the units of the system (rad, m, rad/s, m/s for
//! mechanisms). Integration runs forward in time only (`t_stop > t`).
//! Error control uses Hairer's RMS norm, with the scale
//! `sc_i = atol + rtol * max(|y_i|, |ynew_i|)`; a step is accepted when the
//! norm of the scaled local error estimate is `<= 1`.
//!
//! References: E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential
//! Equations I* (2nd ed., Springer 1993), II.4-II.6; E. Hairer, G. Wanner,
//! *Solving Ordinary Differential Equations II* (2nd ed., Springer 1996), IV.8;
//! scipy's `scipy/integrate/_ivp` (`rk.py`, `radau.py`, `common.py`), whose
//! structure these implementations follow.

// Index loops over stages and components read like the formulas of the references.
#![allow(clippy::needless_range_loop)]

mod control;
pub mod dop853;
pub mod dopri5;
pub mod radau5;
pub mod rk4;

use crate::error::{Setting, SettingError, Time};
use std::fmt;
use std::str::FromStr;

/// A first-order system y' = f(t, y) whose evaluation may fail.
pub trait OdeSystem {
    /// The error of a failed evaluation (for a mechanism: the position analysis
    /// did not converge). Carried by [`StepError::Rhs`].
    type Error: Clone + std::fmt::Debug;
    /// Number of state components (length of `y` and `dy`).
    fn dim(&self) -> usize;
    /// Write f(t, y) into dy. An Err makes the integrator reject the step and retry with a smaller one.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Self::Error>;
    /// f(t, y) at a point that must be evaluated rather than avoided by a shorter step: the
    /// dense-output stages of a step already accepted. The default is [`OdeSystem::rhs`]; a
    /// system that refuses evaluations far from its last one may try harder here.
    fn rhs_dense(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Self::Error> {
        self.rhs(t, y, dy)
    }
    /// The exact Jacobian df/dy (row-major, dim x dim) into `jac`, where the system has one;
    /// None (the default): the implicit integrators difference `rhs` instead.
    fn jacobian(&mut self, _t: f64, _y: &[f64], _jac: &mut [f64]) -> Option<Result<(), Self::Error>> {
        None
    }
}

/// What an integrator declares in its own file: its names, orders and kind, how it is made
/// and how it interpolates. The registration table (`integrators!` below) lists the
/// integrators; [`Method`] and [`Stepper`] read everything else from here.
pub trait Integrator: Sized {
    /// The canonical lower-case name (as `FromStr` and a model's `simulate.method` accept
    /// it, case-insensitive), and the other names accepted.
    const NAME: &'static str;
    const ALIASES: &'static [&'static str];
    /// Classical order of the propagated solution (global error `O(h^ORDER)`).
    const ORDER: usize;
    /// Order of the dense output: its local error is `O(h^(DENSE_ORDER + 1))`.
    const DENSE_ORDER: usize;
    /// With local error control (false: a fixed step, [`Options::dt`]).
    const ADAPTIVE: bool;
    /// Implicit (stiffly accurate).
    const IMPLICIT: bool;
    /// Whose error estimate also bounds a step's reach towards the solution's nearest
    /// singularity (DOP853's third-order estimate against the step's increment), so that the
    /// run need not bound the steps into a type II singularity itself.
    const SEES_REACH: bool;
    /// A stepper for systems of dimension `dim`, all buffers allocated here.
    fn new(opts: &Options, dim: usize) -> Self;
    /// The solution at t in [t_prev, t] of the last accepted step into `out`; `sys` for a
    /// dense output that evaluates stages of its own (Dop853's, once a step).
    fn interpolate<S: OdeSystem>(&mut self, sys: &mut S, t: f64, out: &mut [f64]);
}

/// The registration table's macro: from each method's doc, variant and integrator type it
/// makes [`Method`] (with `Method::ALL`), [`Stepper`], and the macros `registry!` (a method
/// to its integrator type) and `dispatch!` (a stepper to its integrator). `$d` is a `$`
/// passed in, which the macros it defines need.
macro_rules! integrators {
    ($d:tt $($(#[$doc:meta])* $variant:ident => $module:ident::$ty:ident,)*) => {
        /// The integration method, chosen at run time.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Method {
            $($(#[$doc])* $variant,)*
        }

        impl Method {
            /// All methods, in declaration order.
            pub const ALL: [Method; [$(Method::$variant),*].len()] = [$(Method::$variant),*];
        }

        /// One integrator, chosen at run time (enum dispatch, so generic `step<S>` works
        /// without trait objects).
        ///
        /// Created once per simulation, so the variants' different sizes do not matter.
        #[allow(clippy::large_enum_variant)]
        pub enum Stepper {
            $($variant($module::$ty),)*
        }

        /// Evaluate `$body` with `$T` the integrator type of a method.
        macro_rules! registry {
            ($d method:expr, $d T:ident => $d body:expr) => {
                match $d method {
                    $(Method::$variant => {
                        type $d T = $module::$ty;
                        $d body
                    })*
                }
            };
        }

        /// Evaluate `$body` with `$s` the integrator of a stepper.
        macro_rules! dispatch {
            ($d stepper:expr, $d s:ident => $d body:expr) => {
                match $d stepper {
                    $(Stepper::$variant($d s) => $d body,)*
                }
            };
        }

        impl Stepper {
            /// The method of this stepper.
            pub fn method(&self) -> Method {
                match self {
                    $(Stepper::$variant(_) => Method::$variant,)*
                }
            }

            /// A stepper of `method` for valid options.
            fn of(method: Method, opts: &Options, dim: usize) -> Stepper {
                match method {
                    $(Method::$variant => Stepper::$variant(<$module::$ty as Integrator>::new(opts, dim)),)*
                }
            }
        }
    };
}

// The registration table: each integrator's file declares the rest (`Integrator`).
integrators! { $
    /// Classic fixed-step Runge-Kutta of order 4 (needs [`Options::dt`]).
    Rk4 => rk4::Rk4,
    /// Dormand-Prince 5(4), adaptive, FSAL.
    Dopri5 => dopri5::Dopri5,
    /// Dormand-Prince 8(5,3), adaptive, for tight tolerances.
    Dop853 => dop853::Dop853,
    /// Radau IIA of order 5, implicit, for stiff systems (stiff springs, dampers).
    Radau5 => radau5::Radau5,
}

impl Method {
    /// Classical order of the propagated solution (global error `O(h^order)`).
    pub fn order(self) -> usize {
        registry!(self, T => T::ORDER)
    }

    /// Order of the dense output: its local error is `O(h^(dense_order + 1))`.
    pub fn dense_order(self) -> usize {
        registry!(self, T => T::DENSE_ORDER)
    }

    /// True for the methods with local error control (all but `Rk4`).
    pub fn is_adaptive(self) -> bool {
        registry!(self, T => T::ADAPTIVE)
    }

    /// True for the implicit (stiffly accurate) methods.
    pub fn is_implicit(self) -> bool {
        registry!(self, T => T::IMPLICIT)
    }

    /// True for the methods whose error estimate also bounds a step's reach towards the
    /// solution's nearest singularity (DOP853).
    pub fn sees_reach(self) -> bool {
        registry!(self, T => T::SEES_REACH)
    }

    /// The canonical lower-case name, as accepted by `FromStr`.
    pub fn name(self) -> &'static str {
        registry!(self, T => T::NAME)
    }

    /// The other names `FromStr` accepts.
    fn aliases(self) -> &'static [&'static str] {
        registry!(self, T => T::ALIASES)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = String;

    /// Case-insensitive: a method's name or one of its aliases ("rk4", "dopri5" or "rk45",
    /// "dop853", "radau5" or "radau").
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let name = s.trim().to_ascii_lowercase();
        let known = |m: &Method| m.name() == name || m.aliases().contains(&name.as_str());
        Method::ALL.into_iter().find(known).ok_or_else(|| {
            let quoted = |names: &[&str]| names.iter().map(|n| format!("{n:?}")).collect::<Vec<_>>().join(", ");
            let each = Method::ALL.map(|m| match m.aliases() {
                [] => quoted(&[m.name()]),
                aliases => format!("{} ({})", quoted(&[m.name()]), quoted(aliases)),
            });
            format!("unknown integration method {s:?}: use one of {}", each.join(", "))
        })
    }
}

/// Integrator options. Times in seconds.
#[derive(Clone, Debug)]
pub struct Options {
    /// Relative tolerance (dimensionless), at least 100 machine epsilons. Default `1e-8`.
    pub rtol: f64,
    /// Absolute tolerance (units of `y`), `> 0`: with 0, a component passing through 0
    /// has a zero error scale and the step collapses there. Default `1e-10`.
    pub atol: f64,
    /// First trial step (s). `None`: chosen automatically by Hairer's algorithm
    /// (HNW I, II.4, as scipy's `select_initial_step`). Default `None`.
    pub h0: Option<f64>,
    /// Largest step (s). Default `f64::INFINITY`.
    pub h_max: f64,
    /// Smallest step, relative to the time scale: when rejections shrink the
    /// trial step below `h_min * max(|t|, 1 s)` (and never below 10 ulp of `t`),
    /// the step ends with an error ([`StepError::StepSizeUnderflow`], `Rhs` or
    /// `NonFinite`, after the last cause of rejection). A step that lands on a
    /// `t_stop` closer than this is still taken. Default `1e-14`.
    pub h_min: f64,
    /// Fixed step (s). Required by `Rk4`. For the adaptive methods, `Some(dt)`
    /// switches the error control off and steps with `dt` (used to measure the
    /// order of convergence); a failing `rhs` still shrinks the trial step
    /// (by 0.25, see [`StepError::Rhs`]).
    /// Default `None`.
    pub dt: Option<f64>,
    /// Largest number of step attempts (accepted plus rejected) since
    /// [`Stepper::new`]; past it [`StepError::TooManySteps`]. Default `10_000_000`.
    pub max_steps: usize,
    /// Full-order dense output. Only `Dop853` pays for it: 3 extra `rhs` evaluations in
    /// each step where [`Stepper::interpolate`] is called; when `false` its interpolant
    /// is cubic Hermite. Default `true`.
    pub dense_output: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: 1e-8,
            atol: 1e-10,
            h0: None,
            h_max: f64::INFINITY,
            h_min: 1e-14,
            dt: None,
            max_steps: 10_000_000,
            dense_output: true,
        }
    }
}

impl Options {
    /// Default options with tolerances `rtol`, `atol`.
    pub fn tol(rtol: f64, atol: f64) -> Self {
        Options { rtol, atol, ..Options::default() }
    }

    /// Default options with a fixed step `dt` (s): no error control, for any method.
    pub fn fixed(dt: f64) -> Self {
        Options { dt: Some(dt), ..Options::default() }
    }

    /// Check the options for `method` by each one's rule ([`Setting::check`]); the error
    /// names the option and says what to change.
    pub fn validate(&self, method: Method) -> Result<(), SettingError> {
        Setting::Rtol.check(self.rtol)?;
        Setting::Atol.check(self.atol)?;
        if let Some(h0) = self.h0 {
            Setting::H0.check(h0)?;
        }
        Setting::HMax.check(self.h_max)?;
        Setting::HMin.check(self.h_min)?;
        match self.dt {
            Some(dt) => {
                Setting::Dt.check(dt)?;
            }
            None if !method.is_adaptive() => {
                return Err(SettingError::missing(
                    Setting::Dt,
                    format!(
                        "is needed: {method} is a fixed-step method; set the step dt (e.g. Options::fixed(1e-3)), \
                         or choose an adaptive method such as dopri5"
                    ),
                ))
            }
            None => {}
        }
        // usize to f64 is exact up to 2^53, far above MAX_STEPS.
        Setting::MaxSteps.check(self.max_steps as f64)?;
        Ok(())
    }
}

/// Why a step could not be completed. The stepper state stays at the last
/// accepted point (`t()`, `y()`, `dy()`, `interpolate` are unchanged).
#[derive(Clone, Debug)]
pub enum StepError<E> {
    /// The error control (or Newton convergence, for Radau5) drove the step below `h_min`.
    StepSizeUnderflow { t: f64, h: f64 },
    /// `rhs` kept failing until the step underflowed; `error` is the last failure.
    Rhs { t: f64, error: E },
    /// NaN or infinity in the solution, persisting down to `h_min`.
    NonFinite { t: f64 },
    /// [`Options::max_steps`] attempts were used.
    TooManySteps { t: f64, steps: usize },
}

impl<E: fmt::Debug> fmt::Display for StepError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::StepSizeUnderflow { t, h } => write!(
                f,
                "step size underflow at t = {} s (h = {h:e} s): the problem may be stiff \
                 (try radau5) or singular there, or loosen rtol/atol",
                Time(*t)
            ),
            StepError::Rhs { t, error } => {
                write!(f, "right-hand side failed at t = {} s even for the smallest step: {error:?}", Time(*t))
            }
            StepError::NonFinite { t } => write!(
                f,
                "NaN or infinity in the solution near t = {} s: the rates or efforts overflow there; \
                 try smaller start rates (qd0), efforts or motion speeds, or tighter rtol/atol",
                Time(*t)
            ),
            StepError::TooManySteps { t, steps } => write!(
                f,
                "{steps} steps used before t_stop (stopped at t = {} s): raise max_steps, \
                 loosen the tolerances, or try radau5 if the problem is stiff",
                Time(*t)
            ),
        }
    }
}

impl<E: fmt::Debug> std::error::Error for StepError<E> {}

/// Work counters, cumulative since [`Stepper::new`] (a `reset` does not clear them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Evaluations of `rhs`, failed ones included.
    pub nfev: usize,
    /// Accepted steps.
    pub naccept: usize,
    /// Rejected trial steps (error too large, `rhs` failure, non-finite values, Newton failure).
    pub nreject: usize,
    /// Jacobian evaluations (Radau5: the system's exact one, or by finite differences, `dim`
    /// `rhs` calls each).
    pub njev: usize,
    /// LU decompositions (Radau5: the real and the complex matrix count one each).
    pub nlu: usize,
}

impl fmt::Debug for Stepper {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Stepper")
            .field("method", &self.method())
            .field("t", &self.t())
            .field("t_prev", &self.t_prev())
            .field("h_next", &self.h_next())
            .field("stats", &self.stats())
            .finish_non_exhaustive()
    }
}

impl Stepper {
    /// A stepper for systems of dimension `dim`, all buffers allocated here.
    /// Err for invalid options, with the fix in the message.
    pub fn new(method: Method, opts: &Options, dim: usize) -> Result<Self, String> {
        opts.validate(method).map_err(|e| e.to_string())?;
        Ok(Stepper::of(method, opts, dim))
    }

    /// Start, or restart after a discontinuity / change of coordinates, at (t, y). Evaluates f(t, y).
    ///
    /// Forgets the step-size history (the next step starts from `h0` or the
    /// automatic initial step) and, for Radau5, the Jacobian. Panics if
    /// `y.len()` differs from the `dim` given to `new` (a driver bug).
    pub fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), StepError<S::Error>> {
        dispatch!(self, s => s.reset(sys, t, y))
    }

    /// Bound the automatic first step after the last `reset` by `h_max` (s), from what the
    /// system knows of itself (a mechanism: how far its new chart's coordinates may move in
    /// one step). The starting-step rule knows only f and its change along f, and its guess
    /// after a chart switch was rejected twice or three times at most of the five-bar's
    /// switches. A step size given in `Options::h0` is the caller's and is kept.
    pub fn bound_first_step(&mut self, h_max: f64) {
        dispatch!(self, s => s.core.first_step_max = h_max)
    }

    /// Bound the next trial step by `h_max` (s), from what the system knows of itself (a
    /// mechanism: how far its solutions may move from the last accepted point, see
    /// `MechanismOde::reach_step_bound`). The controller's proposal is kept where shorter;
    /// right after a `reset` the bound caps the automatic first step as
    /// [`Stepper::bound_first_step`] does. Fixed steps (`Options::dt`) are left alone.
    pub fn bound_next_step(&mut self, h_max: f64) {
        dispatch!(self, s => s.core.bound_next_step(h_max))
    }

    /// Bound the next trial step by the trend of the error estimates over the last two
    /// accepted steps (Gustafsson's predictive controller), where the system expects its error
    /// constant to keep growing (a mechanism approaching its chart's singularity). No-op
    /// without two accepted steps since the last `reset`, or for fixed steps.
    pub fn predict_next_step(&mut self) {
        dispatch!(self, s => s.core.predict_next_step())
    }

    /// Advance by one accepted step, never past t_stop (t_stop > t). Rejected tries are retried inside.
    ///
    /// The last step before `t_stop` ends exactly on it. With `t_stop <= t` nothing
    /// is done. Panics if called before `reset` (a driver bug).
    pub fn step<S: OdeSystem>(&mut self, sys: &mut S, t_stop: f64) -> Result<(), StepError<S::Error>> {
        dispatch!(self, s => s.step(sys, t_stop))
    }

    /// Current time (s).
    pub fn t(&self) -> f64 {
        dispatch!(self, s => s.core.t)
    }

    /// Start of the last accepted step (s); equals `t()` right after `reset`.
    pub fn t_prev(&self) -> f64 {
        dispatch!(self, s => s.core.t_prev)
    }

    /// Current state.
    pub fn y(&self) -> &[f64] {
        dispatch!(self, s => &s.core.y)
    }

    /// The derivative f(t, y) at the current point (available for all methods after reset/step).
    pub fn dy(&self) -> &[f64] {
        dispatch!(self, s => &s.core.f)
    }

    /// Dense output: the solution at any t in [t_prev, t] of the last accepted step, written to out.
    ///
    /// Outside that interval the polynomial is extrapolated (less accurate).
    /// Right after `reset`, returns `y()`. `sys` is the system being integrated: Dop853
    /// evaluates its 3 dense-output stages on the first call within a step (so steps with no
    /// output time in them do not pay for them); call it before the next `step`.
    pub fn interpolate<S: OdeSystem>(&mut self, sys: &mut S, t: f64, out: &mut [f64]) {
        dispatch!(self, s => Integrator::interpolate(s, sys, t, out))
    }

    /// Work counters since `new`.
    pub fn stats(&self) -> Stats {
        dispatch!(self, s => s.core.stats)
    }

    /// The step size the next `step` will try first (s), 0 before the first step after a reset.
    pub fn h_next(&self) -> f64 {
        dispatch!(self, s => s.core.h_next)
    }
}
