//! In-place LU factorisation with partial pivoting, `P A = L U`, for the small
//! dense systems of Radau5 (dim <= ~40), generic over `f64` and
//! `nalgebra::Complex<f64>` so the real and the complex Newton matrices share
//! one code. No allocation: the matrix (row-major, `n x n`) is overwritten by
//! its factors and the pivots go into a caller-owned slice.
//!
//! Reference: G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed.,
//! Algorithm 3.4.1 (Gaussian elimination with partial pivoting).

use nalgebra::Complex;
use std::ops::{Div, Mul, MulAssign, Sub, SubAssign};

/// The scalars the LU works with.
pub(crate) trait Scalar:
    Copy + Mul<Output = Self> + Div<Output = Self> + Sub<Output = Self> + SubAssign + MulAssign
{
    /// Magnitude used to choose the pivot (the modulus for complex numbers).
    fn magnitude(self) -> f64;
}

impl Scalar for f64 {
    fn magnitude(self) -> f64 {
        self.abs()
    }
}

impl Scalar for Complex<f64> {
    fn magnitude(self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// The matrix is singular to working precision (a zero or non-finite pivot).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Singular;

/// Factor the row-major `n x n` matrix `a` in place: afterwards the strict lower
/// triangle holds `L` (unit diagonal implied) and the upper triangle `U`;
/// `piv[k]` is the row swapped with row `k` at elimination step `k`.
pub(crate) fn factor<T: Scalar>(a: &mut [T], n: usize, piv: &mut [usize]) -> Result<(), Singular> {
    debug_assert!(a.len() >= n * n && piv.len() >= n);
    for k in 0..n {
        // Pivot: the largest magnitude in column k at or below the diagonal.
        let mut p = k;
        let mut best = a[k * n + k].magnitude();
        for i in k + 1..n {
            let m = a[i * n + k].magnitude();
            if m > best {
                best = m;
                p = i;
            }
        }
        if best == 0.0 || !best.is_finite() {
            return Err(Singular);
        }
        piv[k] = p;
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
        }
        let pivot = a[k * n + k];
        for i in k + 1..n {
            let l = a[i * n + k] / pivot;
            a[i * n + k] = l;
            for j in k + 1..n {
                let u = a[k * n + j];
                a[i * n + j] -= l * u;
            }
        }
    }
    Ok(())
}

/// Solve `A x = b` in place (`b` becomes `x`) with the factors from [`factor`].
pub(crate) fn solve<T: Scalar>(lu: &[T], n: usize, piv: &[usize], b: &mut [T]) {
    // Apply the row swaps, then forward substitution with unit-lower L.
    for k in 0..n {
        b.swap(k, piv[k]);
    }
    for i in 1..n {
        let mut s = b[i];
        for j in 0..i {
            s -= lu[i * n + j] * b[j];
        }
        b[i] = s;
    }
    // Back substitution with U.
    for i in (0..n).rev() {
        let mut s = b[i];
        for j in i + 1..n {
            s -= lu[i * n + j] * b[j];
        }
        b[i] = s / lu[i * n + i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_solve_matches_known_solution() {
        // A = [[0, 2, 1], [1, 1, 0], [3, 0, 1]] needs a pivot swap; x = (1, -2, 3).
        let mut a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let x = [1.0, -2.0, 3.0];
        let mut b = [-1.0, -1.0, 6.0];
        let mut piv = [0; 3];
        factor(&mut a, 3, &mut piv).unwrap();
        solve(&a, 3, &piv, &mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
    }

    #[test]
    fn complex_solve_matches_known_solution() {
        let c = |re, im| Complex::new(re, im);
        // A = [[i, 1], [2, 1 - i]], x = (1 + i, -1) -> b = A x.
        let a0 = [c(0.0, 1.0), c(1.0, 0.0), c(2.0, 0.0), c(1.0, -1.0)];
        let x = [c(1.0, 1.0), c(-1.0, 0.0)];
        let mut b = [a0[0] * x[0] + a0[1] * x[1], a0[2] * x[0] + a0[3] * x[1]];
        let mut a = a0;
        let mut piv = [0; 2];
        factor(&mut a, 2, &mut piv).unwrap();
        solve(&a, 2, &piv, &mut b);
        for i in 0..2 {
            assert!((b[i] - x[i]).norm() < 1e-14);
        }
    }

    #[test]
    fn singular_is_reported() {
        let mut a = [1.0, 2.0, 2.0, 4.0];
        let mut piv = [0; 2];
        assert!(factor(&mut a, 2, &mut piv).is_err());
    }
}
