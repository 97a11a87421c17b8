//! The factorised, scaled Jacobian J = dF/dx of the position equations (docs/formulation.md,
//! *Scaling by the characteristic length*).
//!
//! J is factorised in scaled variables so that its pivots and singular values are
//! dimensionless: translations are measured in units of the mechanism's characteristic
//! length L (column scale L) and length-valued rows are divided by L (angle rows are kept).
//! All solves take and return unscaled vectors. The factorisation is block-triangular
//! (`linalg::BlockLu`): input links and Assur groups are eliminated one after another, with
//! the blocks found once per chart from the pattern of J.

use super::constraints::{jacobian, jacobian_into, jacobian_pattern, Chart};
use super::pairs;
use crate::linalg::BlockLu;
use crate::model::{CoordinateKind, Mechanism};

/// A scaled pivot below this counts as singular. Scaled entries are O(1), so 1e-12 is about
/// 1e4 times the rounding error of an O(1) elimination.
pub const SINGULAR_PIVOT: f64 = 1e-12;
/// Inverse iterations of the singularity estimate from a cold start: 2 digits when the two
/// smallest singular values differ by 30 %, many more near a singularity (where they separate).
const SIGMA_ITERATIONS: usize = 8;
/// A warm-started estimate stops when an iteration changes 1/sigma^2 by less than this
/// (relative): sigma to about 1e-3, far finer than the chart thresholds (0.05, 0.1) need.
const SIGMA_RTOL: f64 = 2e-3;

/// J(x) for one chart, scaled and LU-factorised.
#[derive(Debug, Clone)]
pub struct System {
    lu: BlockLu,
    /// The chart whose pattern `lu` was analysed for.
    pattern_chart: Chart,
    /// Row scale: 1/L for rows in metres, 1 for rows in radians.
    pub row_scale: Vec<f64>,
    /// Column scale: L for translations, 1 for angles (x = col_scale * x_scaled).
    pub col_scale: Vec<f64>,
    /// Whether the last factorisation succeeded.
    factored: bool,
    /// The chart of the last factorisation.
    chart: Chart,
    /// Inverse-iteration vectors of [`System::sigma_min_estimate`].
    v: Vec<f64>,
    w: Vec<f64>,
    /// Whether `v` holds the singular vector of a previous estimate (a warm start).
    sigma_warm: bool,
}

/// Column scales of the body coordinates: L for X and Y, 1 for phi.
pub fn col_scales(mech: &Mechanism) -> Vec<f64> {
    (0..mech.n_x()).map(|i| if i % 3 == 2 { 1.0 } else { mech.scale }).collect()
}

impl System {
    pub fn new(mech: &Mechanism) -> Self {
        let n = mech.n_x();
        System {
            lu: BlockLu::new(&jacobian_pattern(mech, &Chart::Inputs)),
            pattern_chart: Chart::Inputs,
            row_scale: vec![1.0; n],
            col_scale: col_scales(mech),
            factored: false,
            chart: Chart::Inputs,
            v: vec![0.0; n],
            w: vec![0.0; n],
            sigma_warm: false,
        }
    }

    /// Evaluate and factorise J(x). Err carries the column (body coordinate) that had no
    /// pivot. A new chart's pattern is analysed here (at a chart switch, not in a step).
    pub fn factor(&mut self, mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]]) -> Result<(), usize> {
        if self.pattern_chart != *chart {
            self.lu = BlockLu::new(&jacobian_pattern(mech, chart));
            self.pattern_chart.clone_from(chart);
        }
        set_row_scale(mech, chart, &mut self.row_scale);
        jacobian_into(mech, chart, x, trig, &mut self.lu.sink(&self.row_scale, &self.col_scale));
        self.chart.clone_from(chart);
        let out = self.lu.factor(SINGULAR_PIVOT).map_err(|e| e.column);
        self.factored = out.is_ok();
        out
    }

    /// Whether J is factorised (the last [`System::factor`] succeeded).
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Whether J is factorised for `chart` (at some nearby x, for a chord iteration).
    pub fn is_factored_for(&self, chart: &Chart) -> bool {
        self.factored && self.chart == *chart
    }

    /// The smallest singular value of the factorised scaled J, by inverse iteration on
    /// (J^T J)^-1 with the LU factors (Golub & Van Loan 8.2.2): no new factorisation, 2n^2
    /// flops per iteration. The estimate approaches sigma_min from above; the error falls as
    /// (sigma_1 / sigma_2)^(2k) with the two smallest singular values, so it is sharpest
    /// exactly where it matters, near a singularity. Along a simulation each call starts
    /// from the previous singular vector, which is nearly right, and stops once the estimate
    /// moves by less than [`SIGMA_RTOL`] (usually after 2 iterations instead of 8).
    /// `None` if J is not factorised.
    pub fn sigma_min_estimate(&mut self) -> Option<f64> {
        if !self.factored {
            return None;
        }
        // A fixed start with no special structure, so it is never orthogonal by design to
        // the singular vector of a symmetric mechanism; a little of it is mixed into the warm
        // start so that no direction is missing there either.
        let fixed = |i: usize| 1.0 + 0.37 * ((i * 7 + 3) % 11) as f64;
        let warm = self.sigma_warm;
        for (i, v) in self.v.iter_mut().enumerate() {
            *v = if warm { *v + 1e-3 * fixed(i) } else { fixed(i) };
        }
        let mut lambda = 0.0;
        for k in 0..SIGMA_ITERATIONS {
            let norm = self.v.iter().map(|x| x * x).sum::<f64>().sqrt();
            self.v.iter_mut().for_each(|x| *x /= norm);
            self.w.copy_from_slice(&self.v);
            self.lu.solve(&mut self.w);
            self.lu.solve_transpose(&mut self.w);
            let previous = lambda;
            lambda = self.w.iter().zip(&self.v).map(|(a, b)| a * b).sum::<f64>();
            std::mem::swap(&mut self.v, &mut self.w);
            if warm && k > 0 && (lambda - previous).abs() <= SIGMA_RTOL * lambda {
                break;
            }
        }
        self.sigma_warm = lambda.is_finite() && lambda > 0.0;
        Some(if lambda > 0.0 { 1.0 / lambda.sqrt() } else { 0.0 })
    }

    /// Solve J y = b in place (b and y unscaled).
    pub fn solve(&mut self, b: &mut [f64]) {
        self.lu.solve_scaled(b, &self.row_scale, &self.col_scale);
    }

    /// Solve J Y = B in place for the columns of `b` (3n values each, one after the other).
    pub fn solve_many(&mut self, b: &mut [f64]) {
        self.lu.solve_many_scaled(b, &self.row_scale, &self.col_scale);
    }

    /// Solve J^T y = b in place (b and y unscaled).
    pub fn solve_transpose(&mut self, b: &mut [f64]) {
        for (v, s) in b.iter_mut().zip(&self.col_scale) {
            *v *= s;
        }
        self.lu.solve_transpose(b);
        for (v, s) in b.iter_mut().zip(&self.row_scale) {
            *v *= s;
        }
    }
}

/// Fill `j` (row-major, n x n) with the scaled Jacobian of a chart and `rs` with its row
/// scales, given the column scales `cs`.
pub fn scaled_jacobian(
    mech: &Mechanism,
    chart: &Chart,
    x: &[f64],
    trig: &[[f64; 2]],
    rs: &mut [f64],
    cs: &[f64],
    j: &mut [f64],
) {
    let n = x.len();
    set_row_scale(mech, chart, rs);
    jacobian(mech, chart, x, trig, j);
    for r in 0..n {
        for (v, c) in j[r * n..(r + 1) * n].iter_mut().zip(cs) {
            *v *= rs[r] * c;
        }
    }
}

/// 1/L for rows measured in metres, 1 for rows measured in radians.
pub fn set_row_scale(mech: &Mechanism, chart: &Chart, rs: &mut [f64]) {
    let inv = 1.0 / mech.scale;
    for (pair, slots) in mech.pairs.iter().zip(&mech.pair_slots) {
        for (slot, scale) in slots.iter().zip(pairs::row_scales(pair, inv)) {
            if let Some(i) = *slot {
                rs[i] = scale;
            }
        }
    }
    let nc = mech.n_constraints;
    for (k, r) in rs[nc..].iter_mut().enumerate() {
        let angle = match chart {
            Chart::Inputs => mech.coordinates[k].kind == CoordinateKind::Angle,
            Chart::Partition(idx) => idx[k] % 3 == 2,
        };
        *r = if angle { 1.0 } else { inv };
    }
}
