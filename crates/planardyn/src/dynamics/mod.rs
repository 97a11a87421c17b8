//! Dynamics (docs/formulation.md): applied forces, A and b, forward and inverse dynamics,
//! pair reactions, energies, task-space inverse dynamics along an end-effector path. Stages
//! run in a [`crate::Workspace`].

pub mod energy;
pub mod forces;
pub mod forward;
pub mod inverse;
pub mod reactions;
pub mod regular;
pub mod task;

pub use energy::{kinetic_energy, potential_energy};
pub use forces::{applied_forces, Drives, ModelDrives};
pub use forward::{dynamic_stages, forward, mass_matrix};
pub use inverse::inverse;
pub use reactions::reactions;
pub use regular::{finite, type_ii_measure, SINGULAR_SIGMA};
pub use task::{SingularityKind, TaskError, TaskPath, TaskSolution};
