//! Gaussian elimination with complete pivoting, used only to choose independent columns
//! (Wehage & Haug 1982): at each step the largest remaining entry is the pivot, so the
//! columns it picks are the best-conditioned independent set.

/// Eliminate the row-major `rows x cols` matrix `a` (destroyed) with complete pivoting;
/// returns the first `count` pivot columns in pivot order (fewer if a pivot is exactly 0).
pub fn pivot_columns(a: &mut [f64], rows: usize, cols: usize, count: usize) -> Vec<usize> {
    let mut free: Vec<usize> = (0..cols).collect();
    let mut pivots = Vec::new();
    for k in 0..rows.min(count) {
        let (mut pr, mut pc, mut best) = (k, 0, 0.0);
        for r in k..rows {
            for (ci, &c) in free.iter().enumerate() {
                let v = a[r * cols + c].abs();
                if v > best {
                    (pr, pc, best) = (r, ci, v);
                }
            }
        }
        if best == 0.0 {
            break;
        }
        let col = free.remove(pc);
        pivots.push(col);
        for j in 0..cols {
            a.swap(k * cols + j, pr * cols + j);
        }
        for r in k + 1..rows {
            let l = a[r * cols + col] / a[k * cols + col];
            for j in 0..cols {
                a[r * cols + j] -= l * a[k * cols + j];
            }
        }
    }
    pivots
}
