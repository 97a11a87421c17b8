//! Dynamics (docs/formulation.md): applied forces, A and b, forward and inverse dynamics,
//! forward dynamics with coordinates driven by motion,
//! pair reactions, energies, task-space inverse dynamics along an end-effector path. Stages
//! run in a [`Workspace`]: the kinematic frame and the dynamics' buffers.

pub mod along;
pub mod derivatives;
pub mod energy;
pub mod evaluate;
pub mod force_rates;
pub mod forces;
pub mod forward;
pub mod friction;
mod gears;
pub mod inverse;
mod loss_buffers;
mod loss_columns;
mod losses;
pub mod motion;
pub mod prescribed;
pub mod query;
pub mod reactions;
pub mod redundant;
pub mod regressor;
pub mod regular;
pub mod stages;
pub mod task;
pub mod transmission;
pub mod workspace;

pub use along::{along, carried_points, point_motion, Along, FixedDrives, Rows};
pub use derivatives::{forward_derivatives, inverse_derivatives, motion_derivatives, Jacobians, PowerRates};
pub use energy::{kinetic_energy, potential_energy};
pub use evaluate::{evaluate, map_rows, sigma_rows, Evaluation, MapGrid, MapRows};
pub use forces::{applied_forces, Drives, ModelDrives};
pub use forward::{dynamic_stages, forward};
pub use inverse::{inverse, inverse_at_rates, rates_mismatch};
pub use loss_buffers::LossBuffers;
pub use losses::motor_torques;
pub use motion::{Motion, MotionFunction, Prescribed};
pub use prescribed::{forward_prescribed, prescribed_sigma_min};
pub use reactions::reactions;
pub use regular::{finite, type_ii_measure, SINGULAR_SIGMA};
pub use stages::{kinematic_stages, mass_matrix};
pub use task::{SingularityKind, TaskError, TaskPath, TaskSolution};
pub use transmission::motor_torque;
pub use workspace::Workspace;
