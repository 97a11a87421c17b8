//! Stiffness and vibration of the mechanism with its compliances (`model::compliance`;
//! docs/stiffness.md): the compliant mechanism in redundant coordinates (`model`), its
//! elastostatics at a pose (`stiffness`), natural and small-oscillation modes (`modes`), their maps over two coordinates (`map_rows`), the
//! linearised state-space models of the rigid and the compliant mechanism (`linearize`), and the simulation with
//! compliant drives (`flexible`). A layer above the dynamics, the structure report, the
//! integrators and the simulation: it uses the kinematics (assembly, analogues), the pair
//! kinds' exact first and second derivatives, the dynamics' exact derivatives, and the
//! integrators.
//!
//! nalgebra's dense decompositions (SVD, symmetric eigen, Cholesky) are used throughout: these
//! are analyses at a pose, on matrices of a few dozen columns, where allocating is of no
//! consequence (unlike the hand-written in-place factorisations of `linalg`).

pub mod flexible;
pub mod linearize;
pub mod map_rows;
mod model;
pub mod modes;
pub mod stiffness;

pub use flexible::{simulate_flexible, FlexibleOde, FlexibleRun};
pub use linearize::{linearize, linearize_compliant, StateSpace};
pub use map_rows::{map_rows, MapValue};
pub use model::Output;
pub use modes::{equilibrium, modes, modes_about, small_oscillations, Modes};
pub use stiffness::{
    deflection, stiffness, stiffness_about, weakest_direction, CartesianStiffness, Deflection, Load, Weakest,
};
