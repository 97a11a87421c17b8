//! The buffers of the dynamics with losses (docs/actuators.md): the levers of the friction
//! pairs and of the actuators, the friction efforts, the motors' gears and the fixed-point
//! iteration's state, filled by `dynamics::losses`.

use super::gears::{Gears, Rotor};
use crate::model::pairs::gear::Side;
use crate::model::Mechanism;

/// The buffers of an evaluation with losses, sized once for a mechanism (empty without
/// losses). A lever is a pair's relative coordinate seen from the bodies: its gradient (3n)
/// and that gradient times U (m); the friction entries' come first, then one per actuator
/// (the coordinates', then the pair actuators').
#[derive(Debug, Default)]
pub struct LossBuffers {
    /// (3n) the applied forces, and (m) b or the efforts, before the friction.
    pub(super) f0: Vec<f64>,
    pub(super) b0: Vec<f64>,
    /// ((n_f + n_a) x 3n) lever gradients and ((n_f + n_a) x m) their products with U.
    pub(super) grad: Vec<f64>,
    pub(super) gu: Vec<f64>,
    /// (n_f) the friction pairs' rates and efforts, and the gear carrying each (a gear
    /// mesh's driver; `Side::A` for the other pairs); (n_a) the actuators' pairs' rates.
    pub(super) rates: Vec<f64>,
    pub(super) e: Vec<f64>,
    pub(super) sides: Vec<Side>,
    pub(super) actuator_rates: Vec<f64>,
    /// The motors' rotors and gears.
    pub(super) gears: Gears,
    /// (m) the right-hand side of a fixed-point step and the accelerations without the gears.
    pub(super) rhs: Vec<f64>,
    pub(super) y0: Vec<f64>,
    /// (3n) the multipliers and (p) the reactions of the last fixed-point step.
    pub(super) lambda: Vec<f64>,
    pub(super) reactions: Vec<[f64; 3]>,
}

clone_reusing!(LossBuffers { f0, b0, grad, gu, rates, e, sides, actuator_rates, gears, rhs, y0, lambda, reactions });

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

    /// The motors' gears, to hold their sides of the at-rest band through a run's steps.
    pub(crate) fn gears_mut(&mut self) -> &mut Gears {
        &mut self.gears
    }

    /// The motors' torques t_m of the drives in `tau` and `pair_tau` move to the gears.
    pub(crate) fn take_motor_torques(&mut self, tau: &mut [f64], pair_tau: &[f64]) {
        self.gears.take_torques(tau, pair_tau);
    }
}
