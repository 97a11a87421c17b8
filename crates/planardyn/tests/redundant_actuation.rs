//! Redundant actuation: a 5R robot with a third actuated leg (2 degrees of freedom, 3
//! actuators; with its left and middle elbows actuated too, 5), its efforts shared by minimum
//! norm, min-max and a preload.

mod common;

use common::yaml;
use planardyn::dynamics::motor_torques;
use planardyn::dynamics::redundant::{forward_redundant, inverse_redundant, Distribution};
use planardyn::{Mechanism, Workspace};

/// The five-bar of examples/models/five-bar.yaml (without its PD springs) with a third leg
/// A3 -> C3 -> P (0.25 m and 0.35 m) whose base pivot is actuated.
fn three_legs() -> Mechanism {
    yaml(&three_legs_yaml("  - {pair: motor3}\n"))
}

/// The same with the elbows elbow1 and elbow3 actuated too: 5 actuators, 3 internal forces.
fn three_legs_actuated_elbows() -> Mechanism {
    yaml(&three_legs_yaml("  - {pair: motor3}\n  - {pair: elbow1}\n  - {pair: elbow3}\n"))
}

/// Gear ratio, efficiency, rotor inertia (kg m^2), viscous (N m s/rad) and Coulomb (N m)
/// friction of the geared motors on theta1 and theta2 in [`three_legs_geared`].
const GEAR: (f64, f64, f64, f64, f64) = (20.0, 0.8, 2e-5, 1e-4, 0.01);

/// The three-legged five-bar with geared motors on its two coordinates.
fn three_legs_geared() -> Mechanism {
    let (n, eta, j, c, tc) = GEAR;
    let motor = |q: &str| {
        format!(
            "  - {{coordinate: {q}, gear_ratio: {n}, efficiency: {eta}, rotor_inertia: {j}, viscous: {c}, coulomb: {tc}}}\n"
        )
    };
    yaml(&three_legs_yaml(&(motor("theta1") + &motor("theta2") + "  - {pair: motor3}\n")))
}

fn three_legs_yaml(actuators: &str) -> String {
    r#"
name: 5R with a third actuated leg
gravity: [0.0, -9.81]
points:
  A1: [-0.15, 0.0]
  A2: [0.15, 0.0]
  A3: [0.0, 0.0]
  C1: [-0.25565456543517484, 0.2265769467591625]
  C2: [0.275, 0.21650635094610965]
  C3: [0.1983444079681374, 0.1521824425739351]
  P: [0.014002680494367873, 0.44970240410926887]
ground: [A1, A2, A3]
bodies:
  proximal_left: {points: [A1, C1], uniform_bar: [A1, C1], mass: 0.5}
  proximal_right: {points: [A2, C2], uniform_bar: [A2, C2], mass: 0.5}
  proximal_mid: {points: [A3, C3], uniform_bar: [A3, C3], mass: 0.5}
  distal_left:
    points: [C1, P]
    parts: [{uniform_bar: [C1, P], mass: 0.7}, {point_mass: P, mass: 0.3}]
  distal_right: {points: [C2, P], uniform_bar: [C2, P], mass: 0.7}
  distal_mid: {points: [C3, P], uniform_bar: [C3, P], mass: 0.7}
pairs:
  - {type: revolute, name: motor1, at: A1, bodies: [ground, proximal_left]}
  - {type: revolute, name: elbow1, at: C1, bodies: [proximal_left, distal_left]}
  - {type: revolute, name: effector, at: P, bodies: [distal_left, distal_right]}
  - {type: revolute, name: elbow2, at: C2, bodies: [proximal_right, distal_right]}
  - {type: revolute, name: motor2, at: A2, bodies: [ground, proximal_right]}
  - {type: revolute, name: motor3, at: A3, bodies: [ground, proximal_mid]}
  - {type: revolute, name: elbow3, at: C3, bodies: [proximal_mid, distal_mid]}
  - {type: revolute, name: effector3, at: P, bodies: [distal_left, distal_mid]}
coordinates:
  - {name: theta1, pair: motor1, value: 2.007128639793479}
  - {name: theta2, pair: motor2, value: 1.0471975511965976}
actuators:
"#
    .to_owned()
        + actuators
}

/// A point of a motion near the drawing.
fn point(mech: &Mechanism) -> ([f64; 2], [f64; 2], [f64; 2]) {
    let (q0, _) = mech.initial_state();
    ([q0[0] + 0.05, q0[1] - 0.04], [1.2, -0.7], [3.0, 5.0])
}

#[test]
fn min_norm_efforts_are_the_least_squares_solution() {
    let mech = three_legs();
    let (q, qd, qdd) = point(&mech);
    let mut ws = Workspace::new(&mech);
    let (act, tau) = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::MinNorm, &mut ws).unwrap();
    assert_eq!((act.m, act.n_a, act.internal.len()), (2, 3, 1));
    // Independently: tau = B^T (B B^T)^-1 f, the 2 x 2 system solved by Cramer's rule.
    let (b, f) = (&act.b, &ws.tau);
    let g = |i: usize, j: usize| (0..3).map(|a| b[i * 3 + a] * b[j * 3 + a]).sum::<f64>();
    let det = g(0, 0) * g(1, 1) - g(0, 1) * g(1, 0);
    let y = [(f[0] * g(1, 1) - f[1] * g(0, 1)) / det, (g(0, 0) * f[1] - g(1, 0) * f[0]) / det];
    for a in 0..3 {
        let expected = b[a] * y[0] + b[3 + a] * y[1];
        assert!((tau[a] - expected).abs() <= 1e-12 * (1.0 + expected.abs()), "{a}: {} vs {expected}", tau[a]);
    }
    // The internal force moves nothing: B v = 0, |v| = 1.
    let v = &act.internal[0];
    for j in 0..2 {
        assert!((0..3).map(|a| b[j * 3 + a] * v[a]).sum::<f64>().abs() <= 1e-13);
    }
    assert!(((v.iter().map(|x| x * x).sum::<f64>()) - 1.0).abs() <= 1e-14);
}

#[test]
fn distributed_efforts_reproduce_the_motion_in_forward_dynamics() {
    let mech = three_legs();
    let (q, qd, qdd) = point(&mech);
    for how in [Distribution::MinNorm, Distribution::MinMax, Distribution::Preload(vec![4.0])] {
        let mut ws = Workspace::new(&mech);
        let (_, efforts) = inverse_redundant(&mech, &q, &qd, &qdd, &how, &mut ws).unwrap();
        forward_redundant(&mech, 0.0, &q, &qd, &efforts, &mut ws).unwrap();
        for k in 0..2 {
            assert!((ws.qdd[k] - qdd[k]).abs() <= 1e-10 * qdd[k].abs(), "{how:?}: qdd {:?} vs {qdd:?}", ws.qdd);
        }
    }
}

#[test]
fn min_max_is_the_least_largest_effort() {
    let mech = three_legs();
    let (q, qd, qdd) = point(&mech);
    let mut ws = Workspace::new(&mech);
    let (act, mm) = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::MinMax, &mut ws).unwrap();
    let (_, mn) = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::MinNorm, &mut ws).unwrap();
    let largest = |t: &[f64]| t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // A scan of lambda over +-50 N m in 1e-4 steps never does better (to the step's error).
    let v = &act.internal[0];
    let scanned = (-500_000..=500_000)
        .map(|i| {
            let l = i as f64 * 1e-4;
            largest(&mn.iter().zip(v).map(|(t, v)| t + l * v).collect::<Vec<_>>())
        })
        .fold(f64::INFINITY, f64::min);
    assert!(largest(&mm) <= scanned + 1e-12 && scanned - largest(&mm) <= 1e-4, "{} vs {scanned}", largest(&mm));
    assert!(largest(&mm) <= largest(&mn));
    // The closed form with one internal force v: max_a |t_a + lambda v_a| is convex and
    // piecewise linear in lambda, least where two of its lines t_a + lambda v_a and
    // +-(t_b + lambda v_b) cross; the least over every crossing.
    let worst = |l: f64| largest(&mn.iter().zip(v).map(|(t, v)| t + l * v).collect::<Vec<_>>());
    let (t, v) = (&mn, v);
    let closed = (0..3)
        .flat_map(|a| (0..3).flat_map(move |b| [(t[a] - t[b], v[a] - v[b]), (t[a] + t[b], v[a] + v[b])]))
        .filter(|(_, den)| *den != 0.0)
        .map(|(num, den)| worst(-num / den))
        .fold(largest(&mn), f64::min);
    assert!((largest(&mm) - closed).abs() <= 1e-13 * closed, "LP {} vs closed form {closed}", largest(&mm));
}

#[test]
fn min_max_with_three_internal_forces() {
    let mech = three_legs_actuated_elbows();
    let (q, qd, qdd) = point(&mech);
    let mut ws = Workspace::new(&mech);
    let (act, mm) = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::MinMax, &mut ws).unwrap();
    assert_eq!((act.n_a, act.internal.len()), (5, 3));
    let largest = |t: &[f64]| t.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // The drive map holds: B tau = the generalized efforts, to round-off.
    for j in 0..2 {
        let f: f64 = (0..5).map(|a| act.b[j * 5 + a] * mm[a]).sum();
        assert!((f - ws.tau[j]).abs() <= 1e-12 * (1.0 + ws.tau[j].abs()), "row {j}: {f} vs {}", ws.tau[j]);
    }
    // Optimality (LP duality): at the optimum s the efforts at +-s (the active set) admit
    // weights y_a >= 0, one per active effort, with sum_a y_a sgn(tau_a) N_a = 0 and
    // sum y_a = 1. Here the optimum equalises 4 of the 5 efforts (3 internal forces + s).
    let s = largest(&mm);
    let active: Vec<usize> = (0..5).filter(|&a| (mm[a].abs() - s).abs() <= 1e-12 * s).collect();
    assert_eq!(active.len(), 4, "efforts {mm:?}");
    // Solve for y in the 4 x 4 system [sgn_a N_a^T; 1] y = [0; 1] by Gaussian elimination.
    let mut m4: Vec<[f64; 5]> = (0..4)
        .map(|r| {
            let mut row = [0.0; 5];
            for (c, &a) in active.iter().enumerate() {
                row[c] = if r < 3 { mm[a].signum() * act.internal[r][a] } else { 1.0 };
            }
            row[4] = f64::from(r == 3);
            row
        })
        .collect();
    for c in 0..4 {
        let p = (c..4).max_by(|&i, &j| m4[i][c].abs().total_cmp(&m4[j][c].abs())).unwrap();
        m4.swap(c, p);
        let pivot = m4[c];
        for (_, row) in m4.iter_mut().enumerate().filter(|(r, _)| *r != c) {
            let k = row[c] / pivot[c];
            row.iter_mut().zip(pivot).for_each(|(x, p)| *x -= k * p);
        }
    }
    let y: Vec<f64> = (0..4).map(|c| m4[c][4] / m4[c][c]).collect();
    assert!(y.iter().all(|&y| y >= 0.0), "dual weights {y:?}: not optimal");
    // And the drives reproduce the motion.
    forward_redundant(&mech, 0.0, &q, &qd, &mm, &mut ws).unwrap();
    for k in 0..2 {
        assert!((ws.qdd[k] - qdd[k]).abs() <= 1e-10 * qdd[k].abs(), "qdd {:?} vs {qdd:?}", ws.qdd);
    }
    let (_, mn) = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::MinNorm, &mut ws).unwrap();
    assert!(s < largest(&mn));
}

#[test]
fn the_smallest_sign_keeping_preload_found_by_bisection() {
    let mech = three_legs();
    let (q, qd, qdd) = point(&mech);
    let mut ws = Workspace::new(&mech);
    let (act, mn) = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::MinNorm, &mut ws).unwrap();
    let v = act.internal[0].clone();
    assert!(v.iter().all(|x| x.abs() > 1e-3), "every actuator takes part in the internal force: {v:?}");
    // Efforts keep the signs of the internal force v (backlash-free) once the preload
    // lambda is large enough; bisect on lambda for the smallest.
    let keeps = |l: f64| {
        let (_, t) = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::Preload(vec![l]), &mut ws.clone()).unwrap();
        t.iter().zip(&v).all(|(t, v)| t * v > 0.0)
    };
    let (mut lo, mut hi) = (-1e3, 1e3);
    assert!(!keeps(lo) && keeps(hi));
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if keeps(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // The closed form: lambda* = max_a (-t_a / v_a) over the minimum-norm efforts t.
    let closed = mn.iter().zip(&v).map(|(t, v)| -t / v).fold(f64::NEG_INFINITY, f64::max);
    assert!((hi - closed).abs() <= 1e-9 * (1.0 + closed.abs()), "bisection {hi} vs {closed}");
    assert!(keeps(closed + 1e-6) && !keeps(closed - 1e-6));
}

#[test]
fn geared_motors_share_the_joint_side_efforts_and_keep_their_rotors() {
    let (geared, ideal) = (three_legs_geared(), three_legs());
    let (q, qd, qdd) = point(&geared);
    let (n, eta, j, c, tc) = GEAR;
    for how in [Distribution::MinNorm, Distribution::MinMax, Distribution::Preload(vec![4.0])] {
        let mut ws = Workspace::new(&geared);
        let (act, e) = inverse_redundant(&geared, &q, &qd, &qdd, &how, &mut ws).unwrap();
        let (_, e0) = inverse_redundant(&ideal, &q, &qd, &qdd, &how, &mut Workspace::new(&ideal)).unwrap();
        // The rotors turn before their gears (on the ground): the joint-side efforts are
        // shared as without them.
        for a in 0..3 {
            assert!((e[a] - e0[a]).abs() <= 1e-12 * (1.0 + e0[a].abs()), "{how:?} {a}: {e:?} vs {e0:?}");
        }
        // The motor torques reproduce the motion in forward dynamics.
        let mut t_m = vec![0.0; 2];
        motor_torques(&geared, &ws, &e[..2], &mut t_m);
        let inputs = [t_m[0], t_m[1], e[2]];
        forward_redundant(&geared, 0.0, &q, &qd, &inputs, &mut ws).unwrap();
        for k in 0..2 {
            assert!((ws.qdd[k] - qdd[k]).abs() <= 1e-10 * qdd[k].abs(), "{how:?}: qdd {:?} vs {qdd:?}", ws.qdd);
        }
        // Power balance: the motors' and the third actuator's input power = the mechanism's
        // (B e0 . qd) + the rotors' n^2 J qdd qd + each gearbox's and motor's loss, in closed
        // form (1/eta - 1) e qd while motoring, (1 - eta) |e qd| while generating, plus the
        // motor friction's (c w + T_c tanh(w / 1e-2)) w at motor speed w = n qd.
        let rate3: f64 = (0..2).map(|k| act.b[k * 3 + 2] * qd[k]).sum();
        let input = t_m[0] * n * qd[0] + t_m[1] * n * qd[1] + e[2] * rate3;
        let mechanism: f64 = (0..2).map(|k| (0..3).map(|a| act.b[k * 3 + a] * e0[a]).sum::<f64>() * qd[k]).sum();
        let rotors: f64 = (0..2).map(|k| n * n * j * qdd[k] * qd[k]).sum();
        let losses: f64 = (0..2)
            .map(|k| {
                let (p, w) = (e[k] * qd[k], n * qd[k]);
                let gear = if p >= 0.0 { (1.0 / eta - 1.0) * p } else { (1.0 - eta) * -p };
                gear + (c * w + tc * (w / 1e-2).tanh()) * w
            })
            .sum();
        assert!(losses > 0.0);
        let balance = input - mechanism - rotors - losses;
        assert!(balance.abs() <= 1e-12 * input.abs(), "{how:?}: {input} W in, {balance} W unbalanced");
    }
}

/// Gear ratio, efficiency, rotor inertia (kg m^2), viscous (N m s/rad) and Coulomb (N m)
/// friction of the geared motor on the third leg's base pair motor3.
const PAIR_GEAR: (f64, f64, f64, f64, f64) = (15.0, 0.85, 3e-5, 2e-4, 0.02);

/// The geared motor on motor3 as an actuator spec line.
fn pair_motor() -> String {
    let (n, eta, j, c, tc) = PAIR_GEAR;
    format!(
        "  - {{pair: motor3, gear_ratio: {n}, efficiency: {eta}, rotor_inertia: {j}, viscous: {c}, coulomb: {tc}}}\n"
    )
}

/// The third leg's angular acceleration and rate (proximal_mid is body 2; motor3 joins it to
/// the ground, so its relative angle is the body's angle), from the body motion in `ws`.
fn third_leg(ws: &Workspace) -> (f64, f64) {
    (ws.xdd[8], ws.xd[8])
}

#[test]
fn a_geared_pair_actuator_adds_its_reflected_inertia_along_its_lever() {
    // Ideal drives on the coordinates, so forward dynamics is linear in their efforts and
    // A^-1 e_j = qdd(e_j) - qdd(0); the pair motor's torque is 0 and, without its friction, so
    // is its joint-side effort.
    let (n, _, j, _, _) = PAIR_GEAR;
    let rotor_only = format!("  - {{pair: motor3, gear_ratio: {n}, rotor_inertia: {j}}}\n");
    let (geared, ideal) = (yaml(&three_legs_yaml(&rotor_only)), three_legs());
    let (q, qd, _) = point(&geared);
    let mass = |mech: &Mechanism| -> (Vec<f64>, Vec<f64>) {
        let mut ws = Workspace::new(mech);
        let mut qdd = |efforts: [f64; 3]| {
            forward_redundant(mech, 0.0, &q, &qd, &efforts, &mut ws).unwrap();
            [ws.qdd[0], ws.qdd[1]]
        };
        let q0 = qdd([0.0; 3]);
        let (c0, c1) = (qdd([1.0, 0.0, 0.0]), qdd([0.0, 1.0, 0.0]));
        let inv = [c0[0] - q0[0], c1[0] - q0[0], c0[1] - q0[1], c1[1] - q0[1]];
        let det = inv[0] * inv[3] - inv[1] * inv[2];
        (vec![inv[3] / det, -inv[1] / det, -inv[2] / det, inv[0] / det], q0.to_vec())
    };
    let ((a, _), (a0, _)) = (mass(&geared), mass(&ideal));
    let mut ws = Workspace::new(&ideal);
    let (act, _) = inverse_redundant(&ideal, &q, &qd, &[0.0; 2], &Distribution::MinNorm, &mut ws).unwrap();
    let g = [act.b[2], act.b[5]];
    let scale = a0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for r in 0..2 {
        for c in 0..2 {
            let expected = a0[r * 2 + c] + n * n * j * g[r] * g[c];
            assert!((a[r * 2 + c] - expected).abs() <= 1e-10 * scale, "A[{r}][{c}] = {} vs {expected}", a[r * 2 + c]);
        }
    }
    assert!(n * n * j * g[0] * g[0] > 1e-4 * scale, "the rotor's share is visible: {g:?}");
}

#[test]
fn a_geared_pair_actuator_keeps_its_rotor_and_its_losses() {
    let (n, eta, j, c, tc) = GEAR;
    let motor = |q: &str| {
        format!(
            "  - {{coordinate: {q}, gear_ratio: {n}, efficiency: {eta}, rotor_inertia: {j}, viscous: {c}, coulomb: {tc}}}\n"
        )
    };
    let geared = yaml(&three_legs_yaml(&(motor("theta1") + &motor("theta2") + &pair_motor())));
    let ideal = three_legs();
    let gears = [GEAR, GEAR, PAIR_GEAR];
    let (q, qd, qdd) = point(&geared);
    for how in [Distribution::MinNorm, Distribution::MinMax, Distribution::Preload(vec![4.0])] {
        let mut ws = Workspace::new(&geared);
        let (act, e) = inverse_redundant(&geared, &q, &qd, &qdd, &how, &mut ws).unwrap();
        let (qdd3, rate3) = third_leg(&ws);
        let (_, e0) = inverse_redundant(&ideal, &q, &qd, &qdd, &how, &mut Workspace::new(&ideal)).unwrap();
        // The actuators' rates B^T qd; the third is the leg's own rate.
        let rates: Vec<f64> = (0..3).map(|a| (0..2).map(|k| act.b[k * 3 + a] * qd[k]).sum()).collect();
        assert!((rates[2] - rate3).abs() <= 1e-12 * rate3.abs(), "{rates:?} vs {rate3}");
        // Each rotor turns before its gear (on the ground), its power n^2 J qdd_a qd_a its
        // motor's: the joint-side efforts are shared as without them.
        let accelerations = [qdd[0], qdd[1], qdd3];
        let rotor: Vec<f64> = gears.iter().zip(&accelerations).map(|((n, _, j, _, _), a)| n * n * j * a).collect();
        for a in 0..3 {
            assert!((e[a] - e0[a]).abs() <= 1e-12 * (1.0 + e0[a].abs()), "{how:?} {a}: {e:?} vs {e0:?}");
        }
        // The motor torques reproduce the motion in forward dynamics.
        let mut t_m = vec![0.0; 3];
        motor_torques(&geared, &ws, &e, &mut t_m);
        forward_redundant(&geared, 0.0, &q, &qd, &t_m, &mut ws).unwrap();
        for k in 0..2 {
            assert!((ws.qdd[k] - qdd[k]).abs() <= 1e-10 * qdd[k].abs(), "{how:?}: qdd {:?} vs {qdd:?}", ws.qdd);
        }
        // Power balance: the three motors' input power = the mechanism's (B e0 . qd) + the
        // rotors' n^2 J qdd_a qd_a + each gearbox's loss in closed form, (1/eta - 1) e qd_a
        // while motoring, (1 - eta) |e qd_a| while generating, + the motor friction's
        // (c w + T_c tanh(w / 1e-2)) w at motor speed w = n qd_a.
        let input: f64 = (0..3).map(|a| t_m[a] * gears[a].0 * rates[a]).sum();
        let mechanism: f64 = (0..2).map(|k| (0..3).map(|a| act.b[k * 3 + a] * e0[a]).sum::<f64>() * qd[k]).sum();
        let rotors: f64 = (0..3).map(|a| rotor[a] * rates[a]).sum();
        let losses: f64 = (0..3)
            .map(|a| {
                let (n, eta, _, c, tc) = gears[a];
                let (p, w) = (e[a] * rates[a], n * rates[a]);
                let gear = if p >= 0.0 { (1.0 / eta - 1.0) * p } else { (1.0 - eta) * -p };
                gear + (c * w + tc * (w / 1e-2).tanh()) * w
            })
            .sum();
        assert!(losses > 0.0 && rotor[2].abs() > 1e-3 * e[2].abs(), "{losses} W, {rotor:?}");
        let balance = input - mechanism - rotors - losses;
        assert!(balance.abs() <= 1e-12 * input.abs(), "{how:?}: {input} W in, {balance} W unbalanced");
    }
}

#[test]
fn a_preload_that_is_not_finite_is_refused_naming_it() {
    // Before (issue 23 finding 6): NaN efforts for a NaN preload, infinite ones for inf.
    let mech = three_legs();
    let (q, qd, qdd) = point(&mech);
    let mut ws = Workspace::new(&mech);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let err = inverse_redundant(&mech, &q, &qd, &qdd, &Distribution::Preload(vec![bad]), &mut ws).unwrap_err();
        let text = err.to_string();
        assert!(
            text.starts_with(&format!(
                "preload: expected finite values (N m or N), one per internal force, got preload[0] = {bad}"
            )),
            "{text}"
        );
    }
}
