//! Cholesky factorisation of the small symmetric positive definite mass matrix A (m x m).

/// Factor a row-major SPD matrix in place into its lower factor L (A = L L^T), row by row
/// (Cholesky-Banachiewicz). L keeps the envelope of A (the zeros left of each row's first
/// non-zero), so the products there are skipped: a block-diagonal A (independent parts of a
/// mechanism) costs its blocks' factorisations. Returns false if A is not positive definite
/// to working precision. Only the lower triangle is read.
pub fn cholesky_in_place(a: &mut [f64], m: usize) -> bool {
    factor(a, m, |a, i| a[i * m..i * m + i].iter().position(|v| *v != 0.0).unwrap_or(i))
}

/// As [`cholesky_in_place`] with the envelope given: `first[i]`, the first column of row i that
/// may be non-zero (from the supports of U), so that no row is scanned for it.
pub fn cholesky_envelope(a: &mut [f64], m: usize, first: &[usize]) -> bool {
    // m as a constant up to 4 (`cholesky_envelope_fixed`).
    match m {
        1 => cholesky_envelope_fixed::<1>(a, first),
        2 => cholesky_envelope_fixed::<2>(a, first),
        3 => cholesky_envelope_fixed::<3>(a, first),
        4 => cholesky_envelope_fixed::<4>(a, first),
        _ => factor(a, m, |_, i| first[i]),
    }
}

/// [`cholesky_envelope`] for M known when compiled (a few), inlined: the loops of `factor`
/// unroll, for the mass matrix of a mechanism of a few coordinates, where their bookkeeping
/// would cost more than the arithmetic. From M = 3 a full envelope (every row from column 0:
/// the columns of U share bodies, as a 3-RRR's do) has its bounds constant too, so that the
/// loops unroll whole: the same operations (3-RRR -49 instructions an evaluation; at M = 2 it
/// saved nothing).
#[inline(always)]
pub fn cholesky_envelope_fixed<const M: usize>(a: &mut [f64], first: &[usize]) -> bool {
    if M >= 3 && first == [0; M] {
        factor(a, M, |_, _| 0)
    } else {
        factor(a, M, |_, i| first[i])
    }
}

/// The factorisation, `first(a, i)` giving row i's first non-zero column (of A for the row being
/// factorised, of L for one already done: L keeps the envelope).
#[inline(always)]
fn factor(a: &mut [f64], m: usize, first: impl Fn(&[f64], usize) -> usize) -> bool {
    for i in 0..m {
        let row = i * m;
        let fi = first(a, i);
        for j in fi..i {
            let start = fi.max(first(a, j));
            let mut s = a[row + j];
            for k in start..j {
                s -= a[row + k] * a[j * m + k];
            }
            a[row + j] = s / a[j * m + j];
        }
        let mut d = a[row + i];
        for k in fi..i {
            d -= a[row + k] * a[row + k];
        }
        if !(d > 0.0) {
            return false;
        }
        a[row + i] = d.sqrt();
    }
    true
}

/// Solve A x = b in place with the factor from [`cholesky_in_place`].
pub fn cholesky_solve(l: &[f64], m: usize, b: &mut [f64]) {
    solve(l, m, b, |_| 0)
}

/// As [`cholesky_solve`] over the envelope `first` of [`cholesky_envelope`]: m plus the
/// envelope's size, not m^2.
pub fn cholesky_solve_envelope(l: &[f64], m: usize, first: &[usize], b: &mut [f64]) {
    // m as a constant up to 4 (as in `cholesky_envelope`).
    match m {
        1 => cholesky_solve_envelope_fixed::<1>(l, first, b),
        2 => cholesky_solve_envelope_fixed::<2>(l, first, b),
        3 => cholesky_solve_envelope_fixed::<3>(l, first, b),
        4 => cholesky_solve_envelope_fixed::<4>(l, first, b),
        _ => solve(l, m, b, |i| first[i]),
    }
}

/// [`cholesky_solve_envelope`] for M known when compiled, inlined (as [`cholesky_envelope_fixed`]).
#[inline(always)]
pub fn cholesky_solve_envelope_fixed<const M: usize>(l: &[f64], first: &[usize], b: &mut [f64]) {
    if M >= 3 && first == [0; M] {
        solve(l, M, b, |_| 0)
    } else {
        solve(l, M, b, |i| first[i])
    }
}

/// L y = b by rows, then L^T x = y by columns (row i of L is column i of L^T), each over the
/// envelope.
#[inline(always)]
fn solve(l: &[f64], m: usize, b: &mut [f64], first: impl Fn(usize) -> usize) {
    for i in 0..m {
        let mut s = b[i];
        for k in first(i)..i {
            s -= l[i * m + k] * b[k];
        }
        b[i] = s / l[i * m + i];
    }
    for i in (0..m).rev() {
        let x = b[i] / l[i * m + i];
        b[i] = x;
        for k in first(i)..i {
            b[k] -= l[i * m + k] * x;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_2x2_spd_system() {
        // A = [[4, 2], [2, 3]], x = [1, -1] -> b = [2, -1].
        let mut a = [4.0, 2.0, 2.0, 3.0];
        assert!(cholesky_in_place(&mut a, 2));
        let mut b = [2.0, -1.0];
        cholesky_solve(&a, 2, &mut b);
        assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] + 1.0).abs() < 1e-15);
        let mut not_pd = [1.0, 2.0, 2.0, 1.0];
        assert!(!cholesky_in_place(&mut not_pd, 2));
    }

    #[test]
    fn a_block_diagonal_matrix_gives_the_plain_factor_bit_for_bit() {
        // A = B B^T with B lower triangular of blocks 2, 3, 1 and a coupled tail: every L
        // entry must equal the column-by-column factorisation's, zeros skipped or not.
        let m = 7;
        let mut b = vec![0.0f64; m * m];
        for (i, j, v) in [(0, 0, 2.0), (1, 0, 0.5), (1, 1, 1.5), (2, 2, 1.0), (3, 2, -0.3), (3, 3, 0.9)] {
            b[i * m + j] = v;
        }
        for (i, j, v) in [(4, 2, 0.2), (4, 4, 1.1), (5, 5, 0.7), (6, 5, 0.4), (6, 1, -0.6), (6, 6, 1.3)] {
            b[i * m + j] = v;
        }
        let mut a = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                a[i * m + j] = (0..m).map(|k| b[i * m + k] * b[j * m + k]).sum();
            }
        }
        let mut plain = a.clone();
        for j in 0..m {
            let d = (0..j).fold(plain[j * m + j], |d, k| d - plain[j * m + k] * plain[j * m + k]).sqrt();
            plain[j * m + j] = d;
            for i in j + 1..m {
                let s = (0..j).fold(plain[i * m + j], |s, k| s - plain[i * m + k] * plain[j * m + k]);
                plain[i * m + j] = s / d;
            }
        }
        // A's envelope: the first column of each row of B (B's envelope is A's).
        let first: Vec<usize> = (0..m).map(|i| (0..=i).find(|&k| b[i * m + k] != 0.0).unwrap()).collect();
        let mut env = a.clone();
        assert!(cholesky_in_place(&mut a, m));
        assert!(cholesky_envelope(&mut env, m, &first));
        for i in 0..m {
            for j in 0..=i {
                assert_eq!(a[i * m + j], plain[i * m + j], "L[{i}][{j}]");
                assert_eq!(env[i * m + j], plain[i * m + j], "L[{i}][{j}] over the envelope");
            }
        }
        // The solves: x = (1, ..., 7) back from A x, over the envelope and whole, to round-off.
        let x: Vec<f64> = (1..=m).map(|v| v as f64).collect();
        let ax: Vec<f64> = (0..m)
            .map(|i| (0..m).map(|j| (0..m).map(|k| b[i * m + k] * b[j * m + k]).sum::<f64>() * x[j]).sum())
            .collect();
        let (mut whole, mut over) = (ax.clone(), ax);
        cholesky_solve(&a, m, &mut whole);
        cholesky_solve_envelope(&env, m, &first, &mut over);
        for i in 0..m {
            assert!((whole[i] - x[i]).abs() < 1e-13 && (over[i] - x[i]).abs() < 1e-13, "{whole:?} {over:?}");
        }
    }
}
