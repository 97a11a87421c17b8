//! The passive measure from the user's chart's analysis kept by the caller
//! (`passive_sigma_min_with`, as a run measures it on its own `inputs_sys`) equals the one from
//! a fresh analysis (`passive_sigma_min`) bit for bit, at every point, whatever was measured on
//! the kept one before: a run's change-point checks are unchanged by keeping it.

mod common;
use common::*;
use planardyn::kinematics::{assemble, passive_sigma_min, passive_sigma_min_with, System};
use planardyn::model::CoordinateKind;

/// Points a model is measured at: its first coordinate turned in steps of this (rad, or m
/// scaled by the model's length) from its start, both ways, while it assembles.
const STEP: f64 = 0.15;
const STEPS: usize = 20;

#[test]
fn a_kept_analysis_gives_the_passive_measure_of_a_fresh_one_bit_for_bit() {
    let mut measured = 0;
    for mech in every_model() {
        let (q0, _) = mech.initial_state();
        // One analysis kept across all the model's points, as a run keeps its inputs_sys.
        let mut kept = System::new(&mech);
        for sign in [1.0, -1.0] {
            for k in 0..STEPS {
                let mut q = q0.clone();
                let unit = if mech.coordinates[0].kind == CoordinateKind::Angle { 1.0 } else { mech.scale };
                q[0] += sign * STEP * k as f64 * unit;
                let Ok(x) = assemble(&mech, &q) else { break };
                let fresh = passive_sigma_min(&mech, &x);
                let with = passive_sigma_min_with(&mut kept, &mech, &x);
                assert_eq!(with.to_bits(), fresh.to_bits(), "{} at q = {q:?}: {with} vs {fresh}", mech.name);
                measured += 1;
            }
        }
    }
    // Every model assembles at its start; most along a good part of the sweep.
    assert!(measured > 200, "{measured} points");
}
