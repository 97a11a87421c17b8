//! `dynamics::query`, the one-state entry points a binding calls, against closed forms: the
//! pendulum's (a uniform bar of length l = 0.8 m and mass 2 kg hinged at its end, q its angle
//! from the x axis: I_O = m l^2 / 3, x_G = (l/2)(cos q, sin q), m g (l/2) cos q the gravity
//! torque) and the offset slider-crank's positions on both of its branches (r = 0.1 m,
//! l = 0.35 m, guide at e = 0.02 m: B_x = r cos phi +- sqrt(l^2 - (r sin phi - e)^2)).

mod common;
use common::*;
use planardyn::dynamics::query;
use planardyn::dynamics::redundant::Distribution;
use planardyn::KinematicsError;

/// The pendulum: l, m, g, I_O = m l^2 / 3 (kg m^2).
const L: f64 = 0.8;
const M: f64 = 2.0;
const G: f64 = 9.81;
const I_O: f64 = M * L * L / 3.0;
/// The state compared: an angle away from the axes, a rate, an acceleration, an effort.
const Q: f64 = 0.3;
const QD: f64 = 1.5;
const QDD: f64 = -2.0;
const TAU: f64 = 0.5;
/// Closed form against the core's analogues and dynamics: sums of a few products of O(10)
/// values, round-off of 1e-15 relative; measured worst 3.6e-15 (qdd, the hinge force). 1e-12
/// absolute.
const TOL: f64 = 1e-12;
/// Slider-crank positions from the closed form: Newton converges to `POSITION_TOL` (1e-14 of
/// the scale L = 0.44 m), and the analogue dB_x/dphi to round-off; 1e-11 as
/// `tests/closed_form.rs`'s `X_TOL`. Measured worst 4.4e-16 m (the other branch's B_x).
const X_TOL: f64 = 1e-11;

fn close(got: &[f64], want: &[f64], tol: f64, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: {got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < tol, "{what}: {got:?} vs {want:?}");
    }
}

/// The pendulum at (Q, QD), t = 0, under `tau` (or its drives, none).
fn at(tau: Option<&[f64]>) -> query::ForwardState<'_> {
    query::ForwardState { q: &[Q], qd: &[QD], t: 0.0, tau, allow_singular: false, x_start: None }
}

/// The gravity torque about O (N m) at angle q.
fn gravity_torque(q: f64) -> f64 {
    M * G * L / 2.0 * q.cos()
}

#[test]
fn the_pendulums_kinematics_report_is_its_closed_form() {
    let mech = yaml(PENDULUM);
    let (s, c, h) = (Q.sin(), Q.cos(), L / 2.0);
    let k = query::kinematics(&mech, &[Q], Some(&[QD]), None).unwrap();
    close(&k.x, &[h * c, h * s, Q], TOL, "x");
    close(&k.u, &[-h * s, h * c, 1.0], TOL, "u");
    close(&k.w, &[-h * c, -h * s, 0.0], TOL, "w");
    // The points O (on the ground) and A (the bar's tip), in the model's order.
    close(&k.points, &[0.0, 0.0, L * c, L * s], TOL, "points");
    let r = k.rates.expect("rates were given");
    close(&r.xd, &[-h * s * QD, h * c * QD, QD], TOL, "xd");
    close(&r.c, &[-h * c * QD * QD, -h * s * QD * QD, 0.0], TOL, "c");
    close(&r.point_velocities, &[0.0, 0.0, -L * s * QD, L * c * QD], TOL, "point velocities");
    assert!(k.residual < TOL && k.sigma_min > 0.0, "residual {} sigma {}", k.residual, k.sigma_min);
    // Without rates the report has none, and the same positions.
    let still = query::kinematics(&mech, &[Q], None, None).unwrap();
    assert_eq!((still.rates, still.x), (None, k.x.clone()));
    assert_eq!(query::point_positions(&mech, &k.x), k.points);
}

#[test]
fn the_pendulums_dynamics_are_its_closed_form() {
    let mech = yaml(PENDULUM);
    close(&query::mass_matrix(&mech, &[Q], None, false).unwrap(), &[I_O], TOL, "A");
    // I_O qdd = tau - m g (l/2) cos q.
    let qdd = (TAU - gravity_torque(Q)) / I_O;
    close(&query::forward_dynamics(&mech, at(Some(&[TAU]))).unwrap(), &[qdd], TOL, "qdd");
    close(&query::forward_actuated(&mech, &[Q], &[QD], &[TAU], 0.0).unwrap(), &[qdd], TOL, "qdd actuated");
    // The pendulum has no drives: the model's efforts are zero.
    let free = query::forward_dynamics(&mech, at(None)).unwrap();
    close(&free, &[-gravity_torque(Q) / I_O], TOL, "qdd without drives");
    // dqdd/dq = m g (l/2) sin q / I_O, dqdd/dqd = 0, dqdd/dtau = 1 / I_O.
    let fd = query::forward_derivatives(&mech, at(Some(&[TAU]))).unwrap();
    close(&fd.value, &[qdd], TOL, "qdd of the derivatives");
    let j = &fd.jacobians;
    close(&[j.dq[0], j.dqd[0], j.dthird[0]], &[M * G * L / 2.0 * Q.sin() / I_O, 0.0, 1.0 / I_O], TOL, "dqdd");
    // tau = I_O qdd + m g (l/2) cos q: dtau/dq = -m g (l/2) sin q, dtau/dqd = 0, dtau/dqdd = I_O.
    let id = query::inverse_derivatives(&mech, &[Q], &[QD], &[QDD], false).unwrap();
    let tau = I_O * QDD + gravity_torque(Q);
    close(&id.value, &[tau], TOL, "tau");
    close(&query::inverse_dynamics(&mech, &[Q], &[QD], &[QDD], None).unwrap(), &[tau], TOL, "inverse dynamics");
    let j = &id.jacobians;
    close(&[j.dq[0], j.dqd[0], j.dthird[0]], &[-M * G * L / 2.0 * Q.sin(), 0.0, I_O], TOL, "dtau");
    // One actuator: its share is the whole effort, B = [1], no internal force, no motor.
    let shared = query::distribute_efforts(&mech, &[Q], &[QD], &[QDD], &Distribution::MinNorm, None).unwrap();
    close(&shared.efforts, &[tau], TOL, "efforts");
    close(&shared.motor_torques, &[tau], TOL, "motor torques");
    assert_eq!((shared.actuation.b.clone(), shared.actuation.internal.len()), (vec![1.0], 0));
    // T = I_O qd^2 / 2, V = m g (l/2) sin q.
    let e = query::energy(&mech, &[Q], &[QD], None).unwrap();
    close(&[e.kinetic, e.potential], &[I_O * QD * QD / 2.0, M * G * L / 2.0 * Q.sin()], TOL, "energies");
}

#[test]
fn the_pendulums_hinge_carries_mass_times_the_centres_acceleration_less_gravity() {
    // Newton for the bar: F = m (a_G - g), a_G = u qdd + w qd^2, with qdd from the closed form.
    let mech = yaml(PENDULUM);
    let (s, c, h) = (Q.sin(), Q.cos(), L / 2.0);
    let qdd = (TAU - gravity_torque(Q)) / I_O;
    let a_g = [-h * s * qdd - h * c * QD * QD, h * c * qdd - h * s * QD * QD];
    let r = query::reactions(&mech, at(Some(&[TAU]))).unwrap();
    assert_eq!(r.len(), 1);
    close(&r[0][..2], &[M * a_g[0], M * (a_g[1] + G)], TOL, "hinge force (ground on bar)");
}

/// The slider's X on the branch `sign` (+1 drawn: the slider right of the crank) at crank
/// angle phi.
fn slider_x(phi: f64, sign: f64) -> f64 {
    let (r, l, e) = (0.1, 0.35, 0.02);
    r * phi.cos() + sign * (l * l - (r * phi.sin() - e).powi(2)).sqrt()
}

#[test]
fn the_slider_crank_assembles_on_the_branch_of_its_start() {
    let mech = yaml(SLIDER_CRANK);
    let phi = 1.1;
    // Bodies crank, rod, slider: the slider's X is x[6].
    let drawn = query::assemble(&mech, &[phi], None).unwrap();
    assert!((drawn[6] - slider_x(phi, 1.0)).abs() < X_TOL, "drawn branch: {}", drawn[6]);
    // A start on the other branch, written from the closed form at phi0 = 30 degrees: the
    // crank as drawn, the slider at B' left of the crank, the rod from A to B' turned from
    // its drawn direction A -> B.
    let phi0 = std::f64::consts::FRAC_PI_6;
    let a = [0.1 * phi0.cos(), 0.1 * phi0.sin()];
    let b = [slider_x(phi0, -1.0), 0.02];
    let drawn_rod = (0.02 - a[1]).atan2(slider_x(phi0, 1.0) - a[0]);
    let rod = (b[1] - a[1]).atan2(b[0] - a[0]) - drawn_rod;
    let start = [a[0] / 2.0, a[1] / 2.0, 0.0, (a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, rod, b[0], b[1], 0.0];
    let other = query::assemble(&mech, &[phi], Some(&start)).unwrap();
    assert!((other[6] - slider_x(phi, -1.0)).abs() < X_TOL, "other branch: {}", other[6]);
    // The report follows the same branch; the slider's analogue is dB_x/dphi there.
    let k = query::kinematics(&mech, &[phi], None, Some(&start)).unwrap();
    let root = (0.35f64.powi(2) - (0.1 * phi.sin() - 0.02).powi(2)).sqrt();
    let dbx = -0.1 * phi.sin() + (0.1 * phi.sin() - 0.02) * 0.1 * phi.cos() / root;
    assert!((k.x[6] - other[6]).abs() < X_TOL && (k.u[6] - dbx).abs() < X_TOL, "u {} vs {dbx}", k.u[6]);
}

#[test]
fn a_start_of_the_wrong_size_is_named() {
    let mech = yaml(SLIDER_CRANK);
    match query::assemble(&mech, &[0.5], Some(&[0.0; 2])) {
        Err(KinematicsError::BadArgument { name, .. }) => assert_eq!(name, "x_start"),
        other => panic!("expected a bad x_start, got {other:?}"),
    }
}
