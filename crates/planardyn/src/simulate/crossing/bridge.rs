//! The path across a change point, from the accelerations on both sides of it.

use super::approach::Passed;

/// A path x(t) of the body coordinates: position, rate and acceleration at time t.
pub trait Path {
    fn at(&self, t: f64, x: &mut [f64], xd: &mut [f64], xdd: &mut [f64]);
}

/// The path across a change point from the point (t0, x0, xd0, W0) before it:
///
///   x(t0 + s) = x0 + s xd0 + sum_{j>=2} c_j u^j,  u = s / scale,
///
/// its acceleration the polynomial through the accelerations at the nodes. It takes x0 and
/// xd0 as they are: rates or positions fitted over a few ms carried their round-off into the
/// accelerations, amplified 600 times (the landing's rate against the earlier points' rates).
/// With nodes before the point only it is a Taylor step, an extrapolation (the predictor);
/// with the landing and the points past it among them, an interpolation across the gap (the
/// corrector), whose weights are those of a quadrature rule: on [`super::NODES`] points a
/// side at [`super::SPACING`] of the gap's half-length, the accelerations' errors enter the
/// landing's rates with weights summing to 8.6 times the gap, where the Taylor step from 5
/// points before it has 13 and its own error is that of extrapolating into the gap. The work
/// W is the integral of the polynomial through the powers at the nodes.
pub struct Bridge {
    t0: f64,
    x: Vec<f64>,
    xd: Vec<f64>,
    /// c_2, c_3, ... (3n each).
    c: Vec<Vec<f64>>,
    /// W at t0, and the coefficients of the power in powers of u.
    work: f64,
    beta: Vec<f64>,
    scale: f64,
}

impl Bridge {
    /// From `nodes[0]` (the start, with work `work`) through the accelerations and powers at
    /// `nodes` (distinct times); `scale` about the time the step spans (s).
    pub fn new(nodes: &[&Passed], work: f64, scale: f64) -> Self {
        let start = nodes[0];
        let (k, n) = (nodes.len(), start.x().len());
        let u: Vec<f64> = nodes.iter().map(|p| (p.t - start.t) / scale).collect();
        // xdd = sum_j j (j - 1) c_j u^(j-2) / scale^2, j = col + 2.
        let v = nalgebra::DMatrix::from_fn(k, k, |i, col| {
            let j = (col + 2) as f64;
            j * (j - 1.0) * u[i].powi(col as i32) / (scale * scale)
        });
        let rhs = nalgebra::DMatrix::from_fn(k, n, |i, c| nodes[i].xdd()[c]);
        let c = v.lu().solve(&rhs).unwrap_or_else(|| nalgebra::DMatrix::zeros(k, n));
        let c = (0..k).map(|j| c.row(j).iter().copied().collect()).collect();
        let pv = nalgebra::DMatrix::from_fn(k, k, |i, j| u[i].powi(j as i32));
        let powers = nalgebra::DVector::from_iterator(k, nodes.iter().map(|p| p.power));
        let beta = pv.lu().solve(&powers).map_or_else(|| vec![0.0; k], |b| b.iter().copied().collect());
        Bridge { t0: start.t, x: start.x().to_vec(), xd: start.xd().to_vec(), c, work, beta, scale }
    }

    /// The number of body coordinates (3n).
    pub fn coordinates(&self) -> usize {
        self.x.len()
    }

    /// The work W at t (J).
    pub fn work(&self, t: f64) -> f64 {
        let s = t - self.t0;
        let u = s / self.scale;
        self.beta.iter().enumerate().fold(self.work, |w, (k, b)| w + b * s * u.powi(k as i32) / (k as f64 + 1.0))
    }
}

impl Path for Bridge {
    fn at(&self, t: f64, x: &mut [f64], xd: &mut [f64], xdd: &mut [f64]) {
        let s = t - self.t0;
        let u = s / self.scale;
        x.fill(0.0);
        xd.fill(0.0);
        xdd.fill(0.0);
        // Horner in u for sum_j c_j u^(j-2) and its first two derivatives' sums.
        for (col, c) in self.c.iter().enumerate().rev() {
            let j = (col + 2) as f64;
            for i in 0..c.len() {
                x[i] = x[i] * u + c[i];
                xd[i] = xd[i] * u + j * c[i];
                xdd[i] = xdd[i] * u + j * (j - 1.0) * c[i];
            }
        }
        let sc = self.scale;
        for i in 0..x.len() {
            xdd[i] /= sc * sc;
            xd[i] = self.xd[i] + xd[i] * u / sc;
            x[i] = self.x[i] + s * self.xd[i] + x[i] * u * u;
        }
    }
}

/// The quintic in t through two accepted points' body (x, xd, xdd): c_0 + c_1 u + ... +
/// c_5 u^5 in u = (t - t0) / span (a step's path, to locate a change point it went over).
pub struct Quintic {
    t0: f64,
    span: f64,
    c: [Vec<f64>; 6],
}

impl Quintic {
    pub fn new(a: &Passed, b: (&[f64], &[f64], &[f64]), tb: f64) -> Self {
        let span = tb - a.t;
        let n = a.x().len();
        let (ax, axd, axdd) = (a.x(), a.xd(), a.xdd());
        let mut c: [Vec<f64>; 6] = std::array::from_fn(|_| vec![0.0; n]);
        for i in 0..n {
            let (c0, c1, c2) = (ax[i], axd[i] * span, axdd[i] * span * span / 2.0);
            let p = b.0[i] - (c0 + c1 + c2);
            let v = b.1[i] * span - (c1 + 2.0 * c2);
            let w = b.2[i] * span * span - 2.0 * c2;
            let coefficients =
                [c0, c1, c2, 10.0 * p - 4.0 * v + w / 2.0, -15.0 * p + 7.0 * v - w, 6.0 * p - 3.0 * v + w / 2.0];
            for (ck, v) in c.iter_mut().zip(coefficients) {
                ck[i] = v;
            }
        }
        Quintic { t0: a.t, span, c }
    }
}

impl Path for Quintic {
    fn at(&self, t: f64, x: &mut [f64], xd: &mut [f64], xdd: &mut [f64]) {
        let (u, s) = ((t - self.t0) / self.span, self.span);
        let c = &self.c;
        for i in 0..x.len() {
            x[i] = c[0][i] + u * (c[1][i] + u * (c[2][i] + u * (c[3][i] + u * (c[4][i] + u * c[5][i]))));
            xd[i] = (c[1][i] + u * (2.0 * c[2][i] + u * (3.0 * c[3][i] + u * (4.0 * c[4][i] + u * 5.0 * c[5][i])))) / s;
            xdd[i] = (2.0 * c[2][i] + u * (6.0 * c[3][i] + u * (12.0 * c[4][i] + u * 20.0 * c[5][i]))) / (s * s);
        }
    }
}
