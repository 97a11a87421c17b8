//! The structural analysis (`analyse_spec`) locates a model's errors as `loads` does, on every
//! shipped model with each of its lines deleted or a value broken: where the analysis refuses a
//! text, the loader refuses it with the same message (line and column included).

use planardyn::{analyse_spec, loads, Format};
use std::path::Path;

#[test]
fn the_analysis_refuses_as_the_loader_does_on_every_line_of_every_model() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/models");
    let (mut refused, mut only_loads) = (0, 0);
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("yaml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let mut texts = Vec::new();
        for k in 0..lines.len() {
            let mut without = lines.clone();
            without.remove(k);
            texts.push(without.join("\n"));
            for (from, to) in [("mass: ", "mass: -"), ("revolute", "revolut"), (", ", ", .nan, "), ("[", "[x")] {
                if lines[k].contains(from) {
                    let mut broken = lines.clone();
                    let line = lines[k].replacen(from, to, 1);
                    broken[k] = &line;
                    texts.push(broken.join("\n"));
                }
            }
        }
        for t in &texts {
            let analysed = analyse_spec(t, Format::Yaml, "m.yaml");
            let loaded = loads(t, Format::Yaml, "m.yaml");
            match (analysed, loaded) {
                (Err(a), Err(l)) => {
                    assert_eq!(a.to_string(), l.to_string(), "{}:\n{t}", path.display());
                    refused += 1;
                }
                (Err(a), Ok(_)) => panic!("{}: the analysis refuses what loads: {a}\n{t}", path.display()),
                (Ok(_), Err(_)) => only_loads += 1,
                (Ok(_), Ok(_)) => {}
            }
        }
    }
    eprintln!("refused alike {refused}, by the loader alone {only_loads}");
    assert!(refused > 500, "{refused}");
}
