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
    // The core's text, which a run's message carries (Python adds it, s22-mend): a span alone,
    // and the rows' note at their times (k / 3 s, printed to 10 digits as by `%.10g`).
    assert_eq!(rows.unsolved[0].to_string(), "no motor torques at rows 2-3: the friction efforts did not settle");
    assert_eq!(rows.unsolved[1].to_string(), "no motor torques at row 5: the friction efforts did not settle");
    let t: Vec<f64> = (0..q.len()).map(|k| k as f64 / 3.0).collect();
    assert_eq!(
        rows.note(&t).as_deref(),
        Some(
            "no motor torques at rows 2-3 (t = 0.6666666667-1 s), row 5 (t = 1.666666667 s), rows 8-9 \
             (t = 2.666666667-3 s): the friction efforts did not settle"
        )
    );
    // Every row or the first failure, as the query was before.
    let first: UnsolvedRows = rows.unsolved[0].clone();
    assert_eq!(rows.into_values(), Err(Error::Kinematics(first.error)));
}

#[test]
fn a_runs_note_names_eight_spans_of_a_reason_and_counts_the_others() {
    // Ten spans of one row, locking (0.5 rad/s at 1 rad) between rows at rest, then a span of
    // another reason: the first eight of the ten named, and the other reason's note after "; ".
    let mech = locking_slider_crank();
    let qd: Vec<f64> = (0..20).map(|k| if k % 2 == 0 { 0.5 } else { 0.0 }).collect();
    let q = vec![1.0; qd.len()];
    let qdd = vec![0.0; q.len()];
    let x: Vec<f64> = q.iter().flat_map(|&q| assemble(&mech, &[q]).unwrap()).collect();
    let mut rows = motor_torque_rows(&mech, Branch::Rows(&x, None), &q, &qd, &qdd, None, false).unwrap();
    let spans: Vec<_> = rows.unsolved.iter().map(|u| u.rows.clone()).collect();
    assert_eq!(spans, (0..10).map(|j| 2 * j..2 * j + 1).collect::<Vec<_>>());
    let t: Vec<f64> = (0..q.len()).map(|k| 0.5 * k as f64).collect();
    let friction = "no motor torques at row 0 (t = 0 s), row 2 (t = 1 s), row 4 (t = 2 s), row 6 (t = 3 s), \
                    row 8 (t = 4 s), row 10 (t = 5 s), row 12 (t = 6 s), row 14 (t = 7 s) and 2 more spans of \
                    rows: the friction efforts did not settle";
    assert_eq!(rows.note(&t).as_deref(), Some(friction));
    let jammed = KinematicsError::GearsJammed { actuators: "crank".into() };
    rows.unsolved.push(UnsolvedRows { rows: 19..20, error: jammed });
    let both =
        format!("{friction}; no motor torques at row 19 (t = 9.5 s): the gears of crank admit no consistent motion");
    assert_eq!(rows.note(&t), Some(both));
    // Every row solved: no note.
    let solved =
        motor_torque_rows(&mech, Branch::Rows(&x[..mech.n_x()], None), &q[..1], &[0.0], &qdd[..1], None, false);
    assert_eq!(solved.unwrap().note(&t[..1]), None);
}
