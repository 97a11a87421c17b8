//! The output columns' table (`planardyn::simulate::columns::COLUMNS`): every column has a row
//! of its width per output, holds the trajectory's own values, and its heading pattern names the
//! entries of its rows. (That the Python package knows each column: tests/test_results_io.py.)

mod common;

use common::{yaml, PENDULUM};
use planardyn::dynamics::ModelDrives;
use planardyn::simulate::columns::{Shape, Values, COLUMNS};
use planardyn::simulate::{grid, simulate, Settings};

/// The energy balance T + V of the passive swing holds to the run's tolerance: the model's
/// rtol 1e-9 (`MODEL_RTOL`) of energies of a few J, with margin.
const ENERGY_TOL: f64 = 1e-8;

#[test]
fn every_column_has_a_row_per_output_and_its_own_values() {
    // The pendulum of tests/common (a 0.8 m, 2 kg uniform bar) released horizontal at rest.
    let mech = yaml(PENDULUM);
    let mut settings = Settings::for_model(&mech).unwrap();
    settings.t_end = 0.2;
    settings.t_eval = Some(grid(0.0, 0.2, 0.05));
    let traj = simulate(&mech, &settings, &mut ModelDrives(&mech), None).unwrap();
    assert!(traj.success() && traj.len() == 5, "{:?}: {} rows", traj.status, traj.len());
    let (m, nx) = (1, 3);
    for c in COLUMNS {
        let len = match (c.values)(&traj) {
            Values::Numbers(v) => v.len(),
            Values::Flags(v) => v.len(),
        };
        assert_eq!(len, traj.len() * c.shape.width(m, nx), "column {}", c.name);
    }
    let numbers = |name: &str| match COLUMNS.iter().find(|c| c.name == name).map(|c| (c.values)(&traj)) {
        Some(Values::Numbers(v)) => v.to_vec(),
        other => panic!("{name}: {other:?}"),
    };
    // At release the bar lies along x: its centre of mass at (0.4, 0), phi = 0, at rest.
    assert_eq!(numbers("x")[..3], [0.4, 0.0, 0.0]);
    assert_eq!(numbers("kinetic")[0], 0.0);
    assert_eq!(numbers("t"), grid(0.0, 0.2, 0.05));
    // Passive: T + V constant, V = m g Y falling by T. After 0.2 s the bar has turned by about
    // (3 g / 2 L) t^2 / 2 = 0.37 rad: T ~ 2.7 J.
    let (kin, pot) = (numbers("kinetic"), numbers("potential"));
    assert!((kin[4] + pot[4] - pot[0]).abs() < ENERGY_TOL, "{} {} {}", kin[4], pot[4], pot[0]);
    assert!(kin[4] > 2.0 && kin[4] < 3.0, "T(0.2 s) = {} J", kin[4]);
}

#[test]
fn names_are_unique_and_headings_name_their_row_entries() {
    for (k, c) in COLUMNS.iter().enumerate() {
        assert!(COLUMNS[..k].iter().all(|d| d.name != c.name), "column {} twice", c.name);
        let named = match c.shape {
            Shape::Scalar | Shape::Flag => c.heading == c.name,
            Shape::Coordinates => c.heading.contains("{coordinate}"),
            Shape::BodyPoses => c.heading.contains("{axis}") && c.heading.contains("{body}"),
        };
        assert!(named, "column {}: heading {:?} for shape {:?}", c.name, c.heading, c.shape);
    }
}
