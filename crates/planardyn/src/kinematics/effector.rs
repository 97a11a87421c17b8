//! The end effector: a point of a body (k = 2 task coordinates) or its body's pose (k = 3) as a
//! function of the generalized coordinates q, its task Jacobian J_t, the convective term
//! J_t' qd, the type I singularity measure, and inverse kinematics by Newton on the pose.
//!
//! Task coordinates X (m, m[, rad]): the point's world position P = r_i + R(phi_i) s and, for
//! k = 3, psi = phi_i - phi_i,drawn, the body's rotation from the drawing. Everything comes
//! from the core's point kinematics on the body coordinates x and their analogues:
//!
//! ```text
//! J_t e_j  = [point velocity of s for body rates u_j;  u_phi,j]
//! J_t' qd  = [point acceleration of s for rates xd = U qd, accelerations c;  c_phi]
//! ```
//!
//! with c = sum_jl qd_j qd_l w_jl the convective term of the body coordinates. Inverse
//! kinematics moves the workspace from the body coordinates it holds to each Newton iterate by
//! continuation, so every solve stays on the branch it starts on and never returns to the
//! drawing.

use super::analogues::{convective, velocity_analogues};
use super::constraints::{coordinates, point_acceleration, point_velocity, world_point, Chart};
use super::frame::Frame;
use super::position::{continue_to, solve_position};
use crate::model::{BodyId, CoordinateKind, Link, Mechanism};
use crate::KinematicsError;
use nalgebra::DMatrix;
use thiserror::Error as ThisError;

/// Newton on the task coordinates has converged when the scaled residual |X* - X| / L
/// (position rows; psi in rad) is below this. The position stage solves to ~1e-12 L, so this is
/// as tight as the positions it is computed from allow.
pub const IK_TOL: f64 = 1e-11;
/// Newton iterations before inverse kinematics gives up (quadratic convergence needs ~5).
pub const IK_MAX_ITER: usize = 30;
/// Largest Newton step (rad for an angle input, L for a displacement): keeps a poor guess from
/// jumping to another working mode.
pub const IK_MAX_STEP: f64 = 0.25;
/// Continuation in task space towards a distant target: steps of at most this much of L (or rad).
pub const IK_CONTINUATION_STEP: f64 = 0.02;
/// A motion is refused where either singularity measure (dimensionless, 0 at the
/// singularity) falls below this: there the input rates (type I) or the drive efforts (type II)
/// grow as 1/sigma, about 1000 times their values in a well-conditioned pose.
pub const SINGULAR_TOL: f64 = 1e-3;

/// Why an inverse-kinematics solve failed.
#[derive(Debug, Clone, ThisError, PartialEq)]
#[non_exhaustive]
pub enum EffectorError {
    /// The position stage failed at an iterate (or an argument is bad).
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// Newton on the task coordinates did not converge.
    #[error(
        "inverse kinematics did not converge to X = {target:.4?} (residual {residual:.2e} L after {iterations} \
         iterations): the target is out of reach on this working mode, or at a type I singularity"
    )]
    OutOfReach { target: Vec<f64>, residual: f64, iterations: usize },
}

/// A point of a body, or its body's pose, as the task coordinates of a mechanism with m = k
/// generalized coordinates (so that J_t is square).
#[derive(Debug, Clone, PartialEq)]
pub struct Effector {
    /// The point's name (for messages).
    pub point: String,
    /// The body carrying the point.
    pub body: BodyId,
    /// The point in the body frame (m).
    pub s: [f64; 2],
    /// The body's angle in the drawing (rad): psi = phi - phi0.
    pub phi0: f64,
    /// k: 2 (the point's position) or 3 (and the body's rotation psi).
    pub dim: usize,
    /// Task-row scale: L for positions, 1 for psi.
    task_scale: [f64; 3],
    /// Input-column scale: 1 for angles, L for displacements (as `system.rs` scales x).
    input_scale: Vec<f64>,
}

/// The end effector at one configuration: inputs q (m), task coordinates X (k), J_t (k x m,
/// row-major), the type I measure and the condition number of the scaled J_t.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectorState {
    pub q: Vec<f64>,
    pub pose: Vec<f64>,
    pub jt: Vec<f64>,
    pub sigma_i: f64,
    pub condition: f64,
}

/// The end effector reached at one configuration, with the body coordinates x (3n; m, rad)
/// there: what the entry points that make their own frame return.
#[derive(Debug, Clone, PartialEq)]
pub struct Reached {
    pub state: EffectorState,
    pub x: Vec<f64>,
}

/// A kinematic frame started at the body coordinates `x_start` (a closed configuration on the
/// wanted branch), else at the drawing.
fn frame_from(mech: &Mechanism, x_start: Option<&[f64]>) -> Frame {
    let mut ws = Frame::new(mech);
    if let Some(x) = x_start {
        ws.x.copy_from_slice(x);
    }
    ws
}

impl Effector {
    /// The end effector `point` on `body` (any carrier for k = 2; for k = 3 the body must be
    /// named when several carry the point, since their angles differ).
    pub fn new(mech: &Mechanism, point: &str, body: Option<&str>) -> Result<Self, KinematicsError> {
        let m = mech.dof();
        if m != 2 && m != 3 {
            return Err(KinematicsError::bad_argument(
                "mechanism",
                "m = 2 (a point) or m = 3 (a pose) coordinates for a task-space motion",
                format!("{:?} with m = {m}", mech.name),
            ));
        }
        let pid = mech.point_id(point).ok_or_else(|| {
            KinematicsError::bad_argument(
                "point",
                format!("one of the points {}", mech.point_names().join(", ")),
                format!("{point:?}"),
            )
        })?;
        let carriers: Vec<usize> =
            (0..mech.n_bodies()).filter(|&i| mech.bodies[i].points.iter().any(|(p, _)| *p == pid)).collect();
        let names = || carriers.iter().map(|&i| mech.bodies[i].name.as_str()).collect::<Vec<_>>().join(", ");
        let i = match body {
            Some(name) => mech.body_id(name).map(|b| b.0).filter(|b| carriers.contains(b)).ok_or_else(|| {
                KinematicsError::bad_argument(
                    "body",
                    format!("a body carrying point {point:?} ({})", names()),
                    format!("{name:?}"),
                )
            })?,
            None if m == 3 && carriers.len() > 1 => {
                return Err(KinematicsError::bad_argument(
                    "body",
                    format!("the body whose pose to follow: point {point:?} is on {}", names()),
                    "none",
                ))
            }
            None => *carriers.first().ok_or_else(|| {
                KinematicsError::bad_argument(
                    "point",
                    "a point carried by a mobile body",
                    format!("{point:?} (on the ground only)"),
                )
            })?,
        };
        let s = mech.bodies[i].points.iter().find(|(p, _)| *p == pid).map_or([0.0; 2], |(_, s)| *s);
        let l = mech.scale;
        Ok(Effector {
            point: point.to_string(),
            body: BodyId(i),
            s,
            phi0: mech.x0[3 * i + 2],
            dim: m,
            task_scale: [l, l, 1.0],
            input_scale: mech
                .coordinates
                .iter()
                .map(|c| if c.kind == CoordinateKind::Angle { 1.0 } else { l })
                .collect(),
        })
    }

    /// Task coordinates X (k) at body coordinates x (3n): m, m[, rad].
    pub fn pose(&self, x: &[f64]) -> Vec<f64> {
        let p = world_point(Link::Body(self.body), self.s, x);
        let psi = x[3 * self.body.0 + 2] - self.phi0;
        [p[0], p[1], psi][..self.dim].to_vec()
    }

    /// J_t = dX/dq (k x m, row-major) into `jt`, from the velocity analogues in `ws`.
    pub fn jacobian(&self, ws: &Frame, jt: &mut [f64]) {
        let (k, i) = (self.dim, 3 * self.body.0 + 2);
        for j in 0..k {
            let u = ws.u_col(j);
            let v = point_velocity(Link::Body(self.body), self.s, &ws.x, u);
            for (r, val) in [v[0], v[1], u[i]].into_iter().take(k).enumerate() {
                jt[r * k + j] = val;
            }
        }
    }

    /// J_t' qd = d2X/dq2 [qd, qd] (k; m/s^2, m/s^2[, rad/s^2]) from the body velocities `ws.xd`
    /// and convective term `ws.c` (fill both with [`super::convective`] first).
    pub fn convective(&self, ws: &Frame) -> Vec<f64> {
        let a = point_acceleration(Link::Body(self.body), self.s, &ws.x, &ws.xd, &ws.c);
        [a[0], a[1], ws.c[3 * self.body.0 + 2]][..self.dim].to_vec()
    }

    /// Type I measure and condition number of J_t (k x m, row-major), scaled dimensionless as
    /// `system.rs` scales J: position rows divided by L, displacement inputs multiplied by L.
    /// sigma_I = 0 (and the condition infinite) where the end effector cannot move in some
    /// direction, or where J_t is not finite.
    pub fn measures(&self, jt: &[f64]) -> (f64, f64) {
        let k = self.dim;
        let scaled: Vec<f64> = (0..k * k).map(|e| jt[e] / self.task_scale[e / k] * self.input_scale[e % k]).collect();
        if scaled.iter().any(|v| !v.is_finite()) {
            return (0.0, f64::INFINITY);
        }
        let sv = DMatrix::from_row_slice(k, k, &scaled).singular_values();
        let (lo, hi) = (sv.min(), sv.max());
        (lo, if lo > 0.0 { hi / lo } else { f64::INFINITY })
    }

    /// Largest task-coordinate component of `r` (k) in units of L (positions) or rad.
    pub fn task_norm(&self, r: &[f64]) -> f64 {
        r.iter().zip(&self.task_scale).fold(0.0, |m: f64, (v, s)| m.max((v / s).abs()))
    }

    /// Largest input component of `dq` (m) in rad or units of L.
    pub fn input_norm(&self, dq: &[f64]) -> f64 {
        dq.iter().zip(&self.input_scale).fold(0.0, |m: f64, (v, s)| m.max((v / s).abs()))
    }

    /// Move `ws` to inputs q by continuation from the body coordinates it holds (a converged
    /// position: the drawing of a new workspace, or the last solve), then the velocity
    /// analogues and the end effector there.
    pub fn state(&self, mech: &Mechanism, q: &[f64], ws: &mut Frame) -> Result<EffectorState, KinematicsError> {
        if q.len() != mech.dof() || q.iter().any(|v| !v.is_finite()) {
            return Err(KinematicsError::bad_argument(
                "q",
                format!("{} finite coordinate values ({})", mech.dof(), mech.coordinate_names().join(", ")),
                format!("{q:?}"),
            ));
        }
        let mut z = vec![0.0; q.len()];
        coordinates(mech, &ws.x, &mut z);
        if ws.chart != Chart::Inputs || !ws.sys.is_factored_for(&Chart::Inputs) {
            ws.chart = Chart::Inputs;
            solve_position(mech, &z, ws)?;
        }
        continue_to(mech, &z, q, ws)?;
        velocity_analogues(ws)?;
        let mut jt = vec![0.0; self.dim * self.dim];
        self.jacobian(ws, &mut jt);
        let (sigma_i, condition) = self.measures(&jt);
        Ok(EffectorState { q: q.to_vec(), pose: self.pose(&ws.x), jt, sigma_i, condition })
    }

    /// [`Effector::state`] in a frame of its own, reached from the body coordinates `x_start`
    /// (else the drawing).
    pub fn state_from(&self, mech: &Mechanism, q: &[f64], x_start: Option<&[f64]>) -> Result<Reached, KinematicsError> {
        let mut ws = frame_from(mech, x_start);
        let state = self.state(mech, q, &mut ws)?;
        Ok(Reached { state, x: ws.x })
    }

    /// The end effector at body coordinates x (3n, a closed configuration), and the frame
    /// analysed there (positions and velocity analogues).
    pub fn state_at(&self, mech: &Mechanism, x: &[f64]) -> Result<(EffectorState, Frame), KinematicsError> {
        let mut ws = frame_from(mech, Some(x));
        let mut q = vec![0.0; mech.dof()];
        coordinates(mech, x, &mut q);
        let state = self.state(mech, &q, &mut ws)?;
        Ok((state, ws))
    }

    /// J_t' qd (k) at body coordinates x (3n) and rates qd (m) ([`Effector::convective`]).
    pub fn convective_at(&self, mech: &Mechanism, x: &[f64], qd: &[f64]) -> Result<Vec<f64>, KinematicsError> {
        let (_, mut ws) = self.state_at(mech, x)?;
        convective(mech, qd, &mut ws);
        Ok(self.convective(&ws))
    }

    /// [`Effector::solve`] from `guess` on the branch of `x_start` (else the drawing).
    pub fn solve_from(
        &self,
        mech: &Mechanism,
        target: &[f64],
        guess: &[f64],
        x_start: Option<&[f64]>,
    ) -> Result<Reached, EffectorError> {
        let mut ws = frame_from(mech, x_start);
        let state = self.solve(mech, target, guess, &mut ws)?;
        Ok(Reached { state, x: ws.x })
    }

    /// [`Effector::reach`] from the end effector at `q_start` (else the drawn coordinates),
    /// reached from `x_start` (else the drawing).
    pub fn reach_from(
        &self,
        mech: &Mechanism,
        target: &[f64],
        q_start: Option<&[f64]>,
        x_start: Option<&[f64]>,
    ) -> Result<Reached, EffectorError> {
        let mut ws = frame_from(mech, x_start);
        let q_start = q_start.map_or_else(|| mech.drawn_q(), <[f64]>::to_vec);
        let state = self.reach(mech, target, &q_start, &mut ws)?;
        Ok(Reached { state, x: ws.x })
    }

    /// Inverse kinematics: Newton on q for X(q) = `target` (k) from `guess` (m), on the branch
    /// of the body coordinates in `ws` (each iterate reached by continuation from the last).
    /// Steps are limited to [`IK_MAX_STEP`]; converged at [`IK_TOL`].
    pub fn solve(
        &self,
        mech: &Mechanism,
        target: &[f64],
        guess: &[f64],
        ws: &mut Frame,
    ) -> Result<EffectorState, EffectorError> {
        let mut q = guess.to_vec();
        let mut residual = f64::INFINITY;
        for _ in 0..IK_MAX_ITER {
            let st = self.state(mech, &q, ws)?;
            let mut r: Vec<f64> = target.iter().zip(&st.pose).map(|(a, b)| a - b).collect();
            residual = self.task_norm(&r);
            if residual < IK_TOL {
                return Ok(st);
            }
            if st.sigma_i == 0.0 || !solve_square(&st.jt, &mut r) {
                break;
            }
            let big = self.input_norm(&r);
            let cut = if big > IK_MAX_STEP { IK_MAX_STEP / big } else { 1.0 };
            q.iter_mut().zip(&r).for_each(|(qi, d)| *qi += d * cut);
        }
        Err(EffectorError::OutOfReach { target: target.to_vec(), residual, iterations: IK_MAX_ITER })
    }

    /// Inverse kinematics by continuation along the straight task-space segment from the end
    /// effector at `q_start` to `target`, in steps of at most [`IK_CONTINUATION_STEP`].
    pub fn reach(
        &self,
        mech: &Mechanism,
        target: &[f64],
        q_start: &[f64],
        ws: &mut Frame,
    ) -> Result<EffectorState, EffectorError> {
        let mut st = self.state(mech, q_start, ws)?;
        let x0 = st.pose.clone();
        let d: Vec<f64> = target.iter().zip(&x0).map(|(a, b)| a - b).collect();
        let n = ((self.task_norm(&d) / IK_CONTINUATION_STEP).ceil() as usize).max(1);
        for s in 1..=n {
            let a = s as f64 / n as f64;
            let x: Vec<f64> = x0.iter().zip(&d).map(|(x, d)| x + a * d).collect();
            st = self.solve(mech, &x, &st.q.clone(), ws)?;
        }
        Ok(st)
    }
}

/// Solve the small square system a y = b (row-major a, k x k) in place by LU with partial
/// pivoting; false if a is singular.
pub(crate) fn solve_square(a: &[f64], b: &mut [f64]) -> bool {
    let k = b.len();
    match DMatrix::from_row_slice(k, k, a).lu().solve(&nalgebra::DVector::from_column_slice(b)) {
        Some(y) if y.iter().all(|v| v.is_finite()) => {
            b.copy_from_slice(y.as_slice());
            true
        }
        _ => false,
    }
}
