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
    /// Options that cannot work together (a fixed-step method without `dt`, rtol <= 0...).
    #[error("invalid option: {0}")]
    Options(String),
    /// A user-supplied drive function failed (its message is kept).
    #[error("drive function failed at t = {t}: {message}")]
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
    #[error("row {row} (t = {t} s): {source}")]
    Row { row: usize, t: f64, source: Box<Error> },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
