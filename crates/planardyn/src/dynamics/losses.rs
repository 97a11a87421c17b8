//! Forward and inverse dynamics with the actuators' transmissions and the pairs' Coulomb
//! friction (docs/actuators.md). The friction efforts e depend on the reactions, which
//! depend on the accelerations, which depend on e: at each evaluation the three are solved
//! together by a fixed-point iteration on e, to round-off, each step solving the motors'
//! gears with the accelerations (`dynamics::gears`). It converges while a unit change of the
//! efforts changes the friction by less than itself (mu r small against the mechanism's lever
//! arms); a mechanism that self-locks, where the iterates grow instead, is reported, not
//! guessed.
//!
//! A gear mesh's friction acts on its driver's pitch-line travel (`gear::Side`): which
//! gear drives follows the tooth force found at each step, as the sign of the power that
//! crosses the mesh.

use super::forward::{accelerations, body_accelerations, factor_mass_matrix, solve_factored};
use super::friction;
use super::gears::{Gears, Rotor};
use super::reactions::reactions_into;
use super::transmission::{actuator_pair, motor_torque, motors};
use crate::kinematics::constraints::{pair_coordinate_gamma, pair_coordinate_grad, pair_coordinate_rate, Dense};
use crate::model::pairs::gear::{Gear, Side};
use crate::model::{Mechanism, PairId, PairKind};
use crate::workspace::Workspace;
use crate::KinematicsError;

/// Largest number of fixed-point iterations, and the change of the friction efforts,
/// relative to the largest, at which they count as settled.
const MAX_ITERATIONS: usize = 100;
const SETTLED: f64 = 1e-13;

/// How far the friction efforts may grow beyond their first estimate (the friction of the
/// frictionless reactions) before the iteration counts as diverging: the mechanism
/// self-locks. A fixed point that settles to [`SETTLED`] within [`MAX_ITERATIONS`] contracts
/// by rho <= SETTLED^(1 / MAX_ITERATIONS) = 0.74 a step, so its efforts stay within
/// 1 / (1 - rho) = 3.9 of the first estimate (in the norm where it contracts); a self-locking
/// mechanism's grow by a factor rho > 1 a step, without bound (to overflow for large mu).
const GROWTH: f64 = 1e3;

/// The buffers of an evaluation with losses, sized once for a mechanism (empty without
/// losses). A lever is a pair's relative coordinate seen from the bodies: its gradient (3n)
/// and that gradient times U (m); the friction entries' come first, then one per actuator
/// (the coordinates', then the pair actuators').
#[derive(Debug, Clone, Default)]
pub struct LossBuffers {
    /// (3n) the applied forces, and (m) b or the efforts, before the friction.
    f0: Vec<f64>,
    b0: Vec<f64>,
    /// ((n_f + n_a) x 3n) lever gradients and ((n_f + n_a) x m) their products with U.
    grad: Vec<f64>,
    gu: Vec<f64>,
    /// (n_f) the friction pairs' rates and efforts, and the gear carrying each (a gear
    /// mesh's driver; `Side::A` for the other pairs); (n_a) the actuators' pairs' rates.
    rates: Vec<f64>,
    e: Vec<f64>,
    sides: Vec<Side>,
    actuator_rates: Vec<f64>,
    /// The motors' rotors and gears.
    gears: Gears,
    /// (m) the right-hand side of a fixed-point step and the accelerations without the gears.
    rhs: Vec<f64>,
    y0: Vec<f64>,
    /// (3n) the multipliers and (p) the reactions of the last fixed-point step.
    lambda: Vec<f64>,
    reactions: Vec<[f64; 3]>,
}

impl LossBuffers {
    /// Buffers for `mech` (none when it has no losses).
    pub fn new(mech: &Mechanism) -> Self {
        if !mech.has_losses() {
            return LossBuffers::default();
        }
        let (nx, m, nf) = (mech.n_x(), mech.dof(), mech.friction.len());
        let na = m + mech.pair_actuators.len();
        LossBuffers {
            f0: vec![0.0; nx],
            b0: vec![0.0; m],
            grad: vec![0.0; (nf + na) * nx],
            gu: vec![0.0; (nf + na) * m],
            rates: vec![0.0; nf],
            e: vec![0.0; nf],
            sides: vec![Side::A; nf],
            actuator_rates: vec![0.0; na],
            gears: Gears::new(mech),
            rhs: vec![0.0; m],
            y0: vec![0.0; m],
            lambda: vec![0.0; nx],
            reactions: vec![[0.0; 3]; mech.pairs.len()],
        }
    }

    /// The pairs' reactions [F_x, F_y, M] of the last evaluation with friction (empty
    /// without losses).
    pub(crate) fn reactions(&self) -> &[[f64; 3]] {
        &self.reactions
    }

    /// Every actuator's rotor and gear at the last evaluation with losses (empty without
    /// losses): its pair's rate and acceleration, the rotor's acceleration, the gear's torques.
    pub(crate) fn rotors(&self) -> &[Rotor] {
        self.gears.rotors()
    }

    /// The motors' gears of the last evaluation (their housings' rows for the regressor).
    pub(crate) fn gears(&self) -> &Gears {
        &self.gears
    }

    /// The motors' torques t_m of the drives in `tau` and `pair_tau` move to the gears.
    pub(crate) fn take_motor_torques(&mut self, tau: &mut [f64], pair_tau: &[f64]) {
        self.gears.take_torques(tau, pair_tau);
    }
}

fn add_scaled(out: &mut [f64], s: f64, v: &[f64]) {
    for (o, v) in out.iter_mut().zip(v) {
        *o += s * v;
    }
}

/// Lever `i` of `pair` (on `side` of a gear mesh) at the point in `ws`; returns its rate.
fn set_lever(mech: &Mechanism, pair: PairId, side: Side, ws: &Workspace, lb: &mut LossBuffers, i: usize) -> f64 {
    let (n, m) = (ws.x.len(), ws.b.len());
    lever(mech, pair, side, ws, &mut lb.grad[i * n..(i + 1) * n], &mut lb.gu[i * m..(i + 1) * m])
}

/// The lever of `pair` at the point in `ws` (after the kinematic stages): its relative
/// coordinate (a gear mesh's: a's pitch-line travel) gradient (3n) into `grad`, that
/// gradient times U (m) into `gu`; returns the lever's rate. U^T grad, and so the
/// generalized force of an effort on it, is the same on either side of a mesh.
pub(crate) fn pair_lever(mech: &Mechanism, pair: PairId, ws: &Workspace, grad: &mut [f64], gu: &mut [f64]) -> f64 {
    lever(mech, pair, Side::A, ws, grad, gu)
}

fn lever(mech: &Mechanism, pair: PairId, side: Side, ws: &Workspace, grad: &mut [f64], gu: &mut [f64]) -> f64 {
    let n = ws.x.len();
    grad.fill(0.0);
    let p = &mech.pairs[pair.0];
    let mut sink = Dense { j: grad, ncols: n };
    let rate = match &p.kind {
        PairKind::Gear(g) => {
            g.pitch_grad(p, &ws.x, side, &mut sink, 0);
            g.pitch_speed(p, &ws.x, &ws.xd)
        }
        _ => {
            pair_coordinate_grad(p, &ws.x, &mut sink, 0);
            pair_coordinate_rate(p, &ws.x, &ws.xd)
        }
    };
    for (g, u) in gu.iter_mut().zip(ws.u.chunks_exact(n)) {
        *g = u.iter().zip(grad.iter()).map(|(a, b)| a * b).sum();
    }
    rate
}

/// Every lever at the point in `ws`: the friction pairs', then the actuators'; and the
/// motors' kinematics.
fn set_levers(mech: &Mechanism, ws: &Workspace, lb: &mut LossBuffers) {
    let (nf, n) = (mech.friction.len(), ws.x.len());
    lb.sides.fill(Side::A);
    for (i, fr) in mech.friction.iter().enumerate() {
        lb.rates[i] = set_lever(mech, fr.pair, Side::A, ws, lb, i);
    }
    for k in 0..lb.actuator_rates.len() {
        lb.actuator_rates[k] = set_lever(mech, actuator_pair(mech, k), Side::A, ws, lb, nf + k);
    }
    let grad = &lb.grad[nf * n..];
    let h = |k: usize| pair_term(mech, ws, k, &grad[k * n..(k + 1) * n]);
    lb.gears.kinematics(mech, &ws.u, &ws.c, &ws.xd, h, &lb.actuator_rates);
}

/// h_k = grad_k . c + gamma_k(xd, xd) of actuator k (`grad`: its pair's gradient, 3n) at the
/// point in `ws`, so that qdd_k = g_k . zdd + h_k.
fn pair_term(mech: &Mechanism, ws: &Workspace, k: usize, grad: &[f64]) -> f64 {
    let pair = &mech.pairs[actuator_pair(mech, k).0];
    grad.iter().zip(&ws.c).map(|(a, b)| a * b).sum::<f64>() + pair_coordinate_gamma(pair, &ws.x, &ws.xd, &ws.xd)
}

/// A gear mesh's driver at the reactions in `lb` (`Side::A` for the other pairs).
fn driver(mech: &Mechanism, ws: &Workspace, lb: &LossBuffers, i: usize) -> Side {
    let id = mech.friction[i].pair;
    let p = &mech.pairs[id.0];
    match &p.kind {
        PairKind::Gear(g) => Gear::driver(g.tooth_force(&ws.x, lb.reactions[id.0]), lb.rates[i]),
        _ => Side::A,
    }
}

/// The fixed point's progress: the first estimate's largest effort, the last change.
#[derive(Debug, Clone, Copy, Default)]
struct Progress {
    first: f64,
    change: f64,
}

/// One fixed-point step: the friction efforts from the reactions in `ws` (evaluated with
/// the efforts `lb.e`) replace them, and a gear mesh whose driver changed moves its effort
/// to the new driver's lever; true when the efforts and drivers settled (`lb.e` kept). Efforts
/// that are not finite or grow past [`GROWTH`] times the first estimate mean the iteration
/// diverges: the mechanism self-locks.
fn step_friction(
    mech: &Mechanism,
    ws: &mut Workspace,
    lb: &mut LossBuffers,
    iteration: usize,
    progress: &mut Progress,
) -> Result<bool, KinematicsError> {
    reactions_into(mech, ws, &mut lb.lambda, &mut lb.reactions);
    let (mut change, mut largest) = (0.0f64, 0.0f64);
    for (fr, (&rate, &e)) in mech.friction.iter().zip(lb.rates.iter().zip(&lb.e)) {
        let new = friction::effort(mech, fr, lb.reactions[fr.pair.0], rate);
        change = change.max((new - e).abs());
        largest = largest.max(new.abs());
    }
    if iteration == 0 {
        progress.first = largest;
    }
    let diverging = !(largest <= GROWTH * progress.first && change.is_finite());
    if diverging || iteration + 1 == MAX_ITERATIONS {
        let change = if diverging { progress.change } else { change };
        return Err(KinematicsError::FrictionUnsettled { iterations: iteration + 1, change });
    }
    progress.change = change;
    let mut moved = false;
    for i in 0..mech.friction.len() {
        let side = driver(mech, ws, lb, i);
        if side != lb.sides[i] {
            lb.sides[i] = side;
            set_lever(mech, mech.friction[i].pair, side, ws, lb, i);
            moved = true;
        }
    }
    if change <= SETTLED * largest && !moved {
        return Ok(true);
    }
    for (fr, (&rate, e)) in mech.friction.iter().zip(lb.rates.iter().zip(lb.e.iter_mut())) {
        *e = friction::effort(mech, fr, lb.reactions[fr.pair.0], rate);
    }
    Ok(false)
}

/// Something that solves A zdd = rhs with A factored in the workspace (alone, or with the
/// multipliers of prescribed coordinates: `dynamics::prescribed`).
pub(crate) trait Solve {
    /// zdd of `rhs` in place; `homogeneous`: with the prescribed rows' accelerations 0.
    fn solve(&mut self, ws: &Workspace, rhs: &mut [f64], homogeneous: bool) -> Result<(), KinematicsError>;
    /// Whether coordinate k follows a prescribed motion.
    fn prescribed(&self, k: usize) -> bool;
    /// The prescribed coordinates' efforts of the last solve with their motion into `ws.f`.
    fn add_efforts(&mut self, ws: &mut Workspace);
}

/// A = its Cholesky factor alone: zdd = A^-1 rhs (no coordinate prescribed).
struct Alone;

impl Solve for Alone {
    fn solve(&mut self, ws: &Workspace, rhs: &mut [f64], _homogeneous: bool) -> Result<(), KinematicsError> {
        solve_factored(ws, rhs);
        Ok(())
    }
    fn prescribed(&self, _k: usize) -> bool {
        false
    }
    fn add_efforts(&mut self, _ws: &mut Workspace) {}
}

/// Forward dynamics' last stages with losses, after A, b and f (ideal drives included, the
/// motors' torques taken by [`LossBuffers::take_motor_torques`]) are in `ws`: zdd, xdd, qdd
/// with the gears and the friction efforts settled; `ws.tau` ends with the motors' joint-side
/// efforts (their gears' outputs), `ws.f` with the friction and the gears' forces, `ws.power`
/// with their power, `ws.dissipated` with the friction's.
pub(crate) fn forward_with_losses(mech: &Mechanism, ws: &mut Workspace) -> Result<(), KinematicsError> {
    forward_with_losses_by(mech, ws, &mut Alone)
}

/// [`forward_with_losses`] with `solver` turning right-hand sides into zdd once A is factored:
/// A zdd = b alone, or with the multipliers of prescribed coordinates (`dynamics::prescribed`),
/// whose efforts it adds to `ws.f` after each fixed-point step.
pub(crate) fn forward_with_losses_by(
    mech: &Mechanism,
    ws: &mut Workspace,
    solver: &mut dyn Solve,
) -> Result<(), KinematicsError> {
    // Taken out of `ws` for the evaluation (no allocation: the buffers move), put back after.
    let mut lb = std::mem::take(&mut ws.losses);
    let result = forward_stages(mech, ws, &mut lb, solver);
    ws.losses = lb;
    result
}

fn forward_stages(
    mech: &Mechanism,
    ws: &mut Workspace,
    lb: &mut LossBuffers,
    solver: &mut dyn Solve,
) -> Result<(), KinematicsError> {
    let (nf, m, n) = (mech.friction.len(), ws.b.len(), ws.x.len());
    set_levers(mech, ws, lb);
    factor_mass_matrix(ws)?;
    lb.gears.prepare(mech, &lb.gu[nf * m..], m, |k| solver.prescribed(k));
    for col in lb.gears.columns(m) {
        solver.solve(ws, col, true)?;
    }
    lb.gears.products(mech, &lb.gu[nf * m..], m);
    lb.f0.copy_from_slice(&ws.f);
    lb.b0.copy_from_slice(&ws.b);
    lb.e.fill(0.0);
    let mut progress = Progress::default();
    let mut gear_power = 0.0;
    for iteration in 0..MAX_ITERATIONS {
        ws.f.copy_from_slice(&lb.f0);
        lb.rhs.copy_from_slice(&lb.b0);
        for (i, &e) in lb.e.iter().enumerate() {
            add_scaled(&mut ws.f, e, &lb.grad[i * n..(i + 1) * n]);
            add_scaled(&mut lb.rhs, e, &lb.gu[i * m..(i + 1) * m]);
        }
        lb.gears.housing_torques(&mut lb.rhs);
        lb.y0.copy_from_slice(&lb.rhs);
        solver.solve(ws, &mut lb.y0, false)?;
        lb.gears.solve(mech, &lb.y0, &lb.gu[nf * m..], &mut lb.rhs)?;
        solver.solve(ws, &mut lb.rhs, false)?;
        ws.b.copy_from_slice(&lb.rhs);
        solver.add_efforts(ws);
        gear_power = lb.gears.finish(mech, &ws.b, &lb.gu[nf * m..], &lb.grad[nf * n..], &mut ws.tau, &mut ws.f);
        body_accelerations(&ws.u, &ws.c, &ws.b, ws.sys.u_support(), &mut ws.xdd);
        if nf == 0 || step_friction(mech, ws, lb, iteration, &mut progress)? {
            break;
        }
    }
    accelerations(mech, ws);
    let friction_power: f64 = lb.e.iter().zip(&lb.rates).map(|(e, r)| e * r).sum();
    ws.power += friction_power + gear_power;
    ws.dissipated = -friction_power;
    Ok(())
}

/// Inverse dynamics' losses, after `ws.tau` = A qdd - b (no friction, no motor) with `ws.f`
/// without drives, in the input chart: the rotors' reactions on their housings, then the
/// friction efforts settled against the reactions. `ws.tau` ends joint-side (each motor's gear
/// output, its rotor not included: `dynamics::motor_torques` adds it), `ws.f` with the
/// friction and the drive efforts the bodies feel, `ws.dissipated` with the friction's power.
/// A pair actuator drives nothing here (its motor turns its own rotor).
pub(crate) fn inverse_with_losses(mech: &Mechanism, qdd: &[f64], ws: &mut Workspace) -> Result<(), KinematicsError> {
    let mut lb = std::mem::take(&mut ws.losses);
    let result = inverse_stages(mech, qdd, ws, &mut lb);
    ws.losses = lb;
    result
}

fn inverse_stages(
    mech: &Mechanism,
    qdd: &[f64],
    ws: &mut Workspace,
    lb: &mut LossBuffers,
) -> Result<(), KinematicsError> {
    // ws.xdd holds the body accelerations inverse dynamics formed.
    let (nf, m, n) = (mech.friction.len(), ws.b.len(), ws.x.len());
    set_levers(mech, ws, lb);
    lb.gears.inverse(mech, &ws.xdd, qdd, &lb.gu[nf * m..], &mut ws.tau, &mut ws.f);
    lb.f0.copy_from_slice(&ws.f);
    lb.b0.copy_from_slice(&ws.tau);
    lb.e.fill(0.0);
    let mut progress = Progress::default();
    for iteration in 0..MAX_ITERATIONS {
        ws.f.copy_from_slice(&lb.f0);
        ws.tau.copy_from_slice(&lb.b0);
        for (i, &e) in lb.e.iter().enumerate() {
            add_scaled(&mut ws.f, e, &lb.grad[i * n..(i + 1) * n]);
            add_scaled(&mut ws.tau, -e, &lb.gu[i * m..(i + 1) * m]);
        }
        for (k, &tau) in ws.tau.iter().enumerate() {
            add_scaled(&mut ws.f, tau, &lb.grad[(nf + k) * n..(nf + k + 1) * n]);
        }
        if nf == 0 || step_friction(mech, ws, lb, iteration, &mut progress)? {
            break;
        }
    }
    lb.gears.set_outputs(&ws.tau);
    ws.dissipated = -lb.e.iter().zip(&lb.rates).map(|(e, r)| e * r).sum::<f64>();
    Ok(())
}

/// Motor torques (N m; the effort itself where an actuator has no motor) into `t_m` for
/// joint-side efforts `tau` of the first `tau.len()` actuators (the coordinates', then the pair
/// actuators'), at the motion of the last evaluation in `ws` (its rates, the pairs'
/// accelerations and the rotors', which inverse and forward dynamics leave there).
pub fn motor_torques(mech: &Mechanism, ws: &Workspace, tau: &[f64], t_m: &mut [f64]) {
    let rotors = ws.losses.rotors();
    for (k, (slot, &tau)) in motors(mech).zip(tau).enumerate() {
        t_m[k] = match (slot, rotors.get(k)) {
            (Some(a), Some(r)) => motor_torque(a, tau, r.rate, r.accel, r.rotor_acc),
            _ => tau,
        };
    }
}
