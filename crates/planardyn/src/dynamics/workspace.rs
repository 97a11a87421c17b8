//! Per-evaluation work buffers, sized once from a mechanism and never reallocated in a step.
//! One workspace per thread; the mechanism itself stays immutable and shared.
//!
//! A workspace is the kinematic frame ([`Frame`], the kinematics' buffers: x, U, c, q, qd,
//! ...) and the dynamics' buffers below. Each layer owns its own: the kinematic stages take
//! the frame alone, and the workspace dereferences to its frame, so `ws.x` reads the frame's
//! x and `solve_position(mech, z, ws)` takes a workspace as well as a frame.
//!
//! Shapes use n bodies (3n body coordinates) and m generalized coordinates. The stage that
//! fills each buffer is named, in the order a forward-dynamics evaluation runs them:
//! positions -> analogues -> convective term (the frame) -> forces -> A, b -> accelerations.

use std::ops::{Deref, DerefMut};

use super::loss_buffers::LossBuffers;
use crate::kinematics::Frame;
use crate::model::Mechanism;

#[derive(Debug)]
pub struct Workspace {
    /// The kinematic stages' buffers (positions, analogues, convective term).
    pub frame: Frame,
    /// The `System::supports_id` for which `a` holds zeros outside A's envelope (0: not
    /// known, cleared whole at the next use).
    pub a_zeros_for: u64,
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
    /// (m) b = U^T (f - M c) (A, b); with losses, of the forces before the friction.
    pub b: Vec<f64>,
    /// (m) the chart accelerations zdd = A^-1 b (accelerations).
    pub zdd: Vec<f64>,
    /// (m) the user's accelerations qdd; equal to zdd in the input chart (accelerations).
    pub qdd: Vec<f64>,
    /// (3n) body accelerations U zdd + c (accelerations).
    pub xdd: Vec<f64>,
    /// The transmissions' and the pair friction's buffers (forward and inverse with losses).
    pub losses: LossBuffers,
}

clone_reusing!(Workspace { frame, a_zeros_for, tau, pair_tau, f, power, dissipated, a, b, zdd, qdd, xdd, losses });

impl Workspace {
    /// Buffers for `mech`, starting at its drawing in the input chart.
    pub fn new(mech: &Mechanism) -> Self {
        let (nx, m) = (mech.n_x(), mech.dof());
        Workspace {
            frame: Frame::new(mech),
            a_zeros_for: 0,
            tau: vec![0.0; m],
            pair_tau: vec![0.0; mech.pair_actuators.len()],
            f: vec![0.0; nx],
            power: 0.0,
            dissipated: 0.0,
            a: vec![0.0; m * m],
            b: vec![0.0; m],
            zdd: vec![0.0; m],
            qdd: vec![0.0; m],
            xdd: vec![0.0; nx],
            losses: LossBuffers::new(mech),
        }
    }
}

impl Deref for Workspace {
    type Target = Frame;
    fn deref(&self) -> &Frame {
        &self.frame
    }
}

impl DerefMut for Workspace {
    fn deref_mut(&mut self) -> &mut Frame {
        &mut self.frame
    }
}
