//! The regressor form tau = Y(q, qd, qdd) pi + tau_o against inverse dynamics.

mod common;

use common::{every_model, test_state, yaml, FOUR_BAR};
use planardyn::dynamics::forward::kinematic_stages;
use planardyn::dynamics::inverse;
use planardyn::dynamics::regressor::{parameter_names, parameters, regressor, BODY_PARAMETERS};
use planardyn::kinematics::assemble_into;
use planardyn::{Mechanism, Workspace};

/// Y pi + tau_o and inverse dynamics at (q, qd, qdd) for the parameters `pi` in the frames
/// of `frames` (the model whose kinematics Y is built on) and the dynamics of `model`.
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
    kinematic_stages(frames, q, qd, &mut ws).unwrap();
    let p = pi.len();
    let (mut y, mut tau_o) = (vec![0.0; m * p], vec![0.0; m]);
    regressor(frames, &mut ws, qdd, &mut y, &mut tau_o);
    let linear: Vec<f64> = (0..m).map(|j| (0..p).map(|k| y[j * p + k] * pi[k]).sum::<f64>() + tau_o[j]).collect();
    // The size of the terms summed, for a relative tolerance that cancellation cannot fool.
    let scale =
        (0..m).map(|j| (0..p).map(|k| (y[j * p + k] * pi[k]).abs()).sum::<f64>() + tau_o[j].abs()).fold(0.0, f64::max);
    let mut ws = Workspace::new(model);
    assemble_into(model, q, &mut ws).unwrap();
    inverse(model, q, qd, qdd, &mut ws).unwrap();
    (linear, ws.tau.clone(), scale)
}

#[test]
fn y_pi_is_inverse_dynamics_on_every_model() {
    // Exact in exact arithmetic; round-off of sums of a few dozen terms: 1e-12 of their size.
    for mech in every_model() {
        // Away from the drawing where the model assembles there (not every shipped one
        // does at q0 + 0.05 (k + 1)), else at its start.
        let (q_off, qd) = test_state(&mech);
        let q = if assemble_into(&mech, &q_off, &mut Workspace::new(&mech)).is_ok() {
            q_off
        } else {
            mech.initial_state().0
        };
        let qdd: Vec<f64> = (0..q.len()).map(|k| 1.3 - 0.9 * k as f64).collect();
        let pi = parameters(&mech);
        assert_eq!(pi.len(), BODY_PARAMETERS * mech.bodies.len());
        assert_eq!(parameter_names(&mech).len(), pi.len());
        let (linear, tau, scale) = both(&mech, &mech, &pi, &q, &qd, &qdd);
        for (a, b) in linear.iter().zip(&tau) {
            assert!((a - b).abs() <= 1e-12 * scale.max(1e-300), "{}: Y pi + tau_o {linear:?} vs {tau:?}", mech.name);
        }
    }
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
