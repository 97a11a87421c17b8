//! Small dense linear algebra on caller-owned buffers.
//!
//! Hand-written on purpose: the systems here have 3 to ~40 unknowns and are factorised
//! several times per right-hand-side evaluation. nalgebra's LU allocates its permutation on
//! every call for dynamic sizes and faer is tuned for large matrices, while an in-place
//! factorisation into the workspace keeps a forward-dynamics evaluation allocation-free and
//! well under a microsecond for a four-bar. nalgebra is still used where allocation does not
//! matter (singular values for the singularity measures and the structural analysis).

mod block_lu;
mod cholesky;
mod lu;
mod pivot;
mod sink;

pub use block_lu::{BlockLu, BlockSink, MAX_COLUMNS};
pub use cholesky::{cholesky_envelope, cholesky_in_place, cholesky_solve, cholesky_solve_envelope};
pub use lu::{lu_factor, lu_solve, lu_solve_transpose, Lu, LuError, Scalar};
pub use pivot::pivot_columns;
pub use sink::{Dense, Sink};
