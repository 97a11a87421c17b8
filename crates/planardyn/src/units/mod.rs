//! Units of the model file: a number with its unit as a string (`"120 mm"`, `"30 deg"`,
//! `"3000 rpm"`) wherever a model file takes a dimensional quantity, converted to SI when the
//! file is read; a bare number is SI, as ever. Everything past the loader is SI.
//!
//! Why hand-written: `uom` types every quantity at compile time (dozens of generic parameters
//! for what is, here, a lookup of a factor by a unit's name when a file is read), and its
//! parser knows only its own unit abbreviations; `dimensioned` and `measurements` likewise
//! model arithmetic, not parsing. A model file needs a table per quantity kind, an error
//! that lists the units accepted, and the same table in the JSON Schema (`schema/`, checked
//! against [`KINDS`] by `tests/units_schema.rs`).

mod de;
mod table;

pub use de::*;
pub use table::*;

/// The kind of a quantity: its name, its SI unit and the units a file may write for it,
/// each with the SI value of one of it.
#[derive(Debug, PartialEq)]
pub struct Kind {
    /// What the quantity is, in messages ("a length").
    pub name: &'static str,
    /// Its name in the JSON Schema's `$defs` (`length`).
    pub key: &'static str,
    /// The SI unit a bare number is in ("m").
    pub si: &'static str,
    /// Each unit's spellings (the first in messages) and the SI value of one of it.
    pub units: &'static [(&'static [&'static str], f64)],
}

/// Whether a pair's coordinate turns or slides: which of a pair quantity's two kinds applies
/// (an angle or a length, a torque or a force...).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    Rotation,
    Translation,
}

/// What a field of a model file holds: one kind, or the two kinds of a pair's motion
/// (rotation first, translation second), which the pair decides (a coordinate's drawn value
/// is checked against its pair, `model::construct`; the other pair quantities take either).
pub trait Quantity {
    const KINDS: &'static [&'static Kind];
}

/// A quantity read from text: its value in SI and, when a unit was written, the kind it is
/// a unit of (an index into the field's [`Quantity::KINDS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    pub si: f64,
    pub kind: Option<usize>,
}

/// Why a text is not a quantity of a field.
#[derive(Debug, Clone, PartialEq)]
pub enum UnitError {
    /// No number at the start.
    NoNumber,
    /// A number alone that a double cannot hold (the parsers' own message explains it).
    Overflow,
    /// A unit not in the field's kinds' tables.
    Unknown { unit: String },
}

/// A number, optionally followed by a unit of one of `kinds` (spaces around and between are
/// free: `"120 mm"`, `"120mm"`, `" -1.5e-3 m "`).
pub fn read(text: &str, kinds: &[&Kind]) -> Result<Reading, UnitError> {
    let text = text.trim();
    let split = number_prefix(text).ok_or(UnitError::NoNumber)?;
    let (number, unit) = (&text[..split], text[split..].trim());
    let value: f64 = number.parse().map_err(|_| UnitError::NoNumber)?;
    if unit.is_empty() {
        return if value.is_finite() { Ok(Reading { si: value, kind: None }) } else { Err(UnitError::Overflow) };
    }
    let unit = normalise(unit);
    for (k, kind) in kinds.iter().enumerate() {
        if let Some(factor) = kind.factor(&unit) {
            return Ok(Reading { si: value * factor, kind: Some(k) });
        }
    }
    Err(UnitError::Unknown { unit })
}

impl Kind {
    /// The SI value of one `unit` (a spelling of the table, spaces normalised).
    pub fn factor(&self, unit: &str) -> Option<f64> {
        self.units.iter().find(|(names, _)| names.contains(&unit)).map(|&(_, f)| f)
    }

    /// The units' first spellings, as a message lists them: "m, cm, mm, um, in, ft".
    pub fn unit_list(&self) -> String {
        self.units.iter().map(|(names, _)| names[0]).collect::<Vec<_>>().join(", ")
    }
}

impl UnitError {
    /// What is wrong with `text` in a field of `kinds`, and the fix (the units accepted).
    pub fn message(&self, text: &str, kinds: &[&Kind]) -> (String, String) {
        let accepted = kinds
            .iter()
            .map(|k| format!("{} ({}, or a number alone in {})", k.name, k.unit_list(), k.si))
            .collect::<Vec<_>>()
            .join(" or ");
        let fix = format!("write e.g. \"{}\"", example(kinds[0]));
        match self {
            UnitError::NoNumber | UnitError::Overflow => {
                (format!("\"{text}\" is not a number with a unit; this field takes {accepted}"), fix)
            }
            UnitError::Unknown { unit } => {
                let other = KINDS.iter().find(|k| k.factor(unit).is_some() && !kinds.contains(k));
                let is = other.map_or(String::new(), |k| format!(" ('{unit}' is a unit of {})", k.name));
                (format!("\"{text}\": '{unit}' is not a unit of {accepted}{is}"), fix)
            }
        }
    }
}

/// An example of a quantity with a unit of `kind`, for messages: "30 deg".
fn example(kind: &Kind) -> String {
    let unit = kind.units.get(1).unwrap_or(&kind.units[0]).0[0];
    format!("30 {unit}")
}

/// A unit as the table spells it: white space, `*`, `·` and `⋅` between factors become one
/// space, none beside a `/`; `²` is `^2`, `µ` and `μ` are `u`, `°` is `deg`.
fn normalise(unit: &str) -> String {
    let unit = unit.replace(['*', '·', '⋅'], " ").replace('²', "^2").replace(['µ', 'μ'], "u").replace('°', "deg");
    unit.split_whitespace().collect::<Vec<_>>().join(" ").replace(" /", "/").replace("/ ", "/")
}

/// The length of the decimal number at the start of `text` (sign, digits, point, exponent),
/// the grammar of the JSON Schema's patterns; None without a digit.
fn number_prefix(text: &str) -> Option<usize> {
    let b = text.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let int_end = digits(i);
    let mut end = int_end;
    if b.get(end) == Some(&b'.') {
        end = digits(end + 1);
    }
    // At least one digit before or after the point.
    if end - i <= usize::from(end > int_end) {
        return None;
    }
    i = end;
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let j = i + 1 + usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let k = digits(j);
        if k > j {
            end = k;
        }
    }
    Some(end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_at_the_start_are_split_off() {
        for (text, n) in [("120 mm", 3), ("-1.5e-3m", 7), (".5 in", 2), ("5. in", 2), ("+2kg", 2), ("1e", 1)] {
            assert_eq!(number_prefix(text), Some(n), "{text}");
        }
        for text in ["mm", ".", "-", "e3", ""] {
            assert_eq!(number_prefix(text), None, "{text}");
        }
    }
}
