//! The JSON Schema's quantity kinds (`schema/planardyn-model.schema.json`, `$defs.<key>`)
//! accept the units of the loader's tables (`units::KINDS`), and no other: its pattern is
//! made here from the table, and a mismatch prints the `$defs` entry to paste.

use planardyn::units::{Kind, KINDS};

/// The decimal number the loader reads (`units::number_prefix`), with white space around.
const NUMBER: &str = r"^\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?\s*";

/// A spelling of the table as a pattern of what `units::read` normalises to it: white
/// space, `*`, `·` or `⋅` between factors, spaces beside `/`, `²` for `^2`, `µ`/`μ` for `u`,
/// `°` for `deg`.
fn spelling(unit: &str) -> String {
    let mut out = String::new();
    for (i, factor) in unit.split(' ').enumerate() {
        if i > 0 {
            out.push_str(r"[\s*·⋅]+");
        }
        let f = factor.replace('^', r"\^").replace(r"\^2", r"(\^2|²)").replace('/', r"\s*/\s*");
        let f = match f.strip_prefix('u') {
            Some(rest) => format!("[uµμ]{rest}"),
            None => f,
        };
        out.push_str(&f.replace("deg", "(deg|°)"));
    }
    out
}

fn pattern(kind: &Kind) -> String {
    let units: Vec<String> = kind.units.iter().flat_map(|(names, _)| names.iter().map(|n| spelling(n))).collect();
    format!(r"{NUMBER}({})\s*$", units.join("|"))
}

#[test]
fn the_schema_takes_the_units_the_loader_reads() {
    let path = format!("{}/../../schema/planardyn-model.schema.json", env!("CARGO_MANIFEST_DIR"));
    let schema: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut paste = Vec::new();
    for kind in KINDS {
        let expected = serde_json::json!({
            "description": format!("{} as text: a number and one of its units ({}); a number alone is in {}.",
                kind.name, kind.unit_list(), kind.si),
            "type": "string",
            "pattern": pattern(kind),
        });
        if schema["$defs"][kind.key] != expected {
            paste.push(format!("\"{}\": {expected}", kind.key));
        }
    }
    assert!(paste.is_empty(), "the schema's $defs differ from the units' tables; paste:\n{}", paste.join(",\n"));
}
