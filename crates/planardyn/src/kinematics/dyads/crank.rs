//! An input link: a body turned about a ground point by its revolute input pair. With
//! q_k = phi_b - phi_a - (drawn relative angle) + (drawn value), the body's angle is
//! sign (q_k + offset), sign +1 when the body is the pair's b.

use super::{body, body_mut, put_acceleration, put_rate};
use crate::model::pairs::frames::rot;

#[derive(Debug, Clone)]
pub struct Crank {
    pub body: usize,
    /// The pair point on the ground (m), and the same point in the body's frame.
    pub pivot: [f64; 2],
    pub s: [f64; 2],
    /// The coordinate turning it, and how its angle follows from it.
    pub k: usize,
    pub sign: f64,
    pub offset: f64,
    /// R s at the last positions, for the rates and accelerations (as an RRR dyad's
    /// `Geometry`: no rotation of s again per column of U and per pass).
    pub rs: [f64; 2],
}

impl Crank {
    /// Pose at coordinates z: x and trig of the body.
    #[inline]
    pub fn position(&mut self, z: &[f64], x: &mut [f64], trig: &mut [[f64; 2]]) {
        let phi = self.sign * (z[self.k] + self.offset);
        let (sn, cs) = phi.sin_cos();
        let rs = rot([cs, sn], self.s);
        *body_mut(x, self.body) = [self.pivot[0] - rs[0], self.pivot[1] - rs[1], phi];
        trig[self.body] = [cs, sn];
        self.rs = rs;
    }

    /// The body's rates for the coordinate rates zd, at the last positions.
    #[inline]
    pub fn velocity(&self, zd: &[f64], v: &mut [f64]) {
        put_rate(v, self.body, [0.0; 2], self.rs, self.sign * zd[self.k]);
    }

    /// The body's accelerations for zero coordinate accelerations, from the rates v, at the
    /// last positions.
    #[inline]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        put_acceleration(a, self.body, [0.0; 2], self.rs, body(v, self.body)[2], 0.0);
    }
}
