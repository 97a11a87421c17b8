//! `dynamics::evaluate`, the one-call state of an interactive view (the browser app): at rest
//! its efforts are the holding torques (virtual work, stated in the model file) and the ground
//! carries the weight; in motion its efforts are inverse dynamics' and its reactions are those
//! of a forward evaluation under them.

mod common;
use common::*;
use planardyn::dynamics::{self, evaluate, FixedDrives};
use planardyn::kinematics::assemble_into;
use planardyn::Workspace;

/// The five-bar's holding torques in its drawing, from its model file's comment: dV/dq by
/// virtual work, central differences of the potential energy with the same numbers
/// (tests/data/PROVENANCE.md), an independent computation.
const HOLDING: [f64; 2] = [-2.41181824467418, 2.6065835618815925];
/// Central differences of V err by O(h^2) truncation and eps V / h round-off: about 1e-10 N m
/// (1.8e-10 measured on theta1); 1e-9 N m.
const HOLDING_TOL: f64 = 1e-9;
/// Its total mass (kg): bars 0.5 + 0.5 + 0.7 + 0.7 and the 0.3 kg end effector.
const MASS: f64 = 2.7;
const G: f64 = 9.81;
/// Force balance of sums of a few products of size ~10 N: round-off, 1e-12 N.
const BALANCE_TOL: f64 = 1e-12;

#[test]
fn at_rest_the_efforts_hold_the_drawing_and_the_ground_carries_the_weight() {
    let mech = shipped("five-bar.yaml");
    let q = mech.drawn_q();
    let e = evaluate(&mech, &q, &[0.0; 2], &[0.0; 2], None).unwrap();
    for (tau, holding) in e.tau.iter().zip(HOLDING) {
        assert!((tau - holding).abs() < HOLDING_TOL, "tau {tau} vs holding {holding}");
    }
    // The ground's pairs (motor1, motor2: ground is body a) push the mechanism up by its weight.
    let names = mech.pair_names();
    let ground: Vec<_> = ["motor1", "motor2"].iter().map(|n| names.iter().position(|p| p == n).unwrap()).collect();
    let fx: f64 = ground.iter().map(|&k| e.reactions[k][0]).sum();
    let fy: f64 = ground.iter().map(|&k| e.reactions[k][1]).sum();
    assert!(fx.abs() < BALANCE_TOL && (fy - MASS * G).abs() < BALANCE_TOL, "ground force ({fx}, {fy})");
    assert_eq!((e.kinetic, e.xd.iter().all(|v| *v == 0.0)), (0.0, true));
    assert!(e.sigma > 0.0 && e.sigma_passive > 0.0);
}

#[test]
fn in_motion_the_reactions_are_those_of_forward_dynamics_under_the_efforts() {
    let mech = shipped("five-bar.yaml");
    let q: Vec<f64> = mech.drawn_q().iter().zip([0.1, -0.2]).map(|(q, d)| q + d).collect();
    let (qd, qdd) = ([0.3, -0.5], [1.0, 2.0]);
    let e = evaluate(&mech, &q, &qd, &qdd, None).unwrap();
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &q, &mut ws).unwrap();
    dynamics::inverse(&mech, &q, &qd, &qdd, &mut ws).unwrap();
    assert_eq!(e.tau, ws.tau);
    dynamics::forward(&mech, 0.0, &q, &qd, &mut FixedDrives(e.tau.clone()), &mut ws).unwrap();
    // Forward under the efforts gives back the accelerations asked for (round-off of two solves).
    for (a, b) in ws.qdd.iter().zip(qdd) {
        assert!((a - b).abs() < 1e-9, "qdd {a} vs {b}");
    }
    assert_eq!(e.reactions, dynamics::reactions(&mech, &mut ws));
}

#[test]
fn the_map_rows_measure_each_cell_on_the_branch_followed_and_mark_what_does_not_assemble() {
    use planardyn::dynamics::sigma_rows;
    use planardyn::kinematics::{assemble, sigma_min, Chart};
    let mech = shipped("five-bar.yaml");
    let q = mech.drawn_q();
    // A 3 x 2 grid of small moves around the drawing: every cell is the branch drawn, so each
    // measure is that of the configuration assembled from the drawing (the same solution of
    // the same Newton tolerance: 1e-12 of sigma ~ 0.3 covers the two continuation paths).
    let axes: [&[f64]; 2] = [&[q[0] - 0.05, q[0], q[0] + 0.05], &[q[1] - 0.04, q[1] + 0.04]];
    let out = sigma_rows(&mech, &q, [0, 1], axes, 1, &[0, 1], &mech.x0).unwrap();
    for j in 0..2 {
        for i in 0..3 {
            let x = assemble(&mech, &[axes[0][i], axes[1][j]]).unwrap();
            let expected = sigma_min(&mech, &Chart::Inputs, &x);
            assert!((out.sigma[j * 3 + i] - expected).abs() < 1e-12, "cell ({j}, {i})");
        }
    }
    // theta1 = pi, theta2 = 0 puts the elbows C1 = (-0.4, 0) and C2 = (0.4, 0) 0.8 m apart:
    // two 0.35 m distal links cannot close. NaN, and the next rows continue from where it was.
    let far = sigma_rows(&mech, &q, [0, 1], [&[std::f64::consts::PI], &[0.0]], 0, &[0], &out.x).unwrap();
    assert!(far.sigma[0].is_nan());
    assert_eq!(far.x, out.x);
}
