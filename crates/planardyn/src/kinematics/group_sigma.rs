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

use super::constraints::{fill_row_scale, Chart};
use crate::linalg::{cholesky_in_place, gamma, rounding_shift, BlockLu};
use crate::model::diameter::diameter;
use crate::model::pairs::frames::perp;
use crate::model::Mechanism;
use nalgebra::{DMatrix, SMatrix};

/// Inverse iterations of a block's estimate from a cold start: 2 digits when the two smallest
/// singular values differ by 30 %, many more near a singularity (where they separate).
const ITERATIONS: usize = 8;
/// A warm-started estimate stops when an iteration changes 1/sigma^2 by less than this
/// (relative): sigma to about 1e-3, far finer than the chart thresholds (0.05, 0.1) need.
const RTOL: f64 = 2e-3;
/// A group whose points lie within this fraction of the mechanism's length L of each other is
/// a point (one body with its centre of mass at its one point): its length is then L. Its
/// drawn points and centre of mass may differ by rounding (a slider's centre of mass given at
/// its point, the mass times 1e12: 5.6e-17 m apart), and that difference taken for its length
/// made every scaled distance of the run 1e16 times too large, so every evaluation failed.
const POINT_GROUP: f64 = 1e-9;

/// Largest block whose scratch [`GroupScales::below`] keeps on the stack.
const SMALL_BLOCK: usize = 8;

/// Per permuted position of a [`BlockLu`]: the factors taking the globally scaled J to each
/// block's own length, and the inverse-iteration vectors of the estimate.
#[derive(Debug, Default)]
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
    /// Scratch of [`GroupScales::below`]: a block and its Gram matrix (over [`SMALL_BLOCK`]).
    gram: Vec<f64>,
}

clone_reusing!(GroupScales { row, col, col_scale, v, w, warm, gram });

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
        GroupScales {
            row,
            col,
            col_scale,
            v: vec![0.0; n],
            w: vec![0.0; n],
            warm: vec![false; lu.n_blocks()],
            gram: Vec::new(),
        }
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
            // The SVD iteration need not end on non-finite entries: such a block is singular.
            let Some(sigma) = self.block_sigma(lu, k) else { return 0.0 };
            best = best.min(sigma);
        }
        best
    }

    /// Whether [`GroupScales::exact`] of the filled `lu` is below `t` (> 0), the same answer
    /// without the SVDs wherever rounding cannot change it: block B (scaled, s x s) has its
    /// smallest singular value at or above t exactly where G = B B^T - t^2 I is positive
    /// semidefinite, which a Cholesky factorisation of G shifted by what its rounding can hide
    /// decides both ways (Rump's argument, as `linalg::gram`'s: a factorisation that completes
    /// proves sigma > t; one that fails at the opposite shift proves sigma < t, by Demmel's
    /// condition for its success, Higham 2nd ed. ch. 10). Only a block whose measure is within
    /// hidden / (2 t) of t takes its SVD (hidden: that shift, ~s^2 eps ||B||_F^2), so the band
    /// widens like 1 / t^2 relative to t: ~1e-12 for the five-bar's 8 x 8 dyad block at t ~ 0.3,
    /// ~1e-6 at t ~ 1e-4. 2 s^3 / 3 flops a block where the SVD takes tens of s^3. A threshold
    /// that is not positive (or NaN) is never above a measure, as `exact(..) < t` says.
    pub fn below(&mut self, lu: &BlockLu, t: f64) -> bool {
        if !(t > 0.0) {
            return false;
        }
        for k in 0..lu.n_blocks() {
            let s = lu.span(k).len();
            let (fr, fc) = (&self.row[lu.span(k)], &self.col[lu.span(k)]);
            let b = lu.block(k);
            // As `exact`: a block with a non-finite entry is singular.
            if b.iter().any(|v| !v.is_finite()) {
                return true;
            }
            // On the stack up to 8 x 8 (the five-bar's dyad block): `gram` grew once for
            // each new analysis of the chart's blocks otherwise (16 k of the free fall's run).
            let mut stack = [0.0; 2 * SMALL_BLOCK * SMALL_BLOCK];
            let scratch = if s <= SMALL_BLOCK {
                &mut stack[..2 * s * s]
            } else {
                self.gram.resize(2 * s * s, 0.0);
                &mut self.gram[..]
            };
            let (rows, gram) = scratch.split_at_mut(s * s);
            for (i, row) in rows.chunks_exact_mut(s).enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = b[i * s + j] * fr[i] * fc[j];
                }
            }
            // The lower triangle of B B^T, and its trace (= ||B||_F^2, which bounds every rounding).
            let mut trace = 0.0;
            for i in 0..s {
                for j in 0..=i {
                    gram[i * s + j] =
                        rows[i * s..(i + 1) * s].iter().zip(&rows[j * s..(j + 1) * s]).map(|(a, b)| a * b).sum();
                }
                trace += gram[i * s + i];
            }
            let g = gamma(s + 1);
            let hidden = rounding_shift(s as f64 * g / (1.0 - s as f64 * g), s, trace);
            let t2 = t * t;
            if shifted_factorises(gram, rows, s, t2 * (1.0 + 2.0 * f64::EPSILON) + hidden) {
                continue;
            }
            if !shifted_factorises(gram, rows, s, t2 * (1.0 - 2.0 * f64::EPSILON) - hidden)
                || self.block_sigma(lu, k).is_none_or(|sigma| sigma < t)
            {
                return true;
            }
        }
        false
    }

    /// The smallest singular value of block k of the filled `lu` at its own length (None where
    /// an entry is not finite).
    fn block_sigma(&self, lu: &BlockLu, k: usize) -> Option<f64> {
        let span = lu.span(k);
        let s = span.len();
        let (fr, fc) = (&self.row[span.clone()], &self.col[span]);
        let b = lu.block(k);
        if b.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let entry = |i: usize, j: usize| b[i * s + j] * fr[i] * fc[j];
        // nalgebra's SVD runs the same steps whatever the matrix's storage, except its own
        // 2 x 2 and 3 x 3 paths (which differ in the last bits): a fixed 1 x 1 or 6 x 6 only
        // spares the heap (the five-bar's 176 input-link and 79 dyad blocks of a run's 431).
        Some(match s {
            1 => SMatrix::<f64, 1, 1>::from_fn(entry).singular_values().min(),
            6 => SMatrix::<f64, 6, 6>::from_fn(entry).singular_values().min(),
            _ => DMatrix::from_fn(s, s, entry).singular_values().min(),
        })
    }
}

/// Whether the Cholesky factorisation of `gram` (s x s, its lower triangle) less `shift` on its
/// diagonal runs to completion, in `work` (s x s).
fn shifted_factorises(gram: &[f64], work: &mut [f64], s: usize, shift: f64) -> bool {
    work.copy_from_slice(gram);
    for i in 0..s {
        work[i * s + i] -= shift;
    }
    cholesky_in_place(work, s)
}

/// Length of the group whose block has the columns `cols` (body coordinates): see
/// [`bodies_length`].
fn group_length(mech: &Mechanism, cols: &[usize]) -> f64 {
    let mut bodies: Vec<usize> = cols.iter().map(|c| c / 3).collect();
    bodies.sort_unstable();
    bodies.dedup();
    bodies_length(mech, &bodies)
}

/// Length L_k of the group of `bodies`: the diameter of their drawn points and centres of mass
/// (m); the mechanism's length if that is 0 (a group of one point, to [`POINT_GROUP`]).
pub(crate) fn bodies_length(mech: &Mechanism, bodies: &[usize]) -> f64 {
    let points: Vec<[f64; 2]> = bodies
        .iter()
        .flat_map(|&b| {
            let body = &mech.bodies[b];
            body.points.iter().map(|(id, _)| mech.points[id.0].1).chain([body.com0])
        })
        .collect();
    let l = diameter(&points);
    if l > POINT_GROUP * mech.scale {
        l
    } else {
        mech.scale
    }
}

/// The measure of an input slider on a guide fixed to the ground, in closed form: its block,
/// rows the pair's angle row, its normal row and the coordinate's (along the guide), is
/// [[0, 1], [Q, E R s / L_k]] with Q the guide's normal and axis (orthonormal rows), whose
/// singular values are 1 and those of [[1, a], [0, 1]], a = |s| / L_k, the smaller
/// (sqrt(a^2 + 4) - a) / 2, whatever the slider's place.
pub(crate) fn input_link_sigma(a: f64) -> f64 {
    0.5 * ((a * a + 4.0).sqrt() - a)
}

/// Newton iterations of [`dyad_sigma`]'s scalar equation; from its start it converges
/// monotonically and quadratically, in 4 to 8.
const DYAD_ITERATIONS: usize = 40;

/// The measure of an RRR dyad's block in closed form, from its lever arms at its own length:
/// `a`, `b` the points A, B and `p1`, `p2` the point P, each as R s / L_k on body 1 (A, P) or
/// body 2 (B, P). The block, columns (r1, r2 | phi1, phi2), is [T, Phi] with T the pairs' rows
/// on the translations (constant: T^T T = [[2, -1], [-1, 2]] (x) I, eigenvalues 1 and 3) and
/// Phi their rows on the angles (the arms turned by E, which changes no dot product). Its
/// smallest squared singular value lambda is the smallest root of the 2 x 2 secular equation
/// mu(lambda) = lambda_min(Phi^T Phi - lambda - C^T (T^T T - lambda)^-1 C) = 0, C = T^T Phi,
/// in [0, 1] (lambda <= 1: r1 = r2, no turn, is a unit vector that B' maps to a unit one).
/// mu is decreasing and concave there, so Newton from 0 lands past the root once and then
/// falls back to it monotonically. A root at 0 (mu(0) <= 0) is a type II singularity.
pub(crate) fn dyad_sigma(a: [f64; 2], b: [f64; 2], p1: [f64; 2], p2: [f64; 2]) -> f64 {
    let dot = |u: [f64; 2], v: [f64; 2]| u[0] * v[0] + u[1] * v[1];
    let g = [dot(a, a) + dot(p1, p1), -dot(p1, p2), dot(b, b) + dot(p2, p2)];
    // C^T P1 C and C^T P3 C (P1, P3 the projections on T^T T's eigenspaces, times 2): the
    // sums and differences of C's two row blocks, (a, b) and (a + 2 p1, -(b + 2 p2)).
    let s = [dot(a, a), dot(a, b), dot(b, b)];
    let d1 = [a[0] + 2.0 * p1[0], a[1] + 2.0 * p1[1]];
    let d2 = [-b[0] - 2.0 * p2[0], -b[1] - 2.0 * p2[1]];
    let d = [dot(d1, d1), dot(d1, d2), dot(d2, d2)];
    // mu(lambda) and mu'(lambda): the smaller eigenvalue of the symmetric 2 x 2 M(lambda) and
    // its derivative along M'(lambda).
    let mu = |l: f64| {
        let (k1, k3) = (0.5 / (1.0 - l), 0.5 / (3.0 - l));
        let m = [0, 1, 2].map(|i| g[i] - k1 * s[i] - k3 * d[i] - if i == 1 { 0.0 } else { l });
        let n = [0, 1, 2].map(|i| -k1 * k1 * 2.0 * s[i] - k3 * k3 * 2.0 * d[i] - if i == 1 { 0.0 } else { 1.0 });
        smaller_eigenvalue(m, n)
    };
    secular_root(mu, 1.0).sqrt()
}

/// The smaller eigenvalue of the symmetric 2 x 2 m ([m00, m01, m11]) and its derivative along
/// the symmetric n.
fn smaller_eigenvalue(m: [f64; 3], n: [f64; 3]) -> (f64, f64) {
    let (half, r) = (0.5 * (m[0] - m[2]), (0.25 * (m[0] - m[2]).powi(2) + m[1] * m[1]).sqrt());
    let value = 0.5 * (m[0] + m[2]) - r;
    let slope = if r > 0.0 {
        0.5 * (n[0] + n[2]) - (half * 0.5 * (n[0] - n[2]) + m[1] * n[1]) / r
    } else {
        0.5 * (n[0] + n[2]) - (0.25 * (n[0] - n[2]).powi(2) + n[1] * n[1]).sqrt()
    };
    (value, slope)
}

/// The smallest root in [0, pole) of a secular function mu (value and slope), decreasing and
/// concave there: Newton from 0 lands past the root once and then falls back to it
/// monotonically; a step to the pole or past it is halved. 0 if mu(0) <= 0.
fn secular_root(mu: impl Fn(f64) -> (f64, f64), pole: f64) -> f64 {
    let (mut l, (mut f, mut df)) = (0.0, mu(0.0));
    if !(f > 0.0) {
        return 0.0;
    }
    for _ in 0..DYAD_ITERATIONS {
        let mut next = l - f / df;
        if !(next < pole) {
            next = 0.5 * (l + pole);
        }
        if (next - l).abs() <= 4.0 * f64::EPSILON * next.abs() {
            l = next;
            break;
        }
        l = next;
        (f, df) = mu(l);
    }
    l.max(0.0)
}

/// The measure of an RRP dyad's block in closed form, from the entries of its angle columns
/// at its own length: `a` body 1's at A and `p1` at P, `p2` body 2's at P (each E R s / L_k),
/// and the prismatic pair's normal row: unit normal `n` on body 2's centre (times `sign`) and
/// `g` on its angle. In the basis (t, n) of the guide (rows of each pair and translation
/// columns of each body turned alike, which changes no singular value), the translation
/// columns T split into the t parts of r1, r2, with T^T T = [[2, -1], [-1, 1]], and their n
/// parts, with [[2, -1], [-1, 2]]. The smallest squared singular value lambda is then the
/// smallest root of mu(lambda) = lambda_min(Phi^T Phi - lambda - sum C_i^T (M_i - lambda)^-1
/// C_i) (C_i = T_i^T Phi), below (3 - sqrt 5) / 2, T^T T's smallest eigenvalue (its unit
/// eigenvector, no turn, is one B maps to that length): as [`dyad_sigma`]'s, mu is
/// decreasing and concave there.
///
/// That root is exact to about 1e-16 absolute, so sigma = sqrt(lambda) would lose its
/// relative accuracy near a singularity. The root is therefore polished once: with K the
/// block's angle columns seen from the complement of T's range ([[0, 1], [sign (p1 - a) . n,
/// g - sign p2 . n] / sqrt 3], whose determinant is the dyad's n . E e / L_k, up to sign and
/// sqrt 3), mu(lambda) = lambda_min(K^T K - lambda D(lambda)) with D = I + sum C_i^T M_i^-1
/// (M_i - lambda)^-1 C_i, so lambda is the smallest eigenvalue of the pencil (K^T K, D(lambda)),
/// det(K)^2 / (det D mu_max) with mu_max its largest: no cancellation, and D changes by
/// O(lambda) relative over the root's error.
pub(crate) fn rrp_sigma(a: [f64; 2], p1: [f64; 2], p2: [f64; 2], n: [f64; 2], sign: f64, g: f64) -> f64 {
    let dot = |u: [f64; 2], v: [f64; 2]| u[0] * v[0] + u[1] * v[1];
    let t = [n[1], -n[0]];
    let along = |u: [f64; 2]| [dot(u, t), dot(u, n)];
    let ([at, an], [p1t, p1n], [p2t, p2n]) = (along(a), along(p1), along(p2));
    // C_i (rows r1, r2 of the part; columns phi1, phi2) and Phi^T Phi.
    let c_t = [[at + p1t, -p2t], [-p1t, p2t]];
    let c_n = [[an + p1n, -p2n], [-p1n, p2n + sign * g]];
    let gram = [dot(a, a) + dot(p1, p1), -dot(p1, p2), dot(p2, p2) + 1.0 + g * g];
    // C^T (M - lambda)^-1 C and C^T (M - lambda)^-2 C, M = [[2, -1], [-1, m11]].
    let terms = |c: [[f64; 2]; 2], m11: f64, l: f64| {
        let (p, r) = (2.0 - l, m11 - l);
        let det = p * r - 1.0;
        // W = (M - lambda)^-1 C.
        let w = [0, 1].map(|j| [(r * c[0][j] + c[1][j]) / det, (c[0][j] + p * c[1][j]) / det]);
        let cw = |i: usize, j: usize| c[0][i] * w[j][0] + c[1][i] * w[j][1];
        let ww = |i: usize, j: usize| w[i][0] * w[j][0] + w[i][1] * w[j][1];
        ([cw(0, 0), cw(0, 1), cw(1, 1)], [ww(0, 0), ww(0, 1), ww(1, 1)])
    };
    let mu = |l: f64| {
        let ((st, dt), (sn, dn)) = (terms(c_t, 1.0, l), terms(c_n, 2.0, l));
        let diagonal = |i: usize| if i == 1 { 0.0 } else { 1.0 };
        let m = [0, 1, 2].map(|i| gram[i] - st[i] - sn[i] - l * diagonal(i));
        let d = [0, 1, 2].map(|i| -dt[i] - dn[i] - diagonal(i));
        smaller_eigenvalue(m, d)
    };
    let l = secular_root(mu, 0.5 * (3.0 - 5f64.sqrt()));
    // K (the complement of T's range: the angle row, and (-sign A_n + sign P_n + N) / sqrt 3).
    let third = 1.0 / 3.0;
    let (k10, k11) = (sign * (p1n - an), g - sign * p2n);
    let gk = [k10 * k10 * third, k10 * k11 * third, 1.0 + k11 * k11 * third];
    let det_k2 = k10 * k10 * third;
    // D(lambda): Z = M^-1 (M - lambda)^-1 (they commute), D = I + sum C^T Z C.
    let part = |c: [[f64; 2]; 2], m11: f64| {
        let (det0, det) = (2.0 * m11 - 1.0, (2.0 - l) * (m11 - l) - 1.0);
        // M^-1 = [[m11, 1], [1, 2]] / det0, (M - lambda)^-1 = [[m11 - lambda, 1], [1, 2 - lambda]] / det.
        let z = [m11 * (m11 - l) + 1.0, m11 + 2.0 - l, 1.0 + 2.0 * (2.0 - l)].map(|v| v / (det0 * det));
        let zc = [0, 1].map(|j| [z[0] * c[0][j] + z[1] * c[1][j], z[1] * c[0][j] + z[2] * c[1][j]]);
        let q = |i: usize, j: usize| c[0][i] * zc[j][0] + c[1][i] * zc[j][1];
        [q(0, 0), q(0, 1), q(1, 1)]
    };
    let (dt, dn) = (part(c_t, 1.0), part(c_n, 2.0));
    let d = [1.0 + dt[0] + dn[0], dt[1] + dn[1], 1.0 + dt[2] + dn[2]];
    let det_d = d[0] * d[2] - d[1] * d[1];
    // det(K^T K - mu D) = det_d mu^2 - b mu + det_k2: the smaller root without cancellation.
    let b = d[0] * gk[2] + d[2] * gk[0] - 2.0 * d[1] * gk[1];
    let lambda = 2.0 * det_k2 / (b + (b * b - 4.0 * det_d * det_k2).max(0.0).sqrt());
    lambda.sqrt()
}

/// A group's block at its own length for a fixed-size SVD, where its measure has no closed
/// form: columns (r, phi) of each of its bodies (by place), rows added a pair at a time; as in
/// [`dyad_sigma`], translations enter as +-1 and angles by their lever arms R s / L_k.
pub(crate) struct Block {
    m: DMatrix<f64>,
    row: usize,
    inv_length: f64,
}

impl Block {
    /// The block of a group of `bodies` bodies, 1 / L_k = `inv_length`.
    pub fn new(bodies: usize, inv_length: f64) -> Self {
        Block { m: DMatrix::zeros(3 * bodies, 3 * bodies), row: 0, inv_length }
    }

    /// The two rows of a point's coincidence: per body of the group holding it (its place,
    /// the sign, and R s, the point less the body's centre).
    pub fn point_rows(&mut self, ends: &[(usize, f64, [f64; 2])]) {
        for &(b, sign, arm) in ends {
            for (k, e) in perp(arm).into_iter().enumerate() {
                self.m[(self.row + k, 3 * b + k)] = sign;
                self.m[(self.row + k, 3 * b + 2)] = sign * e * self.inv_length;
            }
        }
        self.row += 2;
    }

    /// The row of two bodies' equal angles.
    pub fn angle_row(&mut self, a: usize, b: usize) {
        (self.m[(self.row, 3 * a + 2)], self.m[(self.row, 3 * b + 2)]) = (-1.0, 1.0);
        self.row += 1;
    }

    /// Its smallest singular value.
    pub fn sigma(self) -> f64 {
        self.m.singular_values().min()
    }
}

/// Iterations of [`triad_sigma`]'s safeguarded Laguerre iteration; it converges in about 5 (up to
/// ~45 at a double root, where it is linear: three-fold symmetric triads).
const TRIAD_ITERATIONS: usize = 60;

/// The relative width of [`triad_sigma`]'s bracket [lo, hi] (M positive definite at lo, not at
/// hi) within which hi is taken as the root: 64 ulps of lambda, 32 of sigma, the round-off of
/// M's entries. At the root M is singular to round-off, and the step that converges lands on it
/// or a few ulps past it (the factor fails there): the iteration then tries [`TRIAD_BRACKET`] / 2
/// below, which closes the bracket (bisecting from lo instead halved a 1e-6 bracket 30 times on
/// the 3-RRR's run).
const TRIAD_BRACKET: f64 = 64.0 * f64::EPSILON;

/// The measure of a 6R triad's 12 x 12 block in closed form, from its lever arms at its own
/// length: per leg i, `a[i]` A_i and `p[i]` C_i on the leg (R s / L_k), `l[i]` C_i on the
/// platform. As in [`dyad_sigma`], the block is B = [T, Phi] (translations | angles), with T^T T =
/// K (x) I constant, K = [[2, 0, 0, -1], [0, 2, 0, -1], [0, 0, 2, -1], [-1, -1, -1, 3]]
/// (the legs, then the platform; eigenvalues 2, 2 and (5 +- 13^(1/2)) / 2). Its smallest
/// squared singular value lambda is the smallest root of det M(lambda) = 0,
/// M(lambda) = Phi^T Phi - lambda - C^T (K (x) I - lambda)^-1 C (4 x 4, C = T^T Phi), in
/// [0, k_min] (a unit translation along K's eigenvector of k_min has |B v|^2 = k_min). M is
/// positive definite exactly below the root (it decreases with lambda), which brackets the
/// steps. det(B^T B - lambda) = det(K (x) I - lambda) det M(lambda) (M the Schur complement) is
/// a polynomial of degree 12 with real roots only, on which Laguerre's iteration from 0 goes up
/// to the smallest root without passing it, cubically near it (5.5 iterations a call in the
/// 3-RRR's benchmark run, where Newton's on det M took 13, 8.5 with this bracket's back-off, each
/// ~250 instructions fewer): from
/// g = (ln det)' = tr(M^-1 M') - sum_r n_r / (k_r - lambda) and
/// h = -(ln det)'' = tr((M^-1 M')^2) - tr(M^-1 M'') + sum_r n_r / (k_r - lambda)^2
/// (n_r the multiplicity of K's eigenvalue k_r, doubled by (x) I), the step is
/// 12 / (-g + ((12 - 1) (12 h - g^2))^(1/2)). A step out of the bracket bisects it.
pub(crate) fn triad_sigma(a: [[f64; 2]; 3], p: [[f64; 2]; 3], l: [[f64; 2]; 3]) -> f64 {
    let dot = |u: [f64; 2], v: [f64; 2]| u[0] * v[0] + u[1] * v[1];
    let add = |u: [f64; 2], v: [f64; 2], s: f64| [u[0] + s * v[0], u[1] + s * v[1]];
    // C's rows (each a 2-vector per angle column): leg i [a_i + p_i at i, -l_i at 3], the
    // platform [-p_i at i, sum l_i at 3].
    let mut c = [[[0.0; 2]; 4]; 4];
    for i in 0..3 {
        c[i][i] = add(a[i], p[i], 1.0);
        c[i][3] = add([0.0; 2], l[i], -1.0);
        c[3][i] = add([0.0; 2], p[i], -1.0);
        c[3][3] = add(c[3][3], l[i], 1.0);
    }
    let root13 = 13.0_f64.sqrt();
    let (k_plus, k_minus) = (0.5 * (5.0 + root13), 0.5 * (5.0 - root13));
    let symmetric = |k: f64| {
        let b = 2.0 - k;
        let a = 1.0 / (3.0 + b * b).sqrt();
        [a, a, a, b * a]
    };
    let (r2, r6) = (0.5_f64.sqrt(), (1.0_f64 / 6.0).sqrt());
    let vectors = [[r2, -r2, 0.0, 0.0], [r6, r6, -2.0 * r6, 0.0], symmetric(k_plus), symmetric(k_minus)];
    // G_r = W_r^T W_r, W_r = (v_r (x) I)^T C; the two of eigenvalue 2 summed. The upper
    // triangles, mirrored (w_j . w_k is w_k . w_j to the bit).
    let mut g = [[[0.0; 4]; 4]; 3];
    for (r, v) in vectors.iter().enumerate() {
        // Leg column j of C holds rows j and 3 only: the other products are zeros, which add exactly.
        let w: [[f64; 2]; 4] = [0, 1, 2, 3].map(|j| {
            if j < 3 {
                add(add([0.0; 2], c[j][j], v[j]), c[3][j], v[3])
            } else {
                (0..4).fold([0.0; 2], |s, n| add(s, c[n][j], v[n]))
            }
        });
        for j in 0..4 {
            for k in j..4 {
                g[r.saturating_sub(1)][j][k] += dot(w[j], w[k]);
            }
        }
    }
    for g in &mut g {
        for (j, k) in [(1, 0), (2, 0), (2, 1), (3, 0), (3, 1), (3, 2)] {
            g[j][k] = g[k][j];
        }
    }
    // K's eigenvalues and their multiplicities in K (x) I (12 in all with M's 4 columns).
    let (poles, multiplicity) = ([2.0, k_plus, k_minus], [4.0, 2.0, 2.0]);
    const DEGREE: f64 = 12.0;
    let mut phi = [[0.0; 4]; 4];
    for i in 0..3 {
        phi[i][i] = dot(a[i], a[i]) + dot(p[i], p[i]);
        phi[i][3] = -dot(p[i], l[i]);
        phi[3][i] = phi[i][3];
        phi[3][3] += dot(l[i], l[i]);
    }
    // M(lambda), symmetric as phi and G_r are to the bit (its (j, k) and (k, j) entries are the
    // same products summed in the same order): the upper triangle, mirrored.
    let m = |f: [f64; 3], lambda: f64| {
        let mut m = [[0.0; 4]; 4];
        for j in 0..4 {
            for k in j..4 {
                let eye = if j == k { 1.0 } else { 0.0 };
                m[j][k] = phi[j][k] - eye * lambda - (0..3).map(|r| g[r][j][k] * f[r]).sum::<f64>();
                m[k][j] = m[j][k];
            }
        }
        m
    };
    let (mut lo, mut hi, mut lambda, mut backed_off) = (0.0, k_minus, 0.0, false);
    for it in 0..TRIAD_ITERATIONS {
        let f = poles.map(|k| 1.0 / (k - lambda));
        let Some(factor) = cholesky(&m(f, lambda)) else {
            if it == 0 {
                return 0.0; // M(0) singular: so is the block
            }
            if lambda - lo <= TRIAD_BRACKET * lambda {
                return lambda.sqrt(); // the root is in [lo, lambda], within round-off of lambda
            }
            hi = lambda;
            // Once just below (the step's landing past the root by round-off), else bisect.
            lambda = if backed_off { 0.5 * (lo + hi) } else { hi - 0.5 * TRIAD_BRACKET * hi };
            backed_off = true;
            continue;
        };
        lo = lambda;
        if hi - lo <= TRIAD_BRACKET * hi {
            return hi.sqrt();
        }
        let inv = inverse(&factor);
        // M' = -I - sum_r G_r f_r^2 (symmetric), x = M^-1 M'; tr(M^-1 M'') from
        // M'' = -2 sum_r G_r f_r^3 as the products <M^-1, G_r> (both symmetric).
        let mut d = [[0.0; 4]; 4];
        let mut inner = [0.0; 3];
        for j in 0..4 {
            for k in j..4 {
                let eye = if j == k { 1.0 } else { 0.0 };
                d[j][k] = -eye - (0..3).map(|r| g[r][j][k] * (f[r] * f[r])).sum::<f64>();
                d[k][j] = d[j][k];
                let twice = if j == k { 1.0 } else { 2.0 };
                (0..3).for_each(|r| inner[r] += twice * inv[j][k] * g[r][j][k]);
            }
        }
        let x: [[f64; 4]; 4] = inv.map(|row| [0, 1, 2, 3].map(|n| (0..4).map(|k| row[k] * d[k][n]).sum::<f64>()));
        let inv_m2 = -2.0 * (0..3).map(|r| inner[r] * (f[r] * f[r] * f[r])).sum::<f64>();
        let trace: f64 = (0..4).map(|j| x[j][j]).sum();
        let square: f64 = (0..4).map(|j| (0..4).map(|k| x[j][k] * x[k][j]).sum::<f64>()).sum();
        let poles_g: f64 = (0..3).map(|r| multiplicity[r] * f[r]).sum();
        let poles_h: f64 = (0..3).map(|r| multiplicity[r] * f[r] * f[r]).sum();
        let (gl, hl) = (trace - poles_g, square - inv_m2 + poles_h);
        let root = ((DEGREE - 1.0) * (DEGREE * hl - gl * gl)).max(0.0).sqrt();
        let mut next = lambda + DEGREE / (root - gl);
        if !(next < hi) {
            next = 0.5 * (lambda + hi);
        }
        if (next - lambda).abs() <= 4.0 * f64::EPSILON * next.abs() {
            return next.max(0.0).sqrt();
        }
        lambda = next;
    }
    lambda.max(0.0).sqrt()
}

/// The Cholesky factor L (M = L L^T) of a symmetric 4 x 4 matrix, None unless positive definite.
fn cholesky(m: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let mut l = [[0.0; 4]; 4];
    for j in 0..4 {
        let d = m[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if !(d > 0.0) {
            return None;
        }
        l[j][j] = d.sqrt();
        for i in j + 1..4 {
            l[i][j] = (m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>()) / l[j][j];
        }
    }
    Some(l)
}

/// M^-1 = L^-T L^-1 from M's Cholesky factor L, column by column (each also a row: it is
/// symmetric).
fn inverse(l: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    [0, 1, 2, 3].map(|c| {
        let mut y = [0.0; 4];
        for i in 0..4 {
            let e = if i == c { 1.0 } else { 0.0 };
            y[i] = (e - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
        }
        for i in (0..4).rev() {
            y[i] = (y[i] - (i + 1..4).map(|k| l[k][i] * y[k]).sum::<f64>()) / l[i][i];
        }
        y
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`triad_sigma`]'s squared measure is the smallest squared singular value of the triad's
    /// 12 x 12 block (its SVD, `Block::sigma`, the path of triads with cylinder legs) within
    /// 64 eps |B|_F^2: the SVD's sigma is exact for B + E with |E| a few eps |B| (so its square
    /// within a few eps |B|^2), and triad_sigma's lambda is a root of det M to M's round-off.
    /// Random triads (arms in [-0.5, 0.5]^2) and three-fold symmetric ones, whose two smallest
    /// singular values are equal (a double root, where Laguerre's iteration is only linear).
    #[test]
    fn triad_sigma_is_the_svd_of_its_block() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let turn = |v: [f64; 2], i: usize| {
            let (s, c) = (2.0 * std::f64::consts::PI * i as f64 / 3.0).sin_cos();
            [c * v[0] - s * v[1], s * v[0] + c * v[1]]
        };
        for case in 0..400 {
            let mut arms = [[[0.0; 2]; 3]; 3];
            for arm in arms.iter_mut() {
                let first = [next(), next()];
                for (i, leg) in arm.iter_mut().enumerate() {
                    *leg = if case % 2 == 0 {
                        turn(first, i)
                    } else if i == 0 {
                        first
                    } else {
                        [next(), next()]
                    };
                }
            }
            let [a, p, l] = arms;
            let mut block = Block::new(4, 1.0);
            let mut frobenius = 0.0;
            for i in 0..3 {
                block.point_rows(&[(i, 1.0, a[i])]);
                block.point_rows(&[(i, 1.0, p[i]), (3, -1.0, l[i])]);
                frobenius += 6.0 + a[i].iter().chain(&p[i]).chain(&l[i]).map(|v| v * v).sum::<f64>();
            }
            let (sigma, svd) = (triad_sigma(a, p, l), block.sigma());
            let tol = 64.0 * f64::EPSILON * frobenius;
            assert!((sigma * sigma - svd * svd).abs() <= tol, "case {case}: {sigma} against the SVD's {svd}");
        }
    }

    /// `exact`'s fixed-size SVDs give the dynamic one's smallest singular value bit for bit
    /// (random blocks of each fixed size, some near singular: a row the sum of two plus 1e-9).
    /// nalgebra's 2 x 2 and 3 x 3 fail it (0.21736490036884942 for ...956).
    #[test]
    fn fixed_size_svds_are_the_dynamic_ones_bit_for_bit() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        macro_rules! check {
            ($s:literal) => {
                for trial in 0..50 {
                    let mut b = DMatrix::from_fn($s, $s, |_, _| next());
                    if trial % 2 == 1 && $s > 1 {
                        let sum = b.row(0) + b.row($s / 2) + DMatrix::from_element(1, $s, 1e-9);
                        b.set_row($s - 1, &sum);
                    }
                    let fixed = SMatrix::<f64, $s, $s>::from_fn(|i, j| b[(i, j)]).singular_values();
                    assert_eq!(fixed.min(), b.singular_values().min(), "{} x {}, trial {trial}", $s, $s);
                }
            };
        }
        check!(1);
        check!(6);
    }

    /// rrp_sigma against the SVD of the block it stands for, over random arms and guides,
    /// down to blocks near singular (the arm p1 turned onto the guide's normal).
    #[test]
    fn rrp_sigma_is_the_svd_of_its_block() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let (mut worst, mut smallest) = (0.0_f64, f64::INFINITY);
        for i in 0..2000 {
            let angle = std::f64::consts::PI * next();
            let n = [angle.cos(), angle.sin()];
            let (a, mut p1, p2) = ([next(), next()], [next(), next()], [next(), next()]);
            if i % 2 == 1 {
                // p1 - a = E e / L_k nearly along the guide: the rod nearly normal to it.
                let off = 1e-6 * next();
                p1 = [a[0] + p1[0] * off + n[1] * 0.5, a[1] + p1[1] * off - n[0] * 0.5];
            }
            let (sign, g) = (if next() > 0.0 { 1.0 } else { -1.0 }, next());
            #[rustfmt::skip]
            let b = SMatrix::<f64, 6, 6>::from_row_slice(&[
                1.0, 0.0, a[0], 0.0, 0.0, 0.0,
                0.0, 1.0, a[1], 0.0, 0.0, 0.0,
                1.0, 0.0, p1[0], -1.0, 0.0, -p2[0],
                0.0, 1.0, p1[1], 0.0, -1.0, -p2[1],
                0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
                0.0, 0.0, 0.0, sign * n[0], sign * n[1], g,
            ]);
            let (svd, closed) = (b.singular_values().min(), rrp_sigma(a, p1, p2, n, sign, g));
            // Both are exact to about 1e-16 (the block's norm) absolute.
            worst = worst.max((svd - closed).abs());
            smallest = smallest.min(svd);
        }
        eprintln!("rrp_sigma: worst difference {worst:.1e}, smallest sigma {smallest:.1e}");
        assert!(smallest < 1e-9, "no near-singular block drawn: smallest {smallest:e}");
        assert!(worst < 1e-14, "rrp_sigma differs from the SVD by {worst:e}");
    }
}
