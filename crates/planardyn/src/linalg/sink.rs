//! Where the entries of a sparse matrix being assembled go: a dense row-major matrix
//! ([`Dense`]), or straight into the storage of a block factorisation
//! ([`BlockSink`](super::BlockSink)), so that the position Jacobian is never laid out densely
//! in a simulation.

/// A receiver of matrix entries.
pub trait Sink {
    /// Add `v` to entry (row, col).
    fn add(&mut self, row: usize, col: usize, v: f64);
}

/// A row-major matrix with `ncols` columns as a [`Sink`].
pub struct Dense<'a> {
    pub j: &'a mut [f64],
    pub ncols: usize,
}

impl Sink for Dense<'_> {
    #[inline]
    fn add(&mut self, row: usize, col: usize, v: f64) {
        self.j[row * self.ncols + col] += v;
    }
}
