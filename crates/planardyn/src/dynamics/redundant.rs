//! Redundant actuation (docs/actuators.md, *Redundant actuation*): more actuators than
//! degrees of freedom. The actuators are the m coordinates followed by the pair actuators
//! (`Mechanism::pair_actuators`); a unit effort of actuator a on its pair's relative
//! coordinate q_a gives the generalized force column B_a = U^T D_x q_a^T, so the efforts tau_a
//! (n_a) produce B tau_a (m). B = L Q with Q's m rows orthonormal (Gram-Schmidt of B's rows,
//! L lower triangular): the minimum-norm efforts are Q^T L^-1 tau, the internal forces (the
//! efforts that move nothing, B N = 0) an orthonormal basis N of the complement of Q's rows.

use super::forward::forward;
use super::inverse::inverse;
use super::Drives;
use crate::kinematics::constraints::{pair_coordinate_grad, pair_coordinate_rate, Dense};
use crate::model::{Mechanism, PairId};
use crate::workspace::Workspace;
use crate::{Error, KinematicsError, SingularityKind};
use microlp::{ComparisonOp, OptimizationDirection, Problem, Variable};

/// Below this (relative to B's largest row norm) a direction counts as lost: the actuators
/// cannot produce some generalized force (an actuation singularity).
const RANK_TOL: f64 = 1e-10;

/// How the efforts are shared among redundant actuators.
#[derive(Debug, Clone, PartialEq)]
pub enum Distribution {
    /// The efforts of least Euclidean norm.
    MinNorm,
    /// The efforts whose largest magnitude is least (any number of internal forces; the
    /// efforts' units as they are, N m and N alike).
    MinMax,
    /// The minimum-norm efforts plus the internal forces N lambda (lambda: one value per
    /// basis vector of [`Actuation::internal`], N m or N): a prescribed preload.
    Preload(Vec<f64>),
}

/// The actuation of a mechanism at one point: B, its factors, and the internal forces.
#[derive(Debug, Clone)]
pub struct Actuation {
    /// Number of coordinates m and of actuators n_a.
    pub m: usize,
    pub n_a: usize,
    /// (m x n_a, row-major) B: generalized force per unit effort of each actuator.
    pub b: Vec<f64>,
    /// (n_a - m) orthonormal internal-force vectors, each n_a.
    pub internal: Vec<Vec<f64>>,
    /// (m x n_a) Q and (m x m) L of B = L Q (row-major).
    q: Vec<Vec<f64>>,
    l: Vec<f64>,
}

fn pair_grad(mech: &Mechanism, pair: PairId, x: &[f64], grad: &mut [f64]) {
    grad.fill(0.0);
    pair_coordinate_grad(&mech.pairs[pair.0], x, &mut Dense { j: grad, ncols: x.len() }, 0);
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// Unit vector of `v` after removing its components along `basis` (twice, for round-off),
/// with the norm before scaling.
fn orthogonalise(v: &mut [f64], basis: &[Vec<f64>]) -> f64 {
    for _ in 0..2 {
        for e in basis {
            let c = dot(v, e);
            v.iter_mut().zip(e).for_each(|(v, e)| *v -= c * e);
        }
    }
    let norm = dot(v, v).sqrt();
    if norm > 0.0 {
        v.iter_mut().for_each(|v| *v /= norm);
    }
    norm
}

impl Actuation {
    /// The actuation at the point in `ws` (after the kinematic stages, in its chart).
    pub fn at(mech: &Mechanism, ws: &Workspace) -> Result<Self, KinematicsError> {
        let (m, n_a, n) = (mech.dof(), mech.n_actuators(), ws.x.len());
        let pairs = mech.coordinates.iter().map(|c| c.pair).chain(mech.pair_actuators.iter().map(|a| a.pair));
        let mut b = vec![0.0; m * n_a];
        let mut grad = vec![0.0; n];
        for (a, pair) in pairs.enumerate() {
            pair_grad(mech, pair, &ws.x, &mut grad);
            for (j, u) in ws.u.chunks_exact(n).enumerate() {
                b[j * n_a + a] = dot(&grad, u);
            }
        }
        let scale = b.chunks_exact(n_a).map(|r| dot(r, r).sqrt()).fold(0.0, f64::max);
        let (mut q, mut l): (Vec<Vec<f64>>, Vec<f64>) = (Vec::with_capacity(m), vec![0.0; m * m]);
        for j in 0..m {
            let mut row = b[j * n_a..(j + 1) * n_a].to_vec();
            for (k, e) in q.iter().enumerate() {
                l[j * m + k] = dot(&row, e);
            }
            let norm = orthogonalise(&mut row, &q);
            if !(norm > RANK_TOL * scale) {
                return Err(KinematicsError::singular(SingularityKind::TypeII));
            }
            l[j * m + j] = norm;
            q.push(row);
        }
        let mut internal: Vec<Vec<f64>> = Vec::with_capacity(n_a - m);
        for i in 0..n_a {
            if internal.len() == n_a - m {
                break;
            }
            let mut v = vec![0.0; n_a];
            v[i] = 1.0;
            let both: Vec<Vec<f64>> = q.iter().chain(&internal).cloned().collect();
            if orthogonalise(&mut v, &both) > 1e-6 {
                internal.push(v);
            }
        }
        Ok(Actuation { m, n_a, b, internal, q, l })
    }

    /// The minimum-norm efforts (n_a) that produce generalized efforts `tau` (m).
    pub fn min_norm(&self, tau: &[f64]) -> Vec<f64> {
        let m = self.m;
        let mut y = vec![0.0; m];
        for j in 0..m {
            y[j] = (tau[j] - (0..j).map(|k| self.l[j * m + k] * y[k]).sum::<f64>()) / self.l[j * m + j];
        }
        let mut out = vec![0.0; self.n_a];
        for (yj, qj) in y.iter().zip(&self.q) {
            out.iter_mut().zip(qj).for_each(|(o, q)| *o += yj * q);
        }
        out
    }

    /// The efforts (n_a) producing generalized efforts `tau` (m), shared as `how` says.
    pub fn distribute(&self, tau: &[f64], how: &Distribution) -> Result<Vec<f64>, KinematicsError> {
        let mut out = self.min_norm(tau);
        let lambda = match how {
            Distribution::MinNorm => return Ok(out),
            Distribution::Preload(lambda) if lambda.len() != self.internal.len() => {
                return Err(KinematicsError::BadArgument {
                    name: "preload",
                    expected: format!("{} values, one per internal force", self.internal.len()),
                    got: format!("{}", lambda.len()),
                })
            }
            Distribution::Preload(lambda) => match lambda.iter().position(|l| !l.is_finite()) {
                Some(i) => {
                    return Err(KinematicsError::bad_argument(
                        "preload",
                        "finite values (N m or N), one per internal force",
                        format!("preload[{i}] = {}", lambda[i]),
                    ))
                }
                None => lambda.clone(),
            },
            Distribution::MinMax => min_max_lambda(&out, &self.internal)?,
        };
        for (l, v) in lambda.iter().zip(&self.internal) {
            out.iter_mut().zip(v).for_each(|(o, v)| *o += l * v);
        }
        // Finite preloads near the floating-point range can still overflow when added.
        super::regular::finite("efforts", out)
    }
}

/// The internal-force amounts lambda minimising max_a |t_a + (N lambda)_a|, as the LP
///   minimise s over (lambda, s)  subject to  -s <= t_a + N_a . lambda <= s  for every a,
/// with t scaled to a largest magnitude of 1 (the solver's feasibility tolerance is absolute).
/// microlp: pure Rust, maintained, few dependencies, and a simplex, whose optimum is a vertex
/// exact to round-off where an interior-point solver (clarabel) stops at its tolerance.
/// The drive map holds whatever lambda is: the efforts stay t + N lambda.
fn min_max_lambda(t: &[f64], internal: &[Vec<f64>]) -> Result<Vec<f64>, KinematicsError> {
    let scale = t.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    if scale == 0.0 {
        return Ok(vec![0.0; internal.len()]);
    }
    let mut lp = Problem::new(OptimizationDirection::Minimize);
    let lambda: Vec<Variable> = internal.iter().map(|_| lp.add_var(0.0, (f64::NEG_INFINITY, f64::INFINITY))).collect();
    let s = lp.add_var(1.0, (0.0, f64::INFINITY));
    for (a, &t_a) in t.iter().enumerate() {
        for sign in [1.0, -1.0] {
            let row = lambda.iter().zip(internal).map(|(&l, v)| (l, sign * v[a])).chain([(s, -1.0)]);
            lp.add_constraint(row.collect::<Vec<_>>(), ComparisonOp::Le, -sign * t_a / scale);
        }
    }
    let failed = |message: String| KinematicsError::EffortSharing { message };
    let solution = lp
        .solve()
        .map_err(|e| failed(e.to_string()))?
        .into_solution()
        .map_err(|_| failed("the LP solve was interrupted".into()))?;
    Ok(lambda.iter().map(|&l| scale * solution.var_value(l)).collect())
}

/// Inverse dynamics with redundant actuators: the joint-side efforts (n_a) of every actuator
/// for coordinates q, rates qd, accelerations qdd, shared as `how` says; `ws` is left with the
/// point's motion (and `ws.tau` the generalized efforts they produce). The sharing is of
/// the joint-side efforts, the gears' outputs: B and its internal forces are the mechanism's,
/// linear, where a motor's torque is not (its gear's efficiency changes with the direction of
/// the power, its Coulomb friction with that of its speed). Each rotor is its own motor's
/// (before its gear); its reaction on a moving housing is part of the generalized efforts.
/// [`super::motor_torques`] with `ws` gives the motor torques.
pub fn inverse_redundant(
    mech: &Mechanism,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    how: &Distribution,
    ws: &mut Workspace,
) -> Result<(Actuation, Vec<f64>), KinematicsError> {
    inverse(mech, q, qd, qdd, ws)?;
    let act = Actuation::at(mech, ws)?;
    let efforts = act.distribute(&ws.tau, how)?;
    Ok((act, efforts))
}

/// Drives for a forward evaluation with every actuator's effort: the coordinates' part.
struct CoordinateEfforts<'a>(&'a [f64]);

impl Drives for CoordinateEfforts<'_> {
    fn efforts(&mut self, _t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.copy_from_slice(&self.0[..tau.len()]);
        Ok(())
    }
}

/// Forward dynamics with every actuator's effort `efforts` (n_a: the coordinates' first, then
/// the pair actuators'; motor torques where an actuator has a motor, as in [`forward`]), at
/// time t (s) and chart state (z, zd). The model's drive laws are not
/// evaluated: `efforts` replaces them.
pub fn forward_redundant(
    mech: &Mechanism,
    t: f64,
    z: &[f64],
    zd: &[f64],
    efforts: &[f64],
    ws: &mut Workspace,
) -> Result<(), Error> {
    let m = mech.dof();
    ws.pair_tau.copy_from_slice(&efforts[m..]);
    let result = forward(mech, t, z, zd, &mut CoordinateEfforts(efforts), ws);
    ws.pair_tau.fill(0.0);
    result
}

/// Add the efforts of the pair actuators without a motor (`ws.pair_tau`) to `ws.f`; returns
/// their power (W). A motor's torque goes through its gear (`dynamics::gears`).
pub(crate) fn apply_pair_efforts(mech: &Mechanism, ws: &mut Workspace) -> f64 {
    let mut power = 0.0;
    for (a, &e) in mech.pair_actuators.iter().zip(&ws.pair_tau) {
        if e != 0.0 && a.drive.is_none() {
            let rate = pair_coordinate_rate(&mech.pairs[a.pair.0], &ws.x, &ws.xd);
            pair_grad(mech, a.pair, &ws.x, &mut ws.tmp);
            ws.f.iter_mut().zip(&ws.tmp).for_each(|(f, g)| *f += e * g);
            power += e * rate;
        }
    }
    power
}
