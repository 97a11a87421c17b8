//! The class II dyad RRP: body 1 hinged at A to a link solved before it and at P to body 2,
//! body 2 joined by a prismatic pair to a link g solved before it (the slider-crank's rod and
//! slider). Body 2 keeps g's angle (plus the pair's drawn one), so the guide's unit normal n
//! in the world is known and the pair's normal row reads n . P = c; P is where that line
//! meets the circle about A of radius l = |AP|, on the side of A along the guide it is on in
//! the reference configuration. Body 1's rates and accelerations solve one scalar equation
//! whose coefficient n . E e (e = P - A) vanishes where the rod stands normal to the guide.

use super::{body, body_mut, pose, put_acceleration, put_rate, rate, Angle, Joint};
use crate::kinematics::group_sigma::rrp_sigma;
use crate::model::pairs::frames::{dot, perp, rot, sub};
use crate::model::{BodyId, Link, Pair, PairKind};
use crate::{KinematicsError, SingularityKind};
use std::f64::consts::{FRAC_PI_2, PI};

/// Whether cos(psi) has the sign of `side` (a branch's, +-1): `psi.cos() * side > 0`. Within
/// [-pi, pi], cos(psi) > 0 where |psi| <= FRAC_PI_2, the f64 below pi/2 (cos 6.1e-17, the next
/// f64's -1.6e-16: the library's cosine, within an ulp, has these signs), and no f64 is a zero
/// of it: the fold guard's test at every evaluation without the library call.
#[inline(always)]
fn on_side(psi: f64, side: f64) -> bool {
    if psi.abs() <= PI {
        let sign = if psi.abs() <= FRAC_PI_2 { 1.0 } else { -1.0 };
        return sign * side > 0.0;
    }
    psi.cos() * side > 0.0
}

#[inline]
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

#[inline]
fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

#[inline]
fn scaled(k: f64, a: [f64; 2]) -> [f64; 2] {
    [k * a[0], k * a[1]]
}

#[derive(Debug, Clone)]
pub struct Rrp {
    pub bodies: [usize; 2],
    /// A on its link, and the same point in body 1's frame.
    pub hinge: Joint,
    pub s_hinge: [f64; 2],
    /// P - A in body 1's frame and its squared length; P in body 2's frame.
    pub arm: [f64; 2],
    pub arm2: f64,
    pub s_p: [f64; 2],
    /// The prismatic pair's point on g (K), and P less the pair's point in body 2's frame (w).
    pub slide: Joint,
    pub w: [f64; 2],
    /// The guide's axis in its owner's frame, whether g owns it (else body 2 does), and
    /// body 2's angle less g's.
    pub axis: [f64; 2],
    pub guide_on_g: bool,
    pub turn: f64,
    pub turn_cs: [f64; 2],
    /// The arm's direction in body 1's frame less the axis's in its owner's: with
    /// psi = phi1 - phi_guide + bend, cos(psi) has the sign of the branch's side.
    pub bend: f64,
}

/// What the dyad keeps from the reference configuration: the side of A along the guide that
/// P is on (+1 ahead along the axis) and body 1's angle.
#[derive(Debug, Clone, Copy, Default)]
pub struct Branch {
    pub side: f64,
    pub angle: Angle,
}

/// The dyad at its solved position: R s of A on its link and on body 1, of K on g, e = P - A,
/// the guide's normal n, R2 w, R2 s_P, D = P - K - R2 w (along the guide), 1 / (n . E e),
/// (R2 s_P also gives body 2's pair point for the measure).
#[derive(Debug, Clone, Copy, Default)]
pub struct Geometry {
    known: [[f64; 2]; 2],
    own: [f64; 2],
    e: [f64; 2],
    n: [f64; 2],
    rw: [f64; 2],
    rp: [f64; 2],
    d: [f64; 2],
    inv_det: f64,
}

impl Geometry {
    /// The dyad's type II measure at these positions, 1 / L_k its group's inverse length: the
    /// smallest singular value of its block of J (columns r1, phi1, r2, phi2; rows of the
    /// pairs at A and P, the prismatic pair's angle and normal rows), lengths in L_k, in
    /// closed form (`group_sigma::rrp_sigma`).
    pub fn sigma(&self, inv_length: f64, guide_on_g: bool) -> f64 {
        let k = inv_length;
        let ea = perp(self.own);
        let ep1 = perp(add(self.own, self.e));
        let ep2 = perp(self.rp);
        // The normal row on body 2: the pair's b-point offset if g owns the guide, else the
        // gradient of n . (K - r2 - R2 s_a) in phi2.
        let (sign, g_phi) = if guide_on_g {
            (1.0, dot(self.n, perp(sub(self.rp, self.rw))))
        } else {
            // K - r2 = R2 s_P - D - R2 w.
            (-1.0, dot(perp(self.n), sub(self.rp, add(self.d, self.rw))))
        };
        let scaled = |v: [f64; 2]| [v[0] * k, v[1] * k];
        rrp_sigma(scaled(ea), scaled(ep1), scaled(ep2), self.n, sign, g_phi * k)
    }
}

impl Rrp {
    /// A dyad of `bodies`: body 1 hinged at A (`hinge`, `s_hinge` the same point in its frame)
    /// and to body 2 at P (`s_p1`, `s_p2` in each frame); body 2 joined to g by the prismatic
    /// `pair`, whose `b` it is if g owns the guide.
    /// None if `pair` is not prismatic.
    pub fn new(bodies: [usize; 2], hinge: Joint, s_hinge: [f64; 2], s_p: [[f64; 2]; 2], pair: &Pair) -> Option<Self> {
        let PairKind::Prismatic { axis } = pair.kind else { return None };
        let guide_on_g = pair.b == Link::Body(BodyId(bodies[1]));
        let (slide, s_own, turn) = if guide_on_g {
            (Joint { link: pair.a, s: pair.sa }, pair.sb, pair.rel_angle0)
        } else {
            (Joint { link: pair.b, s: pair.sb }, pair.sa, -pair.rel_angle0)
        };
        let arm = sub(s_p[0], s_hinge);
        let bend = arm[1].atan2(arm[0]) - axis[1].atan2(axis[0]);
        Some(Rrp {
            bodies,
            hinge,
            s_hinge,
            arm,
            arm2: dot(arm, arm),
            s_p: s_p[1],
            slide,
            w: sub(s_p[1], s_own),
            axis,
            guide_on_g,
            turn,
            turn_cs: [turn.cos(), turn.sin()],
            bend,
        })
    }

    /// The angle of the guide's owner in x.
    #[inline]
    fn guide_angle(&self, x: &[f64]) -> f64 {
        let phi_g = match self.slide.link {
            Link::Ground => 0.0,
            Link::Body(b) => x[3 * b.0 + 2],
        };
        if self.guide_on_g {
            phi_g
        } else {
            phi_g + self.turn
        }
    }

    /// Whether body 1's angle in x (any x, the Newton predictor's too) puts P on `branch`'s
    /// side: cos(psi) has the side's sign. Past the fold (the arm normal to the guide) a
    /// predictor lands on the other side.
    #[inline]
    pub fn keeps_side(&self, branch: &Branch, x: &[f64]) -> bool {
        let psi = x[3 * self.bodies[0] + 2] - self.guide_angle(x) + self.bend;
        on_side(psi, branch.side)
    }

    /// The branch of the configuration x.
    pub fn branch(&self, x: &[f64]) -> Branch {
        let phi = x[3 * self.bodies[0] + 2];
        let psi = phi - self.guide_angle(x) + self.bend;
        Branch { side: if psi.cos() >= 0.0 { 1.0 } else { -1.0 }, angle: Angle::of(phi) }
    }

    /// The bodies' poses (x and trig) on `branch`, the links before them solved, and the
    /// dyad's geometry there into `out` (in place: not returned and copied).
    #[inline(always)]
    pub fn position(
        &self,
        branch: &Branch,
        out: &mut Geometry,
        x: &mut [f64],
        trig: &mut [[f64; 2]],
    ) -> Result<(), KinematicsError> {
        let (a, ra) = self.hinge.place(x, trig);
        let (k, rk) = self.slide.place(x, trig);
        let (_, cg) = pose(self.slide.link, x, trig);
        let phi_g = match self.slide.link {
            Link::Ground => 0.0,
            Link::Body(b) => x[3 * b.0 + 2],
        };
        let c2 = rot(cg, self.turn_cs);
        let u = rot(if self.guide_on_g { cg } else { c2 }, self.axis);
        let n = perp(u);
        let rw = rot(c2, self.w);
        let d = dot(n, sub(add(k, rw), a));
        let h2 = self.arm2 - d * d;
        if !(h2 >= 0.0) {
            // The circle about A misses the guide's line: no assembly at these coordinates.
            return Err(if self.arm2 > 0.0 {
                KinematicsError::AssemblyFailed { residual: (-h2).sqrt(), iterations: 0 }
            } else {
                KinematicsError::singular(SingularityKind::TypeII)
            });
        }
        let h = branch.side * h2.sqrt();
        let e = add(scaled(d, n), scaled(h, u));
        let p = add(a, e);
        // Body 1: the rotation taking its arm to e.
        let (c, s) = (dot(self.arm, e), cross(self.arm, e));
        let (cs, phi) = branch.angle.rotation(c, s);
        let own = rot(cs, self.s_hinge);
        let [b1, b2] = self.bodies;
        *body_mut(x, b1) = [a[0] - own[0], a[1] - own[1], phi];
        trig[b1] = cs;
        // Body 2: g's angle, P at its point s_P.
        let rp = rot(c2, self.s_p);
        *body_mut(x, b2) = [p[0] - rp[0], p[1] - rp[1], phi_g + self.turn];
        trig[b2] = c2;
        let inv_det = 1.0 / dot(n, perp(e));
        *out = Geometry { known: [ra, rk], own, e, n, rw, rp, d: sub(sub(p, k), rw), inv_det };
        Ok(())
    }

    /// The bodies' rates, those of the links before them in v.
    #[inline]
    pub fn velocity(&self, g: &Geometry, v: &mut [f64]) {
        let va = self.hinge.velocity(g.known[0], v);
        let vk = self.slide.velocity(g.known[1], v);
        let (_, wg) = rate(self.slide.link, v);
        // d/dt (n . D) = w_g E n . D + n . (P' - K' - w_g E R2 w) = 0, P' = v_A + w1 E e.
        let rhs = dot(g.n, sub(add(vk, scaled(wg, perp(g.rw))), va)) - wg * dot(perp(g.n), g.d);
        let w1 = rhs * g.inv_det;
        let vp = add(va, scaled(w1, perp(g.e)));
        put_rate(v, self.bodies[0], va, g.own, w1);
        put_rate(v, self.bodies[1], vp, g.rp, wg);
    }

    /// The bodies' accelerations, from the rates v and the accelerations of the links before
    /// them in a.
    #[inline]
    pub fn acceleration(&self, g: &Geometry, v: &[f64], a: &mut [f64]) {
        let aa = self.hinge.acceleration(g.known[0], v, a);
        let ak = self.slide.acceleration(g.known[1], v, a);
        let va = self.hinge.velocity(g.known[0], v);
        let vk = self.slide.velocity(g.known[1], v);
        let (_, wg) = rate(self.slide.link, v);
        let (_, ag) = rate(self.slide.link, a);
        let w1 = body(v, self.bodies[0])[2];
        let vp = add(va, scaled(w1, perp(g.e)));
        // The second derivative of n . D: n'' . D + 2 n' . D' + n . D'' = 0.
        let nd = scaled(wg, perp(g.n));
        let ndd = sub(scaled(ag, perp(g.n)), scaled(wg * wg, g.n));
        let dd = sub(sub(vp, vk), scaled(wg, perp(g.rw)));
        let known = add(sub(aa, ak), add(scaled(-w1 * w1, g.e), sub(scaled(wg * wg, g.rw), scaled(ag, perp(g.rw)))));
        let al1 = -(dot(ndd, g.d) + 2.0 * dot(nd, dd) + dot(g.n, known)) * g.inv_det;
        let ap = add(aa, sub(scaled(al1, perp(g.e)), scaled(w1 * w1, g.e)));
        put_acceleration(a, self.bodies[0], aa, g.own, w1, al1);
        put_acceleration(a, self.bodies[1], ap, g.rp, wg, ag);
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{FRAC_PI_2, PI};

    /// `on_side`'s shortcut within [-pi, pi] decides as the library cosine's sign does, at its
    /// edges (pi/2 and pi, each side of them), at 0 of both signs, across whole turns and at
    /// NaN, for both sides (and a side of 0 or NaN, which no branch has).
    #[test]
    fn on_side_is_the_cosines_sign() {
        let mut angles = vec![0.0, -0.0, f64::NAN, f64::INFINITY, 1e-300, 3.0 * PI, -7.0 * PI, 1e6, -1e6];
        for edge in [FRAC_PI_2, -FRAC_PI_2, PI, -PI, 3.0 * FRAC_PI_2] {
            angles.extend([edge, edge.next_up(), edge.next_down(), edge.next_up().next_up()]);
        }
        angles.extend((-4000..=4000).map(|k| k as f64 * 1.37e-3 * PI));
        for psi in angles {
            for side in [1.0, -1.0, 0.0, f64::NAN] {
                assert_eq!(super::on_side(psi, side), psi.cos() * side > 0.0, "psi = {psi:e}, side {side}");
            }
        }
        assert!(super::on_side(FRAC_PI_2, 1.0) && !super::on_side(FRAC_PI_2.next_up(), 1.0));
    }
}
