//! Motors with transmissions and friction from the pair loads, against closed forms,
//! an independent integration and the power balance (docs/actuators.md).

mod common;

use common::{run, yaml};
use planardyn::dynamics::{forward, inverse, motor_torques, ModelDrives};
use planardyn::kinematics::{assemble_into, velocity_analogues, Chart};
use planardyn::model::loads::friction::FrictionSpec;
use planardyn::model::spec::LoadSpec;
use planardyn::{KinematicsError, Mechanism, Workspace};

const G: f64 = 9.81;

/// A crank (uniform bar, L = 0.4 m, m = 2 kg: I_O = m L^2 / 3) turned by a geared motor,
/// no gravity.
fn crank(actuator: &str, torque: f64) -> Mechanism {
    yaml(&format!(
        r#"
name: geared crank
points: {{O: [0, 0], A: [0.4, 0]}}
ground: [O]
bodies:
  crank: {{points: [O, A], uniform_bar: [O, A], mass: 2.0}}
pairs:
  - {{type: revolute, name: O, at: O, bodies: [ground, crank]}}
coordinates:
  - {{name: theta, pair: O, value: 0.0}}
drives:
  - {{coordinate: theta, effort: {torque}}}
actuators:
  - {{coordinate: theta, {actuator}}}
"#
    ))
}

const I_O: f64 = 2.0 * 0.4 * 0.4 / 3.0;

fn qdd_at(mech: &Mechanism, q: f64, qd: f64) -> (f64, Workspace) {
    let mut ws = Workspace::new(mech);
    forward(mech, 0.0, &[q], &[qd], &mut ModelDrives(mech), &mut ws).unwrap();
    (ws.qdd[0], ws)
}

#[test]
fn reflected_rotor_inertia_adds_n2_j() {
    // qdd = n T / (I_O + n^2 J) for an ideal gearbox (n = 50, J = 1e-4: n^2 J = 0.25 kg m^2).
    let mech = crank("gear_ratio: 50, rotor_inertia: 1.0e-4", 0.3);
    let expected = 50.0 * 0.3 / (I_O + 2500.0 * 1e-4);
    let (qdd, _) = qdd_at(&mech, 0.3, 1.5);
    assert!((qdd - expected).abs() <= 1e-13 * expected, "{qdd} vs {expected}");
}

#[test]
fn efficiency_and_motor_friction_follow_the_power_flow() {
    // The rotor sits before the gear: with c = T - c n qd - T_c sgn(qd) the motor's net torque
    // and t = c - J n qdd what it hands to the gear, I_O qdd = n eta t while motoring (qd > 0:
    // (I_O + eta n^2 J) qdd = eta n c) and I_O qdd = n t / eta back-driven (qd < 0 against
    // T > 0: (I_O + n^2 J / eta) qdd = n c / eta). Stiction speed 1e-2 rad/s against
    // n qd = 100 rad/s: tanh(1e4) = 1 exactly.
    let (n, eta, j, c, tc, t) = (50.0, 0.8, 1e-4, 2e-4, 0.01, 0.3);
    let mech =
        crank(&format!("gear_ratio: {n}, efficiency: {eta}, rotor_inertia: {j}, viscous: {c}, coulomb: {tc}"), t);
    let motoring = eta * n * (t - c * n * 2.0 - tc) / (I_O + eta * n * n * j);
    let generating = n * (t + c * n * 2.0 + tc) / eta / (I_O + n * n * j / eta);
    for (qd, expected) in [(2.0, motoring), (-2.0, generating)] {
        let (qdd, _) = qdd_at(&mech, 0.1, qd);
        assert!((qdd - expected).abs() <= 1e-13 * expected.abs(), "qd {qd}: {qdd} vs {expected}");
        // Inverse dynamics gives the joint side I_O qdd (the rotor is the motor's), and the
        // motor torque of the forward evaluation back.
        let mut ws = Workspace::new(&mech);
        inverse(&mech, &[0.1], &[qd], &[qdd], &mut ws).unwrap();
        assert!((ws.tau[0] - I_O * qdd).abs() <= 1e-13 * ws.tau[0].abs());
        let mut t_m = [0.0];
        motor_torques(&mech, &ws, &ws.tau, &mut t_m);
        assert!((t_m[0] - t).abs() <= 1e-14, "motor torque {} vs {t}", t_m[0]);
    }
}

/// A block (1 kg) on a guide inclined by `a` (rad), the axis pointing downhill, with
/// Coulomb friction mu.
fn incline(a: f64, mu: f64, qd0: f64) -> Mechanism {
    let (c, s) = (a.cos(), a.sin());
    yaml(&format!(
        r#"
name: block on an incline
gravity: [0, -{G}]
points: {{P: [0, 0], Q: [{c}, {ms}]}}
ground: [P]
bodies:
  block: {{points: [P, Q], mass: 1.0, inertia: 0.01, com: P}}
pairs:
  - {{type: prismatic, name: guide, at: P, bodies: [ground, block], axis: [{c}, {ms}]}}
coordinates:
  - {{name: s, pair: guide, value: 0.0, qd0: {qd0}}}
loads:
  - {{type: friction, pair: guide, mu: {mu}}}
"#,
        ms = -s
    ))
}

#[test]
fn block_slides_down_an_incline_at_g_sin_minus_mu_cos() {
    // Sliding at 1 m/s (10^4 stiction speeds): qdd = g (sin a - mu cos a), exactly.
    for (a, mu) in [(30f64.to_radians(), 0.3), (40f64.to_radians(), 0.6), (20f64.to_radians(), 0.9)] {
        let mech = incline(a, mu, 1.0);
        let (qdd, ws) = qdd_at(&mech, 0.0, 1.0);
        let expected = G * (a.sin() - mu * a.cos());
        assert!((qdd - expected).abs() <= 1e-12 * G, "a {a}: {qdd} vs {expected}");
        // The dissipated power is mu N v.
        assert!((ws.dissipated - mu * G * a.cos()).abs() <= 1e-12 * G);
    }
}

#[test]
fn block_sticks_when_tan_a_is_below_mu() {
    // tan 30 deg = 0.577 < mu = 0.7: from rest the regularised law lets the block creep at
    // v_st atanh(tan a / mu) = 1e-4 * 1.17 m/s at most; it never slides off.
    let (a, mu) = (30f64.to_radians(), 0.7);
    let mech = incline(a, mu, 0.0);
    let tr = run(&mech, "radau5", 1.0, 1e-8, None);
    let creep = 1e-4 * (a.tan() / mu).atanh();
    let fastest = tr.qd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(fastest <= creep * (1.0 + 1e-6), "{fastest} > {creep}");
    assert!(tr.q.last().unwrap().abs() <= creep, "moved {}", tr.q.last().unwrap());
    // Past the stiction bound the same block slides: tan a > mu.
    let slides = run(&incline(a, 0.5, 0.0), "radau5", 1.0, 1e-8, None);
    let expected = 0.5 * G * (a.sin() - 0.5 * a.cos());
    assert!((slides.q.last().unwrap() - expected).abs() <= 1e-3 * expected);
}

/// theta'' of the pendulum of common::PENDULUM (m = 2 kg, L = 0.8 m) with pin friction
/// mu r |F| tanh(r theta' / v_st): the one-coordinate equation, the reaction
/// F = m a_c - m g solved with theta'' by fixed-point iteration.
fn pendulum_qdd(theta: f64, w: f64, mu: f64, r: f64, v_st: f64) -> f64 {
    let (m, l) = (2.0, 0.4);
    let i_o = 2.0 * 0.8f64.powi(2) / 3.0;
    let mut qdd = 0.0;
    for _ in 0..200 {
        let (s, c) = theta.sin_cos();
        let ac = [l * (-s * qdd - c * w * w), l * (c * qdd - s * w * w)];
        let f = (m * ac[0]).hypot(m * ac[1] + m * G);
        let next = (-m * G * l * c - mu * r * f * (r * w / v_st).tanh()) / i_o;
        if (next - qdd).abs() <= 1e-15 * next.abs().max(1.0) {
            return next;
        }
        qdd = next;
    }
    qdd
}

#[test]
fn pendulum_with_pin_friction_matches_its_one_coordinate_equation() {
    let (mu, r, v_st) = (0.3, 0.02, 1e-3);
    let mech = yaml(&format!(
        "{}loads:\n  - {{type: friction, pair: O, mu: {mu}, pin_radius: {r}, stiction_speed: {v_st}}}\n",
        common::PENDULUM
    ));
    let t_end = 2.0;
    let tr = run(&mech, "dop853", t_end, 1e-11, Some(vec![t_end]));
    // Classical RK4 on [theta, theta'], h = 1e-4 s: error O(h^4) well below 1e-8 rad.
    let (mut y, h) = ([0.0f64, 0.0], 1e-4);
    let f = |y: [f64; 2]| [y[1], pendulum_qdd(y[0], y[1], mu, r, v_st)];
    for _ in 0..(t_end / h).round() as usize {
        let k1 = f(y);
        let k2 = f([y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]]);
        let k3 = f([y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]]);
        let k4 = f([y[0] + h * k3[0], y[1] + h * k3[1]]);
        for i in 0..2 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    let (q, qd) = (*tr.q.last().unwrap(), *tr.qd.last().unwrap());
    assert!((q - y[0]).abs() <= 1e-7 && (qd - y[1]).abs() <= 1e-6, "({q}, {qd}) vs {y:?}");
    // Friction took energy: T + V - W stays at its start value, W counting the dissipated work.
    let n = tr.t.len() - 1;
    let balance = tr.kinetic[n] + tr.potential[n] - tr.work[n] - (tr.kinetic[0] + tr.potential[0] - tr.work[0]);
    assert!(balance.abs() <= 1e-7, "energy balance {balance}");
    assert!(tr.work[n] < -1e-3, "friction dissipated {}", -tr.work[n]);
}

/// Coulomb friction at every pair of common::SLIDER_CRANK.
const FRICTION: &str = "loads:\n\
  - {type: friction, pair: O, mu: 0.15, pin_radius: 0.01}\n\
  - {type: friction, pair: A, mu: 0.1, pin_radius: 0.008}\n\
  - {type: friction, pair: B, mu: 0.1, pin_radius: 0.008}\n\
  - {type: friction, pair: guide, mu: 0.2, length: 0.04}\n";

fn slider_crank(friction: &str) -> Mechanism {
    let drawing = common::SLIDER_CRANK.split("loads:").next().unwrap_or_default();
    let named = drawing
        .replace("at: A, bodies", "name: A, at: A, bodies")
        .replace("at: B, bodies: [rod", "name: B, at: B, bodies: [rod");
    yaml(&format!("{named}{friction}"))
}

#[test]
fn drive_power_is_frictionless_power_plus_dissipated_power() {
    // Along a non-uniform crank motion, at every point: tau qd = tau_0 qd + dissipated, by
    // the principle of virtual power (the same motion, the same dT/dt + dV/dt).
    let (with, without) = (slider_crank(FRICTION), slider_crank(""));
    let (mut work, mut work0, mut lost) = (0.0, 0.0, 0.0);
    let n = 400;
    let dt = 1.0 / n as f64;
    common::power_balance_along(&with, &without, [0.5, 6.0, 0.8, 3.0], n, (1e-10, 1.0), |s| {
        assert!(s.ws.dissipated > 0.0);
        let wgt = if s.k == 0 || s.k == n { 0.5 } else { 1.0 };
        work += wgt * dt * s.p;
        work0 += wgt * dt * s.p0;
        lost += wgt * dt * s.ws.dissipated;
    });
    assert!((work - work0 - lost).abs() <= 1e-10 * work.abs());
    assert!(lost > 0.01 * work.abs(), "friction costs {lost} J of {work} J");
}

#[test]
fn forward_with_losses_inverts_and_holds_in_a_partition_chart() {
    // The slider-crank with pin friction and a geared motor whose torque is the file's drive
    // effort, 0.4 N m: inverse dynamics at the forward accelerations gives that torque back,
    // and forward dynamics in a partition chart (components of x as coordinates) gives the
    // same qdd (the rotor's g, h and the friction's levers taken through U).
    let motor = "actuators:\n  - {coordinate: phi, gear_ratio: 10, efficiency: 0.9, rotor_inertia: 1.0e-4, \
                 viscous: 1.0e-4, coulomb: 0.005}\n";
    let mech = slider_crank(&format!("{FRICTION}{motor}"));
    let (q, qd) = ([0.9], [4.0]);
    let assembled = || {
        let mut ws = Workspace::new(&mech);
        assemble_into(&mech, &q, &mut ws).unwrap();
        velocity_analogues(&mut ws).unwrap();
        ws
    };
    let mut ws = assembled();
    forward(&mech, 0.0, &q, &qd, &mut ModelDrives(&mech), &mut ws).unwrap();
    let qdd = ws.qdd[0];
    assert!(ws.dissipated > 0.0);
    let mut inv = assembled();
    inverse(&mech, &q, &qd, &[qdd], &mut inv).unwrap();
    let mut t_m = [0.0];
    motor_torques(&mech, &inv, &inv.tau, &mut t_m);
    assert!((t_m[0] - 0.4).abs() <= 1e-12, "motor torque {} vs 0.4 N m", t_m[0]);
    assert!((inv.dissipated - ws.dissipated).abs() <= 1e-12 * ws.dissipated);

    // The slider's X (x[6]) as the chart coordinate: dq/dz is then not 1 (the crank is 0.9 rad
    // from its dead centres, where it would vanish).
    let mut part = assembled();
    let idx = vec![6];
    let z: Vec<f64> = idx.iter().map(|&i| part.x[i]).collect();
    let zd: Vec<f64> = idx.iter().map(|&i| part.u_col(0)[i] * qd[0]).collect();
    part.chart = Chart::Partition(idx);
    forward(&mech, 0.0, &z, &zd, &mut ModelDrives(&mech), &mut part).unwrap();
    assert!((part.qdd[0] - qdd).abs() <= 1e-9 * qdd.abs(), "partition chart {} vs {qdd}", part.qdd[0]);
    assert!((part.dissipated - ws.dissipated).abs() <= 1e-9 * ws.dissipated);
}

/// A shipped model with Coulomb friction `mu` at `pair` (a pin of radius `radius`, or a slot).
fn shipped_with_friction(name: &str, pair: &str, mu: f64, radius: Option<f64>) -> Mechanism {
    let mut spec = common::shipped(name).spec.clone();
    spec.loads.push(LoadSpec::Friction(FrictionSpec {
        pair: pair.into(),
        viscous: None,
        mu: Some(mu),
        mu_static: None,
        pin_radius: radius,
        length: None,
        stiction_speed: None,
        stribeck_speed: None,
        pressure_angle: None,
    }));
    planardyn::build(spec, name).unwrap()
}

#[test]
fn self_locking_friction_is_reported_at_any_mu() {
    // Issue 23, finding 4: the slider-crank's crank pin (r = 8 mm) and the Scotch yoke's slot
    // pin self-lock for mu >= 1e2 at their start states (moving: 5 and 2 rad/s); up to
    // mu ~ 3e3 the fixed point wandered for 100 iterations, beyond it overflowed and forward
    // dynamics returned -1.1e297 (mu 1e15 on the crank pin). Every mu must now give the
    // self-lock error, never a number; a small mu still settles.
    for (model, pair, radius) in [("slider-crank.yaml", "crank_pin", Some(0.008)), ("scotch-yoke.yaml", "pin", None)] {
        let settles = shipped_with_friction(model, pair, 0.1, radius);
        let (q, qd) = settles.initial_state();
        let mut ws = Workspace::new(&settles);
        forward(&settles, 0.0, &q, &qd, &mut ModelDrives(&settles), &mut ws).unwrap();
        assert!(ws.qdd.iter().all(|v| v.is_finite() && v.abs() < 1e4) && ws.dissipated > 0.0, "{model}: {:?}", ws.qdd);
        for mu in [1e2, 3e2, 1e3, 3e3, 1e4, 1e5, 1e6, 1e8, 1e10, 1e12, 1e15, 1e18, 1e20] {
            let mech = shipped_with_friction(model, pair, mu, radius);
            let mut ws = Workspace::new(&mech);
            match forward(&mech, 0.0, &q, &qd, &mut ModelDrives(&mech), &mut ws) {
                Err(planardyn::Error::Kinematics(KinematicsError::FrictionUnsettled { iterations, change })) => {
                    assert!(iterations <= 100 && change.is_finite(), "{model} mu {mu}: {iterations} {change}");
                }
                other => panic!("{model} mu {mu}: {other:?}, qdd {:?}", ws.qdd),
            }
        }
    }
}
