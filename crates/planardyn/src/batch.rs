//! Batch runs: many variants of a mechanism (parameter sweeps, Monte Carlo over lengths,
//! masses, loads and start states) simulated in parallel on a rayon thread pool.
//!
//! A variant is a model plus its [`Overrides`] of the model's `simulate` defaults. The
//! [`Mechanism`] is immutable and `Send + Sync`, so variants may share one; every task makes
//! its own [`crate::Workspace`] inside [`simulate`](crate::simulate::simulate). Each variant
//! gets its own `Result`: a failing one (a start that cannot be assembled, invalid
//! settings) leaves the others untouched. The outputs are in the order of the inputs and
//! equal, bit for bit, those of a serial loop: a run does not depend on which thread it
//! lands on.
//!
//! Inverse dynamics runs the same way ([`inverse_many`]): each variant a model and a motion,
//! either in the coordinates (q, qd, qdd rows) or of an end effector along a sampled path
//! ([`crate::dynamics::task`], also behind `planardyn.robot.solve_motion`), e.g. many designs
//! of a robot on one task, or many tasks of one robot.

pub mod task;

use crate::dynamics::{self, ModelDrives};
use crate::kinematics::{assemble_from, assemble_into, continue_to};
use crate::simulate::charts::SWITCH_TO_PARTITION;
pub use crate::simulate::Overrides;
use crate::simulate::{simulate_prepared, Observe, Prepared, Trajectory};
use crate::{Error, KinematicsError, Mechanism, Workspace};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use task::{TaskError, TaskPath, TaskSolution};

/// One variant: its mechanism (shared, not copied) and its settings. Edited specifications
/// are built by the loader first (`crate::build`, in parallel with [`map_many`]): the
/// batch runs built mechanisms only, as the engine below the loader.
#[derive(Debug, Clone)]
pub struct Variant {
    pub model: Arc<Mechanism>,
    pub overrides: Overrides,
}

impl Variant {
    /// Set up and simulate with the model's drives, in the caller's thread.
    pub fn simulate(&self) -> Result<Trajectory, Error> {
        self.simulate_until(&AtomicBool::new(false))
    }

    /// [`Variant::simulate`] (the coordinates of the overrides' and the model's motions
    /// driven by them), stopping at the first step after `stop` is set (status
    /// `Cancelled`, the trajectory so far kept).
    pub fn simulate_until(&self, stop: &AtomicBool) -> Result<Trajectory, Error> {
        self.simulate_prepared(&Prepared::new(&self.model), stop)
    }

    /// [`Variant::simulate_until`] with the set-up of its model's runs made once for them all
    /// ([`Prepared::new`] of `self.model`; the trajectory is the same, to the bit).
    pub fn simulate_prepared(&self, prepared: &Prepared, stop: &AtomicBool) -> Result<Trajectory, Error> {
        let mech = &*self.model;
        let settings = self.overrides.settings(mech)?;
        let mut motion = self.overrides.prescribed(mech)?;
        let mut go_on = |_t: f64| !stop.load(Ordering::Relaxed);
        let (drives, observe) = (&mut ModelDrives(mech), Observe::default());
        simulate_prepared(mech, prepared, &settings, drives, &mut motion, observe, Some(&mut go_on))
    }
}

/// The motion whose drive efforts a variant asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion {
    /// Time-major rows (N x m) of coordinates (rad or m), rates and accelerations.
    Coordinates { q: Vec<f64>, qd: Vec<f64>, qdd: Vec<f64> },
    /// An end-effector path, solved for the inputs first.
    Task(TaskPath),
}

/// Drive efforts of a [`Motion::Coordinates`] (tau rows, N x m) or the solved task motion.
#[derive(Debug, Clone, PartialEq)]
pub enum Efforts {
    Coordinates(Vec<f64>),
    Task(TaskSolution),
}

/// One inverse-dynamics variant: its model and its motion.
#[derive(Debug, Clone)]
pub struct InverseVariant {
    pub model: Arc<Mechanism>,
    pub motion: Motion,
}

impl InverseVariant {
    /// Solve, in the caller's thread.
    pub fn solve(&self) -> Result<Efforts, TaskError> {
        let mech = &*self.model;
        match &self.motion {
            Motion::Coordinates { q, qd, qdd } => Ok(Efforts::Coordinates(inverse_rows(mech, q, qd, qdd)?)),
            Motion::Task(path) => Ok(Efforts::Task(task::solve(mech, path)?)),
        }
    }
}

/// Which branch of the position analysis the rows of a motion are on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Branch<'a> {
    /// The drawn one: the first row by continuation from the drawing, each next row from
    /// the previous one.
    Drawing,
    /// The one through these body coordinates (3n, e.g. a result's first row), then row to row.
    From(&'a [f64]),
    /// Each row's own body coordinates (N x 3n, as a simulation records them): exact whatever
    /// branches the motion went through; with each row's body rates xd too (N x 3n, a
    /// simulation's), which near a type II singularity hold the state more exactly than qd
    /// (one rounding unit of qd moves the rates J xd = [0; qd] gives by eps/sigma). Rows whose
    /// xd and qd disagree by more than [`RATES_TOL`] are refused.
    Rows(&'a [f64], Option<&'a [f64]>),
    /// A run's own rows (a simulation's x and xd): as `Rows` with the rates, which are not
    /// checked against qd. They are the run's state; where it prescribes coordinates its qd are
    /// the motion's, and J xd meets them only within the integrator's error, magnified near a
    /// fold of the driven coordinates (five-bar-robot, theta1 at 1 rad/s: 1.1e-7 relative
    /// 0.03 s before its fold, 1.2e-6 at 5.5e-5 s, rtol 1e-9), past [`RATES_TOL`].
    Run(&'a [f64], &'a [f64]),
}

impl Branch<'_> {
    /// `Rows` with rates as a run's own rows ([`Branch::Run`]); any other branch as it is.
    pub fn recorded(self) -> Self {
        match self {
            Branch::Rows(x, Some(xd)) => Branch::Run(x, xd),
            other => other,
        }
    }
}

/// A motion given by q alone whose continuation passes below this type II measure is
/// refused ([`Error::BranchUndecided`]): there the two branches meet, and a motion through
/// the singularity may leave on either (the free-falling five-bar does). The integrator's own
/// threshold for leaving the input chart (`simulate::charts::SWITCH_TO_PARTITION`).
pub const BRANCH_SIGMA: f64 = SWITCH_TO_PARTITION;

/// The largest mismatch of given body rates xd with a row's qd, relative to the rates' own scale
/// (the largest translational and angular body rate: [`dynamics::rates_mismatch`]), accepted:
/// round-off leaves a few eps, whatever J's conditioning; the rates of another state are off by
/// more than this fraction of that scale (one body's rate 1e-6 rad/s off, about 1e-7 of it, is
/// refused in tests/test_dynamics.py, 1e-12 rad/s accepted). Rates accepted this way give the
/// same efforts to about this fraction of the velocity terms' size.
pub const RATES_TOL: f64 = 1e-10;

/// Drive efforts (N x m, N m or N) along rows of q, qd, qdd (N x m each) on the drawn branch;
/// see [`inverse_rows_on`].
pub fn inverse_rows(mech: &Mechanism, q: &[f64], qd: &[f64], qdd: &[f64]) -> Result<Vec<f64>, Error> {
    inverse_rows_on(mech, Branch::Drawing, q, qd, qdd)
}

/// Drive efforts (N x m, N m or N) along rows of q, qd, qdd (N x m each) on `branch`. With
/// q alone (`Drawing`, `From`) each row continues from the previous one, and a motion that
/// goes on past a row where the branch followed is within [`BRANCH_SIGMA`] of a type II
/// singularity is refused ([`Error::BranchUndecided`]) rather than guessed; with `Rows` each row is solved from its
/// own body coordinates.
pub fn inverse_rows_on(
    mech: &Mechanism,
    branch: Branch<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> Result<Vec<f64>, Error> {
    inverse_rows_checked(mech, branch, q, qd, qdd, false)
}

/// [`inverse_rows_on`], refusing a row whose type II measure is below
/// [`dynamics::SINGULAR_SIGMA`] (`KinematicsError::Singular` with it) unless `allow_singular`.
pub fn inverse_rows_checked(
    mech: &Mechanism,
    branch: Branch<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    allow_singular: bool,
) -> Result<Vec<f64>, Error> {
    let mut tau = Vec::with_capacity(q.len());
    inverse_walk(mech, branch, q, qd, qdd, allow_singular, |ws| tau.extend_from_slice(&ws.tau))?;
    Ok(tau)
}

/// Motor torques (N x w, N m) along rows of a motion on `branch` (as
/// [`inverse_rows_checked`]): of the joint-side efforts `tau` (N x w: the first w actuators'
/// efforts, the coordinates' then the pair actuators', e.g. a run's tau or shared efforts),
/// or of the motion's own inverse dynamics (w = m) when `tau` is `None`; at each row's rates
/// and accelerations (`dynamics::motor_torques`: a rotor takes its own torque before its gear).
/// Each row's outcome: a row whose losses fail ([`row_failure`]: its friction efforts do not
/// settle, its gears jam) has none, the others are kept
/// ([`MotorTorqueRows::into_values`] for all or the first failure). Motor torques that overflow,
/// and the failures of the walk itself (arguments, assembly, branch), fail the whole call.
#[allow(clippy::too_many_arguments)]
pub fn motor_torque_rows(
    mech: &Mechanism,
    branch: Branch<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    tau: Option<(&[f64], usize)>,
    allow_singular: bool,
) -> Result<MotorTorqueRows, Error> {
    let w = tau.map_or(mech.dof(), |(_, w)| w);
    let m = mech.dof().max(1);
    let mut out = MotorTorqueRows { values: Vec::with_capacity(q.len() / m * w), unsolved: Vec::new() };
    let mut row = vec![0.0; w];
    walk_rows(mech, branch, q, qd, qdd, allow_singular, |ws, rows, xd| {
        let k = rows.start / m;
        let (q, qd, qdd) = (&q[rows.clone()], &qd[rows.clone()], &qdd[rows]);
        match dynamics::inverse_at_rates(mech, q, qd, qdd, xd, ws) {
            Ok(()) => {
                let given = tau.map_or(&ws.tau[..], |(tau, w)| &tau[k * w..(k + 1) * w]);
                dynamics::motor_torques(mech, ws, given, &mut row);
                out.values.extend_from_slice(dynamics::finite("motor torques", &row)?);
            }
            Err(e) => {
                let Some(reason) = row_failure(&e) else { return Err(e.into()) };
                out.values.extend(std::iter::repeat_n(f64::NAN, w));
                out.unsolved_row(k, &reason, e);
            }
        }
        Ok(())
    })?;
    Ok(out)
}

/// Why a row has no motor torques when its inverse dynamics failing with `e` fails that row
/// alone: its losses (the friction efforts that do not settle, the gears that jam there), which
/// leave the next rows' evaluations as they are. `None` for the failures of the query: its
/// arguments (`BadArgument`, `Overflow`), a row's kinematics (`AssemblyFailed`, `Singular`,
/// which the walk's measure then reads), and `EffortSharing`, which no row's inverse dynamics
/// raises.
fn row_failure(e: &KinematicsError) -> Option<String> {
    match e {
        // Not the iterations, which a diverging row's cut short: its span's next rows' may differ.
        KinematicsError::FrictionUnsettled { .. } => Some("the friction efforts did not settle".into()),
        KinematicsError::GearsJammed { actuators } => {
            Some(format!("the gears of {actuators} admit no consistent motion"))
        }
        KinematicsError::AssemblyFailed { .. }
        | KinematicsError::Singular { .. }
        | KinematicsError::EffortSharing { .. }
        | KinematicsError::Overflow { .. }
        | KinematicsError::BadArgument { .. } => None,
    }
}

/// [`motor_torque_rows`]' result: every row's motor torques, and the rows without.
#[derive(Debug, Clone, PartialEq)]
pub struct MotorTorqueRows {
    /// N x w motor torques (N m), NaN on the rows in `unsolved`.
    pub values: Vec<f64>,
    /// The rows whose losses failed, in order: each span consecutive rows failing for the same
    /// reason, so that their number stays that of the failures' runs.
    pub unsolved: Vec<UnsolvedRows>,
}

impl MotorTorqueRows {
    /// The values when every row has them, else the first unsolved row's failure.
    pub fn into_values(self) -> Result<Vec<f64>, Error> {
        match self.unsolved.into_iter().next() {
            Some(span) => Err(span.error.into()),
            None => Ok(self.values),
        }
    }

    /// What a run's message says of its rows without motor torques, `t` the rows' times (s,
    /// one per row): "no motor torques at rows 10314-10317 (t = 3.0912-3.0915 s): the friction
    /// efforts did not settle", consecutive spans of one reason together, the reasons' notes
    /// joined by "; "; `None` when every row has them.
    pub fn note(&self, t: &[f64]) -> Option<String> {
        let mut note = String::new();
        for spans in self.unsolved.chunk_by(|a, b| a.reason() == b.reason()) {
            if !note.is_empty() {
                note.push_str("; ");
            }
            write_note(&mut note, spans, Some(t)).expect("a String takes any text");
        }
        (!note.is_empty()).then_some(note)
    }

    /// Row k failed with `error` for `reason`: its span's, when the row before failed for the
    /// same reason, else a new span.
    fn unsolved_row(&mut self, k: usize, reason: &str, error: KinematicsError) {
        match self.unsolved.last_mut() {
            Some(span) if span.rows.end == k && span.reason() == reason => span.rows.end = k + 1,
            _ => self.unsolved.push(UnsolvedRows { rows: k..k + 1, error }),
        }
    }
}

/// Consecutive rows without motor torques: their indices and the first one's error (with the
/// iterations and the last change), which says why ([`UnsolvedRows::reason`]).
#[derive(Debug, Clone, PartialEq)]
pub struct UnsolvedRows {
    pub rows: std::ops::Range<usize>,
    pub error: KinematicsError,
}

impl UnsolvedRows {
    /// Why the rows have no motor torques ("the friction efforts did not settle"), from the error.
    pub fn reason(&self) -> String {
        row_failure(&self.error).unwrap_or_else(|| self.error.to_string())
    }
}

impl std::fmt::Display for UnsolvedRows {
    /// "no motor torques at rows 10314-10317: the friction efforts did not settle" ("... at
    /// row 7: ..."), a run's note ([`MotorTorqueRows::note`]) of these rows alone, without times.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write_note(f, std::slice::from_ref(self), None)
    }
}

/// The most spans of rows failing for one reason that a run's note names.
const NAMED_SPANS: usize = 8;

/// The note of `spans`, consecutive and failing for one reason, with the rows' times `t` when
/// given: "no motor torques at rows 2-3 (t = 0.2-0.3 s), row 5 (t = 0.5 s): why", the first
/// [`NAMED_SPANS`] named, then "and 3 more spans of rows".
fn write_note(f: &mut impl std::fmt::Write, spans: &[UnsolvedRows], t: Option<&[f64]>) -> std::fmt::Result {
    f.write_str("no motor torques at ")?;
    for (i, span) in spans.iter().take(NAMED_SPANS).enumerate() {
        let (a, b) = (span.rows.start, span.rows.end - 1);
        let sep = if i == 0 { "" } else { ", " };
        match t {
            None if a == b => write!(f, "{sep}row {a}")?,
            None => write!(f, "{sep}rows {a}-{b}")?,
            Some(t) if a == b => write!(f, "{sep}row {a} (t = {} s)", Digits10(t[a]))?,
            Some(t) => write!(f, "{sep}rows {a}-{b} (t = {}-{} s)", Digits10(t[a]), Digits10(t[b]))?,
        }
    }
    if spans.len() > NAMED_SPANS {
        write!(f, " and {} more spans of rows", spans.len() - NAMED_SPANS)?;
    }
    write!(f, ": {}", spans[0].reason())
}

/// A time to 10 significant digits, as C's and Python's `%.10g` print it: trailing zeros
/// dropped, in exponent form ("1.5e-05") below 1e-4 and from 1e10 (the text Python's results
/// showed before the core wrote it). A run's last steps into a fold are down to 6e-12 s: the
/// row numbers tell such rows apart, the times say where they are.
struct Digits10(f64);

impl std::fmt::Display for Digits10 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const P: i32 = 10;
        let v = self.0;
        let e = format!("{v:.*e}", (P - 1) as usize);
        let Some((mantissa, exp)) = e.split_once('e') else { return write!(f, "{v}") }; // NaN, inf
        let exp: i32 = exp.parse().expect("Rust's exponent is an integer");
        let trim = |s: &str| {
            if s.contains('.') {
                s.trim_end_matches('0').trim_end_matches('.').to_owned()
            } else {
                s.to_owned()
            }
        };
        if (-4..P).contains(&exp) {
            // The same digits: the exponent is the rounded value's.
            write!(f, "{}", trim(&format!("{v:.*}", (P - 1 - exp) as usize)))
        } else {
            write!(f, "{}e{}{:02}", trim(mantissa), if exp < 0 { '-' } else { '+' }, exp.abs())
        }
    }
}

/// Inverse dynamics at every row of a motion on `branch` (as [`inverse_rows_checked`]),
/// `keep` taking what it needs from each row's workspace.
fn inverse_walk(
    mech: &Mechanism,
    branch: Branch<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    allow_singular: bool,
    mut keep: impl FnMut(&Workspace),
) -> Result<(), Error> {
    walk_rows(mech, branch, q, qd, qdd, allow_singular, |ws, row, xd| {
        dynamics::inverse_at_rates(mech, &q[row.clone()], &qd[row.clone()], &qdd[row], xd, ws)?;
        keep(ws);
        Ok(())
    })
}

/// The power (W, >= 0) the pairs' Coulomb friction dissipates along rows of a motion, on
/// `branch` (as [`inverse_rows_checked`], whose efforts include that friction).
pub fn dissipation_rows(
    mech: &Mechanism,
    branch: Branch<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    allow_singular: bool,
) -> Result<Vec<f64>, Error> {
    let mut out = Vec::with_capacity(q.len() / mech.dof().max(1));
    inverse_walk(mech, branch, q, qd, qdd, allow_singular, |ws| out.push(ws.dissipated))?;
    Ok(out)
}

/// The regressor form along rows of a motion on `branch` (as [`inverse_rows_checked`], with
/// a result's body rates when given): Y (N x m x p, p = [`dynamics::regressor::n_parameters`])
/// and tau_o (N x m), so that every row's efforts are Y pi + tau_o.
pub fn regressor_rows(
    mech: &Mechanism,
    branch: Branch<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    allow_singular: bool,
) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let p = dynamics::regressor::n_parameters(mech);
    let m = mech.dof().max(1);
    let (mut y, mut tau_o) = (vec![0.0; q.len() * p], vec![0.0; q.len()]);
    walk_rows(mech, branch, q, qd, qdd, allow_singular, |ws, row, xd| {
        let k = row.start / m;
        let (y_row, tau_row) = (&mut y[k * m * p..(k + 1) * m * p], &mut tau_o[row.clone()]);
        let (q, qd, qdd) = (&q[row.clone()], &qd[row.clone()], &qdd[row]);
        dynamics::regressor::regressor(mech, q, qd, qdd, xd, ws, y_row, tau_row)?;
        Ok(())
    })?;
    Ok((y, tau_o))
}

/// Assemble every row of (q, qd, qdd) on `branch` in one workspace and call `each` with the
/// row's index range and given body rates (which computes into the workspace); then the
/// given rates' agreement with qd (within [`RATES_TOL`]) and the type II measure: below
/// [`dynamics::SINGULAR_SIGMA`] refused unless `allow_singular`, and with q alone (no `Rows`)
/// a motion that goes on past a row within [`BRANCH_SIGMA`] refused as `BranchUndecided`.
fn walk_rows(
    mech: &Mechanism,
    branch: Branch<'_>,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    allow_singular: bool,
    mut each: impl FnMut(&mut Workspace, std::ops::Range<usize>, Option<&[f64]>) -> Result<(), Error>,
) -> Result<(), Error> {
    let (m, nx) = (mech.dof(), mech.n_x());
    if m == 0 || !q.len().is_multiple_of(m) || qd.len() != q.len() || qdd.len() != q.len() {
        return Err(KinematicsError::bad_argument(
            "q, qd, qdd",
            format!("the same number of rows of {m} values each"),
            format!("{}, {} and {} values", q.len(), qd.len(), qdd.len()),
        )
        .into());
    }
    let n = q.len() / m;
    // The rows' own body coordinates and rates, and whether the rates are checked against qd.
    let (rows, check_rates) = match branch {
        Branch::Rows(x, xd) => (Some((x, xd)), true),
        Branch::Run(x, xd) => (Some((x, Some(xd))), false),
        Branch::From(_) | Branch::Drawing => (None, false),
    };
    if let Some((x, xd)) = rows {
        for (name, v) in [("x", Some(x)), ("xd", xd)] {
            let Some(v) = v else { continue };
            if v.len() != n * nx {
                let expected = format!("{n} rows of {nx} body values, one per row of q");
                return Err(KinematicsError::bad_argument(name, expected, format!("{} values", v.len())).into());
            }
        }
        if let Some(k) = xd.and_then(|xd| xd.iter().position(|v| !v.is_finite())) {
            let got = format!("{} in row {}", xd.unwrap_or_default()[k], k / nx);
            return Err(KinematicsError::bad_argument("xd", "finite body rates", got).into());
        }
    }
    let mut ws = Workspace::new(mech);
    let mut jac = Vec::new();
    for k in 0..n {
        let row = k * m..(k + 1) * m;
        let mut xd_row = None;
        match (branch, rows, k) {
            (_, Some((x, xd)), _) => {
                assemble_from(mech, &x[k * nx..(k + 1) * nx], &q[row.clone()], &mut ws)?;
                xd_row = xd.map(|xd| &xd[k * nx..(k + 1) * nx]);
            }
            (Branch::From(x), _, 0) => assemble_from(mech, x, &q[row.clone()], &mut ws)?,
            (Branch::Drawing, _, 0) => assemble_into(mech, &q[row.clone()], &mut ws)?,
            _ => continue_to(mech, &q[row.start - m..row.start], &q[row.clone()], &mut ws)?,
        }
        each(&mut ws, row.clone(), xd_row)?;
        if let Some(xd) = xd_row.filter(|_| check_rates) {
            jac.resize(nx * nx, 0.0);
            let mismatch = dynamics::rates_mismatch(mech, &ws, &qd[row], xd, &mut jac);
            if mismatch > RATES_TOL {
                let expected = format!("the body rates of row {k}'s qd (J xd = [0; qd] within {RATES_TOL:e} relative)");
                let got =
                    format!("a relative mismatch of {mismatch:.2e} in row {k}: pass the xd of the same rows as q, qd");
                return Err(KinematicsError::bad_argument("xd", expected, got).into());
            }
        }
        let sigma_min = dynamics::type_ii_measure(mech, &mut ws, allow_singular)?;
        // Only the rows after a near-singular one are in doubt.
        if rows.is_none() && k + 1 < n && sigma_min < BRANCH_SIGMA {
            return Err(Error::BranchUndecided { row: k, sigma_min, tol: BRANCH_SIGMA });
        }
    }
    Ok(())
}

/// A pool of `threads` threads (`None` or 0: one per core). Fails only if the operating
/// system refuses the threads.
fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, Error> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .thread_name(|i| format!("planardyn-batch-{i}"))
        .build()
        .map_err(|e| Error::Options(format!("cannot start the batch thread pool: {e}")))
}

/// Apply `f` to every item on a pool of `threads` threads (`None` or 0: one per core), the
/// results in input order.
pub fn map_many<T: Sync, R: Send>(
    items: &[T],
    threads: Option<usize>,
    f: impl Fn(&T) -> R + Sync + Send,
) -> Result<Vec<R>, Error> {
    // One item a task: runs take from milliseconds to seconds, so work stealing balances
    // them better than fixed chunks.
    Ok(pool(threads)?.install(|| items.par_iter().with_max_len(1).map(&f).collect()))
}

/// [`map_many`] that another thread can stop (on Ctrl-C, a closed window...) by setting
/// `stop`: the items not started by then are `None`; `f` gets the flag too, so a long item
/// can stop early ([`Variant::simulate_until`]). `enter` runs on every thread of the pool
/// before its first item and `leave` after the last (a caller's per-thread context, made once
/// a batch rather than once an item: the Python binding's interpreter state of each thread).
pub fn map_many_until<T: Sync, R: Send>(
    items: &[T],
    threads: Option<usize>,
    stop: &AtomicBool,
    f: impl Fn(&T, &AtomicBool) -> R + Sync + Send,
    (enter, leave): (impl Fn() + Sync, impl Fn() + Sync),
) -> Result<Vec<Option<R>>, Error> {
    let one = |item: &T| (!stop.load(Ordering::Relaxed)).then(|| f(item, stop));
    let pool = pool(threads)?;
    pool.broadcast(|_| enter());
    let out = pool.install(|| items.par_iter().with_max_len(1).map(one).collect());
    pool.broadcast(|_| leave());
    Ok(out)
}

/// Simulate every variant in parallel on `threads` threads (`None`: all cores). The outer
/// `Err` only when no thread pool can be made; one `Result` per variant otherwise.
pub fn simulate_many(variants: &[Variant], threads: Option<usize>) -> Result<Vec<Result<Trajectory, Error>>, Error> {
    map_many(variants, threads, Variant::simulate)
}

/// Solve every inverse-dynamics variant in parallel on `threads` threads (`None`: all
/// cores), on the same pool as [`simulate_many`]; one `Result` per variant, in input order.
pub fn inverse_many(
    variants: &[InverseVariant],
    threads: Option<usize>,
) -> Result<Vec<Result<Efforts, TaskError>>, Error> {
    map_many(variants, threads, InverseVariant::solve)
}

#[cfg(test)]
mod tests {
    use super::Digits10;

    #[test]
    fn times_print_as_pythons_10g() {
        // Each value's `'%.10g' % v` in Python 3.11: its rounding at the tenth digit (up and down,
        // into the next power of ten, a binary tie to even), the forms' bounds, signs and zeros.
        let cases = [
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (0.1 + 0.2, "0.3"),
            (1.0295874723456, "1.029587472"),
            (3.0912345678912, "3.091234568"),
            (1e-4, "0.0001"),
            (9.99999999995e-5, "0.0001"),
            (1.5e-5, "1.5e-05"),
            (6e-12, "6e-12"),
            (123456789.987, "123456790"),
            (1234567890.5, "1234567890"),
            (9999999999.5, "1e+10"),
            (1e10, "1e+10"),
            (12345678912.0, "1.234567891e+10"),
            (-2.5e-7, "-2.5e-07"),
            (9.9999999995, "9.999999999"),
            (0.00012345678915, "0.0001234567891"),
        ];
        for (v, want) in cases {
            assert_eq!(Digits10(v).to_string(), want, "{v:e}");
        }
    }
}
