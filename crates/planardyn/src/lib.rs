//! # planardyn
//!
//! Exact minimal-coordinate dynamics of planar closed-chain mechanisms and planar parallel
//! robots, after Baigunchekov & Baigunchekov, "Differential equations of motion of planar
//! executive mechanisms of parallel manipulating robots": per body M_i = diag(m, m, I),
//! velocity analogues u_j and acceleration analogues w_jk of the centres of mass,
//! A = U^T M U, b = U^T f - U^T M sum_jl qd_j qd_l w_jl, qdd = A^-1 b. The equations, by
//! the paper's numbers, its misprints and the conventions used here: `docs/formulation.md`.
//!
//! A mechanism is described as it is drawn (a model file, see `docs/model-format.md`),
//! validated once into an immutable [`Mechanism`]; every computation runs in a
//! [`Workspace`] of buffers sized once. SI units and radians throughout.
//!
//! The modules are layers, bottom to top, each using only those below it (declared in
//! `crates/layers.toml`, checked by `tools/rust_layers.py` in `./dev test`): [`error`] and
//! [`linalg`]; the [`model`], pure data with the pair and load kinds; [`topology`];
//! [`kinematics`]; [`dynamics`]; the [`structure`] report; [`integrate`] (independent of the
//! mechanics); [`simulate`]; [`elastic`] (stiffness, vibration, compliant drives); [`batch`]; and the [`loader`] on top.

// `!(x > 0.0)` is how the validators reject NaN along with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

/// `impl Clone` for a struct of buffers, field by field, with a `clone_from` that copies each
/// field into the target's own (a derived `clone_from` is `*self = source.clone()`: it allocates
/// every buffer anew and frees the old ones). Copying a saved evaluation or a kept analysis into
/// one of the same sizes then allocates nothing. The struct literal in `clone` names every
/// field, so a field left out of the list does not compile.
macro_rules! clone_reusing {
    ($t:ty { $($f:ident),+ $(,)? }) => {
        impl Clone for $t {
            fn clone(&self) -> Self {
                Self { $($f: self.$f.clone()),+ }
            }

            fn clone_from(&mut self, source: &Self) {
                $(self.$f.clone_from(&source.$f);)+
            }
        }
    };
}

pub mod batch;
pub mod dynamics;
pub mod elastic;
pub mod error;
pub mod integrate;
pub mod kinematics;
pub mod linalg;
pub mod loader;
pub mod model;
pub mod simulate;
pub mod structure;
pub mod topology;
pub mod units;

pub use dynamics::Workspace;
pub use error::{Error, KinematicsError, ModelError, Result, SingularityKind};
pub use loader::{analyse_spec, build, load, loads, Format};
pub use model::{Mechanism, MechanismSpec};
pub use structure::{analyse, Structure};
