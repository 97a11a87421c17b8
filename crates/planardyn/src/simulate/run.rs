//! One run of a simulation as named stages, in the order of MuJoCo's `mj_step`: integrate a
//! step, observe it (dense output, events), write the outputs it passed, accept its end, then
//! the change points, the energy, the passive measure, the rate of progress, the chart and the
//! caller's progress callback. Each stage returns `ControlFlow<Stop>`; [`Stop`] says why the
//! run ended and is turned into the trajectory's status and message once, in `stop.rs`.

use std::ops::ControlFlow::{self, Break, Continue};

use super::charts::{
    chart_sigma, first_step_bound, measure, next_chart, state_in, FallWatch, Measures, NEAR_PASSIVE_SINGULAR,
    PASSIVE_SINGULAR, SWITCH_TO_PARTITION,
};
use super::crossing::{
    cross, inside_step, scaled_speed, stepped_over, user_state, Approach, Bridge, ChangePoint, Grid, Integration, Path,
    APPROACH_BELOW, APPROACH_FRACTION, CHANGE_POINT_RATIO, CROSS_START, WATCH_BELOW,
};
use super::dense::{self, DenseOutput};
use super::events::Watch;
use super::fold_watch::FoldWatch;
use super::gear_sides::GearSides;
use super::ode::MechanismOde;
use super::prepared::Prepared;
use super::start;
use super::stop::{Near, Stop, PROGRESS_MARGIN};
use super::trajectory::Trajectory;
use super::{Observe, Settings};
use crate::dynamics::{prescribed_sigma_min, Drives, Prescribed};
use crate::integrate::{Options, Stats, Stepper};
use crate::kinematics::{passive_sigma_min, Chart};
use crate::model::Mechanism;
use crate::Error;

/// Step attempts before a run's rate of progress is judged: an early transient of small
/// steps (a stiff start, a chart switch) must not stop a run that would finish.
const PROGRESS_MIN_STEPS: usize = 10_000;

/// Below this chart measure, falling, the next step is also bounded by the predictive
/// controller (`Stepper::predict_next_step`): the equations of motion vary like 1/sigma^2
/// near the chart's singularity, and the five-bar's error-test rejections sit there (user
/// chart 0.18 -> 0.05). Not above: far from one, as the driven slider-crank of docs/api.md
/// (least measure 0.47), it only moved the steps (53 -> 54) and the energy balance with them,
/// 9.2e-9 -> 1.4e-8 J over the page's 1e-8.
const PREDICT_BELOW: f64 = 0.25;

/// The progress callback: called with t after each accepted step, false stops the run.
pub type Progress<'p> = Option<&'p mut dyn FnMut(f64) -> bool>;

/// What a crossing did: landed past the change point, reached t_end inside it, met terminal
/// event `index` at `t` inside it, or found none (the passive measure only dipped).
enum Crossed {
    Past,
    AtEnd,
    Event { t: f64, index: usize },
    NoPoint,
}

/// Whether the measure heading to 0 above [`APPROACH_BELOW`] is the passive one
/// ([`Run::change_point_ahead`]): not asked in this approach, put off, or known. Put off, it
/// keeps the point it is to be asked at (passive measure and body coordinates x), and whether
/// the last aim's grid and limit hold only if it is (`on`: that aim could not answer it).
#[derive(Debug, Clone, PartialEq)]
enum Heading {
    Unasked,
    Deferred { passive: f64, x: Vec<f64>, on: bool },
    Known(bool),
}

/// A run: the mechanism in its chart, the integrator, the trajectory written so far, and what
/// the stages keep between steps.
pub struct Run<'a, 's, 'e> {
    settings: &'s Settings,
    prepared: &'s Prepared,
    ode: MechanismOde<'a>,
    stepper: Stepper,
    traj: Trajectory,
    /// The output grid, and the index of the next output time in it.
    t_eval: Option<&'s [f64]>,
    next: usize,
    /// The accepted points near a change point, and the energy balance across it; where the
    /// next step must end at the latest (t_end, or before a change point ahead).
    approach: Approach,
    t_stop: f64,
    grid: Option<Grid>,
    limit: Option<f64>,
    /// Whether the measure now heading to 0 is the passive one (asked once an approach, where
    /// first needed: [`Heading`]).
    heading: Heading,
    /// The integrator's options without dense output (for a crossing's integration past its
    /// landing), and the counters of those integrations.
    options: Options,
    crossing_stats: Stats,
    /// (2m + 1) The state accepted last, and an interpolated one.
    y: Vec<f64>,
    yi: Vec<f64>,
    /// The dense output (for the events and the kept interpolant), and one step's rows of it.
    dense: Option<DenseOutput>,
    rows: Vec<f64>,
    watch: Watch<'e>,
    keep_dense: bool,
    /// The chart's own measure at the last accepted point, while in the same chart.
    last_own: Option<f64>,
    /// The user's chart's type II falls, for the bound on the steps into them.
    fall: FallWatch,
    /// Steps accepted since the last chart switch.
    chart_steps: usize,
    /// The driven coordinates' measure at the last accepted points, near their singularity.
    fold: FoldWatch,
    /// The gears' switches of side of their at-rest bands, located inside steps.
    gear_sides: GearSides,
}

impl<'a, 's, 'e> Run<'a, 's, 'e> {
    /// The run at t0, its start row written; `Break` if it stopped before its first step (a
    /// drive or the integrator failing at the start). Errors in the start itself return Err.
    pub fn start(
        mech: &'a Mechanism,
        prepared: &'s Prepared,
        settings: &'s Settings,
        drives: &'a mut dyn Drives,
        motion: &'a mut Prescribed<'a>,
        observe: Observe<'e>,
    ) -> Result<ControlFlow<Stop, Self>, Error> {
        let (mut ode, y) = match start::start(mech, prepared, settings, drives, motion) {
            Ok(started) => started,
            // A drive that fails at once is a failed run, not bad input: say so in the status.
            Err(e @ Error::Drive { .. }) => return Ok(Break(Stop::StartDrive(e))),
            Err(e) => return Err(e),
        };
        let m = mech.dof();
        // Dense output is only needed to interpolate at requested times, and for events and the
        // kept interpolant (DOP853 pays 3 extra evaluations in each step that uses it).
        let (observing, keep_dense) = (!observe.is_empty(), observe.dense_output);
        // DOP853 evaluates them only when a step is interpolated (outputs, events, a crossing's
        // nodes): a step without pays nothing.
        let options = Options { dense_output: true, ..settings.options.clone() };
        let mut stepper = Stepper::new(settings.method, &options, 2 * m + 1).map_err(Error::Options)?;
        GearSides::hold_all(&mut ode);
        if let Err(error) = stepper.reset(&mut ode, settings.t0, &y) {
            return Ok(Break(Stop::Step { error, crossing: None }));
        }
        let mut run = Run {
            settings,
            prepared,
            ode,
            stepper,
            traj: Trajectory::with_rows(m, mech.n_x(), settings.t_eval.as_ref().map_or(0, Vec::len)),
            t_eval: settings.t_eval.as_deref(),
            next: 0,
            approach: Approach::default(),
            t_stop: settings.t_end,
            grid: None,
            limit: None,
            heading: Heading::Unasked,
            options: Options { dense_output: false, ..settings.options.clone() },
            crossing_stats: Stats::default(),
            y,
            yi: vec![0.0; 2 * m + 1],
            dense: observing.then(|| DenseOutput::new(m, settings.method.dense_order())),
            rows: Vec::new(),
            watch: Watch::new(observe.events, m),
            keep_dense,
            last_own: None,
            fall: FallWatch::new(settings.method),
            chart_steps: 0,
            fold: FoldWatch::default(),
            gear_sides: GearSides::default(),
        };
        // The start counts in the least measures, so that a run of no step reports its start's.
        let first = measure(&mut run.ode);
        (run.traj.stats.min_sigma, run.traj.stats.min_passive_sigma) = (first.sigma, first.passive);
        run.approach.keep(&run.ode, settings.t0, &first);
        if run.t_eval.is_none_or(|te| te.first() == Some(&settings.t0)) {
            run.traj.record(&run.ode, settings.t0, run.y[2 * m], first.sigma);
            run.next = 1;
        }
        Ok(Continue(run))
    }

    /// Step until t_end or a stop; the trajectory with its status.
    pub fn run(mut self, mut progress: Progress) -> Trajectory {
        let stop = match self.stages(&mut progress) {
            Break(stop) => stop,
            Continue(()) => Stop::Reached { t_end: self.settings.t_end },
        };
        self.finish(stop)
    }

    /// The driver: the events' start values, then one step after another.
    fn stages(&mut self, progress: &mut Progress) -> ControlFlow<Stop> {
        self.start_events()?;
        while self.stepper.t() < self.settings.t_end {
            self.step(progress)?;
        }
        Continue(())
    }

    /// One step, as `mj_step`: integrate, observe, output, accept; then what the accepted
    /// point asks for.
    fn step(&mut self, progress: &mut Progress) -> ControlFlow<Stop> {
        if let Err(error) = self.stepper.step(&mut self.ode, self.t_stop) {
            return self.cross_from_last(error);
        }
        let t = self.stepper.t();
        if self.overshot(t) {
            return self.retake();
        }
        match self.gear_sides.switch_in_step(&mut self.ode, &mut self.stepper, &self.y, &mut self.yi) {
            Ok(Some(t_switch)) => return self.retake_to(t_switch),
            Ok(None) => {}
            // Read on the step's interpolant: its failure is the dense output's.
            Err(error) => return Break(Stop::DenseOutput { t, error }),
        }
        self.y.copy_from_slice(self.stepper.y());
        self.chart_steps += 1;
        match self.ode.ws.chart {
            Chart::Inputs => {}
            Chart::Partition(_) => self.traj.stats.partition_steps += 1,
            Chart::Pairs(_) => self.traj.stats.alt_steps += 1,
        }
        // The step's end as the stepper evaluated it, kept from its outputs until `accept`.
        self.ode.set_aside();
        let terminal = self.observe(t)?;
        self.outputs(terminal.map_or(t, |(t_star, _)| t_star))?;
        if let Some((t_star, index)) = terminal {
            return self.end_at_event(t_star, index);
        }
        self.fill_approach(t)?;
        let meas = self.accept(t)?;
        if self.change_points(t, &meas)? {
            return Continue(());
        }
        self.approach.keep(&self.ode, t, &meas);
        self.passive(t, &meas)?;
        self.progress_rate()?;
        self.fold(t, &meas)?;
        self.chart(t, &meas)?;
        self.gears(t)?;
        self.aim(t, &meas);
        self.report(t, progress)
    }

    /// The events' values at the start.
    fn start_events(&mut self) -> ControlFlow<Stop> {
        let t = self.settings.t0;
        match self.watch.start(t, &self.ode.ws.q, &self.ode.ws.qd) {
            Ok(()) => Continue(()),
            Err(error) => Break(Stop::EventAtStart { t, error }),
        }
    }

    /// A failed step: steps that shrink to nothing before a change point cross it from the
    /// last accepted point when it is near enough; otherwise the run stops.
    fn cross_from_last(&mut self, error: crate::integrate::StepError<Error>) -> ControlFlow<Stop> {
        let (t, y) = (self.stepper.t(), self.stepper.y().to_vec());
        let m = self.ode.m();
        self.ode.restart_from_anchor();
        let ode = &mut self.ode;
        let at_last =
            ode.motion.is_none() && self.approach.last().is_some_and(|p| p.t == t) && ode.accept(t, &y).is_ok();
        let meas = if at_last { Some(measure(ode)) } else { None };
        let Some(meas) = meas.filter(|meas| meas.passive < NEAR_PASSIVE_SINGULAR) else {
            return Break(Stop::Step { error, crossing: None });
        };
        match self.cross_change_point((t, meas.sigma, meas.passive, y[2 * m])) {
            Ok(Crossed::Past) => Continue(()),
            Ok(Crossed::AtEnd) => Break(Stop::Reached { t_end: self.settings.t_end }),
            Ok(Crossed::Event { t, index }) => Break(Stop::TerminalEvent { index, t }),
            Ok(Crossed::NoPoint) => {
                let why = "Phi_x keeps its rank on the path ahead: no change point to cross".to_string();
                Break(Stop::Step { error, crossing: Some(why) })
            }
            Err(why) => Break(Stop::Step { error, crossing: Some(why) }),
        }
    }

    /// The step's dense output and its events; the first terminal event's time and index.
    fn observe(&mut self, t: f64) -> ControlFlow<Stop, Option<(f64, usize)>> {
        let Some(dense) = self.dense.as_mut() else { return Continue(None) };
        if let Err(error) = sample_step(&mut self.ode, &mut self.stepper, dense, &mut self.yi, &mut self.rows) {
            return Break(Stop::DenseOutput { t, error });
        }
        match self.watch.step(dense, self.stepper.t_prev()) {
            Ok(found) => Continue(found),
            Err(error) => Break(Stop::EventInStep { t, error }),
        }
    }

    /// The rows of the output grid up to `t_last` (the step's end, or a terminal event's time).
    fn outputs(&mut self, t_last: f64) -> ControlFlow<Stop> {
        let Some(te) = self.t_eval else { return Continue(()) };
        if self.next < te.len() && te[self.next] <= t_last {
            // DOP853's dense-output stages (at 0.1, 0.2 and 7/9 of the step, evaluated by
            // the first interpolation) are predicted from the step's start, not its end.
            self.ode.restart_from_anchor();
        }
        while self.next < te.len() && te[self.next] <= t_last {
            let t = te[self.next];
            if let Err(error) = evaluate_output(&mut self.ode, &mut self.stepper, t, &mut self.yi) {
                return Break(Stop::Output { t, error });
            }
            let sigma = measure(&mut self.ode).sigma;
            self.traj.record(&self.ode, t, self.yi[self.yi.len() - 1], sigma);
            self.next += 1;
        }
        Continue(())
    }

    /// The last row of a run ended by terminal event `index` at `t_star`, within the step just
    /// taken (unless the outputs already hold it).
    fn end_at_event(&mut self, t_star: f64, index: usize) -> ControlFlow<Stop> {
        if self.traj.t.last() != Some(&t_star) {
            self.ode.restart_from_anchor();
            if let Err(error) = evaluate_output(&mut self.ode, &mut self.stepper, t_star, &mut self.yi) {
                return Break(Stop::EventState { index, t: t_star, error });
            }
            let sigma = measure(&mut self.ode).sigma;
            self.traj.record(&self.ode, t_star, self.yi[self.yi.len() - 1], sigma);
        }
        if let Some(d) = self.dense.as_mut() {
            d.truncate(t_star);
        }
        Break(Stop::TerminalEvent { index, t: t_star })
    }

    /// Make the step's end the predictor's anchor and measure it; without a grid, its row.
    fn accept(&mut self, t: f64) -> ControlFlow<Stop, Measures> {
        self.ode.take_back();
        // The step's end is evaluated again only where the stepper's last evaluation was not
        // there; if that is refused, come back along the interpolant as the outputs do.
        let (ode, y) = (&mut self.ode, &self.y);
        let accepted = ode.accept(t, y).or_else(|e| {
            if self.t_eval.is_none() && self.dense.is_none() {
                return Err(e);
            }
            evaluate_output(ode, &mut self.stepper, t, &mut self.yi)?;
            ode.accept(t, y)
        });
        if let Err(error) = accepted {
            return Break(Stop::Accept { t, error });
        }
        let meas = measure(&mut self.ode);
        if self.t_eval.is_none() {
            self.traj.record(&self.ode, t, self.y[self.y.len() - 1], meas.sigma);
        }
        let stats = &mut self.traj.stats;
        stats.min_sigma = stats.min_sigma.min(meas.sigma);
        stats.min_passive_sigma = stats.min_passive_sigma.min(meas.passive);
        Continue(meas)
    }

    /// Cross the change point ahead, or record one the step went over. Continue(true): crossed,
    /// the stepper restarted past it (the step's other stages are skipped).
    fn change_points(&mut self, t: f64, meas: &Measures) -> ControlFlow<Stop, bool> {
        let falling = self.approach.last().is_some_and(|p| meas.passive < p.passive);
        let over = stepped_over(&self.ode, &self.approach, t, meas.passive);
        if over.is_none()
            && meas.passive < CROSS_START
            && falling
            && self.watched()
            && !self.before_crossing_start(t, meas)
        {
            let work = self.y[self.y.len() - 1];
            return match self.cross_change_point((t, meas.sigma, meas.passive, work)) {
                Ok(Crossed::Past) => Continue(true),
                Ok(Crossed::AtEnd) => Break(Stop::Reached { t_end: self.settings.t_end }),
                Ok(Crossed::Event { t, index }) => Break(Stop::TerminalEvent { index, t }),
                // A dip, not a change point: on with the step's other stages, unwatched.
                Ok(Crossed::NoPoint) => {
                    self.heading = Heading::Known(false);
                    Continue(false)
                }
                Err(why) => Break(Stop::NoCrossing { t, passive: meas.passive, why }),
            };
        }
        if let Some(point) = over {
            self.passed_point(point);
            // The points kept are on the other side of it.
            self.approach.clear();
        }
        Continue(false)
    }

    /// Whether the point accepted at t is still before the crossing's start by more than a
    /// quarter of the grid's spacing, as seen from it ([`Approach::grid`]): the next step then
    /// ends there ([`Approach::step_limit`]), and the crossing starts on its grid, its gap
    /// about twice the time from [`super::crossing::CROSS_BELOW`] to the point. Started at the
    /// first point below [`CROSS_START`], the gap was up to 30 % longer wherever a step ended
    /// short of the grid, and the rows inside it were the bridge's worst: the triple-crank
    /// parallelogram (tests/test_api.py, 0.3 s) at rtol 5e-10, 1.1e-9, 2e-9 drifted 4.6e-7 ...
    /// 6.5e-7 J at its last row, 5 ms before the point; with the crossing on its grid, at most
    /// 4.2e-9 J over 14 tolerances 5e-10 ... 1e-6.
    fn before_crossing_start(&self, t: f64, meas: &Measures) -> bool {
        self.approach.grid(t, meas).is_some_and(|g| t < g.t_star - g.tau - 0.25 * g.h)
    }

    /// Report a change point the run went through: in the trajectory's list, and in the least
    /// passive measure seen (the path passes through it, the accepted points do not).
    fn passed_point(&mut self, point: ChangePoint) {
        let (ode, prepared) = (&mut self.ode, self.prepared);
        let passive = prepared.passive_measure(&mut ode.inputs_sys, ode.mech, &point.x);
        let stats = &mut self.traj.stats;
        stats.min_passive_sigma = stats.min_passive_sigma.min(passive);
        self.traj.change_points.push(point);
    }

    /// Stop where the passive mechanism itself is singular.
    fn passive(&self, t: f64, meas: &Measures) -> ControlFlow<Stop> {
        if meas.passive < PASSIVE_SINGULAR {
            return Break(Stop::PassiveSingular { t, passive: meas.passive });
        }
        Continue(())
    }

    /// Stop a run that cannot reach t_end at its present rate: after [`PROGRESS_MIN_STEPS`]
    /// attempts, its mean step is below `(t_end - t0) / (PROGRESS_MARGIN max_steps)`. The steps
    /// of such runs shrink as they go (efforts of 1e12 N m on the five-bar: 10 million steps for
    /// 0.35 % of 1 s), so waiting for `max_steps` only wastes the work.
    fn progress_rate(&self) -> ControlFlow<Stop> {
        let stats = self.stepper.stats();
        let attempts = stats.naccept + stats.nreject;
        let (t0, t, t_end) = (self.settings.t0, self.stepper.t(), self.settings.t_end);
        let max_steps = self.settings.options.max_steps;
        let floor = (t_end - t0) / (PROGRESS_MARGIN * max_steps as f64);
        let mean = (t - t0) / attempts as f64;
        if attempts < PROGRESS_MIN_STEPS || mean >= floor {
            return Continue(());
        }
        let last = t - self.stepper.t_prev();
        Break(Stop::Hopeless { t, attempts, mean, last, floor, t_end, max_steps })
    }

    /// Stop a prescribed motion that runs into a fold of its driven coordinates, where their
    /// measure falls like sqrt(t* - t) and the steps shrink towards t* without passing it
    /// ([`FoldWatch`]). Measured only where the user's type II measure is below
    /// [`SWITCH_TO_PARTITION`]: the driven coordinates are some of the user's, so their measure
    /// is small only near a singularity of the user's chart.
    fn fold(&mut self, t: f64, meas: &Measures) -> ControlFlow<Stop> {
        let ode = &self.ode;
        let driven = match &ode.motion {
            Some(p) if meas.sigma < SWITCH_TO_PARTITION => prescribed_sigma_min(ode.mech, &p.p, ode.anchor_x()),
            _ => f64::INFINITY,
        };
        match self.fold.zeno(t, driven, t - self.stepper.t_prev()) {
            Some(t_star) => Break(Stop::Fold { t, t_star, driven }),
            None => Continue(()),
        }
    }

    /// Change the chart if the measures ask for it, and bound the next step's Newton moves by
    /// the chart's distance to its singularities (and to a change point being approached).
    fn chart(&mut self, t: f64, meas: &Measures) -> ControlFlow<Stop> {
        let m = self.ode.m();
        let mut own = chart_sigma(&mut self.ode, meas.sigma);
        if let Some((chart, known)) = next_chart(&mut self.ode, meas, own) {
            state_in(&self.ode, &chart, self.y[2 * m], &mut self.y);
            self.traj.stats.chart_switches += 1;
            let switched = self.ode.set_chart(chart, t, &self.y).map_err(|e| e.to_string());
            if let Err(error) =
                switched.and_then(|_| self.stepper.reset(&mut self.ode, t, &self.y).map_err(|e| e.to_string()))
            {
                return Break(Stop::ChartChange { t, error });
            }
            own = known.unwrap_or_else(|| chart_sigma(&mut self.ode, meas.sigma));
            self.stepper.bound_first_step(first_step_bound(&self.ode, own));
            self.chart_steps = 0;
        }
        self.ode.limit_correction(own);
        // In the user's chart the passive measure is only bounded by sigma_II (it is
        // measured in a partition, which the integrator takes below 0.05).
        if meas.passive < WATCH_BELOW && self.ode.motion.is_none() && self.ode.ws.chart != Chart::Inputs {
            self.ode.limit_move(APPROACH_FRACTION * meas.passive);
        }
        Continue(())
    }

    /// With a change point ahead, the crossing's grid before it ([`Approach::grid`]) and where
    /// the next step should end at the latest ([`Approach::step_limit`]): below
    /// [`APPROACH_BELOW`] the next step ends there, above only if it would otherwise end past
    /// the crossing's start ([`Run::retake`]). Elsewhere the step's reach is bounded by the
    /// chart's measure (`MechanismOde::limit_step_reach`), which guards a chart's fold; below
    /// [`APPROACH_BELOW`] with a change point ahead the measure is the change point's, which
    /// every chart shares and the motion's branch passes smoothly (the triple-crank
    /// parallelogram's mass matrix is constant through it), and the approach's grid bounds the
    /// steps instead. The reach there (2 x 0.8 x the passive measure, a quarter of the way to
    /// the point) cut the approach's steps off its grid, and the crossing started early
    /// (tests/test_api.py's redundant triple crank at rtol 1e-9: at passive 0.0324, its row at
    /// 0.3 s, 5 ms before the point, 4.9e-8 J off; 0.0256 and 2.5e-9 J without the reach).
    fn aim(&mut self, t: f64, meas: &Measures) {
        let grid = self.approach.grid(t, meas).filter(|_| self.ode.motion.is_none());
        if grid.is_none() {
            self.heading = Heading::Unasked;
        }
        let ahead = if grid.is_some() { self.change_point_ahead(meas) } else { Some(false) };
        if let Heading::Deferred { on, .. } = &mut self.heading {
            *on = ahead.is_none();
        }
        let ahead = ahead != Some(false);
        self.grid = grid.filter(|_| ahead);
        self.limit = self.approach.step_limit(t, meas).filter(|_| ahead).map(|l| l.min(self.settings.t_end));
        if self.limit.is_none() || meas.passive >= APPROACH_BELOW {
            self.ode.limit_step_reach();
            // Also in an approach above APPROACH_BELOW, where the grid does not bound the
            // steps: the five-bar's type II passages look like approaches there (passive
            // measure = type II measure), and without it the five-bar drifted 3.5e-4 J
            // (tests/step_reach.rs, target 1e-4). A02 (N = 40, rtol 1e-12) is 4.7e-10 rad
            // off the reduction with it, 1.2e-9 without (tests/change_points.rs: 1e-8).
            self.stepper.bound_next_step(self.ode.reach_step_bound());
        }
        // The chart's equations of motion vary like 1/sigma^2 near its singularity: while its
        // measure falls, so does the error constant grow from step to step.
        let own = self.ode.chart_measure();
        if own < PREDICT_BELOW && self.last_own.is_some_and(|last| own < last) {
            self.stepper.predict_next_step();
        }
        self.last_own = Some(own);
        // A step in the user's chart may not rush into type II, nor one in an alternative
        // chart into its own singularity (`FallWatch`).
        let m = self.ode.m();
        let qdd = if self.fall.wants_accelerations() {
            self.stepper.dy()[m..2 * m].iter().map(|a| a * a).sum::<f64>().sqrt()
        } else {
            f64::NAN
        };
        if let Some(h) =
            self.fall.next_step_bound(&self.ode.ws.chart, self.chart_steps > 0, own < PREDICT_BELOW, (t, own, qdd))
        {
            self.stepper.bound_next_step(h);
        }
        // The controller's proposal after a switch's first step, which `first_step_bound` kept
        // short, is long: in an alternative chart it is bounded as that first step was.
        if self.chart_steps == 1 && matches!(self.ode.ws.chart, Chart::Pairs(_)) {
            self.stepper.bound_next_step(first_step_bound(&self.ode, own));
        }
        self.t_stop = self.settings.t_end;
    }

    /// Whether the measure heading to 0 at the point in `ode.ws` is the passive one. Above
    /// [`APPROACH_BELOW`] it is the user's chart's type II measure, which bounds the passive
    /// one from below: asked once an approach (the passive measure, an SVD of Phi_x), which is
    /// A02's (the same) and not the 3-RRR's (2.3 times it, where its type II measure dips).
    /// The passive measure is the larger of the user's chart's type II measure and the
    /// partition's; the first is below the ratio's bound already, since `meas.passive` is at
    /// least that measure to round-off (it is that measure, from the closed forms or exact, or
    /// an inverse-iteration estimate of it, which bounds it from above, or the larger of it and
    /// another), so the partition's decides alone and the user's chart's SVD is not taken
    /// again (the 3-RRR benchmark run's 55 k instructions). None: not known yet, asked where
    /// first needed ([`Run::settle`]), which the 3-RRR's dip never is (73 k a run, 99 k more in
    /// the first: the partition's analysis).
    fn change_point_ahead(&mut self, meas: &Measures) -> Option<bool> {
        if meas.passive < APPROACH_BELOW {
            return Some(true);
        }
        match self.heading {
            Heading::Known(ahead) => Some(ahead),
            Heading::Deferred { .. } => None,
            Heading::Unasked => {
                // Once an approach (the question's point), not once a step.
                self.heading = Heading::Deferred { passive: meas.passive, x: self.ode.ws.x.clone(), on: true };
                None
            }
        }
    }

    /// Ask the question [`Run::change_point_ahead`] put off, at the point it was put off at
    /// (the same answer as asked there); without a change point ahead, the grid and the limit
    /// the last aim set on it are dropped.
    fn settle(&mut self) {
        let Heading::Deferred { passive, x, on } = &self.heading else { return };
        let ode = &mut self.ode;
        let ahead = self.prepared.partition_below(&mut ode.inputs_sys, ode.mech, x, CHANGE_POINT_RATIO * passive);
        if *on && !ahead {
            (self.grid, self.limit) = (None, None);
        }
        self.heading = Heading::Known(ahead);
    }

    /// The crossing's grid of the change point ahead, the heading asked if it was put off.
    fn settled_grid(&mut self) -> Option<Grid> {
        self.settle();
        self.grid
    }

    /// Whether a change point is watched for: not after a dip of the passive measure, nor
    /// where the measure heading to 0 is not the passive one, nor in a prescribed motion.
    fn watched(&mut self) -> bool {
        self.settle();
        self.heading != Heading::Known(false) && self.ode.motion.is_none()
    }

    /// Whether the step just taken to t, not limited by the approach, went past the start of
    /// the crossing ahead (as seen from its start) and near or over a change point. Above
    /// [`APPROACH_BELOW`] the measure is the user's chart's: one heading to 0 there may only
    /// dip (the 3-RRR's, the five-bar's), so the step's end and its path are asked (the true
    /// passive measure there; Phi_x's rank along the quintic through its ends).
    fn overshot(&mut self, t: f64) -> bool {
        let unlimited = self.t_stop == self.settings.t_end;
        if !(unlimited && self.grid.is_some_and(|g| t > g.t_star - g.tau)) || self.settled_grid().is_none() {
            return false;
        }
        let Some(last) = self.approach.last() else { return false };
        let saved = self.ode.save();
        let near = self.ode.evaluate(t, self.stepper.y()).map(|()| {
            let (ode, prepared) = (&mut self.ode, self.prepared);
            prepared.passive_below(&mut ode.inputs_sys, ode.mech, &ode.ws.x, CROSS_START) || inside_step(ode, last, t)
        });
        self.ode.restore(saved);
        near.unwrap_or(true)
    }

    /// Take the step again from its start, ending at the approach's limit: a step from above
    /// [`APPROACH_BELOW`] that went past the crossing's start (or over the point: A02 at
    /// rtol 1e-8 stepped from 0.06 to past it in the user's chart) would leave the crossing no
    /// nodes before it. `self.y` still holds the step's start.
    fn retake(&mut self) -> ControlFlow<Stop> {
        self.retake_to(self.limit.unwrap_or(self.settings.t_end))
    }

    /// Take the step just taken again from its start, ending at `t_stop` at the latest.
    fn retake_to(&mut self, t_stop: f64) -> ControlFlow<Stop> {
        let t_prev = self.stepper.t_prev();
        self.ode.restart_from_anchor();
        if let Err(error) = self.stepper.reset(&mut self.ode, t_prev, &self.y) {
            return Break(Stop::Step { error, crossing: None });
        }
        self.t_stop = t_stop;
        Continue(())
    }

    /// Switch the gears' held sides at the point accepted at t ([`GearSides::switch`]),
    /// restarting the integrator where the law jumped.
    fn gears(&mut self, t: f64) -> ControlFlow<Stop> {
        if self.gear_sides.switch(&mut self.ode, t) {
            self.ode.restart_from_anchor();
            if let Err(error) = self.stepper.reset(&mut self.ode, t, &self.y) {
                return Break(Stop::Step { error, crossing: None });
            }
        }
        Continue(())
    }

    /// The crossing's nodes that the step just taken went over (its grid as seen from the
    /// step's start): evaluated on the step's interpolant, as the outputs are, and kept for the
    /// crossing ([`Approach::fill`]).
    fn fill_approach(&mut self, t: f64) -> ControlFlow<Stop> {
        let Some(grid) = self.grid else { return Continue(()) };
        let t_prev = self.stepper.t_prev();
        let inside = |s: &f64| *s > t_prev + grid.h / 4.0 && *s < t - grid.h / 4.0;
        // Not asked for a crossing that would start after t_end (the 3-RRR's dip at 0.69 s
        // of 0.8, its point predicted at 0.92 s): its nodes are left to the points kept.
        let after_end = grid.t_star - grid.tau >= self.settings.t_end;
        let unasked = matches!(self.heading, Heading::Deferred { .. });
        if !grid.nodes().any(|s| inside(&s)) || unasked && after_end || self.settled_grid().is_none() {
            return Continue(());
        }
        // The step's end is set aside (`MechanismOde::set_aside`): these evaluations leave it.
        self.ode.restart_from_anchor();
        // Earliest first, as the outputs are walked.
        for s in grid.nodes().rev().filter(inside) {
            if let Err(error) = evaluate_output(&mut self.ode, &mut self.stepper, s, &mut self.yi) {
                return Break(Stop::Output { t: s, error });
            }
            self.approach.fill(&self.ode, s);
        }
        Continue(())
    }

    /// The caller's progress callback, which may stop the run.
    fn report(&mut self, t: f64, progress: &mut Progress) -> ControlFlow<Stop> {
        let stop = progress.as_mut().is_some_and(|cb| !cb(t));
        if stop {
            return Break(Stop::Cancelled { t });
        }
        Continue(())
    }

    /// The crossing's gap [t0, t1] in the dense output, sampled from the path it followed
    /// (as a partition chart's step: the path is in body coordinates), and the events in it;
    /// the first terminal one's time and index. Without it the step after the landing was
    /// stored over the gap, and sol was 0.33 rad off there (the double parallelogram swung
    /// through its change point, DOP853 at rtol 1e-10). The point in `ode.ws` is kept.
    fn observe_gap(&mut self, path: &Bridge, t0: f64, t1: f64) -> Result<Option<(f64, usize)>, String> {
        let Some(dense) = self.dense.as_mut() else { return Ok(None) };
        let ode = &mut self.ode;
        ode.set_aside();
        let (pieces, n, m) = (dense::PARTITION_PIECES, dense.nodes, ode.m());
        for piece in 0..pieces {
            let (a, b) = dense::piece(t0, t1, piece, pieces);
            self.rows.clear();
            for j in 0..n {
                path_state(ode, path, a + dense::node(j, n) * (b - a));
                self.rows.extend_from_slice(&ode.ws.q[..m]);
                self.rows.extend_from_slice(&ode.ws.qd[..m]);
            }
            dense.push(a, b, &self.rows);
        }
        ode.take_back();
        self.watch.step(dense, t0).map_err(|e| format!("an event inside the crossing: {e}"))
    }

    /// Cross the change point ahead of the point accepted at t (held by `ode.ws`, type II and
    /// passive measures `sigma`, `passive`, work `work`) and restart the stepper past it.
    /// Outputs inside the crossing come from the path it followed; without a grid the point
    /// past it is recorded. Err says why the motion cannot be continued.
    fn cross_change_point(&mut self, (t, sigma, passive, work): (f64, f64, f64, f64)) -> Result<Crossed, String> {
        let t_end = self.settings.t_end;
        let integration = Integration { method: self.settings.method, options: &self.options };
        let at = (t, &Measures { sigma, passive }, work);
        let Some(landing) = cross(&mut self.ode, at, &self.approach, &integration, &mut self.crossing_stats)? else {
            return Ok(Crossed::NoPoint);
        };
        self.passed_point(landing.point.clone());
        (self.t_stop, self.grid, self.heading) = (t_end, None, Heading::Unasked);
        let inside = |s: f64, end: f64| s < end || s == t_end && end >= t_end;
        if let Some((t_star, index)) = self.observe_gap(&landing.path, t, landing.t.min(t_end))? {
            let rows: Vec<f64> = match self.t_eval {
                Some(te) => te[self.next..].iter().copied().take_while(|&s| s < t_star).chain([t_star]).collect(),
                None => vec![t_star],
            };
            for s in rows {
                path_row(&mut self.ode, &mut self.traj, &landing.path, s, sigma);
            }
            if let Some(d) = self.dense.as_mut() {
                d.truncate(t_star);
            }
            return Ok(Crossed::Event { t: t_star, index });
        }
        if landing.t >= t_end {
            let rows: Vec<f64> = match self.t_eval {
                Some(te) => te[self.next..].iter().copied().take_while(|&s| inside(s, t_end)).collect(),
                None => vec![t_end],
            };
            for s in rows {
                path_row(&mut self.ode, &mut self.traj, &landing.path, s, sigma);
            }
            self.next = self.t_eval.map_or(0, <[f64]>::len);
            return Ok(Crossed::AtEnd);
        }
        let ode = &mut self.ode;
        self.stepper.reset(ode, landing.t, &landing.y).map_err(|e| format!("restarting past the change point: {e}"))?;
        self.traj.stats.chart_switches += 1;
        let meas = measure(ode);
        let own = chart_sigma(ode, meas.sigma);
        ode.limit_correction(own);
        self.stepper.bound_first_step(first_step_bound(ode, own));
        let work_past = landing.y[landing.y.len() - 1];
        self.approach.clear();
        self.approach.keep(ode, landing.t, &meas);
        match self.t_eval {
            None => self.traj.record(ode, landing.t, work_past, meas.sigma),
            Some(te) => {
                // In the spare buffers: the next step starts from the landing's evaluation.
                ode.set_aside();
                while self.next < te.len() && inside(te[self.next], landing.t) {
                    path_row(ode, &mut self.traj, &landing.path, te[self.next], sigma);
                    self.next += 1;
                }
                ode.take_back();
            }
        }
        Ok(Crossed::Past)
    }

    /// The trajectory with the run's counters, its events and dense output, and the status and
    /// message of `stop`. A run stopped between two accepted steps keeps the last one as its
    /// final row when the output grid did not reach it.
    fn finish(mut self, stop: Stop) -> Trajectory {
        if stop.keeps_last() && self.traj.t.last().is_none_or(|&t| t < self.stepper.t()) {
            keep_last_state(&mut self.ode, &self.stepper, &mut self.traj);
        }
        let mut traj = self.traj;
        let (run, crossings) = (self.stepper.stats(), self.crossing_stats);
        traj.stats.integrator = Stats {
            nfev: run.nfev + crossings.nfev,
            naccept: run.naccept + crossings.naccept,
            nreject: run.nreject + crossings.nreject,
            ..run
        };
        traj.stats.failed_evaluations = self.ode.failed_evaluations;
        traj.events = self.watch.records;
        // Events alone need the dense output only while the run lasts.
        traj.dense = self.dense.filter(|_| self.keep_dense);
        let (mech, ode, t) = (self.ode.mech, &self.ode, self.stepper.t());
        let fold = self.fold.ahead(t, t - self.stepper.t_prev());
        let h_min = self.settings.options.h_min * t.abs().max(1.0);
        // The last row is the last accepted state (`keeps_last`) for the failures diagnosed;
        // its speed is read only for a failed run's message (`describe` calls `near` then).
        let (xd, nx) = (&traj.xd, traj.nx);
        (traj.status, traj.message) = stop.describe(|| Near {
            passive: passive_sigma_min(mech, ode.anchor_x()),
            driven: ode.motion.as_ref().map_or(f64::INFINITY, |p| prescribed_sigma_min(mech, &p.p, ode.anchor_x())),
            reach: xd.rchunks_exact(nx).next().map_or(0.0, |xd| scaled_speed(mech, xd)) * h_min,
            h_min,
            start: t - self.settings.t0 < h_min,
            fold,
        });
        traj
    }
}

/// The trajectory of a run that stopped before its first step: no row, its status.
pub fn stopped_at_start(mech: &Mechanism, stop: Stop) -> Trajectory {
    let mut traj = Trajectory::new(mech.dof(), mech.n_x());
    let near = Near { passive: f64::INFINITY, driven: f64::INFINITY, reach: 0.0, h_min: 0.0, start: true, fold: None };
    (traj.status, traj.message) = stop.describe(|| near);
    traj
}

/// Record the stepper's last accepted state as the final row (a stopped run keeps it when
/// the output grid did not reach it). Evaluated from its own anchor, so Newton starts at the
/// answer; if even that fails, the rows already recorded stand.
fn keep_last_state(ode: &mut MechanismOde, stepper: &Stepper, traj: &mut Trajectory) {
    let (t, y) = (stepper.t(), stepper.y());
    ode.restart_from_anchor();
    if ode.accept(t, y).is_ok() {
        let sigma = measure(ode).sigma;
        traj.record(ode, t, y[y.len() - 1], sigma);
    }
}

/// Evaluate the dense output of the step just taken at `t_out` into `yi` (walking there
/// from the step's start if a direct evaluation is refused).
fn evaluate_output(ode: &mut MechanismOde, stepper: &mut Stepper, t_out: f64, yi: &mut [f64]) -> Result<(), Error> {
    stepper.interpolate(ode, t_out, yi);
    ode.evaluate_walking(t_out, yi)
}

/// Append the step just taken to `dense`: the user's q and qd at its nodes, from the step's
/// interpolant. In the user's chart that is the interpolant itself, the coordinates driven by
/// motion following it; in a partition chart, the points assembled at the interpolated chart
/// values, over [`dense::PARTITION_PIECES`] pieces of the step (see there).
fn sample_step(
    ode: &mut MechanismOde,
    stepper: &mut Stepper,
    dense: &mut DenseOutput,
    yi: &mut [f64],
    rows: &mut Vec<f64>,
) -> Result<(), Error> {
    let m = ode.m();
    let (t0, t1) = (stepper.t_prev(), stepper.t());
    ode.restart_from_anchor();
    let pieces = if ode.ws.chart == Chart::Inputs { 1 } else { dense::PARTITION_PIECES };
    for piece in 0..pieces {
        let (a, b) = dense::piece(t0, t1, piece, pieces);
        rows.clear();
        for j in 0..dense.nodes {
            let t = a + dense::node(j, dense.nodes) * (b - a);
            if piece + 1 == pieces && j + 1 == dense.nodes {
                yi.copy_from_slice(stepper.y());
            } else {
                stepper.interpolate(ode, t, yi);
            }
            if ode.ws.chart == Chart::Inputs {
                if let Some(motion) = ode.motion.as_deref_mut() {
                    motion.eval(t).map_err(|message| Error::Drive { t, message })?;
                    motion.overwrite(m, yi);
                }
                rows.extend_from_slice(&yi[..2 * m]);
            } else {
                ode.evaluate_walking(t, yi)?;
                rows.extend_from_slice(&ode.ws.q);
                rows.extend_from_slice(&ode.ws.qd);
            }
        }
        dense.push(a, b, rows);
    }
    Ok(())
}

/// Record the row at time s inside a crossing, from the path it followed.
fn path_row(ode: &mut MechanismOde, traj: &mut Trajectory, path: &Bridge, s: f64, sigma: f64) {
    path_state(ode, path, s);
    traj.record(ode, s, path.work(s), sigma);
}

/// The state at time s inside a crossing into `ode.ws`, from the path it followed.
fn path_state(ode: &mut MechanismOde, path: &Bridge, s: f64) {
    let ws = &mut ode.ws;
    path.at(s, &mut ws.frame.x, &mut ws.frame.xd, &mut ws.xdd);
    user_state(ode);
}
