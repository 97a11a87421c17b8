//! The stated limit of one evaluation: the passive four-bar of `four-bar-gravity.yaml` by hand,
//! in closed form, as a textbook writes it for this one mechanism. Crank angle theta (rad) in,
//! its acceleration out:
//!
//!   A = l1 (cos theta, sin theta);  B the intersection of the circles |B - A| = l2,
//!   |B - D| = l3 on the drawing's branch;  u = B - A, v = B - D;
//!   [u; v] B' = [u . A'; 0],  [u; v] B'' = [u . A'' - |B' - A'|^2; -|B'|^2]  (' = d/dtheta);
//!   each body's centre c = P + alpha r + beta r_perp on its line r, angle rate (r x r') / |r|^2;
//!   a = sum m |c'|^2 + J phi'^2,  b = sum m c' . c'' + J phi' phi'',  Q = sum m g . c',
//!   theta'' = (Q - b theta'^2) / a.
//!
//! Its parameters are the model file's; `check` compares it with planardyn's evaluation.

/// Ground pivots O (origin) and D, link lengths OA, AB, DB (m), from the file's points.
const D: [f64; 2] = [1.0, 0.0];
const A0: [f64; 2] = [0.25, 0.4330127018922193];
const B0: [f64; 2] = [1.336926485022576, 0.9415309573722639];
/// Masses (kg) and inertias about the centres (kg m^2) of crank, coupler and rocker.
const MASS: [f64; 3] = [0.5, 1.2, 1.0];
const INERTIA: [f64; 3] = [0.010416666666666666, 0.144, 0.08333333333333333];
/// Centres of mass in the drawing (m).
const COM0: [[f64; 2]; 3] =
    [[0.125, 0.21650635094610965], [0.793463242511288, 0.6872718296322415], [1.168463242511288, 0.47076547868613194]];
const G: f64 = -9.81;

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

/// A body's centre on its line r from point P: c = P + alpha r + beta r_perp.
#[derive(Clone, Copy)]
struct OnLine {
    alpha: f64,
    beta: f64,
}

impl OnLine {
    fn of(p: [f64; 2], q: [f64; 2], com: [f64; 2]) -> Self {
        let (r, c) = (sub(q, p), sub(com, p));
        let l2 = dot(r, r);
        OnLine { alpha: dot(c, r) / l2, beta: cross(r, c) / l2 }
    }
    /// The centre's first or second derivative from its line's (P' + alpha r' + beta r'_perp).
    fn at(&self, p: [f64; 2], r: [f64; 2]) -> [f64; 2] {
        let n = perp(r);
        [p[0] + self.alpha * r[0] + self.beta * n[0], p[1] + self.alpha * r[1] + self.beta * n[1]]
    }
}

/// The four-bar, its lengths squared, centres on their lines and branch, set up once.
pub struct FourBar {
    l2sq: f64,
    l3sq: f64,
    l1: f64,
    com: [OnLine; 3],
    /// +1 or -1: which intersection of the two circles is the drawing's.
    branch: f64,
}

impl FourBar {
    pub fn new() -> Self {
        let (u, v) = (sub(B0, A0), sub(B0, D));
        let com = [OnLine::of([0.0, 0.0], A0, COM0[0]), OnLine::of(A0, B0, COM0[1]), OnLine::of(D, B0, COM0[2])];
        // The drawn B lies to the left (+) or right (-) of A -> D.
        let branch = cross(sub(D, A0), sub(B0, A0)).signum();
        FourBar { l2sq: dot(u, u), l3sq: dot(v, v), l1: dot(A0, A0).sqrt(), com, branch }
    }

    /// dy = [theta', theta'', 0] at y = [theta, theta', work]: the evaluation an integrator makes.
    #[inline(never)]
    pub fn rhs(&self, y: &[f64], dy: &mut [f64]) {
        let (theta, rate) = (y[0], y[1]);
        let (s, c) = theta.sin_cos();
        let a = [self.l1 * c, self.l1 * s];
        let da = [-a[1], a[0]];
        let dda = [-a[0], -a[1]];
        // B: along A -> D by p, across it by h (the branch's side).
        let e = sub(D, a);
        let lsq = dot(e, e);
        let p = 0.5 * (self.l2sq - self.l3sq + lsq) / lsq;
        let h = self.branch * (self.l2sq / lsq - p * p).sqrt();
        let n = perp(e);
        let b = [a[0] + p * e[0] + h * n[0], a[1] + p * e[1] + h * n[1]];
        let (u, v) = (sub(b, a), sub(b, D));
        // [u; v] x = [r1; r2] by Cramer's rule.
        let det = cross(u, v);
        let solve = |r1: f64, r2: f64| [(r1 * v[1] - r2 * u[1]) / det, (u[0] * r2 - v[0] * r1) / det];
        let db = solve(dot(u, da), 0.0);
        let du = sub(db, da);
        let ddb = solve(dot(u, dda) - dot(du, du), -dot(db, db));
        let ddu = sub(ddb, dda);
        // Per body: c', c'' and phi', phi''.
        let origin = [0.0, 0.0];
        let com = [
            (self.com[0].at(origin, da), self.com[0].at(origin, dda), 1.0, 0.0),
            (self.com[1].at(da, du), self.com[1].at(dda, ddu), cross(u, du) / self.l2sq, cross(u, ddu) / self.l2sq),
            (
                self.com[2].at(origin, db),
                self.com[2].at(origin, ddb),
                cross(v, db) / self.l3sq,
                cross(v, ddb) / self.l3sq,
            ),
        ];
        let (mut mass, mut bias, mut q) = (0.0, 0.0, 0.0);
        for (k, (dc, ddc, dphi, ddphi)) in com.into_iter().enumerate() {
            mass += MASS[k] * dot(dc, dc) + INERTIA[k] * dphi * dphi;
            bias += MASS[k] * dot(dc, ddc) + INERTIA[k] * dphi * ddphi;
            q += MASS[k] * G * dc[1];
        }
        dy[0] = rate;
        dy[1] = (q - bias * rate * rate) / mass;
        dy[2] = 0.0;
    }
}

/// Largest relative difference of theta'' from planardyn's at the same state: the limit
/// evaluates the same mechanism (both exact, so only round-off apart).
pub const AGREEMENT: f64 = 1e-12;

/// Check the limit against planardyn's derivative `dy` at `y` (panics if they disagree).
pub fn check(limit: &FourBar, y: &[f64], dy: &[f64]) {
    let mut mine = [0.0; 3];
    limit.rhs(y, &mut mine);
    let diff = (mine[1] - dy[1]).abs() / dy[1].abs().max(1.0);
    assert!(diff < AGREEMENT, "the closed-form four-bar's theta'' {} differs from planardyn's {}", mine[1], dy[1]);
}
