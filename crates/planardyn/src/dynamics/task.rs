//! Task-space inverse dynamics: the inputs and drive efforts that move an end effector along a
//! prescribed path. Per sample i of the sampled path (t_i, X_i, Xd_i, Xdd_i):
//!
//! ```text
//! q_i    Newton on X(q) = X_i from the predictor q + qd h + qdd h^2 / 2 (same working mode)
//! qd_i   J_t qd = Xd_i
//! qdd_i  J_t qdd = Xdd_i - J_t' qd_i              (the acceleration analogues)
//! sigma  type I (scaled J_t) and type II (kinematics) measures; refused below the tolerance
//! tau_i  inverse dynamics at (q_i, qd_i, qdd_i)
//! ```
//!
//! One workspace follows the path: every sample starts from the previous one's body
//! coordinates, so the whole motion stays on one branch. Where a sample cannot be solved, or a
//! measure dips below the tolerance between two samples, the error names the time, the pose
//! and which singularity stops the motion, and carries the motion solved up to there.

use crate::dynamics;
use crate::kinematics::constraints::coordinates;
use crate::kinematics::effector::{solve_square, Effector, EffectorError, EffectorState};
use crate::kinematics::{convective, sigma_min_with, solve_position, Chart, System};
use crate::model::Mechanism;
use crate::{Error, KinematicsError, Workspace};
use thiserror::Error as ThisError;

/// Largest departure (rad for angles, L for displacements) of a solved q from the second-order
/// predictor: beyond it the solution has jumped to another working mode.
pub const JUMP_TOL: f64 = 0.05;
/// Between samples, a local minimum of a measure below this level is refined (golden section
/// in t), so that a singularity crossed between two samples is not missed.
pub const REFINE_LEVEL: f64 = 0.05;
/// Golden-section iterations of that refinement: the bracket shrinks by 0.618^40 ~ 4e-9.
const REFINE_ITER: usize = 40;
/// Bisection steps locating where a path leaves the reach of its working mode.
const EDGE_ITER: usize = 30;

/// A sampled end-effector motion: `t` (N) s and time-major `x`, `xd`, `xdd` (N x k, k = m)
/// task coordinates (m, m[, rad]) and their first and second time derivatives.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskPath {
    pub t: Vec<f64>,
    pub x: Vec<f64>,
    pub xd: Vec<f64>,
    pub xdd: Vec<f64>,
    /// The end-effector point and, for m = 3 when several bodies carry it, its body.
    pub point: String,
    pub body: Option<String>,
    /// A configuration on the wanted working mode (rad or m); default the drawing. The path's
    /// first point is reached from it by continuation in task space.
    pub q_start: Option<Vec<f64>>,
    /// Refuse the motion where sigma_I or sigma_II falls below this (dimensionless); see
    /// [`crate::kinematics::effector::SINGULAR_TOL`].
    pub singular_tol: f64,
}

/// A solved motion, time-major (N x m): inputs (rad or m), their rates and accelerations,
/// drive efforts (N m or N; the model's loads included, its drives not; joint-side) and the
/// motor torques they need (N m; the effort itself on a coordinate without a motor:
/// [`super::motor_torques`]), the two singularity measures and the condition number of the
/// scaled J_t (N each).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TaskSolution {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
    pub tau_motor: Vec<f64>,
    pub sigma_i: Vec<f64>,
    pub sigma_ii: Vec<f64>,
    pub condition: Vec<f64>,
}

impl TaskSolution {
    fn zeros(n: usize, m: usize) -> Self {
        let rows = vec![0.0; n * m];
        TaskSolution {
            q: rows.clone(),
            qd: rows.clone(),
            qdd: rows.clone(),
            tau: rows.clone(),
            tau_motor: rows,
            sigma_i: vec![0.0; n],
            sigma_ii: vec![0.0; n],
            condition: vec![0.0; n],
        }
    }

    /// The first `n` samples.
    fn head(&self, n: usize, m: usize) -> Self {
        let rows = |a: &Vec<f64>| a[..n * m].to_vec();
        TaskSolution {
            q: rows(&self.q),
            qd: rows(&self.qd),
            qdd: rows(&self.qdd),
            tau: rows(&self.tau),
            tau_motor: rows(&self.tau_motor),
            sigma_i: self.sigma_i[..n].to_vec(),
            sigma_ii: self.sigma_ii[..n].to_vec(),
            condition: self.condition[..n].to_vec(),
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.sigma_i.len()
    }

    pub fn is_empty(&self) -> bool {
        self.sigma_i.is_empty()
    }
}

/// Which singularity stops a motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SingularityKind {
    /// Serial: J_t loses rank, the end effector cannot move in some direction.
    TypeI,
    /// Parallel: the inputs no longer determine the mechanism, no effort holds it.
    TypeII,
}

impl SingularityKind {
    /// "I" or "II".
    pub fn label(self) -> &'static str {
        match self {
            SingularityKind::TypeI => "I",
            SingularityKind::TypeII => "II",
        }
    }

    fn text(self) -> &'static str {
        match self {
            SingularityKind::TypeI => {
                "type I (serial) singularity: the end effector cannot move in some direction there (a leg stretched \
                 out or folded back), the input rates would be infinite"
            }
            SingularityKind::TypeII => {
                "type II (parallel) singularity: the mechanism gains an uncontrolled motion there and no drive effort \
                 holds it, the efforts would be infinite"
            }
        }
    }
}

/// Why a task motion has no solution. The motion solved before the failure is `partial`.
#[derive(Debug, Clone, ThisError, PartialEq)]
#[non_exhaustive]
pub enum TaskError {
    /// The model could not be built, the end effector is not on it, or an argument is bad.
    #[error(transparent)]
    Core(#[from] Error),
    /// A singularity measure fell below the tolerance at time `t` (s), end effector at `x`
    /// (k), inputs `q` (m).
    #[error(
        "the prescribed motion reaches a {}; at t = {t:.4} s, end effector {point} at {}, q = {q:.4?}: \
         sigma_{} = {sigma:.2e} < {tol}. Keep the path away from it (robot.singularity_map shows where they are); \
         the motion up to there is the error's .partial",
        kind.text(), fmt_pose(x), kind.label()
    )]
    Singular {
        kind: SingularityKind,
        t: f64,
        point: String,
        x: Vec<f64>,
        q: Vec<f64>,
        sigma: f64,
        tol: f64,
        partial: Box<TaskSolution>,
    },
    /// A point of the path is out of reach on the working mode (sample `t`, s).
    #[error("{message}")]
    OutOfReach { t: f64, message: String, partial: Box<TaskSolution> },
}

/// "(x, y) m" or "(x, y) m, psi = ... rad".
fn fmt_pose(x: &[f64]) -> String {
    let pos = format!("({:.4}, {:.4}) m", x[0], x[1]);
    match x.get(2) {
        Some(psi) => format!("{pos}, psi = {psi:.4} rad"),
        None => pos,
    }
}

/// An end effector and the workspace that follows it along the path.
struct Tracker<'a> {
    mech: &'a Mechanism,
    ee: Effector,
    ws: Workspace,
    /// Body coordinates (3n) of the last solved sample.
    x_last: Vec<f64>,
    /// The blocks of J of the inputs chart, analysed once, for the type II measure.
    sys: System,
}

impl Tracker<'_> {
    /// Solve X from the state (q, qd, qdd) h seconds before, refusing a jump to another mode.
    fn step(&mut self, target: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], h: f64) -> Result<EffectorState, String> {
        let pred: Vec<f64> = (0..q.len()).map(|j| q[j] + qd[j] * h + 0.5 * qdd[j] * h * h).collect();
        let st = self.ee.solve(self.mech, target, &pred, &mut self.ws).map_err(|e| e.to_string())?;
        let dq: Vec<f64> = st.q.iter().zip(&pred).map(|(a, b)| a - b).collect();
        let jump = self.ee.input_norm(&dq);
        if jump > JUMP_TOL {
            return Err(format!("the inputs jumped by {jump:.3} from the predictor: another working mode"));
        }
        Ok(st)
    }

    /// qd = J_t^-1 Xd and qdd = J_t^-1 (Xdd - J_t' qd) at the state just solved.
    fn rates(&mut self, st: &EffectorState, xd: &[f64], xdd: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let mut qd = xd.to_vec();
        if !solve_square(&st.jt, &mut qd) {
            return None;
        }
        convective(self.mech, &qd, &mut self.ws);
        let conv = self.ee.convective(&self.ws);
        let mut qdd: Vec<f64> = xdd.iter().zip(&conv).map(|(a, c)| a - c).collect();
        solve_square(&st.jt, &mut qdd).then_some((qd, qdd))
    }

    fn sigma_ii(&mut self) -> f64 {
        sigma_min_with(&mut self.sys, self.mech, &Chart::Inputs, &self.ws.x)
    }

    /// Put the workspace back at the body coordinates of the last solved sample (after a
    /// search that may have left the branch).
    fn restore(&mut self) -> Result<(), TaskError> {
        self.ws.x.copy_from_slice(&self.x_last);
        self.ws.chart = Chart::Inputs;
        let mut z = vec![0.0; self.mech.dof()];
        coordinates(self.mech, &self.x_last, &mut z);
        solve_position(self.mech, &z, &mut self.ws).map_err(|e| TaskError::Core(e.into()))
    }
}

/// Solve the motion of one built mechanism (see the module docs).
pub fn solve(mech: &Mechanism, path: &TaskPath) -> Result<TaskSolution, TaskError> {
    let ee = Effector::new(mech, &path.point, path.body.as_deref()).map_err(Error::from)?;
    check_path(mech, path)?;
    let (m, n) = (mech.dof(), path.t.len());
    let q_start = path.q_start.clone().unwrap_or_else(|| mech.drawn_q());
    let mut tr = Tracker { mech, ee, ws: Workspace::new(mech), x_last: mech.x0.clone(), sys: System::new(mech) };
    let mut out = TaskSolution::zeros(n, m);
    let row = |a: &[f64], i: usize| a[i * m..(i + 1) * m].to_vec();
    for i in 0..n {
        let target = row(&path.x, i);
        let st = if i == 0 {
            tr.ee.reach(mech, &target, &q_start, &mut tr.ws).map_err(|e| {
                let why = match e {
                    EffectorError::Kinematics(KinematicsError::BadArgument { .. }) => {
                        return TaskError::Core(e_core(e))
                    }
                    other => other.to_string(),
                };
                TaskError::OutOfReach {
                    t: path.t[0],
                    message: format!(
                        "the path's first point {} cannot be reached from the start: {why}",
                        fmt_pose(&target)
                    ),
                    partial: Box::default(),
                }
            })?
        } else {
            let (q, qd, qdd) = (row(&out.q, i - 1), row(&out.qd, i - 1), row(&out.qdd, i - 1));
            match tr.step(&target, &q, &qd, &qdd, path.t[i] - path.t[i - 1]) {
                Ok(st) => st,
                Err(why) => return Err(fail_between(&mut tr, path, &out, i, why)),
            }
        };
        let sigma_ii = tr.sigma_ii();
        let rates = tr.rates(&st, &row(&path.xd, i), &row(&path.xdd, i));
        let (sigma_i, sigma_ii) = (if rates.is_some() { st.sigma_i } else { 0.0 }, sigma_ii);
        if let Some(kind) = below(sigma_i, sigma_ii, path.singular_tol) {
            let sigma = sigma_i.min(sigma_ii);
            return Err(singular(kind, path.t[i], &tr.ee, &st, sigma, path.singular_tol, out.head(i, m)));
        }
        let (qd, qdd) = rates.unwrap_or_default();
        dynamics::inverse(mech, &st.q, &qd, &qdd, &mut tr.ws).map_err(Error::from)?;
        out.tau[i * m..(i + 1) * m].copy_from_slice(&tr.ws.tau);
        let t_m = &mut out.tau_motor[i * m..(i + 1) * m];
        dynamics::motor_torques(mech, &tr.ws, &tr.ws.tau, t_m);
        dynamics::finite("motor torques", t_m).map_err(Error::from)?;
        out.q[i * m..(i + 1) * m].copy_from_slice(&st.q);
        out.qd[i * m..(i + 1) * m].copy_from_slice(&qd);
        out.qdd[i * m..(i + 1) * m].copy_from_slice(&qdd);
        (out.sigma_i[i], out.sigma_ii[i], out.condition[i]) = (sigma_i, sigma_ii, st.condition);
        tr.x_last.copy_from_slice(&tr.ws.x);
        if i >= 2 {
            refine(&mut tr, path, &out, i - 1)?;
        }
    }
    Ok(out)
}

fn e_core(e: EffectorError) -> Error {
    match e {
        EffectorError::Kinematics(k) => k.into(),
        other => Error::Options(other.to_string()),
    }
}

fn check_path(mech: &Mechanism, path: &TaskPath) -> Result<(), TaskError> {
    let (m, n) = (mech.dof(), path.t.len());
    let finite = [&path.t, &path.x, &path.xd, &path.xdd].iter().all(|a| a.iter().all(|v| v.is_finite()));
    if n < 2
        || [&path.x, &path.xd, &path.xdd].iter().any(|a| a.len() != n * m)
        || !finite
        || path.t.windows(2).any(|w| w[1] <= w[0])
    {
        return Err(TaskError::Core(Error::Options(format!(
            "a task path needs N >= 2 increasing times t (s) and N x {m} finite values of X, Xd, Xdd; got N = {n}"
        ))));
    }
    if !(path.singular_tol >= 0.0 && path.singular_tol.is_finite()) {
        return Err(TaskError::Core(Error::Options(format!("singular_tol must be >= 0, got {}", path.singular_tol))));
    }
    Ok(())
}

fn below(s_i: f64, s_ii: f64, tol: f64) -> Option<SingularityKind> {
    if s_i.min(s_ii) >= tol {
        None
    } else if s_i <= s_ii {
        Some(SingularityKind::TypeI)
    } else {
        Some(SingularityKind::TypeII)
    }
}

fn singular(
    kind: SingularityKind,
    t: f64,
    ee: &Effector,
    st: &EffectorState,
    sigma: f64,
    tol: f64,
    partial: TaskSolution,
) -> TaskError {
    let (point, x, q, partial) = (ee.point.clone(), st.pose.clone(), st.q.clone(), Box::new(partial));
    TaskError::Singular { kind, t, point, x, q, sigma, tol, partial }
}

/// Sample i could not be solved: find by bisection how far past t_i-1 the path can be
/// followed; at that edge one of the measures is near zero (the singularity that stops it),
/// or the target is simply out of reach.
fn fail_between(tr: &mut Tracker<'_>, path: &TaskPath, out: &TaskSolution, i: usize, why: String) -> TaskError {
    let m = tr.mech.dof();
    let rows = |a: &[f64]| a[(i - 1) * m..i * m].to_vec();
    let (q, qd, qdd) = (rows(&out.q), rows(&out.qd), rows(&out.qdd));
    let at = |tt: f64| -> Vec<f64> {
        if i >= 2 {
            local_path(path, i - 1, m, tt)
        } else {
            let a = (tt - path.t[0]) / (path.t[1] - path.t[0]);
            (0..m).map(|k| path.x[k] + a * (path.x[m + k] - path.x[k])).collect()
        }
    };
    let (mut lo, mut hi, mut best) = (path.t[i - 1], path.t[i], None);
    for _ in 0..EDGE_ITER {
        let mid = 0.5 * (lo + hi);
        match tr.step(&at(mid), &q, &qd, &qdd, mid - path.t[i - 1]) {
            Ok(st) => {
                best = Some((mid, tr.sigma_ii(), st));
                lo = mid;
            }
            Err(_) => {
                // Back on the branch before trying closer to the last solved sample.
                if tr.restore().is_err() {
                    break;
                }
                hi = mid;
            }
        }
    }
    let partial = out.head(i, m);
    if let Some((tm, s_ii, st)) = best {
        let sigma = st.sigma_i.min(s_ii);
        if sigma < REFINE_LEVEL {
            let tol = if sigma < path.singular_tol { path.singular_tol } else { REFINE_LEVEL };
            if let Some(kind) = below(st.sigma_i, s_ii, tol) {
                return singular(kind, tm, &tr.ee, &st, sigma, tol, partial);
            }
        }
    }
    TaskError::OutOfReach {
        t: path.t[i],
        message: format!(
            "the path leaves the reach of the working mode at t = {:.4} s, end effector at {}: {why}; the motion up \
             to there is the error's .partial",
            path.t[i],
            fmt_pose(&path.x[i * m..(i + 1) * m])
        ),
        partial: Box::new(partial),
    }
}

/// If a measure has a local minimum at sample j below [`REFINE_LEVEL`], find the minimum over
/// (t_j-1, t_j+1) by golden section (the path there the quadratic through the three samples),
/// and refuse the motion if it is below the tolerance there. The tracker is left at sample
/// j + 1.
fn refine(tr: &mut Tracker<'_>, path: &TaskPath, out: &TaskSolution, j: usize) -> Result<(), TaskError> {
    let m = tr.mech.dof();
    let rows = |a: &[f64], i: usize| a[i * m..(i + 1) * m].to_vec();
    let (q, qd, qdd) = (rows(&out.q, j), rows(&out.qd, j), rows(&out.qdd, j));
    let ts = [path.t[j - 1], path.t[j], path.t[j + 1]];
    let quad = |tt: f64| local_path(path, j, m, tt);
    for (kind, s) in [(SingularityKind::TypeI, &out.sigma_i), (SingularityKind::TypeII, &out.sigma_ii)] {
        if !(s[j] < REFINE_LEVEL && s[j] <= s[j - 1] && s[j] <= s[j + 1]) {
            continue;
        }
        let measure = |tr: &mut Tracker<'_>, tt: f64| -> Result<(f64, EffectorState), String> {
            let st = tr.step(&quad(tt), &q, &qd, &qdd, tt - ts[1])?;
            Ok((if kind == SingularityKind::TypeI { st.sigma_i } else { tr.sigma_ii() }, st))
        };
        let search = |tr: &mut Tracker<'_>| -> Result<(f64, f64, EffectorState), String> {
            let g = (5f64.sqrt() - 1.0) / 2.0;
            let (mut a, mut b) = (ts[0], ts[2]);
            let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
            let (mut fc, mut fd) = (measure(tr, c)?.0, measure(tr, d)?.0);
            for _ in 0..REFINE_ITER {
                if fc < fd {
                    (b, d, fd) = (d, c, fc);
                    c = b - g * (b - a);
                    fc = measure(tr, c)?.0;
                } else {
                    (a, c, fc) = (c, d, fd);
                    d = a + g * (b - a);
                    fd = measure(tr, d)?.0;
                }
                if fc.min(fd) < path.singular_tol {
                    break;
                }
            }
            let tm = if fc < fd { c } else { d };
            let (sigma, st) = measure(tr, tm)?;
            Ok((sigma, tm, st))
        };
        // A point of the neighbourhood out of reach: the singularity is there.
        let found = search(tr);
        tr.restore()?;
        let (sigma, tm, st) = found.unwrap_or_else(|_| {
            let st = EffectorState { q: q.clone(), pose: quad(ts[1]), jt: vec![], sigma_i: 0.0, condition: 0.0 };
            (0.0, ts[1], st)
        });
        if sigma < path.singular_tol {
            let st = EffectorState { pose: quad(tm), ..st };
            let n = if tm > ts[1] { j } else { j - 1 };
            return Err(singular(kind, tm, &tr.ee, &st, sigma, path.singular_tol, out.head(n, m)));
        }
    }
    Ok(())
}

/// X(t) near sample j: the quadratic through samples j-1, j, j+1 (Lagrange form); exact
/// enough to locate a singularity, the refused motion is not integrated from it.
fn local_path(path: &TaskPath, j: usize, m: usize, t: f64) -> Vec<f64> {
    let ts = &path.t[j - 1..j + 2];
    (0..m)
        .map(|k| {
            (0..3)
                .map(|i| {
                    let (a, b) = ((i + 1) % 3, (i + 2) % 3);
                    path.x[(j - 1 + i) * m + k] * (t - ts[a]) * (t - ts[b]) / ((ts[i] - ts[a]) * (ts[i] - ts[b]))
                })
                .sum()
        })
        .collect()
}
