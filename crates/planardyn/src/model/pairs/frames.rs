//! The plane geometry every pair kind is written with: link poses, R(phi) s, E v, the
//! projection row, and how a link's gradient goes into a row of J.

use crate::linalg::Sink;
use crate::model::{Link, Pair};

/// Pose of a link in x: centre (m), [cos, sin] of its angle, and its first column in x
/// (None for ground).
#[derive(Clone, Copy)]
pub struct LinkState {
    pub r: [f64; 2],
    pub cs: [f64; 2],
    pub col: Option<usize>,
}

impl LinkState {
    /// R(phi) s.
    #[inline]
    pub fn rot(&self, s: [f64; 2]) -> [f64; 2] {
        rot(self.cs, s)
    }
    /// World position r + R(phi) s of a point s of the link.
    #[inline]
    pub fn point(&self, s: [f64; 2]) -> [f64; 2] {
        let p = self.rot(s);
        [self.r[0] + p[0], self.r[1] + p[1]]
    }
}

#[inline]
pub fn rot(cs: [f64; 2], s: [f64; 2]) -> [f64; 2] {
    [cs[0] * s[0] - cs[1] * s[1], cs[1] * s[0] + cs[0] * s[1]]
}

/// Link pose with the angle's cos/sin taken from `trig` (see `constraints::body_trig`).
#[inline]
pub fn link_state_t(link: Link, x: &[f64], trig: &[[f64; 2]]) -> LinkState {
    match link {
        Link::Ground => LinkState { r: [0.0; 2], cs: [1.0, 0.0], col: None },
        Link::Body(b) => {
            let c = 3 * b.0;
            LinkState { r: [x[c], x[c + 1]], cs: trig[b.0], col: Some(c) }
        }
    }
}

/// Link pose computing the angle's cos/sin (for the occasional single evaluation).
pub fn link_state(link: Link, x: &[f64]) -> LinkState {
    match link {
        Link::Ground => LinkState { r: [0.0; 2], cs: [1.0, 0.0], col: None },
        Link::Body(b) => {
            let c = 3 * b.0;
            let (s, co) = x[c + 2].sin_cos();
            LinkState { r: [x[c], x[c + 1]], cs: [co, s], col: Some(c) }
        }
    }
}

/// World position of a point of a link.
pub fn world_point(link: Link, s: [f64; 2], x: &[f64]) -> [f64; 2] {
    link_state(link, x).point(s)
}

/// Velocity of a point of a link for body rates xd.
pub fn point_velocity(link: Link, s: [f64; 2], x: &[f64], xd: &[f64]) -> [f64; 2] {
    let l = link_state(link, x);
    let (v, w) = part(&l, xd);
    let t = perp(l.rot(s));
    [v[0] + w * t[0], v[1] + w * t[1]]
}

/// Acceleration of a point of a link for body rates xd and accelerations xdd.
pub fn point_acceleration(link: Link, s: [f64; 2], x: &[f64], xd: &[f64], xdd: &[f64]) -> [f64; 2] {
    let l = link_state(link, x);
    let (_, w) = part(&l, xd);
    let (a, al) = part(&l, xdd);
    let p = l.rot(s);
    let t = perp(p);
    [a[0] + al * t[0] - w * w * p[0], a[1] + al * t[1] - w * w * p[1]]
}

/// R(phi) s.
#[inline]
pub fn rotate(phi: f64, s: [f64; 2]) -> [f64; 2] {
    let (sn, cs) = phi.sin_cos();
    rot([cs, sn], s)
}

/// E v: v turned by +90 degrees.
#[inline]
pub fn perp(v: [f64; 2]) -> [f64; 2] {
    [-v[1], v[0]]
}

#[inline]
pub fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

#[inline]
pub fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// The angle of a link (0 for ground).
#[inline]
pub fn angle(link: Link, x: &[f64]) -> f64 {
    match link {
        Link::Ground => 0.0,
        Link::Body(b) => x[3 * b.0 + 2],
    }
}

/// Components (dr_x, dr_y, dphi) of a direction vector for a link (zeros for ground).
#[inline]
pub fn part(link: &LinkState, v: &[f64]) -> ([f64; 2], f64) {
    match link.col {
        Some(c) => ([v[c], v[c + 1]], v[c + 2]),
        None => ([0.0; 2], 0.0),
    }
}

/// Add `g = [d/dr_x, d/dr_y, d/dphi]` of a link to row `row` of `j`; a zero entry is left
/// out (the patterns of `jacobian_pattern` need not include it).
#[inline]
pub fn add_grad<S: Sink>(j: &mut S, row: usize, link: &LinkState, g: [f64; 3]) {
    if let Some(c) = link.col {
        for (k, v) in g.into_iter().enumerate() {
            if v != 0.0 {
                j.add(row, c + k, v);
            }
        }
    }
}

/// The columns of a link in x (none for ground): all three, or its angle only.
pub fn link_columns(link: Link, angle_only: bool) -> std::ops::Range<usize> {
    match link {
        Link::Ground => 0..0,
        Link::Body(b) if angle_only => 3 * b.0 + 2..3 * b.0 + 3,
        Link::Body(b) => 3 * b.0..3 * b.0 + 3,
    }
}

/// A projection row g = (R_a d0) . (p_b - p_a) with d0 a unit vector fixed in link a, p_a
/// and p_b points of a and b: the normal row of a prismatic or slot pair (d0 = normal),
/// their displacement (d0 = axis), a rack's travel.
pub struct Projection {
    pub a: LinkState,
    pub b: LinkState,
    /// d = R_a d0 (global).
    pub d: [f64; 2],
    /// w = r_b + R_b s_b - r_a.
    pub w: [f64; 2],
    /// R_b s_b.
    pub rbsb: [f64; 2],
    /// d0 . s_a, so that g = d . w - offset.
    pub offset: f64,
}

impl Projection {
    /// The offset of b's copy of the pair point from the line through a's copy along
    /// `axis` (fixed in a): the normal row of a prismatic or a slot pair.
    #[inline]
    pub fn normal(pair: &Pair, axis: [f64; 2], x: &[f64], trig: &[[f64; 2]]) -> Self {
        let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
        Projection::new(pair.sa, pair.sb, perp(axis), a, b)
    }
    #[inline]
    pub fn new(sa: [f64; 2], sb: [f64; 2], d0: [f64; 2], a: LinkState, b: LinkState) -> Self {
        let rbsb = b.rot(sb);
        let w = [b.r[0] + rbsb[0] - a.r[0], b.r[1] + rbsb[1] - a.r[1]];
        Projection { a, b, d: a.rot(d0), w, rbsb, offset: dot(d0, sa) }
    }
    #[inline]
    pub fn value(&self) -> f64 {
        dot(self.d, self.w) - self.offset
    }
    /// The gradient times `sign`, added into row `row` of `j`.
    #[inline]
    pub fn grad<S: Sink>(&self, j: &mut S, row: usize, sign: f64) {
        let ed = perp(self.d);
        let (d, g) = ([sign * self.d[0], sign * self.d[1]], sign * dot(ed, self.w));
        add_grad(j, row, &self.a, [-d[0], -d[1], g]);
        add_grad(j, row, &self.b, [d[0], d[1], dot(d, perp(self.rbsb))]);
    }
    /// The gradient times a direction v (the rate of g for v = xd).
    pub fn rate(&self, v: &[f64]) -> f64 {
        let (ra, pa) = part(&self.a, v);
        let (rb, pb) = part(&self.b, v);
        dot(self.d, sub(rb, ra)) + dot(perp(self.d), self.w) * pa + dot(self.d, perp(self.rbsb)) * pb
    }
    /// Bilinear second derivative (see `constraints`), from the Hessian entries
    /// d2/dphi_a2 = -d.w, d2/dphi_a dr_b = E d = -d2/dphi_a dr_a,
    /// d2/dphi_a dphi_b = d.R_b s_b = -d2/dphi_b2.
    #[inline]
    pub fn gamma(&self, u: &[f64], v: &[f64]) -> f64 {
        let (ura, upa) = part(&self.a, u);
        let (urb, upb) = part(&self.b, u);
        let (vra, vpa) = part(&self.a, v);
        let (vrb, vpb) = part(&self.b, v);
        let ed = perp(self.d);
        let h = dot(self.d, self.rbsb);
        -dot(self.d, self.w) * upa * vpa
            + dot(ed, sub(vrb, vra)) * upa
            + dot(ed, sub(urb, ura)) * vpa
            + h * (upa * vpb + upb * vpa - upb * vpb)
    }
    /// Third derivative as a trilinear form gamma3(u, v, t) = d/dx gamma(u, v) . t: the
    /// derivative of `gamma` along t, with d' = E d t_phi_a, (E d)' = -d t_phi_a and
    /// (R_b s_b)' = E R_b s_b t_phi_b.
    #[inline]
    pub fn gamma3(&self, u: &[f64], v: &[f64], t: &[f64]) -> f64 {
        let (ura, upa) = part(&self.a, u);
        let (urb, upb) = part(&self.b, u);
        let (vra, vpa) = part(&self.a, v);
        let (vrb, vpb) = part(&self.b, v);
        let (tra, tpa) = part(&self.a, t);
        let (trb, tpb) = part(&self.b, t);
        let k = dot(perp(self.d), self.rbsb);
        let dw = dot(perp(self.d), self.w) * tpa + dot(self.d, sub(trb, tra)) - k * tpb;
        -dw * upa * vpa - dot(self.d, sub(vrb, vra)) * tpa * upa - dot(self.d, sub(urb, ura)) * tpa * vpa
            + k * (tpa - tpb) * (upa * vpb + upb * vpa - upb * vpb)
    }
}
