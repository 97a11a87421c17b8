//! The motors' rotors before their gears (dynamics::gears, docs/actuators.md): a geared disk
//! motoring and braking, a self-locking worm drive holding its load, a gear stuck at rest,
//! motors on a moving link against an independent Newton-Euler derivation (and, lossless,
//! Lagrange's), and the power balance along a motion.

mod common;

use common::yaml;
use planardyn::dynamics::{forward, inverse, motor_torques, Drives};
use planardyn::simulate::{simulate, Settings};
use planardyn::{Error, KinematicsError, Mechanism, Workspace};

const G: f64 = 9.81;

/// Motor torques given as a function of time.
struct Torques<F: FnMut(f64) -> Vec<f64>>(F);

impl<F: FnMut(f64) -> Vec<f64>> Drives for Torques<F> {
    fn efforts(&mut self, t: f64, _q: &[f64], _qd: &[f64], tau: &mut [f64]) -> Result<(), String> {
        tau.copy_from_slice(&(self.0)(t));
        Ok(())
    }
}

/// Forward dynamics at (q, qd) under motor torques `t_m`: qdd and the workspace.
fn forward_at(mech: &Mechanism, q: &[f64], qd: &[f64], t_m: &[f64]) -> Result<(Vec<f64>, Workspace), Error> {
    let mut ws = Workspace::new(mech);
    forward(mech, 0.0, q, qd, &mut Torques(|_| t_m.to_vec()), &mut ws)?;
    Ok((ws.qdd.clone(), ws))
}

/// The motor torques inverse dynamics gives for (q, qd, qdd).
fn motor_side(mech: &Mechanism, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let mut ws = Workspace::new(mech);
    inverse(mech, q, qd, qdd, &mut ws).unwrap();
    let mut t_m = vec![0.0; q.len()];
    motor_torques(mech, &ws, &ws.tau, &mut t_m);
    t_m
}

/// A disk (I_O = 0.01 kg m^2 about its centre, its pivot) behind a gear of ratio 10 with a
/// rotor J = 1e-4 kg m^2: n^2 J = I_O. No gravity.
fn disk(gear: &str) -> Mechanism {
    yaml(&format!(
        r#"
name: geared disk
gravity: [0, 0]
points: {{O: [0, 0], A: [0.1, 0]}}
ground: [O]
bodies:
  disk: {{points: [O, A], mass: 2.0, inertia: 0.01, com: O}}
pairs:
  - {{type: revolute, name: O, at: O, bodies: [ground, disk]}}
coordinates:
  - {{name: theta, pair: O, value: 0.0}}
actuators:
  - {{coordinate: theta, gear_ratio: 10, rotor_inertia: 1.0e-4, {gear}}}
"#
    ))
}

#[test]
fn geared_disk_motoring_and_braking_take_the_rotor_before_the_gear() {
    // n = 10, J = 1e-4, I_O = n^2 J = 0.01, eta = 0.8, at qd = 5 rad/s. The rotor hands the
    // gear t = T - J n qdd; the disk gets I_O qdd = n eta t while motoring, so
    // qdd = eta n T / (I_O + eta n^2 J) = 0.8 / 0.018 = 44.444 rad/s^2 (the efficiency on the
    // rotor's torque too gives 0.8 / 0.02 = 40: 10 % low). Braking (T = -0.1 N m) back-drives
    // the gear: eta_b I_O qdd = n t, qdd = n T / (eta_b I_O + n^2 J) = -1 / 0.018 = -55.556
    // (62.5 with the rotor inside: 12.5 % high). The motor torque for qdd = 40 while motoring:
    // t_m = J n qdd + I_O qdd / (n eta) = 0.04 + 0.05 = 0.09 N m (0.1, 11 % high, before).
    let (n, j, i_o, eta) = (10.0, 1e-4, 0.01, 0.8);
    let mech = disk("efficiency: 0.8");
    let motoring = eta * n * 0.1 / (i_o + eta * n * n * j);
    let braking = n * -0.1 / (eta * i_o + n * n * j);
    for (t_m, expected) in [(0.1, motoring), (-0.1, braking)] {
        let (qdd, ws) = forward_at(&mech, &[0.0], &[5.0], &[t_m]).unwrap();
        assert!((qdd[0] - expected).abs() <= 1e-13 * expected.abs(), "T {t_m}: {} vs {expected}", qdd[0]);
        // The joint side is the disk's own torque, I_O qdd.
        assert!((ws.tau[0] - i_o * qdd[0]).abs() <= 1e-13 * ws.tau[0].abs());
        // Inverse dynamics and the motor torque give the drive back.
        let back = motor_side(&mech, &[0.0], &[5.0], &qdd);
        assert!((back[0] - t_m).abs() <= 1e-15, "{} vs {t_m}", back[0]);
    }
    assert!((motoring - 400.0 / 9.0).abs() <= 1e-12 && (braking + 500.0 / 9.0).abs() <= 1e-12);
    let t_m = motor_side(&mech, &[0.0], &[5.0], &[40.0]);
    assert!((t_m[0] - 0.09).abs() <= 1e-15, "motor torque {}", t_m[0]);
    // A back-drive efficiency of its own: braking with eta_b = 0.5, qdd = n T / (eta_b I_O + n^2 J).
    let (qdd, _) = forward_at(&disk("efficiency: 0.8, backdrive_efficiency: 0.5"), &[0.0], &[5.0], &[-0.1]).unwrap();
    let expected = n * -0.1 / (0.5 * i_o + n * n * j);
    assert!((qdd[0] - expected).abs() <= 1e-13 * expected.abs(), "{} vs {expected}", qdd[0]);
}

/// A uniform arm (1 kg, 0.5 m: I_O = 1/12 kg m^2, its weight's torque m g L / 2 = 2.4525 N m
/// when level) on a gear of ratio 30 with rotor J = 2e-5 kg m^2.
fn arm(gear: &str) -> Mechanism {
    yaml(&format!(
        r#"
name: geared arm
gravity: [0, -{G}]
points: {{O: [0, 0], A: [0.5, 0]}}
ground: [O]
bodies:
  arm: {{points: [O, A], uniform_bar: [O, A], mass: 1.0}}
pairs:
  - {{type: revolute, name: O, at: O, bodies: [ground, arm]}}
coordinates:
  - {{name: theta, pair: O, value: 0.0}}
actuators:
  - {{coordinate: theta, gear_ratio: 30, rotor_inertia: 2.0e-5, {gear}}}
"#
    ))
}

const I_ARM: f64 = 1.0 / 12.0;

/// A held joint's acceleration (rad/s^2): round-off of the weight's W / I_O = 29 rad/s^2,
/// a few eps of it (measured 5.3e-15).
const HELD: f64 = 1e-13;
const WEIGHT: f64 = 1.0 * G * 0.25;

#[test]
fn a_self_locking_worm_drive_holds_its_load() {
    // eta = 0.4, eta_b = 0: a worm drive. Level and at rest, the weight would back-drive it:
    // the gear holds (qdd = 0 but for round-off, 1e-15 of the weight's W / I_O = 29 rad/s^2)
    // with the joint-side torque m g L / 2.
    let (n, j, eta) = (30.0, 2e-5, 0.4);
    let worm = arm("efficiency: 0.4, backdrive_efficiency: 0.0");
    for t_m in [0.0, 0.1] {
        // 0.1 N m lifts less than the weight: eta n T = 1.2 < 2.4525 N m; still held.
        let (qdd, ws) = forward_at(&worm, &[0.0], &[0.0], &[t_m]).unwrap();
        assert!(qdd[0].abs() <= HELD, "T {t_m}: qdd {}", qdd[0]);
        assert!((ws.tau[0] - WEIGHT).abs() <= 1e-14 * WEIGHT, "holding torque {}", ws.tau[0]);
    }
    // 0.3 N m lifts it: (I_O + eta n^2 J) qdd = eta n T - m g L / 2.
    let (qdd, _) = forward_at(&worm, &[0.0], &[0.0], &[0.3]).unwrap();
    let expected = (eta * n * 0.3 - WEIGHT) / (I_ARM + eta * n * n * j);
    assert!((qdd[0] - expected).abs() <= 1e-13 * expected, "{} vs {expected}", qdd[0]);
    // Coming down (qd = -1 rad/s) the weight back-drives the gear: it takes the load, and the
    // joint follows the rotor, which only its motor turns: J n qdd = T (motor off: it keeps
    // its speed; braking with 0.01 N m: qdd = 0.01 / (J n) = 16.67 rad/s^2), the gear holding
    // tau = I_O qdd + m g L / 2.
    for t_m in [0.0, 0.01] {
        let (qdd, ws) = forward_at(&worm, &[0.0], &[-1.0], &[t_m]).unwrap();
        let expected = t_m / (j * n);
        assert!((qdd[0] - expected).abs() <= 1e-13 * expected.max(1.0), "T {t_m}: {} vs {expected}", qdd[0]);
        let held = I_ARM * qdd[0] + WEIGHT;
        assert!((ws.tau[0] - held).abs() <= 1e-13 * held, "T {t_m}: holding {} vs {held}", ws.tau[0]);
        assert!((motor_side(&worm, &[0.0], &[-1.0], &qdd)[0] - t_m).abs() <= 1e-15);
    }
    // A second of it, motor off, from rest: the arm does not move but for round-off.
    let mut s = Settings::for_model(&worm).unwrap();
    s.t_end = 1.0;
    let tr = simulate(&worm, &s, &mut Torques(|_| vec![0.0]), None).unwrap();
    assert!(tr.success(), "{}", tr.message);
    assert!(tr.q.iter().chain(&tr.qd).all(|v| v.abs() <= HELD), "moved: {:?}", tr.q.last());
}

#[test]
fn a_self_locking_gear_needs_its_rotor() {
    let text = common::PENDULUM.to_string()
        + "actuators:\n  - {coordinate: theta, gear_ratio: 40, efficiency: 0.5, backdrive_efficiency: 0}\n";
    let err = planardyn::loads(&text, planardyn::Format::Yaml, "<test>").unwrap_err().to_string();
    assert!(err.contains("actuators[0].rotor_inertia") && err.contains("self-locking"), "{err}");
    let text = text.replace("backdrive_efficiency: 0", "backdrive_efficiency: 1.5");
    let err = planardyn::loads(&text, planardyn::Format::Yaml, "<test>").unwrap_err().to_string();
    assert!(err.contains("actuators[0].backdrive_efficiency") && err.contains("[0, 1]"), "{err}");
}

#[test]
fn a_lossy_gear_at_rest_sticks_between_its_two_efficiencies() {
    // eta = 0.8, eta_b = 0.6, level arm at rest: the weight 2.4525 N m is lifted once
    // eta n T exceeds it (T > 0.1022 N m), lowered once n T / eta_b falls below it
    // (T < 0.04905 N m); in between the gear's friction holds the arm.
    let (n, j, eta, eta_b) = (30.0, 2e-5, 0.8, 0.6);
    let mech = arm("efficiency: 0.8, backdrive_efficiency: 0.6");
    let (qdd, ws) = forward_at(&mech, &[0.0], &[0.0], &[0.07]).unwrap();
    assert!(qdd[0].abs() <= HELD, "qdd {}", qdd[0]);
    assert!((ws.tau[0] - WEIGHT).abs() <= 1e-14 * WEIGHT);
    // Lifting: (I_O + eta n^2 J) qdd = eta n T - W; lowering, back-driven:
    // eta_b (I_O qdd + W) = n (T - J n qdd), qdd = (n T - eta_b W) / (eta_b I_O + n^2 J).
    let up = (eta * n * 0.11 - WEIGHT) / (I_ARM + eta * n * n * j);
    let down = (n * 0.04 - eta_b * WEIGHT) / (eta_b * I_ARM + n * n * j);
    for (t_m, expected) in [(0.11, up), (0.04, down)] {
        let (qdd, _) = forward_at(&mech, &[0.0], &[0.0], &[t_m]).unwrap();
        assert!((qdd[0] - expected).abs() <= 1e-13 * expected.abs(), "T {t_m}: {} vs {expected}", qdd[0]);
    }
    assert!(up > 0.0 && down < 0.0);
}

/// A two-link arm (links 0.4 m, 1.2 kg and 0.3 m, 0.8 kg, uniform bars) drawn at q1 = 0.3,
/// q2 = 0.5 rad: motor 1 on the ground at the shoulder, motor 2 on link 1 at the elbow (its
/// rotor turns at phi_1' + n2 q2'), with the gears `gear1`, `gear2`.
fn two_link(gear1: &str, gear2: &str, loads: &str) -> Mechanism {
    let (q1, q2) = (0.3f64, 0.5f64);
    let a = [0.4 * q1.cos(), 0.4 * q1.sin()];
    let b = [a[0] + 0.3 * (q1 + q2).cos(), a[1] + 0.3 * (q1 + q2).sin()];
    yaml(&format!(
        r#"
name: two-link arm
gravity: [0, -{G}]
points: {{O: [0, 0], A: [{}, {}], B: [{}, {}]}}
ground: [O]
bodies:
  link1: {{points: [O, A], uniform_bar: [O, A], mass: 1.2}}
  link2: {{points: [A, B], uniform_bar: [A, B], mass: 0.8}}
pairs:
  - {{type: revolute, name: shoulder, at: O, bodies: [ground, link1]}}
  - {{type: revolute, name: elbow, at: A, bodies: [link1, link2]}}
coordinates:
  - {{name: q1, pair: shoulder, value: {q1}}}
  - {{name: q2, pair: elbow, value: {q2}}}
actuators:
  - {{coordinate: q1, {gear1}}}
  - {{coordinate: q2, {gear2}}}
{loads}"#,
        a[0], a[1], b[0], b[1]
    ))
}

/// A gear: ratio n, efficiency eta, back-drive eta_b, rotor J, motor viscous c and Coulomb T_c
/// (regularised over 1e-2 rad/s).
#[derive(Clone, Copy)]
struct Gear {
    n: f64,
    eta: f64,
    eta_b: f64,
    j: f64,
    c: f64,
    tc: f64,
}

impl Gear {
    fn spec(&self) -> String {
        let g = self;
        format!(
            "gear_ratio: {}, efficiency: {}, backdrive_efficiency: {}, rotor_inertia: {}, viscous: {}, coulomb: {}",
            g.n, g.eta, g.eta_b, g.j, g.c, g.tc
        )
    }
    /// The motor's friction torque at coordinate rate qd.
    fn friction(&self, qd: f64) -> f64 {
        let w = self.n * qd;
        self.c * w + self.tc * (w / 1e-2).tanh()
    }
}

const GEAR1: Gear = Gear { n: 20.0, eta: 0.9, eta_b: 0.9, j: 3e-5, c: 1e-4, tc: 0.002 };

/// qdd of the two-link arm at the drawing (q1 = 0.3, q2 = 0.5) with rates qd and motor torques
/// t_m: [`two_link_branches`]'s one consistent solution.
fn two_link_newton_euler(g: [Gear; 2], qd: [f64; 2], t_m: [f64; 2]) -> [f64; 2] {
    let found = two_link_branches(g, qd, t_m);
    assert_eq!(found.len(), 1, "consistent branches: {found:?}");
    found[0]
}

/// The accelerations of the two-link arm at the drawing (q1 = 0.3, q2 = 0.5) with rates qd and
/// motor torques t_m on every consistent choice of branches, by Newton-Euler written out: M qdd + C + G = [tau1 + (t2 - c2), tau2] (the elbow motor's
/// housing, link 1, takes t2 - c2), rotors J1 n1 q1'' = c1 - t1 and
/// J2 (q1'' + n2 q2'') = c2 - t2, c_i = T_i - f_i, gears tau_i = eps_i n_i t_i. Every choice of
/// eps_i (eta_i motoring, 1 / eta_b,i back-driven) is solved and kept when its branch holds
/// (sgn(qd_i) t_i >= 0 motoring).
fn two_link_branches(g: [Gear; 2], qd: [f64; 2], t_m: [f64; 2]) -> Vec<[f64; 2]> {
    let (m1, l1, m2, l2, q2) = (1.2, 0.4, 0.8, 0.3, 0.5f64);
    let (q1, lc1, lc2) = (0.3f64, l1 / 2.0, l2 / 2.0);
    let (i1, i2) = (m1 * l1 * l1 / 12.0, m2 * l2 * l2 / 12.0);
    let m11 = i1 + i2 + m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * q2.cos());
    let m12 = i2 + m2 * (lc2 * lc2 + l1 * lc2 * q2.cos());
    let m22 = i2 + m2 * lc2 * lc2;
    let h = -m2 * l1 * lc2 * q2.sin();
    let cor = [h * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]), -h * qd[0] * qd[0]];
    let grav = [(m1 * lc1 + m2 * l1) * G * q1.cos() + m2 * lc2 * G * (q1 + q2).cos(), m2 * lc2 * G * (q1 + q2).cos()];
    let c = [t_m[0] - g[0].friction(qd[0]), t_m[1] - g[1].friction(qd[1])];
    let mut found = Vec::new();
    for (e1, e2) in [
        (g[0].eta, g[1].eta),
        (g[0].eta, 1.0 / g[1].eta_b),
        (1.0 / g[0].eta_b, g[1].eta),
        (1.0 / g[0].eta_b, 1.0 / g[1].eta_b),
    ] {
        // t1 = c1 - J1 n1 qdd1, t2 = c2 - J2 (qdd1 + n2 qdd2); Q1 = e1 n1 t1 + t2 - c2, Q2 = e2 n2 t2.
        let (n1, j1, n2, j2) = (g[0].n, g[0].j, g[1].n, g[1].j);
        let a = [[m11 + e1 * n1 * n1 * j1 + j2, m12 + j2 * n2], [m12 + e2 * n2 * j2, m22 + e2 * n2 * n2 * j2]];
        let b = [e1 * n1 * c[0] - cor[0] - grav[0], e2 * n2 * c[1] - cor[1] - grav[1]];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let qdd = [(b[0] * a[1][1] - a[0][1] * b[1]) / det, (a[0][0] * b[1] - a[1][0] * b[0]) / det];
        let t = [c[0] - j1 * n1 * qdd[0], c[1] - j2 * (qdd[0] + n2 * qdd[1])];
        let branch = |e: f64, eta: f64, qd: f64, t: f64| if e == eta { qd * t >= 0.0 } else { qd * t <= 0.0 };
        if branch(e1, g[0].eta, qd[0], t[0]) && branch(e2, g[1].eta, qd[1], t[1]) {
            found.push(qdd);
        }
    }
    found
}

#[test]
fn motors_on_a_moving_link_match_newton_euler() {
    // Elbow gears of ratio 15 and 1 (direct drive: its rotor turns at phi_1' + q2'), each
    // motoring and back-driven: planardyn's qdd against the closed form above.
    let q0 = [0.3, 0.5];
    for elbow in [
        Gear { n: 15.0, eta: 0.7, eta_b: 0.5, j: 4e-5, c: 1e-4, tc: 0.002 },
        Gear { n: 1.0, eta: 0.7, eta_b: 0.6, j: 2e-3, c: 0.0, tc: 0.0 },
    ] {
        let mech = two_link(&GEAR1.spec(), &elbow.spec(), "");
        let mut branches = [0, 0];
        for (qd, t_m) in [
            ([1.0, -2.0], [0.3, 0.1]),
            ([1.0, -2.0], [0.3, -0.1]),
            ([-0.5, 1.5], [-0.1, 0.05]),
            ([-0.5, 1.5], [0.4, -0.2]),
        ] {
            let t_m = [t_m[0], t_m[1] / elbow.n.sqrt()];
            let expected = two_link_newton_euler([GEAR1, elbow], qd, t_m);
            let (qdd, ws) = forward_at(&mech, &q0, &qd, &t_m).unwrap();
            for k in 0..2 {
                assert!((qdd[k] - expected[k]).abs() <= 1e-12 * expected[k].abs().max(1.0), "{qdd:?} vs {expected:?}");
            }
            branches[usize::from(ws.tau[1] * qd[1] < 0.0)] += 1;
            // Inverse dynamics and the motor torques give the drives back.
            let back = motor_side(&mech, &q0, &qd, &qdd);
            for k in 0..2 {
                assert!((back[k] - t_m[k]).abs() <= 1e-12 * t_m[k].abs().max(0.1), "{back:?} vs {t_m:?}");
            }
        }
        assert!(branches[0] > 0 && branches[1] > 0, "the elbow gear motoring and back-driven: {branches:?}");
    }
}

#[test]
fn lossless_motors_on_a_moving_link_match_lagrange() {
    // eta = 1: the rotors' kinetic energy 1/2 J1 (n1 q1')^2 + 1/2 J2 (q1' + n2 q2')^2 adds
    // J1 n1^2 e1 e1^T + J2 [1, n2] [1, n2]^T to M (constant: no convective term), and the motor
    // torques' virtual power c1 n1 q1' + c2 n2 q2' (each relative to its housing) gives
    // Q = [n1 c1, n2 c2].
    let ideal = |g: Gear| Gear { eta: 1.0, eta_b: 1.0, ..g };
    let (g1, g2) = (ideal(GEAR1), Gear { n: 3.0, eta: 1.0, eta_b: 1.0, j: 5e-4, c: 2e-4, tc: 0.0 });
    let mech = two_link(&g1.spec(), &g2.spec(), "");
    let (qd, t_m) = ([0.7, -1.3], [0.2, -0.15]);
    let (qdd, _) = forward_at(&mech, &[0.3, 0.5], &qd, &t_m).unwrap();
    // M, C, G from the Newton-Euler helper's closed form (lossless its single branch): check
    // against an assembly of M + rotor terms by hand.
    let (m1, l1, m2, l2, q1, q2) = (1.2f64, 0.4, 0.8, 0.3, 0.3f64, 0.5f64);
    let (lc1, lc2, i1, i2) = (l1 / 2.0, l2 / 2.0, m1 * l1 * l1 / 12.0, m2 * l2 * l2 / 12.0);
    let mut a = [
        [
            i1 + i2 + m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * q2.cos()),
            i2 + m2 * (lc2 * lc2 + l1 * lc2 * q2.cos()),
        ],
        [0.0, i2 + m2 * lc2 * lc2],
    ];
    a[1][0] = a[0][1];
    let rotor = [[g1.j * g1.n * g1.n + g2.j, g2.j * g2.n], [g2.j * g2.n, g2.j * g2.n * g2.n]];
    let h = -m2 * l1 * lc2 * q2.sin();
    let cg = [
        h * (2.0 * qd[0] * qd[1] + qd[1] * qd[1])
            + (m1 * lc1 + m2 * l1) * G * q1.cos()
            + m2 * lc2 * G * (q1 + q2).cos(),
        -h * qd[0] * qd[0] + m2 * lc2 * G * (q1 + q2).cos(),
    ];
    let c = [t_m[0] - g1.friction(qd[0]), t_m[1] - g2.friction(qd[1])];
    let b = [g1.n * c[0] - cg[0], g2.n * c[1] - cg[1]];
    let m: Vec<Vec<f64>> = (0..2).map(|i| (0..2).map(|k| a[i][k] + rotor[i][k]).collect()).collect();
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let expected = [(b[0] * m[1][1] - m[0][1] * b[1]) / det, (m[0][0] * b[1] - m[1][0] * b[0]) / det];
    for k in 0..2 {
        assert!((qdd[k] - expected[k]).abs() <= 1e-12 * expected[k].abs(), "{qdd:?} vs {expected:?}");
    }
}

#[test]
fn power_balance_input_is_mechanism_rotors_gear_losses_and_friction() {
    // The two-link arm under varying motor torques (both gears motoring and back-driven on
    // the way), with pin friction at the elbow. At every output row, independently of the
    // gears' solve: the motors' input power sum T_i n_i qd_i equals the mechanism's
    // d(T + V)/dt (from the body rates and accelerations), the rotors' d(1/2 J omega_r^2)/dt,
    // each gear's loss t_i n_i qd_i - tau_i qd_i (t_i = c_i - J_i omega_r,i'), the motors'
    // friction f_i n_i qd_i and the pin's dissipated power. A gear loses power (>= 0) but
    // within its at-rest band (|n qd| <= v_m = 1e-2 rad/s), where it takes the direction of
    // qdd: there it may hand on up to tau v_m / n.
    let elbow = Gear { n: 15.0, eta: 0.7, eta_b: 0.5, j: 4e-5, c: 1e-4, tc: 0.002 };
    let gears = [GEAR1, elbow];
    let mech = two_link(
        &GEAR1.spec(),
        &elbow.spec(),
        "loads:\n  - {type: friction, pair: elbow, mu: 0.1, pin_radius: 0.005}\n",
    );
    let torques = |t: f64| vec![0.4 * (3.0 * t).sin() + 0.1, 0.05 * (5.0 * t).cos()];
    let mut s = Settings::for_model(&mech).unwrap();
    s.t_end = 2.0;
    s.options.rtol = 1e-10;
    s.options.atol = 1e-12;
    s.t_eval = Some((0..=400).map(|k| k as f64 * 0.005).collect());
    let tr = simulate(&mech, &s, &mut Torques(torques), None).unwrap();
    assert!(tr.success(), "{}", tr.message);
    // The run's own energy balance (the work counts the power into the links).
    assert!(tr.stats.energy_drift <= 1e-8, "energy drift {}", tr.stats.energy_drift);
    let (mut worst, mut modes, mut resting) = (0.0f64, [[0usize; 2]; 2], 0);
    let mut ws = Workspace::new(&mech);
    for r in 0..tr.len() {
        let (t, q, qd) = (tr.t[r], &tr.q[2 * r..2 * r + 2], &tr.qd[2 * r..2 * r + 2]);
        let t_m = torques(t);
        forward(&mech, t, q, qd, &mut Torques(torques), &mut ws).unwrap();
        let (xd, xdd) = (&ws.xd, &ws.xdd);
        let mechanism: f64 = mech
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (v, a) = (&xd[3 * i..3 * i + 3], &xdd[3 * i..3 * i + 3]);
                b.mass * (v[0] * a[0] + v[1] * a[1]) + b.inertia * v[2] * a[2] + b.mass * G * v[1]
            })
            .sum();
        // Rotor 1 on the ground, rotor 2 on link 1 (body 0).
        let omega = [gears[0].n * qd[0], xd[2] + gears[1].n * qd[1]];
        let omega_d = [gears[0].n * ws.qdd[0], xdd[2] + gears[1].n * ws.qdd[1]];
        let (mut input, mut rotors, mut losses) = (0.0, 0.0, 0.0);
        for k in 0..2 {
            let g = gears[k];
            let t = t_m[k] - g.friction(qd[k]) - g.j * omega_d[k];
            let gear_loss = t * g.n * qd[k] - ws.tau[k] * qd[k];
            let at_rest = (g.n * qd[k]).abs() <= 1e-2;
            assert!(gear_loss >= -1e-12 || at_rest, "row {r}: gear {k} loses {gear_loss} W");
            resting += usize::from(at_rest);
            modes[k][usize::from(t * qd[k] < 0.0)] += 1;
            input += t_m[k] * g.n * qd[k];
            rotors += g.j * omega[k] * omega_d[k];
            losses += gear_loss + g.friction(qd[k]) * g.n * qd[k];
        }
        let balance = input - mechanism - rotors - losses - ws.dissipated;
        let scale = input.abs() + mechanism.abs() + rotors.abs() + losses.abs() + ws.dissipated;
        worst = worst.max(balance.abs() / scale);
    }
    assert!(worst <= 1e-12, "power balance off by {worst:e} of its terms");
    assert!(modes.iter().all(|m| m[0] > 0 && m[1] > 0), "both branches of both gears: {modes:?}");
    eprintln!(
        "power balance: worst residual {worst:.2e} of the terms over {} rows ({resting} at rest); branches {modes:?}",
        tr.len()
    );
}

#[test]
fn a_lossy_motor_turning_against_its_housing_is_refused_where_no_branch_holds() {
    // A direct drive (n = 1) at the elbow on link 1 with eta = eta_b = 0.05 and a rotor heavier
    // than the links (J = 0.2 kg m^2): its rotor turns at q1' + q2', and the motoring branch's
    // 1 + J w^T A^-1 (eta n g + e) = 1 + 0.2 (-14.9 + 0.05 * 82.7) < 0 (A^-1 of the arm at the
    // drawing): that branch's orientation flips, and for T2 = -1.9 N m at qd = [1, -1] rad/s
    // Newton-Euler written out has no consistent branch (friction's paradox): forward
    // dynamics says so rather than guess.
    let elbow = Gear { n: 1.0, eta: 0.05, eta_b: 0.05, j: 0.2, c: 0.0, tc: 0.0 };
    let mech = two_link(&GEAR1.spec(), &elbow.spec(), "");
    let (qd, t_m) = ([1.0, -1.0], [0.0, -1.9]);
    assert!(two_link_branches([GEAR1, elbow], qd, t_m).is_empty());
    let err = forward_at(&mech, &[0.3, 0.5], &qd, &t_m).unwrap_err();
    assert!(
        matches!(&err, Error::Kinematics(KinematicsError::GearsJammed { actuators }) if actuators == "q1, q2"),
        "{err}"
    );
}
