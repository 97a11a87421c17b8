//! Friction at a gear mesh (docs/actuators.md, *Friction at a gear mesh*) against the closed
//! forms of a two-gear train: a pinion (r_a = 20 mm, I_a = 4e-5 kg m^2) driving a wheel
//! (r_b = 60 mm, I_b = 1.08e-3 kg m^2) on fixed axes, n = r_a / r_b = 1/3, a drive torque
//! T_in on the pinion and a load torque T_L against the wheel. With c = mu / cos(alpha)
//! and the loss on the driver, F_t the tangential tooth force:
//!
//! - pinion driving:  I_a qdd = T_in - (1 + c) r_a F_t,  I_b n qdd = r_b F_t - T_L, so
//!   qdd = (T_in - (1 + c) n T_L) / (I_a + (1 + c) n^2 I_b), and at qdd = 0 the output
//!   torque is T_L = T_in / (n (1 + c)): efficiency 1 / (1 + c);
//! - wheel driving (load overhauling, T_L < 0): I_a qdd = T_in + r_a F_t,
//!   I_b n qdd = -T_L - (1 + c) r_b F_t, so qdd = ((1 + c) T_in - n T_L) / ((1 + c) I_a + n^2 I_b);
//! - the dissipated power is c F_t |v|, v = r_a qd the pitch speed.

mod common;

use common::{run, yaml};
use planardyn::dynamics::{forward, reactions, ModelDrives};
use planardyn::{Mechanism, Workspace};

const R_A: f64 = 0.02;
const R_B: f64 = 0.06;
const I_A: f64 = 4.0e-5;
const I_B: f64 = 1.08e-3;
const N: f64 = R_A / R_B;
const MU: f64 = 0.08;
const ALPHA: f64 = 20.0 * std::f64::consts::PI / 180.0;

/// The train with drive torque `t_in` on the pinion, `t_load` on the wheel (against its
/// motion when positive: the wheel turns clockwise while the pinion turns counter-clockwise),
/// the pinion starting at `qd0`, and `friction` (a `loads` entry or nothing).
fn train(t_in: f64, t_load: f64, qd0: f64, friction: &str) -> Mechanism {
    yaml(&format!(
        r#"
name: two gears
points: {{O1: [0, 0], T1: [0, 0.02], O2: [0.08, 0], T2: [0.08, 0.06]}}
ground: [O1, O2]
bodies:
  pinion: {{points: [O1, T1], mass: 0.2, com: O1, inertia: {I_A}}}
  wheel: {{points: [O2, T2], mass: 0.6, com: O2, inertia: {I_B}}}
pairs:
  - {{type: revolute, name: pinion_shaft, at: O1, bodies: [ground, pinion]}}
  - {{type: revolute, name: wheel_shaft, at: O2, bodies: [ground, wheel]}}
  - {{type: gear, name: mesh, bodies: [pinion, wheel], centers: [O1, O2], radii: [{R_A}, {R_B}]}}
coordinates:
  - {{name: theta, pair: pinion_shaft, value: 0.0, qd0: {qd0}}}
drives:
  - {{coordinate: theta, effort: {t_in}}}
loads:
  - {{type: torque, body: wheel, value: {t_load}}}
{friction}"#
    ))
}

fn mesh_friction() -> String {
    format!("  - {{type: friction, pair: mesh, mu: {MU}, pressure_angle: {ALPHA}}}\n")
}

const C: f64 = MU / 0.939_692_620_785_908_4; // mu / cos(20 degrees)

/// qdd, the tooth force |F| and the dissipated power of forward dynamics at (q, qd).
fn forward_at(mech: &Mechanism, q: f64, qd: f64) -> (f64, f64, f64) {
    let mut ws = Workspace::new(mech);
    forward(mech, 0.0, &[q], &[qd], &mut ModelDrives(mech), &mut ws).unwrap();
    let r = reactions(mech, &mut ws)[2];
    (ws.qdd[0], r[0].hypot(r[1]), ws.dissipated)
}

#[test]
fn pinion_driving_carries_the_loss_and_the_output_torque_is_t_in_over_n_1_plus_c() {
    assert!((C - MU / ALPHA.cos()).abs() <= 1e-16);
    let (t_in, t_load, qd) = (0.05, 0.09, 20.0);
    let (qdd, tooth, lost) = forward_at(&train(t_in, t_load, qd, &mesh_friction()), 0.3, qd);
    let expected = (t_in - (1.0 + C) * N * t_load) / (I_A + (1.0 + C) * N * N * I_B);
    assert!((qdd - expected).abs() <= 1e-12 * expected.abs(), "qdd {qdd} vs {expected}");
    // The reported tooth force is the one that reaches the wheel.
    let f_t = (I_B * N * expected + t_load) / R_B;
    assert!((tooth - f_t).abs() <= 1e-12 * f_t, "tooth force {tooth} vs {f_t}");
    assert!((lost - C * f_t * R_A * qd).abs() <= 1e-12 * lost, "dissipated {lost}");

    // Steady state: T_in = (1 + c) n T_L holds the train at constant speed; efficiency 1 / (1 + c).
    let t_steady = (1.0 + C) * N * t_load;
    let (qdd, _, lost) = forward_at(&train(t_steady, t_load, qd, &mesh_friction()), 0.3, qd);
    assert!(qdd.abs() <= 1e-12 * t_steady / I_A, "steady qdd {qdd}");
    let efficiency = t_load * N * qd / (t_steady * qd);
    assert!((efficiency - 1.0 / (1.0 + C)).abs() <= 1e-15);
    assert!((t_steady * qd - t_load * N * qd - lost).abs() <= 1e-13, "power balance at steady state");
}

#[test]
fn an_overhauling_load_moves_the_loss_to_the_wheel() {
    // The wheel's load aids its motion and the pinion's drive brakes: the wheel drives.
    let (t_in, t_load, qd) = (-0.01, -0.1, 20.0);
    let (qdd, tooth, lost) = forward_at(&train(t_in, t_load, qd, &mesh_friction()), 0.3, qd);
    let expected = ((1.0 + C) * t_in - N * t_load) / ((1.0 + C) * I_A + N * N * I_B);
    assert!((qdd - expected).abs() <= 1e-12 * expected.abs(), "qdd {qdd} vs {expected}");
    let f_t = (I_A * expected - t_in) / R_A;
    assert!(f_t > 0.0);
    assert!((tooth - f_t).abs() <= 1e-12 * f_t, "tooth force {tooth} vs {f_t}");
    assert!((lost - C * f_t * R_A * qd).abs() <= 1e-12 * lost, "dissipated {lost}");
}

#[test]
fn input_work_is_output_work_plus_kinetic_energy_plus_dissipated_work() {
    // Constant torques: qdd and F_t are constant while the pinion drives, so the dissipated
    // work is c F_t r_a (theta(t) - theta(0)).
    let (t_in, t_load, qd0) = (0.05, 0.09, 20.0);
    let mech = train(t_in, t_load, qd0, &mesh_friction());
    let t_end = 0.5;
    let tr = run(&mech, "dop853", t_end, 1e-11, Some(vec![0.0, t_end]));
    let qdd = (t_in - (1.0 + C) * N * t_load) / (I_A + (1.0 + C) * N * N * I_B);
    let f_t = (I_B * N * qdd + t_load) / R_B;
    let turned = tr.q[1] - tr.q[0];
    assert!((turned - (qd0 * t_end + 0.5 * qdd * t_end * t_end)).abs() <= 1e-8, "theta {turned}");
    let (input, output) = (t_in * turned, t_load * N * turned);
    let kinetic = tr.kinetic[1] - tr.kinetic[0];
    let dissipated = C * f_t * R_A * turned;
    assert!(dissipated > 0.05 * input, "the mesh dissipates {dissipated} J of {input} J");
    assert!((input - output - kinetic - dissipated).abs() <= 1e-9 * input, "balance {input} {output} {kinetic}");
    // The trajectory's work of the non-conservative forces counts the mesh's loss.
    let work = tr.work[1] - tr.work[0];
    assert!((work - (input - output - dissipated)).abs() <= 1e-9 * input, "work {work}");
}

#[test]
fn inverse_drive_power_is_frictionless_power_plus_dissipated_power() {
    // Along a motion that speeds up and slows down (the tooth force changes sign when the
    // wheel's inertia overruns its load, so the driver changes): at every point
    // tau qd = tau_0 qd + dissipated, and while the pinion drives tau is the closed form.
    const T_LOAD: f64 = 0.005;
    let (with, without) = (train(0.0, T_LOAD, 0.0, &mesh_friction()), train(0.0, T_LOAD, 0.0, ""));
    let (mut both, mut wheel_drove) = (0, 0);
    common::power_balance_along(&with, &without, [0.0, 10.0, 0.8, 6.0], 200, (1e-12, 1e-3), |s| {
        let (t, qdd, ws) = (s.t, s.qdd, s.ws);
        assert!(ws.dissipated > 0.0);
        let f_t = (I_B * N * qdd + T_LOAD) / R_B;
        if f_t > 0.0 {
            let tau = I_A * qdd + (1.0 + C) * R_A * f_t;
            assert!((ws.tau[0] - tau).abs() <= 1e-12 * tau.abs(), "t {t}: tau {} vs {tau}", ws.tau[0]);
            both += 1;
        } else {
            let tau = I_A * qdd + R_A * f_t / (1.0 + C);
            assert!((ws.tau[0] - tau).abs() <= 1e-12 * tau.abs(), "t {t}: tau {} vs {tau}", ws.tau[0]);
            wheel_drove += 1;
        }
    });
    assert!(both > 20 && wheel_drove > 20, "pinion drove {both} times, wheel {wheel_drove}");
}

#[test]
fn mesh_friction_fields_are_checked() {
    let bad = |friction: &str, needle: &str| {
        let src = format!(
            "name: g\npoints: {{O1: [0, 0], O2: [0.08, 0]}}\nground: [O1, O2]\nbodies:\n  p: {{points: [O1], mass: 1, \
             com: O1, inertia: 1}}\n  w: {{points: [O2], mass: 1, com: O2, inertia: 1}}\npairs:\n  - {{type: revolute, \
             name: s1, at: O1, bodies: [ground, p]}}\n  - {{type: revolute, name: s2, at: O2, bodies: [ground, w]}}\n  \
             - {{type: gear, name: mesh, bodies: [p, w], centers: [O1, O2], radii: [0.02, 0.06]}}\ncoordinates:\n  - \
             {{name: q, pair: s1, value: 0}}\nloads:\n  - {friction}\n"
        );
        let err = planardyn::loads(&src, planardyn::Format::Yaml, "<test>").map(|_| ()).unwrap_err().to_string();
        assert!(err.contains(needle), "{err}");
    };
    bad("{type: friction, pair: mesh, mu: 0.1, pressure_angle: 1.2}", "pressure angle");
    bad("{type: friction, pair: mesh, mu: 0.1, pin_radius: 0.01}", "pin_radius");
    bad("{type: friction, pair: mesh, viscous: 0.1}", "no relative motion");
    bad("{type: friction, pair: s1, mu: 0.1, pin_radius: 0.01, pressure_angle: 0.3}", "no teeth");
}

#[test]
fn a_rack_carries_the_loss_while_it_drives_its_pinion() {
    // The pinion (r_a = 20 mm) drives a rack (m_r = 0.3 kg, x' = r_a theta') against a force
    // P; the frictionless tooth force is F = m_r r_a qdd + P. Pinion driving (F > 0):
    // tau = I_a qdd + (1 + c) r_a F; rack driving (F < 0, decelerating): tau = I_a qdd + r_a F / (1 + c).
    const P: f64 = 0.005;
    const M_R: f64 = 0.3;
    let rack = |friction: &str| {
        yaml(&format!(
            r#"
name: rack and pinion
points: {{O1: [0, 0], T1: [0, 0.02], R1: [-0.1, -0.02], R2: [0.1, -0.02]}}
ground: [O1]
bodies:
  pinion: {{points: [O1, T1], mass: 0.2, com: O1, inertia: {I_A}}}
  rack: {{points: [R1, R2], uniform_bar: [R1, R2], mass: {M_R}}}
pairs:
  - {{type: revolute, name: pinion_shaft, at: O1, bodies: [ground, pinion]}}
  - {{type: prismatic, name: guide, at: R1, bodies: [ground, rack], axis: [1.0, 0.0]}}
  - {{type: gear, name: mesh, bodies: [pinion, rack], centers: [O1], radii: [{R_A}], rack: [R1, R2]}}
coordinates:
  - {{name: theta, pair: pinion_shaft, value: 0.0}}
loads:
  - {{type: force, body: rack, at: R1, value: [{}, 0.0]}}
{friction}"#,
            -P
        ))
    };
    let (with, without) = (rack(&mesh_friction()), rack(""));
    let (mut pinion_drove, mut rack_drove) = (0, 0);
    common::power_balance_along(&with, &without, [0.0, 10.0, 0.08, 6.0], 200, (1e-12, 1e-3), |s| {
        let (t, qd, qdd, ws) = (s.t, s.qd, s.qdd, s.ws);
        let f = M_R * R_A * qdd + P;
        let tau = if f > 0.0 {
            pinion_drove += 1;
            I_A * qdd + (1.0 + C) * R_A * f
        } else {
            rack_drove += 1;
            I_A * qdd + R_A * f / (1.0 + C)
        };
        assert!((ws.tau[0] - tau).abs() <= 1e-12 * tau.abs(), "t {t}: tau {} vs {tau}", ws.tau[0]);
        // c times the tooth force on the driven gear, times the pitch speed.
        let tooth = if f > 0.0 { f } else { -f / (1.0 + C) };
        assert!((ws.dissipated - C * tooth * R_A * qd).abs() <= 1e-12 * ws.dissipated, "t {t}: {}", ws.dissipated);
    });
    assert!(pinion_drove > 20 && rack_drove > 20, "pinion drove {pinion_drove} times, rack {rack_drove}");
}
