//! Exact first derivatives of inverse and forward dynamics against 8th-order central
//! differences of the dynamics themselves, on every shipped model.

mod common;

use common::{every_model, test_state, yaml};
use planardyn::dynamics::{
    forward, forward_derivatives, inverse, inverse_derivatives, motion_derivatives, FixedDrives, Jacobians,
};
use planardyn::kinematics::{assemble_into, Chart};
use planardyn::{Mechanism, Workspace};

/// Weights of f(x + i h) - f(x - i h), i = 1..4, in the 8th-order central difference.
const STENCIL: [f64; 4] = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];

/// Central difference of `f` in argument `which` (0, 1, 2) and component k, step h.
fn difference(
    f: &mut dyn FnMut(&[Vec<f64>; 3]) -> Vec<f64>,
    at: &[Vec<f64>; 3],
    which: usize,
    k: usize,
    h: f64,
) -> Vec<f64> {
    let mut out = Vec::new();
    for (i, w) in STENCIL.iter().enumerate() {
        for sign in [1.0, -1.0] {
            let mut p = at.clone();
            p[which][k] += sign * (i + 1) as f64 * h;
            let value = f(&p);
            out.resize(value.len(), 0.0);
            for (o, v) in out.iter_mut().zip(value) {
                *o += sign * w * v / h;
            }
        }
    }
    out
}

/// The largest difference of `exact` (m x m) and the central differences, over the
/// largest entry of either (the Jacobian's scale). A Jacobian zero in exact arithmetic (a
/// gear train without gravity: every entry below 1e-12 in SI units, round-off) has scale 1.
fn relative_error(
    f: &mut dyn FnMut(&[Vec<f64>; 3]) -> Vec<f64>,
    at: &[Vec<f64>; 3],
    which: usize,
    exact: &[f64],
    h: f64,
) -> f64 {
    let m = at[0].len();
    let mut scale = exact.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let mut err = 0.0_f64;
    for k in 0..m {
        for (i, d) in difference(f, at, which, k, h).iter().enumerate() {
            err = err.max((exact[i * m + k] - d).abs());
            scale = scale.max(d.abs());
        }
    }
    err / if scale < 1e-12 { 1.0 } else { scale }
}

/// Every shipped model without losses (exact derivatives cover ideal joints and drives; one
/// with transmissions or pin friction, the geared five-bar robot, is refused), and Andrews'
/// squeezer with its spring damped (no shipped model has a damped spring between two moving
/// bodies).
fn models() -> Vec<Mechanism> {
    let path = format!("{}/../../examples/models/andrews-squeezer.yaml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("damping: 0.0"));
    let mut all: Vec<Mechanism> = every_model().into_iter().filter(|m| !m.has_losses()).collect();
    all.push(yaml(&text.replace("damping: 0.0", "damping: 40.0")));
    all
}

/// A state of the model where it assembles: away from the drawing if it can.
fn state(mech: &Mechanism) -> (Workspace, [Vec<f64>; 3]) {
    let (q_off, qd) = test_state(mech);
    let mut ws = Workspace::new(mech);
    let q = if assemble_into(mech, &q_off, &mut ws).is_ok() { q_off } else { mech.initial_state().0 };
    assemble_into(mech, &q, &mut ws).unwrap();
    let third: Vec<f64> = (0..q.len()).map(|k| 1.3 - 0.9 * k as f64).collect();
    (ws, [q, qd, third])
}

fn check(name: &str, jac: &Jacobians, f: &mut dyn FnMut(&[Vec<f64>; 3]) -> Vec<f64>, at: &[Vec<f64>; 3]) {
    // Steps: 1e-3 in q (rad or m: truncation (4h / L)^8 small for links L >= 0.05 m, round-off
    // 1e-16 / h; 1e-2 left 3e-7 on a short-cranked slider-crank),
    // 1e-1 in qd and the third argument (the maps are quadratic and affine in them).
    for (which, exact, h) in [(0, &jac.dq, 1e-3), (1, &jac.dqd, 1e-1), (2, &jac.dthird, 1e-1)] {
        let e = relative_error(f, at, which, exact, h);
        assert!(e <= 1e-8, "{name}: argument {which}: relative error {e:e}");
    }
}

#[test]
fn inverse_dynamics_derivatives_match_central_differences_on_every_model() {
    for mech in models() {
        let (ws0, at) = state(&mech);
        let mut ws = ws0.clone();
        let jac = inverse_derivatives(&mech, &at[0], &at[1], &at[2], &mut ws).unwrap();
        let mut f = |p: &[Vec<f64>; 3]| {
            let mut ws = ws0.clone();
            inverse(&mech, &p[0], &p[1], &p[2], &mut ws).unwrap();
            ws.tau.clone()
        };
        check(&format!("{} inverse", mech.name), &jac, &mut f, &at);
    }
}

#[test]
fn forward_dynamics_derivatives_match_central_differences_on_every_model() {
    for mech in models() {
        let (ws0, at) = state(&mech);
        let mut ws = ws0.clone();
        let (qdd, jac) = forward_derivatives(&mech, &at[0], &at[1], &at[2], &mut ws).unwrap();
        let mut f = |p: &[Vec<f64>; 3]| {
            let mut ws = ws0.clone();
            ws.chart = Chart::Inputs;
            forward(&mech, 0.0, &p[0], &p[1], &mut FixedDrives(&p[2]), &mut ws).unwrap();
            ws.qdd.clone()
        };
        // The same accelerations as forward dynamics, to round-off (A^-1 (tau + b) there with
        // the drives inside b).
        let reference = f(&at);
        let scale = reference.iter().fold(1.0_f64, |a, v| a.max(v.abs()));
        assert!(qdd.iter().zip(&reference).all(|(a, b)| (a - b).abs() <= 1e-12 * scale), "{}", mech.name);
        check(&format!("{} forward", mech.name), &jac, &mut f, &at);
    }
}

#[test]
fn power_derivatives_match_central_differences_on_every_model() {
    // The power of the non-conservative forces P(q, qd) at fixed tau, drives included.
    for mech in models() {
        let (ws0, at) = state(&mech);
        let mut ws = ws0.clone();
        let (_, _, power) = motion_derivatives(&mech, &at[0], &at[1], &at[2], &mut ws).unwrap();
        let mut f = |p: &[Vec<f64>; 3]| {
            let mut ws = ws0.clone();
            ws.chart = Chart::Inputs;
            forward(&mech, 0.0, &p[0], &p[1], &mut FixedDrives(&p[2]), &mut ws).unwrap();
            vec![ws.power]
        };
        for (which, exact, h) in [(0, &power.dq, 1e-3), (1, &power.dqd, 1e-1)] {
            let fd: Vec<f64> = (0..exact.len()).map(|k| difference(&mut f, &at, which, k, h)[0]).collect();
            let scale = exact.iter().chain(&fd).fold(0.0_f64, |a, v| a.max(v.abs()));
            let err = exact.iter().zip(&fd).fold(0.0_f64, |a, (e, d)| a.max((e - d).abs()));
            assert!(err <= 1e-8 * scale.max(1e-4), "{}: argument {which}: {exact:?} vs {fd:?}", mech.name);
        }
    }
}
