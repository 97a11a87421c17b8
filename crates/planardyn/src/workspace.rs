//! Per-evaluation work buffers, sized once from a mechanism and never reallocated in a step.
//! One workspace per thread; the mechanism itself stays immutable and shared.
//!
//! Shapes use n bodies (3n body coordinates) and m generalized coordinates. The stage that
//! fills each buffer is named, in the order a forward-dynamics evaluation runs them:
//! positions -> analogues -> convective term -> forces -> A, b -> accelerations.

use crate::dynamics::LossBuffers;
use crate::kinematics::{Chart, System};
use crate::model::Mechanism;

#[derive(Debug, Clone)]
pub struct Workspace {
    /// The chart whose coordinates z the position stage solves for.
    pub chart: Chart,
    /// (3n) body coordinates [X, Y, phi] per body; the Newton start before `position`,
    /// the solution after it.
    pub x: Vec<f64>,
    /// (n) [cos, sin] of each body angle at `x` (position).
    pub trig: Vec<[f64; 2]>,
    /// J(x) of the chart, scaled and factorised (position).
    pub sys: System,
    /// Largest scaled loop-closure residual left by the last position solve (position).
    pub residual: f64,
    /// Newton iterations of the last position solve (position).
    pub iterations: usize,
    /// (3n x m) velocity analogues, column j = dx/dz_j stored at `u[j*3n..(j+1)*3n]` (analogues).
    /// Zero outside each column's support (`System::u_support`).
    pub u: Vec<f64>,
    /// The `System::supports_id` for which `u` and `a` hold zeros outside the supports and
    /// A's envelope (0: not known, cleared whole at the next use).
    pub u_zeros_for: u64,
    pub a_zeros_for: u64,
    /// (3n) body velocities U zd (convective).
    pub xd: Vec<f64>,
    /// (3n) convective accelerations sum_jl zd_j zd_l w_jl (convective).
    pub c: Vec<f64>,
    /// (m) the user's coordinates q, rates qd and accelerations qdd (positions / convective /
    /// accelerations); equal to z, zd, zdd in the input chart.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// (m) drive efforts on q (forces).
    pub tau: Vec<f64>,
    /// Efforts (N m or N) of the redundant pair actuators during a forward evaluation
    /// (`dynamics::redundant::forward_redundant`), zero otherwise (forces).
    pub pair_tau: Vec<f64>,
    /// (3n) applied forces and moments at the centres of mass, drives included (forces).
    pub f: Vec<f64>,
    /// Power of the non-conservative forces: drives, dampers, external loads (W) (forces).
    pub power: f64,
    /// Power dissipated by the pairs' Coulomb friction (W, >= 0) (forces, with losses).
    pub dissipated: f64,
    /// (m x m, row-major) A = U^T M U, then its Cholesky factor (A, b).
    pub a: Vec<f64>,
    /// (m) b = U^T (f - M c), then zdd (A, b).
    pub b: Vec<f64>,
    /// (3n) body accelerations U zdd + c (accelerations).
    pub xdd: Vec<f64>,
    /// (3n) scratch for right-hand sides.
    pub rhs: Vec<f64>,
    /// (3n) scratch for residuals and second derivatives.
    pub tmp: Vec<f64>,
    /// The transmissions' and the pair friction's buffers (forward and inverse with losses).
    pub losses: LossBuffers,
}

impl Workspace {
    /// Buffers for `mech`, starting at its drawing in the input chart.
    pub fn new(mech: &Mechanism) -> Self {
        let (nx, m) = (mech.n_x(), mech.dof());
        Workspace {
            chart: Chart::Inputs,
            x: mech.x0.clone(),
            trig: vec![[1.0, 0.0]; mech.n_bodies()],
            sys: System::new(mech),
            residual: 0.0,
            iterations: 0,
            u: vec![0.0; nx * m],
            u_zeros_for: 0,
            a_zeros_for: 0,
            xd: vec![0.0; nx],
            c: vec![0.0; nx],
            q: vec![0.0; m],
            qd: vec![0.0; m],
            qdd: vec![0.0; m],
            tau: vec![0.0; m],
            pair_tau: vec![0.0; mech.pair_actuators.len()],
            f: vec![0.0; nx],
            power: 0.0,
            dissipated: 0.0,
            a: vec![0.0; m * m],
            b: vec![0.0; m],
            xdd: vec![0.0; nx],
            rhs: vec![0.0; nx],
            tmp: vec![0.0; nx],
            losses: LossBuffers::new(mech),
        }
    }

    /// Velocity analogue column j (dx/dz_j).
    pub fn u_col(&self, j: usize) -> &[f64] {
        let n = self.x.len();
        &self.u[j * n..(j + 1) * n]
    }
}
