//! A body's angle and its [cos, sin] about those of a reference configuration: a dyad body's
//! angle from its rotation, on the reference's turn (within pi of its angle), and an input
//! link's [cos, sin] from its angle, each through the rotation between the two. Over the
//! integrator's stages that rotation is small, and short series replace atan2 and sin_cos.

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

/// Largest |delta| taken by the sine and cosine series (rad).
const TURN_BOUND: f64 = 0.5;

/// sin(d) / d = sum_k (-1)^k d^2k / (2k + 1)! to k = 6, and cos(d) to d^14, in d^2: the first
/// terms left out are d^14 / 15! <= 5e-17 and d^16 / 16! <= 1e-18 relative for |d| <= 1/2.
const SIN_SERIES: [f64; 7] =
    [1.0, -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0, -1.0 / 39_916_800.0, 1.0 / 6_227_020_800.0];
const COS_SERIES: [f64; 8] = [
    1.0,
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
];

/// sum_k a_k w^k by Horner's rule.
#[inline]
fn horner(a: &[f64], w: f64) -> f64 {
    a.iter().rev().fold(0.0, |p, &a| p * w + a)
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
        let delta = if u.abs() <= SERIES_BOUND { 2.0 * u * horner(&ATAN_SERIES, u * u) } else { s.atan2(c) };
        self.phi + delta
    }

    /// [cos, sin] of the angle `phi`: near the reference's angle, its [cos, sin] turned by
    /// delta = phi - (its angle).
    #[inline]
    pub fn cos_sin(&self, phi: f64) -> [f64; 2] {
        let delta = phi - self.phi;
        if delta.abs() > TURN_BOUND {
            let (s, c) = phi.sin_cos();
            return [c, s];
        }
        let w = delta * delta;
        let (s, c) = (delta * horner(&SIN_SERIES, w), horner(&COS_SERIES, w));
        let [c0, s0] = self.cs;
        [c0 * c - s0 * s, s0 * c + c0 * s]
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

    /// Against sin_cos over angles up to pi from the reference, across the series' bound: equal
    /// to within 3e-16 (the rotation of the reference's [cos, sin] adds a few roundings).
    #[test]
    fn cos_sin_equal_sin_cos_over_the_whole_turn() {
        for phi0 in [0.0, 0.3, -2.5, 7.0, -40.0] {
            let r = Reference::new(phi0);
            for k in -1000..=1000 {
                let phi = phi0 + PI * k as f64 / 1000.0;
                let (s, c) = phi.sin_cos();
                let [gc, gs] = r.cos_sin(phi);
                assert!((gc - c).abs().max((gs - s).abs()) <= 3e-16, "phi {phi}: [{gc}, {gs}] against [{c}, {s}]");
            }
        }
    }
}
