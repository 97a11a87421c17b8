//! The equations of motion as a first-order system for the integrators, in a chart z:
//! y = [z, zd, W] with y' = [zd, zdd, P], where W is the work done by the non-conservative
//! forces and P its power, so that T + V - W is constant along any exact trajectory.

use crate::dynamics::transmission::Band;
use crate::dynamics::{dynamic_stages, forward, forward_prescribed, Drives, Prescribed};
use crate::integrate::OdeSystem;
use crate::kinematics::alt_charts::AltCharts;
use crate::kinematics::analogues::u_times_from;
use crate::kinematics::constraints::gamma;
use crate::kinematics::Frame;
use crate::kinematics::{
    coordinate_rates, coordinates, scaled_distances, sigma_min, sigma_min_with, Chart, ClosedForm, System,
    MAX_CORRECTION,
};
use crate::linalg::copy_small;
use crate::model::Mechanism;
use crate::Workspace;
use crate::{Error, KinematicsError, SingularityKind};
use std::sync::{Arc, OnceLock};

/// Largest Newton correction as a fraction of the chart's type II measure (see
/// `MechanismOde::limit_correction`); both in each group's own length (`group_sigma`).
const BASIN_FRACTION: f64 = 0.5;

/// Largest move of a solution from the converged point it was predicted from, as a multiple
/// of the chart's smallest scaled singular value. The branch x(z) is analytic only out to
/// the nearest fold, about sigma away (scaled); a Taylor predictor taken further can land
/// on the other branch with a small correction (DOPRI5 at rtol 1e-4 on the five-bar: a
/// 0.47 jump in one 3.5 ms step, corrections all under 0.05, -1.8 J).
const MOVE_FRACTION: f64 = 2.0;

/// Largest move of a step's solutions from the last accepted point, as a multiple of the
/// chart's own measure there (scaled, as [`MOVE_FRACTION`], and the same radius: x(z) is
/// analytic only out to the nearest fold). A step whose stages go past it crosses or grazes
/// the chart's singularity, where the chart's equations of motion vary like 1/sigma^2 and the
/// embedded error estimate no longer bounds the error: the five-bar at DOP853 rtol = atol =
/// 2.51e-6 (with the first-step fraction at 0.28) stepped in partition [5, 11] from own 0.09
/// to 0.0017 (0.4519 -> 0.4602 s), its zd 8.8e-3 off (157x the tolerance) while the test
/// passed: +0.76 J; at 3.86e-5 a step in the user's chart from above 0.1 gained 0.89 J. Its
/// solutions are refused past this reach, as the predictor's are past [`MOVE_FRACTION`]; the
/// integrator then shortens the step, and the monitor changes chart at an accepted point.
/// Over rtol = atol = 1e-4 ... 1e-8 (81 values) the worst DOP853 drift went 1.0e-3 -> 8.1e-4 J,
/// DOPRI5's 2.2e-2 -> 4.9e-3 J, for 12 % (DOP853) and 0.3 % (DOPRI5) more evaluations; a
/// reach of 3 let the 0.76 J step through.
const STEP_REACH: f64 = MOVE_FRACTION;

/// The longest step after an accepted point, as a fraction of the step at which its body
/// rates there would carry x to the step's reach ([`STEP_REACH`]; `Run::aim`). A stage past
/// the reach fails the step, which is taken again 4 times shorter (`FAIL_FACTOR`): the 3-RRR
/// of the benchmarks (DOPRI5, rtol 0.195) had 4 of its 14 steps refused so, the five-bar's
/// fall (rtol 7.59e-7) 2 of 140, Andrews' squeezer (rtol 1e-6) 2 of 89. Cheapest DOPRI5
/// setting passing each benchmark's drift target (every step; rtol = 10^(-k/100), the
/// benchmark's search), with the predictive step bound of `Run::aim` and this bound applied
/// before change points too, by this fraction: 0.5: five-bar 780 evaluations, 3-RRR 62,
/// Andrews 470; 0.7: 756, 62, 353; 0.85: 756, 122, 326; 1: 718, 127, 891; without the bound:
/// 767, 74, 522. Kept away from change points' grids, 0.7: 750, 72, 411 (measured in s15 with
/// the bound off in the whole approach; `Run::aim` now keeps it above APPROACH_BELOW too, and
/// these figures were not measured again). The stages move
/// x faster than the start's rates where the motion accelerates towards the singularity, and a
/// longer bound lets more of them fail.
const REACH_STEP_FRACTION: f64 = 0.7;

/// Below this type II measure at the last accepted point the user's chart takes the Newton
/// path even where closed forms exist. A dyad's branch changes where the passive motion goes
/// through its fold (the five-bar's type II singularities, A02's change points, where the
/// parallelogram branch crosses the dyad's base line); the closed forms keep the branch by
/// construction, while the Newton path's predictor follows the motion's tangent there. An
/// evaluation whose predictor has crossed a fold takes the Newton path
/// (`ClosedForm::keeps_branches`); this threshold keeps the closed forms away from the
/// partition threshold (0.05), below which the chart changes. At 0.07 (was 0.1) the five-bar
/// free fall (DOPRI5 rtol 7.59e-7, 1 s) took 401 -> 313 position solves (27.4 -> 24.9 M
/// instructions), its counters unchanged and its drift within 3e-7 of itself; at 0.05, A02's
/// N = 40 crossings at rtol 1e-12 were 1.05e-8 rad off (0.06: 3.5e-9, 0.07: 2.3e-9, 0.1:
/// 2.7e-9; tests/change_points.rs bounds 1e-8).
pub(super) const CLOSED_FORM_SIGMA: f64 = 0.07;

/// Smallest own measure of the chart at a dense-output stage, as a fraction of the measure at
/// the step's start. In a chart the equations of motion are ill-conditioned like 1/sigma^2
/// near its singularity, and a step may pass through one between its stages, which then never
/// see it: the five-bar at DOP853 rtol 1.26e-7 stepped in q (0.6152 -> 0.6270 s) while its
/// cranks' ends C1, C2 passed each other (C1x - C2x from -59 to +14.6 mm; its stages at -9.4
/// and +4.9 mm), and the dense stage at 7/9 of the step, at -0.6 mm, gave qdd = (-116.9, 96.6)
/// rad/s^2 where the path has (-107, 107): its output at t = 0.62 s was 5.8e-5 J off, the steps
/// 4.6e-7 J. A refused stage leaves the step's outputs to `Dop853::substep`. A step that only
/// approaches the singularity has its stages above its end, which the monitor keeps near the
/// switch threshold (0.05) or above.
const DENSE_SIGMA_FRACTION: f64 = 0.1;

/// Smallest |zd| from which the one-coordinate predictor takes w(dz, dz) = (dz / zd)^2 c
/// (`MechanismOde::predict`): the square root of the smallest normal f64, so that zd^2 and the
/// products in c are normal numbers (no precision lost to underflow).
const MIN_RATE: f64 = 1.4916681462400413e-154;

/// A mechanism in one chart, with the state the Newton predictor starts from.
pub struct MechanismOde<'a> {
    pub mech: &'a Mechanism,
    /// Boxed, as the spare's: [`MechanismOde::swap_spare`] swaps two pointers, not the buffers'
    /// headers (688 instructions a swap by value, 5 % of a four-bar run's).
    pub ws: Box<Workspace>,
    pub drives: &'a mut dyn Drives,
    /// The coordinates driven by motion, if any ([`MechanismOde::with_motion`]).
    pub motion: Option<&'a mut Prescribed<'a>>,
    /// (2m + 1) With a prescribed motion, the state evaluated last: y with, in the user's
    /// chart, the prescribed coordinates and rates replaced by their motion's (without one,
    /// `last_y`: [`MechanismOde::evaluated_y`]).
    eval_y: Vec<f64>,
    /// The last accepted point: body coordinates, analogues U (3n x m) and chart values z.
    anchor_x: Vec<f64>,
    anchor_u: Vec<f64>,
    anchor_z: Vec<f64>,
    /// The zero pattern of U (`Frame::u_zeros_for`) whose copy `anchor_u` holds (0: none).
    anchor_u_zeros: u64,
    /// The (t, y) of the evaluation whose results `ws` holds, to reuse it at acceptance.
    last_t: f64,
    last_y: Vec<f64>,
    /// Whether `ws` holds a successful evaluation at `last_y` (in the current chart).
    base_valid: bool,
    /// (3n) the Newton start of the current evaluation, and the converged point it was
    /// predicted from.
    predicted: Vec<f64>,
    /// (2m + 1) the intermediate states of [`MechanismOde::evaluate_walking`].
    walk_y: Vec<f64>,
    base: Vec<f64>,
    /// Largest scaled Newton correction accepted from the predictor (see `limit_correction`).
    max_correction: f64,
    max_move: f64,
    /// Largest move of a solution from the last accepted point: [`STEP_REACH`] times the
    /// chart's measure there, less while a change point is approached ([`MechanismOde::limit_move`]).
    max_approach: f64,
    /// Evaluations that failed (Newton did not converge, or its correction was too large).
    pub failed_evaluations: usize,
    /// The blocks of the user's chart, analysed once: the type II measure while a partition
    /// is integrated (`charts::measure`).
    pub inputs_sys: System,
    /// The user's chart in closed form, where every group has one (`kinematics::closed_form`),
    /// its branches those of the last accepted point; whether the point in `ws` came from it
    /// (its groups' geometry is then that point's); and whether `ws.sys` is then behind that
    /// point (factorised at the monitor's request only, once a step).
    closed: Option<ClosedForm>,
    base_closed: bool,
    stale_j: bool,
    /// The user's chart's closed forms while `closed` holds an alternative chart's (moved, not
    /// copied, at a switch), and the alternative charts, analysed by the first run that asks
    /// (shared with its `Prepared`) and copied into this one then.
    user_closed: Option<ClosedForm>,
    alt_shared: Arc<OnceLock<AltCharts>>,
    alt: Option<AltCharts>,
    /// The scratch frame of the measures taken by other charts' closed forms: where the user's
    /// place the point of an alternative chart for its type II measure
    /// ([`MechanismOde::user_sigma`]), and the alternative charts' the point in `ws` for theirs
    /// (`AltCharts::best`); a copy of the workspace's frame, made at the first such measure.
    measure_frame: Option<Frame>,
    /// Whether the last accepted point is clear of folds ([`CLOSED_FORM_SIGMA`]).
    clear_of_folds: bool,
    /// The chart's own measure at the last accepted point (`limit_correction`), which the
    /// dense-output stages must keep within [`DENSE_SIGMA_FRACTION`] of.
    own_sigma: f64,
    /// The evaluation not in use, of the current chart: the step's end while its outputs are
    /// evaluated ([`MechanismOde::set_aside`]), their scratch otherwise.
    spare: Evaluation,
}

impl<'a> MechanismOde<'a> {
    /// A system whose workspace `ws` holds a converged, analysed point of chart `ws.chart`.
    pub fn new(mech: &'a Mechanism, ws: Workspace, drives: &'a mut dyn Drives) -> Self {
        Self::from_parts(mech, ws, drives, ClosedForm::new(mech), System::new(mech), Default::default())
    }

    /// As [`MechanismOde::new`], given what it derives from the model alone: `closed`, the
    /// model's `ClosedForm::new`, and `inputs_sys`, its `System::new` (copies of a
    /// `simulate::Prepared`'s).
    pub fn from_parts(
        mech: &'a Mechanism,
        ws: Workspace,
        drives: &'a mut dyn Drives,
        mut closed: Option<ClosedForm>,
        inputs_sys: System,
        alt_shared: Arc<OnceLock<AltCharts>>,
    ) -> Self {
        let m = mech.dof();
        if let Some(c) = closed.as_mut() {
            c.set_reference(&ws.x);
        }
        let spare = Evaluation::unused(&ws, &closed);
        MechanismOde {
            motion: None,
            eval_y: vec![0.0; 2 * m + 1],
            anchor_x: ws.x.clone(),
            anchor_u: ws.u.clone(),
            anchor_u_zeros: 0,
            anchor_z: vec![0.0; m],
            last_t: f64::NAN,
            last_y: vec![f64::NAN; 2 * m + 1],
            base_valid: false,
            predicted: vec![0.0; ws.x.len()],
            walk_y: vec![0.0; 2 * m + 1],
            base: vec![0.0; ws.x.len()],
            max_correction: MAX_CORRECTION,
            max_move: f64::INFINITY,
            max_approach: f64::INFINITY,
            failed_evaluations: 0,
            inputs_sys,
            user_closed: None,
            alt_shared,
            alt: None,
            measure_frame: None,
            closed,
            base_closed: false,
            stale_j: false,
            clear_of_folds: true,
            own_sigma: 0.0,
            spare,
            mech,
            ws: Box::new(ws),
            drives,
        }
    }

    /// The same system with the coordinates of `motion` driven by it.
    pub fn with_motion(self, motion: &'a mut Prescribed<'a>) -> Self {
        MechanismOde { motion: Some(motion).filter(|p| !p.is_empty()), ..self }
    }

    pub fn m(&self) -> usize {
        self.mech.dof()
    }

    /// Body coordinates at the last accepted point.
    pub fn anchor_x(&self) -> &[f64] {
        &self.anchor_x
    }

    /// Make (t, y) the Newton predictor's anchor, evaluating there unless `ws` already holds
    /// that point (the FSAL stage of an explicit pair usually does).
    pub fn accept(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        if t != self.last_t || y != self.last_y.as_slice() {
            self.evaluate(t, y)?;
        }
        self.anchor_x.copy_from_slice(&self.ws.x);
        self.copy_anchor_u();
        let m = self.m();
        self.anchor_z.copy_from_slice(&y[..m]);
        // The spare evaluates the outputs of the next step, from this point's branches (a copy
        // of the same closed forms: their references copied, not taken from x again).
        if let Some(c) = self.closed.as_mut() {
            c.set_reference(&self.ws.x);
        }
        if let (Some(spare), Some(c)) = (self.spare.closed.as_mut(), self.closed.as_ref()) {
            spare.copy_reference(c);
        }
        Ok(())
    }

    /// `anchor_u` = U of the point in `ws`. Both are zero outside the supports of the zero
    /// pattern they were last cleared for (`Frame::u_zeros_for`, the position solve's or the
    /// closed form's): with the same pattern, only its supports are copied, at the cost of the
    /// reaches instead of 3n x m (1.8 MB a step on the ladder of 80 five-bar loops). Closed
    /// forms that write U whole (a few coordinates) keep no pattern: U is copied whole.
    fn copy_anchor_u(&mut self) {
        let (id, n) = (self.ws.u_zeros_for, self.ws.x.len());
        let whole = self.closed.as_ref().is_some_and(ClosedForm::writes_u_whole);
        let support = if whole || id == 0 || id != self.anchor_u_zeros {
            None
        } else if id == self.ws.sys.supports_id() {
            Some(self.ws.sys.u_support())
        } else {
            self.closed.as_ref().and_then(|c| c.u_support_for(id))
        };
        match support {
            Some(s) => s.copy_columns(n, &self.ws.u, &mut self.anchor_u),
            None => {
                self.anchor_u.copy_from_slice(&self.ws.u);
                self.anchor_u_zeros = id;
            }
        }
    }

    /// Bound the Newton correction by the chart's smallest scaled singular value `sigma` at
    /// the last accepted point. Near a fold of F(x; z) = 0 (a type II singularity of the
    /// user's coordinates) the other assembly branch is only about 2 sigma away (scaled F''
    /// is O(1)), and Newton from a predictor past half-way lands on it with a correction well
    /// under MAX_CORRECTION: the five-bar of the benchmarks, DOPRI5 at rtol 1e-4, jumped
    /// branch with a 0.047 correction at sigma ~ 0.06 and lost 6e-3 J, ending 4 rad off.
    /// A quarter of the separation keeps the start inside its own basin. Below
    /// [`CLOSED_FORM_SIGMA`] the evaluations also leave the closed forms for Newton.
    pub fn limit_correction(&mut self, sigma: f64) {
        self.max_correction = MAX_CORRECTION.min(BASIN_FRACTION * sigma);
        self.own_sigma = sigma;
        self.clear_of_folds = sigma >= CLOSED_FORM_SIGMA;
        self.max_move = MOVE_FRACTION * sigma;
        self.max_approach = f64::INFINITY;
    }

    /// Bound the move of a step's solutions from the last accepted point by [`STEP_REACH`]
    /// times the chart's measure there (given to [`MechanismOde::limit_correction`]), for the
    /// run's steps: a crossing's integration past its landing (`crossing::integrate_past`)
    /// steps on from the landing without accepting, and keeps its own bounds.
    pub fn limit_step_reach(&mut self) {
        self.max_approach = self.max_approach.min(STEP_REACH * self.own_sigma);
    }

    /// The longest next step whose solutions stay within the step's reach
    /// (`limit_step_reach`) at the body rates of the point in `ws` (the last accepted one),
    /// by [`REACH_STEP_FRACTION`] (s; infinite at rest or without a reach).
    pub fn reach_step_bound(&self) -> f64 {
        let rate = self.scaled_body_rate();
        if rate > 0.0 {
            REACH_STEP_FRACTION * self.max_approach / rate
        } else {
            f64::INFINITY
        }
    }

    /// The chart's own measure at the last accepted point (given to `limit_correction`).
    pub fn chart_measure(&self) -> f64 {
        self.own_sigma
    }

    /// The largest body rate of the point in `ws`, each scaled by its group's length (1/s),
    /// as the Newton bounds' distances are (`limit_correction`).
    pub fn scaled_body_rate(&self) -> f64 {
        let ws = &self.ws;
        ws.xd.iter().zip(ws.sys.group_col_scale()).fold(0.0_f64, |r, (v, s)| r.max(v.abs() / s))
    }

    /// Bound the move of a solution from the point it was predicted from by `max` as well
    /// (scaled, as [`MechanismOde::limit_correction`]'s), and from the last accepted point by
    /// `2 max`, whatever the stages between: a step's stages are each predicted from the one
    /// before, and bounding only those moves let a step of DOP853 (whose stages advance by up
    /// to a third of it) go past a change point (A02 at N = 2).
    /// Near a change point the evaluations take the Newton path (see [`CLOSED_FORM_SIGMA`]).
    pub fn limit_move(&mut self, max: f64) {
        self.max_move = self.max_move.min(max);
        self.max_approach = self.max_approach.min(2.0 * max);
        self.clear_of_folds = false;
    }

    /// Whether evaluations take the closed forms: there are some, in the user's chart, clear
    /// of folds, with no coordinate driven by a prescribed motion.
    fn closed_form_in_use(&self) -> bool {
        self.closed.is_some()
            && !matches!(self.ws.chart, Chart::Partition(_))
            && self.clear_of_folds
            && self.motion.is_none()
    }

    /// Factorise J at the point in `ws` if a closed-form evaluation left it behind (for the
    /// monitor's type II measure). A singular J stays unfactorised, and the monitor then takes
    /// the exact measure, which finds the singularity.
    fn factor_stale_j(&mut self) {
        if self.stale_j {
            self.stale_j = false;
            let ws = &mut self.ws;
            let _singular = ws.frame.sys.factor(self.mech, &ws.frame.chart, &ws.frame.x, &ws.frame.trig);
        }
    }

    /// The type II measure of the point in `ws` from the closed forms, if it was evaluated with
    /// them (J is then not factorised there).
    fn closed_form_sigma(&self) -> Option<f64> {
        let own_chart = !matches!(self.ws.chart, Chart::Partition(_));
        self.closed.as_ref().filter(|_| self.stale_j && own_chart).map(ClosedForm::sigma)
    }

    /// The current chart's own measure at the point in `ws` (in the user's chart its type II
    /// measure): from the closed forms where they gave the point (`ClosedForm::sigma`), else
    /// from the factorisation already in the workspace (inverse iteration, see
    /// `System::sigma_min_estimate`), else exact (an SVD of each block).
    pub fn own_sigma(&mut self) -> f64 {
        let estimate = self.closed_form_sigma().or_else(|| {
            self.factor_stale_j();
            self.ws.sys.sigma_min_estimate()
        });
        estimate.unwrap_or_else(|| match self.ws.chart {
            Chart::Inputs => sigma_min_with(&mut self.inputs_sys, self.mech, &Chart::Inputs, &self.ws.x),
            Chart::Partition(_) | Chart::Pairs(_) => sigma_min(self.mech, &self.ws.chart, &self.ws.x),
        })
    }

    /// The alternative chart of largest own measure at the point in `ws`, and that measure
    /// (`AltCharts::best`); the charts are analysed at the first call of any run of the model.
    pub fn best_alt_chart(&mut self) -> Option<(Chart, f64)> {
        let mech = self.mech;
        let alt = self.alt.get_or_insert_with(|| self.alt_shared.get_or_init(|| AltCharts::new(mech)).clone());
        let frame = self.measure_frame.get_or_insert_with(|| self.ws.frame.clone());
        alt.best(mech, &self.ws.x, frame)
    }

    /// The user's chart's type II measure at the point in `ws` (held in another chart): from its
    /// closed forms, which place the point at its q on its own branches (the same blocks'
    /// smallest singular values as the exact measure's SVDs, to round-off, at a few hundred
    /// instructions for an SVD's tens of thousands), else exact.
    pub fn user_sigma(&mut self) -> f64 {
        if let Some(c) = self.user_closed.as_mut() {
            let frame = self.measure_frame.get_or_insert_with(|| self.ws.frame.clone());
            c.set_reference(&self.ws.x);
            if c.positions(&self.ws.q, frame).is_ok() {
                return c.sigma();
            }
        }
        sigma_min_with(&mut self.inputs_sys, self.mech, &Chart::Inputs, &self.ws.x)
    }

    /// Predict the next evaluation from the last accepted point, not the last evaluation.
    pub fn restart_from_anchor(&mut self) {
        self.base_valid = false;
        self.last_t = f64::NAN;
    }

    /// Change to `chart`, in which the point held by `ws` has state `y`; then evaluates
    /// there and anchors the predictor to it.
    pub fn set_chart(&mut self, chart: Chart, t: f64, y: &[f64]) -> Result<(), Error> {
        let user = if matches!(self.ws.chart, Chart::Pairs(_)) { self.user_closed.take() } else { self.closed.take() };
        match &chart {
            Chart::Pairs(idx) => {
                self.closed = self.alt.as_ref().and_then(|a| a.closed_form(idx)).cloned();
                self.user_closed = user;
            }
            Chart::Inputs | Chart::Partition(_) => self.closed = user,
        }
        self.ws.chart = chart;
        // The first point of a chart takes the Newton path, which analyses the chart's
        // structure (the supports of U that the closed forms' dynamic stages use).
        self.clear_of_folds = false;
        self.anchor_x.copy_from_slice(&self.ws.x);
        if let Some(c) = self.closed.as_mut() {
            // A partition may have carried a dyad through its fold onto its other branch.
            c.set_reference(&self.ws.x);
        }
        let m = self.m();
        self.anchor_z.copy_from_slice(&y[..m]);
        self.last_t = f64::NAN;
        self.base_valid = false;
        // The spare's closed forms are still the old chart's (another alternative chart's may have
        // other groups): `accept` must not copy references into them; `save` renews the spare.
        self.spare.closed = None;
        self.accept(t, y)?;
        // The spare's chart and its structure (`System`'s analysis, which the predictor from
        // the anchor uses before Newton renews it) are the new chart's: a copy, once a switch.
        self.save_to_spare();
        Ok(())
    }

    /// Newton's start for chart values z: a second-order prediction
    /// x + U dz + 1/2 w(dz, dz) from the last evaluation when it succeeded (its x, U and
    /// factorised J are still in `ws`; w(dz, dz) costs one solve, or the closed forms'
    /// accelerations for the rates U dz), else a first-order one from the last accepted point.
    /// Both start from converged points of the same branch. With `fold_guard_only` (the
    /// closed forms will place the point: the prediction is only their fold guard's, see
    /// [`MechanismOde::evaluate_at`]), one coordinate and a closed-form last evaluation (at
    /// `last_y`: no prescribed motion) at a rate zd != 0, w(dz, dz) is (dz / zd)^2 c from
    /// that evaluation's convective term c = w(zd, zd) (w is a quadratic form: at m = 1,
    /// w(dz, dz) = dz^2 w_11), the same to round-off without a pass of the accelerations (over
    /// the tests' integrations the two differ by 7e-15 at most and no decision of the guard
    /// differs); [`MechanismOde::second_order`] makes it exactly if Newton takes over.
    /// At m >= 2 w(dz, dz) has no such form from c. Measured and left out (s17-guard): w from
    /// the last accepted point's m(m+1)/2 columns w(u_j, u_l), made at `accept`, with the last
    /// evaluation's x and U (five-bar 4460 -> 4167 instructions an evaluation, before the three
    /// accelerations passes a step). The shipped models' runs kept their bits, but over the
    /// 58236 such predictions of `tests/{change_points,events,simulation,dense_output,step_reach}.rs`
    /// 26 decisions differed: 14 corrections within their bound that the exact prediction puts
    /// over it, and 12 side tests kept where the exact prediction has crossed a fold (the
    /// anchor's w, a step away, misses the curvature that grows towards the fold).
    ///
    /// Inlined into `evaluate`, the other predictions in calls of their own: the one-coordinate
    /// fold guard's is then a call from `evaluate` (four-bar: 16 fewer instructions an evaluation).
    #[inline(always)]
    fn predict(&mut self, z: &[f64], fold_guard_only: bool) -> Prediction {
        let ws = &mut self.ws;
        if !self.base_valid {
            self.first_order(z);
            return Prediction::Complete;
        }
        if let ([z], [z_last, zd, _]) = (z, self.last_y.as_slice()) {
            if fold_guard_only && self.base_closed && zd.abs() >= MIN_RATE {
                let dz = z - z_last;
                let r = dz / zd;
                fold_guard_prediction(&mut ws.frame.x, &self.base, (&ws.frame.u, dz), (&ws.frame.c, 0.5 * r * r));
                return Prediction::FoldGuard;
            }
        }
        self.second_order(z);
        Prediction::Complete
    }

    /// x + U dz into `ws.x` from the last accepted point.
    #[inline(never)]
    fn first_order(&mut self, z: &[f64]) {
        let (anchor, x) = (&self.anchor_z, &self.anchor_x);
        let ws = &mut self.ws.frame;
        u_times_from(&self.anchor_u, ws.sys.u_support(), |j| z[j] - anchor[j], |i, _| x[i], &mut ws.x);
    }

    /// x + U dz + 1/2 w(dz, dz) into `ws.x`, x the last evaluation's (in `base`).
    #[inline(never)]
    fn second_order(&mut self, z: &[f64]) {
        let ws = &mut self.ws;
        let last = &self.last_y;
        let dz = |j: usize| z[j] - last[j];
        match z.len() {
            2 => rates_by_pairs::<2>(&ws.frame.u, std::array::from_fn(dz), &mut ws.frame.rhs),
            _ => u_times_from(&ws.frame.u, ws.frame.sys.u_support(), dz, |_, _| 0.0, &mut ws.frame.rhs),
        }
        // tmp = w(dz, dz) from the closed forms' accelerations where they gave the last
        // evaluation (their geometry is its), else -w(dz, dz) = J^-1 gamma(dz, dz) by J,
        // which Newton left factorised there.
        let half = match self.closed.as_ref().filter(|_| self.base_closed) {
            Some(c) => {
                c.accelerations(&ws.frame.rhs, &mut ws.frame.tmp);
                0.5
            }
            None => {
                gamma(
                    self.mech,
                    &ws.frame.chart,
                    &self.base,
                    &ws.frame.trig,
                    &ws.frame.rhs,
                    &ws.frame.rhs,
                    &mut ws.frame.tmp,
                );
                ws.frame.sys.solve(&mut ws.frame.tmp);
                -0.5
            }
        };
        for (((x, b), d), w) in ws.frame.x.iter_mut().zip(&self.base).zip(&ws.frame.rhs).zip(&ws.frame.tmp) {
            *x = b + (d + half * w);
        }
    }

    /// Forward dynamics at (t, y). A large Newton correction from the prediction fails the
    /// evaluation (the integrator then takes a shorter step), so a long step cannot carry
    /// the mechanism onto another assembly branch, however close it is (`limit_correction`).
    /// In closed form the solution is that of the last accepted point's branches, and the same
    /// bounds refuse a step along which the predictor fails (near a fold, where the passive
    /// motion may leave that branch): the integrator then shortens it, and the monitor moves
    /// to a partition once an accepted point is close enough.
    pub fn evaluate(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        // Without a prescribed motion the state evaluated is y itself, `last_y` once it succeeds.
        let outcome = if self.motion.is_some() { self.evaluate_prescribed(t, y) } else { self.evaluate_at(t, y) };
        if outcome.is_err() {
            self.failed_evaluations += 1;
        }
        outcome?;
        self.base_valid = true;
        self.last_t = t;
        copy_small(&mut self.last_y, y);
        Ok(())
    }

    /// [`MechanismOde::evaluate_at`] with the prescribed motion at t: the state evaluated,
    /// `eval_y`, is y with (in the user's chart) the prescribed coordinates and rates replaced
    /// by their motion's.
    #[inline(never)]
    fn evaluate_prescribed(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        let mut z = std::mem::take(&mut self.eval_y);
        copy_small(&mut z, y);
        let (m, inputs) = (self.m(), self.ws.chart == Chart::Inputs);
        let outcome = self.motion.as_deref_mut().map_or(Ok(()), |motion| {
            motion.eval(t).map_err(|message| Error::Drive { t, message })?;
            if inputs {
                motion.overwrite(m, &mut z);
            }
            Ok(())
        });
        let outcome = outcome.and_then(|()| self.evaluate_at(t, &z));
        self.eval_y = z;
        outcome
    }

    /// The body of [`MechanismOde::evaluate`] at state `y` (prescribed coordinates replaced).
    /// Inlined into both callers: a call of its own cost the four-bar 11 instructions an
    /// evaluation.
    #[inline(always)]
    fn evaluate_at(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        let m = self.m();
        let (z, zd) = (&y[..m], &y[m..2 * m]);
        // The point predicted from, into `base`: the last evaluation's x by a swap (the
        // prediction then writes `ws.x` whole), else the anchor's by a copy.
        if self.base_valid {
            std::mem::swap(&mut self.base, &mut self.ws.frame.x);
        } else {
            self.base.copy_from_slice(&self.anchor_x);
        }
        // A predictor past a dyad's fold means the motion leaves the closed forms' branch
        // there: Newton from the predictor follows it. The closed forms place the point from z
        // alone, so where they are in use the prediction is only this fold guard's (and the
        // base of the correction's bound): see `FoldGuard`.
        let closed = self.closed_form_in_use();
        let prediction = self.predict(z, closed);
        let newton = !closed || !self.closed.as_ref().is_some_and(|c| c.keeps_branches(&self.ws.x));
        if newton && prediction == Prediction::FoldGuard {
            self.second_order(z);
        }
        // Kept for the correction's bound: moved by a swap where the closed forms then write
        // every body's x without reading it (no triad, whose Newton starts from it).
        if !newton && self.closed.as_ref().is_some_and(ClosedForm::is_explicit) {
            std::mem::swap(&mut self.predicted, &mut self.ws.frame.x);
        } else {
            self.predicted.copy_from_slice(&self.ws.x);
        }
        self.last_t = f64::NAN;
        self.base_valid = false;
        // The pairs' friction needs the reactions, solved with J at this point.
        let reactions = !self.mech.friction.is_empty();
        self.base_closed = !newton;
        self.stale_j = !newton && !reactions;
        let mut outcome = match (self.closed.as_mut().filter(|_| !newton), self.motion.as_deref_mut()) {
            (Some(c), _) => c.predicted_stages(z, zd, &mut self.ws).map_err(Error::from).and_then(|()| {
                let ws = &mut self.ws;
                if matches!(ws.frame.chart, Chart::Pairs(_)) {
                    users_coordinates(self.mech, &mut ws.frame);
                }
                if reactions {
                    let _singular = ws.frame.sys.factor(self.mech, &ws.frame.chart, &ws.frame.x, &ws.frame.trig);
                }
                dynamic_stages(self.mech, t, self.drives, ws)
            }),
            (_, None) => forward(self.mech, t, z, zd, self.drives, &mut self.ws),
            (_, Some(motion)) => forward_prescribed(self.mech, t, z, zd, self.drives, motion, &mut self.ws),
        };
        if outcome.is_ok() {
            let (x, scale) = (&self.ws.x, self.ws.sys.group_col_scale());
            let [correction, moved, approach] = if self.max_approach < f64::INFINITY {
                scaled_distances(x, [&self.predicted, &self.base, &self.anchor_x], scale)
            } else {
                let [correction, moved] = scaled_distances(x, [&self.predicted, &self.base], scale);
                [correction, moved, 0.0]
            };
            let residual = if moved > self.max_move { moved } else { correction };
            if moved > self.max_move || correction > self.max_correction || approach > self.max_approach {
                outcome = Err(KinematicsError::AssemblyFailed { residual, iterations: self.ws.iterations }.into());
            }
        }
        outcome
    }
}

/// x = b + (u dz + h c) entry by entry, the one-coordinate fold guard's prediction
/// ([`MechanismOde::predict`]). Not inlined: as a function's arguments the slices are known not
/// to overlap, so its vectorised loop needs no run-time check of that (four-bar -7
/// instructions an evaluation, Andrews' squeezer -8). The same call for `second_order`'s sum
/// cost the five-bar 11 and the 3-RRR 15 more: their larger frame pays for the call.
#[inline(never)]
fn fold_guard_prediction(x: &mut [f64], b: &[f64], (u, dz): (&[f64], f64), (c, h): (&[f64], f64)) {
    for (((x, b), u), c) in x.iter_mut().zip(b).zip(u).zip(c) {
        *x = b + (u * dz + h * c);
    }
}

/// v = U dz for M (a few) columns of U, as `u_times_from` makes it for a few columns (every
/// row, each entry's terms added in order from 0: the same bits), by pairs of entries: one
/// packed multiply and add a column and pair, with no scalar remainder loop of the vectorised
/// form (five-bar: 12 entries, 2 columns).
#[inline(always)]
fn rates_by_pairs<const M: usize>(u: &[f64], dz: [f64; M], v: &mut [f64]) {
    let n = v.len();
    let columns: [&[f64]; M] = std::array::from_fn(|j| &u[j * n..(j + 1) * n]);
    let pairs = columns.map(|c| c.as_chunks::<2>().0);
    let (v_pairs, v_last) = v.as_chunks_mut::<2>();
    for (k, p) in v_pairs.iter_mut().enumerate() {
        *p = pairs.iter().zip(dz).fold([0.0; 2], |s, (c, r)| [s[0] + c[k][0] * r, s[1] + c[k][1] * r]);
    }
    if let [l] = v_last {
        *l = columns.iter().zip(dz).fold(0.0, |s, (c, r)| s + c[n - 1] * r);
    }
}

/// How far [`MechanismOde::predict`] took Newton's start.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Prediction {
    /// As Newton starts from it.
    Complete,
    /// For the closed forms' fold guard only, from the convective term (see `predict`): the
    /// same prediction to round-off, not to the bit.
    FoldGuard,
}

/// The evaluation a [`MechanismOde`] holds (its workspace and what the next evaluation's
/// Newton start is predicted from), set aside while points off the integration are evaluated
/// ([`MechanismOde::set_aside`], [`MechanismOde::save`]).
pub struct Evaluation {
    ws: Box<Workspace>,
    eval_y: Vec<f64>,
    last_t: f64,
    last_y: Vec<f64>,
    base_valid: bool,
    closed: Option<ClosedForm>,
    base_closed: bool,
    stale_j: bool,
}

impl Evaluation {
    /// Buffers of the chart of `ws`, holding no evaluation.
    fn unused(ws: &Workspace, closed: &Option<ClosedForm>) -> Self {
        let n_y = 2 * ws.q.len() + 1;
        Evaluation {
            ws: Box::new(ws.clone()),
            eval_y: vec![0.0; n_y],
            last_t: f64::NAN,
            last_y: vec![f64::NAN; n_y],
            base_valid: false,
            closed: closed.clone(),
            base_closed: false,
            stale_j: false,
        }
    }
}

/// The user's q, qd of the point in `f` from its x, xd: in an alternative chart the closed forms
/// give q = z, the chart's own coordinates. Not inlined: in the closed-form branch of
/// [`MechanismOde::evaluate_at`] it made that branch a function of its own (+62 k instructions
/// on the four-bar's run, which never takes it).
#[inline(never)]
fn users_coordinates(mech: &Mechanism, f: &mut Frame) {
    coordinates(mech, &f.x, &mut f.q);
    coordinate_rates(mech, &f.x, &f.xd, &mut f.qd);
}

impl MechanismOde<'_> {
    /// Set the evaluation held now (a step's end) aside, evaluations then starting from the
    /// last accepted point in the spare buffers: a step's outputs (rows, dense output, events)
    /// leave the point the next step starts from as the stepper left it, to the bit, and
    /// [`MechanismOde::take_back`] returns it without evaluating it again. Re-evaluated, the
    /// step's end differed from the stepper's in its last bits (Newton started from another
    /// point), which changed the steps: the five-bar at DOP853 rtol 10^-7.4 took 102 steps with
    /// a 0.01 s grid, 101 without. A swap: no allocation.
    pub fn set_aside(&mut self) {
        self.swap_spare();
        self.restart_from_anchor();
    }

    /// Hold motor i's side of its at-rest band (`simulate::gear_sides`) in both evaluations'
    /// buffers: the outputs, evaluated in the spare, follow the law the steps do.
    pub fn hold_gear(&mut self, i: usize, band: Option<Band>) {
        self.ws.losses.gears_mut().hold(i, band);
        self.spare.ws.losses.gears_mut().hold(i, band);
    }

    /// Take back the evaluation set aside by [`MechanismOde::set_aside`].
    pub fn take_back(&mut self) {
        self.swap_spare();
    }

    fn swap_spare(&mut self) {
        let e = &mut self.spare;
        std::mem::swap(&mut self.ws, &mut e.ws);
        std::mem::swap(&mut self.eval_y, &mut e.eval_y);
        std::mem::swap(&mut self.last_t, &mut e.last_t);
        std::mem::swap(&mut self.last_y, &mut e.last_y);
        std::mem::swap(&mut self.base_valid, &mut e.base_valid);
        std::mem::swap(&mut self.closed, &mut e.closed);
        std::mem::swap(&mut self.base_closed, &mut e.base_closed);
        std::mem::swap(&mut self.stale_j, &mut e.stale_j);
    }

    /// The evaluation held now, to be put back by [`MechanismOde::restore`]: evaluating other
    /// points between (the overshoot check's, `Run::overshot`) then leaves the integration as it
    /// would have been, to the bit.
    pub fn save(&self) -> Evaluation {
        Evaluation {
            ws: self.ws.clone(),
            eval_y: self.eval_y.clone(),
            last_t: self.last_t,
            last_y: self.last_y.clone(),
            base_valid: self.base_valid,
            closed: self.closed.clone(),
            base_closed: self.base_closed,
            stale_j: self.stale_j,
        }
    }

    /// [`MechanismOde::save`] into the spare's buffers (`clone_from`: the old spare's
    /// allocations reused, 0.18 M instructions of the five-bar free fall's 11 switches). The
    /// pattern names every field, so one added to [`Evaluation`] but not here does not compile.
    fn save_to_spare(&mut self) {
        let Evaluation { ws, eval_y, last_t, last_y, base_valid, closed, base_closed, stale_j } = &mut self.spare;
        ws.clone_from(&self.ws);
        eval_y.clone_from(&self.eval_y);
        last_y.clone_from(&self.last_y);
        closed.clone_from(&self.closed);
        (*last_t, *base_valid, *base_closed, *stale_j) = (self.last_t, self.base_valid, self.base_closed, self.stale_j);
    }

    /// Put back an evaluation saved by [`MechanismOde::save`].
    pub fn restore(&mut self, e: Evaluation) {
        (self.ws, self.eval_y, self.last_t, self.last_y) = (e.ws, e.eval_y, e.last_t, e.last_y);
        (self.base_valid, self.closed, self.base_closed, self.stale_j) =
            (e.base_valid, e.closed, e.base_closed, e.stale_j);
    }

    /// As [`MechanismOde::evaluate`], for a point that must be evaluated (an output, a dense
    /// output stage) rather than avoided by a shorter step: when refused, walk to it from the
    /// last accepted point in straight pieces of the chart coordinates (4, then 16, then 64),
    /// each a short move on the branch, as continuation does.
    pub fn evaluate_walking(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        let Err(mut error) = self.evaluate(t, y) else { return Ok(()) };
        let m = self.m();
        let mut walk = std::mem::take(&mut self.walk_y);
        walk.copy_from_slice(y);
        for pieces in [4, 16, 64] {
            self.restart_from_anchor();
            // The pieces before the last; the last is y itself, exactly.
            let walked = (1..pieces).try_for_each(|k| {
                let f = k as f64 / pieces as f64;
                for j in 0..m {
                    walk[j] = self.anchor_z[j] + (y[j] - self.anchor_z[j]) * f;
                }
                self.evaluate(t, &walk)
            });
            match walked.and_then(|()| self.evaluate(t, y)) {
                Ok(()) => {
                    self.walk_y = walk;
                    return Ok(());
                }
                Err(e) => error = e,
            }
        }
        self.walk_y = walk;
        Err(error)
    }

    /// The state of the evaluation held in `ws` (a successful one).
    fn evaluated_y(&self) -> &[f64] {
        if self.motion.is_some() {
            &self.eval_y
        } else {
            &self.last_y
        }
    }

    /// dy = [zd, zdd, P] from the evaluation held in `ws` ([`Self::evaluated_y`]). For a few
    /// coordinates each arm's m is a constant, so the copies are moves of a known size: no
    /// dispatch on the size per copy, and no library call whose registers the function would
    /// save (four-bar: 55 -> 34 instructions an evaluation); more take [`Self::derivative_of`]'s
    /// own call.
    fn derivative(&self, dy: &mut [f64]) {
        let y = self.evaluated_y();
        match self.m() {
            1 => self.copy_derivative(1, y, dy),
            2 => self.copy_derivative(2, y, dy),
            3 => self.copy_derivative(3, y, dy),
            4 => self.copy_derivative(4, y, dy),
            m => self.derivative_of(m, y, dy),
        }
    }

    #[inline(never)]
    fn derivative_of(&self, m: usize, y: &[f64], dy: &mut [f64]) {
        self.copy_derivative(m, y, dy);
    }

    #[inline(always)]
    fn copy_derivative(&self, m: usize, y: &[f64], dy: &mut [f64]) {
        let dy = &mut dy[..2 * m + 1];
        copy_small(&mut dy[..m], &y[m..2 * m]);
        copy_small(&mut dy[m..2 * m], &self.ws.zdd);
        dy[2 * m] = self.ws.power;
    }
}

impl OdeSystem for MechanismOde<'_> {
    type Error = Error;
    fn dim(&self) -> usize {
        2 * self.m() + 1
    }
    /// f at (t, y), reusing the evaluation `ws` holds if it is of that point: a chart switch
    /// evaluates its point to anchor the predictor there (`set_chart`), and the stepper's reset
    /// then asks for it again (once a switch: 11 of the five-bar's 1152 evaluations in 1 s).
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        if !(self.base_valid && t == self.last_t && y == self.last_y.as_slice()) {
            self.evaluate(t, y)?;
        }
        self.derivative(dy);
        Ok(())
    }
    /// A dense-output stage, walked to if need be, and refused where the chart is much nearer
    /// its singularity than at the step's start ([`DENSE_SIGMA_FRACTION`]).
    fn rhs_dense(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.evaluate_walking(t, y)?;
        let sigma = self.own_sigma();
        if sigma < DENSE_SIGMA_FRACTION * self.own_sigma {
            self.failed_evaluations += 1;
            self.restart_from_anchor();
            let kind = SingularityKind::TypeII;
            return Err(KinematicsError::Singular { kind, sigma_min: Some(sigma) }.into());
        }
        self.derivative(dy);
        Ok(())
    }
    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut [f64]) -> Option<Result<(), Error>> {
        // The exact Jacobian is written for ideal joints and drives (dynamics::derivatives).
        let exact = self.ws.chart == Chart::Inputs
            && self.motion.is_none()
            && self.drives.time_only()
            && !self.mech.has_losses();
        exact.then(|| super::jacobian::exact_jacobian(self.mech, &self.ws, self.drives, t, y, jac))
    }
}

#[cfg(test)]
mod tests {
    /// `MIN_RATE` is written as a literal (no const sqrt in stable Rust); it must be the square
    /// root of the smallest normal f64 that its comment names.
    #[test]
    fn min_rate_is_the_square_root_of_the_smallest_normal() {
        assert_eq!(super::MIN_RATE, f64::MIN_POSITIVE.sqrt());
    }
}
