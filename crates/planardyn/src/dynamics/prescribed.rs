//! Forward dynamics with some coordinates q_p driven by motion (docs/formulation.md,
//! *Prescribed motion*). In a chart z with A zdd = b + G^T tau_p, the prescribed
//! coordinates' rows G = D_p,x U and their accelerations G zdd = h with
//! h = qdd_p - D_p,x c - gamma_p(xd, xd), the efforts tau_p they need are the multipliers
//! of G zdd = h:
//!   (G A^-1 G^T) tau_p = h - G A^-1 b,   zdd = A^-1 (b + G^T tau_p).
//! In the user's chart G = [0 I] picks q_p and h = qdd_p, and this is
//! A_ff qdd_f = b_f - A_fp qdd_p, tau_p = A_pf qdd_f + A_pp qdd_p - b_p; in a partition chart
//! (near a type II singularity of the user's coordinates) the same equations hold the
//! prescribed coordinates to their motion while x components integrate.

use super::forces::{applied_forces, Drives};
use super::losses::{forward_with_losses_by, Solve};
use super::motion::{Prescribed, Scratch};
use super::stages::{accelerations, drive_efforts, factor_mass_matrix, kinematic_stages, mass_matrix_and_bias};
use super::workspace::Workspace;
use crate::kinematics::constraints::body_trig;
use crate::kinematics::constraints::{pair_coordinate_gamma, pair_coordinate_grad, Dense};
use crate::kinematics::system::{col_scales, scaled_jacobian};
use crate::kinematics::Chart;
use crate::linalg::{cholesky_in_place, cholesky_solve};
use crate::model::Mechanism;
use crate::{Error, KinematicsError, SingularityKind};
use nalgebra::DMatrix;

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// D_p,x, G and h of the prescribed rows at the point in `ws` (after the kinematic stages),
/// with the motion's accelerations `qdd_p`.
fn prescribed_rows(mech: &Mechanism, p: &[usize], qdd_p: &[f64], ws: &Workspace, w: &mut Scratch) {
    let (m, nx) = (ws.q.len(), ws.x.len());
    w.grad.fill(0.0);
    for (i, &k) in p.iter().enumerate() {
        let pair = &mech.pairs[mech.coordinates[k].pair.0];
        let grad = &mut w.grad[i * nx..(i + 1) * nx];
        pair_coordinate_grad(pair, &ws.x, &mut Dense { j: grad, ncols: nx }, 0);
        let g = &mut w.g[i * m..(i + 1) * m];
        if ws.chart == Chart::Inputs {
            // D_x U = I and D_x c + gamma(xd, xd) = 0 in the user's chart, by construction of U and c.
            g.iter_mut().enumerate().for_each(|(j, g)| *g = f64::from(j == k));
            w.h0[i] = qdd_p[i];
        } else {
            g.iter_mut().enumerate().for_each(|(j, g)| *g = dot(grad, ws.u_col(j)));
            w.h0[i] = qdd_p[i] - dot(grad, &ws.c) - pair_coordinate_gamma(pair, &ws.x, &ws.xd, &ws.xd);
        }
    }
}

/// One evaluation at time t (s) and chart state (z, zd) with the coordinates of `motion`
/// (evaluated at t) driven by it: fills every buffer of `ws` as `forward` does, with the
/// prescribed efforts in `ws.tau` (joint-side: a motor's gear output, its rotor not included;
/// the drives' values there are replaced) and their power in `ws.power`. With the actuators'
/// transmissions or Coulomb pair friction, the prescribed efforts are the multipliers of each
/// fixed-point step of `dynamics::losses`, so the friction, the gears, the reactions, the free
/// coordinates' accelerations and the prescribed efforts settle together.
pub fn forward_prescribed(
    mech: &Mechanism,
    t: f64,
    z: &[f64],
    zd: &[f64],
    drives: &mut dyn Drives,
    motion: &mut Prescribed,
    ws: &mut Workspace,
) -> Result<(), Error> {
    kinematic_stages(mech, z, zd, ws)?;
    drive_efforts(t, drives, ws)?;
    ws.losses.take_motor_torques(&mut ws.tau, &ws.pair_tau);
    let Prescribed { p, qdd: qdd_p, scratch: w, .. } = motion;
    p.iter().for_each(|&k| ws.tau[k] = 0.0);
    ws.power = applied_forces(mech, &ws.frame.x, &ws.frame.xd, &ws.tau, &mut ws.f);
    mass_matrix_and_bias(mech, ws);
    prescribed_rows(mech, p, qdd_p, ws, w);
    let mut solver = Held { p, w };
    if mech.has_losses() {
        forward_with_losses_by(mech, ws, &mut solver)?;
    } else {
        factor_mass_matrix(ws)?;
        let mut zdd = std::mem::take(&mut ws.zdd);
        zdd.copy_from_slice(&ws.b);
        let solved = solver.solve(ws, &mut zdd, false);
        ws.zdd = zdd;
        solved?;
        solver.add_efforts(ws);
        accelerations(mech, ws);
    }
    for (&k, &tau) in p.iter().zip(&w.h) {
        ws.tau[k] = tau;
        ws.power += tau * ws.qd[k];
    }
    Ok(())
}

/// A zdd = rhs + G^T tau_p with the prescribed rows G zdd = h held: the solver of
/// `dynamics::losses` for a motion with prescribed coordinates (A factored in `ws.a`).
struct Held<'a> {
    p: &'a [usize],
    w: &'a mut Scratch,
}

impl Solve for Held<'_> {
    /// zdd of `rhs` in place, with the efforts tau_p into `w.h` (from the rows' `w.h0`, or 0 when
    /// `homogeneous`, then into `w.t`).
    fn solve(&mut self, ws: &Workspace, rhs: &mut [f64], homogeneous: bool) -> Result<(), KinematicsError> {
        let (m, mp) = (rhs.len(), self.p.len());
        let w = &mut *self.w;
        cholesky_solve(&ws.a, m, rhs);
        for i in 0..mp {
            let col = &mut w.ainv_gt[i * m..(i + 1) * m];
            col.copy_from_slice(&w.g[i * m..(i + 1) * m]);
            cholesky_solve(&ws.a, m, col);
        }
        let tau = if homogeneous { &mut w.t } else { &mut w.h };
        for (i, (tau, g)) in tau.iter_mut().zip(w.g.chunks_exact(m)).enumerate() {
            *tau = if homogeneous { 0.0 } else { w.h0[i] } - dot(g, rhs);
            for k in 0..mp {
                w.s[i * mp + k] = dot(&w.g[i * m..(i + 1) * m], &w.ainv_gt[k * m..(k + 1) * m]);
            }
        }
        // G A^-1 G^T is positive definite unless the prescribed coordinates are dependent where
        // the motion takes them (a type II singularity of their own drives).
        if !cholesky_in_place(&mut w.s, mp) {
            return Err(KinematicsError::singular(SingularityKind::TypeII));
        }
        cholesky_solve(&w.s, mp, tau);
        for (i, &t) in tau.iter().enumerate() {
            for (zdd, a) in rhs.iter_mut().zip(&w.ainv_gt[i * m..(i + 1) * m]) {
                *zdd += a * t;
            }
        }
        Ok(())
    }

    fn prescribed(&self, k: usize) -> bool {
        self.p.contains(&k)
    }

    fn add_efforts(&mut self, ws: &mut Workspace) {
        let nx = ws.x.len();
        for (i, &tau) in self.w.h.iter().enumerate() {
            for (f, g) in ws.f.iter_mut().zip(&self.w.grad[i * nx..(i + 1) * nx]) {
                *f += tau * g;
            }
        }
    }
}

/// Smallest singular value of the scaled [Phi_x; D_p,x] at x: the pair constraints with the
/// prescribed coordinates `p` fixed. It is 0 where they stop determining their part of the
/// mechanism, and the efforts their motion needs grow without bound (with every coordinate
/// prescribed, the type II measure).
pub fn prescribed_sigma_min(mech: &Mechanism, p: &[usize], x: &[f64]) -> f64 {
    let (n, nc) = (x.len(), mech.n_constraints);
    let mut trig = vec![[0.0; 2]; mech.n_bodies()];
    body_trig(x, &mut trig);
    let mut j = vec![0.0; n * n];
    scaled_jacobian(mech, &Chart::Inputs, x, &trig, &mut vec![1.0; n], &col_scales(mech), &mut j);
    let rows: Vec<usize> = (0..nc).chain(p.iter().map(|k| nc + k)).collect();
    if rows.is_empty() || j.iter().any(|v| !v.is_finite()) {
        return if rows.is_empty() { f64::INFINITY } else { 0.0 };
    }
    let a = DMatrix::from_fn(rows.len(), n, |r, c| j[rows[r] * n + c]);
    a.singular_values().iter().copied().fold(f64::INFINITY, f64::min)
}
