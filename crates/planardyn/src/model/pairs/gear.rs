//! Gear pair: the pitch circles of a's and b's gears roll on each other without slipping;
//! or a's pinion rolls on b's rack. One row in metres, linear in the angles (gears):
//!
//!   r_a theta_a + r_b theta_b = 0,   theta_i = (phi_i - phi_c) - (drawn value),
//!
//! with phi_c the carrier's angle: the carrier is the link holding both gear centres (the
//! ground for a fixed-axis train, the arm of a planetary train). r_a > 0 is a's pitch
//! radius and r_b is b's, signed: positive for an external mesh (the gears turn in opposite
//! senses relative to the carrier), negative for an internal one (a pinion in a ring gear,
//! same sense). The velocity ratio relative to the carrier is theta_b' / theta_a' = -r_a / r_b.
//!
//! A rack: b translates along its pitch line, a line fixed in the carrier at distance r_a
//! from the pinion's centre; the row is sigma r_a theta_a - u = 0 with u the rack's travel
//! along the line (direction `axis`) relative to the carrier and sigma = +1 when a
//! counter-clockwise pinion drives the rack along +axis, -1 otherwise.
//!
//! The gear pair has no relative coordinate of its own and cannot be an input; drive one of
//! its gears' revolute pairs instead. Its reaction is the tooth force with a pressure angle
//! of 0: along the common tangent of the pitch circles at the contact point, reduced to b's
//! centre (b's pair point). Because the row involves the angles only, the bearings (the
//! revolute pairs holding the gears to the carrier) report their loads without the tooth
//! force: the physical bearing load of b is its revolute reaction plus this force.

use super::frames::{add_grad, angle, dot, link_columns, link_state, link_state_t, part, perp, Projection};
use super::{reaction_force, FrictionField, PairGeometry, PairType, Relative, Rows};
use crate::linalg::Sink;
use crate::model::{JointFriction, Link, Pair};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gear {
    /// The link holding both gear centres.
    pub carrier: Link,
    /// a's pitch radius (m), > 0; a's centre is its pair point `sa`.
    pub ra: f64,
    pub mesh: Mesh,
    /// The row's value in the drawing without its offset, subtracted so that it is 0 there.
    pub offset: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mesh {
    /// b is a gear centred at its pair point `sb`, of signed pitch radius `rb` (m): > 0
    /// external, < 0 internal.
    Gear { rb: f64 },
    /// b is a rack; its pitch line passes through its pair point `sb` and `end` (in b's
    /// frame), with unit direction `axis` in the carrier's frame, where `sc` is the drawn
    /// pair point. `sign` is sigma (see the module doc).
    Rack { sign: f64, axis: [f64; 2], sc: [f64; 2], end: [f64; 2] },
}

impl Gear {
    /// The rack's travel along its pitch line relative to the carrier.
    #[inline]
    fn travel(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], sc: [f64; 2], axis: [f64; 2]) -> Projection {
        Projection::new(sc, pair.sb, axis, link_state_t(self.carrier, x, trig), link_state_t(pair.b, x, trig))
    }
    /// The coefficients of phi_a and phi_b in the row.
    #[inline]
    fn coefficients(&self) -> [f64; 2] {
        match self.mesh {
            Mesh::Gear { rb } => [self.ra, rb],
            Mesh::Rack { sign, .. } => [sign * self.ra, 0.0],
        }
    }
}

/// The gear of a mesh that carries its friction torque (docs/actuators.md, *Friction at a
/// gear mesh*): the driver, the one that delivers power through the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Side {
    #[default]
    A,
    B,
}

impl Gear {
    /// The pitch speed v = k_a (phi_a' - phi_c') (m/s), k_a = sigma r_a for a rack: the rate
    /// of both gears' pitch-line travel relative to the carrier.
    pub fn pitch_speed(&self, pair: &Pair, x: &[f64], xd: &[f64]) -> f64 {
        let w = |link: Link| part(&link_state(link, x), xd).1;
        self.coefficients()[0] * (w(pair.a) - w(self.carrier))
    }

    /// The gradient of `side`'s pitch-line travel relative to the carrier, into row `row` of
    /// `j`: k_a (phi_a - phi_c) for a, -k_b (phi_b - phi_c) or the rack's travel for b. Both
    /// move at the pitch speed, and their gradients differ by the row's: an effort on either
    /// gives the same generalized force, and a different tooth force.
    pub fn pitch_grad<S: Sink>(&self, pair: &Pair, x: &[f64], side: Side, j: &mut S, row: usize) {
        let [ka, kb] = self.coefficients();
        let carrier = link_state(self.carrier, x);
        match (side, self.mesh) {
            (Side::A, _) => {
                add_grad(j, row, &link_state(pair.a, x), [0.0, 0.0, ka]);
                add_grad(j, row, &carrier, [0.0, 0.0, -ka]);
            }
            (Side::B, Mesh::Gear { .. }) => {
                add_grad(j, row, &link_state(pair.b, x), [0.0, 0.0, -kb]);
                add_grad(j, row, &carrier, [0.0, 0.0, kb]);
            }
            (Side::B, Mesh::Rack { axis, sc, .. }) => {
                Projection::new(sc, pair.sb, axis, carrier, link_state(pair.b, x)).grad(j, row, 1.0)
            }
        }
    }

    /// The row's multiplier from the pair's reaction (`reaction`'s inverse): the signed
    /// tooth force (N).
    pub fn tooth_force(&self, x: &[f64], reaction: [f64; 3]) -> f64 {
        match self.mesh {
            Mesh::Gear { rb } => reaction[2] / rb,
            Mesh::Rack { axis, .. } => -dot([reaction[0], reaction[1]], link_state(self.carrier, x).rot(axis)),
        }
    }

    /// The driver at tooth force `tooth` and pitch speed `v`: the tooth force gives b the
    /// power -tooth v relative to the carrier, so a drives while it is positive.
    pub fn driver(tooth: f64, v: f64) -> Side {
        if tooth * v <= 0.0 {
            Side::A
        } else {
            Side::B
        }
    }
}

impl PairType for Gear {
    const NAME: &'static str = "gear";
    const ROWS: usize = 1;
    const LETTER: char = 'G';
    const FRICTION_FIELD: FrictionField = FrictionField::PressureAngle;

    #[inline]
    fn residual(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]]) -> Rows {
        let [ka, kb] = self.coefficients();
        let phi_c = angle(self.carrier, x);
        let turn = ka * (angle(pair.a, x) - phi_c) + kb * (angle(pair.b, x) - phi_c) - self.offset;
        match self.mesh {
            Mesh::Gear { .. } => [turn, 0.0],
            Mesh::Rack { axis, sc, .. } => [turn - self.travel(pair, x, trig, sc, axis).value(), 0.0],
        }
    }

    #[inline]
    fn jacobian<S: Sink>(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], j: &mut S, rows: [Option<usize>; 2]) {
        let Some(row) = rows[0] else { return };
        let [ka, kb] = self.coefficients();
        add_grad(j, row, &link_state_t(pair.a, x, trig), [0.0, 0.0, ka]);
        add_grad(j, row, &link_state_t(pair.b, x, trig), [0.0, 0.0, kb]);
        add_grad(j, row, &link_state_t(self.carrier, x, trig), [0.0, 0.0, -(ka + kb)]);
        if let Mesh::Rack { axis, sc, .. } = self.mesh {
            self.travel(pair, x, trig, sc, axis).grad(j, row, -1.0);
        }
    }

    #[inline]
    fn gamma(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> Rows {
        match self.mesh {
            Mesh::Gear { .. } => [0.0; 2],
            Mesh::Rack { axis, sc, .. } => [-self.travel(pair, x, trig, sc, axis).gamma(u, v), 0.0],
        }
    }

    #[inline]
    fn gamma3(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], t: &[f64]) -> Rows {
        match self.mesh {
            Mesh::Gear { .. } => [0.0; 2],
            Mesh::Rack { axis, sc, .. } => [-self.travel(pair, x, trig, sc, axis).gamma3(u, v, t), 0.0],
        }
    }

    fn row_scales(&self, inv_l: f64) -> Rows {
        [inv_l, 0.0]
    }

    fn pattern(&self, pair: &Pair, _row: usize) -> Vec<usize> {
        let rack = matches!(self.mesh, Mesh::Rack { .. });
        let mut cols: Vec<usize> = link_columns(pair.a, true)
            .chain(link_columns(pair.b, !rack))
            .chain(link_columns(self.carrier, !rack))
            .collect();
        cols.sort_unstable();
        cols
    }

    #[inline]
    fn relative(&self) -> Option<Relative> {
        None
    }

    /// The tooth force on b is -mu t, t the tangent at the contact point (+90 degrees from
    /// the direction from a's centre to it; the rack's axis); it gives b the couple r_b mu
    /// about its centre, as the row's gradient in phi_b says.
    fn reaction(&self, pair: &Pair, x: &[f64], mu: Rows) -> [f64; 3] {
        match self.mesh {
            Mesh::Gear { rb } => {
                let (pa, pb) = (link_state(pair.a, x).point(pair.sa), link_state(pair.b, x).point(pair.sb));
                let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
                let e = (self.ra + rb).signum() / dx.hypot(dy);
                let t = perp([e * dx, e * dy]);
                [-mu[0] * t[0], -mu[0] * t[1], rb * mu[0]]
            }
            Mesh::Rack { axis, .. } => {
                let t = link_state(self.carrier, x).rot(axis);
                [-mu[0] * t[0], -mu[0] * t[1], 0.0]
            }
        }
    }

    fn geometry(&self, pair: &Pair, x: &[f64], _scale: f64) -> PairGeometry {
        let (a, b) = (link_state(pair.a, x), link_state(pair.b, x));
        let mut g = PairGeometry::new(Self::NAME);
        g.circles.push((a.point(pair.sa), self.ra));
        match self.mesh {
            Mesh::Gear { rb } => g.circles.push((b.point(pair.sb), rb.abs())),
            Mesh::Rack { end, .. } => g.lines.push([b.point(pair.sb), b.point(end)]),
        }
        g
    }

    /// F_t / cos(alpha): the tangential tooth force F_t over the cosine of the pressure
    /// angle alpha = `fr.pressure_angle` (the reaction force's magnitude is F_t's).
    #[inline]
    fn contact_load(&self, fr: &JointFriction, reaction: [f64; 3]) -> f64 {
        reaction_force(reaction) / fr.pressure_angle.cos()
    }

    /// The pitch-line travel of the gear on `side` (the mesh's friction acts on the
    /// driver's); its rate is the pitch speed.
    #[inline]
    fn slip_lever<S: Sink>(&self, pair: &Pair, x: &[f64], xd: &[f64], side: Side, j: &mut S) -> f64 {
        self.pitch_grad(pair, x, side, j, 0);
        self.pitch_speed(pair, x, xd)
    }

    /// The driver: the side the power crosses the mesh from.
    #[inline]
    fn slip_side(&self, x: &[f64], reaction: [f64; 3], rate: f64) -> Side {
        Gear::driver(self.tooth_force(x, reaction), rate)
    }

    // No relative coordinate (`relative`): never asked for one (see `PairType`).
    fn coordinate(&self, _pair: &Pair, _x: &[f64]) -> f64 {
        0.0
    }
    fn coordinate_grad<S: Sink>(&self, _pair: &Pair, _x: &[f64], _j: &mut S, _row: usize) {}
    fn coordinate_gamma(&self, _pair: &Pair, _x: &[f64], _u: &[f64], _v: &[f64]) -> f64 {
        0.0
    }
    fn coordinate_gamma3(&self, _pair: &Pair, _x: &[f64], _u: &[f64], _v: &[f64], _t: &[f64]) -> f64 {
        0.0
    }
    fn coordinate_rate(&self, _pair: &Pair, _x: &[f64], _xd: &[f64]) -> f64 {
        0.0
    }
    fn linear_coordinate(&self, _pair: &Pair) -> Option<super::LinearCoordinate> {
        None
    }
}
