//! Fuzzing the model loader and builder (proptest): every shipped model file mutated
//! structurally (fields deleted, duplicated, retyped, renamed, names swapped, extreme numbers,
//! NaN and inf, empty lists, wrong mobility) and as text (lines cut, moved, doubled, tokens
//! inserted), random texts, and the corpus kept in `tests/fuzz_corpus/` (shared with the
//! Python fuzz, `tests/test_loader_fuzz.py`).
//!
//! Every input must, within [`TIME_LIMIT`] and without a panic, give `Ok(Mechanism)` or a
//! `ModelError` naming the file, a location (a field path, or line and column) and a fix. A
//! model that loads must assemble at q0 and give finite accelerations, or a clean error.
//!
//! CI runs 1000 inputs per property (about 2 s with --release); a campaign:
//! `PLANARDYN_FUZZ_CASES=250000 PLANARDYN_FUZZ_SEED=7 cargo test --release -p planardyn
//! --test fuzz_loader -- --nocapture --test-threads=1` prints inputs, loads and time per
//! property (the seed is fixed by default, so CI is repeatable).

use planardyn::dynamics::{forward, ModelDrives};
use planardyn::kinematics::assemble_into;
use planardyn::{loads, Format, Mechanism, ModelError, Workspace};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_yaml_ng::{Mapping, Value};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A load plus one dynamics evaluation takes well under a second in a debug build; far
/// beyond it is a hang (an unbounded iteration), not a slow machine.
const TIME_LIMIT: Duration = Duration::from_secs(20);

fn cases() -> u32 {
    std::env::var("PLANARDYN_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(1000)
}

fn runner() -> TestRunner {
    let seed = std::env::var("PLANARDYN_FUZZ_SEED").ok().and_then(|v| v.parse::<u64>().ok()).unwrap_or(0);
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    // Failures are kept by hand in tests/fuzz_corpus/ (with what the loader must say), not
    // in proptest's regression files.
    let config = Config {
        cases: cases(),
        max_global_rejects: cases(),
        failure_persistence: None,
        max_shrink_iters: 2000,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The shipped model files, the bases of the mutations: (file name, text).
fn bases() -> Vec<(String, String)> {
    let mut out = Vec::new();
    for dir in ["examples/models", "examples/models/library"] {
        let mut paths: Vec<PathBuf> = std::fs::read_dir(repo().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
            .collect();
        paths.sort();
        for p in paths {
            out.push((p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read_to_string(&p).unwrap()));
        }
    }
    assert!(out.len() >= 15, "the shipped models are missing: {}", out.len());
    out
}

// ----------------------------------------------------------------------------- the checks

/// What an input gave.
#[derive(Debug, Clone, PartialEq)]
enum Outcome {
    Loaded,
    Refused(ModelError),
}

/// Words a fix is phrased with (an imperative, or the rule the value must follow).
const FIX_WORDS: &[&str] = &[
    "add",
    "remove",
    "use ",
    "give",
    "write",
    "check",
    "rename",
    "draw",
    "must",
    "list ",
    "name ",
    "quote",
    "close",
    "indent",
    "bring",
    "convert",
    "join",
    "see `planardyn docs",
];
/// Rust names that must not reach a user.
const JARGON: &[&str] = &["Spec", "f64", "usize", "struct ", "enum "];

/// The error names the source, a location and a fix, in plain words.
fn check_error(e: &ModelError, source: &str) -> Result<(), String> {
    let text = e.to_string();
    let path = e.path();
    let message = text
        .strip_prefix(&format!("{source}: {path}: "))
        .ok_or_else(|| format!("not '<source>: <path>: <message>': {text}"))?;
    if path.is_empty() || path == "." {
        return Err(format!("no location: {text}"));
    }
    if message.trim().is_empty() {
        return Err(format!("no message: {text}"));
    }
    // The user's own text is quoted ("...", `...`) in messages: only the rest is ours.
    let ours: String = message.split(['"', '`']).step_by(2).collect();
    if let Some(w) = JARGON.iter().find(|w| ours.contains(*w)) {
        return Err(format!("Rust jargon '{w}' in: {text}"));
    }
    let lower = message.to_lowercase();
    if !FIX_WORDS.iter().any(|w| lower.contains(w)) {
        return Err(format!("no fix in: {text}"));
    }
    Ok(())
}

/// A loaded mechanism is validated: finite drawing, positive masses; it assembles at q0 and
/// one forward-dynamics evaluation gives finite accelerations, or a clean error.
fn check_mechanism(mech: &Mechanism) -> Result<(), String> {
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if !finite(&mech.x0) || !mech.scale.is_finite() {
        return Err(format!("non-finite drawing: x0 {:?}, scale {}", mech.x0, mech.scale));
    }
    if let Some(b) =
        mech.bodies.iter().find(|b| !(b.mass > 0.0 && b.inertia > 0.0 && b.mass.is_finite() && b.inertia.is_finite()))
    {
        return Err(format!("body '{}' has mass {} and inertia {}", b.name, b.mass, b.inertia));
    }
    let (q0, qd0) = mech.initial_state();
    let mut ws = Workspace::new(mech);
    // The loader assembled it at q0 already: doing it again must work.
    assemble_into(mech, &q0, &mut ws).map_err(|e| format!("loaded, but does not assemble at q0 = {q0:?}: {e}"))?;
    if !finite(&ws.x) {
        return Err(format!("assembled at non-finite x {:?}", ws.x));
    }
    match forward(mech, 0.0, &q0, &qd0, &mut ModelDrives(mech), &mut ws) {
        Ok(()) if finite(&ws.qdd) => Ok(()),
        Ok(()) => Err(format!("forward dynamics gave qdd = {:?}", ws.qdd)),
        Err(e) if e.to_string().trim().is_empty() || e.to_string().contains("NaN") => {
            Err(format!("forward dynamics: '{e}'"))
        }
        Err(_) => Ok(()),
    }
}

/// Load `text` on a worker thread with a time limit, catching panics; check the outcome.
fn run(text: &str, format: Format, source: &str) -> Result<Outcome, String> {
    let (tx, rx) = mpsc::channel();
    let (t, s) = (text.to_string(), source.to_string());
    std::thread::spawn(move || {
        let result = std::panic::catch_unwind(|| match loads(&t, format, &s) {
            Ok(mech) => check_mechanism(&mech).map(|()| Outcome::Loaded),
            Err(e) => check_error(&e, &s).map(|()| Outcome::Refused(e)),
        });
        let _ = tx.send(result);
    });
    let result = match rx.recv_timeout(TIME_LIMIT) {
        Ok(Ok(checked)) => checked,
        Ok(Err(panic)) => {
            let what =
                panic.downcast_ref::<String>().cloned().or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()));
            Err(format!("panicked: {}", what.unwrap_or_default()))
        }
        Err(_) => Err(format!("no answer within {TIME_LIMIT:?} (a hang)")),
    };
    result.map_err(|why| format!("{why}\n--- input ({format:?}) ---\n{text}\n---"))
}

/// Run one property over `cases()` inputs and print what it did.
fn campaign<S: Strategy>(name: &str, strategy: S, test: impl Fn(S::Value) -> Result<Outcome, String>) {
    let (inputs, loaded, slowest_us) = (AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0));
    let start = Instant::now();
    let result = runner().run(&strategy, |v| {
        let t = Instant::now();
        let outcome = test(v);
        inputs.fetch_add(1, Ordering::Relaxed);
        slowest_us.fetch_max(t.elapsed().as_micros() as u64, Ordering::Relaxed);
        if let Ok(Outcome::Loaded) = outcome {
            loaded.fetch_add(1, Ordering::Relaxed);
        }
        outcome.map(|_| ()).map_err(TestCaseError::fail)
    });
    eprintln!(
        "{name}: {} inputs ({} loaded) in {:.1} s, slowest {:.3} s",
        inputs.into_inner(),
        loaded.into_inner(),
        start.elapsed().as_secs_f64(),
        slowest_us.into_inner() as f64 * 1e-6
    );
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
}

// ----------------------------------------------------------------------------- structural mutations

/// One step into a YAML tree.
#[derive(Debug, Clone)]
enum Step {
    Key(Value),
    Index(usize),
}

fn node_paths(v: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match v {
        Value::Mapping(m) => {
            for (k, child) in m {
                prefix.push(Step::Key(k.clone()));
                out.push(prefix.clone());
                node_paths(child, prefix, out);
                prefix.pop();
            }
        }
        Value::Sequence(s) => {
            for (i, child) in s.iter().enumerate() {
                prefix.push(Step::Index(i));
                out.push(prefix.clone());
                node_paths(child, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn node_mut<'a>(mut v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    for step in path {
        v = match (step, v) {
            (Step::Key(k), Value::Mapping(m)) => m.get_mut(k)?,
            (Step::Index(i), Value::Sequence(s)) => s.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// Every name the model uses (points, bodies, pairs, coordinates): swapping one for another
/// makes references that resolve to the wrong thing.
fn names(model: &Value) -> Vec<String> {
    let mut out = vec!["ground".to_string()];
    for section in ["points", "bodies"] {
        if let Some(Value::Mapping(m)) = model.get(section) {
            out.extend(m.keys().filter_map(|k| k.as_str().map(str::to_string)));
        }
    }
    for section in ["pairs", "coordinates"] {
        if let Some(Value::Sequence(s)) = model.get(section) {
            out.extend(s.iter().filter_map(|e| e.get("name")?.as_str().map(str::to_string)));
        }
    }
    out
}

#[derive(Debug, Clone)]
enum Edit {
    /// Remove the field or list entry.
    Delete,
    /// Put another value there (another type, an extreme number, NaN, inf...).
    Set(Value),
    /// Put a name the model uses there (the k-th, cyclically).
    Name(usize),
    /// Multiply a number (1e9, -1, 0, 1e-300...).
    Scale(f64),
    /// A list entry appended again, or a map entry copied under a new key.
    Duplicate,
    /// Exchange with the k-th sibling.
    Swap(usize),
    /// Rename a map key to a name the model uses (the k-th).
    RenameKey(usize),
    /// x -> [x].
    Wrap,
    /// The node emptied: [] or {}.
    Empty,
}

fn apply(model: &mut Value, (target, shallow, edit): &(usize, bool, Edit)) {
    let mut all = Vec::new();
    node_paths(model, &mut Vec::new(), &mut all);
    // Half the edits go to the top two levels (sections and their entries: pairs,
    // coordinates, bodies...), where they change the structure and the mobility.
    let pool: Vec<&Vec<Step>> = all.iter().filter(|p| !*shallow || p.len() <= 2).collect();
    if pool.is_empty() {
        return;
    }
    let path = pool[target % pool.len()].clone();
    let (last, parent_path) = path.split_last().unwrap();
    let names = names(model);
    let Some(parent) = node_mut(model, parent_path) else { return };
    match (edit, parent, last) {
        (Edit::Delete, Value::Mapping(m), Step::Key(k)) => {
            m.shift_remove(k);
        }
        (Edit::Delete, Value::Sequence(s), Step::Index(i)) => {
            s.remove(*i);
        }
        (Edit::Duplicate, Value::Sequence(s), Step::Index(i)) => {
            let copy = s[*i].clone();
            s.push(copy);
        }
        (Edit::Duplicate, Value::Mapping(m), Step::Key(k)) => {
            let copy = m[k].clone();
            let key = format!("{}2", k.as_str().unwrap_or("k"));
            m.insert(Value::String(key), copy);
        }
        (Edit::Swap(j), Value::Sequence(s), Step::Index(i)) => {
            let j = j % s.len();
            s.swap(*i, j);
        }
        (Edit::Swap(j), Value::Mapping(m), Step::Key(k)) => {
            let mut entries: Vec<(Value, Value)> = std::mem::take(m).into_iter().collect();
            let i = entries.iter().position(|(key, _)| key == k).unwrap();
            let j = j % entries.len();
            let vi = std::mem::replace(&mut entries[i].1, Value::Null);
            entries[i].1 = std::mem::replace(&mut entries[j].1, vi);
            *m = entries.into_iter().collect();
        }
        (Edit::RenameKey(n), Value::Mapping(m), Step::Key(k)) => {
            let name = Value::String(names[n % names.len()].clone());
            // A key renamed to one already there replaces that entry (a YAML map has no duplicates).
            *m =
                std::mem::take(m).into_iter().map(|(key, v)| (if &key == k { name.clone() } else { key }, v)).collect();
        }
        (edit, parent, last) => {
            let node = match (parent, last) {
                (Value::Mapping(m), Step::Key(k)) => m.get_mut(k).unwrap(),
                (Value::Sequence(s), Step::Index(i)) => &mut s[*i],
                _ => return,
            };
            match edit {
                Edit::Set(v) => *node = v.clone(),
                Edit::Name(n) => *node = Value::String(names[n % names.len()].clone()),
                Edit::Scale(f) => {
                    if let Some(x) = node.as_f64() {
                        *node = Value::from(x * f);
                    }
                }
                Edit::Wrap => *node = Value::Sequence(vec![node.clone()]),
                Edit::Empty => {
                    *node = match node {
                        Value::Mapping(_) => Value::Mapping(Mapping::new()),
                        _ => Value::Sequence(Vec::new()),
                    }
                }
                _ => {}
            }
        }
    }
}

fn extreme() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>(),
        prop::sample::select(vec![
            0.0,
            -0.0,
            -1.0,
            1e-300,
            -1e-300,
            5e-324,
            1e-9,
            1e9,
            1.1e9,
            1e15,
            1e20,
            1e300,
            -1e300,
            1e308,
            f64::MAX,
            f64::MIN,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ]),
    ]
}

fn values() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        extreme().prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
        any::<u64>().prop_map(Value::from),
        any::<bool>().prop_map(Value::Bool),
        Just(Value::Null),
        "\\PC{0,12}".prop_map(Value::String),
        prop::sample::select(vec![
            "",
            "ground",
            "revolute",
            "prismatic",
            "force",
            "spring",
            "SI",
            "rk4",
            "O",
            "A",
            "yes",
            "~"
        ])
        .prop_map(|s| Value::String(s.into())),
    ];
    leaf.prop_recursive(2, 8, 3, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Sequence),
            prop::collection::vec(("[a-z_]{1,8}", inner), 0..3)
                .prop_map(|kv| Value::Mapping(kv.into_iter().map(|(k, v)| (Value::String(k), v)).collect())),
        ]
    })
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        3 => Just(Edit::Delete),
        3 => values().prop_map(Edit::Set),
        2 => any::<usize>().prop_map(Edit::Name),
        2 => prop::sample::select(vec![1e9, 1e300, -1.0, 0.0, 1e-300, 2.0, 1e3]).prop_map(Edit::Scale),
        2 => Just(Edit::Duplicate),
        1 => any::<usize>().prop_map(Edit::Swap),
        1 => any::<usize>().prop_map(Edit::RenameKey),
        1 => Just(Edit::Wrap),
        1 => Just(Edit::Empty),
    ]
}

/// A model text: a shipped file with 1 to 4 structural edits, written as YAML or JSON.
fn mutated_models(bases: Vec<(String, String)>) -> impl Strategy<Value = (String, String, Format)> {
    let models: Vec<(String, Value)> =
        bases.into_iter().map(|(n, t)| (n, serde_yaml_ng::from_str(&t).unwrap())).collect();
    (prop::sample::select(models), prop::collection::vec((any::<usize>(), any::<bool>(), edit()), 1..5), any::<bool>())
        .prop_filter_map("not writable as text", |((name, mut model), edits, json)| {
            for e in &edits {
                apply(&mut model, e);
            }
            // JSON cannot write NaN or inf (serde_json makes them null): YAML then.
            let json = json && serde_json::to_string(&model).is_ok_and(|t| !t.contains("null"));
            let text = if json {
                serde_json::to_string_pretty(&model).ok()?
            } else {
                serde_yaml_ng::to_string(&model).ok()?
            };
            Some((name, text, if json { Format::Json } else { Format::Yaml }))
        })
}

/// A shipped file with 1 to 3 of its numbers changed (extreme, NaN, inf, scaled): the
/// structure stays, so most of these load and go on to assembly and dynamics.
fn numeric_mutations(bases: Vec<(String, String)>) -> impl Strategy<Value = (String, String)> {
    let models: Vec<(String, Value)> =
        bases.into_iter().map(|(n, t)| (n, serde_yaml_ng::from_str(&t).unwrap())).collect();
    let change = prop_oneof![
        extreme().prop_map(Err),
        prop::sample::select(vec![1e9, 1e6, 1e3, -1.0, 0.0, 1e-6, 1e-300]).prop_map(Ok)
    ];
    (prop::sample::select(models), prop::collection::vec((any::<usize>(), change), 1..4)).prop_filter_map(
        "not writable as text",
        |((name, mut model), changes)| {
            for (target, change) in changes {
                let mut all = Vec::new();
                node_paths(&model, &mut Vec::new(), &mut all);
                all.retain(|p| node_mut(&mut model, p).is_some_and(|v| v.is_number()));
                let node = node_mut(&mut model, &all[target % all.len()]).unwrap();
                let x = node.as_f64().unwrap();
                *node = Value::from(match change {
                    Ok(factor) => x * factor,
                    Err(value) => value,
                });
            }
            Some((name, serde_yaml_ng::to_string(&model).ok()?))
        },
    )
}

// ----------------------------------------------------------------------------- text mutations

/// Pieces of YAML: the schema's keys, brackets, anchors, tags, special floats, tabs.
const TOKENS: &[&str] = &[
    "\n",
    "\t",
    "  ",
    ": ",
    "- ",
    "[",
    "]",
    "{",
    "}",
    ",",
    "'",
    "\"",
    "#",
    "&a ",
    "*a",
    "<<: *a",
    "!!float ",
    "!!str ",
    "!!binary ",
    "~",
    ".nan",
    "-.inf",
    "1e999",
    "0x10",
    "---\n",
    "...\n",
    "? ",
    "|\n",
    ">\n",
    "%YAML 1.2\n",
    "name: x\n",
    "points:\n",
    "  O: [0, 0]\n",
    "ground: [O]\n",
    "bodies:\n",
    "pairs:\n",
    "coordinates:\n",
    "type: prismatic",
    "{type: revolute, at: O, bodies: [ground, b]}",
    "\u{0}",
    "\u{feff}",
    "\u{1b}",
    "é",
];

#[derive(Debug, Clone)]
enum TextEdit {
    DeleteLine(usize),
    DoubleLine(usize),
    SwapLines(usize, usize),
    Insert(usize, &'static str),
    Cut(usize, usize),
    Truncate(usize),
}

fn text_edit() -> impl Strategy<Value = TextEdit> {
    prop_oneof![
        any::<usize>().prop_map(TextEdit::DeleteLine),
        any::<usize>().prop_map(TextEdit::DoubleLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| TextEdit::SwapLines(a, b)),
        (any::<usize>(), prop::sample::select(TOKENS)).prop_map(|(a, t)| TextEdit::Insert(a, t)),
        (any::<usize>(), 1..20usize).prop_map(|(a, n)| TextEdit::Cut(a, n)),
        any::<usize>().prop_map(TextEdit::Truncate),
    ]
}

fn apply_text(text: &str, edit: &TextEdit) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    let chars: Vec<char> = text.chars().collect();
    let (nl, nc) = (lines.len().max(1), chars.len().max(1));
    match *edit {
        TextEdit::DeleteLine(i) if !lines.is_empty() => {
            lines.remove(i % nl);
        }
        TextEdit::DoubleLine(i) if !lines.is_empty() => lines.insert(i % nl, lines[i % nl]),
        TextEdit::SwapLines(a, b) if !lines.is_empty() => lines.swap(a % nl, b % nl),
        TextEdit::Insert(at, token) => {
            let at = at % nc;
            return chars[..at].iter().collect::<String>() + token + &chars[at..].iter().collect::<String>();
        }
        TextEdit::Cut(at, n) => {
            let at = at % nc;
            return chars[..at].iter().chain(&chars[(at + n).min(chars.len())..]).collect();
        }
        TextEdit::Truncate(at) => return chars[..at % nc].iter().collect(),
        _ => {}
    }
    lines.join("\n") + "\n"
}

fn mutated_texts(bases: Vec<(String, String)>) -> impl Strategy<Value = (String, String)> {
    (prop::sample::select(bases), prop::collection::vec(text_edit(), 1..4)).prop_map(|((name, text), edits)| {
        let text = edits.iter().fold(text, |t, e| apply_text(&t, e));
        (name, text)
    })
}

fn random_texts() -> impl Strategy<Value = String> {
    prop_oneof![
        "\\PC{0,200}",
        any::<Vec<u8>>().prop_map(|b| String::from_utf8_lossy(&b).into_owned()),
        prop::collection::vec(prop::sample::select(TOKENS), 0..30).prop_map(|t| t.concat()),
    ]
}

// ----------------------------------------------------------------------------- the properties

#[test]
fn structurally_mutated_models_load_or_are_refused_with_a_located_fix() {
    campaign("structural mutations", mutated_models(bases()), |(name, text, format)| {
        run(&text, format, &format!("{name}~"))
    });
}

#[test]
fn models_with_extreme_numbers_load_and_evaluate_or_are_refused() {
    campaign("numeric mutations", numeric_mutations(bases()), |(name, text)| {
        run(&text, Format::Yaml, &format!("{name}~"))
    });
}

#[test]
fn textually_mutated_models_load_or_are_refused_with_a_located_fix() {
    campaign("text mutations", mutated_texts(bases()), |(name, text)| run(&text, Format::Yaml, &format!("{name}~")));
}

#[test]
fn random_texts_are_refused_with_a_located_fix() {
    campaign("random texts", (random_texts(), any::<bool>()), |(text, json)| {
        let format = if json { Format::Json } else { Format::Yaml };
        run(&text, format, "<fuzz>")
    });
}

#[test]
fn every_shipped_model_loads_and_evaluates() {
    for (name, text) in bases() {
        assert_eq!(run(&text, Format::Yaml, &name), Ok(Outcome::Loaded), "{name}");
    }
}

/// Inputs kept from fuzz runs; each file's first line says what the loader must do:
/// `# expect: ok`, or `# expect: error <path>` with the error's exact path.
#[test]
fn the_corpus_replays() {
    let dir = repo().join("tests/fuzz_corpus");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.retain(|p| p.extension().is_some_and(|e| e == "yaml"));
    files.sort();
    assert!(files.len() >= 10, "the corpus is missing: {dir:?}");
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&path).unwrap();
        let expect = text.lines().next().and_then(|l| l.strip_prefix("# expect:")).map(str::trim);
        let expect = expect.unwrap_or_else(|| panic!("{name}: the first line must be '# expect: ...'"));
        let got = run(&text, Format::Yaml, &name).unwrap_or_else(|e| panic!("{name}: {e}"));
        match (expect, got) {
            ("ok", Outcome::Loaded) => {}
            (e, Outcome::Refused(err)) if e.strip_prefix("error ") == Some(err.path()) => {}
            (e, got) => panic!("{name}: expected {e}, got {got:?}"),
        }
    }
}
