//! Task-space inverse dynamics of one variant, in Rust so that a batch of design variants on
//! one end-effector motion runs on the batch pool without Python. The stages are those of
//! `planardyn.robot.solve_motion` (python/planardyn/robot/motion.py), per sample i of the
//! sampled path (t_i, X_i, Xd_i, Xdd_i):
//!
//!   q_i    Newton on X(q) = X_i from the predictor q + qd h + qdd h^2 / 2 (same working mode)
//!   qd_i   J qd = Xd_i
//!   qdd_i  J qdd = Xdd_i - d2X/dq2 [qd_i, qd_i]   (from the convective term c)
//!   sigma  type I (scaled J) and type II (kinematics) measures; refused below the tolerance
//!   tau_i  inverse dynamics at (q_i, qd_i, qdd_i)
//!
//! Task coordinates: the position [x, y] (m) of a point of a body for m = 2, and also the
//! body's rotation from its drawing psi = phi - phi_drawn (rad) for m = 3. The position
//! stage continues from the previous sample's solution (the Python code reassembles from the
//! drawing), so the two agree to the position tolerance, not bit for bit.

use crate::dynamics;
use crate::kinematics::{assemble_into, continue_to, convective, sigma_min, velocity_analogues, Chart};
use crate::linalg::Lu;
use crate::model::{CoordinateKind, Mechanism};
use crate::{Error, KinematicsError, Workspace};
use nalgebra::DMatrix;
use std::fmt::Write;
use thiserror::Error as ThisError;

// The constants of python/planardyn/robot/effector.py and motion.py (the reasons are there).
const IK_TOL: f64 = 1e-11;
const IK_MAX_ITER: usize = 30;
const IK_MAX_STEP: f64 = 0.25;
const IK_CONTINUATION_STEP: f64 = 0.02;
const JUMP_TOL: f64 = 0.05;
const REFINE_LEVEL: f64 = 0.05;
const REFINE_ITER: usize = 40;

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
    /// A configuration on the wanted working mode (rad or m); default the drawing.
    pub q_start: Option<Vec<f64>>,
    /// Refuse the motion where sigma_I or sigma_II falls below this (dimensionless).
    pub singular_tol: f64,
}

/// The solved motion, time-major (N x m): inputs, their rates, efforts (N m or N), the two
/// singularity measures and the condition number of the scaled J (N).
#[derive(Debug, Clone, PartialEq)]
pub struct TaskSolution {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub tau: Vec<f64>,
    pub sigma_i: Vec<f64>,
    pub sigma_ii: Vec<f64>,
    pub condition: Vec<f64>,
}

/// Why a task motion has no solution for a variant.
#[derive(Debug, Clone, ThisError, PartialEq)]
pub enum TaskError {
    /// The model could not be built, the end effector is not on it, or an argument is bad.
    #[error(transparent)]
    Core(#[from] Error),
    /// A singularity measure fell below the tolerance along the path.
    #[error("{0}")]
    Singular(String),
    /// A point of the path is out of reach on the working mode.
    #[error("{0}")]
    OutOfReach(String),
}

const KIND_I: &str = "type I (serial) singularity: the end effector cannot move in some direction there, the input rates would be infinite";
const KIND_II: &str = "type II (parallel) singularity: the mechanism gains an uncontrolled motion there and no drive effort holds it, the efforts would be infinite";

/// The end effector of a built mechanism and a workspace following it along the path.
struct Tracker<'a> {
    mech: &'a Mechanism,
    ws: Workspace,
    /// User coordinates at which `ws` holds a converged position (None: not yet assembled).
    at: Option<Vec<f64>>,
    body: usize,
    s: [f64; 2],
    phi0: f64,
    task_scale: [f64; 3],
    input_scale: Vec<f64>,
    lu: Lu,
}

/// One solved sample: inputs, task coordinates, J (k x m row-major) and its factors.
struct Sample {
    q: Vec<f64>,
    x: [f64; 3],
    sigma_i: f64,
    condition: f64,
}

impl<'a> Tracker<'a> {
    fn new(mech: &'a Mechanism, point: &str, body: Option<&str>) -> Result<Self, TaskError> {
        let m = mech.dof();
        let bad = |name, expected: String, got: String| {
            TaskError::Core(KinematicsError::bad_argument(name, expected, got).into())
        };
        if m != 2 && m != 3 {
            return Err(bad(
                "mechanism",
                "m = 2 (a point) or m = 3 (a pose) coordinates for a task-space motion".into(),
                format!("{:?} with m = {m}", mech.name),
            ));
        }
        let pid = mech.point_id(point).ok_or_else(|| {
            bad("point", format!("one of the points {}", mech.point_names().join(", ")), format!("{point:?}"))
        })?;
        let carriers: Vec<usize> =
            (0..mech.n_bodies()).filter(|&i| mech.bodies[i].points.iter().any(|(p, _)| *p == pid)).collect();
        let i = match body {
            Some(name) => mech.body_id(name).map(|b| b.0).filter(|b| carriers.contains(b)),
            None if m == 3 && carriers.len() > 1 => {
                return Err(bad(
                    "body",
                    format!("the body whose pose to follow (point {point:?} is on several)"),
                    "none".into(),
                ))
            }
            None => carriers.first().copied(),
        }
        .ok_or_else(|| match body {
            Some(b) => bad("body", format!("a mobile body carrying point {point:?}"), format!("{b:?}")),
            None => bad("point", "a point carried by a mobile body".into(), format!("{point:?} (on the ground only)")),
        })?;
        let s = mech.bodies[i].points.iter().find(|(p, _)| *p == pid).map(|(_, s)| *s).unwrap_or([0.0; 2]);
        let l = mech.scale;
        let input_scale =
            mech.coordinates.iter().map(|c| if c.kind == CoordinateKind::Angle { 1.0 } else { l }).collect();
        let ws = Workspace::new(mech);
        Ok(Tracker {
            mech,
            ws,
            at: None,
            body: i,
            s,
            phi0: mech.x0[3 * i + 2],
            task_scale: [l, l, 1.0],
            input_scale,
            lu: Lu::new(m),
        })
    }

    fn k(&self) -> usize {
        self.mech.dof()
    }

    /// Positions and velocity analogues at q, continuing from the last solution (the first
    /// time from the drawing).
    fn go(&mut self, q: &[f64]) -> Result<(), KinematicsError> {
        match &self.at {
            None => assemble_into(self.mech, q, &mut self.ws)?,
            Some(from) => continue_to(self.mech, from, q, &mut self.ws)?,
        }
        self.at = Some(q.to_vec());
        velocity_analogues(&mut self.ws)
    }

    /// R(phi) s and the body's pose at the current position.
    fn body(&self) -> ([f64; 2], [f64; 3]) {
        let p = &self.ws.x[3 * self.body..3 * self.body + 3];
        let (c, sn) = (p[2].cos(), p[2].sin());
        ([c * self.s[0] - sn * self.s[1], sn * self.s[0] + c * self.s[1]], [p[0], p[1], p[2]])
    }

    fn task(&self) -> [f64; 3] {
        let (rs, p) = self.body();
        [p[0] + rs[0], p[1] + rs[1], p[2] - self.phi0]
    }

    /// J = dX/dq into the LU buffer (dP/dq_j = u_r,j + u_phi,j E R s; psi row u_phi,j),
    /// with sigma_I and the condition number of the scaled J; factorised.
    fn jacobian(&mut self) -> (f64, f64) {
        let (k, n) = (self.k(), self.ws.x.len());
        let (rs, _) = self.body();
        let a = self.lu.matrix_mut();
        for j in 0..k {
            let u = &self.ws.u[j * n + 3 * self.body..j * n + 3 * self.body + 3];
            let col = [u[0] - u[2] * rs[1], u[1] + u[2] * rs[0], u[2]];
            for r in 0..k {
                a[r * k + j] = col[r];
            }
        }
        let scaled: Vec<f64> = (0..k * k).map(|e| a[e] / self.task_scale[e / k] * self.input_scale[e % k]).collect();
        let sv = DMatrix::from_row_slice(k, k, &scaled).singular_values();
        let (lo, hi) = (sv.min(), sv.max());
        let factored = self.lu.factor(0.0).is_ok() && lo.is_finite();
        (if factored { lo } else { 0.0 }, if factored && lo > 0.0 { hi / lo } else { f64::INFINITY })
    }

    fn scaled_norm(&self, r: &[f64]) -> f64 {
        r.iter().zip(&self.task_scale).fold(0.0, |m: f64, (v, s)| m.max((v / s).abs()))
    }

    /// Inverse kinematics by Newton from `guess` (effector.py `solve`).
    fn solve(&mut self, target: &[f64], guess: &[f64]) -> Result<Sample, TaskError> {
        let k = self.k();
        let mut q = guess.to_vec();
        let mut res = f64::INFINITY;
        for _ in 0..IK_MAX_ITER {
            self.go(&q).map_err(Error::from)?;
            let x = self.task();
            let mut r: Vec<f64> = (0..k).map(|i| target[i] - x[i]).collect();
            res = self.scaled_norm(&r);
            let (sigma_i, condition) = self.jacobian();
            if res < IK_TOL {
                return Ok(Sample { q, x, sigma_i, condition });
            }
            if sigma_i == 0.0 {
                break;
            }
            self.lu.solve(&mut r);
            let big = r.iter().zip(&self.input_scale).fold(0.0, |m: f64, (d, s)| m.max((d / s).abs()));
            let cut = if big > IK_MAX_STEP { IK_MAX_STEP / big } else { 1.0 };
            q.iter_mut().zip(&r).for_each(|(qi, d)| *qi += d * cut);
        }
        Err(TaskError::OutOfReach(format!(
            "inverse kinematics did not converge to X = {} (residual {res:.2e} L after {IK_MAX_ITER} iterations): the target is \
             out of reach on this working mode, or at a type I singularity",
            fmt_vec(target)
        )))
    }

    /// By continuation in task space from `q_start` (default the drawing) to `target`.
    fn inverse(&mut self, target: &[f64], q_start: &[f64]) -> Result<Sample, TaskError> {
        let x0 = self.task_at(q_start)?;
        let k = self.k();
        let d = self.scaled_norm(&(0..k).map(|i| target[i] - x0[i]).collect::<Vec<_>>());
        let n = ((d / IK_CONTINUATION_STEP).ceil() as usize).max(1);
        let mut st = Sample { q: q_start.to_vec(), x: [0.0; 3], sigma_i: 0.0, condition: 0.0 };
        for s in 1..=n {
            let a = s as f64 / n as f64;
            let x: Vec<f64> = (0..k).map(|i| x0[i] + a * (target[i] - x0[i])).collect();
            st = self.solve(&x, &st.q)?;
        }
        Ok(st)
    }

    fn task_at(&mut self, q: &[f64]) -> Result<Vec<f64>, TaskError> {
        self.go(q).map_err(Error::from)?;
        Ok(self.task()[..self.k()].to_vec())
    }

    /// Solve X from the state (q, qd, qdd) h seconds before, refusing a jump to another mode.
    fn step(&mut self, target: &[f64], q: &[f64], qd: &[f64], qdd: &[f64], h: f64) -> Result<Sample, TaskError> {
        let pred: Vec<f64> = (0..q.len()).map(|j| q[j] + qd[j] * h + 0.5 * qdd[j] * h * h).collect();
        let st = self.solve(target, &pred)?;
        let jump = (0..q.len()).fold(0.0, |m: f64, j| m.max((st.q[j] - pred[j]).abs() / self.input_scale[j]));
        if jump > JUMP_TOL {
            return Err(TaskError::OutOfReach(format!(
                "the inputs jumped by {jump:.3} from the predictor: another working mode"
            )));
        }
        Ok(st)
    }

    /// qd = J^-1 Xd and qdd = J^-1 (Xdd - d2X/dq2 [qd, qd]) at the current (factorised) sample.
    fn rates(&mut self, xd: &[f64], xdd: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut qd = xd.to_vec();
        self.lu.solve(&mut qd);
        convective(self.mech, &qd, &mut self.ws);
        let (rs, _) = self.body();
        let b = 3 * self.body;
        let (c, xdb) = (&self.ws.c[b..b + 3], &self.ws.xd[b..b + 3]);
        let w2 = xdb[2] * xdb[2];
        let conv = [c[0] - c[2] * rs[1] - w2 * rs[0], c[1] + c[2] * rs[0] - w2 * rs[1], c[2]];
        let mut qdd: Vec<f64> = (0..self.k()).map(|i| xdd[i] - conv[i]).collect();
        self.lu.solve(&mut qdd);
        (qd, qdd)
    }
}

/// Solve the motion for one built mechanism (see the module docs).
pub fn solve(mech: &Mechanism, path: &TaskPath) -> Result<TaskSolution, TaskError> {
    let mut tr = Tracker::new(mech, &path.point, path.body.as_deref())?;
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
    let q_start = path.q_start.clone().unwrap_or_else(|| mech.drawn_q());
    let mut out = TaskSolution {
        q: vec![0.0; n * m],
        qd: vec![0.0; n * m],
        qdd: vec![0.0; n * m],
        tau: vec![0.0; n * m],
        sigma_i: vec![0.0; n],
        sigma_ii: vec![0.0; n],
        condition: vec![0.0; n],
    };
    let row = |a: &Vec<f64>, i: usize| a[i * m..(i + 1) * m].to_vec();
    for i in 0..n {
        let target = row(&path.x, i);
        let st = if i == 0 {
            tr.inverse(&target, &q_start).map_err(|e| at_sample(e, path.t[i], &target, true))?
        } else {
            let (q, qd, qdd) = (row(&out.q, i - 1), row(&out.qd, i - 1), row(&out.qdd, i - 1));
            match tr.step(&target, &q, &qd, &qdd, path.t[i] - path.t[i - 1]) {
                Ok(st) => st,
                Err(e) => return Err(fail_between(&mut tr, path, &out, i, e)),
            }
        };
        let (qd, qdd) = tr.rates(&row(&path.xd, i), &row(&path.xdd, i));
        out.sigma_ii[i] = sigma_min(mech, &Chart::Inputs, &tr.ws.x);
        (out.sigma_i[i], out.condition[i]) = (st.sigma_i, st.condition);
        check(out.sigma_i[i], out.sigma_ii[i], path.singular_tol, path.t[i], &st)?;
        dynamics::inverse(mech, &st.q, &qd, &qdd, &mut tr.ws).map_err(Error::from)?;
        out.tau[i * m..(i + 1) * m].copy_from_slice(&tr.ws.tau);
        out.q[i * m..(i + 1) * m].copy_from_slice(&st.q);
        out.qd[i * m..(i + 1) * m].copy_from_slice(&qd);
        out.qdd[i * m..(i + 1) * m].copy_from_slice(&qdd);
        if i >= 2 {
            refine(&mut tr, path, &out, i - 1)?;
        }
    }
    Ok(out)
}

fn at_sample(e: TaskError, t: f64, x: &[f64], first: bool) -> TaskError {
    let why = match e {
        TaskError::Core(Error::Kinematics(k)) => k.to_string(),
        TaskError::OutOfReach(why) => why,
        other => return other,
    };
    TaskError::OutOfReach(if first {
        format!("the path's first point {} cannot be reached from the start: {why}", fmt_vec(x))
    } else {
        format!("the path leaves the reach of the working mode at t = {t:.4} s, end effector at {}: {why}", fmt_vec(x))
    })
}

/// Sample i could not be solved: find by bisection how far past t_i-1 the path can be
/// followed; at that edge one of the measures is near zero (the singularity that stops it),
/// or the target is simply out of reach (motion.py `_fail_between`).
fn fail_between(tr: &mut Tracker<'_>, path: &TaskPath, out: &TaskSolution, i: usize, e: TaskError) -> TaskError {
    let m = tr.k();
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
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        match tr.step(&at(mid), &q, &qd, &qdd, mid - path.t[i - 1]) {
            Ok(st) => {
                best = Some((mid, sigma_min(tr.mech, &Chart::Inputs, &tr.ws.x), st));
                lo = mid;
            }
            Err(_) => hi = mid,
        }
    }
    if let Some((tm, s_ii, st)) = best {
        let sigma = st.sigma_i.min(s_ii);
        if sigma < REFINE_LEVEL {
            let tol = if sigma < path.singular_tol { path.singular_tol } else { REFINE_LEVEL };
            if let Err(singular) = check(st.sigma_i, s_ii, tol, tm, &st) {
                return singular;
            }
        }
    }
    at_sample(e, path.t[i], &path.x[i * m..(i + 1) * m], false)
}

fn check(s_i: f64, s_ii: f64, tol: f64, t: f64, st: &Sample) -> Result<(), TaskError> {
    if s_i.min(s_ii) >= tol {
        return Ok(());
    }
    let (kind, text) = if s_i <= s_ii { ("I", KIND_I) } else { ("II", KIND_II) };
    let mut msg = format!(
        "the prescribed motion reaches a {text}; at t = {t:.4} s, end effector at {}, q = {}: ",
        fmt_vec(&st.x[..st.q.len()]),
        fmt_vec(&st.q)
    );
    let _ = write!(
        msg,
        "sigma_{kind} = {:.2e} < {tol}. Keep the path away from it (robot.singularity_map shows where they are)",
        s_i.min(s_ii)
    );
    Err(TaskError::Singular(msg))
}

/// If a measure has a local minimum at sample j below REFINE_LEVEL, find the minimum over
/// (t_j-1, t_j+1) by golden section (the path there the quadratic through the three
/// samples), and refuse the motion if it is below the tolerance there (motion.py `_refine`).
/// The tracker is left at sample j + 1 as found.
fn refine(tr: &mut Tracker<'_>, path: &TaskPath, out: &TaskSolution, j: usize) -> Result<(), TaskError> {
    let m = tr.k();
    let rows = |a: &[f64]| a[j * m..(j + 1) * m].to_vec();
    let (q, qd, qdd) = (rows(&out.q), rows(&out.qd), rows(&out.qdd));
    let ts = [path.t[j - 1], path.t[j], path.t[j + 1]];
    let quad = |tt: f64| local_path(path, j, m, tt);
    for (type_i, s) in [(true, &out.sigma_i), (false, &out.sigma_ii)] {
        if !(s[j] < REFINE_LEVEL && s[j] <= s[j - 1] && s[j] <= s[j + 1]) {
            continue;
        }
        let measure = |tr: &mut Tracker<'_>, tt: f64| -> Result<(f64, Vec<f64>), TaskError> {
            let st = tr.step(&quad(tt), &q, &qd, &qdd, tt - ts[1])?;
            Ok((if type_i { st.sigma_i } else { sigma_min(tr.mech, &Chart::Inputs, &tr.ws.x) }, st.q))
        };
        let search = |tr: &mut Tracker<'_>| -> Result<(f64, f64, Vec<f64>), TaskError> {
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
            let (sigma, qm) = measure(tr, tm)?;
            Ok((sigma, tm, qm))
        };
        // A point of the neighbourhood out of reach: the singularity is there.
        let (sigma, tm, qm) = search(tr).unwrap_or((0.0, ts[1], q.clone()));
        let back = rows_at(out, j + 1, m);
        tr.go(&back).map_err(Error::from)?;
        if sigma < path.singular_tol {
            let x = quad(tm);
            let st = Sample { x: [x[0], x[1], x.get(2).copied().unwrap_or(0.0)], q: qm, sigma_i: 0.0, condition: 0.0 };
            let (si, sii) = if type_i { (sigma, f64::INFINITY) } else { (f64::INFINITY, sigma) };
            return check(si, sii, path.singular_tol, tm, &st);
        }
    }
    Ok(())
}

fn rows_at(out: &TaskSolution, i: usize, m: usize) -> Vec<f64> {
    out.q[i * m..(i + 1) * m].to_vec()
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

fn fmt_vec(v: &[f64]) -> String {
    format!("[{}]", v.iter().map(|x| format!("{x:.4}")).collect::<Vec<_>>().join(", "))
}
