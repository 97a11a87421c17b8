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

/// The compliant five-bar drawn on its other elbow: P reflected across the line C1 C2 (the
/// lower intersection of the distal circles), the same dimensions, masses and springs.
fn other_elbow() -> (Mechanism, [f64; 2]) {
    let path = format!("{}/../../examples/models/five-bar.yaml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    let (c1, c2, p) = (
        [-0.25565456543517484, 0.2265769467591625],
        [0.275, 0.21650635094610965],
        [0.014002680494367873, 0.44970240410926887],
    );
    let (d, w) = ([c2[0] - c1[0], c2[1] - c1[1]], [p[0] - c1[0], p[1] - c1[1]]);
    let s = (w[0] * d[0] + w[1] * d[1]) / (d[0] * d[0] + d[1] * d[1]);
    let foot = [c1[0] + s * d[0], c1[1] + s * d[1]];
    let mirrored = [2.0 * foot[0] - p[0], 2.0 * foot[1] - p[1]];
    let line = text.lines().find(|l| l.trim_start().starts_with("P: [")).unwrap();
    let text = text.replace(line, &format!("  P: [{:?}, {:?}]", mirrored[0], mirrored[1]));
    let rigid = text.split("\ndrives:").next().unwrap();
    let section =
        "  drives:\n    - {actuator: theta1, stiffness: 2.0e3}\n    - {actuator: theta2, stiffness: 3.0e3}\n  \
                   pairs:\n    - {pair: effector, stiffness: 5.0e5}\n";
    (yaml(&format!("{rigid}\ncompliance:\n{section}")), mirrored)
}

#[test]
fn the_per_pose_analyses_about_a_pose_keep_its_branch() {
    // The app's Modes tab and loaded stiffness analyse the pose shown (`modes_about`,
    // `stiffness_about`), which may be on another branch than the drawing's continuation. The
    // same physical mechanism drawn on that branch gives the reference: frequencies and the
    // weakest stiffness are independent of the body frames, so they must agree to round-off
    // through two assemblies and two eigen- or factorisations (RTOL).
    let mech = compliant_five_bar();
    let (drawn_low, p_low) = other_elbow();
    let q = mech.drawn_q();
    assert!(q.iter().zip(drawn_low.drawn_q()).all(|(a, b)| (a - b).abs() < 1e-15), "the same motor angles");
    // A start on the lower elbow: each distal link turned about its elbow so that P goes to P'.
    let p = mech.point_id("P").unwrap();
    let mut start = mech.x0.clone();
    let at = |name: &str| {
        let id = mech.point_id(name).unwrap();
        planardyn::dynamics::query::point_positions(&mech, &mech.x0)[2 * id.0..2 * id.0 + 2].to_vec()
    };
    let (pp, c1, c2) = (at("P"), at("C1"), at("C2"));
    for (body, c) in [(2, &c1), (3, &c2)] {
        let turn = (p_low[1] - c[1]).atan2(p_low[0] - c[0]) - (pp[1] - c[1]).atan2(pp[0] - c[0]);
        let (s, co) = turn.sin_cos();
        let (rx, ry) = (start[3 * body] - c[0], start[3 * body + 1] - c[1]);
        start[3 * body] = c[0] + co * rx - s * ry;
        start[3 * body + 1] = c[1] + s * rx + co * ry;
        start[3 * body + 2] += turn;
    }
    let x_low = planardyn::dynamics::query::assemble(&mech, &q, Some(&start)).unwrap();
    let modes = elastic::modes_about(&mech, &x_low, false, false).unwrap().omega();
    let want = elastic::modes(&drawn_low, &q, false, false, &mut Workspace::new(&drawn_low)).unwrap().omega();
    let upper = elastic::modes(&mech, &q, false, false, &mut Workspace::new(&mech)).unwrap().omega();
    for (g, w) in modes.iter().zip(&want) {
        assert!((g - w).abs() <= RTOL * w, "omega {modes:?} vs {want:?}");
    }
    // The branch matters: the upper elbow's first frequency is another.
    assert!((upper[0] - want[0]).abs() > 1e-3 * want[0], "{upper:?} vs {want:?}");
    let out = Output { body: BodyId(2), point: Some(p) };
    let out_low = Output { body: BodyId(2), point: drawn_low.point_id("P") };
    let weakest = |c| elastic::weakest_direction(&c, None).stiffness;
    let got = weakest(elastic::stiffness_about(&mech, &x_low, out, &Load::default()).unwrap());
    let want = weakest(
        elastic::stiffness(&drawn_low, &q, out_low, &Load::default(), &mut Workspace::new(&drawn_low)).unwrap(),
    );
    let upper = weakest(elastic::stiffness(&mech, &q, out, &Load::default(), &mut Workspace::new(&mech)).unwrap());
    assert!((got - want).abs() <= RTOL * want, "weakest {got} vs {want} N/m");
    assert!((upper - want).abs() > 1e-3 * want, "{upper} vs {want} N/m");
}
