//! Parse errors in plain words. serde and the YAML/JSON parsers say what went wrong in
//! their own terms (`expected struct BodySpec`, an empty path at the top of the document,
//! no line for an error at the first character); this turns each into a [`ModelError`] with
//! a location (the field path, or `line L column C` where no field is known) and a fix.

use super::Format;
use crate::model::spec::LoadSpec;
use crate::units;
use crate::ModelError;
use serde_path_to_error::{Path, Segment};

/// Where a parser stopped: 1-based line and column, if it said.
pub(super) type LineColumn = Option<(usize, usize)>;

/// The text of the model, its format and name, for locating errors.
pub(super) struct Input<'a> {
    pub text: &'a str,
    pub format: Format,
    pub source: &'a str,
}

/// The phrases serde starts its data errors with (anything else is a syntax error).
const DATA_ERRORS: &[&str] = &[
    "invalid type",
    "invalid value",
    "invalid length",
    "missing field",
    "unknown field",
    "unknown variant",
    "duplicate field",
    "duplicate name",
    "data did not match",
];

impl Input<'_> {
    /// A parse error at `path`, with the parser's `message` and its location `at`.
    pub(super) fn error(&self, path: &Path, message: &str, at: LineColumn) -> ModelError {
        let message = strip_marks(message);
        // The YAML parser prefixes its own path to data errors (written like `path`'s, or
        // not quite, e.g. around aliases): keep the message from serde's phrase on.
        let message = message.strip_prefix(&format!("{path}: ")).unwrap_or(&message);
        let message = DATA_ERRORS.iter().filter_map(|p| message.find(p)).min().map_or(message, |i| &message[i..]);
        let mut field = field_path(path);
        let (message, fix) = self.explain(message, &mut field);
        let (path, message) = match (field.is_empty(), at) {
            (true, _) if self.format == Format::Data => ("the model".into(), message),
            (true, _) => (self.line_column(&message, at), message),
            (false, Some((line, column))) => (field, format!("{message} (line {line} column {column})")),
            (false, None) => (field, message),
        };
        ModelError::Parse { source_name: self.source.to_string(), path, message: format!("{message}; {fix}") }
    }

    /// The message in plain words and its fix; a missing field goes onto the path.
    fn explain(&self, message: &str, field: &mut String) -> (String, String) {
        // A quantity's own message (`units::UnitError::message`): what is wrong; the fix.
        if let Some(i) = message.find(units::MARK) {
            let m = &message[i + units::MARK.len()..];
            let (what, fix) = m.split_once(units::FIX).unwrap_or((m, "write a number with its unit"));
            return (what.into(), fix.into());
        }
        let docs = "see `planardyn docs model-format`";
        if let Some(name) = message.strip_prefix("missing field `").and_then(|m| m.strip_suffix('`')) {
            push_field(field, name);
            return (format!("missing field `{name}`"), format!("add it ({docs})"));
        }
        // The name may hold a backtick itself: it ends at "`, expected" / "`, there are no fields".
        if let Some(name) = message.strip_prefix("unknown field `").and_then(|m| m.find("`, ").map(|i| &m[..i])) {
            // Inside a pair or a load (tagged by `type`) serde stops at the entry: name the field.
            if field.rsplit(['.', ']']).next() != Some(name) {
                push_field(field, name);
            }
            return (plain(message), "remove it or correct its spelling".into());
        }
        if message.starts_with("unknown variant") {
            return (plain(message), "use one of those".into());
        }
        if message.starts_with("duplicate field") {
            return (message.into(), "give it once".into());
        }
        if message.starts_with("duplicate name") {
            return (message.into(), "rename one of the two".into());
        }
        if message.starts_with("data did not match any variant of untagged enum Location") {
            return ("expected a point name or coordinates [x, y] (m)".into(), "give one of those".into());
        }
        if message.starts_with("invalid") {
            if field.is_empty() && message.ends_with("expected struct MechanismSpec") {
                let found = between(message, "invalid type: ", ", expected").unwrap_or("something else");
                return (
                    format!("the model is {found}, not a mapping"),
                    format!("a model file must be a mapping with the keys name, points, ground, bodies, pairs and coordinates: {docs}"),
                );
            }
            let message = plain(message);
            if let Some(explained) = number_literal(&message) {
                return explained;
            }
            return (message, format!("give the form the field takes: {docs}"));
        }
        let syntax = match self.format {
            Format::Yaml => "the text is not valid YAML: check the indentation, brackets, quotes and colons there",
            Format::Json => "the text is not valid JSON: check the brackets, quotes, commas and colons there (JSON has no NaN or Infinity)",
            // Data serialised as JSON is valid but for the NaN and infinities it writes as such.
            Format::Data => return ("not a finite number".into(), "give a finite number (NaN and infinities are not model values)".into()),
        };
        let fix = match message {
            "unknown anchor" => {
                "an alias `*name` needs an anchor `&name` before it: add the anchor or write the value out".into()
            }
            "recursion limit exceeded" => "the text nests too deeply: check the brackets".into(),
            "repetition limit exceeded" => "aliases `*name` expand to too much: write the values out".into(),
            "EOF while parsing a value" => format!("the text is empty: write a model ({docs})"),
            m if m.starts_with("deserializing from YAML containing more than one document") => {
                "remove the `---` separators: a model file holds one document".into()
            }
            _ => syntax.into(),
        };
        (message.into(), fix)
    }

    /// `line L column C` for an error no field can name: where the parser stopped, or the
    /// second document of a multi-document YAML text, or the start.
    fn line_column(&self, message: &str, at: LineColumn) -> String {
        let (line, column) = at.unwrap_or_else(|| {
            let second_document = message.contains("more than one document").then(|| {
                let starts =
                    self.text.lines().enumerate().filter(|(_, l)| l.starts_with("---") || l.starts_with("..."));
                let content = self.text.lines().position(|l| !l.trim().is_empty() && !l.starts_with('#')).unwrap_or(0);
                starts.map(|(i, _)| i).find(|&i| i > content)
            });
            (second_document.flatten().map_or(1, |i| i + 1), 1)
        });
        format!("line {line} column {}", column.max(1))
    }
}

/// The field path, `bodies.crank.mass`, `pairs[2].at`; up to an unknown segment (a key
/// that is not a string), empty at the top of the document.
pub(super) fn field_path(path: &Path) -> String {
    let mut out = String::new();
    for segment in path {
        match segment {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } | Segment::Enum { variant: key } => push_field(&mut out, key),
            Segment::Unknown => break,
        }
    }
    out
}

fn push_field(path: &mut String, name: &str) {
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(name);
}

/// A number field given a number the YAML parser reads but not as a number of the model: an
/// integer in another radix (YAML reads `0x10` as the integer 16, but a field of the model
/// takes decimal numbers only), or a number beyond the largest a double holds (read as text).
fn number_literal(message: &str) -> Option<(String, String)> {
    if let Some(n) = between(message, "invalid type: integer ", ", expected a number") {
        let n = n.trim_matches('`');
        return Some((
            format!("the integer {n} is written in hexadecimal, octal or binary (0x, 0o or 0b), which the model does not accept"),
            format!("write the decimal number {n}"),
        ));
    }
    let text = between(message, "invalid type: string \"", "\", expected a number")?;
    let huge = text.bytes().any(|b| b.is_ascii_digit()) && text.parse::<f64>().is_ok_and(f64::is_infinite);
    huge.then(|| {
        let shown = match text.char_indices().nth(20) {
            Some((i, _)) => format!("{}... ({} characters)", &text[..i], text.len()),
            None => text.to_string(),
        };
        (
            format!("the number {shown} is beyond the largest magnitude a number can have (about 1.8e308)"),
            "check the units (SI) and the digits, and write it with at most 17 significant digits, in exponent form if large (e.g. 1.5e12)".to_string(),
        )
    })
}

/// The text between `start` and the next `end` after it.
fn between<'a>(s: &'a str, start: &str, end: &str) -> Option<&'a str> {
    let rest = &s[s.find(start)? + start.len()..];
    Some(&rest[..rest.find(end)?])
}

/// The message without the parsers' " at line L column C" / " at position N" marks (the
/// location is given once, in the path or after the message).
fn strip_marks(message: &str) -> String {
    let mut out = message.to_string();
    for mark in [" at line ", " at position "] {
        while let Some(i) = out.find(mark) {
            let rest = &out[i + mark.len()..];
            let digits = |s: &str| s.len() - s.trim_start_matches(|c: char| c.is_ascii_digit()).len();
            let mut n = digits(rest);
            if n == 0 {
                break;
            }
            if let Some(col) = rest[n..].strip_prefix(" column ") {
                n += " column ".len() + digits(col);
            }
            out.replace_range(i..i + mark.len() + n, "");
        }
    }
    out
}

/// serde's Rust type names in what a user writes.
fn plain(message: &str) -> String {
    const WORDS: &[(&str, &str)] = &[
        ("struct MechanismSpec", "a model (a mapping: name, points, ground, bodies, pairs, coordinates)"),
        ("struct BodySpec", "a body (a mapping: points, mass...)"),
        ("struct PartSpec", "a part (a mapping: mass, and com, uniform_bar or point_mass)"),
        ("struct CoordinateSpec", "a coordinate (a mapping: name, pair, value)"),
        ("struct DriveSpec", "a drive (a mapping: coordinate, and effort, table or motion)"),
        ("struct TableSpec", "a table (a mapping: t, effort)"),
        ("struct MotionSpec", "a motion (a mapping: speed or table)"),
        ("struct MotionTableSpec", "a motion table (a mapping: t, q)"),
        ("struct SimulateSpec", "simulation settings (a mapping: t_end, method...)"),
        ("internally tagged enum PairSpec", "a pair (a mapping with type: revolute or prismatic)"),
        ("struct ActuatorSpec", "an actuator (a mapping: coordinate or pair, gear_ratio, limits...)"),
        ("struct LimitsSpec", "actuator limits (a mapping: peak_torque, continuous_torque, max_speed...)"),
        ("struct ComplianceSpec", "a compliance section (a mapping: drives, pairs, links)"),
        ("struct DriveComplianceSpec", "an elastic drive (a mapping: actuator, stiffness, damping, side)"),
        ("struct PairComplianceSpec", "an elastic pair (a mapping: pair, stiffness, damping)"),
        ("struct LinkComplianceSpec", "an elastic link (a mapping: body, EA and EI, or E and section)"),
        ("struct SectionSpec", "a section (a mapping: area and second_moment, or rectangle)"),
        ("a map from names to entries", "a mapping from names to entries"),
        ("sequence", "list"),
        ("an array of length 2", "a list of 2 items"),
        ("f64", "a number"),
        ("field identifier", "a field name"),
    ];
    let mut out = WORDS.iter().fold(message.to_string(), |m, (rust, words)| m.replace(rust, words));
    if out.contains("internally tagged enum LoadSpec") {
        let [kinds @ .., last] = LoadSpec::NAMES;
        let load = format!("a load (a mapping with type: {} or {last})", kinds.join(", "));
        out = out.replace("internally tagged enum LoadSpec", &load);
    }
    // A pair or load written as a list: "expected struct variant PairSpec::Revolute with 3 elements".
    while let Some(i) = out.find("struct variant ") {
        let end = out[i..].find(" elements").map_or(out.len(), |j| i + j + " elements".len());
        out.replace_range(i..end, "a mapping with the fields of its `type`");
    }
    // Any other part of the model that serde names by its Rust type (`struct ...Spec`): a
    // mapping. Other text (a user's string holding "struct ") is left as written.
    let mut from = 0;
    while let Some(i) = out[from..].find("struct ").map(|i| from + i) {
        let name = out[i + "struct ".len()..].split(|c: char| !c.is_alphanumeric()).next().unwrap_or("");
        let end = i + "struct ".len() + name.len();
        if name.ends_with("Spec") {
            out.replace_range(i..end, "a mapping");
            from = i + "a mapping".len();
        } else {
            from = end;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_are_stripped_wherever_they_are() {
        assert_eq!(
            strip_marks(
                "did not find expected key at line 3 column 5, while parsing a block mapping at line 1 column 1"
            ),
            "did not find expected key, while parsing a block mapping"
        );
        assert_eq!(strip_marks("found unexpected end of stream at position 12"), "found unexpected end of stream");
        assert_eq!(strip_marks("expected value at line 1 column 0"), "expected value");
        assert_eq!(strip_marks("the line at line x"), "the line at line x");
    }

    #[test]
    fn every_part_of_a_model_is_named_in_plain_words() {
        // the actuator's was missing (found by fuzz_loader's structural mutations of
        // five-bar-robot.yaml); a struct not in the list still reads as a mapping
        assert_eq!(
            plain("invalid type: string \"ground\", expected struct ActuatorSpec"),
            "invalid type: string \"ground\", expected an actuator (a mapping: coordinate or pair, gear_ratio, limits...)"
        );
        assert_eq!(
            plain("invalid type: integer `1`, expected struct FutureSpec"),
            "invalid type: integer `1`, expected a mapping"
        );
    }

    #[test]
    fn rust_names_become_plain_words() {
        assert_eq!(plain("invalid type: string \"a\", expected f64"), "invalid type: string \"a\", expected a number");
        assert_eq!(
            plain("invalid length 3, expected an array of length 2"),
            "invalid length 3, expected a list of 2 items"
        );
        assert_eq!(
            plain("invalid length 1, expected struct variant PairSpec::Revolute with 3 elements"),
            "invalid length 1, expected a mapping with the fields of its `type`"
        );
        // The load kinds by name, from `LoadSpec::NAMES`.
        assert_eq!(
            plain("invalid type: integer `5`, expected internally tagged enum LoadSpec"),
            "invalid type: integer `5`, expected a load (a mapping with type: force, torque, spring, \
             torsional_spring or friction)"
        );
    }
}
