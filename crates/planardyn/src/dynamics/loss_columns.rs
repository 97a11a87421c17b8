//! The regressor's columns of the losses (docs/identification.md, *Losses*), after the
//! bodies' [`super::regressor::BODY_PARAMETERS`] each, in this order:
//!
//! - per actuator (coordinate order) `J_<actuator>` (rotor inertia, kg m^2), `fv_<actuator>`
//!   (motor viscous, N m s/rad), `fc_<actuator>` (motor Coulomb, N m): the rotor's torque
//!   J omega_r' (omega_r = omega_housing + n qd) and the motor friction
//!   c n qd + T_c tanh(n qd / v_m) are motor-side, before the gear; a rotor on a moving link
//!   also loads the joints through its housing's reaction -J omega_r' (joint-side, e its row);
//! - per pair with a viscous damper (a pair spring-damper of zero stiffness: the viscous
//!   part of a `friction` load) `fvp_<pair>`: the summed damping c of those loads, whose
//!   effort on the pair's relative coordinate is -c rate (a spring's own damping, like a
//!   servo's PD gains, stays a known load in tau_o);
//! - per friction load `mu_<pair>` (the sliding coefficient of the load-dependent pin
//!   friction) and `fcp_<pair>` (a constant Coulomb effort T, -T tanh(arm rate / v_st), 0 in
//!   the model: the load-independent part a real pin shows).
//!
//! A pair's effort e enters the joint-side efforts as -e U^T grad (its lever, as
//! `dynamics::losses` forms it). On a coordinate with an actuator the row is the motor
//! torque: the joint-side row times 1 / (n eta) while motoring, eta_b / n while back-driven,
//! plus the rotor's and the motor friction's columns.
//!
//! Two terms are not linear in pi and are evaluated at the model's own parameters:
//! - the pin friction's load N is the pair's reaction, which depends on pi: the `mu` column
//!   is arm N (1 - E) tanh(arm rate / v_st) U^T grad with N the model's, and the static
//!   coefficient's share arm N mu_s E tanh(...) (E = exp(-(arm rate / v_str)^2)) goes to
//!   tau_o; Y pi + tau_o is exact at the model's pi (identification keeps the model's
//!   reactions: they depend on parameters the efforts do not determine);
//! - the transmission's branch (motoring or back-driven) is that of the model's joint-side
//!   effort, its power tau qd (at rest tau qdd: `transmission::motoring`).

use super::friction;
use super::losses::pair_lever;
use super::transmission::{gear_input, motoring, smooth_sign};
use crate::model::{Actuator, JointFriction, Load, Mechanism, PairId};
use crate::workspace::Workspace;
use crate::KinematicsError;

/// Parameters per actuator and per friction load.
const ACTUATOR_PARAMETERS: usize = 3;
const FRICTION_PARAMETERS: usize = 2;

/// The coordinates with an actuator, with it.
fn actuated(mech: &Mechanism) -> impl Iterator<Item = (usize, &Actuator)> {
    mech.actuators.iter().enumerate().filter_map(|(k, a)| a.as_ref().map(|a| (k, a)))
}

/// Which loss columns a mechanism has.
#[derive(Debug, Clone)]
pub(crate) struct LossLayout {
    /// Pairs with a viscous damper, in pair order.
    damped: Vec<PairId>,
}

impl LossLayout {
    pub(crate) fn new(mech: &Mechanism) -> Self {
        let damped = (0..mech.pairs.len())
            .map(PairId)
            .filter(|&id| mech.loads.iter().any(|l| damper(l, id).is_some()))
            .collect();
        LossLayout { damped }
    }

    /// Number of loss parameters of `mech`.
    pub(crate) fn len(&self, mech: &Mechanism) -> usize {
        ACTUATOR_PARAMETERS * actuated(mech).count() + self.damped.len() + FRICTION_PARAMETERS * mech.friction.len()
    }

    pub(crate) fn names(&self, mech: &Mechanism) -> Vec<String> {
        let mut out = Vec::new();
        for (_, a) in actuated(mech) {
            out.extend(["J", "fv", "fc"].map(|p| format!("{p}_{}", a.name)));
        }
        out.extend(self.damped.iter().map(|id| format!("fvp_{}", mech.pairs[id.0].name)));
        for fr in &mech.friction {
            out.extend(["mu", "fcp"].map(|p| format!("{p}_{}", mech.pairs[fr.pair.0].name)));
        }
        out
    }

    pub(crate) fn values(&self, mech: &Mechanism) -> Vec<f64> {
        let mut out = Vec::new();
        for (_, a) in actuated(mech) {
            out.extend([a.rotor_inertia, a.viscous, a.coulomb]);
        }
        out.extend(self.damped.iter().map(|&id| damping(mech, id)));
        for fr in &mech.friction {
            out.extend([fr.mu, 0.0]);
        }
        out
    }
}

/// The damping of `load` if it is a viscous damper on pair `id`.
fn damper(load: &Load, id: PairId) -> Option<f64> {
    match load {
        Load::PairSpring(s) if s.pair == id && s.stiffness == 0.0 => Some(s.damping),
        _ => None,
    }
}

/// The summed damping (N m s/rad or N s/m) of the viscous dampers on pair `id`.
fn damping(mech: &Mechanism, id: PairId) -> f64 {
    mech.loads.iter().filter_map(|l| damper(l, id)).sum()
}

/// The friction law of `fr` with other coefficients: mu(s) is linear in (mu, mu_s).
fn law(fr: &JointFriction, mu: f64, mu_static: f64, s: f64) -> f64 {
    friction::coefficient(&JointFriction { mu, mu_static, ..fr.clone() }, s)
}

/// The loss columns from column `start` of `y` (m x p) and their share of `tau_o`, at the
/// state of `ws` after inverse dynamics of the model (`tau_model` its joint-side efforts);
/// rows of actuated coordinates then turned motor-side.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fill(
    mech: &Mechanism,
    ws: &Workspace,
    qd: &[f64],
    qdd: &[f64],
    tau_model: &[f64],
    start: usize,
    y: &mut [f64],
    tau_o: &mut [f64],
) -> Result<(), KinematicsError> {
    let layout = LossLayout::new(mech);
    if mech.has_losses() && !mech.pair_actuators.is_empty() {
        return Err(KinematicsError::bad_argument(
            "actuators",
            "transmissions only without pair actuators (the regressor's rows are the coordinates' generalized \
             efforts under redundant actuation; give the coordinates ideal drives)",
            "a redundantly actuated mechanism with transmissions",
        ));
    }
    let (n, m) = (ws.x.len(), qdd.len());
    let p = y.len() / m.max(1);
    for row in y.chunks_exact_mut(p.max(1)) {
        row[start..].fill(0.0);
    }
    let (mut grad, mut gu) = (vec![0.0; n], vec![0.0; m]);
    // Joint-side columns: the rotors' reactions on their housings, dampers, pin friction.
    let gears = ws.losses.gears();
    let mut col = start;
    for (_, e, rotor) in gears.each(m) {
        for (j, e) in e.iter().enumerate() {
            y[j * p + col] = rotor.rotor_acc * e;
        }
        col += ACTUATOR_PARAMETERS;
    }
    for &id in &layout.damped {
        let rate = pair_lever(mech, id, ws, &mut grad, &mut gu);
        // tau_o holds the damping's effort from the applied forces; it moves to the column.
        add_lever(&gu, col, rate, -damping(mech, id) * rate, y, tau_o);
        col += 1;
    }
    for fr in &mech.friction {
        let rate = pair_lever(mech, fr.pair, ws, &mut grad, &mut gu);
        let load = fr.arm * friction::normal_load(mech, fr, ws.losses.reactions()[fr.pair.0]);
        let s = fr.arm * rate;
        add_lever(&gu, col, load * law(fr, 1.0, 0.0, s), load * law(fr, 0.0, fr.mu_static, s), y, tau_o);
        add_lever(&gu, col + 1, law(fr, 1.0, 1.0, s), 0.0, y, tau_o);
        col += FRICTION_PARAMETERS;
    }
    // Motor side: the joint-side row through the gear, then the rotor and the motor friction.
    let mut col = start;
    for ((k, a), rotor) in actuated(mech).zip(gears.each(m).map(|(_, _, r)| r)) {
        let gear = gear_input(a, 1.0, motoring(a, tau_model[k], qd[k], qdd[k]));
        for v in &mut y[k * p..(k + 1) * p] {
            *v *= gear;
        }
        tau_o[k] *= gear;
        let w = a.ratio * qd[k];
        y[k * p + col] += rotor.rotor_acc;
        y[k * p + col + 1] = w;
        y[k * p + col + 2] = smooth_sign(w, a.stiction_speed);
        col += ACTUATOR_PARAMETERS;
    }
    Ok(())
}

/// A pair's effort per unit of a parameter (`per_unit`) and of the model's known part
/// (`model_share`) through its lever `gu` (m): into column `col` of `y` and into `tau_o`.
fn add_lever(gu: &[f64], col: usize, per_unit: f64, model_share: f64, y: &mut [f64], tau_o: &mut [f64]) {
    let p = y.len() / gu.len();
    for (j, g) in gu.iter().enumerate() {
        y[j * p + col] = per_unit * g;
        tau_o[j] += model_share * g;
    }
}
