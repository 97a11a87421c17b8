//! Complete pivoting on the scaled Phi_x, on its sparse rows: the loader's rank proof, the
//! partition a chart switch chooses and a change point's pivots. The dense elimination of the
//! (3n - m) x 3n matrix was O(n^2) in memory and time at each call (the change point's location
//! calls it about 80 times a crossing: 1.4e8 instructions of a 1.1e9 run of ten five-bars);
//! [`eliminate`] takes the same pivots bit for bit at a cost that follows the non-zeros. A small
//! mechanism's is still the dense one, which has no sets or row vectors to build: the five-bar's
//! (10 x 12) took 29.7 k instructions sparse, 11 k dense, and a crossing's location calls it 43 times.

use super::constraints::body_trig;
use super::system::{col_scale, col_scales};
use crate::linalg::{eliminate, pivot_columns, Dense, Sink, SparseRow};
use crate::model::pairs::{self, row_scales};
use crate::model::Mechanism;

/// Body coordinates up to which [`phi_x_pivots`] eliminates densely: the dense matrix is
/// (3n - m) x 3n, cleared and scanned whole each step, which the sparse elimination's set and
/// per-row vectors cost more than up to a few tens of coordinates (ten bodies).
const DENSE_PIVOTS_MAX: usize = 30;

/// Sparse rows as a [`Sink`]: each entry summed in the order the pair functions add it, as the
/// dense [`Dense`](crate::linalg::Dense) sums it from zero.
struct Rows(Vec<SparseRow>);

impl Sink for Rows {
    fn add(&mut self, row: usize, col: usize, v: f64) {
        let r = &mut self.0[row];
        match r.iter_mut().find(|e| e.0 == col) {
            Some(e) => e.1 += v,
            None => r.push((col, 0.0 + v)),
        }
    }
}

/// The scaled Phi_x's rows placed by `slots` (per pair, as `Mechanism::pair_slots`) among
/// `rows`: the non-zeros of the dense scaled Jacobian (`system::scaled_jacobian`, rows in metres
/// over L, translation columns times L), the same values bit for bit, each row by column.
pub(crate) fn scaled_phi_rows(
    mech: &Mechanism,
    x: &[f64],
    slots: &[[Option<usize>; 2]],
    rows: usize,
) -> Vec<SparseRow> {
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    let mut phi = Rows(vec![Vec::new(); rows]);
    for (pair, s) in mech.pairs.iter().zip(slots) {
        pairs::jacobian(pair, x, &trig, &mut phi, *s);
    }
    let cs = col_scales(mech);
    for (pair, s) in mech.pairs.iter().zip(slots) {
        for (slot, scale) in s.iter().zip(row_scales(pair, 1.0 / mech.scale)) {
            if let Some(r) = *slot {
                for e in &mut phi.0[r] {
                    e.1 *= scale * cs[e.0];
                }
            }
        }
    }
    for row in &mut phi.0 {
        row.retain(|e| e.1 != 0.0);
        row.sort_unstable_by_key(|e| e.0);
    }
    phi.0
}

/// Complete pivoting on the scaled Phi_x (its independent rows) at x: each step's pivot column
/// and |pivot|, in pivot order (fewer than its rows where one is exactly 0). The pivots of
/// `linalg::pivot_columns` on the dense matrix, bit for bit, whichever elimination takes them.
pub fn phi_x_pivots(mech: &Mechanism, x: &[f64]) -> Vec<(usize, f64)> {
    if x.len() <= DENSE_PIVOTS_MAX {
        dense_pivots(mech, x)
    } else {
        sparse_pivots(mech, x)
    }
}

/// [`phi_x_pivots`] by [`eliminate`] on [`scaled_phi_rows`].
fn sparse_pivots(mech: &Mechanism, x: &[f64]) -> Vec<(usize, f64)> {
    let rows = mech.n_constraints;
    let e = eliminate(scaled_phi_rows(mech, x, &mech.pair_slots, rows), x.len(), 0.0, rows);
    e.pivots
        .iter()
        .map(|&(r, c)| (c, e.rows[r].iter().find(|v| v.0 == c).expect("the pivot is an entry of its row").1.abs()))
        .collect()
}

/// [`phi_x_pivots`] by `pivot_columns` on the dense scaled Phi_x, its entries summed and scaled
/// as [`scaled_phi_rows`] makes them, the pivots read back from the eliminated matrix. Its
/// trig and scales are on the stack (n <= [`DENSE_PIVOTS_MAX`]); the matrix is not: a stack
/// array of the largest size, zeroed whole, cost the five-bar free fall 0.2 M instructions more.
fn dense_pivots(mech: &Mechanism, x: &[f64]) -> Vec<(usize, f64)> {
    let (n, rows) = (x.len(), mech.n_constraints);
    let mut trig = [[0.0; 2]; DENSE_PIVOTS_MAX / 3];
    let trig = &mut trig[..mech.n_bodies()];
    body_trig(x, trig);
    let mut j = vec![0.0; rows * n];
    for (pair, s) in mech.pairs.iter().zip(&mech.pair_slots) {
        pairs::jacobian(pair, x, trig, &mut Dense { j: &mut j, ncols: n }, *s);
    }
    let mut cs = [0.0; DENSE_PIVOTS_MAX];
    let cs = &mut cs[..n];
    for (i, c) in cs.iter_mut().enumerate() {
        *c = col_scale(mech, i);
    }
    for (pair, s) in mech.pairs.iter().zip(&mech.pair_slots) {
        for (slot, scale) in s.iter().zip(row_scales(pair, 1.0 / mech.scale)) {
            if let Some(r) = *slot {
                for (v, c) in j[r * n..(r + 1) * n].iter_mut().zip(cs.iter()) {
                    *v *= scale * c;
                }
            }
        }
    }
    let columns = pivot_columns(&mut j, rows, n, rows);
    columns.iter().enumerate().map(|(k, &c)| (c, j[k * n + c].abs())).collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::kinematics::constraints::Chart;
    use crate::kinematics::system::scaled_jacobian;
    use crate::Format;
    use std::f64::consts::FRAC_PI_2;

    /// The dense elimination the sparse one replaces, on the user chart's scaled J (its first
    /// n_constraints rows): `pivot_columns`, the pivots read back from the eliminated matrix.
    fn reference_pivots(mech: &Mechanism, x: &[f64]) -> Vec<(usize, f64)> {
        let (n, rows) = (x.len(), mech.n_constraints);
        let mut j = vec![0.0; n * n];
        let mut trig = vec![[0.0; 2]; mech.n_bodies()];
        body_trig(x, &mut trig);
        scaled_jacobian(mech, &Chart::Inputs, x, &trig, &mut vec![1.0; n], &col_scales(mech), &mut j);
        j.truncate(rows * n);
        let columns = pivot_columns(&mut j, rows, n, rows);
        columns.iter().enumerate().map(|(k, &c)| (c, j[k * n + c].abs())).collect()
    }

    /// Both eliminations against the reference, bit for bit.
    fn assert_pivots(mech: &Mechanism, x: &[f64], what: &str) -> Vec<(usize, f64)> {
        let reference = reference_pivots(mech, x);
        assert_eq!(sparse_pivots(mech, x), reference, "{what}: sparse");
        assert_eq!(dense_pivots(mech, x), reference, "{what}: dense");
        reference
    }

    /// Two parallelogram windows (IFToMM A02 with N = 2, drawn upright).
    const A02: &str = "name: A02\npoints: {O0: [0, 0], O1: [1, 0], O2: [2, 0], A0: [0, 1], A1: [1, 1], A2: [2, 1]}
ground: [O0, O1, O2]
bodies:
  rod0: {points: [O0, A0], uniform_bar: [O0, A0], mass: 1.0}
  rod1: {points: [O1, A1], uniform_bar: [O1, A1], mass: 1.0}
  rod2: {points: [O2, A2], uniform_bar: [O2, A2], mass: 1.0}
  c1: {points: [A0, A1], uniform_bar: [A0, A1], mass: 1.0}
  c2: {points: [A1, A2], uniform_bar: [A1, A2], mass: 1.0}
pairs:
  - {type: revolute, name: g0, at: O0, bodies: [ground, rod0]}
  - {type: revolute, at: O1, bodies: [ground, rod1]}
  - {type: revolute, at: O2, bodies: [ground, rod2]}
  - {type: revolute, at: A0, bodies: [rod0, c1]}
  - {type: revolute, at: A1, bodies: [c1, rod1]}
  - {type: revolute, at: A1, bodies: [rod1, c2]}
  - {type: revolute, at: A2, bodies: [c2, rod2]}
coordinates:
  - {name: theta, pair: g0, value: 1.5707963267948966}
";

    /// A02 and its body coordinates at its change point: the rods turned to +x about their
    /// pivots, the couplers moved with their tops.
    pub(crate) fn a02_folded() -> (Mechanism, Vec<f64>) {
        let mech = crate::loads(A02, Format::Yaml, "A02").unwrap();
        let mut x = mech.x0.clone();
        for (b, body) in mech.bodies.iter().enumerate() {
            let (dx, dy, dphi) = if body.name.starts_with("rod") { (0.5, -0.5, -FRAC_PI_2) } else { (1.0, -1.0, 0.0) };
            x[3 * b] += dx;
            x[3 * b + 1] += dy;
            x[3 * b + 2] += dphi;
        }
        (mech, x)
    }

    #[test]
    fn the_dense_eliminations_pivots_bit_for_bit() {
        // Revolute, prismatic and multi-loop mechanisms at their drawn pose (ties: small
        // integers) and at a perturbed one; and A02 with its rods horizontal, a change point,
        // where Phi_x loses rank 2 (two pivots at rounding level).
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/models/");
        for file in ["five-bar-free-fall", "3-rrr", "andrews-squeezer", "slider-crank"] {
            let mech = crate::load(format!("{root}{file}.yaml")).expect(file);
            let mut x = mech.x0.clone();
            assert_pivots(&mech, &x, &format!("{file} drawn"));
            for (i, v) in x.iter_mut().enumerate() {
                *v += 1e-3 * ((i * 7 % 5) as f64 - 2.0);
            }
            assert_pivots(&mech, &x, &format!("{file} moved"));
        }
        let (mech, x) = a02_folded();
        let pivots = assert_pivots(&mech, &x, "A02 folded");
        // Rank 2 lost: two pivots at rounding level (2.7e-17), the others 0.45 and up.
        assert_eq!(pivots.iter().filter(|p| p.1 < 1e-12).count(), 2, "{pivots:?}");
    }
}
