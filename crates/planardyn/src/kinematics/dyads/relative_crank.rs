//! A body turned by a relative revolute input about a point of a link placed before it (a
//! crank on a crank): with q_k = phi_b - phi_a - (drawn relative angle), the body's angle is
//! the other link's plus sign (q_k + offset), sign +1 when the body is the pair's b. The
//! alternative charts' inputs (`kinematics::alt_charts`): a five-bar's two angles at one
//! ground pivot and its elbow.

use super::{body, body_mut, put_acceleration, put_rate, rate, Joint};
use crate::model::pairs::frames::rot;

#[derive(Debug, Clone)]
pub struct RelativeCrank {
    pub body: usize,
    /// The pair point on the link placed before (its frame).
    pub pivot: Joint,
    /// The same point in the body's frame.
    pub s: [f64; 2],
    /// The coordinate turning it, and how its angle follows from it.
    pub k: usize,
    pub sign: f64,
    pub offset: f64,
    /// R s of the body's and of the pivot's link's point at the last positions.
    pub rs: [f64; 2],
    pub pivot_rs: [f64; 2],
}

impl RelativeCrank {
    /// Pose at coordinates z, from the pivot link's pose in x and trig.
    #[inline]
    pub fn position(&mut self, z: &[f64], x: &mut [f64], trig: &mut [[f64; 2]]) {
        let (p, pivot_rs) = self.pivot.place(x, trig);
        let phi = rate(self.pivot.link, x).1 + self.sign * (z[self.k] + self.offset);
        let (sn, cs) = phi.sin_cos();
        let rs = rot([cs, sn], self.s);
        *body_mut(x, self.body) = [p[0] - rs[0], p[1] - rs[1], phi];
        trig[self.body] = [cs, sn];
        (self.rs, self.pivot_rs) = (rs, pivot_rs);
    }

    /// The body's rates for the coordinate rates zd and the pivot link's rates in v.
    #[inline]
    pub fn velocity(&self, zd: &[f64], v: &mut [f64]) {
        let vp = self.pivot.velocity(self.pivot_rs, v);
        let w = rate(self.pivot.link, v).1 + self.sign * zd[self.k];
        put_rate(v, self.body, vp, self.rs, w);
    }

    /// The body's accelerations for zero coordinate accelerations, from the rates v and the
    /// pivot link's accelerations in a.
    #[inline]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        let ap = self.pivot.acceleration(self.pivot_rs, v, a);
        let al = rate(self.pivot.link, a).1;
        put_acceleration(a, self.body, ap, self.rs, body(v, self.body)[2], al);
    }
}
