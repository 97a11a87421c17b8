//! Stiffness and vibration of the mechanism with its compliances (`model::compliance`;
//! docs/stiffness.md): the compliant mechanism in redundant coordinates (`model`), its
//! elastostatics at a pose (`stiffness`), natural and small-oscillation modes (`modes`), and
//! the linearised state-space model of the rigid mechanism (`linearize`). A layer above the
//! dynamics and the structure report: it uses the kinematics (assembly, analogues), the pair
//! kinds' exact first and second derivatives, and the dynamics' exact derivatives.
//!
//! nalgebra's dense decompositions (SVD, symmetric eigen, Cholesky) are used throughout: these
//! are analyses at a pose, on matrices of a few dozen columns, where allocating is of no
//! consequence (unlike the hand-written in-place factorisations of `linalg`).

pub mod linearize;
mod model;
pub mod modes;
pub mod stiffness;

pub use linearize::{linearize, StateSpace};
pub use model::Output;
pub use modes::{equilibrium, modes, small_oscillations, Modes};
pub use stiffness::{deflection, stiffness, weakest_direction, CartesianStiffness, Deflection, Load, Weakest};
