//! The scaled pair-constraint Jacobian Phi_x and what its singular value decomposition
//! tells: numerical rank, a maximal set of independent rows, and the self-stresses.

use super::constraints::{body_trig, constraint_jacobian};
use super::system::col_scales;
use crate::linalg::{pivot_columns, SparseRow};
use crate::model::pairs::row_scales;
use crate::model::{Mechanism, PairId};
use nalgebra::DMatrix;

/// Relative singular value of the scaled Phi_x below which its rows count as dependent:
/// sigma <= RANK_TOL * max(sigma_max, 1). The scaled entries are O(1) whatever the size of
/// the mechanism, so the threshold needs no factor of the matrix size. It sits far above the
/// SVD's rounding (~1e-15 sigma_max) and below the perturbation that coordinates typed to 9
/// or more significant digits put into the entries, so that a drawn parallelogram is still
/// recognised as redundant, while no drawing is meant to be within 1e-9 of a singular one.
pub const RANK_TOL: f64 = 1e-9;

/// A pair takes part in a self-stress when its rows' share (Euclidean norm) of the unit
/// self-stress vector exceeds this: the null vectors are exact to about RANK_TOL, so 1e-6
/// is well clear of their rounding and far below any real participation.
pub const SELF_STRESS_TOL: f64 = 1e-6;

/// A self-stress: pair reactions in equilibrium without any load (lambda != 0 with
/// Phi_x^T lambda = 0), so the reactions of its pairs are not unique.
#[derive(Debug, Clone, PartialEq)]
pub struct SelfStress {
    /// The pairs with a share above [`SELF_STRESS_TOL`], ascending.
    pub pairs: Vec<PairId>,
    /// lambda, one value per pair-constraint row of the scaled Phi_x, unit norm.
    pub lambda: Vec<f64>,
}

/// The rank structure of all pair-constraint rows at x.
#[derive(Debug, Clone, PartialEq)]
pub struct Rank {
    /// Numerical rank of the scaled Phi_x (tolerance [`RANK_TOL`]).
    pub rank: usize,
    /// Its min(rows, 3n) singular values, ascending (dimensionless).
    pub singular_values: Vec<f64>,
    /// A maximal set of independent rows (indices into `0..n_pair_rows()`), ascending: the
    /// pivot columns of Phi_x^T under complete pivoting, the best-conditioned choice.
    pub independent_rows: Vec<usize>,
    /// A basis of the self-stresses (rows - rank of them), each reduced to involve as few
    /// pairs as the structure allows.
    pub self_stresses: Vec<SelfStress>,
}

/// Phi_x = dPhi/dx at body coordinates x (3n values): all `n_pair_rows()` rows, redundant
/// ones included, by 3n columns (X, Y in m, phi in rad), row-major.
pub fn pair_constraint_jacobian(mech: &Mechanism, x: &[f64]) -> Vec<f64> {
    let rows = mech.n_pair_rows();
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    let all: Vec<Option<usize>> = (0..rows).map(Some).collect();
    let mut j = vec![0.0; rows * mech.n_x()];
    constraint_jacobian(mech, x, &trig, &all, &mut j);
    j
}

/// [`pair_constraint_jacobian`] scaled as the solver's J (`kinematics::system`): rows in
/// metres divided by the characteristic length L, translation columns multiplied by L, so
/// that the entries are dimensionless.
pub fn scaled_constraint_jacobian(mech: &Mechanism, x: &[f64]) -> Vec<f64> {
    let (rows, n) = (mech.n_pair_rows(), mech.n_x());
    let mut j = pair_constraint_jacobian(mech, x);
    let mut rs = vec![1.0; rows];
    for (k, pair) in mech.pairs.iter().enumerate() {
        for (r, s) in mech.pair_rows(PairId(k)).zip(row_scales(pair, 1.0 / mech.scale)) {
            rs[r] = s;
        }
    }
    let cs = col_scales(mech);
    for (row, s) in j.chunks_exact_mut(n.max(1)).zip(&rs) {
        for (v, c) in row.iter_mut().zip(&cs) {
            *v *= s * c;
        }
    }
    j
}

/// Rank, singular values, independent rows and self-stresses of all pair-constraint rows at
/// x, which must be finite (the SVD iteration need not end otherwise). Rows that share no
/// body coordinate, directly or through other rows, form independent blocks of Phi_x (the
/// parts of a mechanism joined only through the ground, five-bars side by side): each is
/// decomposed on its own, so that the cost is the sum of the parts' cubes, not the whole's.
/// The rank threshold is the whole matrix's (its largest singular value is the parts').
pub(crate) fn constraint_rank(mech: &Mechanism, x: &[f64]) -> Rank {
    let (rows, n) = (mech.n_pair_rows(), mech.n_x());
    if rows == 0 {
        return Rank { rank: 0, singular_values: vec![], independent_rows: vec![], self_stresses: vec![] };
    }
    let j = scaled_constraint_jacobian(mech, x);
    let sparse: Vec<SparseRow> =
        (0..rows).map(|r| (0..n).filter(|&c| j[r * n + c] != 0.0).map(|c| (c, j[r * n + c])).collect()).collect();
    let parts: Vec<(Part, PartSvd)> = parts(&sparse, n)
        .into_iter()
        .map(|p| {
            let s = part_svd(&j, n, &p);
            (p, s)
        })
        .collect();
    let top = parts.iter().flat_map(|(_, s)| s.values.iter().copied()).fold(0.0, f64::max);
    let tol = RANK_TOL * top.max(1.0);
    let (mut rank, mut singular_values, mut independent_rows, mut null) =
        (0, Vec::<f64>::new(), Vec::new(), Vec::new());
    for (part, svd) in &parts {
        let part_rank = svd.values.iter().filter(|&&s| s > tol).count();
        rank += part_rank;
        singular_values.extend(&svd.values);
        for (i, _) in svd.values.iter().enumerate().filter(|(_, &s)| s <= tol) {
            let mut v = vec![0.0; rows];
            for (k, &r) in part.rows.iter().enumerate() {
                v[r] = svd.u[(k, i)];
            }
            null.push(v);
        }
        // Phi_x^T of the part: its columns are the part's rows, ascending as in the whole.
        let (pr, pn) = (part.rows.len(), part.cols.len());
        let mut t = vec![0.0; pn * pr];
        for (a, &r) in part.rows.iter().enumerate() {
            for (c, &col) in part.cols.iter().enumerate() {
                t[c * pr + a] = j[r * n + col];
            }
        }
        independent_rows.extend(pivot_columns(&mut t, pn, pr, part_rank).into_iter().map(|a| part.rows[a]));
    }
    singular_values.sort_by(|a, b| b.total_cmp(a));
    singular_values.truncate(rows.min(n));
    singular_values.reverse();
    independent_rows.sort_unstable();
    Rank { rank, singular_values, independent_rows, self_stresses: self_stresses(mech, null) }
}

/// Rows of Phi_x and the body coordinates they touch, ascending; no other row touches these
/// columns.
pub(super) struct Part {
    pub rows: Vec<usize>,
    pub cols: Vec<usize>,
}

/// A part's singular values (one per row: zero columns pad it to a square matrix, so that the
/// full U (rows x rows) holds the whole left null space also where there are more rows than
/// body coordinates) and U.
struct PartSvd {
    values: Vec<f64>,
    u: DMatrix<f64>,
}

fn part_svd(j: &[f64], n: usize, part: &Part) -> PartSvd {
    let (pr, pn) = (part.rows.len(), part.cols.len());
    let width = pn.max(pr);
    let padded = DMatrix::from_fn(pr, width, |r, c| if c < pn { j[part.rows[r] * n + part.cols[c]] } else { 0.0 });
    let svd = padded.svd(true, false);
    PartSvd { values: svd.singular_values.iter().copied().collect(), u: svd.u.expect("requested") }
}

/// The rows of Phi_x (sparse rows, columns ascending) joined when they share a column
/// (union-find over the columns): each part's rows and columns ascending, the parts in order of
/// their first row (a row of zeros is a part of its own, with no columns).
pub(super) fn parts(phi: &[SparseRow], n: usize) -> Vec<Part> {
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut c: usize) -> usize {
        while parent[c] != c {
            parent[c] = parent[parent[c]];
            c = parent[c];
        }
        c
    }
    for row in phi {
        if let Some(&(f, _)) = row.first() {
            for &(c, _) in &row[1..] {
                let (rf, rc) = (root(&mut parent, f), root(&mut parent, c));
                parent[rc] = rf;
            }
        }
    }
    let (mut index, mut out): (Vec<Option<usize>>, Vec<Part>) = (vec![None; n], Vec::new());
    for (r, row) in phi.iter().enumerate() {
        let part = match row.first() {
            None => {
                out.push(Part { rows: vec![], cols: vec![] });
                out.len() - 1
            }
            Some(&(c, _)) => {
                let rc = root(&mut parent, c);
                *index[rc].get_or_insert_with(|| {
                    out.push(Part { rows: vec![], cols: vec![] });
                    out.len() - 1
                })
            }
        };
        out[part].rows.push(r);
    }
    for c in 0..n {
        let rc = root(&mut parent, c);
        if let Some(p) = index[rc] {
            out[p].cols.push(c);
        }
    }
    out
}

/// Reduce a basis of the left null space (column echelon form: each vector gets a pivot row
/// the others lack, so each involves as few pairs as possible) and name its pairs.
fn self_stresses(mech: &Mechanism, mut q: Vec<Vec<f64>>) -> Vec<SelfStress> {
    let rows = mech.n_pair_rows();
    let mut pivot_rows: Vec<usize> = Vec::new();
    for j in 0..q.len() {
        let (mut best, mut at) = (-1.0, (0, j));
        for i in (0..rows).filter(|i| !pivot_rows.contains(i)) {
            for (c, v) in q.iter().enumerate().skip(j) {
                if v[i].abs() > best {
                    (best, at) = (v[i].abs(), (i, c));
                }
            }
        }
        let (i, c) = at;
        q.swap(j, c);
        let p = q[j][i];
        q[j].iter_mut().for_each(|v| *v /= p);
        let pivot = q[j].clone();
        for v in q.iter_mut().enumerate().filter(|(c, _)| *c != j).map(|(_, v)| v) {
            let f = v[i];
            v.iter_mut().zip(&pivot).for_each(|(a, b)| *a -= f * b);
        }
        pivot_rows.push(i);
    }
    q.into_iter()
        .map(|mut lambda| {
            let norm = lambda.iter().map(|v| v * v).sum::<f64>().sqrt();
            lambda.iter_mut().for_each(|v| *v /= norm);
            let pairs = (0..mech.pairs.len())
                .map(PairId)
                .filter(|&k| mech.pair_rows(k).map(|r| lambda[r] * lambda[r]).sum::<f64>().sqrt() > SELF_STRESS_TOL)
                .collect();
            SelfStress { pairs, lambda }
        })
        .collect()
}
