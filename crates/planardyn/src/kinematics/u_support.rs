//! Where each column of U = dx/dz may be non-zero: per column j, the bodies of the blocks its
//! coordinate reaches, as runs [first, end) of consecutive bodies. The products of U's columns
//! (U zd, U^T f, U^T M c, U zdd) run over these runs only, so they cost the sum of the
//! reaches: linear in the coordinates for a mechanism whose loops are local (a ladder of
//! five-bar loops, whose bodies are numbered rods first and dyads after, gives each column a
//! few bodies spread over the whole order: its range [first, end) would be O(n) bodies).

/// A gap of fewer bodies than this between two of a column's bodies is run through (U's entries
/// there are exact zeros: adding their products changes no non-zero sum's bits): a run's own
/// bookkeeping costs about what a few bodies' products do (callgrind, five-bars side by side,
/// whose columns reach rod, gap, two links: two runs a column cost 10 % more per evaluation
/// than one range).
const MERGE_GAP: usize = 4;

/// Per column of U, its bodies as ascending runs (see the module doc).
#[derive(Debug, Default, PartialEq)]
pub struct USupport {
    /// Column j's runs: `runs[runs_at[j]..runs_at[j + 1]]`.
    runs_at: Vec<usize>,
    runs: Vec<(usize, usize)>,
}

clone_reusing!(USupport { runs_at, runs });

impl USupport {
    /// From each column's bodies (ascending, no repeats); gaps below [`MERGE_GAP`] bodies joined.
    pub fn new(u_bodies: &[Vec<usize>]) -> Self {
        let mut s = USupport { runs_at: vec![0], runs: Vec::new() };
        for bodies in u_bodies {
            let start = s.runs.len();
            for &b in bodies {
                match s.runs[start..].last_mut() {
                    Some(run) if b - run.1 < MERGE_GAP => run.1 = b + 1,
                    _ => s.runs.push((b, b + 1)),
                }
            }
            s.runs_at.push(s.runs.len());
        }
        s
    }

    /// The number of columns.
    pub fn len(&self) -> usize {
        self.runs_at.len() - 1
    }

    /// Whether there are no columns (m = 0).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Column j's bodies as runs [first, end), ascending.
    #[inline]
    pub fn runs(&self, j: usize) -> &[(usize, usize)] {
        &self.runs[self.runs_at[j]..self.runs_at[j + 1]]
    }

    /// Column j's body coordinates (3 per body) as runs [first, end) of rows of U.
    pub fn rows(&self, j: usize) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.runs(j).iter().map(|&(first, end)| 3 * first..3 * end)
    }

    /// Copy U's columns (column-major, `n` rows each) from `src` to `dst` over their runs only:
    /// where both hold zeros outside them, `dst` is then `src` whole, at the cost of the
    /// supports instead of n x m.
    pub fn copy_columns(&self, n: usize, src: &[f64], dst: &mut [f64]) {
        for j in 0..self.len() {
            for rows in self.rows(j) {
                let rows = j * n + rows.start..j * n + rows.end;
                dst[rows.clone()].copy_from_slice(&src[rows]);
            }
        }
    }

    /// u_j . f over column j's rows (`u`: the column, 3n values), the terms added in order
    /// from -0.0 (as f64's `Sum` over all rows: the skipped terms are zero). Inlined: called
    /// per entry of b, a call's overhead is a five-bar's whole sum.
    #[inline(always)]
    pub fn dot(&self, j: usize, u: &[f64], f: &[f64]) -> f64 {
        let mut s = -0.0;
        for &(first, end) in self.runs(j) {
            for (u, f) in u[3 * first..3 * end].iter().zip(&f[3 * first..3 * end]) {
                s += u * f;
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_join_consecutive_bodies_per_column() {
        // Column 0: bodies 0, 1, 2 and 7 (a gap of 4 = MERGE_GAP) -> runs [0, 3), [7, 8);
        // column 1: none; column 2: body 4 only; a run never continues across columns (column
        // 3 starts at 7 again); column 4: bodies 1 and 4, a gap of 2, run through -> [1, 5).
        let s = USupport::new(&[vec![0, 1, 2, 7], vec![], vec![4], vec![7, 8], vec![1, 4]]);
        assert_eq!(s.len(), 5);
        assert_eq!(s.runs(0), &[(0, 3), (7, 8)]);
        assert!(s.runs(1).is_empty());
        assert_eq!(s.runs(2), &[(4, 5)]);
        assert_eq!(s.runs(3), &[(7, 9)]);
        assert_eq!(s.runs(4), &[(1, 5)]);
        assert_eq!(s.rows(0).collect::<Vec<_>>(), vec![0..9, 21..24]);
        // A copy over the runs of columns 0 and 2 (n = 27 rows) takes their runs' rows only.
        let s = USupport::new(&[vec![0, 1, 2, 7], vec![4]]);
        let src: Vec<f64> = (1..=54).map(f64::from).collect();
        let mut dst = vec![0.0; 54];
        s.copy_columns(27, &src, &mut dst);
        let copied: Vec<usize> = (0..54).filter(|&i| dst[i] != 0.0).collect();
        assert!(copied.iter().all(|&i| dst[i] == src[i]));
        let want: Vec<usize> = (0..9).chain(21..24).chain(27 + 12..27 + 15).collect();
        assert_eq!(copied, want);
    }
}
