//! An input slider: a body moved along a guide fixed to the ground by its prismatic input
//! pair. The body keeps the pair's drawn angle and its pair point lies at G + (q_k - value) u,
//! G the pair point on the ground and u the guide's direction.

use super::{body_mut, put_rate};
use crate::model::pairs::frames::rot;

#[derive(Debug, Clone)]
pub struct Slider {
    pub body: usize,
    /// The pair point on the ground (m), the guide's unit direction, and the same point in the
    /// body's frame.
    pub origin: [f64; 2],
    pub axis: [f64; 2],
    pub s: [f64; 2],
    /// The coordinate moving it and its drawn value, and the body's angle with [cos, sin].
    pub k: usize,
    pub value: f64,
    pub phi: f64,
    pub cs: [f64; 2],
}

impl Slider {
    /// Pose at coordinates z: x and trig of the body.
    #[inline]
    pub fn position(&self, z: &[f64], x: &mut [f64], trig: &mut [[f64; 2]]) {
        let d = z[self.k] - self.value;
        let rs = rot(self.cs, self.s);
        *body_mut(x, self.body) =
            [self.origin[0] + d * self.axis[0] - rs[0], self.origin[1] + d * self.axis[1] - rs[1], self.phi];
        trig[self.body] = self.cs;
    }

    /// The body's rates for the coordinate rates zd: a translation along the guide.
    #[inline]
    pub fn velocity(&self, zd: &[f64], v: &mut [f64]) {
        put_rate(v, self.body, [zd[self.k] * self.axis[0], zd[self.k] * self.axis[1]], [0.0; 2], 0.0);
    }

    /// The body's accelerations for zero coordinate accelerations: none (it does not turn).
    #[inline]
    pub fn acceleration(&self, a: &mut [f64]) {
        *body_mut(a, self.body) = [0.0; 3];
    }
}
