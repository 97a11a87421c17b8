//! Forward and inverse dynamics with the actuators' transmissions and the pairs' Coulomb
//! friction (docs/actuators.md). The friction efforts e depend on the reactions, which
//! depend on the accelerations, which depend on e: at each evaluation the three are solved
//! together by a fixed-point iteration on e, to round-off. It converges while a unit
//! change of the efforts changes the friction by less than itself (mu r small against the
//! mechanism's lever arms); a mechanism that self-locks is reported, not guessed.

use super::forward::{accelerations, body_accelerations, factor_mass_matrix};
use super::friction;
use super::reactions::reactions;
use super::transmission::{add_rotor_inertia, rotors, Rotor};
use crate::kinematics::constraints::{pair_coordinate_grad, pair_coordinate_rate, Dense};
use crate::linalg::cholesky_solve;
use crate::model::{Mechanism, PairId};
use crate::workspace::Workspace;
use crate::KinematicsError;

/// Largest number of fixed-point iterations, and the change of the friction efforts,
/// relative to the largest, at which they count as settled.
const MAX_ITERATIONS: usize = 100;
const SETTLED: f64 = 1e-13;

/// A pair's relative coordinate seen from the bodies: its gradient (3n) and, in the chart,
/// its gradient times U (m).
struct Lever {
    grad: Vec<f64>,
    gu: Vec<f64>,
}

fn lever(mech: &Mechanism, pair: PairId, ws: &Workspace) -> Lever {
    let n = ws.x.len();
    let mut grad = vec![0.0; n];
    pair_coordinate_grad(&mech.pairs[pair.0], &ws.x, &mut Dense { j: &mut grad, ncols: n }, 0);
    let gu = ws.u.chunks_exact(n).map(|u| u.iter().zip(&grad).map(|(a, b)| a * b).sum()).collect();
    Lever { grad, gu }
}

fn add_scaled(out: &mut [f64], s: f64, v: &[f64]) {
    for (o, v) in out.iter_mut().zip(v) {
        *o += s * v;
    }
}

/// One fixed-point step: the friction efforts from the reactions in `ws` (evaluated with
/// the efforts `e`) replace `e`, unless they settled (then true and `e` is kept).
fn step_friction(
    mech: &Mechanism,
    ws: &mut Workspace,
    rates: &[f64],
    e: &mut [f64],
    iteration: usize,
) -> Result<bool, KinematicsError> {
    let r = reactions(mech, ws);
    let (mut change, mut largest) = (0.0f64, 0.0f64);
    for (fr, (&rate, &e)) in mech.friction.iter().zip(rates.iter().zip(e.iter())) {
        let new = friction::effort(mech, fr, r[fr.pair.0], rate);
        change = change.max((new - e).abs());
        largest = largest.max(new.abs());
    }
    if change <= SETTLED * largest {
        return Ok(true);
    }
    if iteration + 1 == MAX_ITERATIONS {
        return Err(KinematicsError::FrictionUnsettled { iterations: MAX_ITERATIONS, change });
    }
    for (fr, (&rate, e)) in mech.friction.iter().zip(rates.iter().zip(e.iter_mut())) {
        *e = friction::effort(mech, fr, r[fr.pair.0], rate);
    }
    Ok(false)
}

/// The pairs' relative rates and levers, for the friction entries of `mech`.
fn friction_levers(mech: &Mechanism, ws: &Workspace) -> (Vec<f64>, Vec<Lever>) {
    let rates = mech.friction.iter().map(|fr| pair_coordinate_rate(&mech.pairs[fr.pair.0], &ws.x, &ws.xd)).collect();
    (rates, mech.friction.iter().map(|fr| lever(mech, fr.pair, ws)).collect())
}

/// Forward dynamics' last stages with losses, after A, b and f (joint-side drive efforts
/// included) are in `ws`: rotor inertia into A and b, then zdd, xdd, qdd with the friction
/// efforts settled; `ws.f` ends with the friction and the rotors' torques, `ws.power` with
/// their power, `ws.dissipated` with the friction's.
pub(crate) fn forward_with_losses(
    mech: &Mechanism,
    z: &[f64],
    zd: &[f64],
    ws: &mut Workspace,
) -> Result<(), KinematicsError> {
    let mut grad = vec![0.0; ws.x.len()];
    let rotors = rotors(mech, ws, &mut grad);
    add_rotor_inertia(&rotors, &mut ws.a, &mut ws.b);
    factor_mass_matrix(ws)?;
    let rotor_levers: Vec<Lever> =
        rotors.iter().map(|r| lever(mech, mech.coordinates[r.coordinate].pair, ws)).collect();
    let (rates, levers) = friction_levers(mech, ws);
    let (f0, b0) = (ws.f.clone(), ws.b.clone());
    let mut e = vec![0.0; mech.friction.len()];
    for iteration in 0..MAX_ITERATIONS {
        ws.f.copy_from_slice(&f0);
        ws.b.copy_from_slice(&b0);
        for (&e, l) in e.iter().zip(&levers) {
            add_scaled(&mut ws.f, e, &l.grad);
            add_scaled(&mut ws.b, e, &l.gu);
        }
        cholesky_solve(&ws.a, ws.b.len(), &mut ws.b);
        body_accelerations(&ws.u, &ws.c, &ws.b, &mut ws.xdd);
        add_rotor_torques(&rotors, &rotor_levers, &ws.b, &mut ws.f);
        if mech.friction.is_empty() || step_friction(mech, ws, &rates, &mut e, iteration)? {
            break;
        }
    }
    accelerations(mech, z, zd, ws);
    let friction_power: f64 = e.iter().zip(&rates).map(|(e, r)| e * r).sum();
    let rotor_power: f64 = rotors.iter().map(|r| -r.inertia * ws.qdd[r.coordinate] * ws.qd[r.coordinate]).sum();
    ws.power += friction_power + rotor_power;
    ws.dissipated = -friction_power;
    Ok(())
}

/// f -= n^2 J qdd_k grad_k: the rotors' inertia torques, with qdd_k = g . zdd + h.
fn add_rotor_torques(rotors: &[Rotor], levers: &[Lever], zdd: &[f64], f: &mut [f64]) {
    for (r, l) in rotors.iter().zip(levers) {
        let qdd = r.g.iter().zip(zdd).map(|(g, a)| g * a).sum::<f64>() + r.h;
        add_scaled(f, -r.inertia * qdd, &l.grad);
    }
}

/// Inverse dynamics' losses, after `ws.tau` = A qdd - b (no friction, no rotor) with `ws.f`
/// without drives, in the input chart: the friction efforts settled against the reactions,
/// then the rotors' n^2 J qdd. `ws.tau` ends joint-side, `ws.f` with the friction and the
/// drive efforts the bodies feel, `ws.dissipated` with the friction's power.
pub(crate) fn inverse_with_losses(mech: &Mechanism, qdd: &[f64], ws: &mut Workspace) -> Result<(), KinematicsError> {
    body_accelerations(&ws.u, &ws.c, qdd, &mut ws.xdd);
    let (rates, levers) = friction_levers(mech, ws);
    let drive_levers: Vec<Lever> = mech.coordinates.iter().map(|c| lever(mech, c.pair, ws)).collect();
    let (f0, tau0) = (ws.f.clone(), ws.tau.clone());
    let mut e = vec![0.0; mech.friction.len()];
    for iteration in 0..MAX_ITERATIONS {
        ws.f.copy_from_slice(&f0);
        ws.tau.copy_from_slice(&tau0);
        for (&e, l) in e.iter().zip(&levers) {
            add_scaled(&mut ws.f, e, &l.grad);
            add_scaled(&mut ws.tau, -e, &l.gu);
        }
        for (&tau, l) in ws.tau.iter().zip(&drive_levers) {
            add_scaled(&mut ws.f, tau, &l.grad);
        }
        if mech.friction.is_empty() || step_friction(mech, ws, &rates, &mut e, iteration)? {
            break;
        }
    }
    for a in mech.actuators.iter().flatten() {
        ws.tau[a.coordinate] += a.ratio * a.ratio * a.rotor_inertia * qdd[a.coordinate];
    }
    ws.dissipated = -e.iter().zip(&rates).map(|(e, r)| e * r).sum::<f64>();
    Ok(())
}
