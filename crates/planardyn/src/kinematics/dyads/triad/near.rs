//! sin, cos and atan of the small turns a triad's bodies make from its reference configuration
//! (the last accepted point) by their series, in place of the library's calls at every
//! evaluation: the platform's rotation in each Newton iteration, each leg's angle, and the
//! fold guard's side test. Within [`EXACT_TURN`] and [`EXACT_TAN`] they are the library's to
//! a few units in the last place; the callers take the library's beyond.
//!
//! Hand-written because only the polynomials are wanted: the libraries' full functions reduce
//! any argument first (glibc's sincos and atan2 cost 110-130 instructions a call here, most of
//! it the reduction and its checks), and a turn from the reference needs none.

/// Largest turn (rad) from the reference whose [`near_sin_cos`] is the library's sin and cos to
/// rounding: its first left-out terms are 0.25^13 / 13! = 2.4e-18 (sin) and 0.25^14 / 14! =
/// 4.3e-20 (cos), below a tenth of an ulp of sin d near 0.25 (5.6e-17 / 2).
pub(in crate::kinematics::dyads) const EXACT_TURN: f64 = 0.25;

/// Largest |tan| of a turn taken by [`near_atan`]: 7/16, the end of fdlibm's first interval
/// of atan (where its kernel needs no reduction; error below one ulp there, fdlibm's
/// s_atan.c), a turn of 0.41 rad.
pub(super) const EXACT_TAN: f64 = 0.4375;

/// sin d and cos d by their Taylor series to d^11 and d^12, for |d| <= 0.5 (within 2e-14 of
/// the library's there, the first left-out terms 0.5^13 / 13! and 0.5^14 / 14!; to rounding
/// for |d| <= [`EXACT_TURN`]).
#[inline(always)]
pub(super) fn near_sin_cos(d: f64) -> (f64, f64) {
    let d2 = d * d;
    let k = |n: f64| d2 * (1.0 / n);
    let s = d * (1.0 - k(6.0) * (1.0 - k(20.0) * (1.0 - k(42.0) * (1.0 - k(72.0) * (1.0 - k(110.0))))));
    let c = 1.0 - k(2.0) * (1.0 - k(12.0) * (1.0 - k(30.0) * (1.0 - k(56.0) * (1.0 - k(90.0) * (1.0 - k(132.0))))));
    (s, c)
}

/// The rotation r ([cos, sin] of an angle) turned by d, as [cos, sin], d's sin and cos by
/// [`near_sin_cos`].
#[inline(always)]
pub(in crate::kinematics::dyads) fn turned(r: [f64; 2], d: f64) -> [f64; 2] {
    let (s, c) = near_sin_cos(d);
    [r[0] * c - r[1] * s, r[1] * c + r[0] * s]
}

/// fdlibm's coefficients of atan t = t - t (t^2 aT0 - t^4 aT1 + ...) on |t| < 7/16
/// (s_atan.c, Sun Microsystems 1993; the same in musl and Rust's libm), its 21-digit decimals
/// written as the shortest that name the same doubles.
const AT: [f64; 11] = [
    0.3333333333333293,
    -0.19999999999876483,
    0.14285714272503466,
    -0.11111110405462356,
    0.09090887133436507,
    -0.0769187620504483,
    0.06661073137387531,
    -0.058335701337905735,
    0.049768779946159324,
    -0.036531572744216916,
    0.016285820115365782,
];

/// 2^-27: below it t^3 / 3 is under half an ulp of t.
const TINY_TAN: f64 = 7.450580596923828e-9;

/// atan2(y, x): for x > 0 and |y| < [`EXACT_TAN`] x, atan(y / x) by fdlibm's kernel (its odd
/// and even halves as s_atan.c sums them), else the library's.
#[inline(always)]
pub(in crate::kinematics::dyads) fn near_atan2(y: f64, x: f64) -> f64 {
    if !(x > 0.0 && y.abs() < EXACT_TAN * x) {
        return y.atan2(x);
    }
    let t = y / x;
    // As s_atan.c: below 2^-27, atan t rounds to t (and a zero keeps its sign).
    if t.abs() < TINY_TAN {
        return t;
    }
    let z = t * t;
    let w = z * z;
    let s1 = z * (AT[0] + w * (AT[2] + w * (AT[4] + w * (AT[6] + w * (AT[8] + w * AT[10])))));
    let s2 = w * (AT[1] + w * (AT[3] + w * (AT[5] + w * (AT[7] + w * AT[9]))));
    t - t * (s1 + s2)
}

#[cfg(test)]
mod tests {
    use super::{near_atan2, near_sin_cos, turned, EXACT_TAN, EXACT_TURN};

    /// The series are within 2e-14 of the library's sin and cos over |d| <= 0.5 (the bound
    /// the side test's margin takes: the first left-out term, 0.5^13 / 13! = 2.0e-14), and
    /// within 2 ulp (of 1, 2.2e-16 each) over |d| <= EXACT_TURN.
    #[test]
    fn near_sin_cos_is_within_its_bounds() {
        for k in -5000..=5000 {
            let d = k as f64 * 0.5 / 5000.0;
            let (s, c) = near_sin_cos(d);
            let bound = if d.abs() <= EXACT_TURN { 2.0 * f64::EPSILON } else { 2e-14 };
            assert!((s - d.sin()).abs() <= bound && (c - d.cos()).abs() <= bound, "d = {d}");
        }
    }

    /// A reference rotation turned by the series is the library's rotation of the sum within
    /// 4 ulp of 1 (8.9e-16: the series' 2 and the product's rounding), at references up to
    /// 1000 rad and turns up to EXACT_TURN.
    #[test]
    fn turned_is_the_library_rotation_to_rounding() {
        for k in 0..20000 {
            let reference = (k as f64 * 0.7548776662466927).sin() * 1000.0 * if k % 3 == 0 { 1e-3 } else { 1.0 };
            let d = EXACT_TURN * (k as f64 * 0.5698402909980532).sin();
            let (s, c) = reference.sin_cos();
            let r = turned([c, s], d);
            let (s2, c2) = (reference + d).sin_cos();
            // reference + d is rounded (half an ulp of up to 1000, 5.7e-14): compare with the
            // angle the float sum names, which is what a body's x holds.
            let tol = 4.0 * f64::EPSILON + 0.5 * (reference + d).abs() * f64::EPSILON;
            assert!((r[0] - c2).abs() <= tol && (r[1] - s2).abs() <= tol, "reference {reference}, d {d}");
        }
    }

    /// fdlibm's kernel is the library's atan2 within 2 ulp of the turn over |tan| < EXACT_TAN
    /// (its error below 1 ulp, the division's half), and the library's itself beyond; the
    /// signs of zero and tiny turns are kept.
    #[test]
    fn near_atan2_is_the_library_atan2_to_rounding() {
        for k in -20000..=20000 {
            let angle = k as f64 * 1.2 / 20000.0;
            for length in [1e-3, 0.37, 1.0, 250.0] {
                let (y, x) = (length * angle.sin(), length * angle.cos());
                let (a, b) = (near_atan2(y, x), y.atan2(x));
                assert!((a - b).abs() <= 2.0 * f64::EPSILON * b.abs(), "angle {angle}, length {length}: {a} vs {b}");
                if y.abs() >= EXACT_TAN * x {
                    assert_eq!(a.to_bits(), b.to_bits());
                }
            }
        }
        for y in [0.0, -0.0, 1e-300, -1e-300, 1e-20] {
            assert_eq!(near_atan2(y, 1.0).to_bits(), y.atan2(1.0).to_bits(), "y = {y:e}");
        }
    }
}
