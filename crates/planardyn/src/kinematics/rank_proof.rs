//! The rank of the pair constraints as the loader needs it (the rank, a maximal set of
//! independent rows, the pairs of each self-stress), proven from a sparse elimination of the
//! scaled Phi_x instead of read from its SVD, so that loading a chain of n bodies costs O(n),
//! not the SVD's O(n^3) (96 % of a 200-body ladder's build). The answer is the SVD's
//! ([`rank::constraint_rank`](super::rank)): the same threshold RANK_TOL, and where the proofs
//! below do not settle the rank (a drawing within about 1e-6 of a singular one) the SVD decides.
//!
//! Per independent part of Phi_x (as in `rank`), complete pivoting on Phi_x^T picks k rows S,
//! those whose pivots exceed the threshold; then
//! - rank <= k: Phi_x^T = (a matrix of rank k) + [0; E] - dA, E the Schur complement of the
//!   other rows and dA the elimination's rounding (|dA| <= gamma |L| |U|, Higham Thm 9.3), so
//!   sigma_{k+1} <= ||E||_F + gamma ||L||_F ||U||_F, which must lie below the threshold;
//! - rank >= k: sigma_k(Phi_x) >= sigma_min(Phi_S) (interlacing), and sigma_min(Phi_S)^2 =
//!   lambda_min(Phi_S Phi_S^T) is proven above the threshold's square by a shifted Cholesky
//!   factorisation ([`gram_exceeds`]).
//!
//! Both sides keep a further margin for the SVD's own rounding (its singular values are exact
//! for a matrix within p u ||Phi_x||_2 of Phi_x), so where the proofs hold the SVD's count
//! agrees. The independent rows are the SVD path's (the same pivots, [`eliminate`] being
//! `pivot_columns` on sparse rows); a self-stress is the null vector that is 1 on one left-out
//! row and 0 on the others (a column echelon basis, each as local as the left-out rows allow).

use super::phi_pivots::scaled_phi_rows;
use super::rank::{constraint_rank, parts, Part, RANK_TOL, SELF_STRESS_TOL};
use crate::linalg::{eliminate, gamma, gram_exceeds, SparseRow};
use crate::model::{Mechanism, PairId};

/// The SVD's backward error per row or column of Phi_x, in units of u ||Phi_x||_2 (its
/// p(m, n) u ||Phi_x||_2 with p = rows + columns; Golub & Van Loan, 4th ed., 8.6.3): the margin
/// the proofs keep so that the SVD's rounded singular values fall on the same side.
const SVD_ERROR_PER_DIMENSION: f64 = 4.0;

/// The rank of all pair-constraint rows at x, the independent rows (ascending) and the pairs
/// of each self-stress (rows - rank of them).
#[derive(Debug, Clone, PartialEq)]
pub struct IndependentRows {
    pub rank: usize,
    pub rows: Vec<usize>,
    pub stresses: Vec<Vec<PairId>>,
}

/// [`proven_rank`], or the SVD's answer where the proofs do not settle it. x must be finite.
pub fn independent_rows(mech: &Mechanism, x: &[f64]) -> IndependentRows {
    proven_rank(mech, x).unwrap_or_else(|| {
        let r = constraint_rank(mech, x);
        IndependentRows {
            rank: r.rank,
            rows: r.independent_rows,
            stresses: r.self_stresses.into_iter().map(|s| s.pairs).collect(),
        }
    })
}

/// The sparse rows of the scaled Phi_x, all pair rows: [`rank::scaled_constraint_jacobian`](super::rank)'s
/// non-zeros, the same values bit for bit (summed and scaled in the same order).
fn sparse_scaled_jacobian(mech: &Mechanism, x: &[f64]) -> Vec<SparseRow> {
    let rows = mech.n_pair_rows();
    let all: Vec<Option<usize>> = (0..rows).map(Some).collect();
    scaled_phi_rows(mech, x, &mech.slots_by_pair(&all), rows)
}

/// Bounds on ||Phi_x||_2: below, its largest row or column norm; above, sqrt(||.||_1 ||.||_inf).
fn norm_bounds(phi: &[SparseRow], n: usize) -> (f64, f64) {
    let (mut col_abs, mut col_sq) = (vec![0.0; n], vec![0.0; n]);
    let (mut row_abs, mut lo): (f64, f64) = (0.0, 0.0);
    for row in phi {
        row_abs = row_abs.max(row.iter().map(|e| e.1.abs()).sum());
        lo = lo.max(row.iter().map(|e| e.1 * e.1).sum::<f64>().sqrt());
        for &(c, v) in row {
            col_abs[c] += v.abs();
            col_sq[c] += v * v;
        }
    }
    let col_max = col_abs.iter().copied().fold(0.0, f64::max);
    lo = col_sq.iter().map(|s| s.sqrt()).fold(lo, f64::max);
    // Rounding of the sums: a relative 1e-12 either way is far above it.
    (lo * (1.0 - 1e-12), (row_abs * col_max).sqrt() * (1.0 + 1e-12))
}

/// The rank structure where the proofs settle it for every part; None where one does not.
pub fn proven_rank(mech: &Mechanism, x: &[f64]) -> Option<IndependentRows> {
    let (rows, n) = (mech.n_pair_rows(), mech.n_x());
    let phi = sparse_scaled_jacobian(mech, x);
    let (lo, hi) = norm_bounds(&phi, n);
    let svd_error = SVD_ERROR_PER_DIMENSION * (rows + n) as f64 * f64::EPSILON * hi;
    // The SVD's threshold RANK_TOL max(sigma_max, 1) lies in [tol_lo, tol_hi].
    let (tol_lo, tol_hi) = (RANK_TOL * lo.max(1.0) - svd_error, RANK_TOL * hi.max(1.0) + svd_error);
    let mut row_pair = vec![PairId(0); rows];
    for k in 0..mech.pairs.len() {
        mech.pair_rows(PairId(k)).for_each(|r| row_pair[r] = PairId(k));
    }
    let mut out = IndependentRows { rank: 0, rows: Vec::new(), stresses: Vec::new() };
    let mut local = vec![0; n];
    let mut lambda = vec![0.0; rows];
    for Part { rows: part_rows, cols } in parts(&phi, n) {
        for (i, &c) in cols.iter().enumerate() {
            local[c] = i;
        }
        // Phi_x^T of the part: a row per body coordinate, a column per pair row.
        let mut t: Vec<SparseRow> = vec![Vec::new(); cols.len()];
        for (a, &r) in part_rows.iter().enumerate() {
            for &(c, v) in &phi[r] {
                t[local[c]].push((a, v));
            }
        }
        let pr = part_rows.len();
        let e = eliminate(t, pr, tol_lo, pr);
        let k = e.pivots.len();
        let lu_error = gamma(e.max_updates + 1) * ((e.l_norm2 + k as f64) * e.u_norm2).sqrt();
        if !(e.schur_norm2().sqrt() + lu_error < tol_lo) {
            return None;
        }
        let selected: Vec<SparseRow> = e.pivots.iter().map(|&(_, a)| phi[part_rows[a]].clone()).collect();
        if !gram_exceeds(&selected, n, tol_hi * tol_hi) {
            return None;
        }
        out.rank += k;
        out.rows.extend(e.pivots.iter().map(|&(_, a)| part_rows[a]));
        let u_cols = e.u_columns(pr);
        for o in (0..pr).filter(|&a| e.col_step[a] == usize::MAX) {
            let v = e.null_vector(o, &u_cols, &mut lambda[..pr]);
            out.stresses.push(stress_pairs(&v, &part_rows, &row_pair));
        }
    }
    out.rows.sort_unstable();
    Some(out)
}

/// The pairs whose rows hold more than SELF_STRESS_TOL of the unit self-stress `v` (its
/// non-zeros over the part's rows), ascending.
fn stress_pairs(v: &[(usize, f64)], part_rows: &[usize], row_pair: &[PairId]) -> Vec<PairId> {
    let norm2: f64 = v.iter().map(|e| e.1 * e.1).sum();
    let mut share: Vec<(PairId, f64)> = v.iter().map(|&(a, x)| (row_pair[part_rows[a]], x * x / norm2)).collect();
    share.sort_unstable_by_key(|s| s.0 .0);
    let mut pairs: Vec<PairId> = Vec::new();
    let mut i = 0;
    while i < share.len() {
        let (p, mut s) = (share[i].0, 0.0);
        while i < share.len() && share[i].0 == p {
            s += share[i].1;
            i += 1;
        }
        if s.sqrt() > SELF_STRESS_TOL {
            pairs.push(p);
        }
    }
    pairs
}
