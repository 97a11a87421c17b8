//! Closed forms of the groups the Assur decomposition finds (`kinematics::closed_form`), one
//! file a kind: the input link turned by its revolute pair ([`crank`]) or moved along a guide
//! on the ground ([`slider`]), the class I groups of one body with a gear or slot pair
//! ([`one_link`]: 1R1G, 1P1G, 1P1S), the class II dyads of three revolute pairs ([`rrr`]), of
//! two revolute pairs and an outer prismatic one ([`rrp`]) or an inner one ([`rpr`]), and of
//! two outer prismatic pairs and an inner revolute one ([`prp`]), the class III triad of six
//! revolute pairs ([`triad`], Newton on its 3 x 3 platform system), and a group link of two
//! bodies a relative prismatic input locks ([`extension`]; in an RRR dyad, [`extended_rrr`]).
//! The class I groups, PRP and RPR share their rows' Jacobian and gamma on a local copy of the
//! links they touch ([`local`]). Each gives positions, velocities (a column of U for a unit rate) and accelerations with zero
//! input accelerations (the convective term c), from the links solved before it, in the order
//! of the decomposition.

pub mod crank;
pub mod extended_rrr;
pub mod extension;
pub mod local;
pub mod one_link;
pub mod prp;
pub mod relative_crank;
pub mod rpr;
pub mod rrp;
pub mod rrr;
pub mod slider;
pub mod triad;

use crate::model::pairs::frames::rot;
use crate::model::Link;
use std::f64::consts::TAU;
use triad::near::near_atan2;

/// A body's angle in the reference configuration (the last accepted point), as whole turns,
/// a remainder in (-pi, pi] and the remainder's [cos, sin]: a new angle is taken within pi of
/// it, as its turn from the reference.
#[derive(Debug, Clone, Copy, Default)]
pub struct Angle {
    turns: f64,
    rest: f64,
    rest_cs: [f64; 2],
}

impl Angle {
    /// The reference angle phi.
    pub fn of(phi: f64) -> Self {
        let turns = TAU * (phi / TAU).round();
        let rest = phi - turns;
        let (s, c) = rest.sin_cos();
        Angle { turns, rest, rest_cs: [c, s] }
    }

    /// The rotation whose cosine and sine are proportional to (c, s), as [cos, sin], and its
    /// angle, the one within pi of the reference: the reference's whole turns + rest + the turn
    /// from the reference, the angle of (c, s) turned back by rest (in [-pi, pi]). The turns a
    /// body makes between evaluations are small, so the turn's atan2 is mostly the kernel
    /// alone ([`near_atan2`]: no reduction), where the angle of (c, s) less rest would need the
    /// library's full atan2 (12 % of the four-bar's evaluation, 18 % of Andrews').
    #[inline(always)]
    pub(crate) fn rotation(&self, c: f64, s: f64) -> ([f64; 2], f64) {
        let r = (c * c + s * s).sqrt();
        let [rc, rs] = self.rest_cs;
        let turn = near_atan2(s * rc - c * rs, c * rc + s * rs);
        ([c / r, s / r], self.turns + self.rest + turn)
    }
}

/// `t.round()` (the nearest whole number, halves away from zero; the same bits, the sign of a
/// zero too) without the library call that x86-64's baseline makes of it (no `roundsd`
/// before SSE4.1): the fold guards take it at every evaluation. The cast truncates exactly
/// below 2^52 (every f64 beyond is whole), and t less its whole part is exact.
#[inline(always)]
pub(crate) fn round(t: f64) -> f64 {
    if !(t.abs() < WHOLE_FROM) {
        return t;
    }
    let whole = (t as i64 as f64).copysign(t);
    if (t - whole).abs() >= 0.5 {
        whole + 1f64.copysign(t)
    } else {
        whole
    }
}

/// 2^52: from here on every f64 is a whole number.
const WHOLE_FROM: f64 = 4503599627370496.0;

/// A point fixed in a link: the link and the point in its frame (m).
#[derive(Debug, Clone, Copy)]
pub struct Joint {
    pub link: Link,
    pub s: [f64; 2],
}

/// Body b's three entries (centre x, y and angle, or their rates) of a vector of 3 per body:
/// one bounds check, where a slice 3b..3b + 3 costs about six instructions an access.
#[inline(always)]
pub(crate) fn body(v: &[f64], b: usize) -> &[f64; 3] {
    &v.as_chunks::<3>().0[b]
}

/// [`body`], to write.
#[inline(always)]
pub(crate) fn body_mut(v: &mut [f64], b: usize) -> &mut [f64; 3] {
    &mut v.as_chunks_mut::<3>().0[b]
}

/// A vector of 3 per body as whole body rows flattened again (the same entries): the pieces'
/// [`body`] of it then needs no division of its length by 3 an access (it folds with the
/// multiplication), a loop's worth of them for a pass over the pieces.
#[inline(always)]
pub(crate) fn rows(v: &[f64]) -> &[f64] {
    v.as_chunks::<3>().0.as_flattened()
}

/// [`rows`], to write.
#[inline(always)]
pub(crate) fn rows_mut(v: &mut [f64]) -> &mut [f64] {
    v.as_chunks_mut::<3>().0.as_flattened_mut()
}

/// Pose (centre, [cos, sin]) of a link in x and trig; the ground's is the identity.
#[inline(always)]
pub(crate) fn pose(link: Link, x: &[f64], trig: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    match link {
        Link::Ground => ([0.0; 2], [1.0, 0.0]),
        Link::Body(b) => {
            let r = body(x, b.0);
            ([r[0], r[1]], trig[b.0])
        }
    }
}

/// (linear, angular) part of a rate vector for a link (zeros for the ground).
#[inline(always)]
pub(crate) fn rate(link: Link, v: &[f64]) -> ([f64; 2], f64) {
    match link {
        Link::Ground => ([0.0; 2], 0.0),
        Link::Body(b) => {
            let r = body(v, b.0);
            ([r[0], r[1]], r[2])
        }
    }
}

impl Joint {
    /// World position of the point, and R(phi) s.
    #[inline(always)]
    pub(crate) fn place(&self, x: &[f64], trig: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
        let (r, cs) = pose(self.link, x, trig);
        let p = rot(cs, self.s);
        ([r[0] + p[0], r[1] + p[1]], p)
    }

    /// Velocity of the point for rates v, given R s (`place`): r' + w E R s.
    #[inline(always)]
    pub(crate) fn velocity(&self, rs: [f64; 2], v: &[f64]) -> [f64; 2] {
        let (rd, w) = rate(self.link, v);
        [rd[0] - w * rs[1], rd[1] + w * rs[0]]
    }

    /// Acceleration of the point for rates v and accelerations a, given R s:
    /// r'' + al E R s - w^2 R s.
    #[inline(always)]
    pub(crate) fn acceleration(&self, rs: [f64; 2], v: &[f64], a: &[f64]) -> [f64; 2] {
        let (_, w) = rate(self.link, v);
        let (rdd, al) = rate(self.link, a);
        [rdd[0] - al * rs[1] - w * w * rs[0], rdd[1] + al * rs[0] - w * w * rs[1]]
    }
}

/// Write a body's rates (centre velocity r' = v_p - w E R s from a point p = r + R s of
/// velocity v_p, and w) into v.
#[inline(always)]
pub(crate) fn put_rate(v: &mut [f64], b: usize, vp: [f64; 2], rs: [f64; 2], w: f64) {
    *body_mut(v, b) = [vp[0] + w * rs[1], vp[1] - w * rs[0], w];
}

/// Write a body's accelerations (r'' = a_p - al E R s + w^2 R s from a point p = r + R s of
/// acceleration a_p, and al) into a.
#[inline(always)]
pub(crate) fn put_acceleration(a: &mut [f64], b: usize, ap: [f64; 2], rs: [f64; 2], w: f64, al: f64) {
    *body_mut(a, b) = [ap[0] + al * rs[1] + w * w * rs[0], ap[1] - al * rs[0] + w * w * rs[1], al];
}

/// Where one pass over the pieces (`ClosedForm::stages_from`) writes, at the positions just
/// solved: U's M columns (n rows each), the rates xd = U zd and the convective term c. Each
/// piece, in the decomposition's order, writes its bodies' rows of every column of U, then
/// their rates, then their accelerations ([`Pass::piece`]): what it reads of the pieces before
/// it is written by then, so one pass per piece replaces a pass over the pieces per column,
/// one for xd and one for c, with the same operations on the same numbers. The vectors are
/// held as body rows ([`Pass::new`]): the pieces' [`body`] of the flat vectors handed to them
/// then needs no division of their length by 3 an access (it folds with the multiplication).
pub(crate) struct Pass<'a, const M: usize> {
    zd: [f64; M],
    /// The bodies, U's columns (`bodies` rows each), xd and c.
    bodies: usize,
    u: &'a mut [[f64; 3]],
    xd: &'a mut [[f64; 3]],
    c: &'a mut [[f64; 3]],
}

impl<'a, const M: usize> Pass<'a, M> {
    /// U's first M columns (3 per body of xd each), xd and c for the rates zd.
    #[inline(always)]
    pub fn new(zd: [f64; M], u: &'a mut [f64], xd: &'a mut [f64], c: &'a mut [f64]) -> Self {
        let bodies = xd.len() / 3;
        // U's columns and c as long as xd's rows: a body's check on one then holds for all.
        let u = &mut u.as_chunks_mut().0[..M * bodies];
        Pass { zd, bodies, u, xd: xd.as_chunks_mut().0, c: &mut c.as_chunks_mut().0[..bodies] }
    }

    /// A piece of `bodies` by its rates for coordinate rates zd (`velocity(zd, v)`, the links
    /// before it in v) and its accelerations for rates v (`acceleration(v, a)`): its rows of
    /// U's column j by `velocity` at the unit rates e_j, of xd from them, of c from xd.
    #[inline(always)]
    pub fn piece(
        &mut self,
        bodies: &[usize],
        velocity: impl Fn(&[f64], &mut [f64]),
        acceleration: impl Fn(&[f64], &mut [f64]),
    ) {
        let n = self.bodies;
        for j in 0..M {
            let unit: [f64; M] = std::array::from_fn(|i| if i == j { 1.0 } else { 0.0 });
            velocity(&unit, self.u[j * n..(j + 1) * n].as_flattened_mut());
        }
        for &b in bodies {
            self.rates(b);
        }
        acceleration(self.xd.as_flattened(), self.c.as_flattened_mut());
    }

    /// Body b's rates xd = U zd, each 0 + u_0 zd_0 + u_1 zd_1 + ... in that order (as
    /// `analogues::u_times_from` sums them).
    #[inline(always)]
    fn rates(&mut self, b: usize) {
        let mut s = [0.0; 3];
        for (j, zd) in self.zd.iter().enumerate() {
            let u = self.u[j * self.bodies + b];
            s = [s[0] + u[0] * zd, s[1] + u[1] * zd, s[2] + u[2] * zd];
        }
        self.xd[b] = s;
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    /// [`super::Angle::rotation`] is the angle the library's atan2 gives (the angle of (c, s)
    /// less the reference's remainder, taken in [-pi, pi], plus the reference's turns and
    /// remainder) to rounding: within 2 ulp of the turn (the kernel's 1 and the turned-back
    /// products') and half an ulp of the angle's sum, at references up to 100 rad either side
    /// and turns across the whole circle (the kernel's and the library's parts), and its
    /// [cos, sin] is the direction of (c, s) to the bit.
    #[test]
    fn rotation_is_the_library_angle_to_rounding() {
        for k in 0..40000 {
            let reference = 100.0 * (k as f64 * 0.7548776662466927).sin();
            let turn = PI * (k as f64 * 0.5698402909980532).sin() * if k % 2 == 0 { 0.1 } else { 1.0 };
            let angle = super::Angle::of(reference);
            let r = 0.01 + (k % 7) as f64;
            let (s, c) = (reference + turn).sin_cos();
            let (c, s) = (r * c, r * s);
            let (cs, phi) = angle.rotation(c, s);
            let turns = super::TAU * (reference / super::TAU).round();
            let rest = reference - turns;
            let mut library = s.atan2(c) - rest;
            if library > PI {
                library -= super::TAU;
            } else if library < -PI {
                library += super::TAU;
            }
            let old = turns + rest + library;
            let tol =
                2.0 * f64::EPSILON * library.abs() + 4.0 * f64::EPSILON * rest.abs() + 0.5 * old.abs() * f64::EPSILON;
            assert!((phi - old).abs() <= tol, "reference {reference}, turn {turn}: {phi} vs {old}");
            let h = (c * c + s * s).sqrt();
            assert_eq!(cs.map(f64::to_bits), [c / h, s / h].map(f64::to_bits));
        }
    }

    /// [`super::round`] is `f64::round` to the bit: halves either side of zero, the largest
    /// double below a half, signed zeros, the edges of 2^52, infinities and NaN.
    #[test]
    fn round_is_the_library_round() {
        let half_below = 0.49999999999999994;
        let mut cases = vec![0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, half_below, -half_below, 0.3, -0.3, 0.7, -0.7];
        cases.extend([4503599627370495.5, -4503599627370495.5, 4503599627370496.0, 9.3e18, -9.3e18, 1e300]);
        cases.extend([f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE, -f64::MIN_POSITIVE]);
        cases.extend((-2000..2000).map(|k| k as f64 * 0.0123 / std::f64::consts::TAU));
        for t in cases {
            assert_eq!(super::round(t).to_bits(), t.round().to_bits(), "t = {t:e}");
        }
        assert!(super::round(f64::NAN).is_nan());
    }
}
