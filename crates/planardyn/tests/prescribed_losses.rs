//! Prescribed motion with the pairs' Coulomb friction and a geared motor: the drive effort
//! against inverse dynamics with losses, the power balance drive = frictionless + dissipated,
//! the run's energy balance with the friction's work, and a geared crank whose rotor is its
//! motor's.

mod common;
use common::*;
use planardyn::dynamics::{inverse, motor_torques, ModelDrives};
use planardyn::simulate::{simulate, Settings, Trajectory};
use planardyn::{Mechanism, Workspace};

const OMEGA: f64 = std::f64::consts::TAU;

const PINS: &str = "  - {type: friction, pair: O, mu: 0.2, pin_radius: 0.01}
  - {type: friction, pair: A, mu: 0.2, pin_radius: 0.008}
  - {type: friction, pair: B, mu: 0.2, pin_radius: 0.008}
  - {type: friction, pair: guide, mu: 0.1, length: 0.05}
";

const CRANK_ONLY: &str = "coordinates:
  - {name: phi, pair: O, value: 0.5235987755982988}
drives:
  - {coordinate: phi, motion: {speed: 6.283185307179586}}
";

fn settings(mech: &Mechanism, t_end: f64, t_eval: Vec<f64>) -> Settings {
    let mut s = Settings::for_model(mech).unwrap();
    s.t_end = t_end;
    s.options.rtol = 1e-10;
    s.options.atol = 1e-13;
    s.t_eval = Some(t_eval);
    s
}

fn run(mech: &Mechanism, t_end: f64) -> Trajectory {
    let t_eval: Vec<f64> = (0..=20).map(|k| k as f64 * t_end / 20.0).collect();
    let tr = simulate(mech, &settings(mech, t_end, t_eval), &mut ModelDrives(mech), None).unwrap();
    assert!(tr.success(), "{}", tr.message);
    tr
}

/// Along one turn at constant speed: the crank torque equals inverse dynamics with losses of
/// the motion, and its power is the frictionless torque's plus the power the friction
/// dissipates (drive = frictionless + dissipated, W).
#[test]
fn crank_power_is_the_frictionless_power_plus_the_dissipated_power() {
    let (rough, smooth) =
        (slider_crank_at_speed(&format!("{PINS}{CRANK_ONLY}"), false), slider_crank_at_speed(CRANK_ONLY, false));
    let tr = run(&rough, 1.0);
    let (mut ws, mut ws0) = (Workspace::new(&rough), Workspace::new(&smooth));
    let nx = rough.n_x();
    let mut least = f64::INFINITY;
    for k in 0..tr.len() {
        let (q, tau) = (tr.q[k], tr.tau[k]);
        ws.x.copy_from_slice(&tr.x[k * nx..(k + 1) * nx]);
        ws0.x.copy_from_slice(&tr.x[k * nx..(k + 1) * nx]);
        inverse(&rough, &[q], &[OMEGA], &[0.0], &mut ws).unwrap();
        inverse(&smooth, &[q], &[OMEGA], &[0.0], &mut ws0).unwrap();
        // Two solves of the same equations, the forward one through its multiplier.
        assert!((tau - ws.tau[0]).abs() <= 1e-10 * (1.0 + tau.abs()), "t = {}: {tau} vs {}", tr.t[k], ws.tau[0]);
        let balance = tau * OMEGA - ws0.tau[0] * OMEGA - ws.dissipated;
        assert!(balance.abs() <= 1e-10 * (tau * OMEGA).abs().max(1.0), "t = {}: {balance} W", tr.t[k]);
        least = least.min(ws.dissipated);
    }
    // Every pin rubs all the way round: the friction dissipates a visible power throughout.
    assert!(least > 0.01, "least dissipated power {least} W");
    // T + V - W, W the work of the crank torque and of the friction, stays constant.
    assert!(tr.stats.energy_drift < 1e-9, "energy balance {} J", tr.stats.energy_drift);
}

/// A free coordinate beside the prescribed crank: a rider on the slider with its own guide
/// (friction too), the energy balance (with the friction's work) closes along the run.
#[test]
fn mixed_run_with_friction_closes_its_energy_balance() {
    let text = format!(
        "{PINS}  - {{type: friction, pair: ride, mu: 0.15, length: 0.04}}
  - {{type: spring, between: [[slider, B], [rider, C]], stiffness: 80.0, rest_length: 0.1}}
coordinates:
  - {{name: phi, pair: O, value: 0.5235987755982988}}
  - {{name: s, pair: ride, value: 0.0, qd0: 0.3}}
drives:
  - {{coordinate: phi, motion: {{speed: 6.283185307179586}}}}
"
    );
    let mech = slider_crank_at_speed(&text, true);
    let tr = run(&mech, 1.0);
    let mut ws = Workspace::new(&mech);
    let nx = mech.n_x();
    for k in 0..tr.len() {
        let (q, qd, qdd) = (&tr.q[2 * k..2 * k + 2], &tr.qd[2 * k..2 * k + 2], &tr.qdd[2 * k..2 * k + 2]);
        ws.x.copy_from_slice(&tr.x[k * nx..(k + 1) * nx]);
        inverse(&mech, q, qd, qdd, &mut ws).unwrap();
        let scale = 1.0 + ws.tau[0].abs();
        assert!(
            (tr.tau[2 * k] - ws.tau[0]).abs() < 1e-8 * scale,
            "t = {}: {} vs {}",
            tr.t[k],
            tr.tau[2 * k],
            ws.tau[0]
        );
        // The free coordinate has no drive: inverse dynamics with its friction needs none.
        assert!(ws.tau[1].abs() < 1e-8 * scale, "t = {}: effort on s {}", tr.t[k], ws.tau[1]);
    }
    assert!(tr.stats.energy_drift < 1e-9, "energy balance {} J", tr.stats.energy_drift);
}

/// A balanced crank (centre of mass on its pivot, I_O = 0.002 kg m^2) behind a motor of ratio
/// n = 10 and rotor J = 1e-4 kg m^2, following q = 2 t^2 - t^3 (a table motion the
/// not-a-knot spline reproduces): the joint-side effort is tau = I_O qdd exactly, qdd = 4 - 6 t,
/// and the motor's torque t_m = J n qdd + tau / n (the rotor before the gear).
#[test]
fn geared_crank_torque_is_its_inertia_and_its_motor_turns_the_rotor() {
    let times: Vec<f64> = (0..=8).map(|k| k as f64 / 8.0).collect();
    let q = |t: f64| 2.0 * t * t - t.powi(3);
    let tt: Vec<String> = times.iter().map(|t| t.to_string()).collect();
    let qq: Vec<String> = times.iter().map(|&t| q(t).to_string()).collect();
    let mech = yaml(&format!(
        r#"
name: geared crank
gravity: [0, -9.81]
points: {{O: [0, 0], A: [0.1, 0]}}
ground: [O]
bodies:
  crank: {{points: [O, A], mass: 1.0, inertia: 0.002, com: O}}
pairs:
  - {{type: revolute, name: O, at: O, bodies: [ground, crank]}}
coordinates:
  - {{name: phi, pair: O, value: 0.0}}
actuators:
  - {{coordinate: phi, gear_ratio: 10.0, rotor_inertia: 1.0e-4}}
drives:
  - {{coordinate: phi, motion: {{table: {{t: [{}], q: [{}]}}}}}}
"#,
        tt.join(", "),
        qq.join(", ")
    ));
    let tr = run(&mech, 1.0);
    let mut ws = Workspace::new(&mech);
    for k in 0..tr.len() {
        let qdd = 4.0 - 6.0 * tr.t[k];
        assert!((tr.tau[k] - 0.002 * qdd).abs() <= 1e-9, "t = {}: {} vs {} N m", tr.t[k], tr.tau[k], 0.002 * qdd);
        inverse(&mech, &tr.q[k..=k], &tr.qd[k..=k], &tr.qdd[k..=k], &mut ws).unwrap();
        let mut t_m = [0.0];
        motor_torques(&mech, &ws, &tr.tau[k..=k], &mut t_m);
        let expected = (1e-4 * 10.0 + 0.002 / 10.0) * qdd;
        assert!((t_m[0] - expected).abs() <= 1e-10, "t = {}: motor {} vs {expected} N m", tr.t[k], t_m[0]);
    }
    // The rotor's kinetic energy is outside T and its motor's: the work counts the gear's
    // power into the crank, so the balance closes.
    assert!(tr.stats.energy_drift < 1e-9, "energy balance {} J", tr.stats.energy_drift);
}
