//! Task-space inverse dynamics of one variant: the core's [`crate::dynamics::task`], run on the
//! batch pool so that many designs of a robot on one end-effector motion (or many motions of
//! one robot) solve in parallel without Python.

pub use crate::dynamics::task::{solve, SingularityKind, TaskError, TaskPath, TaskSolution};
