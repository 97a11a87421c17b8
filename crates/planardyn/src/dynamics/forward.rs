//! Forward dynamics, docs/formulation.md eqs. 29-31 in the workspace's chart z:
//!   positions -> analogues U -> convective term c -> forces f -> A = U^T M U,
//!   b = U^T (f - M c) -> zdd = A^-1 b -> xdd = U zdd + c, qdd.

use super::forces::{applied_forces, Drives};
use super::losses::forward_with_losses;
use super::redundant;
use crate::kinematics::constraints::{coordinate_rates, coordinates, pair_coordinate_gamma, pair_coordinate_rate};
use crate::kinematics::{convective, solve_position, velocity_analogues, Chart};
use crate::linalg::{cholesky_envelope, cholesky_in_place, cholesky_solve, cholesky_solve_envelope};
use crate::model::Mechanism;
use crate::workspace::Workspace;
use crate::{Error, KinematicsError, SingularityKind};

/// sum_i M_ii a_i b_i over the body coordinates, M = blockdiag(m, m, I) per body.
/// a^T M b over the bodies `first..end` (a and b: 3n values each).
#[inline]
pub(crate) fn m_dot(mech: &Mechanism, a: &[f64], b: &[f64], (first, end): (usize, usize)) -> f64 {
    if first >= end {
        return 0.0;
    }
    let (a, b) = (&a[3 * first..3 * end], &b[3 * first..3 * end]);
    mech.bodies[first..end]
        .iter()
        .zip(a.chunks_exact(3).zip(b.chunks_exact(3)))
        .map(|(body, (a, b))| body.mass * (a[0] * b[0] + a[1] * b[1]) + body.inertia * a[2] * b[2])
        .sum()
}

/// A = U^T M U (m x m, row-major) into `ws.a`, from `ws.u`: the pairs of columns whose
/// supports meet (`System::a_pairs`), over the bodies where both may be non-zero (the columns
/// of independent parts of a mechanism, five-bars side by side, share none). The other
/// entries keep the zeros of the last clearing, except where the Cholesky factor may have
/// filled in (`System::a_fill_in`): cleared at each call.
pub fn mass_matrix(mech: &Mechanism, ws: &mut Workspace) {
    let n = ws.x.len();
    let m = ws.b.len();
    let id = ws.sys.supports_id();
    if ws.a_zeros_for != id {
        ws.a.fill(0.0);
        ws.a_zeros_for = id;
    } else {
        for &(k, j) in ws.sys.a_fill_in() {
            ws.a[k * m + j] = 0.0;
        }
    }
    let support = ws.sys.u_support();
    for &(j, k) in ws.sys.a_pairs() {
        let ((fj, ej), (fk, ek)) = (support[j], support[k]);
        let s = m_dot(mech, &ws.u[j * n..(j + 1) * n], &ws.u[k * n..(k + 1) * n], (fj.max(fk), ej.min(ek)));
        ws.a[j * m + k] = s;
        ws.a[k * m + j] = s;
    }
}

/// b = U^T (f - M c) = U^T f - (U^T M c) into `ws.b`, from `ws.u`, `ws.f`, `ws.c`.
pub(crate) fn bias(mech: &Mechanism, ws: &mut Workspace) {
    let n = ws.x.len();
    for (j, bj) in ws.b.iter_mut().enumerate() {
        let uj = &ws.u[j * n..(j + 1) * n];
        let (first, end) = ws.sys.u_support()[j];
        let (u, f) = (&uj[3 * first..3 * end], &ws.f[3 * first..3 * end]);
        *bj = u.iter().zip(f).map(|(u, f)| u * f).sum::<f64>() - m_dot(mech, uj, &ws.c, (first, end));
    }
}

/// The user's coordinates and rates from x, xd. In the input chart they are the chart's own
/// z, zd: D(x) = z to the Newton tolerance and D_x U = I, so they are copied rather than
/// recomputed.
fn user_coordinates(mech: &Mechanism, ws: &mut Workspace, z: &[f64], zd: &[f64]) {
    if ws.chart == Chart::Inputs {
        ws.q.copy_from_slice(z);
        ws.qd.copy_from_slice(zd);
    } else {
        coordinates(mech, &ws.x, &mut ws.q);
        coordinate_rates(mech, &ws.x, &ws.xd, &mut ws.qd);
    }
}

/// The user's accelerations from x, xd and xdd; in the input chart the chart's own zdd, in
/// `ws.b` (as [`user_coordinates`]).
fn user_accelerations(mech: &Mechanism, ws: &mut Workspace) {
    if ws.chart == Chart::Inputs {
        ws.qdd.copy_from_slice(&ws.b);
        return;
    }
    for (k, c) in mech.coordinates.iter().enumerate() {
        let p = &mech.pairs[c.pair.0];
        ws.qdd[k] = pair_coordinate_rate(p, &ws.x, &ws.xdd) + pair_coordinate_gamma(p, &ws.x, &ws.xd, &ws.xd);
    }
}

/// Positions, analogues and the convective term at chart coordinates z, zd (`ws.x` is the
/// Newton start), then the user's coordinates q and rates qd.
pub fn kinematic_stages(mech: &Mechanism, z: &[f64], zd: &[f64], ws: &mut Workspace) -> Result<(), KinematicsError> {
    solve_position(mech, z, ws)?;
    velocity_analogues(ws)?;
    convective(mech, zd, ws);
    user_coordinates(mech, ws, z, zd);
    Ok(())
}

/// One forward-dynamics evaluation at time t (s) and chart state (z, zd): fills every
/// buffer of `ws`; the chart accelerations zdd are left in `ws.b`, the user's in `ws.qdd`.
/// On a coordinate with an actuator the drive's effort is the motor torque (N m, motor
/// side); `ws.tau` ends with the joint-side efforts.
pub fn forward(
    mech: &Mechanism,
    t: f64,
    z: &[f64],
    zd: &[f64],
    drives: &mut dyn Drives,
    ws: &mut Workspace,
) -> Result<(), Error> {
    kinematic_stages(mech, z, zd, ws)?;
    dynamic_stages(mech, t, drives, ws)
}

/// The stages of [`forward`] after the kinematic ones (whose results `ws` holds): forces,
/// A, b, zdd, xdd and the user's accelerations.
pub fn dynamic_stages(mech: &Mechanism, t: f64, drives: &mut dyn Drives, ws: &mut Workspace) -> Result<(), Error> {
    drive_efforts(t, drives, ws)?;
    ws.losses.take_motor_torques(&mut ws.tau, &ws.pair_tau);
    ws.power = applied_forces(mech, &ws.x, &ws.xd, &ws.tau, &mut ws.f);
    ws.power += redundant::apply_pair_efforts(mech, ws);
    mass_matrix(mech, ws);
    bias(mech, ws);
    if mech.has_losses() {
        return Ok(forward_with_losses(mech, ws)?);
    }
    factor_mass_matrix(ws)?;
    solve_mass_matrix(ws);
    accelerations(mech, ws);
    Ok(())
}

/// The drives' efforts at time t (s) and the point in `ws` into `ws.tau`, checked finite.
pub(crate) fn drive_efforts(t: f64, drives: &mut dyn Drives, ws: &mut Workspace) -> Result<(), Error> {
    drives.efforts(t, &ws.q, &ws.qd, &mut ws.tau).map_err(|message| Error::Drive { t, message })?;
    if let Some(bad) = ws.tau.iter().position(|v| !v.is_finite()) {
        return Err(Error::Drive { t, message: format!("effort {bad} is {}", ws.tau[bad]) });
    }
    Ok(())
}

/// `ws.a` into its Cholesky factor, or the singularity that keeps A from being positive definite.
/// Over A's envelope from the supports of U when `mass_matrix` left A within it.
pub(crate) fn factor_mass_matrix(ws: &mut Workspace) -> Result<(), KinematicsError> {
    let m = ws.b.len();
    let factored = if ws.a_zeros_for == ws.sys.supports_id() {
        cholesky_envelope(&mut ws.a, m, ws.sys.a_first())
    } else {
        cholesky_in_place(&mut ws.a, m)
    };
    if !factored {
        let type_ii = matches!(ws.chart, Chart::Inputs);
        return Err(KinematicsError::singular(SingularityKind::MassMatrix { type_ii }));
    }
    Ok(())
}

/// zdd = A^-1 b in `ws.b`, with the factor from [`factor_mass_matrix`].
pub(crate) fn solve_mass_matrix(ws: &mut Workspace) {
    let mut b = std::mem::take(&mut ws.b);
    solve_factored(ws, &mut b);
    ws.b = b;
}

/// A^-1 rhs in place, with the factor from [`factor_mass_matrix`] (over its envelope when it
/// kept one).
pub(crate) fn solve_factored(ws: &Workspace, rhs: &mut [f64]) {
    let m = rhs.len();
    if ws.a_zeros_for == ws.sys.supports_id() {
        cholesky_solve_envelope(&ws.a, m, ws.sys.a_first(), rhs);
    } else {
        cholesky_solve(&ws.a, m, rhs);
    }
}

/// Body accelerations xdd = U zdd + c and the user's qdd from the chart accelerations zdd
/// in `ws.b`, at the point of the kinematic stages.
pub(crate) fn accelerations(mech: &Mechanism, ws: &mut Workspace) {
    body_accelerations(&ws.u, &ws.c, &ws.b, ws.sys.u_support(), &mut ws.xdd);
    user_accelerations(mech, ws);
}

/// xdd = U zdd + c: the body accelerations of chart accelerations zdd (U column-major,
/// one column of 3n a coordinate), each column over the bodies of its `support`
/// (`System::u_support`), where it may be non-zero.
pub(crate) fn body_accelerations(u: &[f64], c: &[f64], zdd: &[f64], support: &[(usize, usize)], xdd: &mut [f64]) {
    let n = c.len();
    xdd.copy_from_slice(c);
    for ((u, &a), &(first, end)) in u.chunks_exact(n).zip(zdd).zip(support) {
        for (x, u) in xdd[3 * first..3 * end].iter_mut().zip(&u[3 * first..3 * end]) {
            *x += u * a;
        }
    }
}
