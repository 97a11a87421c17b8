//! Errors of the planardyn core. Every variant carries the data a user needs to
//! find the problem and says what to try next; nothing in the crate panics on user input.

use thiserror::Error;

/// A model that cannot be built: a malformed file, or a drawing that is not a mechanism.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum ModelError {
    /// The text is not valid YAML/JSON, or a field has the wrong type or an unknown name.
    #[error("{source_name}: {path}: {message}")]
    Parse { source_name: String, path: String, message: String },
    /// A field has a value that is well-formed but not allowed (unknown name, non-positive mass...).
    #[error("{source_name}: {path}: {message}")]
    Invalid { source_name: String, path: String, message: String },
}

impl ModelError {
    /// The field path the error is about (`bodies.crank.mass`, `pairs[2].at`...).
    pub fn path(&self) -> &str {
        match self {
            ModelError::Parse { path, .. } | ModelError::Invalid { path, .. } => path,
        }
    }
}

/// Which matrix lost rank where a computation needs it regular, and so what to change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum SingularityKind {
    /// Type II (parallel): J with the generalized coordinates fixed is singular, so q does not
    /// determine the position (the actuated mechanism gains an uncontrolled motion).
    TypeII,
    /// The pair constraints Phi_x lose rank: a singularity of the passive mechanism, whatever
    /// the coordinates.
    Passive,
    /// The start is a type II singularity and the rates qd0 are not all zero: they do not
    /// determine the body velocities there.
    TypeIIStartInMotion,
    /// The passive mechanism is singular at the start of a simulation.
    PassiveAtStart,
    /// The mass matrix A = U^T M U is not positive definite (`type_ii`: in the chart of the
    /// generalized coordinates, i.e. at a type II singularity).
    MassMatrix { type_ii: bool },
}

impl SingularityKind {
    /// A stable identifier (`"type_ii"`, `"passive"`...), for bindings and logs.
    pub fn name(self) -> &'static str {
        match self {
            SingularityKind::TypeII => "type_ii",
            SingularityKind::Passive => "passive",
            SingularityKind::TypeIIStartInMotion => "type_ii_start_in_motion",
            SingularityKind::PassiveAtStart => "passive_at_start",
            SingularityKind::MassMatrix { .. } => "mass_matrix",
        }
    }
}

impl std::fmt::Display for SingularityKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SingularityKind::TypeII => {
                "the generalized coordinates do not determine the mechanism's position \
                 (a type II, parallel singularity of the actuated mechanism)"
            }
            SingularityKind::Passive => "the pair constraints lose rank (a singularity of the passive mechanism)",
            SingularityKind::TypeIIStartInMotion => {
                "the start is a type II singularity, where the rates qd0 do not determine the body \
                 velocities; start at rest or elsewhere"
            }
            SingularityKind::PassiveAtStart => {
                "the passive mechanism is singular at the start (its pair constraints lose rank); start elsewhere"
            }
            SingularityKind::MassMatrix { type_ii: true } => {
                "the mass matrix A = U^T M U is not positive definite (type II singularity)"
            }
            SingularityKind::MassMatrix { type_ii: false } => "the mass matrix A = U^T M U is not positive definite",
        })
    }
}

/// A kinematic computation that failed at a given configuration.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum KinematicsError {
    /// Newton's method on the loop-closure equations did not converge.
    #[error(
        "position analysis did not converge (residual {residual:.3e} after {iterations} iterations): \
         the mechanism cannot be assembled at these coordinates, or they lie on another branch; \
         try values closer to the drawing or a smaller step"
    )]
    AssemblyFailed { residual: f64, iterations: usize },
    /// A matrix the computation needs regular is singular. `sigma_min`: the smallest scaled
    /// singular value, where it was measured (a failed factorisation measures nothing).
    #[error("the mechanism is singular here{}: {kind}", sigma_note(.sigma_min))]
    Singular { kind: SingularityKind, sigma_min: Option<f64> },
    /// Finite inputs whose result overflows the floating-point range: `what` names the
    /// quantity (e.g. "accelerations qdd").
    #[error(
        "the {what} overflow (not finite) for these finite inputs: the efforts or rates are too large \
         for the mechanism; try smaller efforts (tau) or rates (qd)"
    )]
    Overflow { what: &'static str },
    /// The pairs' Coulomb friction efforts and the reactions they depend on did not settle
    /// to a common solution: the mechanism self-locks (or nearly) under its friction.
    #[error(
        "the friction efforts did not settle in {iterations} iterations (last change {change:.3e} N m): \
         the mechanism self-locks under its pair friction here; lower mu or the pin radii"
    )]
    FrictionUnsettled { iterations: usize, change: f64 },
    /// No choice of the gears' branches (motoring, back-driven, stuck) is consistent: a motor
    /// on a moving link whose housing turns against its rotor, with a lossy gear (Painleve's
    /// paradox of friction; docs/actuators.md).
    #[error(
        "the gears of {actuators} admit no consistent motion here (their efficiencies against the \
         housings' rotation: friction's paradox); raise the efficiencies or mount the motors elsewhere"
    )]
    GearsJammed { actuators: String },
    /// The linear program of min-max effort sharing found no optimum (`message`: the solver's).
    #[error("the min-max sharing of the efforts failed: {message}; share them by minimum norm or a preload")]
    EffortSharing { message: String },
    /// An argument with the wrong length or a non-finite value.
    #[error("{name}: expected {expected}, got {got}")]
    BadArgument { name: &'static str, expected: String, got: String },
}

fn sigma_note(sigma_min: &Option<f64>) -> String {
    sigma_min.map(|s| format!(" (smallest scaled singular value {s:.3e})")).unwrap_or_default()
}

impl KinematicsError {
    /// A singularity found by a factorisation, which measures no singular value.
    pub fn singular(kind: SingularityKind) -> Self {
        KinematicsError::Singular { kind, sigma_min: None }
    }

    /// An argument `name` that is not what was `expected`; `got` says what it is.
    pub fn bad_argument(name: &'static str, expected: impl Into<String>, got: impl Into<String>) -> Self {
        KinematicsError::BadArgument { name, expected: expected.into(), got: got.into() }
    }
}

/// Errors returned by the dynamics and simulation entry points.
#[derive(Debug, Clone, Error, PartialEq)]
#[non_exhaustive]
pub enum Error {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// A setting of a run that breaks its rule ([`Setting::check`]): rtol <= 0, a
    /// fixed-step method without `dt`...
    #[error("invalid option: {0}")]
    Setting(#[from] SettingError),
    /// Other options that cannot work together (an unknown method name, an event's
    /// coordinate that does not exist...).
    #[error("invalid option: {0}")]
    Options(String),
    /// A user-supplied drive function failed (its message is kept).
    #[error("drive function failed at t = {}: {message}", Time(*.t))]
    Drive { t: f64, message: String },
    /// Rows of a motion given by q alone pass so near a type II singularity that the branch
    /// after it cannot be told from q: the motion may have changed assembly mode there.
    #[error(
        "row {row} of the motion is at a type II singularity of the branch followed (smallest scaled singular \
         value {sigma_min:.3e} < {tol}): from q alone the branch the motion took after that row cannot be decided; \
         give the body coordinates of every row (x=, which a simulation result and a results file carry)"
    )]
    BranchUndecided { row: usize, sigma_min: f64, tol: f64 },
    /// A computation along the rows of a trajectory failed at one row.
    #[error("row {row} (t = {} s): {source}", Time(*.t))]
    Row { row: usize, t: f64, source: Box<Error> },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Smallest relative tolerance: 100 machine epsilons (below it the error test asks for more
/// than double precision holds).
pub const MIN_RTOL: f64 = 100.0 * f64::EPSILON;
/// Largest relative tolerance: above it the error test accepts a step whose error exceeds
/// the state itself (rtol = 1, the loosest meaningful, is the benchmarks' cheapest scan point).
pub const MAX_RTOL: f64 = 1.0;
/// Most step attempts a run may be given: days of computing at a microsecond a step.
pub const MAX_STEPS: f64 = 1e12;

/// Most output times an `output_dt` may ask for over a run: a guard against output_dt = 1e-12
/// or t_end = 1e30 s, whose grid would not fit in memory (8e8 bytes at this count).
pub const MAX_OUTPUTS: f64 = 1e8;

/// A setting of a simulation given as a number: the run's times and the integrator's options.
/// Each has one rule ([`Setting::check`]), the same for every caller: `Overrides` (the Python
/// API, the batch runner, the CLI through the glue), a Rust user's `Settings`, and the
/// integrator's `Options::validate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Setting {
    /// End time of a run (s).
    TEnd,
    /// Relative tolerance (dimensionless).
    Rtol,
    /// Absolute tolerance (units of the state).
    Atol,
    /// Fixed step (s).
    Dt,
    /// Interval of the output times (s).
    OutputDt,
    /// Most step attempts, accepted plus rejected.
    MaxSteps,
    /// First trial step (s).
    H0,
    /// Largest step (s).
    HMax,
    /// Smallest step, relative to the time scale.
    HMin,
}

impl Setting {
    /// Every setting, in the order of the Python API's arguments.
    pub const ALL: [Setting; 9] = [
        Setting::TEnd,
        Setting::Rtol,
        Setting::Atol,
        Setting::Dt,
        Setting::OutputDt,
        Setting::MaxSteps,
        Setting::H0,
        Setting::HMax,
        Setting::HMin,
    ];

    /// Its name, as the Python API, the CLI and model files spell it.
    pub fn name(self) -> &'static str {
        match self {
            Setting::TEnd => "t_end",
            Setting::Rtol => "rtol",
            Setting::Atol => "atol",
            Setting::Dt => "dt",
            Setting::OutputDt => "output_dt",
            Setting::MaxSteps => "max_steps",
            Setting::H0 => "h0",
            Setting::HMax => "h_max",
            Setting::HMin => "h_min",
        }
    }

    /// The setting called `name`.
    pub fn from_name(name: &str) -> Option<Setting> {
        Setting::ALL.into_iter().find(|s| s.name() == name)
    }

    /// `value` if it keeps this setting's rule, else the error naming the setting and the fix.
    /// The times and tolerances are finite numbers > 0 (t_end after the start at 0 s): with
    /// atol = 0 a state component passing through 0 has no error scale and the step
    /// collapses; rtol is in [[`MIN_RTOL`], [`MAX_RTOL`]]; max_steps an integer in 1..=[`MAX_STEPS`].
    pub fn check(self, value: f64) -> Result<f64, SettingError> {
        match self.broken(value) {
            Some(rule) => Err(SettingError::new(self, value, rule)),
            None => Ok(value),
        }
    }

    /// t_end's rule for a run that starts at t0 (s): finite and after t0 ([`Setting::check`]
    /// at the start 0 s that every run made from `Overrides` has).
    pub fn check_end(t0: f64, t_end: f64) -> Result<f64, SettingError> {
        if t0 == 0.0 {
            return Setting::TEnd.check(t_end);
        }
        if t0.is_finite() && t_end.is_finite() && t_end > t0 {
            return Ok(t_end);
        }
        Err(SettingError::new(
            Setting::TEnd,
            t_end,
            format!("must be a finite number > t0 = {} (the end time in s)", Time(t0)),
        ))
    }

    /// output_dt's rule over a run from t0 to t_end (s): its own ([`Setting::check`]), and at
    /// most [`MAX_OUTPUTS`] output times.
    pub fn check_outputs(t0: f64, t_end: f64, output_dt: f64) -> Result<f64, SettingError> {
        let h = Setting::OutputDt.check(output_dt)?;
        let count = (t_end - t0) / h;
        if count > MAX_OUTPUTS {
            let rule = format!(
                "gives (t_end - t0) / output_dt = {count:.3e} output times, more than {MAX_OUTPUTS:e}: use a larger \
                 output_dt or a shorter t_end"
            );
            return Err(SettingError::new(Setting::OutputDt, h, rule));
        }
        Ok(h)
    }

    /// dt's rule with the run's step budget: a fixed step dt (s) that needs more than
    /// `max_steps` steps from t0 to t_end cannot finish, which is known before the first step.
    pub fn check_fixed_steps(t0: f64, t_end: f64, dt: f64, max_steps: usize) -> Result<f64, SettingError> {
        let count = (t_end - t0) / dt;
        // usize to f64 is exact up to 2^53, far above MAX_STEPS.
        if count > max_steps as f64 {
            let rule = format!(
                "is a fixed step: (t_end - t0) / dt = {count:.3e} steps to t_end = {} s, more than max_steps = \
                 {max_steps}: use a larger dt, a shorter t_end, or raise max_steps (at most {MAX_STEPS:e})",
                Time(t_end)
            );
            return Err(SettingError::new(Setting::Dt, dt, rule));
        }
        Ok(dt)
    }

    /// The rule `value` breaks, if any.
    fn broken(self, v: f64) -> Option<&'static str> {
        let positive = v.is_finite() && v > 0.0;
        match self {
            Setting::TEnd => (!positive).then_some("must be a finite number > 0 (the end time in s)"),
            Setting::Rtol if !positive => Some("must be a finite number > 0 (try 1e-8)"),
            Setting::Rtol if v > MAX_RTOL => {
                Some("must be at most 1: above it a step's error may exceed the state itself (try 1e-6)")
            }
            Setting::Rtol => {
                (v < MIN_RTOL).then_some("is below 100 machine epsilons and cannot be met: use rtol >= 2.3e-14")
            }
            Setting::Atol => (!positive).then_some(
                "must be a finite number > 0 (try 1e-10): with 0, a component of the state passing through 0 \
                 has no error scale and the step collapses",
            ),
            Setting::Dt => (!positive).then_some("must be a finite number > 0 (the fixed step in s)"),
            Setting::OutputDt => (!positive).then_some("must be a finite number > 0 (the output interval in s)"),
            Setting::MaxSteps => {
                (!(v.fract() == 0.0 && (1.0..=MAX_STEPS).contains(&v))).then_some("must be an integer from 1 to 1e12")
            }
            Setting::H0 => (!positive).then_some("must be a finite number > 0, or None for automatic"),
            Setting::HMax => (v.is_nan() || v <= 0.0).then_some("must be > 0 (use infinity for no limit)"),
            Setting::HMin => (!(v.is_finite() && v >= 0.0)).then_some("must be finite and >= 0 (default 1e-14)"),
        }
    }
}

/// A time (s) in a message, as short as it reads back exactly: the shortest decimal that
/// parses to the same f64, in scientific notation outside 1e-5 <= |t| < 1e16 (where f64's
/// Display would write 1e300 in 301 digits and 1e-300 with 300 zeros), as Python prints it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Time(pub f64);

impl std::fmt::Display for Time {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-5..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// A setting whose value breaks its rule: `"{name} = {value} {rule}"`.
#[derive(Debug, Clone, Error, PartialEq)]
#[error("{} = {value} {rule}", .setting.name())]
pub struct SettingError {
    pub setting: Setting,
    /// The value as given (integers without a decimal point; "none" for a missing one).
    pub value: String,
    /// What it must be, and how to mend it.
    pub rule: String,
}

impl SettingError {
    /// `setting` = `value` breaks `rule`.
    pub fn new(setting: Setting, value: f64, rule: impl Into<String>) -> Self {
        // Whole numbers as integers (0, -1, 10000), others by their shortest exact form
        // (1e-9, NaN, inf): as a caller wrote them.
        let value = if is_whole(value) { format!("{value:.0}") } else { format!("{value:?}") };
        SettingError { setting, value, rule: rule.into() }
    }

    /// `setting` is missing where it is needed (`rule` says why and what to give).
    pub fn missing(setting: Setting, rule: impl Into<String>) -> Self {
        SettingError { setting, value: "none".to_string(), rule: rule.into() }
    }
}

/// A whole number small enough to print exactly as an integer.
fn is_whole(v: f64) -> bool {
    v.fract() == 0.0 && v.abs() < 1e15
}
