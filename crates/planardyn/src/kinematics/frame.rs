//! The kinematic frame: the buffers the kinematic stages fill, sized once from a mechanism and
//! never reallocated in a step (the kinematics' part of the evaluation's buffers, as MuJoCo's
//! `mjData` documents each of its arrays). The dynamics' buffers extend it in
//! [`crate::dynamics::Workspace`].
//!
//! Shapes use n bodies (3n body coordinates) and m generalized coordinates. The stage that
//! fills each buffer is named, in the order the kinematic stages run:
//! positions -> analogues -> convective term.

use super::{Chart, System};
use crate::model::Mechanism;

#[derive(Debug)]
pub struct Frame {
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
    /// The `System::supports_id` for which `u` holds zeros outside the supports (0: not
    /// known, cleared whole at the next use).
    pub u_zeros_for: u64,
    /// (3n) body velocities U zd (convective).
    pub xd: Vec<f64>,
    /// (3n) convective accelerations sum_jl zd_j zd_l w_jl (convective).
    pub c: Vec<f64>,
    /// (m) the user's coordinates q and rates qd (positions / convective); equal to z, zd in
    /// the input chart.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// (3n) scratch for right-hand sides.
    pub rhs: Vec<f64>,
    /// (3n) scratch for residuals and second derivatives.
    pub tmp: Vec<f64>,
}

clone_reusing!(Frame { chart, x, trig, sys, residual, iterations, u, u_zeros_for, xd, c, q, qd, rhs, tmp });

impl Frame {
    /// Buffers for `mech`, starting at its drawing in the input chart.
    pub fn new(mech: &Mechanism) -> Self {
        let (nx, m) = (mech.n_x(), mech.dof());
        Frame {
            chart: Chart::Inputs,
            x: mech.x0.clone(),
            trig: vec![[1.0, 0.0]; mech.n_bodies()],
            sys: System::new(mech),
            residual: 0.0,
            iterations: 0,
            u: vec![0.0; nx * m],
            u_zeros_for: 0,
            xd: vec![0.0; nx],
            c: vec![0.0; nx],
            q: vec![0.0; m],
            qd: vec![0.0; m],
            rhs: vec![0.0; nx],
            tmp: vec![0.0; nx],
        }
    }

    /// Velocity analogue column j (dx/dz_j).
    pub fn u_col(&self, j: usize) -> &[f64] {
        let n = self.x.len();
        &self.u[j * n..(j + 1) * n]
    }
}
