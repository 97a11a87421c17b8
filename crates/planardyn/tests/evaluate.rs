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
            assert!((out.values[j * 3 + i] - expected).abs() < 1e-12, "cell ({j}, {i})");
        }
    }
    // theta1 = pi, theta2 = 0 puts the elbows C1 = (-0.4, 0) and C2 = (0.4, 0) 0.8 m apart:
    // two 0.35 m distal links cannot close. NaN, and the next rows continue from where it was.
    let far = sigma_rows(&mech, &q, [0, 1], [&[std::f64::consts::PI], &[0.0]], 0, &[0], &out.x).unwrap();
    assert!(far.values[0].is_nan());
    assert_eq!(far.x, out.x);
}

/// The 5R's side: the sign of (C2 - C1) x (P - C1), the end effector P left or right of the
/// line through the elbows (the RRR dyad's assembly mode), from the points' world positions.
fn five_bar_side(mech: &planardyn::Mechanism, x: &[f64]) -> f64 {
    let at = planardyn::dynamics::query::point_positions(mech, x);
    let [c1, c2, p] = ["C1", "C2", "P"].map(|n| {
        let i = mech.point_id(n).unwrap().0;
        [at[2 * i], at[2 * i + 1]]
    });
    ((c2[0] - c1[0]) * (p[1] - c1[1]) - (c2[1] - c1[1]) * (p[0] - c1[0])).signum()
}

/// Whether the 5R closes at (theta1, theta2), from its model file's numbers alone: the elbows
/// C_i = A_i + 0.25 (cos theta_i, sin theta_i) (A1 = (-0.15, 0), A2 = (0.15, 0)) are at most
/// 0.35 + 0.35 m apart (two distal links of 0.35 m meet). None within 1e-9 m of the fold.
fn five_bar_closes(theta: [f64; 2]) -> Option<bool> {
    let c = [(-0.15, theta[0]), (0.15, theta[1])].map(|(a, t)| [a + 0.25 * t.cos(), 0.25 * t.sin()]);
    let d = (c[1][0] - c[0][0]).hypot(c[1][1] - c[0][1]);
    ((d - 0.7).abs() > 1e-9).then_some(d < 0.7)
}

/// The map's rows by Newton continuation alone, cell after cell as `sigma_rows` walked them
/// before the branch rule (each row from the previous row's start, each cell from its
/// neighbour): per cell the measure and the side of the configuration reached.
fn continued_rows(
    mech: &planardyn::Mechanism,
    axes: [&[f64]; 2],
    i0: usize,
    rows: &[usize],
    x_start: &[f64],
) -> (Vec<Option<(f64, f64)>>, Vec<f64>) {
    use planardyn::kinematics::{assemble_from, sigma_min, Chart, Frame};
    let n = axes[0].len();
    let mut frame = Frame::new(mech);
    let cell = |q: &[f64], from: &[f64], frame: &mut Frame| {
        assemble_from(mech, from, q, frame).ok().map(|()| (sigma_min(mech, &Chart::Inputs, &frame.x), frame.x.clone()))
    };
    let (mut start, mut out) = (x_start.to_vec(), Vec::new());
    for &j in rows {
        let mut row = vec![None; n];
        if let Some((s, x)) = cell(&[axes[0][i0], axes[1][j]], &start, &mut frame) {
            row[i0] = Some((s, five_bar_side(mech, &x)));
            start = x;
        }
        let sides: [Vec<usize>; 2] = [(i0 + 1..n).collect(), (0..i0).rev().collect()];
        for side in sides {
            let mut last = start.clone();
            for i in side {
                match cell(&[axes[0][i], axes[1][j]], &last, &mut frame) {
                    Some((s, x)) => {
                        row[i] = Some((s, five_bar_side(mech, &x)));
                        last = x;
                    }
                    None => last.clone_from(&start),
                }
            }
        }
        out.extend(row);
    }
    (out, start)
}

/// The drawing's branch continued through assembled neighbours by Newton's method, a flood
/// fill over the grid from the cell (i0, j0): a cell is reached from a reached 4-neighbour
/// when continuation from it converges on the drawing's side (a cell that fails from one
/// neighbour is tried again from the next reached). Its measure per cell, None if not reached.
fn flood_filled(mech: &planardyn::Mechanism, axes: [&[f64]; 2], (i0, j0): (usize, usize)) -> Vec<Option<f64>> {
    use planardyn::kinematics::{assemble_from, sigma_min, Chart, Frame};
    let n = axes[0].len();
    let side = five_bar_side(mech, &mech.x0);
    let mut frame = Frame::new(mech);
    let mut reached: Vec<Option<(f64, Vec<f64>)>> = vec![None; n * n];
    let mut queue = std::collections::VecDeque::new();
    assemble_from(mech, &mech.x0, &[axes[0][i0], axes[1][j0]], &mut frame).unwrap();
    reached[j0 * n + i0] = Some((sigma_min(mech, &Chart::Inputs, &frame.x), frame.x.clone()));
    queue.push_back((i0, j0));
    while let Some((i, j)) = queue.pop_front() {
        let from = reached[j * n + i].as_ref().unwrap().1.clone();
        let near = [(i.wrapping_sub(1), j), (i + 1, j), (i, j.wrapping_sub(1)), (i, j + 1)];
        for (a, b) in near {
            if a >= n || b >= n || reached[b * n + a].is_some() {
                continue;
            }
            let ok = assemble_from(mech, &from, &[axes[0][a], axes[1][b]], &mut frame).is_ok();
            if ok && five_bar_side(mech, &frame.x) == side {
                reached[b * n + a] = Some((sigma_min(mech, &Chart::Inputs, &frame.x), frame.x.clone()));
                queue.push_back((a, b));
            }
        }
    }
    reached.into_iter().map(|c| c.map(|(s, _)| s)).collect()
}

#[test]
fn the_map_shows_the_drawings_branch_at_every_cell_that_closes() {
    use planardyn::dynamics::sigma_rows;
    use planardyn::kinematics::ClosedForm;
    let mech = shipped("five-bar.yaml");
    assert!(
        ClosedForm::new(&mech).is_some_and(|c| c.is_explicit()),
        "the 5R's dyad has a closed form without iteration: the branch rule's path is the one tested"
    );
    let q = mech.drawn_q();
    // The page's grid (web/src/map.js): 60 x 60 cell centres over q +- pi, the middle row
    // first, then the rows above it, then those below.
    const N: usize = 60;
    let axis = |k: usize| -> Vec<f64> { (0..N).map(|i| q[k] - PI + 2.0 * PI * (i as f64 + 0.5) / N as f64).collect() };
    let (a0, a1) = (axis(0), axis(1));
    let axes: [&[f64]; 2] = [&a0, &a1];
    let (j0, i0) = (N / 2, N / 2);
    let order: Vec<usize> = (j0..N).chain((0..j0).rev()).collect();
    let map = sigma_rows(&mech, &q, [0, 1], axes, i0, &order, &mech.x0).unwrap();
    assert_eq!(map.x, mech.x0, "the branch's reference is handed on");
    let mut sigma = vec![f64::NAN; N * N];
    for (r, &j) in order.iter().enumerate() {
        sigma[j * N..(j + 1) * N].copy_from_slice(&map.values[r * N..(r + 1) * N]);
    }
    // The same configurations to Newton's tolerance: sigma to 1e-12 of its scale (1 far from a
    // singularity; relative to itself near a fold, where Newton converges slowly and its
    // stopping tolerance shows: 2.2e-12 relative at sigma 0.047 measured, 1.0e-13 absolute).
    let worst = std::cell::Cell::new(0.0f64);
    let close = |a: f64, b: f64| {
        worst.set(worst.get().max((a - b).abs() / b));
        (a - b).abs() <= 1e-12 * b.max(1.0)
    };
    // A missing cell is one where the 5R does not close at all (the model's geometry), and a
    // present one where it does.
    for j in 0..N {
        for i in 0..N {
            if let Some(closes) = five_bar_closes([a0[i], a1[j]]) {
                assert_eq!(sigma[j * N + i].is_finite(), closes, "cell ({j}, {i}): {}", sigma[j * N + i]);
            }
        }
    }
    // The branch continued through assembled neighbours (a flood fill by Newton's method) is
    // the map's wherever it reaches.
    let flood = flood_filled(&mech, axes, (i0, j0));
    let reached = flood.iter().flatten().count();
    for (c, f) in flood.iter().enumerate() {
        if let Some(f) = f {
            assert!(close(sigma[c], *f), "cell {c}: {} vs the flood fill's {f}", sigma[c]);
        }
    }
    // The old walk (rows continued from the previous row's start): equal wherever it reached a
    // configuration on the drawing's side; elsewhere it had jumped to the other elbow.
    let side = five_bar_side(&mech, &mech.x0);
    let (mid, x_mid) = continued_rows(&mech, axes, i0, &order[..1], &mech.x0);
    let (rest, _) = continued_rows(&mech, axes, i0, &order[1..], &x_mid);
    let (mut same, mut other) = (0, 0);
    for (&j, row) in order.iter().zip(mid.chunks(N).chain(rest.chunks(N))) {
        for (i, cell) in row.iter().enumerate() {
            match cell {
                Some((s, d)) if *d == side => {
                    assert!(close(sigma[j * N + i], *s), "cell ({j}, {i}): {} vs {s}", sigma[j * N + i]);
                    same += 1;
                }
                Some(_) => other += 1,
                None => {}
            }
        }
    }
    let present = sigma.iter().filter(|s| s.is_finite()).count();
    let worst = worst.get();
    println!("{present} of {} cells present, {reached} reached by the flood fill; the old walk: {same} on the drawing's side, {other} on the other; largest relative difference {worst:.2e}", N * N);
    // The grid crosses the folds (3208 of 3600 cells close); the flood fill reaches every cell
    // that closes (on this grid the rule and the flood fill are one map), the old walk 2609
    // on the drawing's side (and 26 on the other elbow).
    assert!(present > N * N / 4 && present < N * N - N, "{present} cells present");
    assert_eq!(reached, present, "cells reached by the flood fill");
    assert!(same > present / 2, "{same} cells of the old walk on the drawing's side");
}
