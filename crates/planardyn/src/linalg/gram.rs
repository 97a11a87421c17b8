//! A proof that the smallest eigenvalue of the Gram matrix G = R R^T of sparse rows R exceeds
//! a bound: a floating-point Cholesky factorisation of G - s I that runs to completion, with
//! the shift s the bound plus what the rounding of G and of the factorisation can hide.
//!
//! The computed factor L of A = fl(G - s I) satisfies L L^T = A + dA with
//! ||dA||_2 <= gamma_{w+1} ||L||_F^2 <= gamma_{w+1} trace(A) / (1 - gamma_{w+1}), w the longest
//! row of L (Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed., Thm 10.3; the
//! argument of Rump, "Verification of positive definiteness", BIT 46, 2006): so A + dA is
//! positive semidefinite and lambda_min(A) >= -||dA||_2. Each entry of the computed G is a sum
//! of at most d products (d the longest row of R): ||fl(G) - G||_2 <= gamma_d trace(G). The
//! shift below covers both, twice over, and the rounding of the diagonal's subtraction.
//!
//! The rows are put in reverse Cuthill-McKee order (rows adjacent when they share a column),
//! so that L stays within a narrow envelope, kept row by row (a skyline): O(rows w^2) for a
//! chain or a ladder of loops, where a dense G would be O(rows^3). Hand-written rather than a
//! sparse crate added for this one check of the loader: nalgebra, the crate's linear algebra,
//! has no sparse Cholesky, and the proof's shift needs the envelope's widest row w, which the
//! skyline knows before it factorises.

use super::sparse_pivot::SparseRow;

/// Twice the unit roundoff: every gamma below is an over-estimate.
const U: f64 = f64::EPSILON;

/// gamma_n = n u / (1 - n u) (Higham, Lemma 3.1), with u over-estimated as eps: the bound on
/// the relative rounding of a sum of n products.
pub fn gamma(n: usize) -> f64 {
    let nu = n as f64 * U;
    nu / (1.0 - nu)
}

/// What the rounding of a Gram matrix G (entries sums of at most `d` products, trace `trace`) and
/// of a Cholesky factorisation of it can hide of its eigenvalues, twice over (see the module):
/// `factor` bounds ||dA||_2 / trace for the factorisation, gamma_{w+1} / (1 - gamma_{w+1}) for
/// an envelope of width w.
pub fn rounding_shift(factor: f64, d: usize, trace: f64) -> f64 {
    2.0 * (factor + 2.0 * gamma(d) + U) * trace
}

/// Whether lambda_min(R R^T) > `bound` is proven, `rows` the rows of R (`ncols` columns).
/// False means not proven (G near singular, or not positive definite at all).
pub fn gram_exceeds(rows: &[SparseRow], ncols: usize, bound: f64) -> bool {
    let k = rows.len();
    if k == 0 {
        return true;
    }
    let mut col_rows = vec![Vec::new(); ncols];
    for (i, row) in rows.iter().enumerate() {
        for &(c, _) in row {
            col_rows[c].push(i);
        }
    }
    let adj: Vec<Vec<usize>> = rows
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let mut a: Vec<usize> =
                row.iter().flat_map(|&(c, _)| col_rows[c].iter().copied()).filter(|&j| j != i).collect();
            a.sort_unstable();
            a.dedup();
            a
        })
        .collect();
    let order = reverse_cuthill_mckee(&adj);
    let mut at = vec![0; k];
    for (p, &i) in order.iter().enumerate() {
        at[i] = p;
    }
    // Row p of L spans columns first[p]..=p (its envelope), stored from start[p].
    let first: Vec<usize> =
        order.iter().enumerate().map(|(p, &i)| adj[i].iter().map(|&j| at[j]).fold(p, usize::min)).collect();
    let mut start = vec![0; k + 1];
    for p in 0..k {
        start[p + 1] = start[p] + p - first[p] + 1;
    }
    let w = (0..k).map(|p| p - first[p] + 1).max().unwrap_or(1);
    let d = rows.iter().map(Vec::len).max().unwrap_or(1);
    let trace: f64 = rows.iter().flat_map(|row| row.iter().map(|&(_, v)| v * v)).sum();
    let g_w = gamma(w + 1);
    let shift = bound * (1.0 + 2.0 * U) + rounding_shift(g_w / (1.0 - g_w), d, trace);
    let mut l = vec![0.0; start[k]];
    let mut dense = vec![0.0; ncols];
    for p in 0..k {
        let (i, fp, sp) = (order[p], first[p], start[p]);
        // Row p of A = G - s I, over its envelope (zero where no column is shared).
        for &(c, v) in &rows[i] {
            dense[c] = v;
        }
        for &j in adj[i].iter().chain(std::iter::once(&i)) {
            let q = at[j];
            if q <= p {
                l[sp + q - fp] = rows[j].iter().map(|&(c, v)| v * dense[c]).sum();
            }
        }
        for &(c, _) in &rows[i] {
            dense[c] = 0.0;
        }
        l[sp + p - fp] -= shift;
        // Cholesky-Banachiewicz over the envelope.
        for q in fp..p {
            let (fq, sq) = (first[q], start[q]);
            let mut s = l[sp + q - fp];
            for t in fp.max(fq)..q {
                s -= l[sp + t - fp] * l[sq + t - fq];
            }
            l[sp + q - fp] = s / l[sq + q - fq];
        }
        let mut diag = l[sp + p - fp];
        for t in fp..p {
            diag -= l[sp + t - fp] * l[sp + t - fp];
        }
        if !(diag > 0.0) {
            return false;
        }
        l[sp + p - fp] = diag.sqrt();
    }
    true
}

/// Reverse Cuthill-McKee order of a graph's nodes: breadth first from a node of least degree
/// (each component), neighbours by increasing degree, then reversed (George & Liu, "Computer
/// Solution of Large Sparse Positive Definite Systems", 1981, 4.3).
fn reverse_cuthill_mckee(adj: &[Vec<usize>]) -> Vec<usize> {
    let k = adj.len();
    let mut seen = vec![false; k];
    let mut order = Vec::with_capacity(k);
    let mut by_degree: Vec<usize> = (0..k).collect();
    by_degree.sort_by_key(|&i| (adj[i].len(), i));
    for &s in &by_degree {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        let mut head = order.len();
        order.push(s);
        while head < order.len() {
            let i = order[head];
            head += 1;
            let mut next: Vec<usize> = adj[i].iter().copied().filter(|&j| !seen[j]).collect();
            next.sort_by_key(|&j| (adj[j].len(), j));
            for j in next {
                seen[j] = true;
                order.push(j);
            }
        }
    }
    order.reverse();
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn proves_the_smallest_eigenvalue_of_a_chain_and_no_more() {
        // R upper bidiagonal (1 and -0.5, a last 0.75): lambda_min(R R^T) = sigma_min(R)^2 from
        // nalgebra's SVD of the same rows, which rounds to ~1e-16; the 1e-6 either side is far
        // above that and above the certificate's own shift (~1e-13 here).
        let k = 30;
        let rows: Vec<SparseRow> =
            (0..k).map(|i| if i + 1 < k { vec![(i, 1.0), (i + 1, -0.5)] } else { vec![(i, 0.75)] }).collect();
        let mut dense = nalgebra::DMatrix::<f64>::zeros(k, k);
        for (i, row) in rows.iter().enumerate() {
            for &(c, v) in row {
                dense[(i, c)] = v;
            }
        }
        let sigma = dense.singular_values().min();
        let lambda = sigma * sigma;
        // Proven just below lambda_min, not just above it.
        assert!(gram_exceeds(&rows, k, lambda * (1.0 - 1e-6)), "lambda_min {lambda}");
        assert!(!gram_exceeds(&rows, k, lambda * (1.0 + 1e-6)), "lambda_min {lambda}");
        // A repeated row: G singular, nothing above 0 is proven.
        let mut singular = rows.clone();
        singular.push(rows[3].clone());
        assert!(!gram_exceeds(&singular, k, 0.0));
    }
}
