//! The class II dyad RPR: body o hinged at A to a link solved before it, body f hinged at B to
//! another, and the two joined by a prismatic pair whose guide body o owns (the pair's `a`;
//! body f keeps o's angle plus the pair's drawn one). In o's frame B runs along a line (the
//! guide, carried to B): B = c0 + lambda u, at the signed offset h = u x (c0 - A) from A. So
//! |AB| fixes lambda up to the side of A's foot on the line that B is on, and o's angle turns
//! the frame's A -> B onto the world's: asin(h / |AB|) off the direction A -> B. The branch is
//! that side; its fold is where |AB| = |h| (the guide normal to A -> B). Rates, accelerations
//! and the measure come from the group's block of J (`Local`).

use super::local::Local;
use super::{Angle, Joint};
use crate::model::pairs::frames::{dot, perp, rot, sub};
use crate::model::{Mechanism, Pair, PairId, PairKind};
use crate::{KinematicsError, SingularityKind};

#[derive(Debug, Clone)]
pub struct Rpr {
    /// Bodies o (the guide's owner) and f: their rows on a local copy.
    local: Local,
    /// A and B on their links, and each in its body's frame (A in o's, B in f's).
    hinges: [Joint; 2],
    s_hinges: [[f64; 2]; 2],
    /// The guide's unit direction in o's frame, and A's offset from the guide's line through
    /// B there (c0 - A).
    axis: [f64; 2],
    w: [f64; 2],
    /// Body f's angle less o's.
    turn_cs: [f64; 2],
    turn: f64,
}

/// What the dyad keeps from the reference configuration: the side of A's foot on the guide
/// that B is on (+1 ahead along the axis) and body o's angle.
#[derive(Debug, Clone, Copy, Default)]
pub struct Branch {
    pub side: f64,
    pub angle: Angle,
}

impl Rpr {
    /// The dyad of bodies o and f (the prismatic `pair`'s `a` and `b`), hinged at A and B
    /// (`hinges` on the solved links, `s_hinges` in o's and f's frames) by the outer revolute
    /// pairs `outer` (A's first); None if `pair` is not prismatic or the rows do not fit the
    /// local copy.
    pub fn new(
        mech: &Mechanism,
        bodies: [usize; 2],
        hinges: [Joint; 2],
        s_hinges: [[f64; 2]; 2],
        outer: [PairId; 2],
        inner: PairId,
    ) -> Option<Self> {
        let pair: &Pair = &mech.pairs[inner.0];
        let PairKind::Prismatic { axis } = pair.kind else { return None };
        let norm = axis[0].hypot(axis[1]);
        if !(norm > 0.0) {
            return None;
        }
        let axis = [axis[0] / norm, axis[1] / norm];
        let turn = pair.rel_angle0;
        let turn_cs = [turn.cos(), turn.sin()];
        // B in o's frame at slide lambda: sa + lambda u + R(turn) (s_B - sb).
        let c0 = {
            let r = rot(turn_cs, sub(s_hinges[1], pair.sb));
            [pair.sa[0] + r[0], pair.sa[1] + r[1]]
        };
        let local = Local::new(mech, &bodies, &[outer[0], outer[1], inner])?;
        Some(Rpr { local, hinges, s_hinges, axis, w: sub(c0, s_hinges[0]), turn_cs, turn })
    }

    pub fn bodies(&self) -> &[usize] {
        self.local.bodies()
    }

    /// The guide's direction in the world and B - A for the bodies' coordinates in x.
    fn guide_and_ab(&self, x: &[f64]) -> ([f64; 2], [f64; 2]) {
        let [o, f] = [0, 1].map(|i| self.local.bodies()[i]);
        let place = |b: usize, s: [f64; 2]| {
            let (sn, cs) = x[3 * b + 2].sin_cos();
            let r = rot([cs, sn], s);
            [x[3 * b] + r[0], x[3 * b + 1] + r[1]]
        };
        let (sn, cs) = x[3 * o + 2].sin_cos();
        (rot([cs, sn], self.axis), sub(place(f, self.s_hinges[1]), place(o, self.s_hinges[0])))
    }

    /// Whether the bodies' coordinates in x (any x, the Newton predictor's too) put B on
    /// `branch`'s side of A's foot on the guide; past the fold a predictor lands on the other.
    #[inline]
    pub fn keeps_side(&self, branch: &Branch, x: &[f64]) -> bool {
        let (u, ab) = self.guide_and_ab(x);
        dot(u, ab) * branch.side > 0.0
    }

    /// The branch of the configuration x.
    pub fn branch(&self, x: &[f64]) -> Branch {
        let (u, ab) = self.guide_and_ab(x);
        let phi = x[3 * self.local.bodies()[0] + 2];
        Branch { side: if dot(u, ab) >= 0.0 { 1.0 } else { -1.0 }, angle: Angle::of(phi) }
    }

    /// The bodies' poses (x and trig) on `branch`, the links before them solved.
    #[inline]
    pub fn position(&mut self, branch: &Branch, x: &mut [f64], trig: &mut [[f64; 2]]) -> Result<(), KinematicsError> {
        let (a, _) = self.hinges[0].place(x, trig);
        let (b, _) = self.hinges[1].place(x, trig);
        let ab = sub(b, a);
        let dist2 = dot(ab, ab);
        let (along, h) = (dot(self.axis, self.w), dot(perp(self.axis), self.w));
        let m2 = dist2 - h * h;
        if !(m2 >= 0.0 && dist2 > 0.0) {
            // B is nearer to A than the guide's offset: no assembly at these coordinates.
            return Err(if h != 0.0 {
                KinematicsError::AssemblyFailed { residual: h.abs() - dist2.sqrt(), iterations: 0 }
            } else {
                KinematicsError::singular(SingularityKind::TypeII)
            });
        }
        // A -> B in o's frame: the foot's offset, then along the guide on the branch's side.
        let t = branch.side * m2.sqrt();
        let v = [self.w[0] + (t - along) * self.axis[0], self.w[1] + (t - along) * self.axis[1]];
        let (c, s) = (dot(v, ab), v[0] * ab[1] - v[1] * ab[0]);
        let (cs, phi) = branch.angle.rotation(c, s);
        let cf = rot(cs, self.turn_cs);
        let (ro, rf) = (rot(cs, self.s_hinges[0]), rot(cf, self.s_hinges[1]));
        self.local.load(x, trig);
        self.local.x[..6].copy_from_slice(&[
            a[0] - ro[0],
            a[1] - ro[1],
            phi,
            b[0] - rf[0],
            b[1] - rf[1],
            phi + self.turn,
        ]);
        self.local.trig[..2].copy_from_slice(&[cs, cf]);
        self.local.store(x, trig);
        Ok(())
    }

    /// The bodies' rates, those of the links before them in v.
    #[inline]
    pub fn velocity(&self, v: &mut [f64]) {
        self.local.velocity(v);
    }

    /// The bodies' accelerations, from the rates v and the accelerations of the links before
    /// them in a.
    #[inline]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        self.local.acceleration(v, a);
    }

    /// The type II measure at the last positions, 1 / L_k its group's inverse length.
    pub fn sigma(&self, inv_length: f64) -> f64 {
        self.local.sigma(inv_length)
    }
}
