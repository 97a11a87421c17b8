//! Beyond four coordinates the closed forms write each column of U over the pieces its
//! coordinate moves (`ColumnReach`) and the mass matrix sums each entry over the bodies both
//! columns reach (`System::a_runs`): checked against finite differences of the positions, the
//! dense U^T M U, and the few-coordinate path of one copy (benchmarks/families.py's ladder and
//! five-bars, written here again so that the crate's tests stand alone).

mod common;
use common::*;
use planardyn::dynamics::query::{self, ForwardState};
use planardyn::kinematics::{ClosedForm, Frame};
use planardyn::Mechanism;

/// The ladder's rods' spacing, rods' and links' lengths (m).
const GAP: f64 = 0.3;
const ROD: f64 = 0.2;
const LINK: f64 = 0.25;

/// How far below the rods' tips a dyad's middle joint hangs (m).
fn depth() -> f64 {
    (LINK * LINK - (GAP / 2.0) * (GAP / 2.0)).sqrt()
}

/// A uniform bar from a to b of `mass` (kg) as a body's mass, inertia and centre of mass.
fn bar(a: [f64; 2], b: [f64; 2], mass: f64) -> String {
    let l2 = (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2);
    format!(
        "mass: {mass}, inertia: {:?}, com: [{:?}, {:?}]",
        mass * l2 / 12.0,
        (a[0] + b[0]) / 2.0,
        (a[1] + b[1]) / 2.0
    )
}

/// `2n` rods hanging from the ground 0.3 m apart, consecutive tips joined by a dyad of two
/// 0.25 m links (benchmarks/families.py `ladder`): 2n coordinates, each dyad coupling two.
fn ladder(n: usize) -> Mechanism {
    let (gap, rod, depth) = (GAP, ROD, depth());
    let (mut points, mut bodies, mut pairs, mut coords) = (String::new(), String::new(), String::new(), String::new());
    let mut at = std::collections::HashMap::new();
    for i in 0..2 * n {
        let (o, c) = ([gap * i as f64, 0.0], [gap * i as f64, -rod]);
        at.insert(format!("C{i}"), c);
        points += &format!("  O{i}: [{:?}, 0.0]\n  C{i}: [{:?}, {:?}]\n", o[0], c[0], c[1]);
        bodies += &format!("  rod{i}: {{points: [O{i}, C{i}], {}}}\n", bar(o, c, rod));
        pairs += &format!("  - {{type: revolute, name: g{i}, at: O{i}, bodies: [ground, rod{i}]}}\n");
        coords += &format!("  - {{name: t{i}, pair: g{i}, value: {:?}}}\n", -std::f64::consts::FRAC_PI_2);
    }
    for i in 0..2 * n - 1 {
        let p = [gap * (i as f64 + 0.5), -rod - depth];
        points += &format!("  P{i}: [{:?}, {:?}]\n", p[0], p[1]);
        for (side, tip) in [("l", i), ("r", i + 1)] {
            bodies += &format!("  {side}{i}: {{points: [C{tip}, P{i}], {}}}\n", bar(at[&format!("C{tip}")], p, LINK));
            pairs += &format!("  - {{type: revolute, at: C{tip}, bodies: [rod{tip}, {side}{i}]}}\n");
        }
        pairs += &format!("  - {{type: revolute, at: P{i}, bodies: [l{i}, r{i}]}}\n");
    }
    let ground: Vec<String> = (0..2 * n).map(|i| format!("O{i}")).collect();
    yaml(&format!(
        "name: ladder\nunits: SI\ngravity: [0, -9.81]\npoints:\n{points}ground: [{}]\nbodies:\n{bodies}pairs:\n{pairs}coordinates:\n{coords}",
        ground.join(", ")
    ))
}

/// A pose away from the drawing (each rod turned by its own amount), within the workspace.
fn pose(mech: &Mechanism) -> Vec<f64> {
    mech.drawn_q().iter().enumerate().map(|(i, q)| q + 0.05 * (i as f64 + 1.0).sin()).collect()
}

/// The closed forms' x and U at q.
fn closed_form_u(mech: &Mechanism, q: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut closed = ClosedForm::new(mech).expect("dyads and cranks: closed forms");
    let mut frame = Frame::new(mech);
    closed.set_reference(&mech.x0);
    closed.positions(q, &mut frame).unwrap();
    closed.velocity_analogues(&mut frame);
    (frame.x.clone(), frame.u.clone())
}

/// Central differences with step H of x(q) have truncation error H^2/6 |x'''| (about 1e-12
/// here: links of 0.2 m, rates of order 1) and round-off eps |x| / H (about 1e-10): 1e-8 holds
/// both with a margin and fails on any wrong column entry (entries are of order 0.1).
const H: f64 = 1e-6;
const FD_TOL: f64 = 1e-8;
/// The same sums in another order (dense U^T M U against the pattern's runs): round-off of a
/// few additions of entries of order 0.01 kg m^2.
const SUM_TOL: f64 = 1e-14;

#[test]
fn beyond_four_coordinates_each_column_of_u_is_the_derivative_of_the_positions() {
    let mech = ladder(3);
    let m = mech.dof();
    assert_eq!(m, 6, "six coordinates: the per-column path");
    let q = pose(&mech);
    let (x, u) = closed_form_u(&mech, &q);
    let n = x.len();
    for j in 0..m {
        let mut plus = q.clone();
        let mut minus = q.clone();
        plus[j] += H;
        minus[j] -= H;
        let (xp, _) = closed_form_u(&mech, &plus);
        let (xm, _) = closed_form_u(&mech, &minus);
        for i in 0..n {
            let fd = (xp[i] - xm[i]) / (2.0 * H);
            assert!((u[j * n + i] - fd).abs() < FD_TOL, "U[{i}, {j}] = {} vs {fd}", u[j * n + i]);
        }
    }
    // The Newton path's analogues (J^-1, not the closed forms) agree too.
    let report = query::kinematics(&mech, &q, None, None).unwrap();
    for (i, (a, b)) in report.x.iter().zip(&x).enumerate() {
        assert!((a - b).abs() < FD_TOL, "x[{i}]: {a} vs {b}");
    }
    for i in 0..n {
        for j in 0..m {
            let (a, b) = (report.u[i * m + j], u[j * n + i]);
            assert!((a - b).abs() < FD_TOL, "U[{i}, {j}]: report {a} vs closed forms {b}");
        }
    }
}

#[test]
fn beyond_four_coordinates_the_mass_matrix_is_the_dense_product() {
    let mech = ladder(3);
    let (m, q) = (mech.dof(), pose(&mech));
    let a = query::mass_matrix(&mech, &q, None, false).unwrap();
    let report = query::kinematics(&mech, &q, None, None).unwrap();
    let mut zero_pairs = 0;
    for j in 0..m {
        for k in 0..m {
            let dense: f64 = mech
                .bodies
                .iter()
                .enumerate()
                .map(|(b, body)| {
                    let uu = |r: usize, c: usize| report.u[r * m + c];
                    let (x, y, p) = (3 * b, 3 * b + 1, 3 * b + 2);
                    body.mass * (uu(x, j) * uu(x, k) + uu(y, j) * uu(y, k)) + body.inertia * uu(p, j) * uu(p, k)
                })
                .sum();
            assert!((a[j * m + k] - dense).abs() < SUM_TOL, "A[{j}, {k}] = {} vs {dense}", a[j * m + k]);
            // Rods two apart share no body: an exact zero, not a small number.
            if j.abs_diff(k) > 1 {
                assert_eq!(a[j * m + k], 0.0, "A[{j}, {k}]");
                zero_pairs += 1;
            }
        }
    }
    assert_eq!(zero_pairs, 20, "the ladder's A is tridiagonal (6 x 6: 20 entries off the band)");
}

#[test]
fn separate_five_bars_have_the_mass_matrix_of_one_in_each_block() {
    // Three copies of one five-bar side by side (the ladder's first loop, n = 1, is a
    // five-bar): A is block-diagonal, each block the single five-bar's A, which its two
    // coordinates compute on the fixed-size path.
    let one = ladder(1);
    let text_one = |dx: f64, k: usize| {
        let (gap, rod, depth) = (GAP, ROD, depth());
        let (o0, o1) = ([dx, 0.0], [dx + gap, 0.0]);
        let (c0, c1, p) = ([dx, -rod], [dx + gap, -rod], [dx + gap / 2.0, -rod - depth]);
        (
            format!(
                "  O0_{k}: [{:?}, 0.0]\n  O1_{k}: [{:?}, 0.0]\n  C0_{k}: [{:?}, {:?}]\n  C1_{k}: [{:?}, {:?}]\n  P_{k}: [{:?}, {:?}]\n",
                o0[0], o1[0], c0[0], c0[1], c1[0], c1[1], p[0], p[1]
            ),
            format!(
                "  rod0_{k}: {{points: [O0_{k}, C0_{k}], {}}}\n  rod1_{k}: {{points: [O1_{k}, C1_{k}], {}}}\n  l_{k}: {{points: [C0_{k}, P_{k}], {}}}\n  r_{k}: {{points: [C1_{k}, P_{k}], {}}}\n",
                bar(o0, c0, rod), bar(o1, c1, rod), bar(c0, p, LINK), bar(c1, p, LINK)
            ),
            format!(
                "  - {{type: revolute, name: g0_{k}, at: O0_{k}, bodies: [ground, rod0_{k}]}}\n  - {{type: revolute, name: g1_{k}, at: O1_{k}, bodies: [ground, rod1_{k}]}}\n  - {{type: revolute, at: C0_{k}, bodies: [rod0_{k}, l_{k}]}}\n  - {{type: revolute, at: C1_{k}, bodies: [rod1_{k}, r_{k}]}}\n  - {{type: revolute, at: P_{k}, bodies: [l_{k}, r_{k}]}}\n"
            ),
            format!(
                "  - {{name: a_{k}, pair: g0_{k}, value: {:?}}}\n  - {{name: b_{k}, pair: g1_{k}, value: {:?}}}\n",
                -std::f64::consts::FRAC_PI_2,
                -std::f64::consts::FRAC_PI_2
            ),
            format!("O0_{k}, O1_{k}"),
        )
    };
    let parts: Vec<_> = (0..3).map(|k| text_one(0.6 * k as f64, k)).collect();
    let cat = |f: fn(&(String, String, String, String, String)) -> &String, sep: &str| {
        parts.iter().map(f).cloned().collect::<Vec<_>>().join(sep)
    };
    let three = yaml(&format!(
        "name: three five-bars\nunits: SI\ngravity: [0, -9.81]\npoints:\n{}ground: [{}]\nbodies:\n{}pairs:\n{}coordinates:\n{}",
        cat(|p| &p.0, ""),
        cat(|p| &p.4, ", "),
        cat(|p| &p.1, ""),
        cat(|p| &p.2, ""),
        cat(|p| &p.3, "")
    ));
    let q1 = pose(&one);
    let a1 = query::mass_matrix(&one, &q1, None, false).unwrap();
    let q3: Vec<f64> = (0..3).flat_map(|_| q1.clone()).collect();
    let a3 = query::mass_matrix(&three, &q3, None, false).unwrap();
    for j in 0..6 {
        for k in 0..6 {
            let want = if j / 2 == k / 2 { a1[(j % 2) * 2 + k % 2] } else { 0.0 };
            assert!((a3[j * 6 + k] - want).abs() < SUM_TOL, "A[{j}, {k}] = {} vs {want}", a3[j * 6 + k]);
            if j / 2 != k / 2 {
                assert_eq!(a3[j * 6 + k], 0.0, "A[{j}, {k}] off the blocks");
            }
        }
    }
}

#[test]
fn beyond_four_coordinates_u_is_zero_outside_each_columns_runs_of_bodies() {
    // The products U zd, U^T f, U^T M c and U zdd run each column over its runs of bodies
    // only (`System::u_support`): U must be exactly zero elsewhere, and the runs must be the
    // ladder's few bodies per coordinate (rod j, and the two links of each dyad it carries:
    // 5 bodies inside, 3 at the ends), not a range across the body order.
    let mech = ladder(4);
    let (m, q) = (mech.dof(), pose(&mech));
    let ws = query::forward_at(
        &mech,
        ForwardState { q: &q, qd: &vec![0.0; m], t: 0.0, tau: None, allow_singular: false, x_start: None },
    )
    .unwrap();
    let (n, support) = (ws.x.len(), ws.frame.sys.u_support());
    assert_eq!(support.len(), m);
    for j in 0..m {
        let bodies: usize = support.runs(j).iter().map(|(first, end)| end - first).sum();
        assert_eq!(bodies, if j == 0 || j == m - 1 { 3 } else { 5 }, "column {j}: {:?}", support.runs(j));
        let mut inside = vec![false; n];
        support.rows(j).flatten().for_each(|i| inside[i] = true);
        for i in (0..n).filter(|&i| !inside[i]) {
            assert_eq!(ws.frame.u[j * n + i], 0.0, "U[{i}, {j}] outside the runs");
        }
    }
}

/// The ladder's accelerations against the dense formulas: a relative 1e-12 is round-off of
/// sums over a few dozen bodies and of a Cholesky solve of a well-conditioned 8 x 8 A (its
/// entries of order 0.01 kg m^2, qdd of order 100 rad/s^2), far below any missing term.
const DENSE_TOL: f64 = 1e-12;

#[test]
fn ladder_accelerations_are_the_dense_solution_and_inverse_dynamics_gives_zero_effort() {
    // qdd = (U^T M U)^-1 U^T (f - M c) with every sum over all bodies (nalgebra's LU), against
    // the evaluation over the runs of U and A's envelope; then the passive ladder's inverse
    // dynamics at that qdd is zero effort.
    let mech = ladder(4);
    let m = mech.dof();
    let q = pose(&mech);
    let qd: Vec<f64> = (0..m).map(|j| 0.7 * (j as f64 + 0.3).cos()).collect();
    let ws = query::forward_at(
        &mech,
        ForwardState { q: &q, qd: &qd, t: 0.0, tau: None, allow_singular: false, x_start: None },
    )
    .unwrap();
    let n = ws.x.len();
    let (u, c, f) = (&ws.frame.u, &ws.frame.c, &ws.f);
    let mass = |i: usize| if i % 3 == 2 { mech.bodies[i / 3].inertia } else { mech.bodies[i / 3].mass };
    let a = nalgebra::DMatrix::<f64>::from_fn(m, m, |j, k| (0..n).map(|i| mass(i) * u[j * n + i] * u[k * n + i]).sum());
    let b = nalgebra::DVector::<f64>::from_fn(m, |j, _| (0..n).map(|i| u[j * n + i] * (f[i] - mass(i) * c[i])).sum());
    let dense: nalgebra::DVector<f64> = a.lu().solve(&b).unwrap();
    let scale = dense.amax();
    assert!(scale > 1.0, "a real acceleration: {scale}");
    for j in 0..m {
        assert!((ws.qdd[j] - dense[j]).abs() < DENSE_TOL * scale, "qdd[{j}] = {} vs dense {}", ws.qdd[j], dense[j]);
    }
    // xdd = U qdd + c over all rows.
    for i in 0..n {
        let want = c[i] + (0..m).map(|j| u[j * n + i] * ws.qdd[j]).sum::<f64>();
        assert!((ws.xdd[i] - want).abs() < DENSE_TOL * scale, "xdd[{i}] = {} vs {want}", ws.xdd[i]);
    }
    // tau = U^T (M xdd - f): zero for the passive ladder, to the round-off of b (|f| ~ 1 N).
    let tau = query::inverse_dynamics(&mech, &q, &qd, &ws.qdd, None).unwrap();
    let b_scale = b.amax();
    for (j, t) in tau.iter().enumerate() {
        assert!(t.abs() < DENSE_TOL * b_scale.max(1.0), "tau[{j}] = {t}");
    }
}

/// qdd of the ODE's closed-form evaluation against the general path's (Newton, J's factor),
/// relative to the largest entry: as tests/closed_form.rs's REL_TOL (measured worst there
/// 1.4e-11, where b is a difference of terms 10 times larger than itself).
const ODE_REL_TOL: f64 = 1e-10;

#[test]
fn the_odes_derivative_is_the_rates_the_accelerations_and_the_power_for_two_to_eight_coordinates() {
    // `MechanismOde::derivative` copies with m a constant up to 4 coordinates and through
    // `derivative_of` beyond: ladders of 2, 4, 6 and 8 coordinates take both. dy = [zd, qdd, P]:
    // zd the state's rates to the bit, qdd the general path's at the same state, P the power of
    // the non-conservative forces (none in the ladder: zero).
    use planardyn::dynamics::{forward, ModelDrives};
    use planardyn::integrate::OdeSystem;
    use planardyn::kinematics::assemble_into;
    use planardyn::Workspace;
    for n in 1..=4 {
        let mech = ladder(n);
        let m = mech.dof();
        let mut drives = ModelDrives(&mech);
        let (mut ode, mut y) = common::ode::at_drawing(&mech, &mut drives);
        y[..m].iter_mut().enumerate().for_each(|(j, v)| *v += 1e-3 * (j as f64 + 1.0));
        y[m..2 * m].iter_mut().enumerate().for_each(|(j, v)| *v = 0.5 - 0.2 * j as f64);
        let mut dy = vec![f64::NAN; 2 * m + 1];
        ode.rhs(0.0, &y, &mut dy).unwrap_or_else(|e| panic!("m = {m}: {e}"));
        assert_eq!(dy[..m], y[m..2 * m], "m = {m}: the rates");
        let mut general = Workspace::new(&mech);
        assemble_into(&mech, &y[..m], &mut general).unwrap();
        forward(&mech, 0.0, &y[..m], &y[m..2 * m], &mut ModelDrives(&mech), &mut general).unwrap();
        let scale = general.qdd.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        assert!(scale > 1.0, "m = {m}: a real acceleration ({scale})");
        for j in 0..m {
            let d = (dy[m + j] - general.qdd[j]).abs();
            assert!(d < ODE_REL_TOL * scale, "m = {m}: qdd[{j}] {} vs {}", dy[m + j], general.qdd[j]);
        }
        assert_eq!(dy[2 * m], 0.0, "m = {m}: the power of a passive ladder without losses");
    }
}
