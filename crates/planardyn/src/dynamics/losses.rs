//! Forward and inverse dynamics with the actuators' transmissions and the pairs' Coulomb
//! friction (docs/actuators.md). The friction efforts e depend on the reactions, which
//! depend on the accelerations, which depend on e: at each evaluation the three are solved
//! together by a fixed-point iteration on e, to round-off. It converges while a unit
//! change of the efforts changes the friction by less than itself (mu r small against the
//! mechanism's lever arms); a mechanism that self-locks is reported, not guessed.
//!
//! A gear mesh's friction acts on its driver's pitch-line travel (`gear::Side`): which
//! gear drives follows the tooth force found at each step, as the sign of the power that
//! crosses the mesh.

use super::forward::{accelerations, body_accelerations, factor_mass_matrix};
use super::friction;
use super::reactions::reactions_into;
use super::transmission::{actuator_pair, add_rotor_inertia, rotor_inertias, rotor_terms};
use crate::kinematics::constraints::{pair_coordinate_grad, pair_coordinate_rate, Dense};
use crate::linalg::cholesky_solve;
use crate::model::pairs::gear::{Gear, Side};
use crate::model::{Mechanism, PairId, PairKind};
use crate::workspace::Workspace;
use crate::KinematicsError;

/// Largest number of fixed-point iterations, and the change of the friction efforts,
/// relative to the largest, at which they count as settled.
const MAX_ITERATIONS: usize = 100;
const SETTLED: f64 = 1e-13;

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
    /// mesh's driver; `Side::A` for the other pairs).
    rates: Vec<f64>,
    e: Vec<f64>,
    sides: Vec<Side>,
    /// (n_a) per actuator: the rotor's n^2 J (0 without), its h (qdd_k = gu_k . zdd + h_k),
    /// its pair's rate qd_k and the rotor's torque n^2 J qdd_k of the last evaluation.
    rotor_inertia: Vec<f64>,
    rotor_h: Vec<f64>,
    rotor_rates: Vec<f64>,
    rotor_torques: Vec<f64>,
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
            rotor_inertia: rotor_inertias(mech),
            rotor_h: vec![0.0; na],
            rotor_rates: vec![0.0; na],
            rotor_torques: vec![0.0; na],
            lambda: vec![0.0; nx],
            reactions: vec![[0.0; 3]; mech.pairs.len()],
        }
    }

    /// The pairs' reactions [F_x, F_y, M] of the last evaluation with friction (empty
    /// without losses).
    pub(crate) fn reactions(&self) -> &[[f64; 3]] {
        &self.reactions
    }

    /// Each actuator's rotor torque n^2 J qdd_k (N m or N, joint side; 0 without a rotor) of
    /// the last evaluation with losses (empty without losses).
    pub(crate) fn rotor_torques(&self) -> &[f64] {
        &self.rotor_torques
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

/// Every lever at the point in `ws`: the friction pairs', then the actuators'.
fn set_levers(mech: &Mechanism, ws: &Workspace, lb: &mut LossBuffers) {
    let nf = mech.friction.len();
    lb.sides.fill(Side::A);
    for (i, fr) in mech.friction.iter().enumerate() {
        lb.rates[i] = set_lever(mech, fr.pair, Side::A, ws, lb, i);
    }
    for k in 0..lb.rotor_rates.len() {
        lb.rotor_rates[k] = set_lever(mech, actuator_pair(mech, k), Side::A, ws, lb, nf + k);
    }
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

/// One fixed-point step: the friction efforts from the reactions in `ws` (evaluated with
/// the efforts `lb.e`) replace them, and a gear mesh whose driver changed moves its effort
/// to the new driver's lever; true when the efforts and drivers settled (`lb.e` kept).
fn step_friction(
    mech: &Mechanism,
    ws: &mut Workspace,
    lb: &mut LossBuffers,
    iteration: usize,
) -> Result<bool, KinematicsError> {
    reactions_into(mech, ws, &mut lb.lambda, &mut lb.reactions);
    let (mut change, mut largest) = (0.0f64, 0.0f64);
    for (fr, (&rate, &e)) in mech.friction.iter().zip(lb.rates.iter().zip(&lb.e)) {
        let new = friction::effort(mech, fr, lb.reactions[fr.pair.0], rate);
        change = change.max((new - e).abs());
        largest = largest.max(new.abs());
    }
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
    if iteration + 1 == MAX_ITERATIONS {
        return Err(KinematicsError::FrictionUnsettled { iterations: MAX_ITERATIONS, change });
    }
    for (fr, (&rate, e)) in mech.friction.iter().zip(lb.rates.iter().zip(lb.e.iter_mut())) {
        *e = friction::effort(mech, fr, lb.reactions[fr.pair.0], rate);
    }
    Ok(false)
}

/// Forward dynamics' last stages with losses, after A, b and f (joint-side drive efforts
/// included) are in `ws`: rotor inertia into A and b, then zdd, xdd, qdd with the friction
/// efforts settled; `ws.f` ends with the friction and the rotors' torques, `ws.power` with
/// their power, `ws.dissipated` with the friction's.
pub(crate) fn forward_with_losses(mech: &Mechanism, ws: &mut Workspace) -> Result<(), KinematicsError> {
    let m = ws.b.len();
    forward_with_losses_by(mech, ws, &mut |ws| {
        cholesky_solve(&ws.a, m, &mut ws.b);
        Ok(())
    })
}

/// [`forward_with_losses`] with `solve` turning `ws.b` into zdd once A is factored: A zdd = b
/// alone, or with the multipliers of prescribed coordinates (`dynamics::prescribed`), whose
/// efforts `solve` adds to `ws.f`. It runs once per fixed-point step.
pub(crate) fn forward_with_losses_by(
    mech: &Mechanism,
    ws: &mut Workspace,
    solve: &mut dyn FnMut(&mut Workspace) -> Result<(), KinematicsError>,
) -> Result<(), KinematicsError> {
    // Taken out of `ws` for the evaluation (no allocation: the buffers move), put back after.
    let mut lb = std::mem::take(&mut ws.losses);
    let result = forward_stages(mech, ws, &mut lb, solve);
    ws.losses = lb;
    result
}

fn forward_stages(
    mech: &Mechanism,
    ws: &mut Workspace,
    lb: &mut LossBuffers,
    solve: &mut dyn FnMut(&mut Workspace) -> Result<(), KinematicsError>,
) -> Result<(), KinematicsError> {
    let (nf, m, n) = (mech.friction.len(), ws.b.len(), ws.x.len());
    set_levers(mech, ws, lb);
    rotor_terms(mech, ws, &lb.rotor_inertia, &lb.grad[nf * n..], &mut lb.rotor_h);
    add_rotor_inertia(&lb.rotor_inertia, &lb.gu[nf * m..], &lb.rotor_h, &mut ws.a, &mut ws.b);
    factor_mass_matrix(ws)?;
    lb.f0.copy_from_slice(&ws.f);
    lb.b0.copy_from_slice(&ws.b);
    lb.e.fill(0.0);
    for iteration in 0..MAX_ITERATIONS {
        ws.f.copy_from_slice(&lb.f0);
        ws.b.copy_from_slice(&lb.b0);
        for (i, &e) in lb.e.iter().enumerate() {
            add_scaled(&mut ws.f, e, &lb.grad[i * n..(i + 1) * n]);
            add_scaled(&mut ws.b, e, &lb.gu[i * m..(i + 1) * m]);
        }
        solve(ws)?;
        body_accelerations(&ws.u, &ws.c, &ws.b, ws.sys.u_support(), &mut ws.xdd);
        // f -= n^2 J qdd_k grad_k: the rotors' inertia torques, qdd_k = gu_k . zdd + h_k.
        for (k, &inertia) in lb.rotor_inertia.iter().enumerate().filter(|(_, j)| **j > 0.0) {
            let l = nf + k;
            let qdd = lb.gu[l * m..(l + 1) * m].iter().zip(&ws.b).map(|(g, a)| g * a).sum::<f64>() + lb.rotor_h[k];
            lb.rotor_torques[k] = inertia * qdd;
            add_scaled(&mut ws.f, -inertia * qdd, &lb.grad[l * n..(l + 1) * n]);
        }
        if nf == 0 || step_friction(mech, ws, lb, iteration)? {
            break;
        }
    }
    accelerations(mech, ws);
    let friction_power: f64 = lb.e.iter().zip(&lb.rates).map(|(e, r)| e * r).sum();
    let rotor_power: f64 = lb.rotor_torques.iter().zip(&lb.rotor_rates).map(|(t, v)| -t * v).sum();
    ws.power += friction_power + rotor_power;
    ws.dissipated = -friction_power;
    Ok(())
}

/// Inverse dynamics' losses, after `ws.tau` = A qdd - b (no friction, no rotor) with `ws.f`
/// without drives, in the input chart: the friction efforts settled against the reactions,
/// then the rotors' n^2 J qdd. `ws.tau` ends joint-side, `ws.f` with the friction and the
/// drive efforts the bodies feel, `ws.dissipated` with the friction's power. A pair
/// actuator's rotor is driven by the coordinates: its torque r adds r gu_k to `ws.tau`.
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
    rotor_terms(mech, ws, &lb.rotor_inertia, &lb.grad[nf * n..], &mut lb.rotor_h);
    lb.f0.copy_from_slice(&ws.f);
    lb.b0.copy_from_slice(&ws.tau);
    lb.e.fill(0.0);
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
        if nf == 0 || step_friction(mech, ws, lb, iteration)? {
            break;
        }
    }
    for ((tau, j), a) in ws.tau.iter_mut().zip(&lb.rotor_inertia).zip(qdd) {
        *tau += j * a;
    }
    lb.rotor_torques.fill(0.0);
    for (k, &inertia) in lb.rotor_inertia.iter().enumerate().filter(|(_, j)| **j > 0.0) {
        let l = nf + k;
        let gu = &lb.gu[l * m..(l + 1) * m];
        let qdd_k = if k < m { qdd[k] } else { gu.iter().zip(qdd).map(|(g, a)| g * a).sum::<f64>() + lb.rotor_h[k] };
        let r = inertia * qdd_k;
        lb.rotor_torques[k] = r;
        if k >= m {
            // The coordinates supply r gu_k; the bodies feel it, less the rotor's reaction r grad_k.
            add_scaled(&mut ws.tau, r, gu);
            add_scaled(&mut ws.f, -r, &lb.grad[l * n..(l + 1) * n]);
            for (&g, coordinate) in gu.iter().zip(lb.grad[nf * n..].chunks_exact(n)) {
                add_scaled(&mut ws.f, r * g, coordinate);
            }
        }
    }
    ws.dissipated = -lb.e.iter().zip(&lb.rates).map(|(e, r)| e * r).sum::<f64>();
    Ok(())
}
