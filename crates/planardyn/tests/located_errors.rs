//! Every parse error is located: a field path, or the line and column where the text stops
//! being YAML/JSON (the document's top level has no field to name), and says what to do.
//! The exact messages a user reads, for the cases the parsers alone leave unlocated or in
//! Rust terms.

mod common;
use common::*;
use planardyn::{load, loads, Format, ModelError};

/// The whole message (`<source>: <path>: <message>`) and the path of a refused text.
fn refused(text: &str, format: Format) -> (String, String) {
    match loads(text, format, "m.yaml") {
        Err(e) => (e.to_string(), e.path().to_string()),
        Ok(_) => panic!("accepted:\n{text}"),
    }
}

const MAPPING_FIX: &str =
    "a model file must be a mapping with the keys name, points, ground, bodies, pairs and coordinates: see `planardyn docs model-format`";

#[test]
fn a_document_that_is_not_a_mapping_says_what_a_model_is() {
    let (msg, path) = refused("# a comment\n;\n", Format::Yaml);
    assert_eq!(path, "line 2 column 1");
    assert_eq!(msg, format!("m.yaml: line 2 column 1: the model is string \";\", not a mapping; {MAPPING_FIX}"));
    let (msg, _) = refused("[1, 2]", Format::Yaml);
    assert_eq!(msg, format!("m.yaml: line 1 column 1: the model is sequence, not a mapping; {MAPPING_FIX}"));
    let (msg, _) = refused("3", Format::Json);
    assert_eq!(msg, format!("m.yaml: line 1 column 1: the model is integer `3`, not a mapping; {MAPPING_FIX}"));
}

#[test]
fn a_missing_top_level_field_is_the_path() {
    let (msg, path) = refused(&FOUR_BAR.replace("name: four-bar under gravity\n", ""), Format::Yaml);
    assert_eq!(path, "name");
    assert_eq!(msg, "m.yaml: name: missing field `name` (line 2 column 1); add it (see `planardyn docs model-format`)");
    // Nested: the missing field's own path, not its parent's.
    let (_, path) = refused(&FOUR_BAR.replace(", value: 1.0471975511965976}", "}"), Format::Yaml);
    assert_eq!(path, "coordinates[0].value");
}

#[test]
fn yaml_syntax_errors_give_line_and_column_even_at_the_first_character() {
    // libyaml's mark at line 1 column 1 is printed as nothing: the path still says where.
    let (msg, path) = refused(",./;[]", Format::Yaml);
    assert_eq!(path, "line 1 column 1");
    assert_eq!(
        msg,
        "m.yaml: line 1 column 1: did not find expected node content, while parsing a block node; \
         the text is not valid YAML: check the indentation, brackets, quotes and colons there"
    );
    let (msg, path) = refused("*a", Format::Yaml);
    assert_eq!(path, "line 1 column 1");
    assert!(
        msg.ends_with(
            "unknown anchor; an alias `*name` needs an anchor `&name` before it: add the anchor or write the value out"
        ),
        "{msg}"
    );
    let (_, path) = refused("name: x\n!!float ~}~~\n", Format::Yaml);
    assert_eq!(path, "line 3 column 1");
    let (msg, path) = refused("", Format::Json);
    assert_eq!(path, "line 1 column 1");
    assert_eq!(msg, "m.yaml: line 1 column 1: EOF while parsing a value; the text is empty: write a model (see `planardyn docs model-format`)");
}

#[test]
fn a_second_yaml_document_is_located_at_its_separator() {
    let text = format!("{FOUR_BAR}---\n{FOUR_BAR}");
    let separator = text.lines().position(|l| l == "---").unwrap() + 1;
    let (msg, path) = refused(&text, Format::Yaml);
    assert_eq!(path, format!("line {separator} column 1"));
    assert!(msg.ends_with("remove the `---` separators: a model file holds one document"), "{msg}");
}

#[test]
fn errors_inside_a_field_keep_its_path_and_add_the_line() {
    let (msg, path) = refused(&FOUR_BAR.replace("mass: 0.5,", "mass: heavy,"), Format::Yaml);
    assert_eq!(path, "bodies.crank.mass");
    assert_eq!(
        msg,
        "m.yaml: bodies.crank.mass: \"heavy\" is not a number with a unit; this field takes a mass (kg, g, lb, \
         or a number alone in kg) (line 11 column 33); write e.g. \"30 g\""
    );
    // An unknown field inside a pair (an entry tagged by `type`): the field itself.
    let (msg, path) = refused(
        &FOUR_BAR.replace("{type: revolute, name: O,", "{type: revolute, axis: [1, 0], name: O,"),
        Format::Yaml,
    );
    assert_eq!(path, "pairs[0].axis");
    assert!(
        msg.contains("unknown field `axis`, expected one of `name`, `at`, `bodies`")
            && msg.ends_with("; remove it or correct its spelling"),
        "{msg}"
    );
    // A pair written as a list: no Rust type names.
    let (msg, path) = refused(
        &FOUR_BAR.replace("{type: revolute, name: O, at: O, bodies: [ground, crank]}", "[revolute]"),
        Format::Yaml,
    );
    assert_eq!(path, "pairs[0]");
    assert!(msg.contains("expected a mapping with the fields of its `type`"), "{msg}");
}

#[test]
fn json_errors_are_located_in_the_field_being_read() {
    let (msg, path) = refused(r#"{"name": "x", "points": {"O": [0, NaN]}}"#, Format::Json);
    assert_eq!(path, "points.O[1]");
    assert_eq!(
        msg,
        "m.yaml: points.O[1]: expected value (line 1 column 35); \
         the text is not valid JSON: check the brackets, quotes, commas and colons there (JSON has no NaN or Infinity)"
    );
}

#[test]
fn a_file_that_cannot_be_read_says_which_and_where() {
    let e = load("/nonexistent/model.yaml").unwrap_err();
    assert_eq!(e.path(), "<file>");
    assert!(e.to_string().starts_with("/nonexistent/model.yaml: <file>: cannot read the file: "), "{e}");
    let dir = std::env::temp_dir().join(format!("planardyn-latin1-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("m.yaml");
    std::fs::write(&file, b"name: x\npoints: {\xe9: [0, 0]}\n").unwrap();
    let e = load(&file).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(matches!(e, ModelError::Parse { .. }));
    assert_eq!(e.path(), "line 2 column 10");
    assert!(e.to_string().ends_with("the file is not UTF-8 text; save it as UTF-8"), "{e}");
}

/// A triangle of two bars pinned to the ground at O and A and to each other at B: 3*2 - 2*3 = 0.
const TRIANGLE: &str = "name: s\npoints: {O: [0, 0], A: [1, 0], B: [0, 1]}\nground: [O, A]\nbodies:\n  \
    b1: {points: [O, B], mass: 1, inertia: 1, com: [0, 0.5]}\n  b2: {points: [A, B], mass: 1, inertia: 1, com: [0.5, 0.5]}\n\
    pairs:\n  - {type: revolute, name: O, at: O, bodies: [ground, b1]}\n  - {type: revolute, name: A, at: A, bodies: [ground, b2]}\n  \
    - {type: revolute, name: B, at: B, bodies: [b1, b2]}\n";

#[test]
fn a_structure_is_told_it_cannot_move_whatever_its_coordinates() {
    // Located at the list's value on its key's line, or at the key above a block list.
    for (coordinates, at) in [
        ("coordinates: []\n", "line 11 column 14"),
        ("coordinates:\n  - {name: q, pair: O, value: 1.5707963267948966}\n", "line 11 column 1"),
    ] {
        let (msg, path) = refused(&format!("{TRIANGLE}{coordinates}"), Format::Yaml);
        assert_eq!(path, "coordinates");
        assert_eq!(
            msg,
            format!(
                "m.yaml: coordinates: the drawing is a structure (mobility 0): its 6 pair constraints have rank 6 = 3n \
                 in the drawing (Chebyshev-Grubler: 3n - 2p = 3*2 - 2*3 = 0), so nothing can move, and planardyn moves \
                 mechanisms only ({at}); remove a pair or a body (or add a body) until the mobility is at least 1, or \
                 check the drawing, then give one coordinate per degree of freedom"
            )
        );
    }
    // A mechanism with no coordinate is told how many to give.
    let (msg, _) =
        refused(&FOUR_BAR.replace("  - {name: theta1, pair: O, value: 1.0471975511965976}\n", ""), Format::Yaml);
    assert_eq!(
        msg,
        "m.yaml: coordinates: no generalized coordinates, but the mechanism has mobility 3n - rank = 1 (line 19 column 1); \
         name 1 input pair(s) under `coordinates`"
    );
}

#[test]
fn a_number_in_another_radix_or_beyond_a_double_is_named_for_what_it_is() {
    // YAML reads 0x10 as the integer 16, and the number field refuses it: not "expected a number".
    let (msg, path) = refused(&FOUR_BAR.replace("mass: 0.5,", "mass: 0x10,"), Format::Yaml);
    assert_eq!(path, "bodies.crank.mass");
    assert_eq!(
        msg,
        "m.yaml: bodies.crank.mass: the integer 16 is written in hexadecimal, octal or binary (0x, 0o or 0b), \
         which the model does not accept (line 11 column 33); write the decimal number 16"
    );
    // 400 digits overflow a double (YAML then reads them as text): not "a string".
    let (msg, _) = refused(&FOUR_BAR.replace("mass: 0.5,", &format!("mass: {},", "1".repeat(400))), Format::Yaml);
    assert_eq!(
        msg,
        "m.yaml: bodies.crank.mass: the number 11111111111111111111... (400 characters) is beyond the largest \
         magnitude a number can have (about 1.8e308) (line 11 column 33); check the units (SI) and the digits, \
         and write it with at most 17 significant digits, in exponent form if large (e.g. 1.5e12)"
    );
    // A long number within range is read (to the nearest double).
    let long = format!("0.5{}", "0".repeat(400));
    yaml(&FOUR_BAR.replace("mass: 0.5,", &format!("mass: {long},")));
}

#[test]
fn a_centre_of_mass_far_outside_the_drawing_is_named() {
    let text = FOUR_BAR.replace("com: [0.125, 0.21650635094610965]", "com: [1e9, 0.2]");
    let (msg, path) = refused(&text, Format::Yaml);
    assert_eq!(path, "bodies.crank.com");
    assert_eq!(
        msg,
        "m.yaml: bodies.crank.com: the centre of mass [1000000000, 0.2] is 1.000e9 m from the nearest point of body \
         'crank', more than 1e6 times the size of the drawing (1.6351920284924188 m): it is far outside the drawing \
         (line 11 column 74); \
         check its coordinates and units (SI: metres), and give it in the same frame as `points`"
    );
    // A part's centre of mass is named as the part's.
    let parts = FOUR_BAR.replace(
        "crank: {points: [O, A], mass: 0.5, inertia: 0.010416666666666666, com: [0.125, 0.21650635094610965]}",
        "crank: {points: [O, A], parts: [{point_mass: A, mass: 0.5}, {mass: 1e-3, inertia: 0, com: [0, -1e7]}]}",
    );
    let (_, path) = refused(&parts, Format::Yaml);
    assert_eq!(path, "bodies.crank.parts[1].com");
}

#[test]
fn a_bar_of_length_zero_is_named_as_the_bar() {
    // The body's inertia is then 0: it was reported as `bodies.crank.inertia`, a field not given.
    let crank = "crank: {points: [O, A], mass: 0.5, inertia: 0.010416666666666666, com: [0.125, 0.21650635094610965]}";
    let (msg, path) =
        refused(&FOUR_BAR.replace(crank, "crank: {points: [O, A], mass: 0.5, uniform_bar: [A, A]}"), Format::Yaml);
    assert_eq!(path, "bodies.crank.uniform_bar");
    assert_eq!(
        msg,
        "m.yaml: bodies.crank.uniform_bar: the bar's ends A and A are at the same place, a bar of length 0 with no \
         moment of inertia (line 11 column 51); name the bar's two ends, or give a point mass (`point_mass: A`) or \
         `com` with `inertia`"
    );
    // A part's bar is named as the part's (the body's other part gives it inertia).
    let parts = "crank: {points: [O, A], parts: [{mass: 0.5, uniform_bar: [O, A]}, {mass: 0.1, uniform_bar: [A, A]}]}";
    let (_, path) = refused(&FOUR_BAR.replace(crank, parts), Format::Yaml);
    assert_eq!(path, "bodies.crank.parts[1].uniform_bar");
}

#[test]
fn an_unnamed_pair_is_not_referenced_by_its_made_up_name() {
    let text = FOUR_BAR.replace("{name: theta1, pair: O,", "{name: theta1, pair: crank-coupler@A,");
    let (msg, path) = refused(&text, Format::Yaml);
    assert_eq!(path, "coordinates[0].pair");
    assert_eq!(
        msg,
        "m.yaml: coordinates[0].pair: 'crank-coupler@A' is the name made up for the unnamed pairs[1], which a model \
         may not refer to (line 20 column 26); give that pair a `name:` and refer to it by that name"
    );
}

#[test]
fn a_yaml_tag_is_refused_where_it_is() {
    let (msg, path) = refused(&FOUR_BAR.replace("mass: 0.5,", "mass: !foo 3,"), Format::Yaml);
    assert_eq!(path, "bodies.crank.mass");
    assert_eq!(
        msg,
        "m.yaml: bodies.crank.mass: the YAML tag `!foo` is not part of the model format (line 11 column 33); \
         remove it and write the value alone (see `planardyn docs model-format`)"
    );
    let (msg, path) = refused(&format!("!model\n{FOUR_BAR}"), Format::Yaml);
    assert_eq!(path, "line 1 column 1");
    assert!(msg.starts_with("m.yaml: line 1 column 1: the YAML tag `!model` is not part"), "{msg}");
    // The core tags are YAML's own types, and `!` inside a plain string is text.
    yaml(&FOUR_BAR.replace("mass: 0.5,", "mass: !!float 0.5,").replace("under gravity", "under gravity !x"));
}

/// A drive whose table's times go back (its third), for the drive's refused value.
const DRIVE: &str = "drives:\n  - coordinate: theta1\n    table:\n      t: [0, 2, 1]\n      effort: [1, 2, 3]\n";

/// A value the loader's checks refuse (a body's mass, a pair's point in the list of pairs, a
/// point, a drive's time) is located as a parse error is, `(line L column C)` of the value
/// before the fix, in YAML block style (the shipped four-bar), flow style (`FOUR_BAR`'s
/// bodies, pairs and coordinates) and JSON (`FOUR_BAR` with a drive, pretty-printed).
#[test]
fn a_refused_value_is_located_in_yaml_block_and_flow_and_json() {
    let shipped = format!("{}/../../examples/models/four-bar-gravity.yaml", env!("CARGO_MANIFEST_DIR"));
    let block = std::fs::read_to_string(shipped).unwrap();
    let json = serde_json::to_string_pretty(&yaml(&format!("{FOUR_BAR}{}", DRIVE.replace("1]", "7]"))).spec).unwrap();
    let mass = "bodies.rocker.mass: mass must be > 0 kg, got -1";
    let pair = ("pairs[2].at: unknown point 'Q'", "; points are: O, D, A, B (use one of them, or add it to `points`)");
    let point = "points.B: 1e31 is beyond the largest magnitude accepted, 1e30: check the units (SI)";
    let drive = "drives[0].table.t[2]: times must increase strictly";
    let drive_block = format!("{DRIVE}simulate:");
    let drive_flow = format!("{DRIVE}coordinates:");
    let cases = [
        (block.as_str(), Format::Yaml, "    mass: 1.0\n", "    mass: -1.0\n", mass, "(line 36 column 11)", ""),
        (block.as_str(), Format::Yaml, "at: B,", "at: Q,", pair.0, "(line 43 column 48)", pair.1),
        (block.as_str(), Format::Yaml, "B: [1.336926485022576,", "B: [1e31,", point, "(line 20 column 6)", ""),
        (block.as_str(), Format::Yaml, "simulate:", &drive_block, drive, "(line 60 column 17)", ""),
        (FOUR_BAR, Format::Yaml, "mass: 1.0,", "mass: -1.0,", mass, "(line 13 column 34)", ""),
        (FOUR_BAR, Format::Yaml, "at: B,", "at: Q,", pair.0, "(line 17 column 26)", pair.1),
        (FOUR_BAR, Format::Yaml, "B: [1.336926485022576,", "B: [1e31,", point, "(line 8 column 6)", ""),
        (FOUR_BAR, Format::Yaml, "coordinates:", &drive_flow, drive, "(line 22 column 17)", ""),
        (json.as_str(), Format::Json, "\"mass\": 1.0", "\"mass\": -1.0", mass, "(line 59 column 15)", ""),
        (json.as_str(), Format::Json, "\"at\": \"B\"", "\"at\": \"Q\"", pair.0, "(line 87 column 13)", pair.1),
        (json.as_str(), Format::Json, "1.336926485022576", "1e31", point, "(line 20 column 10)", ""),
        (json.as_str(), Format::Json, "7.0", "1.0", drive, "(line 117 column 11)", ""),
    ];
    for (text, format, old, new, what, at, fix) in cases {
        assert!(text.contains(old), "{old}");
        let (msg, _) = refused(&text.replacen(old, new, 1), format);
        assert_eq!(msg, format!("m.yaml: {what} {at}{fix}"));
    }
}

/// A field the text does not give is located at its parent: a body's missing `inertia` at the
/// body (its key above a block, its mapping's `{` in flow style and JSON).
#[test]
fn a_missing_fields_error_is_located_at_its_parent() {
    let shipped = format!("{}/../../examples/models/four-bar-gravity.yaml", env!("CARGO_MANIFEST_DIR"));
    let block = std::fs::read_to_string(shipped).unwrap();
    let json = serde_json::to_string_pretty(&yaml(FOUR_BAR).spec).unwrap();
    let cases = [
        (block.as_str(), Format::Yaml, "    inertia: 0.08333333333333333\n", "(line 34 column 3)"),
        (FOUR_BAR, Format::Yaml, " inertia: 0.08333333333333333,", "(line 13 column 11)"),
        (json.as_str(), Format::Json, "\n      \"inertia\": 0.08333333333333333,", "(line 54 column 15)"),
    ];
    for (text, format, written, at) in cases {
        assert!(text.contains(written), "{written}");
        let (msg, _) = refused(&text.replacen(written, "", 1), format);
        assert_eq!(
            msg,
            format!(
                "m.yaml: bodies.rocker.inertia: missing: add the moment of inertia about the centre of mass (kg m^2) {at}"
            )
        );
    }
}

/// A model given as data (a Python dict, serialised as JSON text its user never wrote): its
/// errors name the field path alone, the checks' as the parsers', with no line of that text.
#[test]
fn a_model_given_as_data_is_located_by_its_field_path_alone() {
    let json = serde_json::to_string(&yaml(FOUR_BAR).spec).unwrap();
    let cases = [
        ("\"mass\":1.0", "\"mass\":-1.0", "bodies.rocker.mass: mass must be > 0 kg, got -1".to_string()),
        (
            "\"mass\":1.0",
            "\"mass\":\"heavy\"",
            "bodies.rocker.mass: \"heavy\" is not a number with a unit; this field takes a mass (kg, g, lb, or a \
             number alone in kg); write e.g. \"30 g\""
                .to_string(),
        ),
        (
            "\"mass\":1.0",
            "\"mass\":NaN",
            "bodies.rocker.mass: not a finite number; give a finite number (NaN and infinities are not model values)"
                .to_string(),
        ),
        (
            "\"at\":\"B\"",
            "\"at\":\"Q\"",
            "pairs[2].at: unknown point 'Q'; points are: O, D, A, B (use one of them, or add it to `points`)"
                .to_string(),
        ),
    ];
    for (old, new, expected) in cases {
        assert!(json.contains(old), "{old}");
        let text = json.replacen(old, new, 1);
        assert_eq!(loads(&text, Format::Data, "<dict>").unwrap_err().to_string(), format!("<dict>: {expected}"));
        // As JSON text, the same error with its line.
        let located = loads(&text, Format::Json, "<dict>").unwrap_err().to_string();
        assert!(located.contains(" (line 1 column "), "{located}");
    }
}

/// The structural analysis reads a model the loader refuses for its mobility; every other
/// error is the loader's, located as [`loads`] locates it.
#[test]
fn the_structural_analysis_locates_the_loaders_errors() {
    let text = FOUR_BAR.replace("mass: 1.0,", "mass: -1.0,");
    let err = planardyn::analyse_spec(&text, Format::Yaml, "m.yaml").unwrap_err().to_string();
    assert_eq!(err, "m.yaml: bodies.rocker.mass: mass must be > 0 kg, got -1 (line 13 column 34)");
    assert_eq!(err, loads(&text, Format::Yaml, "m.yaml").unwrap_err().to_string());
}
