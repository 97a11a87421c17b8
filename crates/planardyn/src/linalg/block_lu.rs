//! Block-triangular LU of a sparse square matrix with a fixed pattern (Duff & Reid's block
//! triangular form): rows and columns are permuted so that the matrix is block lower
//! triangular; only the diagonal blocks are factorised (dense, partial pivoting within the
//! block), the entries left of them are kept as a sparse list, and a solve runs block after
//! block. The permutation comes from the pattern alone: a maximum matching puts a structural
//! non-zero on every diagonal position, and the strongly connected components of the
//! resulting dependency graph, in topological order, are the blocks.
//!
//! For the position Jacobian of a mechanism the blocks are its input links and its Assur
//! groups in the order they can be solved (a four-bar: the crank, then the coupler-rocker
//! dyad; a 3-RRR: three cranks, then the class-III triad), so the cost of a factorisation
//! falls from n^3 to the sum of the groups' sizes cubed.
//!
//! Hand-written: sparse LU crates (faer's, ...) do a symbolic analysis and dispatch per call
//! that cost more than the whole factorisation at these sizes (n = 9 to ~60, microseconds);
//! the graph algorithms come from petgraph.

use super::lu::{lu_factor, lu_solve, lu_solve_transpose, LuError};
use super::sink::Sink;
use petgraph::algo::{maximum_matching, tarjan_scc};
use petgraph::graph::{DiGraph, NodeIndex, UnGraph};

/// The block-triangular factors of an n x n matrix, in buffers sized once per pattern.
#[derive(Debug)]
pub struct BlockLu {
    n: usize,
    /// Permuted position -> original row, and -> original column.
    row: Vec<usize>,
    col: Vec<usize>,
    /// Block k spans the permuted positions `start[k]..start[k + 1]`.
    start: Vec<usize>,
    /// The diagonal blocks, block k row-major from `lu_at[k]`, then the entries left of
    /// them (from `off_base`, in `off_col` order). Filled through [`BlockLu::sink`]; the blocks are then
    /// factorised in place: unit lower L below the diagonal, U on and above it, of the
    /// block's rows in pivoted order.
    store: Vec<f64>,
    lu_at: Vec<usize>,
    off_base: usize,
    /// Where the entries of each row go: row r's pattern entries are `dest[dest_at[r]..dest_at[r + 1]]`,
    /// each (its column, its slot in `store`), in the order the pattern lists them. Per row, not
    /// an n x n table: the pattern's O(entries) (a dense table was 8 MB and a fifth of the build
    /// at the ladder's n = 1434), and a row has a few entries (a pair's row: its two bodies').
    dest_at: Vec<usize>,
    dest: Vec<(u32, u32)>,
    /// Row pivots of the last factorisation, per permuted position, local to its block.
    piv: Vec<usize>,
    /// The permuted position whose row the factor row at each position is (the block's row
    /// pivots composed into one gather index).
    src: Vec<usize>,
    /// Entries of the row at permuted position p left of its diagonal block:
    /// `off_at[p]..off_at[p + 1]` index `off_col` (permuted column) and the values
    /// `store[off_base..]`.
    off_at: Vec<usize>,
    off_col: Vec<usize>,
    /// 1 / U_ii, per permuted position.
    inv_diag: Vec<f64>,
    /// The solution in permuted column order while a solve runs, up to [`MAX_COLUMNS`]
    /// right-hand sides interleaved (`work[i * R + r]`).
    work: Vec<f64>,
    /// Whether `work` is all zero: a solve over some blocks leaves it so (it reads the
    /// unsolved blocks' values as 0), so a sequence of them costs their blocks only.
    work_clean: bool,
}

clone_reusing!(BlockLu {
    n,
    row,
    col,
    start,
    store,
    lu_at,
    off_base,
    dest_at,
    dest,
    piv,
    src,
    off_at,
    off_col,
    inv_diag,
    work,
    work_clean
});

/// Row and column scales applied on the way in and out of a solve (see [`BlockLu::sink`]).
type Scales<'a> = Option<(&'a [f64], &'a [f64])>;

/// Right-hand sides solved in one sweep (the velocity analogues of a 3-DOF robot).
pub const MAX_COLUMNS: usize = 3;

/// The entries of the matrix to factorise, scaled and written into the blocks as they come.
pub struct BlockSink<'a> {
    store: &'a mut [f64],
    dest_at: &'a [usize],
    dest: &'a [(u32, u32)],
    rs: &'a [f64],
    cs: &'a [f64],
}

impl Sink for BlockSink<'_> {
    /// Add `v` (of the unscaled matrix) to entry (row, col). An entry outside the pattern
    /// is a bug in the pattern: it panics in debug builds and is dropped in release ones.
    #[inline]
    fn add(&mut self, row: usize, col: usize, v: f64) {
        let entries = &self.dest[self.dest_at[row]..self.dest_at[row + 1]];
        let slot = entries.iter().find(|&&(c, _)| c as usize == col);
        debug_assert!(slot.is_some(), "entry ({row}, {col}) is outside the pattern");
        if let Some(&(_, d)) = slot {
            self.store[d as usize] += v * self.rs[row] * self.cs[col];
        }
    }
}

impl BlockLu {
    /// Analyse the pattern: `pattern[i]` lists the columns where row i may be non-zero (a
    /// superset of the true non-zeros is fine; a missing one is not). A structurally singular
    /// pattern (no perfect matching) gets one dense block.
    pub fn new(pattern: &[Vec<usize>]) -> Self {
        let n = pattern.len();
        let blocks = blocks(pattern).unwrap_or_else(|| vec![((0..n).collect(), (0..n).collect())]);
        let (mut row, mut col, mut start, mut lu_at): (Vec<usize>, Vec<usize>, _, _) =
            (Vec::with_capacity(n), Vec::with_capacity(n), vec![0], Vec::new());
        let mut size = 0;
        for (rows, cols) in &blocks {
            lu_at.push(size);
            size += rows.len() * rows.len();
            row.extend(rows);
            col.extend(cols);
            start.push(row.len());
        }
        let mut position = vec![0; n];
        for (j, &c) in col.iter().enumerate() {
            position[c] = j;
        }
        let mut dest_at = Vec::with_capacity(n + 1);
        dest_at.push(0);
        for r in pattern {
            dest_at.push(dest_at.last().unwrap() + r.len());
        }
        let mut dest = vec![(0, 0); *dest_at.last().unwrap()];
        let (mut off_at, mut off_col) = (vec![0], Vec::new());
        for k in 0..blocks.len() {
            let (s0, s1) = (start[k], start[k + 1]);
            for (i, &r) in row[s0..s1].iter().enumerate() {
                for (&c, d) in pattern[r].iter().zip(&mut dest[dest_at[r]..dest_at[r + 1]]) {
                    let j = position[c];
                    let slot = if j < s0 {
                        off_col.push(j);
                        (size + off_col.len() - 1) as u32
                    } else if j < s1 {
                        (lu_at[k] + i * (s1 - s0) + j - s0) as u32
                    } else {
                        unreachable!("the block-triangular form has no entry right of a block")
                    };
                    *d = (c as u32, slot);
                }
                off_at.push(off_col.len());
            }
        }
        BlockLu {
            n,
            start,
            store: vec![0.0; size + off_col.len()],
            lu_at,
            off_base: size,
            dest_at,
            dest,
            piv: vec![0; n],
            src: (0..n).collect(),
            off_at,
            off_col,
            inv_diag: vec![0.0; n],
            work: vec![0.0; n * MAX_COLUMNS],
            work_clean: true,
            row,
            col,
        }
    }

    /// Sizes of the diagonal blocks, in solve order.
    pub fn block_sizes(&self) -> impl Iterator<Item = usize> + '_ {
        self.start.windows(2).map(|w| w[1] - w[0])
    }

    /// The diagonal blocks in solve order: each block's rows and its columns (original
    /// indices, ascending). For the position Jacobian they are the input links and the Assur
    /// groups (see `structure`).
    pub fn blocks(&self) -> impl Iterator<Item = (Vec<usize>, Vec<usize>)> + '_ {
        self.start.windows(2).map(|w| {
            let (mut rows, mut cols) = (self.row[w[0]..w[1]].to_vec(), self.col[w[0]..w[1]].to_vec());
            rows.sort_unstable();
            cols.sort_unstable();
            (rows, cols)
        })
    }

    /// Number of diagonal blocks.
    pub fn n_blocks(&self) -> usize {
        self.start.len() - 1
    }

    /// Permuted positions of block k: its local row (and column) i is position `span(k).start + i`.
    pub fn span(&self, k: usize) -> std::ops::Range<usize> {
        self.start[k]..self.start[k + 1]
    }

    /// Original row and column of each permuted position.
    pub fn position_rows(&self) -> &[usize] {
        &self.row
    }
    pub fn position_cols(&self) -> &[usize] {
        &self.col
    }

    /// Block k, row-major in its local order: the filled matrix B between [`BlockLu::sink`]
    /// and [`BlockLu::factor`], its factors after.
    pub fn block(&self, k: usize) -> &[f64] {
        let s = self.start[k + 1] - self.start[k];
        &self.store[self.lu_at[k]..self.lu_at[k] + s * s]
    }

    /// Solve B_k y = b in place with the factors of block k alone (b in its local row order,
    /// y in its local column order).
    pub fn block_solve(&self, k: usize, b: &mut [f64]) {
        lu_solve(self.block(k), b.len(), &self.piv[self.span(k)], b)
    }

    /// Solve B_k^T y = b in place with the factors of block k alone.
    pub fn block_solve_transpose(&self, k: usize, b: &mut [f64]) {
        lu_solve_transpose(self.block(k), b.len(), &self.piv[self.span(k)], b)
    }

    /// Start filling the matrix B = diag(rs) A diag(cs) to factorise: every entry is zeroed,
    /// and the sink scales the entries of A it is given. Then [`BlockLu::factor`].
    pub fn sink<'a>(&'a mut self, rs: &'a [f64], cs: &'a [f64]) -> BlockSink<'a> {
        self.store.fill(0.0);
        BlockSink { store: &mut self.store, dest_at: &self.dest_at, dest: &self.dest, rs, cs }
    }

    /// Factorise the filled matrix B block by block. A pivot of magnitude `<= tiny` (or not
    /// finite) makes it singular; the error names the original column being eliminated.
    pub fn factor(&mut self, tiny: f64) -> Result<(), LuError> {
        for k in 0..self.start.len() - 1 {
            let (s0, s1, base) = (self.start[k], self.start[k + 1], self.lu_at[k]);
            let s = s1 - s0;
            let block = &mut self.store[base..base + s * s];
            lu_factor(block, s, &mut self.piv[s0..s1], tiny)
                .map_err(|e| LuError { column: self.col[s0 + e.column] })?;
            let src = &mut self.src[s0..s1];
            for (i, p) in src.iter_mut().enumerate() {
                *p = s0 + i;
            }
            for (i, &p) in self.piv[s0..s1].iter().enumerate() {
                src.swap(i, p);
            }
            for (i, d) in self.inv_diag[s0..s1].iter_mut().enumerate() {
                *d = 1.0 / block[i * s + i];
            }
        }
        Ok(())
    }

    /// Solve B y = b in place for the factorised (scaled) B.
    pub fn solve(&mut self, b: &mut [f64]) {
        self.solve_columns::<1>(b, None, None, None)
    }

    /// Solve A x = b in place for the unscaled A: x = diag(cs) B^-1 diag(rs) b, the scalings
    /// folded into the gather and the scatter.
    pub fn solve_scaled(&mut self, b: &mut [f64], rs: &[f64], cs: &[f64]) {
        self.solve_columns::<1>(b, Some((rs, cs)), None, None)
    }

    /// As [`BlockLu::solve_scaled`] for the columns of `b` (n values each, one after the
    /// other), up to [`MAX_COLUMNS`] in one sweep: each factor entry is read once for all.
    pub fn solve_many_scaled(&mut self, b: &mut [f64], rs: &[f64], cs: &[f64]) {
        self.solve_many_over(b, rs, cs, None)
    }

    /// As [`BlockLu::solve_many_scaled`], with `reach[c]` the blocks (ascending, from
    /// [`BlockLu::reach`]) on which the solution of the c-th sweep of columns may be non-zero:
    /// only those are solved and written, the solution is 0 on the others (whose entries of `b`
    /// are left as they are).
    pub fn solve_many_over(&mut self, b: &mut [f64], rs: &[f64], cs: &[f64], reach: Option<&[Vec<usize>]>) {
        self.solve_sweeps(b, rs, cs, reach, None)
    }

    /// Solve A X = [0; I] for the unscaled A: column j of `b` gets the solution whose
    /// right-hand side is 1 in row `first_row + j` and 0 elsewhere (the right-hand side is not
    /// read from `b`). With `reach` (from [`BlockLu::reach`] of each sweep's rows) only the
    /// reached blocks are solved and only their entries of `b` written: the others must hold 0
    /// already, so that the cost is that of the reached blocks, not n per column.
    pub fn solve_unit_columns(
        &mut self,
        b: &mut [f64],
        first_row: usize,
        rs: &[f64],
        cs: &[f64],
        reach: Option<&[Vec<usize>]>,
    ) {
        self.solve_sweeps(b, rs, cs, reach, Some(first_row))
    }

    /// The sweeps of [`MAX_COLUMNS`] columns of the solves above; `unit`: the row of the first
    /// column's unit right-hand side, else the right-hand sides are `b`'s.
    fn solve_sweeps(
        &mut self,
        b: &mut [f64],
        rs: &[f64],
        cs: &[f64],
        reach: Option<&[Vec<usize>]>,
        unit: Option<usize>,
    ) {
        let n = self.n.max(1);
        for (c, chunk) in b.chunks_mut(MAX_COLUMNS * n).enumerate() {
            let blocks = reach.map(|r| r[c].as_slice());
            let unit = unit.map(|row| row + c * MAX_COLUMNS);
            match chunk.len() / n {
                3 => self.solve_columns::<3>(chunk, Some((rs, cs)), blocks, unit),
                2 => self.solve_columns::<2>(chunk, Some((rs, cs)), blocks, unit),
                _ => self.solve_columns::<1>(chunk, Some((rs, cs)), blocks, unit),
            }
        }
    }

    /// The blocks (ascending) on which the solution of B y = b may be non-zero when b is
    /// non-zero only on the original `rows`: their blocks and every block that depends on one
    /// of them through an entry left of its diagonal block.
    pub fn reach(&self, rows: &[usize]) -> Vec<usize> {
        self.reaches([rows]).swap_remove(0)
    }

    /// [`Self::reach`] of each set of rows, the blocks' dependency graph built once: O(n + the
    /// entries) and then each set's reached blocks, where a `reach` per set is O(n) each (m of
    /// them cost O(n m) for a model's m coordinates, the build's largest cost once the rank
    /// test stopped being cubic).
    pub fn reaches<'a>(&self, sets: impl IntoIterator<Item = &'a [usize]>) -> Vec<Vec<usize>> {
        let nb = self.n_blocks();
        let (mut block_at, mut block_of_row) = (vec![0; self.n], vec![0; self.n]);
        for k in 0..nb {
            for p in self.span(k) {
                block_at[p] = k;
                block_of_row[self.row[p]] = k;
            }
        }
        // dependents[j]: the blocks with an entry left of their diagonal block in block j's columns.
        let mut dependents = vec![Vec::new(); nb];
        for k in 0..nb {
            for p in self.span(k) {
                for &c in &self.off_col[self.off_at[p]..self.off_at[p + 1]] {
                    dependents[block_at[c]].push(k);
                }
            }
        }
        let mut hit = vec![false; nb];
        sets.into_iter()
            .map(|rows| {
                let mut stack: Vec<usize> = rows.iter().map(|&r| block_of_row[r]).collect();
                let mut out = Vec::new();
                while let Some(k) = stack.pop() {
                    if !hit[k] {
                        hit[k] = true;
                        out.push(k);
                        stack.extend(dependents[k].iter().copied().filter(|&d| !hit[d]));
                    }
                }
                out.iter().for_each(|&k| hit[k] = false);
                out.sort_unstable();
                out
            })
            .collect()
    }

    /// Block after block: forward rows (the right-hand side in pivoted order less the
    /// entries of the blocks already solved, then L), then backward rows (U), for R
    /// right-hand sides at once.
    /// `blocks`: solve only these (ascending; the solution is 0 on the others, whose entries of
    /// `b` are left as they are), else all. `unit`: right-hand side r is 1 in row `unit + r`
    /// and 0 elsewhere, instead of `b`'s column r.
    fn solve_columns<const R: usize>(
        &mut self,
        b: &mut [f64],
        scales: Scales,
        blocks: Option<&[usize]>,
        unit: Option<usize>,
    ) {
        let n = self.n;
        assert!(b.len() == R * n && R <= MAX_COLUMNS && scales.is_none_or(|(rs, cs)| rs.len() == n && cs.len() == n));
        assert!(blocks.is_none_or(|ks| ks.iter().all(|&k| k < self.n_blocks())));
        let y = &mut self.work;
        if blocks.is_some() && !self.work_clean {
            y.fill(0.0);
        }
        let all = self.start.len() - 1;
        // SAFETY: every index read below was built in `new` from the n x n pattern: `row`,
        // `col` and `src` hold 0..n, `off_col` < n, `off_at` and `start` index inside their
        // arrays, a block's L and U entries lie in its s x s slice of `store`; b has R columns
        // of n and rs, cs have n values and the listed blocks exist (asserted), `work` has
        // n * MAX_COLUMNS. Unchecked
        // because the blocks have 1 to ~12 rows: bounds checks cost more than the arithmetic
        // there, and the solves are a third of a forward-dynamics evaluation.
        unsafe {
            let at = |v: &[f64], i: usize| *v.get_unchecked(i);
            let ix = |v: &[usize], i: usize| *v.get_unchecked(i);
            for idx in 0..blocks.map_or(all, <[usize]>::len) {
                let k = blocks.map_or(idx, |ks| ix(ks, idx));
                let (s0, s1, base) = (ix(&self.start, k), ix(&self.start, k + 1), ix(&self.lu_at, k));
                let s = s1 - s0;
                for i in s0..s1 {
                    let p = ix(&self.src, i);
                    let r0 = ix(&self.row, p);
                    let scale = scales.map_or(1.0, |(rs, _)| at(rs, r0));
                    let mut v = [0.0; R];
                    for (r, v) in v.iter_mut().enumerate() {
                        *v = match unit {
                            Some(row) => f64::from(r0 == row + r) * scale,
                            None => at(b, r * n + r0) * scale,
                        };
                    }
                    for e in ix(&self.off_at, p)..ix(&self.off_at, p + 1) {
                        let (a, c) = (at(&self.store, self.off_base + e), ix(&self.off_col, e));
                        for (r, v) in v.iter_mut().enumerate() {
                            *v -= a * at(y, c * R + r);
                        }
                    }
                    let l = base + (i - s0) * s - s0;
                    for j in s0..i {
                        let a = at(&self.store, l + j);
                        for (r, v) in v.iter_mut().enumerate() {
                            *v -= a * at(y, j * R + r);
                        }
                    }
                    for (r, v) in v.into_iter().enumerate() {
                        *y.get_unchecked_mut(i * R + r) = v;
                    }
                }
                for i in (s0..s1).rev() {
                    let u = base + (i - s0) * s - s0;
                    let mut v = [0.0; R];
                    for (r, v) in v.iter_mut().enumerate() {
                        *v = at(y, i * R + r);
                    }
                    for j in i + 1..s1 {
                        let a = at(&self.store, u + j);
                        for (r, v) in v.iter_mut().enumerate() {
                            *v -= a * at(y, j * R + r);
                        }
                    }
                    let d = at(&self.inv_diag, i);
                    for (r, v) in v.into_iter().enumerate() {
                        *y.get_unchecked_mut(i * R + r) = v * d;
                    }
                }
            }
        }
        let (col, start) = (&self.col, &self.start);
        let scatter = |j: usize, y: &[f64], b: &mut [f64]| {
            let c = col[j];
            let scale = scales.map_or(1.0, |(_, cs)| cs[c]);
            for r in 0..R {
                b[r * n + c] = y[j * R + r] * scale;
            }
        };
        match blocks {
            Some(ks) => {
                for &k in ks {
                    for j in start[k]..start[k + 1] {
                        scatter(j, y, b);
                        y[j * R..(j + 1) * R].fill(0.0);
                    }
                }
                self.work_clean = true;
            }
            None => {
                (0..n).for_each(|j| scatter(j, y, b));
                self.work_clean = false;
            }
        }
    }

    /// Solve B^T y = b in place for the factorised (scaled) B: the blocks in reverse order,
    /// each by the dense transposed solve of its factors, its transposed off-diagonal entries
    /// then taken from the earlier blocks' right-hand sides. Used by the singularity monitor.
    pub fn solve_transpose(&mut self, b: &mut [f64]) {
        self.work_clean = false;
        let y = &mut self.work;
        for (w, &c) in y.iter_mut().zip(&self.col) {
            *w = b[c];
        }
        for k in (0..self.start.len() - 1).rev() {
            let (s0, s1) = (self.start[k], self.start[k + 1]);
            let s = s1 - s0;
            let lu = &self.store[self.lu_at[k]..self.lu_at[k] + s * s];
            // The block's transposed solve, pivots undone: the solution in its row order.
            lu_solve_transpose(lu, s, &self.piv[s0..s1], &mut y[s0..s1]);
            for p in s0..s1 {
                let v = y[p];
                b[self.row[p]] = v;
                for e in self.off_at[p]..self.off_at[p + 1] {
                    y[self.off_col[e]] -= self.store[self.off_base + e] * v;
                }
            }
        }
    }
}

/// The blocks (rows, matched columns) in solve order, or None if the pattern is structurally
/// singular.
fn blocks(pattern: &[Vec<usize>]) -> Option<Vec<(Vec<usize>, Vec<usize>)>> {
    let n = pattern.len();
    // Bipartite graph: rows are nodes 0..n, columns n..2n.
    let mut bip = UnGraph::<(), ()>::with_capacity(2 * n, pattern.iter().map(Vec::len).sum());
    for _ in 0..2 * n {
        bip.add_node(());
    }
    for (r, cols) in pattern.iter().enumerate() {
        for &c in cols {
            bip.add_edge(NodeIndex::new(r), NodeIndex::new(n + c), ());
        }
    }
    let matching = maximum_matching(&bip);
    if !matching.is_perfect() {
        return None;
    }
    let col_of = |r: usize| matching.mate(NodeIndex::new(r)).map(|c| c.index() - n);
    let mut row_of = vec![0; n];
    for r in 0..n {
        row_of[col_of(r)?] = r;
    }
    // Row r depends on the rows that determine the columns it uses.
    let mut dep = DiGraph::<(), ()>::with_capacity(n, 0);
    for _ in 0..n {
        dep.add_node(());
    }
    for (r, cols) in pattern.iter().enumerate() {
        for &c in cols {
            if row_of[c] != r {
                dep.add_edge(NodeIndex::new(r), NodeIndex::new(row_of[c]), ());
            }
        }
    }
    // Tarjan emits a component after every component it reaches: dependencies first.
    let mut out = Vec::new();
    for scc in tarjan_scc(&dep) {
        let mut rows: Vec<usize> = scc.iter().map(|v| v.index()).collect();
        rows.sort_unstable();
        let mut cols: Vec<usize> = rows.iter().map(|&r| col_of(r)).collect::<Option<_>>()?;
        cols.sort_unstable();
        out.push((rows, cols));
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fill with the non-zeros of the row-major n x n `a`, unscaled.
    fn fill(lu: &mut BlockLu, a: &[f64], n: usize) {
        let ones = vec![1.0; n];
        let mut sink = lu.sink(&ones, &ones);
        for (i, &v) in a.iter().enumerate().filter(|(_, v)| **v != 0.0) {
            sink.add(i / n, i % n, v);
        }
    }

    /// A 5 x 5 matrix whose block-triangular form has blocks of 1, 2 and 2, given scrambled.
    fn example() -> (Vec<f64>, Vec<Vec<usize>>) {
        // Unknowns: a (col 3) alone; b, c (cols 0, 4) coupled, using a; d, e (cols 1, 2) coupled, using b.
        let mut a = vec![0.0; 25];
        let mut set = |r: usize, c: usize, v: f64| a[r * 5 + c] = v;
        set(2, 3, 2.0); // a
        set(0, 0, 1.0);
        set(0, 4, 3.0);
        set(0, 3, -1.0); // b, c rows
        set(4, 0, -2.0);
        set(4, 4, 0.5);
        set(1, 1, 0.0);
        set(1, 2, 4.0);
        set(1, 0, 1.5); // d, e rows (zero first entry: needs pivoting)
        set(3, 1, 3.0);
        set(3, 2, 1.0);
        let pattern = (0..5).map(|r| (0..5).filter(|&c| a[r * 5 + c] != 0.0 || (r, c) == (1, 1)).collect()).collect();
        (a, pattern)
    }

    #[test]
    fn finds_the_blocks_and_solves_both_ways() {
        let (a, pattern) = example();
        let mut lu = BlockLu::new(&pattern);
        assert_eq!(lu.block_sizes().collect::<Vec<_>>(), vec![1, 2, 2]);
        fill(&mut lu, &a, 5);
        lu.factor(1e-300).unwrap();
        let x = [1.0, -2.0, 0.5, 3.0, -0.25];
        let mut b: Vec<f64> = (0..5).map(|i| (0..5).map(|j| a[i * 5 + j] * x[j]).sum()).collect();
        lu.solve(&mut b);
        let mut bt: Vec<f64> = (0..5).map(|i| (0..5).map(|j| a[j * 5 + i] * x[j]).sum()).collect();
        lu.solve_transpose(&mut bt);
        for i in 0..5 {
            assert!((b[i] - x[i]).abs() < 1e-14, "solve: {b:?}");
            assert!((bt[i] - x[i]).abs() < 1e-14, "solve_transpose: {bt:?}");
        }
    }

    #[test]
    fn solves_many_scaled_columns_in_sweeps_of_three() {
        // B = diag(rs) A diag(cs) is factorised; A x = b is solved for 5 columns (3 + 2).
        let (a, pattern) = example();
        let (rs, cs) = ([2.0, 0.5, 1.0, 4.0, 0.25], [1.0, 3.0, 0.5, 2.0, 1.0]);
        let mut lu = BlockLu::new(&pattern);
        let mut sink = lu.sink(&rs, &cs);
        for (i, &v) in a.iter().enumerate().filter(|(_, v)| **v != 0.0) {
            sink.add(i / 5, i % 5, v);
        }
        lu.factor(1e-300).unwrap();
        let xs: Vec<f64> = (0..25).map(|k| ((k * 7 % 11) as f64 - 5.0) / 3.0).collect();
        let mut b: Vec<f64> = xs
            .chunks(5)
            .flat_map(|x| (0..5).map(|i| (0..5).map(|j| a[i * 5 + j] * x[j]).sum::<f64>()).collect::<Vec<_>>())
            .collect();
        lu.solve_many_scaled(&mut b, &rs, &cs);
        for (k, (got, want)) in b.iter().zip(&xs).enumerate() {
            assert!((got - want).abs() < 1e-13, "entry {k}: {got} vs {want}");
        }
    }

    #[test]
    fn solves_unit_columns_on_the_blocks_they_reach_only() {
        // Blocks in solve order: {row 2} (a), {rows 0, 4} (b, c: use a), {rows 1, 3} (d, e: use b).
        let (a, pattern) = example();
        let mut lu = BlockLu::new(&pattern);
        assert_eq!(lu.reach(&[2]), vec![0, 1, 2]);
        assert_eq!(lu.reach(&[4]), vec![1, 2]);
        assert_eq!(lu.reach(&[3]), vec![2]);
        fill(&mut lu, &a, 5);
        lu.factor(1e-300).unwrap();
        let (rs, cs) = ([2.0, 0.5, 1.0, 4.0, 0.25], [1.0, 3.0, 0.5, 2.0, 1.0]);
        // Unit columns from row `first` on, in one sweep: the same values as the full solve of
        // [0; I] where reached, and the entries outside the reached blocks untouched (NaN
        // here). A full solve in between leaves the solver's buffer dirty: no effect either.
        for (first, count) in [(2, 3), (3, 2), (4, 1), (3, 1)] {
            let mut full: Vec<f64> = (0..count).flat_map(|r| (0..5).map(move |i| f64::from(i == first + r))).collect();
            lu.solve_many_scaled(&mut full, &rs, &cs);
            let reach = vec![lu.reach(&(first..first + count).collect::<Vec<_>>())];
            let written: Vec<usize> = reach[0].iter().flat_map(|&k| lu.span(k)).map(|p| lu.col[p]).collect();
            let mut over = vec![f64::NAN; 5 * count];
            lu.solve_unit_columns(&mut over, first, &rs, &cs, Some(&reach));
            for (k, (o, f)) in over.iter().zip(&full).enumerate() {
                if written.contains(&(k % 5)) {
                    assert_eq!(o, f, "rows from {first}: entry {k}");
                } else {
                    assert!(o.is_nan() && *f == 0.0, "rows from {first}: entry {k} = {o}, full {f}");
                }
            }
        }
    }

    #[test]
    fn structurally_singular_pattern_is_one_block() {
        // Two rows that can only use column 0.
        let lu = BlockLu::new(&[vec![0], vec![0]]);
        assert_eq!(lu.block_sizes().collect::<Vec<_>>(), vec![2]);
    }

    #[test]
    fn reports_a_numerically_singular_block_by_its_column() {
        let pattern = vec![vec![0], vec![0, 1, 2], vec![1, 2]];
        let mut lu = BlockLu::new(&pattern);
        // Block {rows 1, 2; cols 1, 2} = [[1, 2], [2, 4]] is singular.
        let a = [1.0, 0.0, 0.0, 5.0, 1.0, 2.0, 0.0, 2.0, 4.0];
        fill(&mut lu, &a, 3);
        let err = lu.factor(1e-12).unwrap_err();
        assert!(err.column == 1 || err.column == 2, "{err:?}");
    }
}
