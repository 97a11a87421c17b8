//! The class II dyad of three revolute pairs: bodies 1 and 2 hinged to each other at P and to
//! links solved before them at A and B. P is where the circles about A and B of radii
//! l1 = |AP| and l2 = |BP| meet, on the side of AB it is on in the reference configuration
//! (the assembly branch); the two bodies' rates and accelerations solve
//! w1 E e1 - w2 E e2 = v_B - v_A (and its derivative) with e1 = P - A, e2 = P - B, whose
//! determinant e1 x e2 = l1 l2 sin(mu) vanishes with the transmission angle mu.

use super::{put_acceleration, put_rate, Joint};
use crate::kinematics::pairs::frames::{dot, link_state, perp, rot, sub};
use crate::model::{BodyId, Link};
use crate::{KinematicsError, SingularityKind};

#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

#[derive(Debug, Clone)]
pub struct Rrr {
    pub bodies: [usize; 2],
    /// A and B on the links solved before, and the same points in the frames of bodies 1, 2.
    pub outer: [Joint; 2],
    pub s_outer: [[f64; 2]; 2],
    /// P in the frames of bodies 1 and 2.
    pub s_inner: [[f64; 2]; 2],
}

/// What the dyad keeps from the reference configuration: the side of AB that P is on (+1 to
/// the left of A -> B) and the bodies' angles (the new ones are taken within pi of them).
#[derive(Debug, Clone, Copy, Default)]
pub struct Branch {
    pub side: f64,
    pub phi: [f64; 2],
}

impl Rrr {
    /// P - A in body 1's frame and P - B in body 2's.
    #[inline]
    fn arms(&self) -> [[f64; 2]; 2] {
        [sub(self.s_inner[0], self.s_outer[0]), sub(self.s_inner[1], self.s_outer[1])]
    }

    /// The branch of the configuration x.
    pub fn branch(&self, x: &[f64]) -> Branch {
        let [a, b] = self.outer.map(|j| link_state(j.link, x).point(j.s));
        let p = link_state(Link::Body(BodyId(self.bodies[0])), x).point(self.s_inner[0]);
        Branch { side: cross(sub(b, a), sub(p, a)).signum(), phi: self.bodies.map(|i| x[3 * i + 2]) }
    }

    /// The bodies' poses (x and trig) on `branch`, the links before them solved.
    #[inline]
    pub fn position(&self, branch: &Branch, x: &mut [f64], trig: &mut [[f64; 2]]) -> Result<(), KinematicsError> {
        let a = self.outer[0].place(x, trig).0;
        let b = self.outer[1].place(x, trig).0;
        let arms = self.arms();
        let (l1, l2) = (dot(arms[0], arms[0]), dot(arms[1], arms[1]));
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
        for (i, (q, arm)) in [(a, arms[0]), (b, arms[1])].into_iter().enumerate() {
            // The rotation taking the arm in the body's frame to P - q in the world.
            let e = sub(p, q);
            let (c, s) = (dot(arm, e), cross(arm, e));
            let r = c.hypot(s);
            let cs = [c / r, s / r];
            let turn = s.atan2(c) - branch.phi[i];
            let phi = branch.phi[i] + turn - std::f64::consts::TAU * (turn / std::f64::consts::TAU).round();
            let rs = rot(cs, self.s_outer[i]);
            let k = 3 * self.bodies[i];
            x[k] = q[0] - rs[0];
            x[k + 1] = q[1] - rs[1];
            x[k + 2] = phi;
            trig[self.bodies[i]] = cs;
        }
        Ok(())
    }

    /// e1, e2 in the world and their cross product.
    #[inline]
    fn frame(&self, trig: &[[f64; 2]]) -> ([f64; 2], [f64; 2], f64) {
        let arms = self.arms();
        let e1 = rot(trig[self.bodies[0]], arms[0]);
        let e2 = rot(trig[self.bodies[1]], arms[1]);
        (e1, e2, cross(e1, e2))
    }

    /// The bodies' rates, those of the links before them in v.
    #[inline]
    pub fn velocity(&self, x: &[f64], trig: &[[f64; 2]], v: &mut [f64]) {
        let va = self.outer[0].velocity(x, trig, v);
        let vb = self.outer[1].velocity(x, trig, v);
        let (e1, e2, det) = self.frame(trig);
        let g = sub(vb, va);
        let (w1, w2) = (dot(g, e2) / det, dot(g, e1) / det);
        put_rate(v, self.bodies[0], va, rot(trig[self.bodies[0]], self.s_outer[0]), w1);
        put_rate(v, self.bodies[1], vb, rot(trig[self.bodies[1]], self.s_outer[1]), w2);
    }

    /// The bodies' accelerations, from the rates v and the accelerations of the links before
    /// them in a.
    #[inline]
    pub fn acceleration(&self, x: &[f64], trig: &[[f64; 2]], v: &[f64], a: &mut [f64]) {
        let aa = self.outer[0].acceleration(x, trig, v, a);
        let ab = self.outer[1].acceleration(x, trig, v, a);
        let (e1, e2, det) = self.frame(trig);
        let (w1, w2) = (v[3 * self.bodies[0] + 2], v[3 * self.bodies[1] + 2]);
        let (k1, k2) = (w1 * w1, w2 * w2);
        let g = [ab[0] - aa[0] + k1 * e1[0] - k2 * e2[0], ab[1] - aa[1] + k1 * e1[1] - k2 * e2[1]];
        let (al1, al2) = (dot(g, e2) / det, dot(g, e1) / det);
        put_acceleration(a, self.bodies[0], aa, rot(trig[self.bodies[0]], self.s_outer[0]), w1, al1);
        put_acceleration(a, self.bodies[1], ab, rot(trig[self.bodies[1]], self.s_outer[1]), w2, al2);
    }
}
