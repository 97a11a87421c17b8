//! Model files written by their dimensions: quantities with units, points by construction,
//! coordinate values as measures of the drawing; and the errors, located and with their fix.

mod common;
use common::*;
use planardyn::units::{read, Position, Quantity, ANGLE, LENGTH};
use planardyn::{loads, Format, Mechanism};
use std::f64::consts::PI;

/// Round-off of a few products and square roots of numbers near 1 (m, rad): a drawing
/// constructed from its dimensions agrees with one computed by hand to a few ulps.
const CONSTRUCTED_TOL: f64 = 1e-12;

fn load(text: &str) -> Mechanism {
    loads(text, Format::Yaml, "m.yaml").unwrap_or_else(|e| panic!("{e}"))
}

fn refused(text: &str, format: Format) -> String {
    match loads(text, format, "m.yaml") {
        Err(e) => e.to_string(),
        Ok(_) => panic!("accepted:\n{text}"),
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn units_convert_to_si_by_their_definitions() {
    // The inch is 25.4 mm and the degree pi/180 rad by definition (table.rs).
    let cases: [(&str, f64); 7] = [
        ("120 mm", 0.12),
        ("0.5 m", 0.5),
        ("3 in", 3.0 * 0.0254),
        ("2.5cm", 0.025),
        (" -1.5e-3 m ", -1.5e-3),
        ("250", 250.0),
        ("1 ft", 0.3048),
    ];
    for (text, si) in cases {
        let r = read(text, &[&LENGTH]).unwrap();
        assert!((r.si - si).abs() <= f64::EPSILON * si.abs(), "{text}: {} vs {si}", r.si);
    }
    for (text, si) in [("30 deg", PI / 6.0), ("1.2 rad", 1.2), ("90°", PI / 2.0), ("0.25 rev", PI / 2.0)] {
        let r = read(text, &[&ANGLE]).unwrap();
        assert!((r.si - si).abs() <= f64::EPSILON * si.abs(), "{text}: {} vs {si}", r.si);
    }
    // A pair's position is an angle or a length; the kind read tells which.
    assert_eq!(read("30 deg", Position::KINDS).unwrap().kind, Some(0));
    assert_eq!(read("30 mm", Position::KINDS).unwrap().kind, Some(1));
    assert_eq!(read("30", Position::KINDS).unwrap().kind, None);
}

/// The four-bar of `common::FOUR_BAR` by its dimensions: crank 0.5 m at 60 deg, coupler
/// 1.2 m, rocker 1.0 m, B above the line A -> D; gravity and the crank's mass with units.
fn four_bar_by_dimensions() -> String {
    let drawn = "  D: [1.0, 0.0]\n  A: [0.25, 0.4330127018922193]\n  B: [1.336926485022576, 0.9415309573722639]";
    let by_dimensions = "  D: [\"1000 mm\", 0]\n  A: {from: O, length: \"500 mm\", angle: \"60 deg\"}\n  \
                         B: {circles: [[A, \"1.2 m\"], [D, \"1 m\"]], side: left}";
    assert!(FOUR_BAR.contains(drawn));
    FOUR_BAR
        .replace(drawn, by_dimensions)
        .replace("gravity: [0.0, -9.81]", "gravity: [0.0, \"-9810 mm/s^2\"]")
        .replace("mass: 0.5,", "mass: \"500 g\",")
        .replace("value: 1.0471975511965976}", "value: {angle: [O, A]}}")
}

#[test]
fn a_four_bar_by_its_dimensions_is_the_four_bar_by_coordinates() {
    let (by_dims, by_coords) = (load(&four_bar_by_dimensions()), load(FOUR_BAR));
    let d = max_diff(&by_dims.x0, &by_coords.x0);
    assert!(d < CONSTRUCTED_TOL, "x0 differs by {d:e}");
    assert!((by_dims.spec.coordinates[0].value - PI / 3.0).abs() < CONSTRUCTED_TOL);
    assert_eq!(by_dims.spec.gravity, [0.0, -9.81]);
    assert!((by_dims.spec.bodies.0["crank"].mass.unwrap() - 0.5).abs() < CONSTRUCTED_TOL);
    // The other assembly: B mirrored in the line A -> D.
    let right = load(&four_bar_by_dimensions().replace("side: left", "side: right"));
    let p = |m: &Mechanism, n: &str| m.spec.points.0[n];
    let (a, dd, bl, br) = (p(&right, "A"), p(&right, "D"), p(&by_dims, "B"), p(&right, "B"));
    let cross = |q: [f64; 2]| (dd[0] - a[0]) * (q[1] - a[1]) - (dd[1] - a[1]) * (q[0] - a[0]);
    assert!(cross(bl) > 0.0 && cross(br) < 0.0, "left is the counter-clockwise side of A -> D");
}

#[test]
fn points_along_a_line_and_where_a_line_meets_a_circle() {
    let text = four_bar_by_dimensions().replace(
        "ground: [O, D]",
        "  M: {along: [O, D], fraction: 0.5}\n  E: {along: [O, A], distance: \"250 mm\"}\n  \
         F: {line: [O, D], circle: [A, 0.5], crossing: second}\n  \
         G: {from: A, length: 0.1, angle: \"90 deg\", relative_to: [O, A]}\nground: [O, D]",
    );
    let m = load(&text);
    let p = |n: &str| m.spec.points.0[n];
    let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < CONSTRUCTED_TOL;
    assert!(close(p("M"), [0.5, 0.0]));
    // Half way along the crank O -> A (0.5 m at 60 deg).
    assert!(close(p("E"), [0.125, 0.25 * (PI / 3.0).sin()]));
    // The circle of 0.5 m about A = (0.25, 0.433) meets y = 0 at x = 0.25 +- 0.25: the second is x = 0.5.
    assert!(close(p("F"), [0.5, 0.0]), "{:?}", p("F"));
    // 0.1 m from A at 60 + 90 deg.
    let a = p("A");
    assert!(close(p("G"), [a[0] + 0.1 * (150f64.to_radians()).cos(), a[1] + 0.1 * (150f64.to_radians()).sin()]));
}

#[test]
fn an_unknown_unit_names_the_field_the_line_and_the_units() {
    let msg = refused(&four_bar_by_dimensions().replace("\"60 deg\"", "\"60 degs\""), Format::Yaml);
    assert_eq!(
        msg,
        "m.yaml: points.A.angle: \"60 degs\": 'degs' is not a unit of an angle (rad, deg, rev, or a number alone \
         in rad) (line 7 column 41); write e.g. \"30 deg\""
    );
    // A unit of another kind says which kind it is.
    let msg = refused(&four_bar_by_dimensions().replace("\"500 mm\"", "\"500 kg\""), Format::Yaml);
    assert!(msg.contains("points.A.length: \"500 kg\": 'kg' is not a unit of a length (m, mm, cm, um, in, ft, or a number alone in m) ('kg' is a unit of a mass)"), "{msg}");
    // JSON too.
    let json = r#"{"name": "x", "points": {"O": ["1 mx", 0]}, "bodies": {}, "pairs": [], "coordinates": []}"#;
    let msg = refused(json, Format::Json);
    assert!(msg.starts_with("m.yaml: points.O[0]: \"1 mx\": 'mx' is not a unit of a length"), "{msg}");
}

#[test]
fn circles_that_do_not_meet_name_the_point_and_the_gap() {
    // |AD| = 0.9539 m at the drawing; radii 0.5 + 0.3 = 0.8 m: 0.1539 m short.
    let msg = refused(
        &four_bar_by_dimensions().replace("[[A, \"1.2 m\"], [D, \"1 m\"]]", "[[A, 0.5], [D, 0.3]]"),
        Format::Yaml,
    );
    let d = (1.0f64 - 0.25).hypot(0.5 * (PI / 3.0).sin());
    assert_eq!(
        msg,
        format!(
            "m.yaml: points.B: the circles of radius 0.5 m about A and 0.3 m about D do not meet: their centres are \
             0.866025403784 m apart, more than the sum of the radii 0.8 by {:.6e} m (line 8 column 6); change a radius by at least that, \
             or move a centre",
            d - 0.8
        )
    );
    let msg = refused(
        &four_bar_by_dimensions().replace("[[A, \"1.2 m\"], [D, \"1 m\"]]", "[[A, 3], [D, 0.3]]"),
        Format::Yaml,
    );
    assert!(msg.contains("one lies inside the other"), "{msg}");
    // In JSON too, the line of the point's key and the column of its value.
    let json = "{\n  \"name\": \"x\",\n  \"points\": {\n    \"A\": [0, 0],\n    \"D\": [1, 0],\n    \
                \"B\": {\"circles\": [[\"A\", 0.2], [\"D\", 0.3]], \"side\": \"left\"}\n  },\n  \
                \"bodies\": {}, \"pairs\": [], \"coordinates\": []\n}";
    let msg = refused(json, Format::Json);
    assert!(
        msg.starts_with("m.yaml: points.B: the circles") && msg.contains("by 5.000000e-1 m (line 6 column 10); "),
        "{msg}"
    );
}

#[test]
fn constructions_refer_to_points_that_exist_and_do_not_go_round() {
    let msg = refused(&four_bar_by_dimensions().replace("from: O,", "from: Q,"), Format::Yaml);
    assert!(msg.starts_with("m.yaml: points.A: unknown point 'Q' (line 7 column 6); points are: O, D, A, B"), "{msg}");
    let msg = refused(&four_bar_by_dimensions().replace("from: O,", "from: B,"), Format::Yaml);
    assert!(msg.contains("points.A: 'A' is constructed from B, which cannot be placed before it"), "{msg}");
    // A construction missing its side says so.
    let msg = refused(&four_bar_by_dimensions().replace(", side: left", ""), Format::Yaml);
    assert!(
        msg.contains("points.B: a point where two circles meet needs the side it lies on, side: left or right"),
        "{msg}"
    );
}

#[test]
fn a_value_in_a_unit_of_the_wrong_motion_is_refused() {
    let msg = refused(&four_bar_by_dimensions().replace("{angle: [O, A]}", "\"60 mm\""), Format::Yaml);
    assert_eq!(
        msg,
        "m.yaml: coordinates[0].value: the pair 'O' turns, so its value is an angle (line 20 column 36); give it in rad or deg"
    );
    let m = load(&four_bar_by_dimensions().replace("{angle: [O, A]}", "\"60 deg\""));
    assert!((m.spec.coordinates[0].value - PI / 3.0).abs() < CONSTRUCTED_TOL);
    // The start q0 too.
    let msg =
        refused(&four_bar_by_dimensions().replace("{angle: [O, A]}}", "{angle: [O, A]}, q0: \"1 in\"}"), Format::Yaml);
    assert!(msg.starts_with("m.yaml: coordinates[0].q0: the pair 'O' turns, so its value is an angle"), "{msg}");
    let m = load(&four_bar_by_dimensions().replace("{angle: [O, A]}}", "{angle: [O, A]}, q0: \"90 deg\"}"));
    assert!((m.spec.coordinates[0].q0.unwrap() - PI / 2.0).abs() < CONSTRUCTED_TOL);
}

#[test]
fn units_inside_pairs_and_loads_are_read_in_yaml_and_json() {
    use planardyn::loader::parse_spec;
    use planardyn::model::spec::LoadSpec;
    // serde buffers these entries to read their `type` first (`units::tagged`).
    let yaml = four_bar_by_dimensions()
        .replace("coordinates:", "loads:\n  - {type: torque, body: crank, value: \"500 N mm\"}\ncoordinates:");
    let spec = parse_spec(&yaml, Format::Yaml, "m.yaml").unwrap();
    let LoadSpec::Torque(t) = &spec.loads[0] else { panic!("{:?}", spec.loads) };
    assert!((t.value - 0.5).abs() < 1e-15);
    let json = r#"{"name": "x", "points": {"O": [0, 0]}, "bodies": {}, "coordinates": [],
        "pairs": [{"type": "gear", "bodies": ["a", "b"], "centers": ["O"], "radii": ["20 mm"], "rack": ["O", "O"]}]}"#;
    let spec = parse_spec(json, Format::Json, "m.json").unwrap();
    let planardyn::model::spec::PairSpec::Gear { radii, .. } = &spec.pairs[0] else { panic!() };
    assert!((radii[0] - 0.02).abs() < 1e-15);
}
