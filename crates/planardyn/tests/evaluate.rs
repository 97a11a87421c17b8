//! `dynamics::evaluate`, the one-call state of an interactive view (the browser app): at rest
//! its efforts are the holding torques (virtual work, stated in the model file) and the ground
//! carries the weight; in motion its efforts are inverse dynamics' and its reactions are those
//! of a forward evaluation under them.

mod common;
use common::*;
use planardyn::dynamics::{self, evaluate, FixedDrives};
use planardyn::kinematics::assemble_into;
use planardyn::Workspace;
use std::f64::consts::PI;

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

/// The map's rows by Newton continuation alone, cell after cell as `sigma_rows` walks them
/// (its walk before the closed forms placed the cells): the reference of the closed-form path.
fn continued_rows(
    mech: &planardyn::Mechanism,
    axes: [&[f64]; 2],
    i0: usize,
    rows: &[usize],
    x_start: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    use planardyn::kinematics::{assemble_from, sigma_min, Chart, Frame};
    let n = axes[0].len();
    let mut frame = Frame::new(mech);
    let cell = |q: &[f64], from: &[f64], frame: &mut Frame| {
        assemble_from(mech, from, q, frame).ok().map(|()| (sigma_min(mech, &Chart::Inputs, &frame.x), frame.x.clone()))
    };
    let (mut start, mut sigma) = (x_start.to_vec(), Vec::new());
    for &j in rows {
        let mut row = vec![f64::NAN; n];
        if let Some((s, x)) = cell(&[axes[0][i0], axes[1][j]], &start, &mut frame) {
            row[i0] = s;
            start = x;
        }
        let sides: [Vec<usize>; 2] = [(i0 + 1..n).collect(), (0..i0).rev().collect()];
        for side in sides {
            let mut last = start.clone();
            for i in side {
                match cell(&[axes[0][i], axes[1][j]], &last, &mut frame) {
                    Some((s, x)) => {
                        row[i] = s;
                        last = x;
                    }
                    None => last.clone_from(&start),
                }
            }
        }
        sigma.extend(row);
    }
    (sigma, start)
}

#[test]
fn the_map_rows_by_closed_forms_are_those_of_continuation_on_the_five_bar() {
    use planardyn::dynamics::sigma_rows;
    use planardyn::kinematics::ClosedForm;
    let mech = shipped("five-bar.yaml");
    assert!(
        ClosedForm::new(&mech).is_some_and(|c| c.is_explicit()),
        "the 5R's dyad has a closed form without iteration: the fast path is the one tested"
    );
    let q = mech.drawn_q();
    // The page's grid (web/src/map.js): 60 x 60 cell centres over q +- pi, the middle row
    // first, then the rows above it, then those below from the middle row's start.
    const N: usize = 60;
    let axis = |k: usize| -> Vec<f64> { (0..N).map(|i| q[k] - PI + 2.0 * PI * (i as f64 + 0.5) / N as f64).collect() };
    let (a0, a1) = (axis(0), axis(1));
    let axes: [&[f64]; 2] = [&a0, &a1];
    let (j0, i0) = (N / 2, N / 2);
    let (up, down): (Vec<usize>, Vec<usize>) = ((j0..N).collect(), (0..j0).rev().collect());
    let fast_up = sigma_rows(&mech, &q, [0, 1], axes, i0, &up[..1], &mech.x0).unwrap();
    let fast_rest = sigma_rows(&mech, &q, [0, 1], axes, i0, &up[1..], &fast_up.x).unwrap();
    let fast_down = sigma_rows(&mech, &q, [0, 1], axes, i0, &down, &fast_up.x).unwrap();
    let (ref_up, x_mid) = continued_rows(&mech, axes, i0, &up[..1], &mech.x0);
    let (ref_rest, x_top) = continued_rows(&mech, axes, i0, &up[1..], &x_mid);
    let (ref_down, x_bottom) = continued_rows(&mech, axes, i0, &down, &x_mid);
    // The same configurations to Newton's tolerance (the continuation's residual is at
    // round-off after its last quadratic step): sigma to 1e-12 relative, and the same cells
    // missing (where the followed branch does not assemble).
    let (mut finite, mut missing) = (0, 0);
    for (fast, reference) in [(&fast_up, &ref_up), (&fast_rest, &ref_rest), (&fast_down, &ref_down)] {
        for (c, (a, b)) in fast.sigma.iter().zip(reference).enumerate() {
            assert_eq!(a.is_nan(), b.is_nan(), "cell {c}: {a} vs {b}");
            if a.is_nan() {
                missing += 1;
            } else {
                assert!((a - b).abs() <= 1e-12 * b, "cell {c}: {a} vs {b}");
                finite += 1;
            }
        }
    }
    // The grid crosses the folds (cells that do not assemble) and the rows restart after them.
    assert!(finite > N * N / 4 && missing > N, "{finite} cells measured, {missing} missing");
    // The branch: the rows' start cells (where the next rows continue) are the same
    // configurations, elbows on the same sides, to 1e-12 m.
    for (fast, reference) in [(&fast_up.x, &x_mid), (&fast_rest.x, &x_top), (&fast_down.x, &x_bottom)] {
        for (a, b) in fast.iter().zip(reference) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }
}
