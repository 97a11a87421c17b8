//! Kinematics: position analysis, velocity and acceleration analogues, points, singularities,
//! the end effector and its inverse kinematics.
//! One algorithm a file; all of them work on the body coordinates x (3n values).

pub mod alt_charts;
pub mod analogues;
pub mod branch_path;
pub mod closed_form;
mod column_reach;
pub mod constraints;
pub mod dyads;
pub mod effector;
pub mod frame;
pub mod group_sigma;
pub mod phi_pivots;
pub mod position;
pub mod rank;
pub mod rank_proof;
pub mod singularity;
pub mod system;
pub mod third;
pub mod u_support;

pub use analogues::{acceleration_analogues, convective, velocity_analogues};
pub use branch_path::BranchPath;
pub use closed_form::ClosedForm;
pub use constraints::{coordinate_rates, coordinates, Chart};
pub use effector::{Effector, EffectorError, EffectorState, SINGULAR_TOL};
pub use frame::Frame;
pub use position::{
    assemble, assemble_from, assemble_into, continue_to, scaled_distance, scaled_distances, solve_position,
    MAX_CORRECTION, POSITION_TOL,
};
pub use singularity::{
    partition_sigma_below_with, passive_sigma_below_with, passive_sigma_min, passive_sigma_min_with, select_partition,
    sigma_min, sigma_min_with,
};
pub use system::System;
pub use u_support::USupport;
