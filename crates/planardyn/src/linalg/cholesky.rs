//! Cholesky factorisation of the small symmetric positive definite mass matrix A (m x m).

/// Factor a row-major SPD matrix in place into its lower factor L (A = L L^T), row by row
/// (Cholesky-Banachiewicz). L keeps the envelope of A (the zeros left of each row's first
/// non-zero), so the products there are skipped: a block-diagonal A (independent parts of a
/// mechanism) costs its blocks' factorisations. Returns false if A is not positive definite
/// to working precision.
pub fn cholesky_in_place(a: &mut [f64], m: usize) -> bool {
    for i in 0..m {
        let row = i * m;
        let first = a[row..row + i].iter().position(|v| *v != 0.0).unwrap_or(i);
        for j in first..i {
            // Row j of L is zero left of its own first non-zero.
            let start = (first..j).find(|&k| a[j * m + k] != 0.0).unwrap_or(j);
            let mut s = a[row + j];
            for k in start..j {
                s -= a[row + k] * a[j * m + k];
            }
            a[row + j] = s / a[j * m + j];
        }
        let mut d = a[row + i];
        for k in first..i {
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
    for i in 0..m {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * m + k] * b[k];
        }
        b[i] = s / l[i * m + i];
    }
    for i in (0..m).rev() {
        let mut s = b[i];
        for k in i + 1..m {
            s -= l[k * m + i] * b[k];
        }
        b[i] = s / l[i * m + i];
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
        assert!(cholesky_in_place(&mut a, m));
        for i in 0..m {
            for j in 0..=i {
                assert_eq!(a[i * m + j], plain[i * m + j], "L[{i}][{j}]");
            }
        }
    }
}
