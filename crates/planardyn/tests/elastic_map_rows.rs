//! `elastic::map_rows`, the design view's maps of the first natural frequency and of a point's
//! weakest stiffness: each cell is the per-pose analysis (`elastic::modes`,
//! `elastic::stiffness`) at that cell's configuration, on the singularity map's grid and
//! branch.

mod common;
use common::*;
use planardyn::dynamics::{sigma_rows, MapGrid};
use planardyn::elastic::{self, Load, MapValue, Output};
use planardyn::model::BodyId;
use planardyn::{Mechanism, Workspace};
use std::f64::consts::TAU;

/// The shipped five-bar with elastic motors and an elastic end-effector pin (the browser
/// test's and tests/test_stiffness.py's model).
fn compliant_five_bar() -> Mechanism {
    with_compliance(
        "  drives:\n    - {actuator: theta1, stiffness: 2.0e3}\n    - {actuator: theta2, stiffness: 3.0e3}\n  \
         pairs:\n    - {pair: effector, stiffness: 5.0e5}\n",
    )
}

/// The shipped five-bar without its drives, with the `compliance:` section's body `section`.
fn with_compliance(section: &str) -> Mechanism {
    let path = format!("{}/../../examples/models/five-bar.yaml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    let rigid = text.split("\ndrives:").next().unwrap();
    yaml(&format!("{rigid}\ncompliance:\n{section}"))
}

/// The same configuration reached two ways (the closed forms at the cell; Newton from the
/// drawing, to its tolerance) and the same analysis (an SVD null space, a symmetric
/// eigenproblem or a factorisation of a 10-column model): 1e-12 relative.
/// Measured: 4.6e-13 at most where sigma > 0.1.
const RTOL: f64 = 1e-12;
/// Near a type II singularity (sigma below this) J's conditioning amplifies Newton's stopping
/// error in the reference's configuration (~1 / sigma): 1.21e-12 measured at sigma 0.019 (the
/// loaded stiffness at cell (8, 0)), so 1e-11 there.
const NEAR_SINGULAR: f64 = 0.05;
const RTOL_NEAR_SINGULAR: f64 = 1e-11;

#[test]
fn the_elastic_maps_cells_are_the_per_pose_analyses() {
    let mech = compliant_five_bar();
    let q = mech.drawn_q();
    // 9 x 9 cells over q +- 1.2 rad: the drawing's branch, with cells past the workspace's
    // edge (the elbows more than 0.7 m apart) in the corners.
    const N: usize = 9;
    let axis = |k: usize| -> Vec<f64> { (0..N).map(|i| q[k] - 1.2 + 2.4 * (i as f64 + 0.5) / N as f64).collect() };
    let (a0, a1) = (axis(0), axis(1));
    let rows: Vec<usize> = (0..N).collect();
    let grid = MapGrid::new(&mech, [0, 1], [&a0, &a1], N / 2, &rows, &mech.x0).unwrap();
    let p = mech.point_id("P").unwrap();
    let out = Output { body: BodyId(2), point: Some(p) }; // distal_left, the first body carrying P
    let loaded = Load { wrench: [3.0, -20.0, 0.5], preload: vec![(0, 1.5)], gravity: true };
    let values = [
        MapValue::FirstFrequency { free_rotors: false },
        MapValue::Weakest { out, load: Load::default() },
        MapValue::Weakest { out, load: loaded.clone() },
    ];
    let maps: Vec<_> = values.iter().map(|v| elastic::map_rows(&mech, &q, &grid, v).unwrap().values).collect();
    let sigma = sigma_rows(&mech, &q, [0, 1], [&a0, &a1], N / 2, &rows, &mech.x0).unwrap().values;
    let mut compared = 0;
    for (j, &q1) in a1.iter().enumerate() {
        for (i, &q0) in a0.iter().enumerate() {
            let c = j * N + i;
            let qc = [q0, q1];
            // The same cells as the singularity map's (the same placement).
            assert!(maps.iter().all(|m| m[c].is_finite() == sigma[c].is_finite()), "cell ({j}, {i})");
            if sigma[c].is_nan() {
                continue;
            }
            let mut ws = Workspace::new(&mech);
            let modes = elastic::modes(&mech, &qc, false, false, &mut ws).unwrap();
            let want = [
                modes.omega()[0] / TAU,
                elastic::weakest_direction(
                    &elastic::stiffness(&mech, &qc, out, &Load::default(), &mut ws).unwrap(),
                    None,
                )
                .stiffness,
                elastic::weakest_direction(&elastic::stiffness(&mech, &qc, out, &loaded, &mut ws).unwrap(), None)
                    .stiffness,
            ];
            let rtol = if sigma[c] > NEAR_SINGULAR { RTOL } else { RTOL_NEAR_SINGULAR };
            for (m, w) in maps.iter().zip(want) {
                assert!((m[c] - w).abs() <= rtol * w, "cell ({j}, {i}): {} vs {w}", m[c]);
            }
            compared += 1;
        }
    }
    // Most cells close; the load changes the stiffness (its geometric term and the preload).
    assert!(compared > N * N / 2 && compared < N * N, "{compared} cells compared");
    let c = (N / 2) * N + N / 2;
    assert!((maps[1][c] - maps[2][c]).abs() > 1e-6 * maps[1][c], "{} vs {}", maps[1][c], maps[2][c]);
}

#[test]
fn a_rigid_model_or_a_preload_without_a_spring_is_refused_before_any_cell() {
    let rigid = shipped("five-bar.yaml");
    let axis = [0.0, 0.5];
    let grid = MapGrid::new(&rigid, [0, 1], [&axis, &axis], 0, &[0], &rigid.x0).unwrap();
    let err = elastic::map_rows(&rigid, &rigid.drawn_q(), &grid, &MapValue::FirstFrequency { free_rotors: false });
    assert!(err.unwrap_err().to_string().contains("compliance:"));
    // theta2's motor has no transmission spring here: a preload on it is refused.
    let one = with_compliance("  drives:\n    - {actuator: theta1, stiffness: 2.0e3}\n");
    let out = Output { body: BodyId(2), point: one.point_id("P") };
    let value = MapValue::Weakest { out, load: Load { preload: vec![(1, 1.0)], ..Load::default() } };
    let err = elastic::map_rows(&one, &one.drawn_q(), &grid, &value).unwrap_err().to_string();
    assert!(err.contains("preload on actuator 1"), "{err}");
}
