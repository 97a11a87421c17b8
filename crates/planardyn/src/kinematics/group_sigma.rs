//! The type II measure per group (docs/formulation.md, *Singularities*): the smallest singular
//! value of each diagonal block of the block-triangular J (the input links and the Assur groups,
//! `linalg::BlockLu`), each block scaled by its own length, and the smallest of them.
//!
//! Why per group: J is singular exactly where one of its diagonal blocks is (det J is their
//! product), and a block's conditioning depends only on its own links. The smallest singular
//! value of the whole J also carries the chain's lever arms: on a chain of N parallelograms it
//! falls like 1/N^2 (its smallest along a 30 degree swing: 0.10 at N = 2, 5.8e-4 at N = 40)
//! with no group anywhere near a singularity, so no fixed threshold on it means the same for a
//! 3-body and an 81-body mechanism. Per group it stays at or above 0.37 along the same swing,
//! for every N.
//!
//! Why its own length: the factorised J is scaled by the mechanism's length L (the drawing's
//! diameter), which grows with a chain. Block k is rescaled here to its group's length L_k (the
//! diameter of its bodies' drawn points and centres of mass): rows in metres by L / L_k,
//! translation columns by L_k / L, so that the block's entries are O(1) in the group's own
//! units whatever the mechanism around it.
//!
//! Cost: linear in the bodies. The estimate runs inverse iteration on each block with the
//! factors already in hand (2 s^2 flops an iteration for a block of s rows); the exact measure
//! takes the SVD of each block (s^3), never of the whole J.

use super::constraints::Chart;
use super::system::fill_row_scale;
use crate::linalg::BlockLu;
use crate::model::diameter::diameter;
use crate::model::Mechanism;
use nalgebra::DMatrix;

/// Inverse iterations of a block's estimate from a cold start: 2 digits when the two smallest
/// singular values differ by 30 %, many more near a singularity (where they separate).
const ITERATIONS: usize = 8;
/// A warm-started estimate stops when an iteration changes 1/sigma^2 by less than this
/// (relative): sigma to about 1e-3, far finer than the chart thresholds (0.05, 0.1) need.
const RTOL: f64 = 2e-3;

/// Per permuted position of a [`BlockLu`]: the factors taking the globally scaled J to each
/// block's own length, and the inverse-iteration vectors of the estimate.
#[derive(Debug, Clone, Default)]
pub struct GroupScales {
    /// Row factor (L / L_k on rows in metres, 1 on rows in radians) and column factor (L_k / L
    /// on translations, 1 on angles), per permuted position.
    row: Vec<f64>,
    col: Vec<f64>,
    /// Per original column of J: L_k for a translation of a body of group k, 1 for an angle
    /// (x = col_scale * x_scaled, as `System::col_scale` with each group's own length).
    pub col_scale: Vec<f64>,
    /// The estimate's iteration vector (per position) and whether block k holds the singular
    /// vector of a previous estimate (a warm start).
    v: Vec<f64>,
    w: Vec<f64>,
    warm: Vec<bool>,
}

impl GroupScales {
    /// The factors of `lu`'s blocks, J being that of `chart`.
    pub fn new(mech: &Mechanism, chart: &Chart, lu: &BlockLu) -> Self {
        let n = mech.n_x();
        let mut metres = vec![0.0; n];
        // With 1/L = 0 the row scale is 0 exactly on the rows in metres.
        fill_row_scale(mech, chart, 0.0, &mut metres);
        let (rows, cols) = (lu.position_rows(), lu.position_cols());
        let (mut row, mut col, mut col_scale) = (vec![1.0; n], vec![1.0; n], vec![1.0; n]);
        for k in 0..lu.n_blocks() {
            let span = lu.span(k);
            let l_k = group_length(mech, &cols[span.clone()]);
            for p in span {
                if metres[rows[p]] == 0.0 {
                    row[p] = mech.scale / l_k;
                }
                if cols[p] % 3 != 2 {
                    col[p] = l_k / mech.scale;
                    col_scale[cols[p]] = l_k;
                }
            }
        }
        GroupScales { row, col, col_scale, v: vec![0.0; n], w: vec![0.0; n], warm: vec![false; lu.n_blocks()] }
    }

    /// Forget the singular vectors (the next estimate starts cold).
    pub fn reset(&mut self) {
        self.warm.fill(false);
    }

    /// The smallest, over the blocks of the factorised `lu`, of the estimated smallest singular
    /// value of the block at its own length: inverse iteration on (B B^T)^-1 with the block's
    /// LU factors (Golub & Van Loan 8.2.2). Each block's estimate approaches its sigma_min from
    /// above, with an error falling as (sigma_1 / sigma_2)^(2k), so it is sharpest exactly where
    /// it matters, near a singularity. Along a simulation each block starts from its previous
    /// singular vector and stops once the estimate moves by less than [`RTOL`].
    pub fn estimate(&mut self, lu: &BlockLu) -> f64 {
        // A fixed start with no special structure, so it is never orthogonal by design to
        // the singular vector of a symmetric group; a little of it is mixed into the warm
        // start so that no direction is missing there either.
        let fixed = |i: usize| 1.0 + 0.37 * ((i * 7 + 3) % 11) as f64;
        let mut best = f64::INFINITY;
        for k in 0..lu.n_blocks() {
            let span = lu.span(k);
            let (fr, fc) = (&self.row[span.clone()], &self.col[span.clone()]);
            let (v, w) = (&mut self.v[span.clone()], &mut self.w[span]);
            let warm = self.warm[k];
            for (i, v) in v.iter_mut().enumerate() {
                *v = if warm { *v + 1e-3 * fixed(i) } else { fixed(i) };
            }
            let mut lambda = 0.0;
            for it in 0..ITERATIONS {
                let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                v.iter_mut().for_each(|x| *x /= norm);
                // w = B'^-T B'^-1 v with B' = diag(fr) B diag(fc).
                for ((w, v), r) in w.iter_mut().zip(v.iter()).zip(fr) {
                    *w = v / r;
                }
                lu.block_solve(k, w);
                for (w, c) in w.iter_mut().zip(fc) {
                    *w /= c * c;
                }
                lu.block_solve_transpose(k, w);
                for (w, r) in w.iter_mut().zip(fr) {
                    *w /= r;
                }
                let previous = lambda;
                lambda = w.iter().zip(v.iter()).map(|(a, b)| a * b).sum::<f64>();
                v.copy_from_slice(w);
                if warm && it > 0 && (lambda - previous).abs() <= RTOL * lambda {
                    break;
                }
            }
            self.warm[k] = lambda.is_finite() && lambda > 0.0;
            best = best.min(if lambda > 0.0 { 1.0 / lambda.sqrt() } else { 0.0 });
        }
        best
    }

    /// The exact measure of the filled (not yet factorised) `lu`: the SVD of each block at its
    /// own length, the smallest singular value of them all.
    pub fn exact(&self, lu: &BlockLu) -> f64 {
        let mut best = f64::INFINITY;
        for k in 0..lu.n_blocks() {
            let span = lu.span(k);
            let s = span.len();
            let (fr, fc) = (&self.row[span.clone()], &self.col[span]);
            let b = lu.block(k);
            // The SVD iteration need not end on non-finite entries: such a block is singular.
            if b.iter().any(|v| !v.is_finite()) {
                return 0.0;
            }
            let mat = DMatrix::from_fn(s, s, |i, j| b[i * s + j] * fr[i] * fc[j]);
            best = best.min(mat.singular_values().min());
        }
        best
    }
}

/// Length of the group whose block has the columns `cols` (body coordinates): the diameter of
/// its bodies' drawn points and centres of mass (m); the mechanism's length if that is 0 (a
/// group of one point).
fn group_length(mech: &Mechanism, cols: &[usize]) -> f64 {
    let mut bodies: Vec<usize> = cols.iter().map(|c| c / 3).collect();
    bodies.sort_unstable();
    bodies.dedup();
    let points: Vec<[f64; 2]> = bodies
        .iter()
        .flat_map(|&b| {
            let body = &mech.bodies[b];
            body.points.iter().map(|(id, _)| mech.points[id.0].1).chain([body.com0])
        })
        .collect();
    let l = diameter(&points);
    if l > 0.0 {
        l
    } else {
        mech.scale
    }
}
