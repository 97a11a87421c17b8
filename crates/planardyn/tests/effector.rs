//! The end effector and task-space inverse dynamics against closed forms: the five-bar's
//! task Jacobian and convective term against finite differences of its forward position,
//! its inverse kinematics against circle intersections, and the efforts along a path against
//! the forward dynamics they must reproduce.

mod common;

use common::shipped;
use planardyn::dynamics::task::{solve, TaskPath};
use planardyn::dynamics::{forward, Drives};
use planardyn::kinematics::{assemble_into, convective, Effector, SINGULAR_TOL};
use planardyn::{Mechanism, Workspace};
use std::f64::consts::PI;

/// Central differences with h = 1e-6 on positions solved to ~1e-12 L: error ~ 1e-12 / 1e-6.
const FD_TOL: f64 = 1e-7;
/// Second differences with h = 1e-4: truncation ~ h^2 |X''''| ~ 1e-8, round-off 1e-12 / h^2.
const FD2_TOL: f64 = 1e-6;
/// Inverse kinematics stops at a scaled task residual of 1e-11 (`IK_TOL`): with |J^-1| ~ 10
/// (sigma_I ~ 0.1 in the well-conditioned drawing's neighbourhood), q to ~1e-10 rad.
const IK_Q_TOL: f64 = 1e-9;
/// Forward dynamics under the computed efforts gives back qdd: A qdd = b + tau solved twice
/// (Cholesky of A ~ 1e-2 kg m^2, entries O(1..100)): round-off ~ 1e-12 relative.
const QDD_TOL: f64 = 1e-9;

fn five_bar() -> Mechanism {
    shipped("five-bar.yaml")
}

fn point(mech: &Mechanism, name: &str) -> [f64; 2] {
    mech.points.iter().find(|(n, _)| n == name).unwrap().1
}

/// The end effector at q in a fresh workspace (positions by continuation from the drawing).
fn pose_at(mech: &Mechanism, ee: &Effector, q: &[f64]) -> Vec<f64> {
    ee.state(mech, q, &mut Workspace::new(mech)).unwrap().pose
}

#[test]
fn task_jacobian_and_convective_term_match_finite_differences() {
    for (file, point) in [("five-bar.yaml", "P"), ("3-rrr.yaml", "P")] {
        let mech = shipped(file);
        let ee = Effector::new(&mech, point, None).unwrap();
        let m = mech.dof();
        let q: Vec<f64> = mech.drawn_q().iter().map(|v| v + 0.05).collect();
        let qd: Vec<f64> = (0..m).map(|j| 0.5 + 0.7 * j as f64 / (m - 1) as f64).collect();
        let mut ws = Workspace::new(&mech);
        let st = ee.state(&mech, &q, &mut ws).unwrap();
        let h = 1e-6;
        for j in 0..m {
            let shifted = |s: f64| {
                let mut qs = q.clone();
                qs[j] += s * h;
                pose_at(&mech, &ee, &qs)
            };
            let (plus, minus) = (shifted(1.0), shifted(-1.0));
            for r in 0..m {
                let fd = (plus[r] - minus[r]) / (2.0 * h);
                let err = (st.jt[r * m + j] - fd).abs();
                assert!(err < FD_TOL, "{file}: J[{r}][{j}] = {} vs {fd} (error {err:.1e})", st.jt[r * m + j]);
            }
        }
        // d2/dt2 X(q + qd t) at t = 0 is J_t' qd.
        convective(&mech, &qd, &mut ws);
        let conv = ee.convective(&ws);
        let h = 1e-4;
        let along = |s: f64| pose_at(&mech, &ee, &q.iter().zip(&qd).map(|(a, b)| a + s * h * b).collect::<Vec<_>>());
        let (plus, minus) = (along(1.0), along(-1.0));
        for r in 0..m {
            let fd = (plus[r] - 2.0 * st.pose[r] + minus[r]) / (h * h);
            assert!((conv[r] - fd).abs() < FD2_TOL, "{file}: J_t' qd [{r}] = {} vs {fd}", conv[r]);
        }
    }
}

/// The five-bar's inputs for end effector P in closed form: the elbow C_i is where the circle
/// of the proximal link (centre A_i, radius |A_i C_i|) meets that of the distal link (centre
/// P, radius |C_i P|), on the same side of A_i P as in the drawing; theta_i = atan2(C_i - A_i).
fn five_bar_closed_form(mech: &Mechanism, p: [f64; 2]) -> [f64; 2] {
    let side = |a: [f64; 2], c: [f64; 2], p: [f64; 2]| {
        ((p[0] - a[0]) * (c[1] - a[1]) - (p[1] - a[1]) * (c[0] - a[0])).signum()
    };
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let p0 = point(mech, "P");
    let mut q = [0.0; 2];
    for (k, (a, c)) in [("A1", "C1"), ("A2", "C2")].into_iter().enumerate() {
        let (a, c0) = (point(mech, a), point(mech, c));
        let (r1, r2, d) = (dist(a, c0), dist(c0, p0), dist(a, p));
        let along = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
        let off = (r1 * r1 - along * along).sqrt();
        let (ex, ey) = ((p[0] - a[0]) / d, (p[1] - a[1]) / d);
        let sign = side(a, c0, p0);
        // (A -> P) x (-ey, ex) = +1: the side whose cross product has the drawing's sign.
        let c = [a[0] + along * ex - sign * off * ey, a[1] + along * ey + sign * off * ex];
        assert_eq!(side(a, c, p), sign);
        q[k] = (c[1] - a[1]).atan2(c[0] - a[0]).rem_euclid(2.0 * PI);
    }
    q
}

#[test]
fn five_bar_inverse_kinematics_matches_the_circle_intersections() {
    let mech = five_bar();
    let ee = Effector::new(&mech, "P", None).unwrap();
    let p0 = point(&mech, "P");
    let drawn = five_bar_closed_form(&mech, p0);
    assert!(drawn.iter().zip(mech.drawn_q()).all(|(a, b)| (a - b).abs() < 1e-12), "{drawn:?}");
    // One workspace for all targets: each solve continues from the last one's body coordinates.
    let mut ws = Workspace::new(&mech);
    for target in [[0.05, 0.40], [-0.06, 0.48], [0.10, 0.35], [0.0, 0.30]] {
        let st = ee.reach(&mech, &target, &mech.drawn_q(), &mut ws).unwrap();
        let exact = five_bar_closed_form(&mech, target);
        for k in 0..2 {
            assert!((st.q[k] - exact[k]).abs() < IK_Q_TOL, "P = {target:?}: q = {:?}, closed form {exact:?}", st.q);
        }
        assert!((st.pose[0] - target[0]).abs() < 1e-11 && (st.pose[1] - target[1]).abs() < 1e-11);
        assert!(st.sigma_i > SINGULAR_TOL && st.condition >= 1.0);
    }
}

/// The entry points that make their own frame (what a binding calls): `reach_from` and
/// `solve_from` land on the closed form's inputs, the body coordinates they return put P on
/// the target, and `state_at` / `convective_at` at those x give what a frame carried there gives.
#[test]
fn frame_free_entry_points_match_the_closed_form() {
    let mech = five_bar();
    let ee = Effector::new(&mech, "P", None).unwrap();
    let target = [0.05, 0.40];
    let exact = five_bar_closed_form(&mech, target);
    let reached = ee.reach_from(&mech, &target, None, None).unwrap();
    let guess: Vec<f64> = reached.state.q.iter().map(|v| v + 0.01).collect();
    let solved = ee.solve_from(&mech, &target, &guess, Some(&reached.x)).unwrap();
    for r in [&reached, &solved] {
        for k in 0..2 {
            assert!((r.state.q[k] - exact[k]).abs() < IK_Q_TOL, "q = {:?}, closed form {exact:?}", r.state.q);
        }
        // IK_TOL: the scaled task residual at which Newton stops (L ~ 1 m here).
        let p = ee.pose(&r.x);
        assert!((p[0] - target[0]).abs() < 1e-11 && (p[1] - target[1]).abs() < 1e-11, "{p:?}");
    }
    // At the same body coordinates the same state, bit for bit: one code path.
    let (at_x, mut frame) = ee.state_at(&mech, &reached.x).unwrap();
    let from_q = ee.state_from(&mech, &at_x.q, Some(&reached.x)).unwrap();
    assert_eq!((&at_x.jt, &at_x.pose), (&from_q.state.jt, &from_q.state.pose));
    let qd = [0.5, -1.2];
    convective(&mech, &qd, &mut frame);
    assert_eq!(ee.convective_at(&mech, &reached.x, &qd).unwrap(), ee.convective(&frame));
}

struct Given(Vec<f64>);
impl Drives for Given {
    fn efforts(&mut self, _t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.copy_from_slice(&self.0);
        Ok(())
    }
}

#[test]
fn efforts_along_a_path_reproduce_its_accelerations_in_forward_dynamics() {
    let mech = five_bar();
    let p0 = point(&mech, "P");
    // A circle of radius 5 cm through the drawn P, once round in 1 s (x, xd, xdd exact).
    let (r, w) = (0.05, 2.0 * PI);
    let t: Vec<f64> = (0..=250).map(|i| i as f64 * 0.004).collect();
    let (mut x, mut xd, mut xdd) = (vec![], vec![], vec![]);
    for &ti in &t {
        let (c, s) = ((w * ti).cos(), (w * ti).sin());
        x.extend([p0[0] + r * (c - 1.0), p0[1] + r * s]);
        xd.extend([-r * w * s, r * w * c]);
        xdd.extend([-r * w * w * c, -r * w * w * s]);
    }
    let path = TaskPath { t, x, xd, xdd, point: "P".into(), body: None, q_start: None, singular_tol: SINGULAR_TOL };
    let sol = solve(&mech, &path).unwrap();
    let ee = Effector::new(&mech, "P", None).unwrap();
    let mut ws = Workspace::new(&mech);
    for i in (0..path.t.len()).step_by(25) {
        let row = 2 * i..2 * i + 2;
        let (q, qd) = (&sol.q[row.clone()], &sol.qd[row.clone()]);
        // On the path: P at the solved inputs, and the inputs equal the closed form.
        let exact = five_bar_closed_form(&mech, [path.x[2 * i], path.x[2 * i + 1]]);
        assert!(q.iter().zip(exact).all(|(a, b)| (a - b).abs() < IK_Q_TOL), "sample {i}: {q:?} vs {exact:?}");
        assemble_into(&mech, q, &mut ws).unwrap();
        forward(&mech, path.t[i], q, qd, &mut Given(sol.tau[row.clone()].to_vec()), &mut ws).unwrap();
        for k in 0..2 {
            let want = sol.qdd[2 * i + k];
            assert!((ws.qdd[k] - want).abs() < QDD_TOL * (1.0 + want.abs()), "sample {i}: {:?} vs {want}", ws.qdd);
        }
        // The rates move P along the path: J_t qd = Xd.
        let st = ee.state(&mech, q, &mut ws).unwrap();
        for k in 0..2 {
            let v: f64 = (0..2).map(|j| st.jt[2 * k + j] * qd[j]).sum();
            assert!((v - path.xd[2 * i + k]).abs() < 1e-12, "sample {i}");
        }
    }
}
