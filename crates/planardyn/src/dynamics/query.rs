//! What a binding, or a Rust user, asks of a mechanism at one state, each as one call with a
//! typed result: the assembly, a kinematics report, the mass matrix, forward dynamics (and its
//! reactions), inverse dynamics, the derivatives of forward and inverse dynamics, redundant actuation both ways,
//! the energies. Every call makes its own buffers (a [`Frame`] or a [`Workspace`], sized once
//! per call), so calls are reproducible and thread-safe: positions come by continuation from
//! the drawing, or from the body coordinates `x_start` of a neighbouring state on the wanted
//! branch. The same quantities along the rows of a motion are `crate::batch`'s
//! (`inverse_rows_checked`, `motor_torque_rows`, `dissipation_rows`, `regressor_rows`) and
//! [`super::along`]; one view's whole state is [`super::evaluate`].
//!
//! Shapes with n bodies, m coordinates, P named points, p pairs, n_a actuators; matrices are
//! row-major; SI units and radians.

use super::derivatives::{self, Jacobians};
use super::redundant::{forward_redundant, inverse_redundant, Actuation, Distribution};
use super::{
    finite, forward, inverse, kinetic_energy, potential_energy, type_ii_measure, Drives, FixedDrives, ModelDrives,
};
use super::{motor_torques, Workspace};
use crate::kinematics::constraints::{point_velocity, world_point};
use crate::kinematics::{
    acceleration_analogues, assemble_from, assemble_into, convective, passive_sigma_min, sigma_min, velocity_analogues,
    Chart, Frame,
};
use crate::model::{Attachment, Mechanism, PointId};
use crate::{Error, KinematicsError};

/// Assembles `frame` at coordinates q (m): by continuation from `x_start` (3n) if given, else
/// from the drawing.
pub fn assemble_at(
    mech: &Mechanism,
    q: &[f64],
    x_start: Option<&[f64]>,
    frame: &mut Frame,
) -> Result<(), KinematicsError> {
    match x_start {
        Some(x) => assemble_from(mech, x, q, frame),
        None => assemble_into(mech, q, frame),
    }
}

/// A workspace assembled at q (see [`assemble_at`]): the start of every dynamics query.
pub fn assembled(mech: &Mechanism, q: &[f64], x_start: Option<&[f64]>) -> Result<Workspace, KinematicsError> {
    let mut ws = Workspace::new(mech);
    assemble_at(mech, q, x_start, &mut ws)?;
    Ok(ws)
}

/// Body coordinates x (3n; m, rad) at coordinates q, on the branch of `x_start` (else the
/// drawn one).
pub fn assemble(mech: &Mechanism, q: &[f64], x_start: Option<&[f64]>) -> Result<Vec<f64>, KinematicsError> {
    let mut frame = Frame::new(mech);
    assemble_at(mech, q, x_start, &mut frame)?;
    Ok(frame.x)
}

/// The kinematics at one configuration ([`kinematics`]).
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicsReport {
    /// Body coordinates [X, Y, phi] per body (3n; m, rad).
    pub x: Vec<f64>,
    /// Velocity analogues (3n x m): entry [i, j] = dx_i / dq_j (m or rad per unit of q_j).
    pub u: Vec<f64>,
    /// Acceleration analogues (3n x m x m): entry [i, j, k] = d^2 x_i / dq_j dq_k.
    pub w: Vec<f64>,
    /// World positions of every named point (P x 2, m); NaN for a point no link carries.
    pub points: Vec<f64>,
    /// The rates, when rates qd were given.
    pub rates: Option<KinematicRates>,
    /// Smallest scaled singular value of J in the input chart (type II measure; 0 at a
    /// singularity), and of the passive mechanism's constraints.
    pub sigma_min: f64,
    pub sigma_passive: f64,
    /// Loop-closure residual of the assembly (m).
    pub residual: f64,
}

/// The rates part of a [`KinematicsReport`].
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicRates {
    /// Body rates xd = U qd (3n; m/s, rad/s).
    pub xd: Vec<f64>,
    /// Convective accelerations c = sum_jk w_jk qd_j qd_k (3n; m/s^2, rad/s^2).
    pub c: Vec<f64>,
    /// Velocities of every named point (P x 2, m/s); NaN for a point no link carries.
    pub point_velocities: Vec<f64>,
}

/// Positions and analogues at coordinates q (and the rates with qd), on the branch of
/// `x_start` (else the drawn one). Stages: positions -> U -> w (-> xd, c) -> measures.
pub fn kinematics(
    mech: &Mechanism,
    q: &[f64],
    qd: Option<&[f64]>,
    x_start: Option<&[f64]>,
) -> Result<KinematicsReport, KinematicsError> {
    let mut frame = Frame::new(mech);
    assemble_at(mech, q, x_start, &mut frame)?;
    velocity_analogues(&mut frame)?;
    let w_cols = acceleration_analogues(mech, &mut frame);
    let carriers = carriers(mech);
    let rates = match qd {
        Some(qd) => {
            convective(mech, qd, &mut frame);
            finite("body velocities xd", &frame.xd)?;
            finite("convective accelerations c", &frame.c)?;
            let point_velocities = per_point(&carriers, |a| point_velocity(a.link, a.s, &frame.x, &frame.xd));
            Some(KinematicRates { xd: frame.xd.clone(), c: frame.c.clone(), point_velocities })
        }
        None => None,
    };
    // The core keeps U and w by columns (u_j, w_jk: 3n each); the report gives them row-major.
    let (nx, m) = (frame.x.len(), q.len());
    let u = (0..nx * m).map(|e| frame.u[(e % m) * nx + e / m]).collect();
    let w = (0..nx * m * m).map(|e| w_cols[(e % (m * m)) * nx + e / (m * m)]).collect();
    Ok(KinematicsReport {
        u,
        w,
        points: per_point(&carriers, |a| world_point(a.link, a.s, &frame.x)),
        rates,
        sigma_min: sigma_min(mech, &Chart::Inputs, &frame.x),
        sigma_passive: passive_sigma_min(mech, &frame.x),
        residual: frame.residual,
        x: frame.x,
    })
}

/// For each named point, the link that carries it first (ground before bodies) and where.
fn carriers(mech: &Mechanism) -> Vec<Option<Attachment>> {
    (0..mech.points.len()).map(|p| mech.carrier(PointId(p))).collect()
}

/// `f` of every carried point (P x 2), NaN for a point no link carries.
fn per_point(carriers: &[Option<Attachment>], f: impl Fn(&Attachment) -> [f64; 2]) -> Vec<f64> {
    carriers.iter().flat_map(|c| c.as_ref().map_or([f64::NAN; 2], &f)).collect()
}

/// World positions of every named point (P x 2, m; NaN for a point no link carries) at body
/// coordinates x (3n).
pub fn point_positions(mech: &Mechanism, x: &[f64]) -> Vec<f64> {
    per_point(&carriers(mech), |a| world_point(a.link, a.s, x))
}

/// The mass matrix A = U^T M U (m x m; kg, kg m, kg m^2) at q, on the branch of `x_start`
/// (else the drawn one); refused near a type II singularity unless `allow_singular`.
pub fn mass_matrix(
    mech: &Mechanism,
    q: &[f64],
    x_start: Option<&[f64]>,
    allow_singular: bool,
) -> Result<Vec<f64>, KinematicsError> {
    let mut ws = assembled(mech, q, x_start)?;
    velocity_analogues(&mut ws)?;
    type_ii_measure(mech, &mut ws, allow_singular)?;
    super::mass_matrix(mech, &mut ws);
    Ok(ws.a)
}

/// The model's drives, or the efforts `tau` (m; N m or N per coordinate) when given.
fn with_drives<R>(mech: &Mechanism, tau: Option<&[f64]>, f: impl FnOnce(&mut dyn Drives) -> R) -> R {
    match tau {
        Some(tau) => f(&mut FixedDrives(tau)),
        None => f(&mut ModelDrives(mech)),
    }
}

/// Where forward dynamics is asked: coordinates q and rates qd (m each), time t (s), and the
/// efforts (m; N m or N, motor torques where a motor is) `tau`, or the model's drives if None.
/// The positions are those of the branch of `x_start` (3n; else the drawn one); a state near
/// a type II singularity is refused (`Singular`) unless `allow_singular`.
#[derive(Debug, Clone, Copy)]
pub struct ForwardState<'a> {
    pub q: &'a [f64],
    pub qd: &'a [f64],
    pub t: f64,
    pub tau: Option<&'a [f64]>,
    pub allow_singular: bool,
    pub x_start: Option<&'a [f64]>,
}

/// A forward evaluation at `at`: every buffer of the returned workspace filled. Refused also
/// where the accelerations are not finite.
pub fn forward_at(mech: &Mechanism, at: ForwardState<'_>) -> Result<Workspace, Error> {
    let ForwardState { q, qd, t, tau, allow_singular, x_start } = at;
    let mut ws = assembled(mech, q, x_start)?;
    with_drives(mech, tau, |drives| forward(mech, t, q, qd, drives, &mut ws))?;
    type_ii_measure(mech, &mut ws, allow_singular)?;
    finite("accelerations qdd", &ws.qdd)?;
    Ok(ws)
}

/// Accelerations qdd (m; rad/s^2 or m/s^2) of [`forward_at`].
pub fn forward_dynamics(mech: &Mechanism, at: ForwardState<'_>) -> Result<Vec<f64>, Error> {
    Ok(forward_at(mech, at)?.qdd)
}

/// Pair reactions (p, each [F_x, F_y, M] that body a exerts on body b; N, N m) of
/// [`forward_at`].
pub fn reactions(mech: &Mechanism, at: ForwardState<'_>) -> Result<Vec<[f64; 3]>, Error> {
    let mut ws = forward_at(mech, at)?;
    let r = super::reactions(mech, &mut ws);
    finite("reactions", r.as_flattened())?;
    Ok(r)
}

/// Drive efforts tau (m; N m or N, joint side) for (q, qd, qdd), on the branch of `x_start`
/// (else the drawn one): inverse dynamics at one state ([`super::inverse`]; along rows,
/// `crate::batch::inverse_rows_checked`).
pub fn inverse_dynamics(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    x_start: Option<&[f64]>,
) -> Result<Vec<f64>, Error> {
    let mut ws = assembled(mech, q, x_start)?;
    inverse(mech, q, qd, qdd, &mut ws)?;
    Ok(ws.tau)
}

/// A value of a dynamics map with its three Jacobians.
#[derive(Debug, Clone, PartialEq)]
pub struct Derivatives {
    /// qdd (forward dynamics) or tau (inverse dynamics), m values.
    pub value: Vec<f64>,
    /// d value / d (q, qd, and tau or qdd), each m x m.
    pub jacobians: Jacobians,
}

/// Exact first derivatives of forward dynamics at `at`, with its efforts held fixed
/// ([`derivatives::forward_derivatives`]).
pub fn forward_derivatives(mech: &Mechanism, at: ForwardState<'_>) -> Result<Derivatives, Error> {
    let ForwardState { q, qd, t, tau, allow_singular, x_start } = at;
    let mut ws = assembled(mech, q, x_start)?;
    let mut efforts = vec![0.0; q.len()];
    with_drives(mech, tau, |drives| drives.efforts(t, q, qd, &mut efforts))
        .map_err(|message| Error::Drive { t, message })?;
    let (value, jacobians) = derivatives::forward_derivatives(mech, q, qd, &efforts, &mut ws)?;
    type_ii_measure(mech, &mut ws, allow_singular)?;
    Ok(Derivatives { value, jacobians })
}

/// Exact first derivatives of inverse dynamics at (q, qd, qdd), on the drawn branch
/// ([`derivatives::inverse_derivatives`]); refused near a type II singularity unless
/// `allow_singular`.
pub fn inverse_derivatives(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    allow_singular: bool,
) -> Result<Derivatives, Error> {
    let mut ws = assembled(mech, q, None)?;
    let jacobians = derivatives::inverse_derivatives(mech, q, qd, qdd, &mut ws)?;
    type_ii_measure(mech, &mut ws, allow_singular)?;
    Ok(Derivatives { value: ws.tau, jacobians })
}

/// Every actuator's share of a motion ([`distribute_efforts`]).
#[derive(Debug, Clone)]
pub struct SharedEfforts {
    /// The actuation matrix B (m x n_a) and the internal forces.
    pub actuation: Actuation,
    /// Joint-side efforts (n_a; N m or N), the coordinates' first, then the pair actuators'.
    pub efforts: Vec<f64>,
    /// Motor torques (n_a; N m, motor side); on an actuator without a motor, the effort.
    pub motor_torques: Vec<f64>,
}

/// Every actuator's effort for (q, qd, qdd), shared as `how` says
/// ([`inverse_redundant`]), on the branch of `x_start` (else the drawn one).
pub fn distribute_efforts(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    how: &Distribution,
    x_start: Option<&[f64]>,
) -> Result<SharedEfforts, Error> {
    let mut ws = assembled(mech, q, x_start)?;
    let (actuation, efforts) = inverse_redundant(mech, q, qd, qdd, how, &mut ws)?;
    let mut t_m = vec![0.0; efforts.len()];
    motor_torques(mech, &ws, &efforts, &mut t_m);
    Ok(SharedEfforts { actuation, efforts, motor_torques: finite("motor torques", t_m)? })
}

/// Accelerations qdd (m) at (q, qd) and time t (s) under every actuator's effort `efforts`
/// (n_a: the coordinates' first, as drive efforts, motor torques where a motor is, then the
/// pair actuators'), on the drawn branch ([`forward_redundant`]).
pub fn forward_actuated(mech: &Mechanism, q: &[f64], qd: &[f64], efforts: &[f64], t: f64) -> Result<Vec<f64>, Error> {
    let mut ws = assembled(mech, q, None)?;
    forward_redundant(mech, t, q, qd, efforts, &mut ws)?;
    finite("accelerations qdd", &ws.qdd)?;
    Ok(ws.qdd)
}

/// Kinetic and potential energy (J).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energies {
    pub kinetic: f64,
    pub potential: f64,
}

/// The energies at (q, qd), on the branch of `x_start` (else the drawn one). At rest no
/// analogues are needed (xd = 0), so a configuration where they are undefined has energies too.
pub fn energy(mech: &Mechanism, q: &[f64], qd: &[f64], x_start: Option<&[f64]>) -> Result<Energies, KinematicsError> {
    let mut frame = Frame::new(mech);
    assemble_at(mech, q, x_start, &mut frame)?;
    if qd.iter().any(|&v| v != 0.0) {
        velocity_analogues(&mut frame)?;
        convective(mech, qd, &mut frame);
    } else {
        frame.xd.fill(0.0);
    }
    let [kinetic, potential] = finite("energies", [kinetic_energy(mech, &frame.xd), potential_energy(mech, &frame.x)])?;
    Ok(Energies { kinetic, potential })
}
