//! Pin-in-slot pair: b's pin (the pair point) slides along a line fixed in a, and b turns
//! freely. One row in metres: the pin's normal offset from the slot's centre line, 0.
//! Relative coordinate: the pin's displacement along the slot (as a prismatic pair's).
//! Reaction: the normal force at the pin (no friction, no couple).

use super::frames::{link_state, perp, Projection};
use super::gear::Side;
use super::revolute::both_links;
use super::{
    along_coordinate, coordinate_lever, reaction_force, FrictionField, PairGeometry, PairType, Relative, Rows,
};
use crate::linalg::Sink;
use crate::model::{JointFriction, Pair};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slot {
    /// Unit direction of the slot in a's frame.
    pub axis: [f64; 2],
    /// The slot's drawn ends in a's frame (m), for the drawings.
    pub ends: [[f64; 2]; 2],
}

impl PairType for Slot {
    const NAME: &'static str = "slot";
    const ROWS: usize = 1;
    const LETTER: char = 'S';
    const FRICTION_FIELD: FrictionField = FrictionField::None;

    #[inline]
    fn residual(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]]) -> Rows {
        [Projection::normal(pair, self.axis, x, trig).value(), 0.0]
    }

    #[inline]
    fn jacobian<S: Sink>(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], j: &mut S, rows: [Option<usize>; 2]) {
        if let Some(row) = rows[0] {
            Projection::normal(pair, self.axis, x, trig).grad(j, row, 1.0);
        }
    }

    #[inline]
    fn gamma(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> Rows {
        [Projection::normal(pair, self.axis, x, trig).gamma(u, v), 0.0]
    }

    #[inline]
    fn gamma3(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], t: &[f64]) -> Rows {
        [Projection::normal(pair, self.axis, x, trig).gamma3(u, v, t), 0.0]
    }

    fn row_scales(&self, inv_l: f64) -> Rows {
        [inv_l, 0.0]
    }

    fn pattern(&self, pair: &Pair, _row: usize) -> Vec<usize> {
        both_links(pair)
    }

    #[inline]
    fn relative(&self) -> Option<Relative> {
        Some(Relative::Along { axis: self.axis })
    }

    /// The row's gradient in r_b is the slot's normal n, so mu n is the force on b.
    fn reaction(&self, pair: &Pair, x: &[f64], mu: Rows) -> [f64; 3] {
        let n = link_state(pair.a, x).rot(perp(self.axis));
        [mu[0] * n[0], mu[0] * n[1], 0.0]
    }

    fn geometry(&self, pair: &Pair, x: &[f64], _scale: f64) -> PairGeometry {
        let (a, b) = (link_state(pair.a, x), link_state(pair.b, x));
        let mut g = PairGeometry::new(Self::NAME);
        g.pins.push(b.point(pair.sb));
        g.lines.push(self.ends.map(|e| a.point(e)));
        g
    }

    /// The slot's normal force.
    #[inline]
    fn contact_load(&self, _fr: &JointFriction, reaction: [f64; 3]) -> f64 {
        reaction_force(reaction)
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
