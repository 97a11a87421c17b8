//! The factorised, scaled Jacobian J = dF/dx of the position equations (docs/formulation.md,
//! *Scaling by the characteristic length*).
//!
//! J is factorised in scaled variables so that its pivots and singular values are
//! dimensionless: translations are measured in units of the mechanism's characteristic
//! length L (column scale L) and length-valued rows are divided by L (angle rows are kept).
//! All solves take and return unscaled vectors. The factorisation is block-triangular
//! (`linalg::BlockLu`): input links and Assur groups are eliminated one after another, with
//! the blocks found once per chart from the pattern of J.

use super::constraints::{jacobian, jacobian_into, jacobian_pattern, set_row_scale, Chart};
use super::group_sigma::GroupScales;
use crate::linalg::{BlockLu, MAX_COLUMNS};
use crate::model::Mechanism;
use std::sync::atomic::{AtomicU64, Ordering};

/// A scaled pivot below this counts as singular. Scaled entries are O(1), so 1e-12 is about
/// 1e4 times the rounding error of an O(1) elimination.
pub const SINGULAR_PIVOT: f64 = 1e-12;
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
    /// The blocks' own scales and the type II estimate's vectors (`group_sigma`).
    groups: GroupScales,
    /// Per sweep of [`MAX_COLUMNS`] columns of J U = [0; I_m], the blocks U may be non-zero
    /// on (`BlockLu::reach`): a coordinate moves only the groups that depend on it. None when
    /// every sweep reaches every block (a single closed chain): the plain solve, no zeroing.
    unit_reach: Option<Vec<Vec<usize>>>,
    /// Per column j of U, the bodies it may be non-zero on, [first, end): those of the blocks
    /// its coordinate's row reaches.
    u_support: Vec<(usize, usize)>,
    /// The entries of A = U^T M U that may be non-zero: the pairs j <= k of columns whose
    /// supports meet, and per row k the first such j (A's envelope, kept by its Cholesky factor);
    /// the entries (k, j) of the envelope below the diagonal that are no such pair, where the
    /// factor may fill in.
    a_pairs: Vec<(usize, usize)>,
    a_first: Vec<usize>,
    a_fill_in: Vec<(usize, usize)>,
    /// Identifies the analysis the supports above come from (unique over all systems): buffers
    /// that keep zeros outside the supports are cleared once when it changes.
    supports_id: u64,
}

/// The next [`System::supports_id`] (and the closed form's zero pattern of U, `column_reach`).
pub(crate) fn next_supports_id() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Column scales of the body coordinates: L for X and Y, 1 for phi.
pub fn col_scales(mech: &Mechanism) -> Vec<f64> {
    (0..mech.n_x()).map(|i| if i % 3 == 2 { 1.0 } else { mech.scale }).collect()
}

impl System {
    pub fn new(mech: &Mechanism) -> Self {
        let lu = BlockLu::new(&jacobian_pattern(mech, &Chart::Inputs));
        let u_support = u_support(mech, &lu);
        let (a_pairs, a_first, a_fill_in) = a_pattern(&u_support);
        System {
            groups: GroupScales::new(mech, &Chart::Inputs, &lu),
            unit_reach: unit_reach(mech, &lu),
            u_support,
            a_pairs,
            a_first,
            a_fill_in,
            supports_id: next_supports_id(),
            lu,
            pattern_chart: Chart::Inputs,
            row_scale: vec![1.0; mech.n_x()],
            col_scale: col_scales(mech),
            factored: false,
            chart: Chart::Inputs,
        }
    }

    /// Evaluate and factorise J(x). Err carries the column (body coordinate) that had no
    /// pivot. A new chart's pattern is analysed here (at a chart switch, not in a step).
    pub fn factor(&mut self, mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]]) -> Result<(), usize> {
        self.fill(mech, chart, x, trig);
        let out = self.lu.factor(SINGULAR_PIVOT).map_err(|e| e.column);
        self.factored = out.is_ok();
        out
    }

    /// Evaluate J(x) into the blocks without factorising it.
    fn fill(&mut self, mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]]) {
        if self.pattern_chart != *chart {
            self.lu = BlockLu::new(&jacobian_pattern(mech, chart));
            self.groups = GroupScales::new(mech, chart, &self.lu);
            self.unit_reach = unit_reach(mech, &self.lu);
            self.u_support = u_support(mech, &self.lu);
            (self.a_pairs, self.a_first, self.a_fill_in) = a_pattern(&self.u_support);
            self.supports_id = next_supports_id();
            self.pattern_chart.clone_from(chart);
        }
        set_row_scale(mech, chart, &mut self.row_scale);
        jacobian_into(mech, chart, x, trig, &mut self.lu.sink(&self.row_scale, &self.col_scale));
        self.chart.clone_from(chart);
        self.factored = false;
    }

    /// The exact type II measure of `chart`'s J at x (see `group_sigma`): J is evaluated and
    /// each of its blocks decomposed (SVD); the factorisation is left invalid.
    pub fn group_sigma_exact(&mut self, mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]]) -> f64 {
        self.fill(mech, chart, x, trig);
        self.groups.reset();
        self.groups.exact(&self.lu)
    }

    /// Whether J is factorised (the last [`System::factor`] succeeded).
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Whether J is factorised for `chart` (at some nearby x, for a chord iteration).
    pub fn is_factored_for(&self, chart: &Chart) -> bool {
        self.factored && self.chart == *chart
    }

    /// The type II measure of the factorised J (see `group_sigma`): the smallest singular
    /// value of its blocks at their own lengths, estimated by inverse iteration with the factors
    /// in hand, warm-started from the previous call. `None` if J is not factorised.
    pub fn sigma_min_estimate(&mut self) -> Option<f64> {
        self.factored.then(|| self.groups.estimate(&self.lu))
    }

    /// Column scales with each group's own length (L_k for translations, 1 for angles): the
    /// units in which a Newton correction is compared with the type II measure.
    pub fn group_col_scale(&self) -> &[f64] {
        &self.groups.col_scale
    }

    /// Solve J y = b in place (b and y unscaled).
    pub fn solve(&mut self, b: &mut [f64]) {
        self.lu.solve_scaled(b, &self.row_scale, &self.col_scale);
    }

    /// Solve J U = [0; I_m] into `u` (m columns of 3n): each column is solved and written on
    /// the blocks it reaches only; its other entries must be 0 already (see [`System::supports_id`]).
    pub fn solve_unit_columns(&mut self, u: &mut [f64]) {
        let n = self.col_scale.len();
        let first_row = n - u.len() / n.max(1);
        self.lu.solve_unit_columns(u, first_row, &self.row_scale, &self.col_scale, self.unit_reach.as_deref());
    }

    /// Per column j of U = dx/dz, the bodies it may be non-zero on, [first, end) (from the
    /// blocks its coordinate reaches): the products of U's columns skip the others.
    pub fn u_support(&self) -> &[(usize, usize)] {
        &self.u_support
    }

    /// The pairs (j, k), j <= k, of columns of U whose supports meet: the entries of
    /// A = U^T M U (and its mirror) that may be non-zero.
    pub fn a_pairs(&self) -> &[(usize, usize)] {
        &self.a_pairs
    }

    /// Per row k of A, the first column j with (j, k) in [`System::a_pairs`]: A's envelope.
    pub fn a_first(&self) -> &[usize] {
        &self.a_first
    }

    /// The entries (k, j), j < k, of A's envelope that are not in [`System::a_pairs`]: zero in A,
    /// possibly not in its Cholesky factor.
    pub fn a_fill_in(&self) -> &[(usize, usize)] {
        &self.a_fill_in
    }

    /// Changes whenever [`System::u_support`] and the pattern of A may have changed (a new
    /// chart's pattern): a buffer that relies on zeros outside them is cleared then.
    pub fn supports_id(&self) -> u64 {
        self.supports_id
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

/// The blocks of `lu` each sweep of unit columns of [0; I_m] reaches (see
/// [`System::solve_unit_columns`]).
fn unit_reach(mech: &Mechanism, lu: &BlockLu) -> Option<Vec<Vec<usize>>> {
    let (n, m) = (mech.n_x(), mech.dof());
    let rows: Vec<usize> = (n - m..n).collect();
    let reach: Vec<Vec<usize>> = rows.chunks(MAX_COLUMNS).map(|sweep| lu.reach(sweep)).collect();
    reach.iter().any(|blocks| blocks.len() < lu.n_blocks()).then_some(reach)
}

/// The bodies each column of U may be non-zero on (see [`System::u_support`]).
fn u_support(mech: &Mechanism, lu: &BlockLu) -> Vec<(usize, usize)> {
    let (n, m) = (mech.n_x(), mech.dof());
    let cols = lu.position_cols();
    (n - m..n)
        .map(|row| {
            let bodies = lu.reach(&[row]).into_iter().flat_map(|k| lu.span(k)).map(|p| cols[p] / 3);
            bodies.fold((usize::MAX, 0), |(first, end), b| (first.min(b), end.max(b + 1)))
        })
        .map(|(first, end)| (first.min(end), end))
        .collect()
}

/// The pairs of columns whose supports meet, A's envelope and its fill-in (see
/// [`System::a_pairs`]). Once per chart: the m^2 / 2 comparisons are not made in a step.
type APattern = (Vec<(usize, usize)>, Vec<usize>, Vec<(usize, usize)>);
fn a_pattern(support: &[(usize, usize)]) -> APattern {
    let meet = |(f1, e1): (usize, usize), (f2, e2): (usize, usize)| f1.max(f2) < e1.min(e2);
    let (mut pairs, mut first, mut fill_in) = (Vec::new(), Vec::with_capacity(support.len()), Vec::new());
    for (k, &sk) in support.iter().enumerate() {
        let row: Vec<usize> = (0..k).filter(|&j| meet(support[j], sk)).collect();
        let f = row.first().copied().unwrap_or(k);
        fill_in.extend((f..k).filter(|j| !row.contains(j)).map(|j| (k, j)));
        pairs.extend(row.into_iter().chain([k]).map(|j| (j, k)));
        first.push(f);
    }
    (pairs, first, fill_in)
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
