//! A relative prismatic input inside a group (a hydraulic cylinder): the decomposition locks
//! the pair's two bodies into one link of the group, whose shape follows the input. The
//! follower slides on the base (the body of the group's outer pair) along the guide by
//! d = q_k - (drawn value), at the drawn relative angle: r_f = r_b + R_b (o + d u),
//! phi_f = phi_b + (drawn phi_f - phi_b), u the guide's direction and o the follower's centre
//! at d = 0, both in the base's frame. A point carried by the follower moves on the base by
//! R_b u d' (a relative velocity) and so gains the Coriolis acceleration 2 w_b E R_b u d'.

use super::rate;
use crate::kinematics::group_sigma::Block;
use crate::model::pairs::frames::{dot, perp, rot};
use crate::model::{BodyId, Link, Mechanism};

#[derive(Debug, Clone)]
pub struct Extension {
    pub base: usize,
    pub follower: usize,
    /// The coordinate and its drawn value.
    k: usize,
    value: f64,
    /// In the base's frame: u and o; the follower's angle less the base's, and its [cos, sin].
    axis: [f64; 2],
    origin: [f64; 2],
    angle: f64,
    cs: [f64; 2],
    /// The pair point in the base's and the follower's frames, and whether the guide is fixed
    /// in the base (the base is the pair's a).
    s_base: [f64; 2],
    s_follower: [f64; 2],
    guide_on_base: bool,
    /// At the last positions: R_b u, r_f - r_b, R_b s_b and R_f s_f.
    dir: [f64; 2],
    rho: [f64; 2],
    rb: [f64; 2],
    rf: [f64; 2],
}

/// A link of a group made of two bodies by a relative input, the group's outer pair on the base
/// and its inner pair on the follower: the extension, and the group's arm on the link (from the
/// outer pair's point to the inner pair's, in the base's frame) at d = 0; it grows by d u.
/// (A follower without the group's inner pair has a block of its own in J, not the group's:
/// such a link takes the general path.)
#[derive(Debug, Clone)]
pub struct Arm {
    pub ext: Extension,
    arm0: [f64; 2],
}

impl Arm {
    /// The arm from `s_outer` on the base to `s_inner` on the follower (each in its body's
    /// frame).
    pub fn new(ext: Extension, s_outer: [f64; 2], s_inner: [f64; 2]) -> Self {
        let p = ext.in_base(s_inner);
        Arm { ext, arm0: [p[0] - s_outer[0], p[1] - s_outer[1]] }
    }

    /// The arm at extension d.
    #[inline]
    pub fn arm(&self, d: f64) -> [f64; 2] {
        [self.arm0[0] + d * self.ext.axis[0], self.arm0[1] + d * self.ext.axis[1]]
    }

    /// The inner pair's velocity relative to the base for d' (world, at the last positions).
    #[inline]
    pub fn slide(&self, rate: f64) -> [f64; 2] {
        [self.ext.dir[0] * rate, self.ext.dir[1] * rate]
    }

    /// R s of the inner pair's point on the follower, from R s on the base (world).
    #[inline]
    pub fn on_follower(&self, p: [f64; 2]) -> [f64; 2] {
        [p[0] - self.ext.rho[0], p[1] - self.ext.rho[1]]
    }
}

impl Extension {
    /// The extension of coordinate k (a prismatic pair) with `base` one of its pair's bodies;
    /// None if the pair is not a prismatic one between `base` and another body.
    pub fn new(mech: &Mechanism, k: usize, base: usize) -> Option<Self> {
        let c = &mech.coordinates[k];
        let p = &mech.pairs[c.pair.0];
        let crate::model::PairKind::Prismatic { axis } = p.kind else { return None };
        // The pair's b point sits at a's point + d u (u = axis in a's frame), b turned by
        // rel_angle0 from a; seen from b, a's point sits at b's - d R(-rel) u.
        let (follower, sign, angle, s_base, s_follower) = match (p.a, p.b) {
            (Link::Body(a), Link::Body(b)) if a.0 == base => (b.0, 1.0, p.rel_angle0, p.sa, p.sb),
            (Link::Body(a), Link::Body(b)) if b.0 == base => (a.0, -1.0, -p.rel_angle0, p.sb, p.sa),
            _ => return None,
        };
        let back = [(-p.rel_angle0).cos(), (-p.rel_angle0).sin()];
        let axis = if sign > 0.0 { axis } else { rot(back, axis).map(|v| -v) };
        let cs = [angle.cos(), angle.sin()];
        let r = rot(cs, s_follower);
        let origin = [s_base[0] - r[0], s_base[1] - r[1]];
        Some(Extension {
            base,
            follower,
            k,
            value: c.value,
            axis,
            origin,
            angle,
            cs,
            s_base,
            s_follower,
            guide_on_base: sign > 0.0,
            dir: [0.0; 2],
            rho: [0.0; 2],
            rb: [0.0; 2],
            rf: [0.0; 2],
        })
    }

    /// d at the coordinates z.
    #[inline]
    pub fn shift(&self, z: &[f64]) -> f64 {
        z[self.k] - self.value
    }

    /// d in the body coordinates x (the follower's centre along u in the base's frame).
    pub fn shift_in(&self, x: &[f64]) -> f64 {
        let (b, f) = (3 * self.base, 3 * self.follower);
        let (s, c) = x[b + 2].sin_cos();
        let rho = rot([c, -s], [x[f] - x[b], x[f + 1] - x[b + 1]]);
        dot(self.axis, [rho[0] - self.origin[0], rho[1] - self.origin[1]])
    }

    /// u in the base's frame.
    pub fn axis(&self) -> [f64; 2] {
        self.axis
    }

    /// A point s of the follower's frame in the base's frame at d = 0.
    pub fn in_base(&self, s: [f64; 2]) -> [f64; 2] {
        let r = rot(self.cs, s);
        [self.origin[0] + r[0], self.origin[1] + r[1]]
    }

    /// The rows of the pair and the coordinate in a group's block at its own length (see
    /// `group_sigma::Block`): turned into the world (which keeps the singular values), the
    /// other body's copy of the pair point less the guide body's, [-I, -E w] on the guide's
    /// body (w from its centre to the other copy) and [I, E R s] on the other; and the angles'
    /// row. `base`, `follower` the bodies' places among the block's.
    pub(crate) fn block_rows(&self, base: usize, follower: usize, block: &mut Block) {
        let (rho, rb, rf) = (self.rho, self.rb, self.rf);
        if self.guide_on_base {
            block.point_rows(&[(base, -1.0, [rho[0] + rf[0], rho[1] + rf[1]]), (follower, 1.0, rf)]);
        } else {
            block.point_rows(&[(follower, -1.0, [rb[0] - rho[0], rb[1] - rho[1]]), (base, 1.0, rb)]);
        }
        block.angle_row(base, follower);
    }

    /// The follower's pose (x and trig) at z, the base's placed.
    #[inline]
    pub fn place(&mut self, z: &[f64], x: &mut [f64], trig: &mut [[f64; 2]]) {
        let (b, f) = (3 * self.base, 3 * self.follower);
        let cb = trig[self.base];
        let d = self.shift(z);
        self.dir = rot(cb, self.axis);
        self.rho = rot(cb, [self.origin[0] + d * self.axis[0], self.origin[1] + d * self.axis[1]]);
        x[f] = x[b] + self.rho[0];
        x[f + 1] = x[b + 1] + self.rho[1];
        x[f + 2] = x[b + 2] + self.angle;
        trig[self.follower] = rot(cb, self.cs);
        (self.rb, self.rf) = (rot(cb, self.s_base), rot(trig[self.follower], self.s_follower));
    }

    /// q_k' in the coordinate rates zd.
    #[inline]
    pub fn input_rate(&self, zd: &[f64]) -> f64 {
        zd[self.k]
    }

    /// d' for the rates v (the follower's velocity relative to the base, along R_b u).
    #[inline]
    pub fn rate(&self, v: &[f64]) -> f64 {
        let (vb, w) = rate(Link::Body(BodyId(self.base)), v);
        let (vf, _) = rate(Link::Body(BodyId(self.follower)), v);
        let e = perp(self.rho);
        dot([vf[0] - vb[0] - w * e[0], vf[1] - vb[1] - w * e[1]], self.dir)
    }

    /// The follower's rates for the base's in v and the coordinate rates zd.
    #[inline]
    pub fn velocity(&self, zd: &[f64], v: &mut [f64]) {
        let (vb, w) = rate(Link::Body(BodyId(self.base)), v);
        let (e, s) = (perp(self.rho), zd[self.k]);
        let f = 3 * self.follower;
        v[f] = vb[0] + w * e[0] + s * self.dir[0];
        v[f + 1] = vb[1] + w * e[1] + s * self.dir[1];
        v[f + 2] = w;
    }

    /// The follower's accelerations at zero coordinate accelerations, from the rates v and the
    /// base's accelerations in a.
    #[inline]
    pub fn acceleration(&self, v: &[f64], a: &mut [f64]) {
        let (_, w) = rate(Link::Body(BodyId(self.base)), v);
        let (ab, al) = rate(Link::Body(BodyId(self.base)), a);
        let (e, c) = (perp(self.rho), 2.0 * w * self.rate(v));
        let n = perp(self.dir);
        let f = 3 * self.follower;
        a[f] = ab[0] + al * e[0] - w * w * self.rho[0] + c * n[0];
        a[f + 1] = ab[1] + al * e[1] - w * w * self.rho[1] + c * n[1];
        a[f + 2] = al;
    }
}
