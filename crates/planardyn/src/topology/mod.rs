//! Topology: what the graph of the pairs tells without a configuration. The independent loops
//! of the body-pair graph, and the Assur groups: the blocks of the block-triangular form of
//! the position Jacobian with the inputs locked, which the closed forms of `kinematics` solve
//! one after another. Above the model, below kinematics.

pub mod assur;
pub mod loops;

pub use assur::AssurGroup;
pub use loops::Loop;
