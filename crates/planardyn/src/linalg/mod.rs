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
mod gram;
mod lu;
mod pivot;
mod sink;
mod sparse_pivot;

pub use block_lu::{BlockLu, BlockSink, MAX_COLUMNS};
pub use cholesky::{
    cholesky_envelope, cholesky_envelope_fixed, cholesky_in_place, cholesky_solve, cholesky_solve_envelope,
    cholesky_solve_envelope_fixed,
};
pub use gram::{gamma, gram_exceeds, rounding_shift};
pub use lu::{lu_factor, lu_solve, lu_solve_transpose, Lu, LuError, Scalar};
pub use pivot::pivot_columns;
pub use sink::{Dense, Sink};
pub use sparse_pivot::{eliminate, Elimination, SparseRow};

/// `dst.copy_from_slice(src)` for the few values of a state or its coordinates (m, 2m + 1) as
/// moves: `copy_from_slice` of a length known only at run time is a call to the C library's
/// `memcpy`, about 12 instructions for one value (issue 25's instruction counts, which make
/// such copies several times an evaluation). Panics as `copy_from_slice` does if the lengths
/// differ.
#[inline(always)]
pub fn copy_small(dst: &mut [f64], src: &[f64]) {
    match src.len() {
        1 => copy_fixed::<1>(dst, src),
        2 => copy_fixed::<2>(dst, src),
        3 => copy_fixed::<3>(dst, src),
        4 => copy_fixed::<4>(dst, src),
        5 => copy_fixed::<5>(dst, src),
        _ => dst.copy_from_slice(src),
    }
}

#[inline(always)]
fn copy_fixed<const N: usize>(dst: &mut [f64], src: &[f64]) {
    let dst: &mut [f64; N] = dst.try_into().expect("copy_small: destination and source lengths differ");
    *dst = src.try_into().expect("copy_small: the source has N values");
}
