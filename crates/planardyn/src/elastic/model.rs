//! The compliant mechanism in redundant coordinates z (docs/stiffness.md, *Method*): the
//! rigid mechanism's body coordinates x (3n), a node [X, Y, phi] at the tip of every slender
//! link (the pairs at the tip attach to it), and, when the rotors are free, one coordinate per
//! elastic drive (its rotor's angle reflected to the joint side). The position equations are
//! split into rigid rows g(z) = 0 (every pair row not made compliant, and every actuator
//! without a transmission spring held at its pose) and elastic elements, each a few strain
//! rows delta(z) with a stiffness K_e and damping D_e:
//!
//!   Pi(z) = sum_e 1/2 delta_e^T K_e delta_e + sigma0_e . delta_e - W . p(z),   g(z) = 0.
//!
//! Every row has its value, gradient and second derivative as a bilinear form (the pair
//! kinds' own, `model::pairs`; the beam's below), so that the tangent stiffness
//! sum B^T K B + sum_r sigma_r d2delta_r - sum_r lambda_r d2g_r - W . d2p is exact.

use crate::dynamics::transmission::actuator_pair;
use crate::kinematics::constraints::body_trig;
use crate::linalg::Dense;
use crate::model::compliance::LinkCompliance;
use crate::model::pairs::frames::rotate;
use crate::model::pairs::{self, coordinate, coordinate_gamma, coordinate_grad};
use crate::model::{BodyId, CoordinateKind, Link, Mechanism, Pair, PointId};
use nalgebra::{DMatrix, DVector};

/// One scalar row of the position equations of the compliant mechanism.
#[derive(Debug, Clone, Copy)]
enum Row {
    /// Row `row` of pair `pair` (its value is zero when assembled).
    Pair { pair: usize, row: usize },
    /// Pair `pair`'s relative coordinate from its value `at` (rad or m), minus the rotor
    /// coordinate in column `rotor` (measured from its reference value) when it is free.
    Coordinate { pair: usize, at: f64, rotor: Option<(usize, f64)> },
    /// Component `comp` (axial, transverse, rotation) of slender link `link`'s tip
    /// displacement relative to its clamped frame.
    Beam { link: usize, comp: usize },
}

/// An elastic element: its strain rows and 3 x 3 (at most) stiffness and damping.
#[derive(Debug, Clone)]
pub(crate) struct Element {
    rows: Vec<Row>,
    pub stiffness: DMatrix<f64>,
    pub damping: DMatrix<f64>,
    /// The actuator it belongs to, for a drive's spring.
    pub actuator: Option<usize>,
}

/// A body's point in z: the link (a body or a node) and the point in its frame (m).
#[derive(Debug, Clone, Copy)]
pub struct Output {
    pub body: BodyId,
    pub point: Option<PointId>,
}

/// The compliant mechanism at a reference pose z0 (every element unstrained there).
#[derive(Debug, Clone)]
pub(crate) struct ElasticModel<'m> {
    pub mech: &'m Mechanism,
    /// The pairs, those at a slender link's tip attached to its node (body n + k).
    pairs: Vec<Pair>,
    links: Vec<LinkCompliance>,
    /// Tip points of the slender links in their bodies' frames (m).
    tips: Vec<[f64; 2]>,
    rigid: Vec<Row>,
    /// The actuator each locked coordinate row belongs to (None for a pair row).
    pub rigid_actuator: Vec<Option<usize>>,
    pub elements: Vec<Element>,
    /// Mass matrix diagonal per column (kg, kg m^2; 0 for a node).
    pub mass: Vec<f64>,
    pub z0: Vec<f64>,
    /// Column scale: 1 for a length, the drawing's size L for an angle (so that a rank test
    /// compares like with like).
    pub col_scale: Vec<f64>,
}

impl<'m> ElasticModel<'m> {
    /// The compliant mechanism about the rigid mechanism's assembled body coordinates `x`;
    /// `free_rotors`: each elastic drive with a rotor gets its own coordinate.
    pub fn new(mech: &'m Mechanism, x: &[f64], free_rotors: bool) -> Self {
        let c = &mech.compliance;
        let n = mech.n_bodies();
        let mut pairs = mech.pairs.clone();
        let mut z0 = x.to_vec();
        let mut tips = Vec::new();
        for (k, l) in c.links.iter().enumerate() {
            let node = Link::Body(BodyId(n + k));
            let body = &mech.bodies[l.body.0];
            let s = body.points[1].1;
            tips.push(s);
            let xb = &x[3 * l.body.0..3 * l.body.0 + 3];
            let r = rotate(xb[2], s);
            z0.extend([xb[0] + r[0], xb[1] + r[1], xb[2]]);
            for p in pairs.iter_mut().filter(|p| p.point == l.tip) {
                if p.a == Link::Body(l.body) {
                    (p.a, p.sa) = (node, [0.0, 0.0]);
                }
                if p.b == Link::Body(l.body) {
                    (p.b, p.sb) = (node, [0.0, 0.0]);
                }
            }
        }
        let n_body_cols = z0.len();
        let mut mass: Vec<f64> = mech.bodies.iter().flat_map(|b| [b.mass, b.mass, b.inertia]).collect();
        mass.resize(n_body_cols, 0.0);
        let mut col_scale: Vec<f64> = (0..n_body_cols).map(|i| if i % 3 == 2 { mech.scale } else { 1.0 }).collect();
        let mut model = ElasticModel {
            mech,
            pairs,
            links: c.links.clone(),
            tips,
            rigid: Vec::new(),
            rigid_actuator: Vec::new(),
            elements: Vec::new(),
            mass: Vec::new(),
            z0: Vec::new(),
            col_scale: Vec::new(),
        };
        for (k, p) in model.pairs.iter().enumerate() {
            let released = c.pairs.iter().find(|pc| pc.pair.0 == k);
            let rows: Vec<Row> = (0..pairs::n_rows(&p.kind)).map(|row| Row::Pair { pair: k, row }).collect();
            match released {
                Some(pc) => model.elements.push(Element {
                    rows,
                    stiffness: DMatrix::from_diagonal(&DVector::from_column_slice(&pc.stiffness)),
                    damping: DMatrix::from_diagonal(&DVector::from_column_slice(&pc.damping)),
                    actuator: None,
                }),
                None => {
                    model.rigid_actuator.extend(rows.iter().map(|_| None));
                    model.rigid.extend(rows);
                }
            }
        }
        for a in 0..mech.n_actuators() {
            let pair = actuator_pair(mech, a).0;
            let at = coordinate(&model.pairs[pair], &z0);
            match c.drives.iter().find(|d| d.actuator == a) {
                Some(d) => {
                    let rotor = (free_rotors && d.rotor_inertia > 0.0).then(|| {
                        z0.push(at);
                        mass.push(d.rotor_inertia);
                        col_scale.push(if actuator_is_angle(mech, a) { mech.scale } else { 1.0 });
                        (z0.len() - 1, at)
                    });
                    model.elements.push(Element {
                        rows: vec![Row::Coordinate { pair, at, rotor }],
                        stiffness: DMatrix::from_element(1, 1, d.stiffness),
                        damping: DMatrix::from_element(1, 1, d.damping),
                        actuator: Some(a),
                    });
                }
                None => {
                    model.rigid.push(Row::Coordinate { pair, at, rotor: None });
                    model.rigid_actuator.push(Some(a));
                }
            }
        }
        for (k, l) in c.links.iter().enumerate() {
            model.elements.push(Element {
                rows: (0..3).map(|comp| Row::Beam { link: k, comp }).collect(),
                stiffness: cantilever_stiffness(l),
                damping: DMatrix::zeros(3, 3),
                actuator: None,
            });
        }
        (model.mass, model.z0, model.col_scale) = (mass, z0, col_scale);
        model
    }

    pub fn n_cols(&self) -> usize {
        self.z0.len()
    }

    /// Number of columns holding bodies and nodes [X, Y, phi].
    fn n_frames(&self) -> usize {
        self.mech.n_bodies() + self.links.len()
    }

    fn trig(&self, z: &[f64]) -> Vec<[f64; 2]> {
        let mut trig = vec![[0.0; 2]; self.n_frames()];
        body_trig(&z[..3 * self.n_frames()], &mut trig);
        trig
    }

    fn value(&self, row: Row, z: &[f64], trig: &[[f64; 2]]) -> f64 {
        match row {
            Row::Pair { pair, row } => pairs::residual(&self.pairs[pair], z, trig)[row],
            Row::Coordinate { pair, at, rotor } => {
                coordinate(&self.pairs[pair], z) - at - rotor.map_or(0.0, |(c, r0)| z[c] - r0)
            }
            Row::Beam { link, comp } => self.beam(link, z).0[comp],
        }
    }

    fn grad(&self, row: Row, z: &[f64], trig: &[[f64; 2]], out: &mut [f64]) {
        out.fill(0.0);
        let ncols = out.len();
        match row {
            Row::Pair { pair, row } => {
                let mut j = vec![0.0; 2 * ncols];
                let slots = [Some(0), Some(1)];
                pairs::jacobian(&self.pairs[pair], z, trig, &mut Dense { j: &mut j, ncols }, slots);
                out.copy_from_slice(&j[row * ncols..(row + 1) * ncols]);
            }
            Row::Coordinate { pair, rotor, .. } => {
                coordinate_grad(&self.pairs[pair], z, &mut Dense { j: out, ncols }, 0);
                if let Some((c, _)) = rotor {
                    out[c] -= 1.0;
                }
            }
            Row::Beam { link, comp } => {
                let g = self.beam(link, z).1[comp];
                let (b, n) = (3 * self.links[link].body.0, 3 * (self.mech.n_bodies() + link));
                for i in 0..3 {
                    out[b + i] += g[i];
                    out[n + i] += g[3 + i];
                }
            }
        }
    }

    /// d2 row / dz2 [u, v].
    fn gamma(&self, row: Row, z: &[f64], trig: &[[f64; 2]], u: &[f64], v: &[f64]) -> f64 {
        match row {
            Row::Pair { pair, row } => pairs::gamma(&self.pairs[pair], z, trig, u, v)[row],
            Row::Coordinate { pair, .. } => coordinate_gamma(&self.pairs[pair], z, u, v),
            Row::Beam { link, comp } => self.beam_gamma(link, comp, z, u, v),
        }
    }

    /// The tip's displacement relative to the clamped frame, in the link frame
    /// e = [R(phi_b)^T (r_node - r_b) - s_tip; phi_node - phi_b], and the gradient of each
    /// component with respect to the body's [X, Y, phi] and the node's.
    fn beam(&self, link: usize, z: &[f64]) -> ([f64; 3], [[f64; 6]; 3]) {
        let (b, n) = (3 * self.links[link].body.0, 3 * (self.mech.n_bodies() + link));
        let (s, c) = z[b + 2].sin_cos();
        let d = [z[n] - z[b], z[n + 1] - z[b + 1]];
        let e = [c * d[0] + s * d[1], -s * d[0] + c * d[1]];
        let tip = self.tips[link];
        let value = [e[0] - tip[0], e[1] - tip[1], z[n + 2] - z[b + 2]];
        let grad = [[-c, -s, e[1], c, s, 0.0], [s, -c, -e[0], -s, c, 0.0], [0.0, 0.0, -1.0, 0.0, 0.0, 1.0]];
        (value, grad)
    }

    /// Second derivative of beam component `comp`: only the body angle couples (the rotation
    /// component is linear).
    fn beam_gamma(&self, link: usize, comp: usize, z: &[f64], u: &[f64], v: &[f64]) -> f64 {
        let (b, n) = (3 * self.links[link].body.0, 3 * (self.mech.n_bodies() + link));
        let (s, c) = z[b + 2].sin_cos();
        let d = [z[n] - z[b], z[n + 1] - z[b + 1]];
        let e = [c * d[0] + s * d[1], -s * d[0] + c * d[1]];
        let du = [u[n] - u[b], u[n + 1] - u[b + 1]];
        let dv = [v[n] - v[b], v[n + 1] - v[b + 1]];
        let (pu, pv) = (u[b + 2], v[b + 2]);
        // d/dphi R^T = [[-s, c], [-c, -s]], d2/dphi2 R^T d = -R^T d.
        let dr = match comp {
            0 => [-s, c],
            1 => [-c, -s],
            _ => return 0.0,
        };
        let cross = dr[0] * (du[0] * pv + dv[0] * pu) + dr[1] * (du[1] * pv + dv[1] * pu);
        cross - e[comp] * pu * pv
    }

    /// Values and gradients (rows x cols) of the rigid rows at z.
    pub fn rigid_rows(&self, z: &[f64]) -> (DVector<f64>, DMatrix<f64>) {
        self.rows(&self.rigid, z)
    }

    fn rows(&self, rows: &[Row], z: &[f64]) -> (DVector<f64>, DMatrix<f64>) {
        let trig = self.trig(z);
        let nc = self.n_cols();
        let mut g = DMatrix::zeros(rows.len(), nc);
        let mut buf = vec![0.0; nc];
        let values = DVector::from_iterator(rows.len(), rows.iter().map(|&r| self.value(r, z, &trig)));
        for (i, &r) in rows.iter().enumerate() {
            self.grad(r, z, &trig, &mut buf);
            g.row_mut(i).copy_from_slice(&buf);
        }
        (values, g)
    }

    /// The model's gravity as a generalized force on z: m g on each body's centre of mass
    /// (whose coordinates z holds, so that its potential is linear in z: no curvature of its
    /// own; its geometric term comes through the forces that carry it). Zero on the nodes
    /// (massless) and the rotors (turning about their fixed axes).
    pub fn gravity_force(&self) -> DVector<f64> {
        let g = self.mech.gravity;
        let mut f = DVector::zeros(self.n_cols());
        for (i, b) in self.mech.bodies.iter().enumerate() {
            f[3 * i] = b.mass * g[0];
            f[3 * i + 1] = b.mass * g[1];
        }
        f
    }

    /// The free rotors: each one's column and its drive's actuator.
    pub fn rotors(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for e in &self.elements {
            for r in &e.rows {
                if let (Row::Coordinate { rotor: Some((c, _)), .. }, Some(a)) = (r, e.actuator) {
                    out.push((*c, a));
                }
            }
        }
        out
    }

    /// The gradient (one entry a column) of the mechanism's coordinate `k` (its pair's
    /// relative coordinate) at z.
    pub fn coordinate_gradient(&self, k: usize, z: &[f64]) -> Vec<f64> {
        let pair = self.mech.coordinates[k].pair.0;
        let mut out = vec![0.0; self.n_cols()];
        self.grad(Row::Coordinate { pair, at: 0.0, rotor: None }, z, &self.trig(z), &mut out);
        out
    }

    /// Strains delta_e and their gradients B_e of every element at z.
    pub fn strains(&self, z: &[f64]) -> Vec<(DVector<f64>, DMatrix<f64>)> {
        self.elements.iter().map(|e| self.rows(&e.rows, z)).collect()
    }

    /// sum_r weight_r d2 row_r / dz2, projected: N^T (...) N, over the rigid rows (weights
    /// `lambda`) and the elements' rows (weights `sigma`, stacked element by element).
    pub fn curvature(&self, z: &[f64], lambda: &[f64], sigma: &[f64], basis: &DMatrix<f64>) -> DMatrix<f64> {
        let trig = self.trig(z);
        let rows = self.rigid.iter().zip(lambda).chain(self.elements.iter().flat_map(|e| &e.rows).zip(sigma));
        let d = basis.ncols();
        let cols: Vec<Vec<f64>> = (0..d).map(|a| basis.column(a).iter().copied().collect()).collect();
        let mut h = DMatrix::zeros(d, d);
        for (&row, &w) in rows.filter(|(_, w)| **w != 0.0) {
            for a in 0..d {
                for b in a..d {
                    let v = w * self.gamma(row, z, &trig, &cols[a], &cols[b]);
                    h[(a, b)] += v;
                    if a != b {
                        h[(b, a)] += v;
                    }
                }
            }
        }
        h
    }

    /// The output's pose p = [x, y, phi] at z (m, m, rad) and its gradient S (3 x cols).
    pub fn output(&self, out: Output, z: &[f64]) -> ([f64; 3], DMatrix<f64>) {
        let (frame, s) = self.output_frame(out);
        let xb = &z[3 * frame..3 * frame + 3];
        let r = rotate(xb[2], s);
        let mut g = DMatrix::zeros(3, self.n_cols());
        for i in 0..3 {
            g[(i, 3 * frame + i)] = 1.0;
        }
        g[(0, 3 * frame + 2)] = -r[1];
        g[(1, 3 * frame + 2)] = r[0];
        ([xb[0] + r[0], xb[1] + r[1], xb[2]], g)
    }

    /// W . d2p/dz2 on the frame's angle: W_xy . (-R(phi) s), as a matrix over the basis.
    pub fn output_curvature(&self, out: Output, z: &[f64], w: &[f64; 3], basis: &DMatrix<f64>) -> DMatrix<f64> {
        let (frame, s) = self.output_frame(out);
        let r = rotate(z[3 * frame + 2], s);
        let k = -(w[0] * r[0] + w[1] * r[1]);
        let phi = basis.row(3 * frame + 2);
        phi.transpose() * phi * k
    }

    /// The frame (a body or a node) that carries the output and the point in it.
    fn output_frame(&self, out: Output) -> (usize, [f64; 2]) {
        let body = &self.mech.bodies[out.body.0];
        if let Some(p) = out.point {
            if let Some(k) = self.links.iter().position(|l| l.body == out.body && l.tip == p) {
                return (self.mech.n_bodies() + k, [0.0, 0.0]);
            }
            if let Some(&(_, s)) = body.points.iter().find(|(id, _)| *id == p) {
                return (out.body.0, s);
            }
        }
        (out.body.0, [0.0, 0.0])
    }
}

/// Whether actuator `a`'s coordinate is an angle.
fn actuator_is_angle(mech: &Mechanism, a: usize) -> bool {
    pairs::coordinate_kind(&mech.pairs[actuator_pair(mech, a).0]) == Some(CoordinateKind::Angle)
}

/// The stiffness of a cantilever's tip in its frame (axial, transverse, rotation), the
/// inverse of its compliance [[L/EA, 0, 0], [0, L^3/3EI, L^2/2EI], [0, L^2/2EI, L/EI]]
/// (Euler-Bernoulli, e.g. Gere & Goodno, *Mechanics of Materials*, table of deflections).
fn cantilever_stiffness(l: &LinkCompliance) -> DMatrix<f64> {
    let (len, ea, ei) = (l.length, l.ea, l.ei);
    DMatrix::from_row_slice(
        3,
        3,
        &[
            ea / len,
            0.0,
            0.0,
            0.0,
            12.0 * ei / len.powi(3),
            -6.0 * ei / len.powi(2),
            0.0,
            -6.0 * ei / len.powi(2),
            4.0 * ei / len,
        ],
    )
}
