//! An input link: a body turned about a ground point by its revolute input pair. With
//! q_k = phi_b - phi_a - (drawn relative angle) + (drawn value), the body's angle is
//! sign (q_k + offset), sign +1 when the body is the pair's b.

use super::triad::near::{turned, EXACT_TURN};
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
    /// The body's angle in the reference configuration (the last accepted point; NaN before
    /// one) and its [cos, sin].
    pub reference: (f64, [f64; 2]),
}

impl Crank {
    /// Take the reference angle from the configuration x.
    pub fn set_reference(&mut self, x: &[f64]) {
        let phi = body(x, self.body)[2];
        let (sn, cs) = phi.sin_cos();
        self.reference = (phi, [cs, sn]);
    }

    /// Take the reference of `from`, the same crank in another copy of the closed forms.
    pub fn copy_reference(&mut self, from: &Crank) {
        self.reference = from.reference;
    }

    /// Pose at coordinates z: x and trig of the body. Its [cos, sin] is the reference's turned
    /// by the turn from it where that is within [`EXACT_TURN`] (the series, to rounding: the
    /// library's sin_cos costs about 120 instructions, most of it its argument's reduction),
    /// the library's beyond. Inlined into `ClosedForm::place` (see there).
    #[inline(always)]
    pub fn position(&mut self, z: &[f64], x: &mut [f64], trig: &mut [[f64; 2]]) {
        let phi = self.sign * (z[self.k] + self.offset);
        let turn = phi - self.reference.0;
        let cs = if turn.abs() <= EXACT_TURN {
            turned(self.reference.1, turn)
        } else {
            let (sn, cs) = phi.sin_cos();
            [cs, sn]
        };
        let rs = rot(cs, self.s);
        *body_mut(x, self.body) = [self.pivot[0] - rs[0], self.pivot[1] - rs[1], phi];
        trig[self.body] = cs;
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

#[cfg(test)]
mod tests {
    use super::Crank;

    /// The crank's [cos, sin] from its reference turned by the series is the library's sin_cos
    /// of its angle within 4 ulp of 1 (the series' 2 and the turned products', as
    /// `near::tests::turned_is_the_library_rotation_to_rounding`) plus half an ulp of the angle
    /// (the turn phi - reference is rounded), at references up to 100 rad and turns across
    /// EXACT_TURN's edge (the library's beyond, to the bit), and before any reference (the
    /// library's).
    #[test]
    fn position_is_the_library_rotation_to_rounding() {
        let mut c = Crank {
            body: 0,
            pivot: [0.3, -0.2],
            s: [0.5, 0.1],
            k: 0,
            sign: 1.0,
            offset: 0.0,
            rs: [0.0; 2],
            reference: (f64::NAN, [0.0; 2]),
        };
        let (mut x, mut trig) = ([0.0; 3], [[0.0; 2]]);
        let mut near = 0;
        for k in 0..20000 {
            let reference = 100.0 * (k as f64 * 0.7548776662466927).sin();
            if k > 0 {
                c.set_reference(&[0.0, 0.0, reference]);
            }
            let phi = reference + 0.3 * (k as f64 * 0.5698402909980532).sin();
            c.position(&[phi], &mut x, &mut trig);
            let (s, cs) = phi.sin_cos();
            if k == 0 || (phi - reference).abs() > super::EXACT_TURN {
                assert_eq!(trig[0].map(f64::to_bits), [cs, s].map(f64::to_bits), "phi {phi}");
            } else {
                near += 1;
                let tol = 4.0 * f64::EPSILON + 0.5 * phi.abs() * f64::EPSILON;
                assert!((trig[0][0] - cs).abs() <= tol && (trig[0][1] - s).abs() <= tol, "phi {phi}");
            }
            assert_eq!(x[2], phi);
        }
        assert!(near > 10000, "{near} turns within EXACT_TURN");
    }
}
