//! The class II dyad of three revolute pairs: bodies 1 and 2 hinged to each other at P and to
//! links solved before them at A and B. P is where the circles about A and B of radii
//! l1 = |AP| and l2 = |BP| meet, on the side of AB it is on in the reference configuration
//! (the assembly branch); the two bodies' rates and accelerations solve
//! w1 E e1 - w2 E e2 = v_B - v_A (and its derivative) with e1 = P - A, e2 = P - B, whose
//! determinant e1 x e2 = l1 l2 sin(mu) vanishes with the transmission angle mu.

use super::{body, body_mut, put_acceleration, put_rate, round, Angle, Joint};
use crate::kinematics::group_sigma::dyad_sigma;
use crate::model::pairs::frames::{dot, link_state, perp, rot, sub};
use crate::model::{BodyId, Link};
use crate::{KinematicsError, SingularityKind};
use std::f64::consts::{PI, TAU};

#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Whether the angle psi between a dyad's links is on `side` (+-1): psi reduced to [-pi, pi] has
/// the sign of sin(psi). Within (-pi, pi), where a branch keeps psi (the bodies' angles are
/// continuous and sin(psi) is never 0 on a branch), |psi / TAU| < 0.5 rounds to 0 and the
/// reduction leaves psi itself: the same test without the rounding (the fold guard's at every
/// evaluation: four-bar -21 instructions, Andrews' squeezer -40).
#[inline(always)]
fn on_side(psi: f64, side: f64) -> bool {
    if psi.abs() < PI {
        return psi * side > 0.0;
    }
    (psi - TAU * round(psi / TAU)) * side > 0.0
}

#[derive(Debug, Clone)]
pub struct Rrr {
    pub bodies: [usize; 2],
    /// A and B on the links solved before, and the same points in the frames of bodies 1, 2.
    pub outer: [Joint; 2],
    pub s_outer: [[f64; 2]; 2],
    /// P - A in body 1's frame and P - B in body 2's, and their squared lengths.
    pub arms: [[f64; 2]; 2],
    pub arms2: [f64; 2],
    /// The angle from e1 to e2 less phi2 - phi1 (the arms' directions in their frames): the
    /// angle at P is psi = phi2 - phi1 + bend, and sin(psi) has the sign of the branch's side.
    pub bend: f64,
}

/// What the dyad keeps from the reference configuration: the side of AB that P is on (+1 to
/// the left of A -> B) and the bodies' angles (the new angles are taken within pi of them).
#[derive(Debug, Clone, Copy, Default)]
pub struct Branch {
    pub side: f64,
    pub angles: [Angle; 2],
}

/// The dyad at its solved position, for the rates and accelerations: R s of A and B on their
/// links and on bodies 1 and 2, e1, e2 in the world and 1 / (e1 x e2).
#[derive(Debug, Clone, Copy, Default)]
pub struct Geometry {
    known: [[f64; 2]; 2],
    pub(crate) own: [[f64; 2]; 2],
    pub(crate) e: [[f64; 2]; 2],
    inv_det: f64,
}

impl Geometry {
    /// The dyad's type II measure at these positions, 1 / L_k its group's inverse length
    /// (`group_sigma::dyad_sigma`): the arms of A and P on body 1 (R s_A, R s_A + e1) and of
    /// B and P on body 2.
    pub fn sigma(&self, inv_length: f64) -> f64 {
        let [a, b] = self.own.map(|r| [r[0] * inv_length, r[1] * inv_length]);
        let [p1, p2] = [0, 1]
            .map(|i| [(self.own[i][0] + self.e[i][0]) * inv_length, (self.own[i][1] + self.e[i][1]) * inv_length]);
        dyad_sigma(a, b, p1, p2)
    }
}

impl Rrr {
    /// A dyad of `bodies` hinged at A and B to the links before it (`outer`, with the same
    /// points `s_outer` in the bodies' frames) and to each other at P (`s_inner` in each frame).
    pub fn new(bodies: [usize; 2], outer: [Joint; 2], s_outer: [[f64; 2]; 2], s_inner: [[f64; 2]; 2]) -> Self {
        let arms = [sub(s_inner[0], s_outer[0]), sub(s_inner[1], s_outer[1])];
        let mut d = Rrr { bodies, outer, s_outer, arms2: [0.0; 2], arms, bend: 0.0 };
        d.set_arms(arms);
        d
    }

    /// Set P - A in body 1's frame and P - B in body 2's (a link whose shape a relative input
    /// changes: `extension`).
    #[inline]
    pub fn set_arms(&mut self, arms: [[f64; 2]; 2]) {
        self.bend = arms[1][1].atan2(arms[1][0]) - arms[0][1].atan2(arms[0][0]);
        (self.arms, self.arms2) = (arms, arms.map(|a| dot(a, a)));
    }

    /// Whether the bodies' angles in x (any x, not necessarily assembled: the Newton
    /// predictor's) put P on `branch`'s side of AB: sin(psi) of x's angles has the side's sign.
    /// A predictor that follows the motion through the dyad's fold (where e1 and e2 align and
    /// the branches meet) lands on the other side; the closed form on the kept side would then
    /// go on along the other branch.
    #[inline]
    pub fn keeps_side(&self, branch: &Branch, x: &[f64]) -> bool {
        let [b1, b2] = self.bodies;
        on_side(x[3 * b2 + 2] - x[3 * b1 + 2] + self.bend, branch.side)
    }

    /// The branch of the configuration x.
    pub fn branch(&self, x: &[f64]) -> Branch {
        let [a, b] = self.outer.map(|j| link_state(j.link, x).point(j.s));
        let s_p = [self.s_outer[0][0] + self.arms[0][0], self.s_outer[0][1] + self.arms[0][1]];
        let p = link_state(Link::Body(BodyId(self.bodies[0])), x).point(s_p);
        let angles = self.bodies.map(|i| Angle::of(x[3 * i + 2]));
        Branch { side: cross(sub(b, a), sub(p, a)).signum(), angles }
    }

    /// The bodies' poses (x and trig) on `branch`, the links before them solved, and their
    /// geometry `g` (written in place: no copy of it between the stages).
    #[inline(always)]
    pub fn position(
        &self,
        branch: &Branch,
        g: &mut Geometry,
        x: &mut [f64],
        trig: &mut [[f64; 2]],
    ) -> Result<(), KinematicsError> {
        let (a, ra) = self.outer[0].place(x, trig);
        let (b, rb) = self.outer[1].place(x, trig);
        let [l1, l2] = self.arms2;
        let d = sub(b, a);
        let dd = dot(d, d);
        let along = (l1 - l2 + dd) / (2.0 * dd);
        let h2 = l1 / dd - along * along;
        if !(h2 >= 0.0) {
            // The circles miss each other (or A = B): no assembly at these coordinates.
            return Err(if dd > 0.0 {
                KinematicsError::AssemblyFailed { residual: (-h2).sqrt(), iterations: 0 }
            } else {
                KinematicsError::singular(SingularityKind::TypeII)
            });
        }
        let h = branch.side * h2.sqrt();
        let n = perp(d);
        let p = [a[0] + along * d[0] + h * n[0], a[1] + along * d[1] + h * n[1]];
        g.known = [ra, rb];
        for (i, q) in [a, b].into_iter().enumerate() {
            // The rotation taking the arm in the body's frame to e = P - q in the world.
            let (arm, e) = (self.arms[i], sub(p, q));
            let (c, s) = (dot(arm, e), cross(arm, e));
            let (cs, phi) = branch.angles[i].rotation(c, s);
            let rs = rot(cs, self.s_outer[i]);
            *body_mut(x, self.bodies[i]) = [q[0] - rs[0], q[1] - rs[1], phi];
            trig[self.bodies[i]] = cs;
            g.own[i] = rs;
            g.e[i] = e;
        }
        g.inv_det = 1.0 / cross(g.e[0], g.e[1]);
        Ok(())
    }

    /// The bodies' rates, those of the links before them in v; `slide` P's velocity relative to
    /// body 1 and to body 2 (zero unless a relative input moves it along its link).
    #[inline(always)]
    pub fn velocity(&self, g: &Geometry, slide: [[f64; 2]; 2], v: &mut [f64]) {
        let va = self.outer[0].velocity(g.known[0], v);
        let vb = self.outer[1].velocity(g.known[1], v);
        let dv = [vb[0] + slide[1][0] - va[0] - slide[0][0], vb[1] + slide[1][1] - va[1] - slide[0][1]];
        let (w1, w2) = (dot(dv, g.e[1]) * g.inv_det, dot(dv, g.e[0]) * g.inv_det);
        put_rate(v, self.bodies[0], va, g.own[0], w1);
        put_rate(v, self.bodies[1], vb, g.own[1], w2);
    }

    /// The bodies' accelerations, from the rates v and the accelerations of the links before
    /// them in a; `slide` as in [`Rrr::velocity`] (P's Coriolis acceleration 2 w E slide).
    #[inline(always)]
    pub fn acceleration(&self, g: &Geometry, slide: [[f64; 2]; 2], v: &[f64], a: &mut [f64]) {
        let aa = self.outer[0].acceleration(g.known[0], v, a);
        let ab = self.outer[1].acceleration(g.known[1], v, a);
        let (w1, w2) = (body(v, self.bodies[0])[2], body(v, self.bodies[1])[2]);
        let (k1, k2, [e1, e2]) = (w1 * w1, w2 * w2, g.e);
        let (c1, c2) = (perp(slide[0]), perp(slide[1]));
        let (t1, t2) = (2.0 * w1, 2.0 * w2);
        let da = [
            ab[0] + t2 * c2[0] - aa[0] - t1 * c1[0] + k1 * e1[0] - k2 * e2[0],
            ab[1] + t2 * c2[1] - aa[1] - t1 * c1[1] + k1 * e1[1] - k2 * e2[1],
        ];
        let (al1, al2) = (dot(da, e2) * g.inv_det, dot(da, e1) * g.inv_det);
        put_acceleration(a, self.bodies[0], aa, g.own[0], w1, al1);
        put_acceleration(a, self.bodies[1], ab, g.own[1], w2, al2);
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{PI, TAU};

    /// `on_side`'s shortcut within (-pi, pi) decides as the full reduction does, at the
    /// shortcut's edges (pi itself reduces to -pi: the other side), at 0 of both signs, across
    /// whole turns and at NaN, for both sides.
    #[test]
    fn on_side_is_the_reduced_angles_sign() {
        let reduced = |psi: f64, side: f64| (psi - TAU * (psi / TAU).round()) * side > 0.0;
        let mut angles = vec![0.0, -0.0, f64::NAN, 1e-300, 3.0 * PI, -7.0 * PI, 1e6, -1e6, 1e17];
        for edge in [PI, -PI, TAU, -TAU] {
            angles.extend([edge, edge.next_up(), edge.next_down(), edge.next_up().next_up()]);
        }
        angles.extend((-4000..=4000).map(|k| k as f64 * 1.37e-3 * PI));
        for psi in angles {
            for side in [1.0, -1.0] {
                assert_eq!(super::on_side(psi, side), reduced(psi, side), "psi = {psi:e}, side {side}");
            }
        }
        assert!(!super::on_side(PI, 1.0) && super::on_side(PI.next_down(), 1.0));
    }
}
