//! The regressor form tau = Y(q, qd, qdd) pi + tau_o against inverse dynamics.

mod common;

use common::{every_model, test_state, yaml, FOUR_BAR};
use planardyn::dynamics::regressor::{n_parameters, parameter_names, parameters, regressor, BODY_PARAMETERS};
use planardyn::dynamics::{inverse, motor_torques};
use planardyn::kinematics::assemble_into;
use planardyn::model::spec::{ActuatorSpec, LoadSpec, PairSpec};
use planardyn::model::Load;
use planardyn::{Mechanism, Workspace};

/// Y pi + tau_o and inverse dynamics (motor torques where a coordinate has an actuator) at
/// (q, qd, qdd) for the parameters `pi` in the frames of `frames` (the model whose
/// kinematics Y is built on) and the dynamics of `model`, with the size of the terms summed.
fn both(
    frames: &Mechanism,
    model: &Mechanism,
    pi: &[f64],
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> (Vec<f64>, Vec<f64>, f64) {
    let m = q.len();
    let mut ws = Workspace::new(frames);
    assemble_into(frames, q, &mut ws).unwrap();
    let p = pi.len();
    assert_eq!(p, n_parameters(frames));
    let (mut y, mut tau_o) = (vec![0.0; m * p], vec![0.0; m]);
    regressor(frames, q, qd, qdd, None, &mut ws, &mut y, &mut tau_o).unwrap();
    let linear: Vec<f64> = (0..m).map(|j| (0..p).map(|k| y[j * p + k] * pi[k]).sum::<f64>() + tau_o[j]).collect();
    // The size of the terms summed, for a relative tolerance that cancellation cannot fool.
    let scale =
        (0..m).map(|j| (0..p).map(|k| (y[j * p + k] * pi[k]).abs()).sum::<f64>() + tau_o[j].abs()).fold(0.0, f64::max);
    let mut ws = Workspace::new(model);
    assemble_into(model, q, &mut ws).unwrap();
    inverse(model, q, qd, qdd, &mut ws).unwrap();
    let mut t_m = vec![0.0; m];
    motor_torques(model, &ws, &ws.tau, &mut t_m);
    (linear, t_m, scale)
}

/// A state of `mech` away from its drawing where it assembles there (not every model does
/// at q0 + 0.05 (k + 1)), else at its start, with accelerations.
fn state(mech: &Mechanism) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (q_off, qd) = test_state(mech);
    let q = if assemble_into(mech, &q_off, &mut Workspace::new(mech)).is_ok() { q_off } else { mech.initial_state().0 };
    let qdd = (0..q.len()).map(|k| 1.3 - 0.9 * k as f64).collect();
    (q, qd, qdd)
}

/// `mech` with real drives: a geared motor on every coordinate (unless it has pair
/// actuators, which share the coordinates' efforts), and a load on every revolute pair
/// (`friction_law`: its type and coefficients in the model file's form), as
/// tests/actuators.rs gives them.
fn with_losses(mech: &Mechanism, friction_law: &str) -> Mechanism {
    let mut spec = mech.spec.clone();
    if mech.pair_actuators.is_empty() {
        for (c, _) in mech.coordinates.iter().zip(&mech.actuators).filter(|(_, a)| a.is_none()) {
            let text = format!(
                "{{coordinate: {}, name: motor_{}, gear_ratio: 20, efficiency: 0.85, rotor_inertia: 2.0e-5, \
                 viscous: 1.0e-4, coulomb: 0.01, stiction_speed: 0.5}}",
                c.name, c.name
            );
            spec.actuators.push(serde_yaml_ng::from_str::<ActuatorSpec>(&text).unwrap());
        }
    }
    let mut friction = Vec::new();
    for (i, pair) in spec.pairs.iter_mut().enumerate() {
        if let PairSpec::Revolute { name, .. } = pair {
            let name = name.get_or_insert_with(|| format!("pin{i}"));
            let text = format!("{{pair: {name}, {friction_law}}}");
            friction.push(serde_yaml_ng::from_str::<LoadSpec>(&text).unwrap());
        }
    }
    spec.loads.extend(friction);
    planardyn::build(spec, "with losses").unwrap_or_else(|e| panic!("{}: {e}", mech.name))
}

/// Y pi + tau_o against inverse dynamics at the model's pi, to `rtol` of the terms' size.
/// Pin friction and viscous damping.
const PIN: &str = "type: friction, mu: 0.08, mu_static: 0.12, pin_radius: 0.01, viscous: 0.002";

fn check_model(mech: &Mechanism, rtol: f64) {
    let (q, qd, qdd) = state(mech);
    let pi = parameters(mech);
    assert_eq!(parameter_names(mech).len(), pi.len());
    let (linear, tau, scale) = both(mech, mech, &pi, &q, &qd, &qdd);
    for (a, b) in linear.iter().zip(&tau) {
        assert!((a - b).abs() <= rtol * scale.max(1e-300), "{}: Y pi + tau_o {linear:?} vs {tau:?}", mech.name);
    }
}

#[test]
fn y_pi_is_inverse_dynamics_on_every_model() {
    // Exact in exact arithmetic; round-off of sums of a few dozen terms: 1e-12 of their size.
    for mech in every_model() {
        let damper = |l: &Load| matches!(l, Load::PairSpring(s) if s.stiffness == 0.0);
        if !mech.has_losses() && !mech.loads.iter().any(damper) {
            assert_eq!(n_parameters(&mech), BODY_PARAMETERS * mech.bodies.len(), "{}", mech.name);
        }
        check_model(&mech, 1e-12);
    }
}

#[test]
fn y_pi_is_inverse_dynamics_with_motors_and_pin_friction_on_every_model() {
    // The bound, 1e-10 of the terms' size: the pin friction settles to 1e-13 of
    // itself (dynamics::losses' fixed point), the rest is round-off as above.
    let mut lossy = 0;
    for mech in every_model() {
        let mech = with_losses(&mech, PIN);
        lossy += usize::from(mech.has_losses());
        check_model(&mech, 1e-10);
    }
    assert!(lossy >= 20, "{lossy} models with losses");
}

#[test]
fn the_loss_parameters_are_named_with_the_models_values() {
    let mech = with_losses(&yaml(FOUR_BAR), PIN);
    let names = parameter_names(&mech);
    let pi = parameters(&mech);
    let value = |name: &str| pi[names.iter().position(|n| n == name).unwrap_or_else(|| panic!("{name} in {names:?}"))];
    let motor = format!("motor_{}", mech.coordinates[0].name);
    assert_eq!(
        [value(&format!("J_{motor}")), value(&format!("fv_{motor}")), value(&format!("fc_{motor}"))],
        [2.0e-5, 1.0e-4, 0.01]
    );
    let pair = &mech.pairs[0].name;
    assert_eq!(
        [value(&format!("fvp_{pair}")), value(&format!("mu_{pair}")), value(&format!("fcp_{pair}"))],
        [0.002, 0.08, 0.0]
    );
}

#[test]
fn redundant_actuation_rows_are_the_generalized_efforts() {
    // The five-bar with a third actuator on its left elbow (2 degrees of freedom, 3
    // actuators) and viscous friction (the model refuses pin friction there: its reactions
    // depend on how the efforts are shared): the rows are inverse dynamics' generalized
    // efforts, which B tau_a of any distribution of the actuators' efforts equals.
    let mut spec =
        with_losses(&common::shipped("five-bar.yaml"), "type: torsional_spring, stiffness: 0.0, damping: 0.002").spec;
    spec.actuators = vec![serde_yaml_ng::from_str::<ActuatorSpec>("{pair: elbow1}").unwrap()];
    let mech = planardyn::build(spec.clone(), "redundant five-bar").unwrap();
    assert_eq!(mech.pair_actuators.len(), 1);
    assert_eq!(n_parameters(&mech), 4 * 4 + 5, "bodies and the five pairs' damping");
    check_model(&mech, 1e-10);
    // With transmissions the motor torques are not rows of the coordinates: refused.
    let mut geared = spec;
    geared.actuators.push(serde_yaml_ng::from_str::<ActuatorSpec>("{coordinate: theta1, gear_ratio: 10}").unwrap());
    let mech = planardyn::build(geared, "redundant geared five-bar").unwrap();
    let (q, qd, qdd) = state(&mech);
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &q, &mut ws).unwrap();
    let p = n_parameters(&mech);
    let err = regressor(&mech, &q, &qd, &qdd, None, &mut ws, &mut vec![0.0; 2 * p], &mut [0.0; 2]).unwrap_err();
    assert!(err.to_string().contains("pair actuators"), "{err}");
}

#[test]
fn a_moved_centre_of_mass_is_other_numbers_in_pi() {
    // The coupler's real centre of mass 0.1 m along and 0.05 m across its line from the
    // model's, and heavier: the same Y, with pi = [m, m d_x, m d_y, I_com + m |d|^2] for the
    // offset d in the model's coupler frame (origin at its centre of mass, x along A -> B),
    // gives the efforts of the model drawn with that centre of mass.
    let frames = yaml(FOUR_BAR);
    let (ax, ay, bx, by): (f64, f64, f64, f64) = (0.25, 0.4330127018922193, 1.336926485022576, 0.9415309573722639);
    let len = (bx - ax).hypot(by - ay);
    let e = [(bx - ax) / len, (by - ay) / len];
    let d = [0.1, 0.05];
    let com = [0.793463242511288 + d[0] * e[0] - d[1] * e[1], 0.6872718296322415 + d[0] * e[1] + d[1] * e[0]];
    let (mass, inertia) = (1.5, 0.2);
    let moved = yaml(&FOUR_BAR.replace(
        "coupler: {points: [A, B], mass: 1.2, inertia: 0.144, com: [0.793463242511288, 0.6872718296322415]}",
        &format!("coupler: {{points: [A, B], mass: {mass}, inertia: {inertia}, com: [{}, {}]}}", com[0], com[1]),
    ));
    assert_ne!(moved.bodies[1].mass, frames.bodies[1].mass);
    let mut pi = parameters(&frames);
    pi[4..8].copy_from_slice(&[mass, mass * d[0], mass * d[1], inertia + mass * (d[0] * d[0] + d[1] * d[1])]);
    let (q, qd) = test_state(&frames);
    let (linear, tau, scale) = both(&frames, &moved, &pi, &q, &qd, &[2.5]);
    assert!((linear[0] - tau[0]).abs() <= 1e-12 * scale, "Y pi + tau_o {linear:?} vs {tau:?}");
}
