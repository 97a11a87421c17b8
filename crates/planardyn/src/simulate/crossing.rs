//! Change points: where Phi_x loses rank, several branches of the passive mechanism's
//! configuration space meet and its mobility jumps (parallelogram cranks aligned, a folded
//! four-bar). No chart is regular there, so the integrator cannot step through; the motion
//! goes on along the branch whose tangent it arrives with (docs/formulation.md, *Change
//! points*). The crossing is a Taylor step from the last accepted point before it to as far
//! past it (its acceleration extrapolated from those of the last few accepted points, see
//! [`Extrapolation`]), then a projection onto the constraints: the branch the motion
//! follows is O(h^6) from the prediction, any other one O(h) (they cross
//! at an angle), so Newton lands on the continuing branch, and the velocity projected there
//! must be the predicted one (a dead end, where no branch continues the motion, fails that
//! test and the run stops as before). Where the integrator itself stepped over a change
//! point (its branch guard allows a step to land as far past as it started before), the
//! crossing is only detected and reported.

use super::ode::MechanismOde;
use crate::dynamics::{kinetic_energy, potential_energy};
use crate::kinematics::constraints::{body_trig, pair_coordinate_gamma, pair_coordinate_rate};
use crate::kinematics::singularity::scaled_phi_x;
use crate::kinematics::{
    coordinate_rates, coordinates, passive_sigma_min, scaled_distance, select_partition, solve_position,
    velocity_analogues, Chart,
};
use crate::linalg::pivot_columns;
use crate::model::Mechanism;

/// A passive measure below this at an accepted step, falling, starts a crossing. Nearer the
/// point the evaluations themselves lose accuracy like eps / sigma^2: the position solve
/// leaves x off the branch by about its tolerance / sigma along the other branch's tangent,
/// where U turns by that over sigma (A02 at 1e-5: accelerations 2e-3 off). Farther, the Taylor
/// step is longer. On A02 at N = 40 (rate error after the first crossing, before the energy
/// is restored): 3e-4: 6e-6 rad/s, 1e-3: 1e-8, 3e-3: 3e-9, 5e-3: 4e-9 with the smallest
/// error after 20 s, 1e-2: 2e-8.
pub const CROSS_BELOW: f64 = 5e-3;
/// Below this passive measure at an accepted step the next step may move the mechanism by
/// at most [`APPROACH_FRACTION`] of it (scaled), so that the integrator approaches a change
/// point down to [`CROSS_BELOW`] instead of stepping over it: its stages would evaluate
/// where the evaluations are inaccurate (see [`CROSS_BELOW`]; a step over A02's change point
/// left its rate 4e-7 rad/s off). A step that still went over is recognised (`stepped_over`).
/// Not higher: the five-bar passes type II singularities with the passive measure at 0.05,
/// where the limit would only cost steps.
pub const WATCH_BELOW: f64 = 0.02;
/// See [`WATCH_BELOW`].
pub const APPROACH_FRACTION: f64 = 0.5;
/// A scaled pivot of Phi_x below this at the change point counts as a lost rank.
const LOST_PIVOT: f64 = 1e-4;
/// Largest projection from the prediction, as a fraction of the passive measure before the
/// point (the other branches are about that far, scaled).
const PROJECTION_FRACTION: f64 = 0.25;
/// Largest change of the predicted velocity by its projection, relative to it: the branch
/// the motion follows has its tangent to the prediction's accuracy, another branch one at an
/// O(1) angle.
const TANGENT_MISMATCH: f64 = 1e-3;
/// Golden-section steps locating the point within a crossing (0.618^40 of its length).
const LOCATE_ITERATIONS: usize = 40;
/// Lengthenings of the step tried when the point past it is still too near the singularity.
const ATTEMPTS: usize = 4;
/// Accepted points kept for the quintic: it is fitted on the latest one and the latest
/// earlier point at least half the crossing's length before it, so that it extrapolates at
/// most about twice its own span.
const KEPT: usize = 24;

/// One crossing of a change point, as the result reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct ChangePoint {
    /// Time of the crossing (s), where the passive measure extrapolates to 0.
    pub t: f64,
    /// Body coordinates (3n) and the user's coordinates (m) there.
    pub x: Vec<f64>,
    pub q: Vec<f64>,
    /// Rank Phi_x loses there: the mobility jumps by this much.
    pub rank_drop: usize,
}

/// An accepted point on the way: time, passive measure and body (x, xd, xdd).
#[derive(Debug, Clone)]
pub struct Passed {
    pub t: f64,
    pub passive: f64,
    pub x: Vec<f64>,
    pub xd: Vec<f64>,
    pub xdd: Vec<f64>,
}

impl Passed {
    fn of(ode: &MechanismOde, t: f64, passive: f64) -> Self {
        let ws = &ode.ws;
        Passed { t, passive, x: ws.x.clone(), xd: ws.xd.clone(), xdd: ws.xdd.clone() }
    }
}

/// The last accepted points (newest last), while near a passive singularity; and the energy
/// balance T + V - W before the last change point crossed, to be restored once clear of it.
///
/// Near the point the energy measured from the chart's state is itself inaccurate: the
/// position solve leaves x off the branch by its tolerance / sigma along the other branch's
/// tangent, where U, and T from the rates U zd, turn by that over sigma (like eps / sigma^2).
/// The balance restored at the landing is then off by as much, and the state carries it away:
/// on A02 at N = 40, 1e-7 to 1e-6 J after a crossing (1e-9 of T), always a gain, 1.9e-6 rad
/// after 20 s. Taken and restored where the passive measure is at least [`WATCH_BELOW`], the
/// energy is as accurate as along the integration.
#[derive(Debug, Clone, Default)]
pub struct Approach {
    passed: std::collections::VecDeque<Passed>,
    /// T + V - W at the last point kept at or above [`WATCH_BELOW`].
    balance: Option<f64>,
    /// The balance before the change point just crossed, until clear of it.
    owed: Option<f64>,
}

impl Approach {
    /// Remember the point held by `ode.ws` (accepted at t, passive measure `passive`, work
    /// `work`); far from any passive singularity only the last one is kept, with its balance.
    pub fn keep(&mut self, ode: &MechanismOde, t: f64, passive: f64, work: f64) {
        let far = passive >= WATCH_BELOW;
        let recycled = if far || self.passed.len() >= KEPT { self.passed.pop_front() } else { None };
        if far {
            self.passed.clear();
            let ws = &ode.ws;
            self.balance = Some(kinetic_energy(ode.mech, &ws.xd) + potential_energy(ode.mech, &ws.x) - work);
        }
        let ws = &ode.ws;
        match recycled {
            Some(mut p) => {
                (p.t, p.passive) = (t, passive);
                p.x.copy_from_slice(&ws.x);
                p.xd.copy_from_slice(&ws.xd);
                p.xdd.copy_from_slice(&ws.xdd);
                self.passed.push_back(p);
            }
            None => self.passed.push_back(Passed::of(ode, t, passive)),
        }
    }

    /// Forget the way (after a crossing: the points before it are on the other side), owing
    /// the balance before it.
    pub fn clear(&mut self) {
        self.passed.clear();
        self.owed = self.balance.take();
    }

    /// The factor on the rates of the point accepted in `ode.ws` (passive measure `passive`,
    /// work `work`) that restores the balance before the change point last crossed, once at
    /// or above [`WATCH_BELOW`] (see [`Approach`]); none for a change of more than
    /// [`TANGENT_MISMATCH`] (as [`keep_energy`]), nor where coordinates are driven by motion
    /// (their rates are not the state's to scale).
    pub fn restore(&mut self, ode: &MechanismOde, passive: f64, work: f64) -> Option<f64> {
        let balance = self.owed.take_if(|_| passive >= WATCH_BELOW)?;
        if ode.motion.is_some() {
            return None;
        }
        let ws = &ode.ws;
        let kinetic = kinetic_energy(ode.mech, &ws.xd);
        let scale = ((balance + work - potential_energy(ode.mech, &ws.x)) / kinetic).sqrt();
        (kinetic > 0.0 && (scale - 1.0).abs() < TANGENT_MISMATCH && scale != 1.0).then_some(scale)
    }

    /// The newest point kept.
    pub fn last(&self) -> Option<&Passed> {
        self.passed.back()
    }

    /// Up to three points before `t`, newest first, each at least `gap` before the next.
    fn samples(&self, t: f64, gap: f64) -> Vec<&Passed> {
        let mut out: Vec<&Passed> = Vec::new();
        for p in self.passed.iter().rev() {
            if out.len() < 3 && out.last().map_or(t, |q| q.t) - p.t >= gap {
                out.push(p);
            }
        }
        out
    }
}

/// Where a crossing lands: time, body coordinates, chart and chart state y = [z, zd, W]
/// past the point.
pub struct Landing {
    pub t: f64,
    pub x: Vec<f64>,
    pub chart: Chart,
    pub y: Vec<f64>,
    pub point: ChangePoint,
    /// The path the crossing followed, and the point it started from.
    pub path: Extrapolation,
    pub start: Passed,
}

/// A path x(t) of the body coordinates: position, rate and acceleration at time t.
pub trait Path {
    fn at(&self, t: f64, x: &mut [f64], xd: &mut [f64], xdd: &mut [f64]);
}

/// The Taylor step from an accepted point, its acceleration the polynomial through the
/// accelerations there and at up to three points before it:
///   x(t0 + s) = x + s xd + sum_k alpha_k s^(k+2) / ((k+1)(k+2)),  xdd(t0 + s) = sum_k alpha_k s^k.
/// It is exact for an x of degree 5 and takes the point's own x and xd as they are (the
/// quintic through two points, extrapolated twice its span, multiplies their errors by
/// ~500: 2e-7 rad/s after A02's first crossing).
pub struct Extrapolation {
    t0: f64,
    x: Vec<f64>,
    xd: Vec<f64>,
    /// alpha_k (3n each), in powers of s / `scale`.
    alpha: Vec<Vec<f64>>,
    scale: f64,
}

impl Extrapolation {
    /// From the point accepted at t0 (body state in `ws`-like slices) and earlier points
    /// `samples` (newest first), `scale` the time the step spans.
    fn new(t0: f64, (x, xd, xdd): (&[f64], &[f64], &[f64]), samples: &[&Passed], scale: f64) -> Self {
        let k = samples.len() + 1;
        let u: Vec<f64> = std::iter::once(0.0).chain(samples.iter().map(|p| (p.t - t0) / scale)).collect();
        let v = nalgebra::DMatrix::from_fn(k, k, |i, j| u[i].powi(j as i32));
        let inv = v.try_inverse().unwrap_or_else(|| nalgebra::DMatrix::identity(k, k));
        let rows: Vec<&[f64]> = std::iter::once(xdd).chain(samples.iter().map(|p| p.xdd.as_slice())).collect();
        let alpha =
            (0..k).map(|j| (0..x.len()).map(|c| (0..k).map(|i| inv[(j, i)] * rows[i][c]).sum()).collect()).collect();
        Extrapolation { t0, x: x.to_vec(), xd: xd.to_vec(), alpha, scale }
    }
}

impl Path for Extrapolation {
    fn at(&self, t: f64, x: &mut [f64], xd: &mut [f64], xdd: &mut [f64]) {
        let s = t - self.t0;
        let u = s / self.scale;
        x.copy_from_slice(&self.x);
        for (v, (x, &xd0)) in xd.iter_mut().zip(x.iter_mut().zip(&self.xd)) {
            *v = xd0;
            *x += s * xd0;
        }
        xdd.fill(0.0);
        for (k, alpha) in self.alpha.iter().enumerate() {
            let kf = k as f64;
            let (pa, pv, px) = (
                u.powi(k as i32),
                s * u.powi(k as i32) / (kf + 1.0),
                s * s * u.powi(k as i32) / ((kf + 1.0) * (kf + 2.0)),
            );
            for (i, a) in alpha.iter().enumerate() {
                xdd[i] += a * pa;
                xd[i] += a * pv;
                x[i] += a * px;
            }
        }
    }
}

/// The quintic in t through two accepted points' body (x, xd, xdd): c_0 + c_1 u + ... +
/// c_5 u^5 in u = (t - t0) / span.
pub struct Quintic {
    t0: f64,
    span: f64,
    c: [Vec<f64>; 6],
}

impl Quintic {
    pub fn new(a: &Passed, b: (&[f64], &[f64], &[f64]), tb: f64) -> Self {
        let span = tb - a.t;
        let n = a.x.len();
        let mut c: [Vec<f64>; 6] = std::array::from_fn(|_| vec![0.0; n]);
        for i in 0..n {
            let (c0, c1, c2) = (a.x[i], a.xd[i] * span, a.xdd[i] * span * span / 2.0);
            let p = b.0[i] - (c0 + c1 + c2);
            let v = b.1[i] * span - (c1 + 2.0 * c2);
            let w = b.2[i] * span * span - 2.0 * c2;
            let coefficients =
                [c0, c1, c2, 10.0 * p - 4.0 * v + w / 2.0, -15.0 * p + 7.0 * v - w, 6.0 * p - 3.0 * v + w / 2.0];
            for (ck, v) in c.iter_mut().zip(coefficients) {
                ck[i] = v;
            }
        }
        Quintic { t0: a.t, span, c }
    }
}

impl Path for Quintic {
    fn at(&self, t: f64, x: &mut [f64], xd: &mut [f64], xdd: &mut [f64]) {
        let (u, s) = ((t - self.t0) / self.span, self.span);
        let c = &self.c;
        for i in 0..x.len() {
            x[i] = c[0][i] + u * (c[1][i] + u * (c[2][i] + u * (c[3][i] + u * (c[4][i] + u * c[5][i]))));
            xd[i] = (c[1][i] + u * (2.0 * c[2][i] + u * (3.0 * c[3][i] + u * (4.0 * c[4][i] + u * 5.0 * c[5][i])))) / s;
            xdd[i] = (2.0 * c[2][i] + u * (6.0 * c[3][i] + u * (12.0 * c[4][i] + u * 20.0 * c[5][i]))) / (s * s);
        }
    }
}

/// The time from the point accepted at `t` (passive measure `passive`) to the change point
/// ahead, from the points before it: the passive measure falls linearly to 0 at a
/// transversal crossing.
fn time_to_point(approach: &Approach, t: f64, passive: f64) -> Option<f64> {
    let last = approach.passed.iter().rev().find(|p| p.t < t)?;
    let to_point = passive * (t - last.t) / (last.passive - passive);
    (last.passive > passive && to_point > 0.0 && to_point.is_finite()).then_some(to_point)
}

/// Whether the step from the last point kept to the one accepted at `t` (held by `ode.ws`,
/// passive measure `passive`) went over a change point, and the point, located on the
/// quintic through the step's two ends. From a point near it (below [`WATCH_BELOW`]) the
/// measure fell towards 0 before it and rose after it as |t - t*| does (a V), not as past a
/// minimum above 0 (the V's linear extrapolation only tells that it is there: at its time
/// Phi_x's pivots can still be above [`LOST_PIVOT`]). A step from farther away, whose moves
/// are not bounded, can land past the point anywhere in the watched range (below
/// [`WATCH_BELOW`]; A02 at N = 5 from 0.027 to 0.013 past it), the measure still falling as
/// seen from before it; only the path between tells: Phi_x loses rank inside the step.
pub fn stepped_over(ode: &MechanismOde, approach: &Approach, t: f64, passive: f64) -> Option<ChangePoint> {
    let last = approach.last().filter(|p| p.t < t)?;
    let near = last.passive < WATCH_BELOW;
    if near {
        let to_point = time_to_point(approach, last.t, last.passive)?;
        let t_star = last.t + to_point;
        let expected = last.passive / to_point * (t - t_star);
        if !(t_star < t && passive > 0.5 * expected && passive < 2.0 * expected) {
            return None;
        }
    } else if passive >= WATCH_BELOW {
        return None;
    }
    let ws = &ode.ws;
    let path = Quintic::new(last, (&ws.x, &ws.xd, &ws.xdd), t);
    let point = change_point(ode.mech, &path, locate(ode.mech, &path, last.t, t));
    // Located at the step's end, the point is still ahead (golden section ends within
    // 0.618^40 of an end where the pivot only falls).
    let inside = point.t < t - 1e-6 * (t - last.t);
    (near || (point.rank_drop > 0 && inside)).then_some(point)
}

/// Cross the change point ahead of the point accepted at `t` with passive measure `passive`
/// (held by `ode.ws`, evaluated), with the points before it in `approach`; `work` is the
/// work W there. Err says why the motion cannot be continued.
pub fn cross(ode: &mut MechanismOde, t: f64, passive: f64, work: f64, approach: &Approach) -> Result<Landing, String> {
    let mech = ode.mech;
    let (n, m) = (ode.ws.x.len(), mech.dof());
    let to_point = time_to_point(approach, t, passive).ok_or_else(|| {
        format!("the time to the change point could not be estimated (passive measure {passive:.2e})")
    })?;
    let start = Passed::of(ode, t, passive);
    let ws = &ode.ws;
    let samples = approach.samples(t, to_point / 2.0);
    let path = Extrapolation::new(t, (&ws.x, &ws.xd, &ws.xdd), &samples, to_point);
    let power = ws.power;
    let energy = kinetic_energy(mech, &ws.xd) + potential_energy(mech, &ws.x);
    let (mut x, mut xd, mut xdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut why = String::new();
    for attempt in 0..ATTEMPTS {
        let h = 2.0 * to_point * f64::from(1u32 << attempt);
        path.at(t + h, &mut x, &mut xd, &mut xdd);
        match project(ode, &x, &xd, passive) {
            Ok((chart, past)) if past >= 0.5 * passive => {
                keep_energy(ode, energy + h * power);
                let mut y = vec![0.0; 2 * m + 1];
                if let Chart::Partition(idx) = &chart {
                    for (k, &i) in idx.iter().enumerate() {
                        (y[k], y[m + k]) = (ode.ws.x[i], ode.ws.xd[i]);
                    }
                }
                y[2 * m] = work + h * power;
                let point = change_point(mech, &path, locate(mech, &path, t, t + h));
                return Ok(Landing { t: t + h, x: ode.ws.x.clone(), chart, y, point, path, start });
            }
            Ok((_, past)) => why = format!("{h:.2e} s past it the passive measure is still {past:.2e}"),
            Err(e) => {
                why = e;
                break;
            }
        }
    }
    Err(format!("no branch continues the motion through the change point: {why}"))
}

/// Scale the rates `ode.ws.xd` so that T + V = `energy` (J): the balance T + V - W holds
/// across the crossing as along the integration, W growing by the power before it times the
/// crossing's length. On a branch of mobility 1 the direction of xd is the tangent's, so
/// this makes the rate exact for the position; any branch keeps its energy. A change of more
/// than [`TANGENT_MISMATCH`] is not made (the projection's test already bounds it).
fn keep_energy(ode: &mut MechanismOde, energy: f64) {
    let ws = &mut ode.ws;
    let kinetic = kinetic_energy(ode.mech, &ws.xd);
    let target = energy - potential_energy(ode.mech, &ws.x);
    let scale = (target / kinetic).sqrt();
    if kinetic > 0.0 && (scale - 1.0).abs() < TANGENT_MISMATCH {
        ws.xd.iter_mut().for_each(|v| *v *= scale);
    }
}

/// Project the predicted (x, xd) onto the constraints and their tangent in the partition
/// chosen at x; the chart and the passive measure there, or why it is not the motion's branch.
fn project(ode: &mut MechanismOde, x: &[f64], xd: &[f64], passive: f64) -> Result<(Chart, f64), String> {
    let mech = ode.mech;
    let idx = select_partition(mech, x);
    let chart = Chart::Partition(idx.clone());
    let ws = &mut ode.ws;
    ws.chart = chart.clone();
    ws.x.copy_from_slice(x);
    let z: Vec<f64> = idx.iter().map(|&i| x[i]).collect();
    solve_position(mech, &z, ws).map_err(|e| format!("the predicted point does not assemble: {e}"))?;
    let moved = scaled_distance(&ws.x, x, ws.sys.group_col_scale());
    if moved > PROJECTION_FRACTION * passive {
        return Err(format!("the predicted point is {moved:.2e} from the nearest branch (scaled)"));
    }
    velocity_analogues(ws).map_err(|e| format!("no tangent past the point: {e}"))?;
    let n = x.len();
    ws.xd.fill(0.0);
    for (j, &i) in idx.iter().enumerate() {
        for (v, u) in ws.frame.xd.iter_mut().zip(&ws.frame.u[j * n..(j + 1) * n]) {
            *v += u * xd[i];
        }
    }
    let scale = ws.sys.group_col_scale();
    let speed = xd.iter().zip(scale).fold(0.0, |s: f64, (v, l)| s.max((v / l).abs()));
    let mismatch = scaled_distance(&ws.xd, xd, scale);
    if mismatch > TANGENT_MISMATCH * speed {
        return Err(format!("the branch's tangent differs from the motion's by {:.2e} of its speed", mismatch / speed));
    }
    Ok((chart, passive_sigma_min(mech, &ws.x)))
}

/// The change point at time `t` on `path`: its configuration and the rank Phi_x loses
/// there (scaled pivots of complete pivoting below [`LOST_PIVOT`]).
fn change_point(mech: &Mechanism, path: &dyn Path, t: f64) -> ChangePoint {
    let n = mech.n_x();
    let (mut x, mut xd, mut xdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    path.at(t, &mut x, &mut xd, &mut xdd);
    let mut q = vec![0.0; mech.dof()];
    coordinates(mech, &x, &mut q);
    ChangePoint { t, rank_drop: rank_drop(mech, &x), x, q }
}

/// The scaled pivots of complete pivoting on Phi_x at x, in pivot order (fewer than its
/// rows where one is exactly 0).
fn pivots(mech: &Mechanism, x: &[f64]) -> Vec<f64> {
    let (n, rows) = (x.len(), mech.n_constraints);
    let mut a = scaled_phi_x(mech, x);
    let columns = pivot_columns(&mut a, rows, n, rows);
    columns.iter().enumerate().map(|(k, &c)| a[k * n + c].abs()).collect()
}

/// Rank Phi_x has lost at x against a regular point (3n - m).
fn rank_drop(mech: &Mechanism, x: &[f64]) -> usize {
    let rank = pivots(mech, x).iter().filter(|&&p| p > LOST_PIVOT).count();
    (x.len() - mech.dof()).saturating_sub(rank)
}

/// The time in [a, b] where `path` passes the change point: where the smallest of Phi_x's
/// regular pivots (0 at the point, growing as |t - t*| on either side) is least, by golden
/// section. The passive measure's own V is not symmetric enough (the partition chosen on
/// either side differs): located from it, A02's point was 3e-6 rad off.
fn locate(mech: &Mechanism, path: &dyn Path, mut a: f64, mut b: f64) -> f64 {
    let n = mech.n_x();
    let regular = n - mech.dof();
    let (mut x, mut xd, mut xdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut f = |t: f64| {
        path.at(t, &mut x, &mut xd, &mut xdd);
        let p = pivots(mech, &x);
        if p.len() < regular {
            0.0
        } else {
            p.iter().fold(f64::INFINITY, |m: f64, &v| m.min(v))
        }
    };
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - r * (b - a), a + r * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..LOCATE_ITERATIONS {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - r * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    (a + b) / 2.0
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
