//! A spring-damper on the relative motion of a pair: `type: torsional_spring` (an angle at a
//! revolute pair, a displacement along a prismatic or slot pair, from the drawing), effort
//! -k (theta - rest) - c theta' on the pair's relative coordinate. It stores
//! 1/2 k (theta - rest)^2; its damper's power is -c theta'^2. A `friction` load's viscous
//! part is one with k = 0 (`friction`).

use super::apply::pair_effort_rate;
use super::{Load, LoadSpecType, LoadType};
use crate::model::checks::{relative_pair, Ctx, R};
use crate::model::pairs::{
    add_effort, coordinate, coordinate_gamma, coordinate_rate, linear_coordinate, LinearCoordinate,
};
use crate::model::{Mechanism, PairId};
use crate::units;
use serde::{Deserialize, Serialize};

/// A torsional spring-damper at a revolute pair (or a linear one along a prismatic pair),
/// acting on the pair's relative motion from the drawing: torque -k (theta - rest) - c theta'.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
// `expecting`: as `force::ForceSpec`'s.
#[serde(deny_unknown_fields, expecting = "struct variant LoadSpec::TorsionalSpring")]
pub struct TorsionalSpringSpec {
    pub pair: String,
    #[serde(deserialize_with = "units::pair_stiffness")]
    pub stiffness: f64,
    #[serde(default, deserialize_with = "units::pair_damping")]
    pub damping: f64,
    /// Relative rotation (rad) or displacement (m) from the drawing at which it is unloaded.
    #[serde(default, deserialize_with = "units::position")]
    pub rest: f64,
}

/// Spring-damper on the relative motion of a pair (angle or displacement from the drawing):
/// generalized effort -k (theta - rest) - c theta'. Viscous friction has k = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairSpring {
    pub pair: PairId,
    pub stiffness: f64,
    pub damping: f64,
    pub rest: f64,
    /// The pair's relative coordinate where it is a difference of two entries of x
    /// (`pairs::linear_coordinate`): the effort through it at every evaluation.
    pub linear: Option<LinearCoordinate>,
}

impl LoadSpecType for TorsionalSpringSpec {
    fn build(&self, ctx: &Ctx, mech: &Mechanism, path: &str) -> R<Option<Load>> {
        let pair = relative_pair(ctx, mech, &format!("{path}.pair"), &self.pair)?;
        Ok(Some(Load::PairSpring(PairSpring {
            pair,
            stiffness: ctx.non_negative(&format!("{path}.stiffness"), self.stiffness)?,
            damping: ctx.non_negative(&format!("{path}.damping"), self.damping)?,
            rest: ctx.finite(&format!("{path}.rest"), self.rest)?,
            linear: linear_coordinate(&mech.pairs[pair.0]),
        })))
    }
}

impl LoadType for PairSpring {
    #[inline]
    fn add_force(&self, mech: &Mechanism, x: &[f64], xd: &[f64], f: &mut [f64]) -> f64 {
        let effort = |value, rate| -self.stiffness * (value - self.rest) - self.damping * rate;
        let (_, rate) = add_effort(self.linear.as_ref(), &mech.pairs, self.pair, x, xd, f, effort);
        -(self.damping * rate * rate)
    }

    fn add_force_dx(&self, mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64], df: &mut [f64], scratch: &mut [f64]) {
        let p = &mech.pairs[self.pair.0];
        let (k, c) = (self.stiffness, self.damping);
        let rate = coordinate_rate(p, x, xd);
        let effort = -k * (coordinate(p, x) - self.rest) - c * rate;
        let deffort = -k * coordinate_rate(p, x, t) - c * coordinate_gamma(p, x, xd, t);
        pair_effort_rate(mech, self.pair.0, effort, deffort, x, t, df, scratch);
    }

    fn power_dx(&self, mech: &Mechanism, x: &[f64], xd: &[f64], t: &[f64]) -> f64 {
        let p = &mech.pairs[self.pair.0];
        -(2.0 * self.damping * coordinate_rate(p, x, xd) * coordinate_gamma(p, x, xd, t))
    }

    fn potential(&self, mech: &Mechanism, x: &[f64]) -> f64 {
        0.5 * self.stiffness * (coordinate(&mech.pairs[self.pair.0], x) - self.rest).powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{add_force, Load};
    use crate::linalg::Dense;
    use crate::model::pairs::{coordinate, coordinate_grad};

    /// A pair spring adds its effort -k (theta - rest) - c theta' times the pair coordinate's
    /// gradient (its row written into a dense row), theta' the gradient along xd, and returns
    /// the damper's power -c theta'^2, bit for bit: the five-bar's two servo springs on its
    /// motor pairs, at its drawing with rates 1.3 ... and the springs off their rest.
    #[test]
    fn a_spring_adds_its_effort_times_the_gradient() {
        let path = format!("{}/../../examples/models/five-bar.yaml", env!("CARGO_MANIFEST_DIR"));
        let mech = crate::load(&path).unwrap();
        let mut x = mech.x0.clone();
        x.iter_mut().enumerate().for_each(|(i, v)| *v += 0.01 * i as f64);
        let n = x.len();
        let xd: Vec<f64> = (0..n).map(|i| 1.3 - 0.2 * i as f64).collect();
        let springs: Vec<_> =
            mech.loads.iter().filter_map(|l| if let Load::PairSpring(s) = l { Some(s) } else { None }).collect();
        assert_eq!(springs.len(), 2);
        for s in springs {
            let p = &mech.pairs[s.pair.0];
            let mut f: Vec<f64> = (0..n).map(|i| 0.5 * i as f64 - 1.0).collect();
            let mut expected = f.clone();
            let power = add_force(&Load::PairSpring(*s), &mech, &x, &xd, &mut f);
            let mut g = vec![0.0; n];
            coordinate_grad(p, &x, &mut Dense { j: &mut g, ncols: n }, 0);
            let nonzero = || g.iter().enumerate().filter(|(_, g)| **g != 0.0);
            let rate = nonzero().fold(-0.0, |r, (i, g)| r + g * xd[i]);
            let effort = -s.stiffness * (coordinate(p, &x) - s.rest) - s.damping * rate;
            nonzero().for_each(|(i, g)| expected[i] += effort * g);
            assert_ne!(effort, 0.0);
            assert_eq!(power.to_bits(), (-(s.damping * rate * rate)).to_bits());
            assert!(f.iter().zip(&expected).all(|(a, b)| a.to_bits() == b.to_bits()), "{f:?} {expected:?}");
        }
    }
}
