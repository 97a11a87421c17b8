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

use super::lu::{lu_factor, LuError};
use super::sink::Sink;
use petgraph::algo::{maximum_matching, tarjan_scc};
use petgraph::graph::{DiGraph, NodeIndex, UnGraph};

/// The block-triangular factors of an n x n matrix, in buffers sized once per pattern.
#[derive(Debug, Clone)]
pub struct BlockLu {
    n: usize,
    /// Permuted position -> original row, and -> original column.
    row: Vec<usize>,
    col: Vec<usize>,
    /// Block k spans the permuted positions `start[k]..start[k + 1]`.
    start: Vec<usize>,
    /// The diagonal blocks, block k row-major from `lu_at[k]`, then the entries left of
    /// them (`off_val`, from `off_base`). Filled through [`BlockLu::sink`]; the blocks are then
    /// factorised in place: unit lower L below the diagonal, U on and above it, of the
    /// block's rows in pivoted order.
    store: Vec<f64>,
    lu_at: Vec<usize>,
    off_base: usize,
    /// Slot in `store` of entry (r, c) of the matrix at `r * n + c` (`NONE` outside the pattern).
    dest: Vec<u32>,
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
    /// The solve as sparse rows, rebuilt by each factorisation (the pivots move rows): forward
    /// row i takes the right-hand side of original row `rhs_row[i]` and subtracts
    /// `fwd_val * y[fwd_idx]` over `fwd_at[i]..fwd_at[i + 1]` (entries of the blocks already
    /// solved, then L); backward row i subtracts the U entries `bwd_*` and scales by `inv_diag`.
    rhs_row: Vec<usize>,
    fwd_at: Vec<usize>,
    fwd_idx: Vec<usize>,
    fwd_val: Vec<f64>,
    bwd_at: Vec<usize>,
    bwd_idx: Vec<usize>,
    bwd_val: Vec<f64>,
    inv_diag: Vec<f64>,
    /// The solution in permuted column order while a solve runs.
    work: Vec<f64>,
}

/// Row and column scales applied on the way in and out of a solve (see [`BlockLu::sink`]).
type Scales<'a> = Option<(&'a [f64], &'a [f64])>;

/// `dest` of an entry outside the pattern.
const NONE: u32 = u32::MAX;

/// The entries of the matrix to factorise, scaled and written into the blocks as they come.
pub struct BlockSink<'a> {
    n: usize,
    store: &'a mut [f64],
    dest: &'a [u32],
    rs: &'a [f64],
    cs: &'a [f64],
}

impl Sink for BlockSink<'_> {
    /// Add `v` (of the unscaled matrix) to entry (row, col). An entry outside the pattern
    /// is a bug in the pattern: it panics in debug builds and is dropped in release ones.
    #[inline]
    fn add(&mut self, row: usize, col: usize, v: f64) {
        let d = self.dest[row * self.n + col];
        debug_assert!(d != NONE, "entry ({row}, {col}) is outside the pattern");
        if d != NONE {
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
        let (mut row, mut col, mut start, mut lu_at) = (Vec::with_capacity(n), Vec::with_capacity(n), vec![0], Vec::new());
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
        let mut dest = vec![NONE; n * n];
        let (mut off_at, mut off_col) = (vec![0], Vec::new());
        let (mut bwd_at, mut bwd_idx) = (vec![0], Vec::new());
        for k in 0..blocks.len() {
            let (s0, s1) = (start[k], start[k + 1]);
            for (i, &r) in row[s0..s1].iter().enumerate() {
                for &c in &pattern[r] {
                    let j = position[c];
                    dest[r * n + c] = if j < s0 {
                        off_col.push(j);
                        (size + off_col.len() - 1) as u32
                    } else if j < s1 {
                        (lu_at[k] + i * (s1 - s0) + j - s0) as u32
                    } else {
                        unreachable!("the block-triangular form has no entry right of a block")
                    };
                }
                off_at.push(off_col.len());
                bwd_idx.extend(s0 + i + 1..s1);
                bwd_at.push(bwd_idx.len());
            }
        }
        let l_entries: usize = blocks.iter().map(|(r, _)| r.len() * (r.len() - 1) / 2).sum();
        BlockLu {
            n,
            start,
            store: vec![0.0; size + off_col.len()],
            lu_at,
            off_base: size,
            dest,
            piv: vec![0; n],
            src: (0..n).collect(),
            off_at,
            fwd_idx: vec![0; off_col.len() + l_entries],
            fwd_val: vec![0.0; off_col.len() + l_entries],
            off_col,
            rhs_row: row.clone(),
            fwd_at: vec![0; n + 1],
            bwd_val: vec![0.0; bwd_idx.len()],
            bwd_at,
            bwd_idx,
            inv_diag: vec![0.0; n],
            work: vec![0.0; n],
            row,
            col,
        }
    }

    /// Sizes of the diagonal blocks, in solve order.
    pub fn block_sizes(&self) -> impl Iterator<Item = usize> + '_ {
        self.start.windows(2).map(|w| w[1] - w[0])
    }

    /// Start filling the matrix B = diag(rs) A diag(cs) to factorise: every entry is zeroed,
    /// and the sink scales the entries of A it is given. Then [`BlockLu::factor`].
    pub fn sink<'a>(&'a mut self, rs: &'a [f64], cs: &'a [f64]) -> BlockSink<'a> {
        self.store.fill(0.0);
        BlockSink { n: self.n, store: &mut self.store, dest: &self.dest, rs, cs }
    }

    /// Factorise the filled matrix B block by block. A pivot of magnitude `<= tiny` (or not
    /// finite) makes it singular; the error names the original column being eliminated.
    pub fn factor(&mut self, tiny: f64) -> Result<(), LuError> {
        let mut fwd = 0;
        for k in 0..self.start.len() - 1 {
            let (s0, s1, base) = (self.start[k], self.start[k + 1], self.lu_at[k]);
            let s = s1 - s0;
            let (blocks, off_val) = self.store.split_at_mut(self.off_base);
            let block = &mut blocks[base..base + s * s];
            lu_factor(block, s, &mut self.piv[s0..s1], tiny).map_err(|e| LuError { column: self.col[s0 + e.column] })?;
            let src = &mut self.src[s0..s1];
            for (i, p) in src.iter_mut().enumerate() {
                *p = s0 + i;
            }
            for (i, &p) in self.piv[s0..s1].iter().enumerate() {
                src.swap(i, p);
            }
            // The solve's rows for this block, in pivoted order.
            for i in 0..s {
                let p = self.src[s0 + i];
                self.rhs_row[s0 + i] = self.row[p];
                for e in self.off_at[p]..self.off_at[p + 1] {
                    (self.fwd_idx[fwd], self.fwd_val[fwd]) = (self.off_col[e], off_val[e]);
                    fwd += 1;
                }
                for j in 0..i {
                    (self.fwd_idx[fwd], self.fwd_val[fwd]) = (s0 + j, block[i * s + j]);
                    fwd += 1;
                }
                self.fwd_at[s0 + i + 1] = fwd;
                let b0 = self.bwd_at[s0 + i];
                self.bwd_val[b0..b0 + s - i - 1].copy_from_slice(&block[i * s + i + 1..(i + 1) * s]);
                self.inv_diag[s0 + i] = 1.0 / block[i * s + i];
            }
        }
        Ok(())
    }

    /// Solve B y = b in place for the factorised (scaled) B.
    pub fn solve(&mut self, b: &mut [f64]) {
        self.solve_with(b, None)
    }

    /// Solve A x = b in place for the unscaled A: x = diag(cs) B^-1 diag(rs) b, the scalings
    /// folded into the gather and the scatter.
    pub fn solve_scaled(&mut self, b: &mut [f64], rs: &[f64], cs: &[f64]) {
        self.solve_with(b, Some((rs, cs)))
    }

    /// Block after block: forward rows (the right-hand side less the entries of the blocks
    /// already solved, and L), then backward rows (U).
    fn solve_with(&mut self, b: &mut [f64], scales: Scales) {
        assert!(b.len() == self.n && scales.is_none_or(|(rs, cs)| rs.len() == self.n && cs.len() == self.n));
        let y = &mut self.work;
        // SAFETY: every index read below was built in `new` and `factor` from the n x n
        // pattern: `rhs_row` and `col` hold 0..n, `fwd_idx` and `bwd_idx` < n, the `*_at`
        // ranges lie inside their arrays, and b, rs, cs have length n (asserted above).
        // Unchecked because the blocks have 1 to ~12 rows: bounds checks cost more than the
        // arithmetic there (the solve is a third of a forward-dynamics evaluation).
        unsafe {
            let at = |v: &[f64], i: usize| *v.get_unchecked(i);
            let ix = |v: &[usize], i: usize| *v.get_unchecked(i);
            for k in 0..self.start.len() - 1 {
                let (s0, s1) = (ix(&self.start, k), ix(&self.start, k + 1));
                for i in s0..s1 {
                    let r = ix(&self.rhs_row, i);
                    let mut v = match scales {
                        Some((rs, _)) => at(b, r) * at(rs, r),
                        None => at(b, r),
                    };
                    for e in ix(&self.fwd_at, i)..ix(&self.fwd_at, i + 1) {
                        v -= at(&self.fwd_val, e) * at(y, ix(&self.fwd_idx, e));
                    }
                    *y.get_unchecked_mut(i) = v;
                }
                for i in (s0..s1).rev() {
                    let mut v = at(y, i);
                    for e in ix(&self.bwd_at, i)..ix(&self.bwd_at, i + 1) {
                        v -= at(&self.bwd_val, e) * at(y, ix(&self.bwd_idx, e));
                    }
                    *y.get_unchecked_mut(i) = v * at(&self.inv_diag, i);
                }
            }
        }
        match scales {
            Some((_, cs)) => self.col.iter().zip(y.iter()).for_each(|(&c, &v)| b[c] = v * cs[c]),
            None => self.col.iter().zip(y.iter()).for_each(|(&c, &v)| b[c] = v),
        }
    }

    /// Solve B^T y = b in place for the factorised (scaled) B: the blocks in reverse order,
    /// U^T then L^T and the pivots undone, each block's transposed off-diagonal entries then
    /// taken from the earlier blocks' right-hand sides. Used by the singularity monitor only.
    pub fn solve_transpose(&mut self, b: &mut [f64]) {
        let y = &mut self.work;
        for (w, &c) in y.iter_mut().zip(&self.col) {
            *w = b[c];
        }
        for k in (0..self.start.len() - 1).rev() {
            let (s0, s1) = (self.start[k], self.start[k + 1]);
            let s = s1 - s0;
            let lu = &self.store[self.lu_at[k]..self.lu_at[k] + s * s];
            let t = &mut y[s0..s1];
            for i in 0..s {
                let v = t[i] - (0..i).map(|j| lu[j * s + i] * t[j]).sum::<f64>();
                t[i] = v * self.inv_diag[s0 + i];
            }
            for i in (0..s).rev() {
                t[i] -= (i + 1..s).map(|j| lu[j * s + i] * t[j]).sum::<f64>();
            }
            // t holds the solution in pivoted order: back to the block's row order.
            for i in s0..s1 {
                b[self.row[self.src[i]]] = y[i];
            }
            for p in s0..s1 {
                let v = b[self.row[p]];
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
