//! LU factorisation with partial pivoting, in place, row-major (Golub & Van Loan, alg. 3.4.1).

/// A zero pivot: the matrix is singular to working precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuError {
    /// Elimination step at which no usable pivot was found.
    pub column: usize,
}

/// The factors `P A = L U` of an n x n matrix, stored in one row-major buffer
/// (unit lower L below the diagonal, U on and above it) with the row permutation.
#[derive(Debug, Clone)]
pub struct Lu {
    n: usize,
    lu: Vec<f64>,
    perm: Vec<usize>,
}

impl Lu {
    /// Buffers for n x n matrices.
    pub fn new(n: usize) -> Self {
        Lu { n, lu: vec![0.0; n * n], perm: (0..n).collect() }
    }
    pub fn dim(&self) -> usize {
        self.n
    }
    /// The matrix buffer (row-major, n x n) to fill before [`Lu::factor`].
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.lu
    }
    /// Factorise the matrix in the buffer in place. `tiny` is the absolute pivot size below
    /// which the matrix counts as singular.
    pub fn factor(&mut self, tiny: f64) -> Result<(), LuError> {
        let n = self.n;
        let a = &mut self.lu;
        for (i, p) in self.perm.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..n {
            let mut piv = k;
            let mut best = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > best {
                    best = v;
                    piv = i;
                }
            }
            if !(best > tiny) {
                return Err(LuError { column: k });
            }
            if piv != k {
                for j in 0..n {
                    a.swap(k * n + j, piv * n + j);
                }
                self.perm.swap(k, piv);
            }
            let inv = 1.0 / a[k * n + k];
            // Row slices so that the update loop vectorises; J is sparse, so most
            // multipliers are zero and skipped.
            let (top, rest) = a.split_at_mut((k + 1) * n);
            let pivot_row = &top[k * n + k + 1..(k + 1) * n];
            for row in rest.chunks_exact_mut(n) {
                let l = row[k] * inv;
                row[k] = l;
                if l != 0.0 {
                    for (v, p) in row[k + 1..].iter_mut().zip(pivot_row) {
                        *v -= l * p;
                    }
                }
            }
        }
        Ok(())
    }
    /// Solve `A x = b` in place (`b` becomes `x`); `tmp` has length n.
    pub fn solve(&self, b: &mut [f64], tmp: &mut [f64]) {
        let n = self.n;
        let a = &self.lu;
        for i in 0..n {
            tmp[i] = b[self.perm[i]];
        }
        for i in 0..n {
            let row = &a[i * n..i * n + i];
            tmp[i] -= row.iter().zip(&tmp[..i]).map(|(l, t)| l * t).sum::<f64>();
        }
        for i in (0..n).rev() {
            let row = &a[i * n + i + 1..(i + 1) * n];
            let s = tmp[i] - row.iter().zip(&tmp[i + 1..n]).map(|(u, t)| u * t).sum::<f64>();
            tmp[i] = s / a[i * n + i];
        }
        b[..n].copy_from_slice(&tmp[..n]);
    }
    /// Solve `A^T x = b` in place; `tmp` has length n.
    pub fn solve_transpose(&self, b: &mut [f64], tmp: &mut [f64]) {
        let n = self.n;
        let a = &self.lu;
        // U^T y = b, then L^T z = y, then x = P^T z.
        for i in 0..n {
            let mut s = b[i];
            for j in 0..i {
                s -= a[j * n + i] * tmp[j];
            }
            tmp[i] = s / a[i * n + i];
        }
        for i in (0..n).rev() {
            let mut s = tmp[i];
            for j in i + 1..n {
                s -= a[j * n + i] * tmp[j];
            }
            tmp[i] = s;
        }
        for i in 0..n {
            b[self.perm[i]] = tmp[i];
        }
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
        let mut lu = Lu::new(3);
        lu.matrix_mut().copy_from_slice(&a);
        lu.factor(1e-300).unwrap();
        let mut tmp = [0.0; 3];
        let mut b: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum()).collect();
        lu.solve(&mut b, &mut tmp);
        let mut bt: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[j * 3 + i] * x[j]).sum()).collect();
        lu.solve_transpose(&mut bt, &mut tmp);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14, "solve: {b:?}");
            assert!((bt[i] - x[i]).abs() < 1e-14, "solve_transpose: {bt:?}");
        }
    }

    #[test]
    fn reports_a_singular_matrix() {
        let mut lu = Lu::new(2);
        lu.matrix_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        assert_eq!(lu.factor(1e-12), Err(LuError { column: 1 }));
    }
}
