//! Errors of the planardyn core. Every variant carries the data a user needs to
//! find the problem and says what to try next; nothing in the crate panics on user input.

use thiserror::Error;

/// A model that cannot be built: a malformed file, or a drawing that is not a mechanism.
#[derive(Debug, Clone, Error, PartialEq)]
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

/// A kinematic computation that failed at a given configuration.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum KinematicsError {
    /// Newton's method on the loop-closure equations did not converge.
    #[error(
        "position analysis did not converge (residual {residual:.3e} after {iterations} iterations): \
         the mechanism cannot be assembled at these coordinates, or they lie on another branch; \
         try values closer to the drawing or a smaller step"
    )]
    AssemblyFailed { residual: f64, iterations: usize },
    /// The Jacobian of the constraints with the given coordinates fixed is singular.
    #[error(
        "the mechanism is singular here (smallest scaled singular value {sigma_min:.3e}): \
         {what}"
    )]
    Singular { sigma_min: f64, what: String },
    /// An argument with the wrong length or a non-finite value.
    #[error("{0}")]
    BadArgument(String),
}

/// Errors returned by the dynamics and simulation entry points.
#[derive(Debug, Clone, Error, PartialEq)]
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
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
