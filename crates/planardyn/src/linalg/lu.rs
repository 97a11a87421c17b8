//! LU factorisation with partial pivoting, in place, row-major (Golub & Van Loan,
//! *Matrix Computations*, alg. 3.4.1), generic over `f64` and `Complex<f64>` so that the
//! kinematics (real) and Radau5's Newton matrices (real and complex) share one code.
//! The factors overwrite the matrix (unit lower L below the diagonal, U on and above it);
//! `piv[k]` is the row swapped with row k at step k (LAPACK's convention).

use nalgebra::Complex;
use std::ops::{Div, Mul, Sub, SubAssign};

/// The scalars the LU works with.
pub trait Scalar: Copy + PartialEq + Mul<Output = Self> + Div<Output = Self> + Sub<Output = Self> + SubAssign {
    const ZERO: Self;
    /// Magnitude used to choose the pivot (the modulus for complex numbers).
    fn magnitude(self) -> f64;
}

impl Scalar for f64 {
    const ZERO: f64 = 0.0;
    fn magnitude(self) -> f64 {
        self.abs()
    }
}

impl Scalar for Complex<f64> {
    const ZERO: Complex<f64> = Complex { re: 0.0, im: 0.0 };
    fn magnitude(self) -> f64 {
        self.re.hypot(self.im)
    }
}

/// No pivot above the threshold: the matrix is singular to working precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuError {
    /// Elimination step at which no usable pivot was found.
    pub column: usize,
}

/// Factor the row-major n x n matrix `a` in place. A pivot of magnitude `<= tiny` (or not
/// finite) makes the matrix singular.
pub fn lu_factor<T: Scalar>(a: &mut [T], n: usize, piv: &mut [usize], tiny: f64) -> Result<(), LuError> {
    assert!(a.len() >= n * n && piv.len() >= n, "lu_factor: buffers smaller than n = {n}");
    // SAFETY: every index below is < n * n into `a` or < n into `piv` (asserted above).
    // Unchecked because the matrices are small (1 to ~40, mostly under 12), where bounds
    // checks and slice set-up per row cost more than the elimination itself.
    unsafe {
        let at = |a: &[T], i: usize| *a.get_unchecked(i);
        for k in 0..n {
            let (mut p, mut best) = (k, at(a, k * n + k).magnitude());
            for i in k + 1..n {
                let v = at(a, i * n + k).magnitude();
                if v > best {
                    (p, best) = (i, v);
                }
            }
            if !(best > tiny && best.is_finite()) {
                return Err(LuError { column: k });
            }
            *piv.get_unchecked_mut(k) = p;
            if p != k {
                let (top, bottom) = a.split_at_mut(p * n);
                top[k * n..(k + 1) * n].swap_with_slice(&mut bottom[..n]);
            }
            let pivot = at(a, k * n + k);
            // Kinematic Jacobians are sparse: most multipliers are zero and skipped.
            for i in k + 1..n {
                let l = at(a, i * n + k) / pivot;
                *a.get_unchecked_mut(i * n + k) = l;
                if l != T::ZERO {
                    for j in k + 1..n {
                        let u = at(a, k * n + j);
                        *a.get_unchecked_mut(i * n + j) -= l * u;
                    }
                }
            }
        }
    }
    Ok(())
}

/// Solve A x = b in place (`b` becomes `x`) with the factors from [`lu_factor`].
pub fn lu_solve<T: Scalar>(lu: &[T], n: usize, piv: &[usize], b: &mut [T]) {
    for (k, &p) in piv[..n].iter().enumerate() {
        b.swap(k, p);
    }
    for i in 1..n {
        let mut s = b[i];
        for (l, &x) in lu[i * n..i * n + i].iter().zip(&b[..i]) {
            s -= *l * x;
        }
        b[i] = s;
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for (u, &x) in lu[i * n + i + 1..(i + 1) * n].iter().zip(&b[i + 1..n]) {
            s -= *u * x;
        }
        b[i] = s / lu[i * n + i];
    }
}

/// Solve A^T x = b in place with the factors from [`lu_factor`] (real matrices).
pub fn lu_solve_transpose(lu: &[f64], n: usize, piv: &[usize], b: &mut [f64]) {
    // U^T y = b, then L^T z = y, then undo the row swaps in reverse order.
    for i in 0..n {
        let mut s = b[i];
        for j in 0..i {
            s -= lu[j * n + i] * b[j];
        }
        b[i] = s / lu[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for j in i + 1..n {
            s -= lu[j * n + i] * b[j];
        }
        b[i] = s;
    }
    for k in (0..n).rev() {
        b.swap(k, piv[k]);
    }
}

/// A real n x n matrix and its factors, in buffers sized once.
#[derive(Debug, Clone)]
pub struct Lu {
    n: usize,
    lu: Vec<f64>,
    piv: Vec<usize>,
}

impl Lu {
    pub fn new(n: usize) -> Self {
        Lu { n, lu: vec![0.0; n * n], piv: vec![0; n] }
    }
    /// The matrix buffer (row-major, n x n) to fill before [`Lu::factor`].
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.lu
    }
    /// Factorise the matrix in the buffer in place (see [`lu_factor`]).
    pub fn factor(&mut self, tiny: f64) -> Result<(), LuError> {
        lu_factor(&mut self.lu, self.n, &mut self.piv, tiny)
    }
    /// Solve A x = b in place.
    pub fn solve(&self, b: &mut [f64]) {
        lu_solve(&self.lu, self.n, &self.piv, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_transposes_a_pivoting_system() {
        // A needs a row swap at the first step (zero leading entry).
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let x = [1.0, -2.0, 0.5];
        let (mut lu, mut piv) = (a, [0; 3]);
        lu_factor(&mut lu, 3, &mut piv, 1e-300).unwrap();
        let mut b: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum()).collect();
        lu_solve(&lu, 3, &piv, &mut b);
        let mut bt: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[j * 3 + i] * x[j]).sum()).collect();
        lu_solve_transpose(&lu, 3, &piv, &mut bt);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14, "solve: {b:?}");
            assert!((bt[i] - x[i]).abs() < 1e-14, "solve_transpose: {bt:?}");
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
        lu_factor(&mut a, 2, &mut piv, 0.0).unwrap();
        lu_solve(&a, 2, &piv, &mut b);
        for i in 0..2 {
            assert!((b[i] - x[i]).norm() < 1e-14);
        }
    }

    #[test]
    fn reports_a_singular_matrix() {
        let (mut a, mut piv) = ([1.0, 2.0, 2.0, 4.0], [0; 2]);
        assert_eq!(lu_factor(&mut a, 2, &mut piv, 1e-12), Err(LuError { column: 1 }));
    }
}
