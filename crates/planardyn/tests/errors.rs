//! Bad input gets an error naming the source, the field path and a fix; never a panic.

mod common;
use common::*;
use planardyn::{loads, Format, KinematicsError, ModelError, SingularityKind};

fn model_error(text: &str, format: Format) -> ModelError {
    match loads(text, format, "bad.yaml") {
        Err(e) => e,
        Ok(_) => panic!("accepted:\n{text}"),
    }
}

/// The four-bar with one substitution; the error must name `path` and contain `words`.
fn expect(from: &str, to: &str, path: &str, words: &str) {
    assert!(FOUR_BAR.contains(from), "test typo: {from}");
    let e = model_error(&FOUR_BAR.replacen(from, to, 1), Format::Yaml);
    let text = e.to_string();
    assert!(text.starts_with("bad.yaml: "), "{text}");
    assert_eq!(e.path(), path, "{text}");
    assert!(text.contains(words), "'{words}' not in: {text}");
}

#[test]
fn unknown_names_are_named_with_the_known_ones() {
    expect(
        "bodies: [crank, coupler]",
        "bodies: [crank, couple]",
        "pairs[1].bodies[1]",
        "unknown body 'couple' (line 16 column 45); bodies are: ground, crank, coupler, rocker",
    );
    expect("at: A, bodies", "at: Q, bodies", "pairs[1].at", "unknown point 'Q'");
    expect("pair: O, value", "pair: X, value", "coordinates[0].pair", "unknown pair 'X'");
}

#[test]
fn duplicate_names_are_refused() {
    expect("  D: [1.0, 0.0]\n", "  D: [1.0, 0.0]\n  D: [2.0, 0.0]\n", "points", "duplicate name 'D'");
    expect(
        "{name: theta1, pair: O",
        "{name: theta1, pair: O, value: 1}\n  - {name: theta1, pair: O",
        "coordinates[1].name",
        "used twice",
    );
}

#[test]
fn a_pair_on_a_point_a_body_does_not_carry_says_where_to_add_it() {
    expect("ground: [O, D]", "ground: [O]", "pairs[3].at", "'ground' does not carry point 'D'");
}

#[test]
fn wrong_mobility_explains_the_count() {
    let e = model_error(
        &FOUR_BAR
            .replace("coordinates:\n", "coordinates:\n  - {name: extra, pair: D, value: 0}\n")
            .replace("at: D, bodies", "name: D, at: D, bodies"),
        Format::Yaml,
    );
    assert_eq!(e.path(), "coordinates");
    assert!(e.to_string().contains("mobility 3n - 2p = 3*3 - 2*4 = 1 but 2 coordinate(s)"), "{e}");
}

#[test]
fn non_positive_mass_and_inertia_are_refused() {
    expect("mass: 1.2", "mass: -1.2", "bodies.coupler.mass", "must be > 0");
    expect("inertia: 0.144", "inertia: 0.0", "bodies.coupler.inertia", "must be > 0");
}

#[test]
fn malformed_text_gets_a_parse_error_with_its_location() {
    let e = model_error("name: x\npoints: [1, 2", Format::Yaml);
    assert!(matches!(e, ModelError::Parse { .. }), "{e:?}");
    let e = model_error("{\"name\": \"x\", \"points\": {\"O\": [0, \"a\"]}}", Format::Json);
    assert_eq!(e.path(), "points.O[1]", "{e}");
    let e = model_error(&FOUR_BAR.replace("type: revolute, name: O", "type: hinge, name: O"), Format::Yaml);
    assert_eq!(e.path(), "pairs[0].type", "{e}");
    assert!(e.to_string().contains("unknown variant `hinge`"), "{e}");
    let e = model_error(&FOUR_BAR.replace("mass: 0.5,", "mas: 0.5,"), Format::Yaml);
    assert!(e.to_string().contains("unknown field `mas`"), "{e}");
}

#[test]
fn a_start_that_cannot_be_assembled_is_refused() {
    // With the rocker pair as input, turning the rocker 1.25 rad clockwise from the drawing
    // puts B about 2.0 m from O, beyond the reach of crank + coupler (0.5 + 1.2 m).
    let text = FOUR_BAR
        .replace("{type: revolute, at: D", "{type: revolute, name: D, at: D")
        .replace("pair: O, value: 1.0471975511965976", "pair: D, value: 0.0, q0: -1.25");
    let e = model_error(&text, Format::Yaml);
    assert_eq!(e.path(), "coordinates", "{e}");
    assert!(e.to_string().contains("cannot start at q0"), "{e}");
}

#[test]
fn inverse_dynamics_at_a_type_ii_singularity_says_so() {
    // The five-bar with both distal links collinear is a type II singularity: drawn there,
    // it loads (the passive constraints keep full rank) but inverse dynamics is undefined.
    let text = FIVE_BAR_FALL.replace("P: [0.0, 0.32320508075688775]", "P: [0.0, 0.17320508075688773]");
    let mech = yaml(&text);
    let mut ws = planardyn::Workspace::new(&mech);
    ws.x.copy_from_slice(&mech.x0);
    let q = mech.drawn_q();
    let err = planardyn::dynamics::inverse(&mech, &q, &[0.0, 0.0], &[0.0, 0.0], &mut ws).unwrap_err();
    assert_eq!(err, KinematicsError::Singular { kind: SingularityKind::TypeII, sigma_min: None });
    assert!(err.to_string().contains("type II"), "{err}");
}

#[test]
fn a_bad_argument_names_it_with_what_was_expected_and_what_came() {
    let mech = yaml(FIVE_BAR_FALL);
    let err = planardyn::kinematics::assemble(&mech, &[1.0]).unwrap_err();
    let KinematicsError::BadArgument { name, expected, got } = &err else { panic!("{err:?}") };
    assert_eq!((*name, expected.as_str(), got.as_str()), ("q", "2 finite coordinate values (theta1, theta2)", "[1.0]"));
    assert_eq!(err.to_string(), "q: expected 2 finite coordinate values (theta1, theta2), got [1.0]");
    let mut ws = planardyn::Workspace::new(&mech);
    let x = vec![f64::NAN; mech.n_x()];
    let err = planardyn::kinematics::assemble_from(&mech, &x, &mech.drawn_q(), &mut ws).unwrap_err();
    assert!(
        matches!(&err, KinematicsError::BadArgument { name: "x_start", got, .. } if got == "NaN at index 0 of 12 values")
    );
}

#[test]
fn an_unmeasured_singularity_has_no_sigma_and_says_nothing_of_one() {
    let err = KinematicsError::singular(SingularityKind::TypeII);
    assert_eq!(err, KinematicsError::Singular { kind: SingularityKind::TypeII, sigma_min: None });
    assert!(!err.to_string().contains("singular value"), "{err}");
    let measured = KinematicsError::Singular { kind: SingularityKind::PassiveAtStart, sigma_min: Some(1.5e-9) };
    assert!(measured.to_string().contains("(smallest scaled singular value 1.500e-9)"), "{measured}");
    assert_eq!(SingularityKind::MassMatrix { type_ii: true }.name(), "mass_matrix");
}

#[test]
fn an_angle_beyond_a_full_turn_is_warned_about_as_likely_degrees() {
    // Loaded (angles are unwrapped, so 30 rad is legal) with one warning: 30 deg = pi/6 rad.
    let mech = yaml(&FOUR_BAR.replacen("value: 1.0471975511965976", "value: 30.0", 1));
    assert_eq!(
        mech.warnings,
        ["coordinates[0].value of angle 'theta1' is 30 rad, more than a full turn (2 pi = 6.283 rad): angles are in \
          radians; if 30 is in degrees, write 0.523599"]
    );
    assert!(yaml(FOUR_BAR).warnings.is_empty());
}
