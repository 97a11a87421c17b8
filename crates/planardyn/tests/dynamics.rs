//! Dynamics against closed forms and consistency: pendulum A and b, A symmetric positive
//! definite, forward then inverse dynamics, reactions of a released pendulum.

mod common;
use common::*;
use planardyn::dynamics::{forward, inverse, mass_matrix, reactions, ModelDrives};
use planardyn::kinematics::{assemble_into, velocity_analogues};
use planardyn::Workspace;

const G: f64 = 9.81;

#[test]
fn pendulum_mass_matrix_and_bias_are_the_closed_form() {
    // Uniform bar L = 0.8 m, m = 2 kg hinged at one end: I_O = m L^2 / 3; with q the angle
    // from the x axis and gravity along -y, the generalized force is -m g (L/2) cos q.
    let mech = yaml(PENDULUM);
    let (m, l) = (2.0, 0.8);
    let i_o = m * l * l / 3.0;
    let mut ws = Workspace::new(&mech);
    for q in [-2.0, -0.3, 0.0, 0.9, 4.0] {
        assemble_into(&mech, &[q], &mut ws).unwrap();
        forward(&mech, 0.0, &[q], &[0.0], &mut ModelDrives(&mech), &mut ws).unwrap();
        mass_matrix(&mech, &mut ws);
        assert!((ws.a[0] - i_o).abs() < 1e-14, "A = {} vs I_O = {i_o}", ws.a[0]);
        let expected_qdd = -m * G * (l / 2.0) * q.cos() / i_o;
        assert!((ws.qdd[0] - expected_qdd).abs() < 1e-12, "qdd = {} vs {expected_qdd}", ws.qdd[0]);
    }
}

#[test]
fn mass_matrix_is_symmetric_positive_definite() {
    for mech in all_models() {
        let (q, _) = test_state(&mech);
        let mut ws = Workspace::new(&mech);
        assemble_into(&mech, &q, &mut ws).unwrap();
        velocity_analogues(&mut ws).unwrap();
        mass_matrix(&mech, &mut ws);
        let m = mech.dof();
        let a = nalgebra::DMatrix::from_row_slice(m, m, &ws.a);
        assert_eq!(a, a.transpose(), "{}: A symmetric", mech.name);
        let eig = a.symmetric_eigenvalues();
        assert!(eig.iter().all(|&e| e > 0.0), "{}: eigenvalues {eig}", mech.name);
    }
}

#[test]
fn forward_then_inverse_dynamics_returns_the_applied_efforts() {
    for mech in all_models() {
        let (q, qd) = test_state(&mech);
        let m = mech.dof();
        let tau: Vec<f64> = (0..m).map(|k| 0.3 - 0.25 * k as f64).collect();
        struct Given(Vec<f64>);
        impl planardyn::dynamics::Drives for Given {
            fn efforts(&mut self, _: f64, _: &[f64], _: &[f64], tau: &mut [f64]) -> Result<(), String> {
                tau.copy_from_slice(&self.0);
                Ok(())
            }
        }
        let mut ws = Workspace::new(&mech);
        assemble_into(&mech, &q, &mut ws).unwrap();
        forward(&mech, 0.0, &q, &qd, &mut Given(tau.clone()), &mut ws).unwrap();
        let qdd = ws.qdd.clone();
        inverse(&mech, &q, &qd, &qdd, &mut ws).unwrap();
        for k in 0..m {
            // 1e-9 relative: the required accuracy; both sides are exact to round-off.
            assert!(
                (ws.tau[k] - tau[k]).abs() < 1e-9 * (1.0 + tau[k].abs()),
                "{}: tau {:?} vs {tau:?}",
                mech.name,
                ws.tau
            );
        }
    }
}

#[test]
fn released_horizontal_pendulum_pin_carries_a_quarter_of_its_weight() {
    // Classic result: a uniform bar released from rest horizontally, hinged at one end,
    // has alpha = 3 g / (2 L) and a pin reaction of m g / 4 upwards.
    let mech = yaml(PENDULUM);
    let mut ws = Workspace::new(&mech);
    assemble_into(&mech, &[0.0], &mut ws).unwrap();
    forward(&mech, 0.0, &[0.0], &[0.0], &mut ModelDrives(&mech), &mut ws).unwrap();
    assert!((ws.qdd[0] + 3.0 * G / (2.0 * 0.8)).abs() < 1e-12);
    let r = reactions(&mech, &mut ws);
    let expected = [0.0, 2.0 * G / 4.0, 0.0];
    for k in 0..3 {
        assert!((r[0][k] - expected[k]).abs() < 1e-12, "reaction {:?} vs {expected:?}", r[0]);
    }
}

#[test]
fn reactions_balance_every_body() {
    // Newton's law per body: m a = applied forces + the reactions of its pairs (each acting
    // at the current position of the second body's copy of the pair point).
    for mech in all_models() {
        let (q, qd) = test_state(&mech);
        let mut ws = Workspace::new(&mech);
        assemble_into(&mech, &q, &mut ws).unwrap();
        forward(&mech, 0.1, &q, &qd, &mut ModelDrives(&mech), &mut ws).unwrap();
        let r = reactions(&mech, &mut ws);
        let mut net = ws.f.clone();
        for (pair, rk) in mech.pairs.iter().zip(&r) {
            for (link, sign) in [(pair.b, 1.0), (pair.a, -1.0)] {
                if let planardyn::model::Link::Body(b) = link {
                    let c = 3 * b.0;
                    // The force acts at b's copy of the pair point (on a slider's guide too).
                    let p = planardyn::kinematics::constraints::world_point(pair.b, pair.sb, &ws.x);
                    let arm = [p[0] - ws.x[c], p[1] - ws.x[c + 1]];
                    net[c] += sign * rk[0];
                    net[c + 1] += sign * rk[1];
                    net[c + 2] += sign * (rk[2] + arm[0] * rk[1] - arm[1] * rk[0]);
                }
            }
        }
        for (i, body) in mech.bodies.iter().enumerate() {
            let mass = [body.mass, body.mass, body.inertia];
            for k in 0..3 {
                let inertial = mass[k] * ws.xdd[3 * i + k];
                let scale = 1.0 + inertial.abs() + ws.f[3 * i + k].abs();
                assert!(
                    (net[3 * i + k] - inertial).abs() < 1e-9 * scale,
                    "{} body {}: {k}: {} vs {inertial}",
                    mech.name,
                    body.name,
                    net[3 * i + k]
                );
            }
        }
    }
}

#[test]
fn slider_crank_positions_and_mass_matrix_are_the_closed_form() {
    // Offset slider-crank (r = 0.1, l = 0.35, offset e = 0.02 m): slider at
    // x_B = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2), rod angle rate
    // beta' = -r cos(phi) / (l cos(beta)); with uniform bars of 0.3 and 0.6 kg and a 0.5 kg
    // slider, A = m_c r^2/3 + m_r |v_G/phi'|^2 + (m_r l^2/12) beta'^2 + m_s x_B'^2.
    let mech = yaml(SLIDER_CRANK);
    let (r, l, e) = (0.1_f64, 0.35_f64, 0.02_f64);
    let (mc, mr, ms) = (0.3, 0.6, 0.5);
    let slider = 3 * mech.body_id("slider").unwrap().0;
    let mut ws = Workspace::new(&mech);
    for phi in [0.3, 1.5, 2.8, 4.0, 5.9] {
        assemble_into(&mech, &[phi], &mut ws).unwrap();
        let root = (l * l - (r * phi.sin() - e).powi(2)).sqrt();
        let xb = r * phi.cos() + root;
        // Newton stops at a scaled residual of POSITION_TOL = 1e-12 (times L = 0.44 m and the
        // conditioning of J): 1e-11 m.
        assert!((ws.x[slider] - xb).abs() < 1e-11, "x_B({phi}) = {} vs {xb}", ws.x[slider]);
        velocity_analogues(&mut ws).unwrap();
        mass_matrix(&mech, &mut ws);
        let dxb = -r * phi.sin() - (r * phi.sin() - e) * r * phi.cos() / root;
        let cos_beta = root / l;
        let dbeta = -r * phi.cos() / (l * cos_beta);
        let vg = [(-r * phi.sin() + dxb) / 2.0, r * phi.cos() / 2.0];
        let a = mc * r * r / 3.0
            + mr * (vg[0].powi(2) + vg[1].powi(2))
            + mr * l * l / 12.0 * dbeta.powi(2)
            + ms * dxb.powi(2);
        assert!((ws.a[0] - a).abs() < 1e-11, "A({phi}) = {} vs {a}", ws.a[0]);
    }
}
