//! Revolute pair (hinge): the two copies of the pair point coincide. Two rows in metres,
//! Phi = p_a - p_b; relative coordinate: the angle phi_b - phi_a.

use super::frames::{add_grad, angle, link_columns, link_state, link_state_t, part, perp};
use super::gear::Side;
use super::{
    coordinate_lever, reaction_force, FrictionField, LinearCoordinate, PairGeometry, PairType, Relative, Rows,
};
use crate::linalg::Sink;
use crate::model::{JointFriction, Link, Pair};

pub struct Revolute;

impl PairType for Revolute {
    const NAME: &'static str = "revolute";
    const ROWS: usize = 2;
    const LETTER: char = 'R';
    const FRICTION_FIELD: FrictionField = FrictionField::None;

    #[inline]
    fn residual(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]]) -> Rows {
        let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
        let (pa, pb) = (a.point(pair.sa), b.point(pair.sb));
        [pa[0] - pb[0], pa[1] - pb[1]]
    }

    #[inline]
    fn jacobian<S: Sink>(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], j: &mut S, rows: [Option<usize>; 2]) {
        let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
        let (ta, tb) = (perp(a.rot(pair.sa)), perp(b.rot(pair.sb)));
        if let Some(row) = rows[0] {
            add_grad(j, row, &a, [1.0, 0.0, ta[0]]);
            add_grad(j, row, &b, [-1.0, 0.0, -tb[0]]);
        }
        if let Some(row) = rows[1] {
            add_grad(j, row, &a, [0.0, 1.0, ta[1]]);
            add_grad(j, row, &b, [0.0, -1.0, -tb[1]]);
        }
    }

    #[inline]
    fn gamma(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> Rows {
        // d2(R(phi) s)/dphi2 = -R(phi) s; only the angle-angle entries are non-zero.
        let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
        let (pa, pb) = (a.rot(pair.sa), b.rot(pair.sb));
        let (ka, kb) = (part(&a, u).1 * part(&a, v).1, part(&b, u).1 * part(&b, v).1);
        [-pa[0] * ka + pb[0] * kb, -pa[1] * ka + pb[1] * kb]
    }

    #[inline]
    fn gamma3(&self, pair: &Pair, x: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64], t: &[f64]) -> Rows {
        // d3(R(phi) s)/dphi3 = -E R(phi) s.
        let (a, b) = (link_state_t(pair.a, x, trig), link_state_t(pair.b, x, trig));
        let (ea, eb) = (perp(a.rot(pair.sa)), perp(b.rot(pair.sb)));
        let ka = part(&a, u).1 * part(&a, v).1 * part(&a, t).1;
        let kb = part(&b, u).1 * part(&b, v).1 * part(&b, t).1;
        [-ea[0] * ka + eb[0] * kb, -ea[1] * ka + eb[1] * kb]
    }

    fn row_scales(&self, inv_l: f64) -> Rows {
        [inv_l, inv_l]
    }

    fn pattern(&self, pair: &Pair, _row: usize) -> Vec<usize> {
        both_links(pair)
    }

    #[inline]
    fn relative(&self) -> Option<Relative> {
        Some(Relative::Angle)
    }

    /// The multiplier of Phi = p_a - p_b is the force on a, so -mu acts on b; no couple.
    fn reaction(&self, _pair: &Pair, _x: &[f64], mu: Rows) -> [f64; 3] {
        [-mu[0], -mu[1], 0.0]
    }

    fn geometry(&self, pair: &Pair, x: &[f64], _scale: f64) -> PairGeometry {
        let mut g = PairGeometry::new(Self::NAME);
        g.pins.push(link_state(pair.a, x).point(pair.sa));
        g
    }

    /// The pin (of radius `fr.arm`) carries the reaction force.
    #[inline]
    fn contact_load(&self, _fr: &JointFriction, reaction: [f64; 3]) -> f64 {
        reaction_force(reaction)
    }

    #[inline]
    fn slip_lever<S: Sink>(&self, pair: &Pair, x: &[f64], xd: &[f64], _side: Side, j: &mut S) -> f64 {
        coordinate_lever(self, pair, x, xd, j)
    }

    #[inline]
    fn slip_side(&self, _x: &[f64], _reaction: [f64; 3], _rate: f64) -> Side {
        Side::A
    }

    // The relative angle phi_b - phi_a - (drawn) is linear in the two angles: its gradient is
    // -1 on a's and +1 on b's (the ground's is no column), its rate their rates' difference,
    // its higher derivatives zero. Neither needs the links' cos and sin.
    #[inline]
    fn coordinate(&self, pair: &Pair, x: &[f64]) -> f64 {
        angle(pair.b, x) - angle(pair.a, x) - pair.rel_angle0
    }
    #[inline]
    fn coordinate_grad<S: Sink>(&self, pair: &Pair, _x: &[f64], j: &mut S, row: usize) {
        if let Link::Body(a) = pair.a {
            j.add(row, 3 * a.0 + 2, -1.0);
        }
        if let Link::Body(b) = pair.b {
            j.add(row, 3 * b.0 + 2, 1.0);
        }
    }
    #[inline]
    fn coordinate_gamma(&self, _pair: &Pair, _x: &[f64], _u: &[f64], _v: &[f64]) -> f64 {
        0.0
    }
    #[inline]
    fn coordinate_gamma3(&self, _pair: &Pair, _x: &[f64], _u: &[f64], _v: &[f64], _t: &[f64]) -> f64 {
        0.0
    }
    #[inline]
    fn coordinate_rate(&self, pair: &Pair, _x: &[f64], xd: &[f64]) -> f64 {
        angle(pair.b, xd) - angle(pair.a, xd)
    }
    fn linear_coordinate(&self, pair: &Pair) -> Option<LinearCoordinate> {
        let column = |link| match link {
            Link::Ground => None,
            Link::Body(b) => Some(3 * b.0 + 2),
        };
        Some(LinearCoordinate { minus: column(pair.a), plus: column(pair.b), offset: pair.rel_angle0 })
    }
}

/// All three columns of both links of a pair, ascending.
pub(super) fn both_links(pair: &Pair) -> Vec<usize> {
    let mut cols: Vec<usize> = link_columns(pair.a, false).chain(link_columns(pair.b, false)).collect();
    cols.sort_unstable();
    cols
}

#[cfg(test)]
mod tests {
    use crate::linalg::Dense;
    use crate::model::pairs::{coordinate, coordinate_gamma, coordinate_grad, coordinate_rate};
    use crate::model::PairKind;

    /// Step of the central differences (rad): the relative angle is linear in x, so they are
    /// exact but for rounding, about 1e-16 / 1e-6 = 1e-10 here.
    const H: f64 = 1e-6;
    const FD_TOL: f64 = 1e-8;

    /// Andrews' squeezer (revolute pairs ground-body and body-body, either order), x off its
    /// drawing and rates xd.
    fn andrews_off_drawing() -> (crate::model::Mechanism, Vec<f64>, Vec<f64>) {
        let path = format!("{}/../../examples/models/andrews-squeezer.yaml", env!("CARGO_MANIFEST_DIR"));
        let mech = crate::load(&path).unwrap();
        let x: Vec<f64> = mech.x0.iter().enumerate().map(|(i, v)| v + 0.013 * i as f64).collect();
        let xd: Vec<f64> = (0..x.len()).map(|i| 1.3 - 0.21 * i as f64).collect();
        (mech, x, xd)
    }

    /// A revolute pair's relative angle from its own module (no cos or sin of the links):
    /// the gradient is the angle's (central differences along every column of x), the rate
    /// the gradient times xd, the second derivative zero. Every revolute pair of Andrews'
    /// squeezer (ground-body and body-body pairs, either order) at a point off the drawing.
    #[test]
    fn the_relative_angle_its_gradient_and_rate() {
        let (mech, x, xd) = andrews_off_drawing();
        let n = x.len();
        let pairs: Vec<_> = mech.pairs.iter().filter(|p| p.kind == PairKind::Revolute).collect();
        assert!(pairs.len() >= 7, "{}", pairs.len());
        for p in pairs {
            let mut g = vec![0.0; n];
            coordinate_grad(p, &x, &mut Dense { j: &mut g, ncols: n }, 0);
            for i in 0..n {
                let (mut up, mut down) = (x.clone(), x.clone());
                up[i] += H;
                down[i] -= H;
                let fd = (coordinate(p, &up) - coordinate(p, &down)) / (2.0 * H);
                assert!((fd - g[i]).abs() < FD_TOL, "column {i}: {fd} against {}", g[i]);
            }
            let along: f64 = g.iter().zip(&xd).map(|(g, v)| g * v).sum();
            assert!((coordinate_rate(p, &x, &xd) - along).abs() <= 1e-15 * along.abs(), "{along}");
            assert_eq!(coordinate_gamma(p, &x, &xd, &xd), 0.0);
        }
    }

    /// An effort through the relative angle's columns found at build (`LinearCoordinate`) is
    /// the generic pair code's to the bit: f, the effort and the rate, with an effort of both
    /// the angle and its rate, at every revolute pair of Andrews' squeezer (ground-body and
    /// body-body pairs) off the drawing; and a prismatic pair has none.
    #[test]
    fn the_linear_coordinate_gives_the_generic_effort_bit_for_bit() {
        use crate::model::pairs::{add_coordinate_effort, linear_coordinate};
        let (mech, x, xd) = andrews_off_drawing();
        let n = x.len();
        let effort = |value: f64, rate: f64| -7.0 * (value - 0.1) - 0.3 * rate;
        let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        let mut grounded = 0;
        for p in mech.pairs.iter().filter(|p| p.kind == PairKind::Revolute) {
            let linear = linear_coordinate(p).expect("a revolute pair's angle is linear");
            grounded += usize::from(linear.minus.is_none() || linear.plus.is_none());
            let start: Vec<f64> = (0..n).map(|i| 0.5 * i as f64 - 1.0).collect();
            let (mut f, mut expected) = (start.clone(), start);
            let (e, r) = linear.add_effort(&x, &xd, &mut f, effort);
            let (e0, r0) = add_coordinate_effort(p, &x, &xd, &mut expected, effort);
            assert_eq!((e.to_bits(), r.to_bits()), (e0.to_bits(), r0.to_bits()), "{}", p.name);
            assert_eq!(bits(&f), bits(&expected), "{}", p.name);
            assert_ne!(f, (0..n).map(|i| 0.5 * i as f64 - 1.0).collect::<Vec<_>>());
        }
        assert!(grounded >= 3, "{grounded}");
        let prismatic = crate::model::Pair { kind: PairKind::Prismatic { axis: [1.0, 0.0] }, ..mech.pairs[0].clone() };
        assert_eq!(linear_coordinate(&prismatic), None);
    }
}
