//! Gaussian elimination with complete pivoting on a sparse matrix held by rows: the pivots of
//! [`pivot_columns`](super::pivot_columns), bit for bit, at a cost that follows the non-zeros.
//!
//! The dense version scans every remaining row at every step and keeps rows x cols values:
//! O(n^2) for a chain of n bodies, the loader's second largest cost once the rank test left the
//! SVD. Here the rows keep their non-zeros only, each column lists the rows that hold it, and the
//! rows' largest entries sit in an ordered set keyed as the dense scan breaks ties (the largest
//! value, then the first row in the current order, which the pivot swaps change). An update
//! does the dense one's arithmetic on the entries where the pivot row is non-zero (elsewhere
//! the dense update subtracts l * 0, which changes no value), so the values and the pivots are
//! the dense elimination's.
//!
//! Hand-written: a sparse LU from a library (faer's, sprs') picks its own pivots, for fill or
//! threshold partial pivoting; the loader needs the dense complete pivoting's rows, ties
//! included (the independent constraints it reports and keeps), and the rounding bound of
//! `rank_proof` needs the factor's row lengths and norms, which those do not report.

use std::collections::BTreeSet;

/// A sparse row: (column, value), in no particular order.
pub type SparseRow = Vec<(usize, f64)>;

/// The state of an elimination after its pivots: the rows (a pivot row is frozen as it was at
/// its step: U's row there, over its pivot column and the columns then free), the pivots in
/// order, and what the rounding bound of the factorisation needs.
pub struct Elimination {
    pub rows: Vec<SparseRow>,
    /// (row, column) of each step.
    pub pivots: Vec<(usize, usize)>,
    /// The step at which each column became a pivot column (usize::MAX for none).
    pub col_step: Vec<usize>,
    /// Whether each row was a pivot row.
    pub done: Vec<bool>,
    /// Squared Frobenius norms of L (the multipliers) and of U (the pivot rows at their steps).
    pub l_norm2: f64,
    pub u_norm2: f64,
    /// The most updates any one row received: every entry is a sum of at most that many
    /// products plus its original value.
    pub max_updates: usize,
}

/// The first largest |entry| of `row` among the free columns: (value, column); (0, MAX) if none.
fn row_max(row: &[(usize, f64)], free: &[bool]) -> (f64, usize) {
    let (mut best, mut col) = (0.0, usize::MAX);
    for &(c, v) in row {
        let v = v.abs();
        if free[c] && (v > best || (v == best && v > 0.0 && c < col)) {
            (best, col) = (v, c);
        }
    }
    (best, col)
}

/// The ordered set's key of a row whose largest entry is `v` at position `pos`: the first key
/// is the dense scan's choice (largest value, then first position). |v| >= 0, so its bits
/// order as its value.
fn key(v: f64, pos: usize) -> (u64, usize) {
    (!v.to_bits(), pos)
}

/// Eliminate `rows` (a matrix of `ncols` columns) with complete pivoting while the largest
/// remaining |entry| exceeds `above` and fewer than `count` pivots are taken.
pub fn eliminate(mut rows: Vec<SparseRow>, ncols: usize, above: f64, count: usize) -> Elimination {
    let n = rows.len();
    let mut free = vec![true; ncols];
    let mut col_rows: Vec<Vec<usize>> = vec![Vec::new(); ncols];
    for (r, row) in rows.iter().enumerate() {
        for &(c, _) in row {
            col_rows[c].push(r);
        }
    }
    let mut best: Vec<(f64, usize)> = rows.iter().map(|row| row_max(row, &free)).collect();
    let (mut pos, mut at): (Vec<usize>, Vec<usize>) = ((0..n).collect(), (0..n).collect());
    let mut queue: BTreeSet<(u64, usize)> = (0..n).map(|r| key(best[r].0, r)).collect();
    let mut e = Elimination {
        rows: Vec::new(),
        pivots: Vec::new(),
        col_step: vec![usize::MAX; ncols],
        done: vec![false; n],
        l_norm2: 0.0,
        u_norm2: 0.0,
        max_updates: 0,
    };
    let mut updates = vec![0usize; n];
    // Where each column sits in the row being updated (usize::MAX: absent).
    let mut slot = vec![usize::MAX; ncols];
    for k in 0..n.min(count) {
        let Some(&(kv, kp)) = queue.first() else { break };
        let pr = at[kp];
        let (value, col) = best[pr];
        if !(value > above) {
            break;
        }
        queue.remove(&(kv, kp));
        // The dense version swaps the pivot row into position k and the row there into its place.
        if kp != k {
            let moved = at[k];
            queue.remove(&key(best[moved].0, k));
            (at[kp], pos[moved]) = (moved, kp);
            queue.insert(key(best[moved].0, kp));
        }
        (at[k], pos[pr]) = (pr, k);
        free[col] = false;
        e.col_step[col] = k;
        e.pivots.push((pr, col));
        e.done[pr] = true;
        let pivot_row = std::mem::take(&mut rows[pr]);
        let diag = pivot_row.iter().find(|&&(c, _)| c == col).expect("the pivot is an entry of its row").1;
        e.u_norm2 += diag * diag + pivot_row.iter().filter(|&&(c, _)| free[c]).map(|&(_, v)| v * v).sum::<f64>();
        // The pivot column is no longer free, so no fill-in lands in its own list.
        for r in std::mem::take(&mut col_rows[col]) {
            if e.done[r] {
                continue;
            }
            let row = &mut rows[r];
            let Some(&(_, rc)) = row.iter().find(|&&(c, _)| c == col) else { continue };
            let l = rc / diag;
            if l != 0.0 {
                e.l_norm2 += l * l;
                updates[r] += 1;
                for (i, &(c, _)) in row.iter().enumerate() {
                    slot[c] = i;
                }
                for &(c, pv) in pivot_row.iter().filter(|&&(c, _)| free[c]) {
                    if slot[c] == usize::MAX {
                        row.push((c, 0.0 - l * pv));
                        col_rows[c].push(r);
                    } else {
                        row[slot[c]].1 -= l * pv;
                    }
                }
                for &(c, _) in row.iter() {
                    slot[c] = usize::MAX;
                }
            }
            if l != 0.0 || best[r].1 == col {
                queue.remove(&key(best[r].0, pos[r]));
                best[r] = row_max(row, &free);
                queue.insert(key(best[r].0, pos[r]));
            }
        }
        rows[pr] = pivot_row;
    }
    e.max_updates = updates.into_iter().max().unwrap_or(0);
    e.rows = rows;
    e
}

impl Elimination {
    /// Squared Frobenius norm of the Schur complement: the rows not pivoted, over the columns
    /// still free.
    pub fn schur_norm2(&self) -> f64 {
        let free = |c: usize| self.col_step[c] == usize::MAX;
        self.rows
            .iter()
            .zip(&self.done)
            .filter(|(_, &d)| !d)
            .flat_map(|(row, _)| row.iter().filter(|&&(c, _)| free(c)).map(|&(_, v)| v * v))
            .sum()
    }

    /// The vector lambda with lambda[o] = 1 for the free column `o`, zero on the other free
    /// columns, and U lambda = 0 on the pivot rows (back substitution, from the last step up,
    /// over the steps it reaches only): the rows times lambda then leave the Schur complement's
    /// column o. `u_cols[c]`: the steps whose pivot row holds column c (from [`Self::u_columns`]).
    /// Returns the non-zeros (column, value).
    pub fn null_vector(&self, o: usize, u_cols: &[Vec<usize>], lambda: &mut [f64]) -> Vec<(usize, f64)> {
        let mut heap: std::collections::BinaryHeap<usize> = u_cols[o].iter().copied().collect();
        let mut out = vec![(o, 1.0)];
        lambda[o] = 1.0;
        let mut last = usize::MAX;
        while let Some(t) = heap.pop() {
            if t == last {
                continue;
            }
            last = t;
            let (pr, col) = self.pivots[t];
            let mut s = 0.0;
            let mut diag = 0.0;
            for &(c, v) in &self.rows[pr] {
                if c == col {
                    diag = v;
                } else if self.col_step[c] > t {
                    s += v * lambda[c];
                }
            }
            let value = -s / diag;
            if value != 0.0 {
                lambda[col] = value;
                out.push((col, value));
                heap.extend(u_cols[col].iter().copied().filter(|&s| s < t));
            }
        }
        for &(c, _) in &out {
            lambda[c] = 0.0;
        }
        out
    }

    /// For each column, the steps whose pivot row holds it as a column then free (U's column
    /// pattern off the diagonal).
    pub fn u_columns(&self, ncols: usize) -> Vec<Vec<usize>> {
        let mut cols = vec![Vec::new(); ncols];
        for (t, &(pr, col)) in self.pivots.iter().enumerate() {
            for &(c, _) in &self.rows[pr] {
                if c != col && self.col_step[c] > t {
                    cols[c].push(t);
                }
            }
        }
        cols
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::pivot_columns;

    #[test]
    fn picks_the_dense_eliminations_columns() {
        // Banded matrices like a chain's Jacobian, with ties (small integers) and a repeated
        // row (rank deficient), as pivot.rs's own test; and the same with the rows shuffled.
        let mut seed = 777u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 33) % 7) as f64 - 3.0
        };
        for (rows, cols) in [(8, 9), (20, 21), (30, 33), (12, 12), (40, 25)] {
            let mut a = vec![0.0; rows * cols];
            for r in 0..rows {
                for c in r..(r + 3).min(cols) {
                    a[r * cols + c] = next();
                }
                a[r * cols + (r * 7) % cols] += next();
            }
            let dup = a[..cols].to_vec();
            a[(rows - 1) * cols..].copy_from_slice(&dup);
            let sparse: Vec<SparseRow> = a
                .chunks_exact(cols)
                .map(|row| row.iter().enumerate().filter(|(_, v)| **v != 0.0).map(|(c, &v)| (c, v)).collect())
                .collect();
            let e = eliminate(sparse, cols, 0.0, rows);
            let columns: Vec<usize> = e.pivots.iter().map(|p| p.1).collect();
            assert_eq!(columns, pivot_columns(&mut a, rows, cols, rows), "{rows} x {cols}");
        }
    }

    #[test]
    fn a_null_vector_of_a_repeated_row_pair_is_their_difference() {
        // Rows of A^T... here A's columns 0 and 2 are equal: lambda = e0 - e2 (or e2 - e0) with
        // A lambda = 0 exactly; column 1 is independent.
        let rows: Vec<SparseRow> = vec![vec![(0, 1.0), (1, 2.0), (2, 1.0)], vec![(0, 3.0), (1, -1.0), (2, 3.0)]];
        let e = eliminate(rows.clone(), 3, 1e-12, 3);
        assert_eq!(e.pivots.len(), 2);
        assert_eq!(e.schur_norm2(), 0.0);
        let free: Vec<usize> = (0..3).filter(|&c| e.col_step[c] == usize::MAX).collect();
        assert_eq!(free.len(), 1);
        let mut lambda = vec![0.0; 3];
        let v = e.null_vector(free[0], &e.u_columns(3), &mut lambda);
        for row in &rows {
            let s: f64 = v.iter().map(|&(c, x)| x * row.iter().find(|e| e.0 == c).map_or(0.0, |e| e.1)).sum();
            assert_eq!(s, 0.0, "A lambda = {s}");
        }
        assert_eq!(v.len(), 2, "{v:?}");
        assert!(lambda.iter().all(|&x| x == 0.0), "the scratch is left cleared");
    }
}
