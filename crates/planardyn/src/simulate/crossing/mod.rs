//! Change points: where Phi_x loses rank, several branches of the passive mechanism's
//! configuration space meet and its mobility jumps (parallelogram cranks aligned, a folded
//! four-bar). No chart is regular there, and near the point every evaluation loses accuracy
//! (the position solve leaves x off the branch by about its tolerance / sigma along the other
//! branch's tangent, where the analogues turn by that over sigma), so the integrator does not
//! step through: the motion goes on along the branch whose tangent it arrives with
//! (docs/formulation.md, *Change points*), and the crossing bridges the gap between the
//! points where the passive measure is [`CROSS_BELOW`] on either side:
//!
//! 1. the approach (`Approach::step_limit`) ends its steps on a grid before the point;
//! 2. a Taylor step ([`Bridge`] through the accelerations there) predicts the landing as far
//!    past the point, projected onto the branch whose tangent the motion arrives with (the
//!    continuing branch is close to the prediction, any other an O(1) angle away: a dead end,
//!    where no branch continues the motion, fails that test and the run stops);
//! 3. [`NODES`] points past the landing are integrated from it with the run's method and
//!    tolerances, and the landing is corrected by the bridge through the accelerations on both
//!    sides, an interpolation; again until a correction is below the tolerance.
//!
//! Its error is then that of the bridge's interpolation over the gap and of the accelerations
//! at its nodes, not of an extrapolation: see [`NODES`].

mod approach;
mod bridge;
mod point;

pub use approach::{scaled_speed, Approach, Grid, Passed};
pub use bridge::{Bridge, Path};
pub use point::{inside_step, stepped_over, ChangePoint};

use super::charts::{chart_sigma, first_step_bound, Measures};
use super::ode::MechanismOde;
use crate::integrate::{Method, Options, Stats, StepError, Stepper};
use crate::kinematics::constraints::{body_trig, pair_coordinate_gamma, pair_coordinate_rate};
use crate::kinematics::{
    coordinate_rates, coordinates, passive_sigma_min, scaled_distance, select_partition, sigma_min, solve_position,
    velocity_analogues, Chart,
};
use crate::Error;
use point::located;

/// A falling passive measure below [`CROSS_START`] starts a crossing, its gap then about
/// twice the time the measure takes from CROSS_BELOW to 0. Nearer the point the evaluations
/// lose accuracy like eps / sigma^2 and worse, and more with the mechanism's size (A02's
/// accelerations at 0.02, N = 2: 7e-12 of 13 rad/s^2, N = 40: 1.6e-10; at 0.04, N = 40: 6e-12);
/// farther, the gap is longer and the bridge's own error grows as a high power of it. On A02
/// (worst angle error at 20 s, rtol = atol = 1e-12, N = 2 / N = 40): 0.015: 2.4e-10 / 3.4e-8,
/// 0.02: 5.4e-10 / 9.2e-9, 0.025: 1.6e-10 / 4.4e-9, 0.03: 3.0e-11 / 7.7e-9 (with 8 nodes at
/// spacing 0.5).
pub const CROSS_BELOW: f64 = 0.025;
/// The grid spacing of the nodes, as a fraction of the time tau the passive measure takes
/// from [`CROSS_BELOW`] to 0.
pub const SPACING: f64 = 0.6;
/// The passive measure below which a falling one starts the crossing: the approach's last
/// step ends at about [`CROSS_BELOW`], the one before at 1 + [`SPACING`] times it.
pub const CROSS_START: f64 = (1.0 + 0.5 * SPACING) * CROSS_BELOW;
/// The scaled distance from the change point (the largest of the angles in rad and the
/// translations per L, at the present speed) nearer which a crossing starts, if its measure
/// there is still above [`CROSS_BELOW`]: the bridge spans the motion, not the measure, and
/// where the measure grows slowly from the point it spanned too much of it. A02's measure is
/// CROSS_BELOW 0.092 rad before its points (N = 2 and 40), so it crosses as before; a double
/// parallelogram (crank 0.306 m, spacing 0.771 m) had 0.026 at 0.33 rad: its gap of 0.1 s
/// (0.65 rad of the cranks) left the prediction 2.4e-2 off the branch's tangent, and its nodes
/// past the landing, 0.24 s of it, ran its partition into a fold.
pub const CROSS_DISTANCE: f64 = 0.1;
/// Nodes on either side of a crossing (besides its start and its landing) whose accelerations
/// its bridge goes through, [`SPACING`] tau apart. Through the exact accelerations of A02 at
/// N = 2 (its reduction), the landing's rate is off by 1.2e-13 rad/s at tau = 0.02 s, 5.5e-12
/// at 0.03 (4 nodes a side at spacing 1: 7.0e-11 and 8.7e-9; 6 at 0.75: 2.5e-14 and 2.9e-11),
/// and the nodes' errors enter it with weights summing to 8.6 times the gap.
pub const NODES: usize = 8;
/// Below this passive measure, falling towards 0, a step may take at most this fraction
/// [`APPROACH_CAP`] of the time left to the change point, and steps on the crossing's grid
/// once there (`Approach::step_limit`). Not above: there the measure is the user's chart's
/// type II measure, which the five-bar and the 3-RRR pass with a dip, and capping their steps
/// cost them up to 22 % more evaluations for nothing; the grid's earlier times are filled
/// from the steps' interpolants instead (`Approach::fill`).
pub const APPROACH_BELOW: f64 = 0.05;
/// Above [`APPROACH_BELOW`] a measure heading to 0 is taken for a change point's if the
/// passive measure there is below this times it: A02's is the same, the 3-RRR's 2.3 times it
/// where its type II measure dips towards 0.14 (the five-bar's are the same too: its
/// approaches are watched, and cost it nothing, 11763 evaluations for 5 s against 12481).
pub const CHANGE_POINT_RATIO: f64 = 1.5;
/// See [`APPROACH_BELOW`].
const APPROACH_CAP: f64 = 1.0 / 3.0;
/// Below this passive measure at an accepted step the next step may move the mechanism by
/// at most [`APPROACH_FRACTION`] of it (scaled): a guard on the integrator's stages, should a
/// step still run towards a change point past the approach's grid (a step that still went
/// over one is recognised, [`stepped_over`]). Not higher: the five-bar passes type II
/// singularities with the passive measure at 0.05, where the limit would only cost steps.
pub const WATCH_BELOW: f64 = 0.02;
/// See [`WATCH_BELOW`].
pub const APPROACH_FRACTION: f64 = 0.5;
/// Largest projection from the prediction, as a fraction of the passive measure before the
/// point or of the prediction's scaled distance from the point, the larger (the other branches
/// are about that far: they meet the motion's there; where the measure grows slowly from the
/// point, as the double parallelogram's, farther than the measure says).
const PROJECTION_FRACTION: f64 = 0.25;
/// Largest change of the predicted velocity by its projection, relative to it: the branch
/// the motion follows has its tangent to the prediction's accuracy, another branch one at an
/// O(1) angle. The prediction extrapolates over about twice the time from [`CROSS_BELOW`] to
/// the point: the triple-crank parallelogram's changed by up to 1.9e-3 at rtol 1e-9 (A02's
/// and its own at 1e-11: below 7e-4).
const TANGENT_MISMATCH: f64 = 1e-2;
/// Lengthenings of the gap tried when the point past it is still too near the singularity.
const ATTEMPTS: usize = 4;
/// A point past the landing whose chart measure is below this fraction of the landing's ends
/// the points integrated past it (`integrate_past`): the motion is heading into another
/// singularity, where the evaluations lose accuracy and then fail. Double parallelograms of
/// benchmarks/change_point_sweep.py whose motion turns near a change point (crank 0.117 m,
/// spacing 0.622 m, theta 3.036: crossed at 0.339 s, the next point 0.118 s later) ran their
/// nodes past the landing, 4.8 times the time to the point, into the next one ("even for the
/// smallest step"). Half: the landing's measure is about [`CROSS_BELOW`], and the run's own
/// crossings start as low as a fifth of it.
const NEXT_SINGULARITY: f64 = 0.5;
/// Corrections of a landing at most. Each changes it by about the last one's change times
/// the contraction (gap |df/dy|: 1e-4 on A02), and the correction ends when that product is
/// below the tolerance ([`CORRECTED`]): usually after 2, each an integration over
/// [`NODES`] spacings.
const MAX_CORRECTIONS: usize = 6;
/// The correction ends when the landing's estimated remaining change is below this fraction
/// of the tolerance (or when the changes stop falling: the evaluations' noise).
const CORRECTED: f64 = 1e-2;
/// The last correction allowed (in tolerances) when the changes still fall slowly after
/// [`MAX_CORRECTIONS`]: below the tightest tolerances the evaluations' noise near the point
/// exceeds the tolerance (A02 at rtol 1e-13, atol 1e-15: 2.0 at N = 10, 7.8 at N = 40), and a
/// landing that far from settled is still within the noise of its nodes.
const NOISE_CORRECTION: f64 = 1e2;
/// A chart keeps the start's partition past the point if its measure there is at least this
/// fraction of the best partition's: its coordinates and rates are then the integrated
/// state's own, not those of another partition assembled and differentiated near the point
/// (A02 at N = 40, rtol = atol = 1e-12: 2.2e-8 rad after 20 s with the best partition, 9.2e-9
/// keeping the start's).
const KEEP_PARTITION: f64 = 0.5;

/// Where a crossing lands: time, chart and chart state y = [z, zd, W] past the point (held
/// by `ode.ws`, evaluated and anchored there), the point, and the path the crossing followed.
pub struct Landing {
    pub t: f64,
    pub chart: Chart,
    pub y: Vec<f64>,
    pub point: ChangePoint,
    pub path: Bridge,
}

/// How a crossing integrates past its landing: the run's method and options (without dense
/// output), which also give the tolerance its corrections are measured in.
pub struct Integration<'o> {
    pub method: Method,
    pub options: &'o Options,
}

impl Integration<'_> {
    /// The largest change from `a` to `b` in units of the tolerance (the integrators' error
    /// test, in the max norm).
    fn norm(&self, a: &[f64], b: &[f64]) -> f64 {
        let (rtol, atol) = (self.options.rtol, self.options.atol);
        a.iter().zip(b).fold(0.0, |e: f64, (a, b)| e.max((a - b).abs() / (atol + rtol * a.abs().max(b.abs()))))
    }
}

/// Cross the change point ahead of the point accepted at `t` with passive measure `passive`
/// and work `work` (held by `ode.ws`, evaluated), with the points before it in `approach`
/// (see the module's steps). On return `ode` holds the landing, evaluated and anchored in its
/// chart; `stats` counts the integrations past it. None, with `ode` as it was, if the measure
/// is not heading to 0, Phi_x keeps its rank on the Taylor step's path or the step's first
/// landing does not assemble: the measure only dips (the five-bar's at its type II
/// singularities, or past a near miss of a change point). Err says why the motion cannot be continued.
pub fn cross(
    ode: &mut MechanismOde,
    (t, meas, work): (f64, &Measures, f64),
    approach: &Approach,
    integration: &Integration,
    stats: &mut Stats,
) -> Result<Option<Landing>, String> {
    // No root ahead of the measure's quadratic through its last points: it only dips (a
    // five-bar's type II passage with its least passive measure at 0.030, between CROSS_BELOW
    // and CROSS_START, stopped the run here as if at a change point).
    let Some(to_point) = approach.time_to_point(t, meas) else { return Ok(None) };
    let passive = meas.passive;
    let start = Passed::of(ode, t, passive);
    let h = SPACING * to_point;
    let before: Vec<&Passed> = std::iter::once(&start).chain(approach.samples(t, h)).collect();
    let predictor = Bridge::new(&before, work, to_point);
    let ahead = located(ode.mech, &predictor, t, t + 2.0 * to_point);
    if ahead.rank_drop == 0 {
        return Ok(None);
    }
    let mut why = String::new();
    let before_landing = ode.save();
    for attempt in 0..ATTEMPTS {
        let t_land = t + 2.0 * to_point * f64::from(1u32 << attempt);
        let landed = match land(ode, &predictor, t_land, (passive, &ahead.x, start.speed)) {
            // The motion turned away from a near miss (a dip of the measure near CROSS_BELOW,
            // the dimensions near a change point's) while the Taylor step ran on into it: a
            // five-bar with base 0.29991, proximal links 0.152 and distal 0.320 dips to 0.02
            // at 0.863 s, and DOPRI5's prediction at rtol 1e-9 ... 1e-12 did not assemble.
            Err(Unprojected::Unassembled(_)) if attempt == 0 => {
                ode.restore(before_landing);
                return Ok(None);
            }
            landed => landed.map_err(Unprojected::why)?,
        };
        match landed {
            (idx, y, past) if past >= 0.5 * passive => {
                let times: Vec<f64> = (1..=NODES).map(|k| t_land + k as f64 * h).collect();
                let landing = (t_land, idx.as_slice(), y, past);
                let (y, path) = correct(ode, (&before, work, to_point), landing, &times, integration, stats)?;
                let point = located(ode.mech, &path, t, t_land);
                return Ok(Some(Landing { t: t_land, chart: Chart::Partition(idx), y, point, path }));
            }
            (_, _, past) => why = format!("{:.2e} s past it the passive measure is still {past:.2e}", t_land - t),
        }
    }
    Err(format!("no branch continues the motion through the change point: {why}"))
}

/// Correct the landing at `t_land` (partition `idx`, state `y`, passive measure `past`, held
/// by `ode`) by the bridge from the nodes `before` (work at the start, time scale) through the
/// landing and the points at `times` past it, integrated from it; the corrected state and the
/// bridge.
fn correct(
    ode: &mut MechanismOde,
    (before, work, scale): (&[&Passed], f64, f64),
    (t_land, idx, mut y, past): (f64, &[usize], Vec<f64>, f64),
    times: &[f64],
    integration: &Integration,
    stats: &mut Stats,
) -> Result<(Vec<f64>, Bridge), String> {
    let mut change = f64::INFINITY;
    let mut landing = Passed::of(ode, t_land, past);
    let mut times = times.to_vec();
    for k in 1..=MAX_CORRECTIONS {
        let (mut after, clear) = integrate_past(ode, (t_land, &y), &times, integration, stats)?;
        return_to(ode, &landing, idx, &y)?;
        // Another singularity ahead: the nodes again, spaced over the part clear of it (with
        // the first nodes only, a double parallelogram drifted 3e-7 of its peak kinetic energy
        // at rtol 1e-11, against 1e-8 for the sweep's balance).
        if after.len() < times.len() && clear > t_land {
            let h = (clear - t_land) / times.len() as f64;
            times = (1..=times.len()).map(|j| t_land + j as f64 * h).collect();
            after = integrate_past(ode, (t_land, &y), &times, integration, stats)?.0;
            return_to(ode, &landing, idx, &y)?;
        }
        landing = Passed::of(ode, t_land, past);
        let nodes: Vec<&Passed> = before.iter().copied().chain([&landing]).chain(&after).collect();
        let path = Bridge::new(&nodes, work, scale);
        let corrected = chart_state(idx, &path, t_land);
        let previous = std::mem::replace(&mut change, integration.norm(&y, &corrected));
        y = corrected;
        ode.accept(t_land, &y).map_err(|e| format!("the corrected landing past it: {e}"))?;
        // The next change is about this one times the contraction, this one / the last; one
        // that does not fall is the evaluations' noise.
        let settled = previous.is_finite() && (change * change / previous <= CORRECTED || change >= previous);
        let at_noise = k == MAX_CORRECTIONS && change <= NOISE_CORRECTION;
        if change <= CORRECTED || settled || at_noise {
            landing = Passed::of(ode, t_land, past);
            let nodes: Vec<&Passed> = before.iter().copied().chain([&landing]).chain(&after).collect();
            return Ok((y, Bridge::new(&nodes, work, scale)));
        }
    }
    Err(format!("the landing past it did not settle: its last correction was {change:.2e} of the tolerance"))
}

/// Land the Taylor step `path` at `t_land`: its (x, xd) projected onto the branch (in the
/// partition of [`partition_at`]), evaluated and anchored there; the partition, the state
/// y = [z, zd, W] and the passive measure there. `passive`, `point` and `arrival`: the
/// passive measure and scaled speed at the crossing's start, the change point. Err when the
/// branch does not continue the motion.
fn land(
    ode: &mut MechanismOde,
    path: &Bridge,
    t_land: f64,
    (passive, point, arrival): (f64, &[f64], f64),
) -> Result<(Vec<usize>, Vec<f64>, f64), Unprojected> {
    let n = path.coordinates();
    let (mut x, mut xd, mut xdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    path.at(t_land, &mut x, &mut xd, &mut xdd);
    let idx = partition_at(ode, &x);
    let past = project(ode, &idx, (&x, &xd), (passive, point, arrival))?;
    let y = partition_state(&idx, &ode.ws.x, &ode.ws.xd, path.work(t_land));
    if past >= 0.5 * passive {
        let set = ode.set_chart(Chart::Partition(idx.clone()), t_land, &y);
        set.map_err(|e| Unprojected::Other(format!("past the change point: {e}")))?;
        let own = chart_sigma(ode, f64::INFINITY);
        ode.limit_correction(own);
    }
    Ok((idx, y, past))
}

/// The partition to land in at x: the start's, unless its measure there is below
/// [`KEEP_PARTITION`] of the partition complete pivoting chooses.
fn partition_at(ode: &MechanismOde, x: &[f64]) -> Vec<usize> {
    let best = select_partition(ode.mech, x);
    match &ode.ws.chart {
        Chart::Partition(own) if own != &best => {
            let own_sigma = sigma_min(ode.mech, &ode.ws.chart, x);
            let best_sigma = sigma_min(ode.mech, &Chart::Partition(best.clone()), x);
            if own_sigma >= KEEP_PARTITION * best_sigma {
                own.clone()
            } else {
                best
            }
        }
        _ => best,
    }
}

/// Back to the landing `landing` (partition `idx`, state `y`) from the points past it:
/// evaluated and anchored there, Newton's moves bounded by its chart's measure.
fn return_to(ode: &mut MechanismOde, landing: &Passed, idx: &[usize], y: &[f64]) -> Result<(), String> {
    ode.ws.x.copy_from_slice(landing.x());
    let chart = Chart::Partition(idx.to_vec());
    ode.set_chart(chart, landing.t, y).map_err(|e| format!("the landing past it: {e}"))?;
    let own = chart_sigma(ode, f64::INFINITY);
    ode.limit_correction(own);
    Ok(())
}

/// The points at `times` past the landing at `t_land` (state `y` in the chart of `ode`, which
/// holds it), integrated from it with the run's method and tolerances; the integration's
/// counters are added to `stats`. Each step's end is accepted as the run's are, and bounds the
/// next step's Newton moves by the chart's measure there: the measure grows away from the
/// point, and the landing's bounds (2 sigma from the last accepted point) kept for all of it
/// refused every evaluation past them (a double parallelogram at 12 rad/s, landing at
/// measure 7e-3: 2 ms past it, "even for the smallest step"). The points end early, before a
/// step whose chart measure is below [`NEXT_SINGULARITY`] of the landing's: the motion is
/// heading into another singularity (the next change point, or the point again where the
/// motion turns past it); with them, the last time accepted before that step.
fn integrate_past(
    ode: &mut MechanismOde,
    (t_land, y): (f64, &[f64]),
    times: &[f64],
    integration: &Integration,
    stats: &mut Stats,
) -> Result<(Vec<Passed>, f64), String> {
    let mut stepper = Stepper::new(integration.method, integration.options, y.len())?;
    let past = |e: StepError<Error>| format!("integrating past the landing: {e}");
    let mut outcome = stepper.reset(ode, t_land, y).map_err(past);
    let landing = chart_sigma(ode, f64::INFINITY);
    stepper.bound_first_step(first_step_bound(ode, landing));
    let accepted = |ode: &mut MechanismOde, stepper: &Stepper, t: f64| {
        ode.accept(t, stepper.y()).map_err(|e| format!("past the landing: {e}"))?;
        let own = chart_sigma(ode, f64::INFINITY);
        ode.limit_correction(own);
        Ok(own)
    };
    let mut out = Vec::with_capacity(times.len());
    let (mut heading, mut clear) = (false, t_land);
    for &time in times {
        while outcome.is_ok() && !heading && stepper.t() < time {
            let step = stepper.step(ode, time).map_err(past);
            outcome = step.and_then(|()| accepted(ode, &stepper, stepper.t())).map(|own| {
                heading = own < NEXT_SINGULARITY * landing;
            });
            if outcome.is_ok() && !heading {
                clear = stepper.t();
            }
        }
        if outcome.is_err() || heading {
            break;
        }
        out.push(Passed::of(ode, time, 0.0));
    }
    let local = stepper.stats();
    stats.nfev += local.nfev;
    stats.naccept += local.naccept;
    stats.nreject += local.nreject;
    outcome.map(|()| (out, clear))
}

/// Why a predicted point past a change point is not on the motion's branch.
enum Unprojected {
    /// It does not assemble in its partition.
    Unassembled(String),
    /// It assembles, too far from the prediction or with another tangent.
    Other(String),
}

impl Unprojected {
    fn why(self) -> String {
        match self {
            Unprojected::Unassembled(why) | Unprojected::Other(why) => why,
        }
    }
}

/// Project the predicted (x, xd) onto the constraints and their tangent in the partition
/// `idx` (`passive`, `point`, `arrival`: see [`land`]); the passive measure there, or why it
/// is not the motion's branch.
fn project(
    ode: &mut MechanismOde,
    idx: &[usize],
    (x, xd): (&[f64], &[f64]),
    (passive, point, arrival): (f64, &[f64], f64),
) -> Result<f64, Unprojected> {
    let mech = ode.mech;
    let ws = &mut ode.ws;
    ws.chart = Chart::Partition(idx.to_vec());
    ws.x.copy_from_slice(x);
    let z: Vec<f64> = idx.iter().map(|&i| x[i]).collect();
    solve_position(mech, &z, ws)
        .map_err(|e| Unprojected::Unassembled(format!("the predicted point does not assemble: {e}")))?;
    let moved = scaled_distance(&ws.x, x, ws.sys.group_col_scale());
    let apart = passive.max(scaled_distance(x, point, ws.sys.group_col_scale()));
    if moved > PROJECTION_FRACTION * apart {
        return Err(Unprojected::Other(format!("the predicted point is {moved:.2e} from the nearest branch (scaled)")));
    }
    velocity_analogues(ws).map_err(|e| Unprojected::Other(format!("no tangent past the point: {e}")))?;
    let n = x.len();
    ws.xd.fill(0.0);
    for (j, &i) in idx.iter().enumerate() {
        for (v, u) in ws.frame.xd.iter_mut().zip(&ws.frame.u[j * n..(j + 1) * n]) {
            *v += u * xd[i];
        }
    }
    let scale = ws.sys.group_col_scale();
    // The prediction's error is of the motion's speed over the gap, not of its speed at the
    // landing: where the motion turns in the gap, the latter is a fraction of it (a double
    // parallelogram turning 0.03 rad past its point: 0.20 at the landing against 2.7 arriving,
    // 1.7e-2 off the tangent). A branch at an O(1) angle is then still told by the position
    // (PROJECTION_FRACTION).
    let landing = xd.iter().zip(scale).fold(0.0, |s: f64, (v, l)| s.max((v / l).abs()));
    let speed = landing.max(arrival);
    let mismatch = scaled_distance(&ws.xd, xd, scale);
    if mismatch > TANGENT_MISMATCH * speed {
        let why = format!("the branch's tangent differs from the motion's by {:.2e} of its speed", mismatch / speed);
        return Err(Unprojected::Other(why));
    }
    Ok(passive_sigma_min(mech, &ws.x))
}

/// The state y = [z, zd, W] of `path` at t in the partition `idx` (indices of x).
fn chart_state(idx: &[usize], path: &Bridge, t: f64) -> Vec<f64> {
    let n = path.coordinates();
    let (mut x, mut xd, mut xdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    path.at(t, &mut x, &mut xd, &mut xdd);
    partition_state(idx, &x, &xd, path.work(t))
}

/// y = [z, zd, W] of body coordinates and rates (x, xd) and work W in the partition `idx`.
fn partition_state(idx: &[usize], x: &[f64], xd: &[f64], work: f64) -> Vec<f64> {
    let m = idx.len();
    let mut y = vec![0.0; 2 * m + 1];
    for (k, &i) in idx.iter().enumerate() {
        (y[k], y[m + k]) = (x[i], xd[i]);
    }
    y[2 * m] = work;
    y
}

/// Fill the user's coordinates, rates and accelerations of `ode.ws` from body (x, xd, xdd)
/// given there (an output inside a crossing).
pub fn user_state(ode: &mut MechanismOde) {
    let (mech, ws) = (ode.mech, &mut ode.ws);
    body_trig(&ws.frame.x, &mut ws.frame.trig);
    coordinates(mech, &ws.frame.x, &mut ws.frame.q);
    coordinate_rates(mech, &ws.frame.x, &ws.frame.xd, &mut ws.frame.qd);
    for (k, c) in mech.coordinates.iter().enumerate() {
        let p = &mech.pairs[c.pair.0];
        ws.qdd[k] = pair_coordinate_rate(p, &ws.x, &ws.xdd) + pair_coordinate_gamma(p, &ws.x, &ws.xd, &ws.xd);
    }
}
