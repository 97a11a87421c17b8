//! The motor torques of a motion's rows keep each row's outcome: a row whose friction efforts
//! do not settle has none (NaN), named with why, and every other row's are its own call's.

mod common;

use planardyn::batch::{motor_torque_rows, Branch, UnsolvedRows};
use planardyn::kinematics::assemble;
use planardyn::model::loads::friction::FrictionSpec;
use planardyn::model::spec::LoadSpec;
use planardyn::{Error, KinematicsError, Mechanism};

/// The slider-crank with Coulomb friction mu = 100 on its crank pin (r = 8 mm): at crank
/// angle 1 rad its inverse dynamics settles at qd <= 1e-3 rad/s and self-locks at 0.1 rad/s
/// (measured with `inverse_dynamics`; `actuators.rs` has the pin's self-lock for mu >= 1e2).
fn locking_slider_crank() -> Mechanism {
    let mut spec = common::shipped("slider-crank.yaml").spec.clone();
    spec.loads.push(LoadSpec::Friction(FrictionSpec {
        pair: "crank_pin".into(),
        viscous: None,
        mu: Some(100.0),
        mu_static: None,
        pin_radius: Some(0.008),
        length: None,
        stiction_speed: None,
        stribeck_speed: None,
        pressure_angle: None,
    }));
    planardyn::build(spec, "slider-crank.yaml").unwrap()
}

#[test]
fn rows_that_do_not_settle_have_no_motor_torques_and_the_others_their_own() {
    // On 7e4b0e1 the query failed whole at row 2 (FrictionUnsettled): Python retried it in
    // chunks and row by row to keep a failed run's rows. Rows at rest or creeping settle; the
    // rows at 0.5-3 rad/s lock: spans 2-3, 5 and 8-9.
    let mech = locking_slider_crank();
    let qd = [0.0, 1e-3, 0.5, 0.5, 0.0, 1.0, 1e-4, 0.0, 2.0, 3.0, 0.0, 0.0];
    let q: Vec<f64> = (0..qd.len()).map(|k| 1.0 + 0.05 * k as f64).collect();
    let qdd = vec![0.0; q.len()];
    let x: Vec<f64> = q.iter().flat_map(|&q| assemble(&mech, &[q]).unwrap()).collect();
    let nx = mech.n_x();
    let rows = motor_torque_rows(&mech, Branch::Rows(&x, None), &q, &qd, &qdd, None, false).unwrap();
    let spans: Vec<_> = rows.unsolved.iter().map(|u| u.rows.clone()).collect();
    assert_eq!(spans, [2..4, 5..6, 8..10]);
    for k in 0..q.len() {
        let own = motor_torque_rows(
            &mech,
            Branch::Rows(&x[k * nx..(k + 1) * nx], None),
            &q[k..=k],
            &qd[k..=k],
            &qdd[k..=k],
            None,
            false,
        )
        .unwrap();
        match rows.unsolved.iter().find(|u| u.rows.contains(&k)) {
            // The row's own call fails alike; the span keeps its first row's error.
            Some(span) => {
                assert!(rows.values[k].is_nan(), "row {k}: {}", rows.values[k]);
                assert_eq!(own.unsolved.len(), 1, "row {k}");
                assert_eq!(own.unsolved[0].reason(), span.reason());
                if span.rows.start == k {
                    assert_eq!(own.unsolved[0].error, span.error);
                }
            }
            None => {
                assert!(own.unsolved.is_empty(), "row {k}: {:?}", own.unsolved);
                assert_eq!(rows.values[k].to_bits(), own.values[0].to_bits(), "row {k}");
            }
        }
    }
    for span in &rows.unsolved {
        assert_eq!(span.reason(), "the friction efforts did not settle");
        assert!(matches!(span.error, KinematicsError::FrictionUnsettled { .. }), "{:?}", span.error);
    }
    assert_eq!(rows.unsolved[0].to_string(), "rows 2-3: the friction efforts did not settle");
    assert_eq!(rows.unsolved[1].to_string(), "row 5: the friction efforts did not settle");
    // Every row or the first failure, as the query was before.
    let first: UnsolvedRows = rows.unsolved[0].clone();
    assert_eq!(rows.into_values(), Err(Error::Kinematics(first.error)));
}
