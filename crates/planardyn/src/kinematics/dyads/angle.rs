//! A dyad body's angle from its rotation, on the turn of a reference configuration: the angle
//! within pi of the reference's, found from the rotation between the two. Over the integrator's
//! stages that rotation is small, and its angle comes from a short series instead of atan2.

/// A body's angle in the reference configuration and its [cos, sin].
#[derive(Debug, Clone, Copy)]
pub struct Reference {
    pub phi: f64,
    pub cs: [f64; 2],
}

impl Default for Reference {
    fn default() -> Self {
        Reference { phi: 0.0, cs: [1.0, 0.0] }
    }
}

/// Largest |tan(delta / 2)| taken by the series: |delta| up to 2 atan(1/4) = 0.49 rad.
const SERIES_BOUND: f64 = 0.25;

/// atan(u) / u = sum_k (-1)^k u^2k / (2k + 1) to k = 12, in u^2: the first term left out is
/// u^26 / 27 <= 2^-52 / 27 relative for |u| <= 1/4, under a twentieth of an ulp.
const ATAN_SERIES: [f64; 13] = [
    1.0,
    -1.0 / 3.0,
    1.0 / 5.0,
    -1.0 / 7.0,
    1.0 / 9.0,
    -1.0 / 11.0,
    1.0 / 13.0,
    -1.0 / 15.0,
    1.0 / 17.0,
    -1.0 / 19.0,
    1.0 / 21.0,
    -1.0 / 23.0,
    1.0 / 25.0,
];

/// The unit rotation [cos, sin] taking the direction of `from` to that of `to` (a body's arm in
/// its frame to the same arm in the world).
#[inline]
pub fn rotation(from: [f64; 2], to: [f64; 2]) -> [f64; 2] {
    let (c, s) = (from[0] * to[0] + from[1] * to[1], from[0] * to[1] - from[1] * to[0]);
    let r = (c * c + s * s).sqrt();
    [c / r, s / r]
}

impl Reference {
    pub fn new(phi: f64) -> Self {
        let (s, c) = phi.sin_cos();
        Reference { phi, cs: [c, s] }
    }

    /// The angle of the unit rotation `cs` ([cos, sin]) within pi of the reference's:
    /// phi + delta, delta in (-pi, pi] the rotation from the reference's [cos, sin] to `cs`,
    /// delta = 2 atan(sin(delta) / (1 + cos(delta))).
    #[inline]
    pub fn angle(&self, cs: [f64; 2]) -> f64 {
        let [c0, s0] = self.cs;
        let (c, s) = (cs[0] * c0 + cs[1] * s0, cs[1] * c0 - cs[0] * s0);
        let u = s / (1.0 + c);
        let delta = if u.abs() <= SERIES_BOUND {
            let w = u * u;
            2.0 * u * ATAN_SERIES.iter().rev().fold(0.0, |p, &a| p * w + a)
        } else {
            s.atan2(c)
        };
        self.phi + delta
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Against the angle from atan2 (the reference's phi plus atan2 of the rotation between),
    /// over rotations of either sign up to pi, across the series' bound and from references
    /// on several turns: equal to within 2 ulp of the angle (both round the same rotation).
    #[test]
    fn equals_atan2_over_the_whole_turn() {
        for phi in [0.0, 0.3, -2.5, 7.0, -40.0] {
            let r = Reference::new(phi);
            for k in -1000..=1000 {
                let delta = PI * k as f64 / 1000.0;
                let (s, c) = (phi + delta).sin_cos();
                let got = r.angle([c, s]);
                let [c0, s0] = r.cs;
                let want = phi + (s * c0 - c * s0).atan2(c * c0 + s * s0);
                let ulp = f64::EPSILON * want.abs().max(delta.abs()).max(f64::MIN_POSITIVE);
                assert!((got - want).abs() <= 2.0 * ulp, "phi {phi}, delta {delta}: {got} against {want}");
                assert!((got - phi).abs() <= PI + 8.0 * f64::EPSILON * phi.abs().max(1.0));
            }
        }
    }
}
