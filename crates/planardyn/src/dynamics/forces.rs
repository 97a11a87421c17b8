//! Applied forces reduced to the centres of mass, f = [F_x, F_y, M] per body
//! (docs/formulation.md, eq. 26): gravity, the loads (point forces, torques, springs and
//! dampers: each kind's own, `model::loads`), and the drive efforts mapped through the
//! coordinates' gradients (f += D_x^T tau, the virtual work of tau on q).

use crate::model::loads;
use crate::model::pairs::add_effort;
use crate::model::Mechanism;

/// Drive efforts on the generalized coordinates (N m on angles, N on displacements).
pub trait Drives {
    /// Write the efforts at time t (s), coordinates q and rates qd into `tau`.
    fn efforts(&mut self, t: f64, q: &[f64], qd: &[f64], tau: &mut [f64]) -> Result<(), String>;
    /// Whether the efforts depend on t alone (not on q, qd): then the exact Jacobian of the
    /// equations of motion holds them fixed. The default, false, is always safe.
    fn time_only(&self) -> bool {
        false
    }
}

/// The drives written in the model file (constants and time tables; none is zero).
pub struct ModelDrives<'a>(pub &'a Mechanism);

impl Drives for ModelDrives<'_> {
    fn efforts(&mut self, t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        for (e, law) in tau.iter_mut().zip(&self.0.drives) {
            *e = law.as_ref().map_or(0.0, |l| l.effort(t));
        }
        Ok(())
    }
    fn time_only(&self) -> bool {
        true
    }
}

/// Fill `f` (3n) with every applied force at (x, xd) and drive efforts `tau`. Returns the power of the non-conservative forces (drives, dampers, point
/// forces and torques) in W; gravity and spring stiffness are counted in the potential.
pub fn applied_forces(mech: &Mechanism, x: &[f64], xd: &[f64], tau: &[f64], f: &mut [f64]) -> f64 {
    let g = mech.gravity;
    for (f, body) in f.chunks_exact_mut(3).zip(&mech.bodies) {
        f.copy_from_slice(&[body.mass * g[0], body.mass * g[1], 0.0]);
    }
    let mut power = 0.0;
    for load in &mech.loads {
        power += loads::add_force(load, mech, x, xd, f);
    }
    for (c, &t) in mech.coordinates.iter().zip(tau) {
        if t == 0.0 {
            continue;
        }
        let (_, rate) = add_effort(c.linear.as_ref(), &mech.pairs, c.pair, x, xd, f, |_, _| t);
        power += t * rate;
    }
    power
}

#[cfg(test)]
mod tests {
    use super::{applied_forces, Drives, ModelDrives};
    use crate::linalg::Dense;
    use crate::model::pairs::coordinate_grad;

    /// The drives' efforts add tau times each coordinate's gradient (its row of D_x, written
    /// into a dense row) and their power tau times the gradient along xd, bit for bit: the
    /// driven five-bar (two revolute inputs on the ground) and Andrews' squeezer at their
    /// drawings with rates 1.
    #[test]
    fn drive_efforts_are_tau_times_the_gradient() {
        for model in ["five-bar", "andrews-squeezer"] {
            let path = format!("{}/../../examples/models/{model}.yaml", env!("CARGO_MANIFEST_DIR"));
            let mech = crate::load(&path).unwrap();
            let (x, xd) = (mech.x0.clone(), vec![1.0; mech.x0.len()]);
            let n = x.len();
            let mut tau = vec![0.0; mech.dof()];
            ModelDrives(&mech).efforts(0.3, &[], &[], &mut tau).unwrap();
            tau.iter_mut().for_each(|t| *t += 0.7);
            let mut f = vec![0.0; n];
            let power = applied_forces(&mech, &x, &xd, &vec![0.0; mech.dof()], &mut f);
            let mut expected = f.clone();
            let mut expected_power = power;
            for (c, &t) in mech.coordinates.iter().zip(&tau) {
                let mut g = vec![0.0; n];
                coordinate_grad(&mech.pairs[c.pair.0], &x, &mut Dense { j: &mut g, ncols: n }, 0);
                let nonzero = || g.iter().enumerate().filter(|(_, g)| **g != 0.0);
                nonzero().for_each(|(i, g)| expected[i] += t * g);
                expected_power += t * nonzero().fold(-0.0, |s, (i, g)| s + g * xd[i]);
            }
            let power = applied_forces(&mech, &x, &xd, &tau, &mut f);
            assert_eq!(power.to_bits(), expected_power.to_bits(), "{model}");
            assert!(f.iter().zip(&expected).all(|(a, b)| a.to_bits() == b.to_bits()), "{model}: {f:?} {expected:?}");
        }
    }
}
