//! Prismatic pair (slider): no relative rotation, and b's copy of the pair point stays on a
//! line fixed in a. Two rows: phi_b - phi_a - (drawn) in radians, then the normal offset
//! from the guide in metres; relative coordinate: the displacement along the guide.

use super::frames::{add_grad, angle, link_state, link_state_t, perp, Projection};
use super::gear::Side;
use super::revolute::both_links;
use super::{
    along_coordinate, coordinate_lever, guide, reaction_force, FrictionField, PairGeometry, PairType, Relative, Rows,
};
use crate::linalg::Sink;
use crate::model::{JointFriction, Pair};

pub struct Prismatic {
    /// Unit direction of the guide in a's frame.
    pub axis: [f64; 2],
}

impl PairType for Prismatic {
    const NAME: &'static str = "prismatic";
    const ROWS: usize = 2;
    const LETTER: char = 'P';
    const FRICTION_FIELD: FrictionField = FrictionField::Length;

    #[inline]
    fn residual(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]]) -> Rows {
        [angle(pair.b, x) - angle(pair.a, x) - pair.rel_angle0, Projection::normal(pair, self.axis, x, trig).value()]
    }

    #[inline]
    fn jacobian<S: Sink>(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], j: &mut S, rows: [Option<usize>; 2]) {
        if let Some(row) = rows[0] {
            add_grad(j, row, &link_state_t(pair.a, x, trig), [0.0, 0.0, -1.0]);
            add_grad(j, row, &link_state_t(pair.b, x, trig), [0.0, 0.0, 1.0]);
        }
        if let Some(row) = rows[1] {
            Projection::normal(pair, self.axis, x, trig).grad(j, row, 1.0);
        }
    }

    #[inline]
    fn gamma(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> Rows {
        [0.0, Projection::normal(pair, self.axis, x, trig).gamma(u, v)]
    }

    #[inline]
    fn gamma3(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], t: &[f64]) -> Rows {
        [0.0, Projection::normal(pair, self.axis, x, trig).gamma3(u, v, t)]
    }

    fn row_scales(&self, inv_l: f64) -> Rows {
        [1.0, inv_l]
    }

    fn pattern(&self, pair: &Pair, _row: usize) -> Vec<usize> {
        both_links(pair)
    }

    #[inline]
    fn relative(&self) -> Option<Relative> {
        Some(Relative::Along { axis: self.axis })
    }

    /// The normal row's multiplier is the force on b along the guide's normal (its
    /// gradient in r_b is the normal); the angle row's is the couple on b.
    fn reaction(&self, pair: &Pair, x: &[f64], mu: Rows) -> [f64; 3] {
        let n = link_state(pair.a, x).rot(perp(self.axis));
        [mu[1] * n[0], mu[1] * n[1], mu[0]]
    }

    fn geometry(&self, pair: &Pair, x: &[f64], scale: f64) -> PairGeometry {
        let mut g = PairGeometry::new(Self::NAME);
        guide(pair, self.axis, x, scale, &mut g);
        g
    }

    /// max(|N|, 2|M|/L) for a slider of length L = `fr.length` > 0, whose normal force N and
    /// couple M are carried at its two ends (contact forces N/2 +- M/L, each rubbing mu times
    /// its magnitude); |N| for a slider of no length.
    #[inline]
    fn contact_load(&self, fr: &JointFriction, reaction: [f64; 3]) -> f64 {
        let force = reaction_force(reaction);
        if fr.length > 0.0 {
            force.max(2.0 * reaction[2].abs() / fr.length)
        } else {
            force
        }
    }

    #[inline]
    fn slip_lever<S: Sink>(&self, pair: &Pair, x: &[f64], xd: &[f64], _side: Side, j: &mut S) -> f64 {
        coordinate_lever(self, pair, x, xd, j)
    }

    #[inline]
    fn slip_side(&self, _x: &[f64], _reaction: [f64; 3], _rate: f64) -> Side {
        Side::A
    }

    along_coordinate!();
}
