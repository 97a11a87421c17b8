//! Batch runs: a parallel batch equals a serial loop bit for bit, in input order; a failing
//! variant reports its own error and leaves the others untouched; specs are built per task.

mod common;
use common::*;
use planardyn::batch::{simulate_many, Model, Overrides, Variant};
use planardyn::dynamics::ModelDrives;
use planardyn::simulate::{simulate, Trajectory};
use planardyn::{Error, KinematicsError};
use std::sync::Arc;

fn same(a: &Trajectory, b: &Trajectory) {
    assert_eq!(a.t, b.t);
    assert_eq!(a.q, b.q);
    assert_eq!(a.qd, b.qd);
    assert_eq!(a.tau, b.tau);
    assert_eq!(a.status, b.status);
}

/// Four-bar variants: start angles around the drawing, over 0.3 s.
fn variants(mech: &Arc<planardyn::Mechanism>, n: usize) -> Vec<Variant> {
    let q0 = mech.initial_state().0[0];
    (0..n)
        .map(|k| Variant {
            model: Model::Built(mech.clone()),
            overrides: Overrides { t_end: Some(0.3), q0: Some(vec![q0 + 0.02 * k as f64]), ..Overrides::default() },
        })
        .collect()
}

#[test]
fn parallel_batch_equals_serial_loop_in_order() {
    let mech = Arc::new(yaml(FOUR_BAR));
    let vs = variants(&mech, 12);
    let batch = simulate_many(&vs, Some(2)).unwrap();
    let serial = simulate_many(&vs, Some(1)).unwrap();
    for (k, (b, s)) in batch.iter().zip(&serial).enumerate() {
        let (b, s) = (b.as_ref().unwrap(), s.as_ref().unwrap());
        assert!(b.success(), "variant {k}: {}", b.message);
        same(b, s);
        // And the plain entry point, with the settings made by hand.
        let settings = vs[k].overrides.settings(&mech).unwrap();
        same(b, &simulate(&mech, &settings, &mut ModelDrives(&mech), None).unwrap());
    }
}

#[test]
fn a_failing_variant_does_not_stop_the_others() {
    let mech = Arc::new(shipped("five-bar.yaml"));
    let over = Overrides { t_end: Some(0.1), ..Overrides::default() };
    let mut vs = vec![Variant { model: Model::Built(mech.clone()), overrides: over }; 5];
    // Proximal links straight out (C1 C2 = 0.8 m > 2 x 0.35 m: the distal links cannot
    // meet), and a method that does not exist.
    vs[2].overrides.q0 = Some(vec![std::f64::consts::PI, 0.0]);
    vs[3].overrides.method = Some("euler".into());
    let out = simulate_many(&vs, None).unwrap();
    assert!(matches!(out[2], Err(Error::Kinematics(KinematicsError::AssemblyFailed { .. }))), "{:?}", out[2].as_ref().err());
    assert!(matches!(out[3], Err(Error::Options(_))));
    for k in [0, 1, 4] {
        assert!(out[k].as_ref().unwrap().success());
    }
}

#[test]
fn spec_variants_are_built_in_the_task() {
    let base = yaml(FOUR_BAR);
    let mut heavy = base.spec.clone();
    heavy.bodies.0.get_mut("coupler").unwrap().mass = Some(2.4);
    let mut broken = base.spec.clone();
    broken.bodies.0.get_mut("coupler").unwrap().mass = Some(-1.0);
    let over = Overrides { t_end: Some(0.2), ..Overrides::default() };
    let vs: Vec<Variant> = [base.spec.clone(), heavy.clone(), broken]
        .into_iter()
        .map(|spec| Variant { model: Model::Spec(spec), overrides: over.clone() })
        .collect();
    let out = simulate_many(&vs, Some(2)).unwrap();
    same(out[0].as_ref().unwrap(), &Variant { model: Model::Built(Arc::new(base)), overrides: over.clone() }.simulate().unwrap());
    assert!(matches!(out[2], Err(Error::Model(_))));
    // The heavier coupler changes the motion.
    assert_ne!(out[0].as_ref().unwrap().q.last(), out[1].as_ref().unwrap().q.last());
}
