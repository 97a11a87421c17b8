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
use super::u_support::USupport;
use crate::linalg::{BlockLu, MAX_COLUMNS};
use crate::model::Mechanism;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// A scaled pivot below this counts as singular. Scaled entries are O(1), so 1e-12 is about
/// 1e4 times the rounding error of an O(1) elimination.
pub const SINGULAR_PIVOT: f64 = 1e-12;
/// J(x) for one chart, scaled and LU-factorised.
#[derive(Debug)]
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
    /// Per column j of U, the bodies it may be non-zero on (those of the blocks its
    /// coordinate's row reaches), as runs.
    u_support: USupport,
    /// The entries of A = U^T M U that may be non-zero: the pairs j <= k of columns that share
    /// a body (of the blocks their coordinates reach, not only of their supports' ranges: a
    /// body order that interleaves the parts would make every range meet), and per row k the
    /// first such j (A's envelope, kept by its Cholesky factor); the entries (k, j) of the
    /// envelope below the diagonal that are no such pair, where the factor may fill in. The
    /// bodies pair p shares: the runs `a_runs[a_runs_at[p]..a_runs_at[p + 1]]`, [first, end).
    a_pairs: Vec<(usize, usize)>,
    a_runs_at: Vec<usize>,
    a_runs: Vec<(usize, usize)>,
    a_first: Vec<usize>,
    a_fill_in: Vec<(usize, usize)>,
    /// Identifies the analysis the supports above come from (unique over all systems): buffers
    /// that keep zeros outside the supports are cleared once when it changes.
    supports_id: u64,
    /// Whether the supports above are analysed (not in a system for measures only,
    /// [`System::other_chart`]'s).
    supports: bool,
    /// A system kept for the measures of another chart ([`System::other_chart`]).
    other: Option<Box<System>>,
    /// The analyses this system and its copies made, shared by them ([`Analyses`]).
    analyses: Analyses,
}

clone_reusing!(System {
    lu,
    pattern_chart,
    row_scale,
    col_scale,
    factored,
    chart,
    groups,
    unit_reach,
    u_support,
    a_pairs,
    a_runs_at,
    a_runs,
    a_first,
    a_fill_in,
    supports_id,
    supports,
    other,
    analyses
});

/// Fresh analyses (as [`System::analysed`] leaves them, before any factorisation) by chart,
/// shared by a system and its copies (a run's saved states, the prepared model's templates):
/// a chart switch back to a chart analysed before copies its analysis instead of analysing
/// it again (the five-bar free fall's run switched 12 times, each analysis 57 k instructions).
/// A copy is the analysis itself, so the results are those of a fresh one to the bit.
#[derive(Debug, Clone, Default)]
struct Analyses(Arc<Mutex<Vec<System>>>);

/// At most this many analyses are kept per [`Analyses`]: a mechanism's partitions are few in a
/// run (the five-bar's 5), and a bound keeps a long run through many charts from growing it.
const MAX_ANALYSES: usize = 16;

impl Analyses {
    /// Copy the analysis of `chart` (and of `supports`) kept here into `sys`; false if none is.
    fn copy_into(&self, sys: &mut System, chart: &Chart) -> bool {
        let kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let Some(a) = kept.iter().find(|a| a.pattern_chart == *chart && a.supports == sys.supports) else {
            return false;
        };
        sys.lu.clone_from(&a.lu);
        sys.groups.clone_from(&a.groups);
        sys.unit_reach.clone_from(&a.unit_reach);
        sys.u_support.clone_from(&a.u_support);
        sys.a_pairs.clone_from(&a.a_pairs);
        sys.a_runs_at.clone_from(&a.a_runs_at);
        sys.a_runs.clone_from(&a.a_runs);
        sys.a_first.clone_from(&a.a_first);
        sys.a_fill_in.clone_from(&a.a_fill_in);
        true
    }

    /// Keep a copy of `sys`'s fresh analysis (of its `pattern_chart`).
    fn keep(&self, sys: &mut System) {
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if kept.len() < MAX_ANALYSES {
            // Not the system kept for another chart, nor the shared list (no cycle of Arcs).
            let other = sys.other.take();
            kept.push(System { analyses: Analyses::default(), ..sys.clone() });
            sys.other = other;
        }
    }
}

/// The next [`System::supports_id`] (and the closed form's zero pattern of U, `column_reach`).
pub(crate) fn next_supports_id() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Column scales of the body coordinates: L for X and Y, 1 for phi.
pub fn col_scales(mech: &Mechanism) -> Vec<f64> {
    (0..mech.n_x()).map(|i| col_scale(mech, i)).collect()
}

/// The column scale of body coordinate i ([`col_scales`]).
pub fn col_scale(mech: &Mechanism, i: usize) -> f64 {
    if i % 3 == 2 {
        1.0
    } else {
        mech.scale
    }
}

impl System {
    /// J of the user's chart, its structure analysed.
    pub fn new(mech: &Mechanism) -> Self {
        Self::for_chart(mech, &Chart::Inputs)
    }

    /// J of `chart`, its structure analysed (once: not the user's chart's first, then this one's).
    pub fn for_chart(mech: &Mechanism, chart: &Chart) -> Self {
        Self::analysed(mech, chart, true)
    }

    /// J of `chart` for its type II measure only ([`System::group_sigma_exact`]): its blocks and
    /// their scales, without the supports of U and A that the solves and A = U^T M U use (20 k
    /// of the five-bar's 57 k instructions an analysis).
    fn for_measures(mech: &Mechanism, chart: &Chart) -> Self {
        Self::analysed(mech, chart, false)
    }

    fn analysed(mech: &Mechanism, chart: &Chart, supports: bool) -> Self {
        let lu = BlockLu::new(&jacobian_pattern(mech, chart));
        let mut sys = System {
            groups: GroupScales::new(mech, chart, &lu),
            unit_reach: None,
            u_support: USupport::default(),
            a_pairs: Vec::new(),
            a_runs_at: Vec::new(),
            a_runs: Vec::new(),
            a_first: Vec::new(),
            a_fill_in: Vec::new(),
            supports,
            supports_id: next_supports_id(),
            other: None,
            analyses: Analyses::default(),
            lu,
            pattern_chart: chart.clone(),
            row_scale: vec![1.0; mech.n_x()],
            col_scale: col_scales(mech),
            factored: false,
            chart: chart.clone(),
        };
        if supports {
            sys.analyse_supports(mech);
        }
        sys.analyses.clone().keep(&mut sys);
        sys
    }

    /// The supports of U and A from the analysed blocks.
    fn analyse_supports(&mut self, mech: &Mechanism) {
        self.unit_reach = unit_reach(mech, &self.lu);
        let u_bodies = u_bodies(mech, &self.lu);
        self.u_support = USupport::new(&u_bodies);
        let a = a_pattern(&u_bodies, mech.n_bodies());
        (self.a_pairs, self.a_runs_at, self.a_runs, self.a_first, self.a_fill_in) =
            (a.pairs, a.runs_at, a.runs, a.first, a.fill_in);
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
            if !self.analyses.clone().copy_into(self, chart) {
                self.lu = BlockLu::new(&jacobian_pattern(mech, chart));
                self.groups = GroupScales::new(mech, chart, &self.lu);
                if self.supports {
                    self.analyse_supports(mech);
                }
                self.pattern_chart.clone_from(chart);
                self.analyses.clone().keep(self);
            }
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

    /// Whether [`System::group_sigma_exact`] would be below `t` (> 0): the same answer, taking
    /// a block's SVD only where rounding could change it (`GroupScales::below`).
    pub fn group_sigma_below(&mut self, mech: &Mechanism, chart: &Chart, x: &[f64], trig: &[[f64; 2]], t: f64) -> bool {
        self.fill(mech, chart, x, trig);
        self.groups.reset();
        self.groups.below(&self.lu, t)
    }

    /// A system kept with this one for the measures of `chart`, another chart than this one's
    /// (the passive measure's partition, which changes only where the pivots do): its pattern is
    /// analysed when the chart changes, not at each measure (the five-bar's analysis cost 74 k
    /// instructions, its measure 35 k). It serves the measures only (no supports of U and A);
    /// its factorisation is not this system's.
    pub fn other_chart(&mut self, mech: &Mechanism, chart: &Chart) -> &mut System {
        self.other.get_or_insert_with(|| Box::new(System::for_measures(mech, chart)))
    }

    /// The system kept for another chart's measures ([`System::other_chart`]), if any.
    pub fn other(&self) -> Option<&System> {
        self.other.as_deref()
    }

    /// Keep `make()` as the system for another chart's measures, unless one is kept already.
    pub fn keep_other(&mut self, make: impl FnOnce() -> System) {
        self.other.get_or_insert_with(|| Box::new(make()));
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

    /// Per column j of U = dx/dz, the bodies it may be non-zero on, as runs (from the blocks
    /// its coordinate reaches): the products of U's columns skip the others.
    pub fn u_support(&self) -> &USupport {
        debug_assert!(self.supports, "a system for measures only has no supports");
        &self.u_support
    }

    /// The pairs (j, k), j <= k, of columns of U that share a body: the entries of
    /// A = U^T M U (and its mirror) that may be non-zero, by rows k, j ascending.
    pub fn a_pairs(&self) -> &[(usize, usize)] {
        debug_assert!(self.supports, "a system for measures only has no supports");
        &self.a_pairs
    }

    /// The bodies the p-th of [`System::a_pairs`] shares, as runs [first, end), ascending.
    pub fn a_runs(&self, p: usize) -> &[(usize, usize)] {
        &self.a_runs[self.a_runs_at[p]..self.a_runs_at[p + 1]]
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
    let reach = lu.reaches(rows.chunks(MAX_COLUMNS));
    reach.iter().any(|blocks| blocks.len() < lu.n_blocks()).then_some(reach)
}

/// The bodies (ascending) each column of U may be non-zero on: those of the blocks its
/// coordinate's row reaches.
fn u_bodies(mech: &Mechanism, lu: &BlockLu) -> Vec<Vec<usize>> {
    let (n, m) = (mech.n_x(), mech.dof());
    let cols = lu.position_cols();
    let rows: Vec<[usize; 1]> = (n - m..n).map(|row| [row]).collect();
    lu.reaches(rows.iter().map(|r| &r[..]))
        .into_iter()
        .map(|blocks| {
            let mut bodies: Vec<usize> = blocks.into_iter().flat_map(|k| lu.span(k)).map(|p| cols[p] / 3).collect();
            bodies.sort_unstable();
            bodies.dedup();
            bodies
        })
        .collect()
}

/// A's pattern (see [`System::a_pairs`]).
struct APattern {
    pairs: Vec<(usize, usize)>,
    runs_at: Vec<usize>,
    runs: Vec<(usize, usize)>,
    first: Vec<usize>,
    fill_in: Vec<(usize, usize)>,
}

/// The pairs of columns that share a body, the bodies they share, A's envelope and its
/// fill-in, from each column's bodies. Once per chart, through the columns on each body: the
/// cost is the pairs' shared bodies, not m^2 comparisons.
fn a_pattern(u_bodies: &[Vec<usize>], n_bodies: usize) -> APattern {
    let mut on_body: Vec<Vec<usize>> = vec![Vec::new(); n_bodies];
    for (j, bodies) in u_bodies.iter().enumerate() {
        bodies.iter().for_each(|&b| on_body[b].push(j));
    }
    // (k, j, body) for j <= k on a common body, sorted: by row k, then j, then body.
    let mut shared: Vec<(usize, usize, usize)> = Vec::new();
    for (b, cols) in on_body.iter().enumerate() {
        for (i, &k) in cols.iter().enumerate() {
            shared.extend(cols[..=i].iter().map(|&j| (k, j, b)));
        }
    }
    shared.sort_unstable();
    let m = u_bodies.len();
    let mut a = APattern {
        pairs: Vec::new(),
        runs_at: vec![0],
        runs: Vec::new(),
        first: (0..m).collect(),
        fill_in: Vec::new(),
    };
    for (i, &(k, j, b)) in shared.iter().enumerate() {
        let new_pair = i == 0 || (shared[i - 1].0, shared[i - 1].1) != (k, j);
        if new_pair {
            if i > 0 {
                a.runs_at.push(a.runs.len());
            }
            a.pairs.push((j, k));
            a.first[k] = a.first[k].min(j);
        }
        match a.runs.last_mut() {
            Some(run) if !new_pair && run.1 == b => run.1 = b + 1,
            _ => a.runs.push((b, b + 1)),
        }
    }
    a.runs_at.push(a.runs.len());
    let mut in_row = vec![false; m];
    let mut p = 0;
    for k in 0..m {
        let start = p;
        while p < a.pairs.len() && a.pairs[p].1 == k {
            in_row[a.pairs[p].0] = true;
            p += 1;
        }
        a.fill_in.extend((a.first[k]..k).filter(|&j| !in_row[j]).map(|j| (k, j)));
        a.pairs[start..p].iter().for_each(|&(j, _)| in_row[j] = false);
    }
    a
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::constraints::body_trig;
    use crate::kinematics::select_partition;

    /// A chart switch back to a chart analysed before copies the kept analysis (the list of
    /// analyses does not grow, and a copy of the system shares it), and the copy factorises,
    /// solves and measures as a fresh analysis does, to the bit.
    #[test]
    fn a_chart_analysed_before_is_copied_and_gives_a_fresh_analysis_bits() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/models");
        let mech = crate::load(root.join("five-bar-free-fall.yaml").to_str().unwrap()).unwrap();
        let x = mech.x0.clone();
        let mut trig = vec![[0.0; 2]; mech.n_bodies()];
        body_trig(&x, &mut trig);
        let partition = Chart::Partition(select_partition(&mech, &x));
        let kept = |sys: &System| sys.analyses.0.lock().unwrap().len();
        // J's factors through a solve, and the type II estimate of the factors.
        let figures = |sys: &mut System, chart: &Chart| {
            sys.factor(&mech, chart, &x, &trig).unwrap();
            let mut b: Vec<f64> = (0..x.len()).map(|i| 1.0 + 0.1 * i as f64).collect();
            sys.solve(&mut b);
            let sigma = sys.sigma_min_estimate().unwrap();
            (b.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), sigma.to_bits())
        };
        let mut sys = System::new(&mech);
        let first = figures(&mut sys, &Chart::Inputs);
        let mut copy = sys.clone();
        let in_partition = figures(&mut copy, &partition);
        assert_eq!(kept(&sys), 2, "the copy's analysis of the partition is shared");
        assert_eq!(figures(&mut System::for_chart(&mech, &partition), &partition), in_partition);
        let id = copy.supports_id();
        assert_eq!(figures(&mut copy, &Chart::Inputs), first, "back in the user's chart: a fresh analysis's bits");
        assert_ne!(copy.supports_id(), id, "a new analysis id for the buffers");
        assert_eq!(figures(&mut sys, &partition), in_partition);
        assert_eq!(kept(&sys), 2, "no chart analysed twice");
    }
}
