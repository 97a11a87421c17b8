//! Points and coordinate values a model file gives by construction, as a draughtsman draws
//! them: from a point at a length and an angle, where two circles meet, along a line, where
//! a line meets a circle; and a coordinate's drawn value as a measure of the drawing (the
//! angle or the distance between two points). Lengths and angles take units
//! ([`crate::units`]). [`super::construct`] resolves them into coordinates when a file is
//! read: a [`MechanismSpec`](super::MechanismSpec) then holds coordinates only.

use crate::units::{self, Motion, Quantity};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;

/// A point of a model file: coordinates [x, y] (m), or a construction.
#[derive(Debug, Clone, PartialEq)]
pub enum PointSpec {
    At([f64; 2]),
    By(Construction),
}

/// How a point is drawn from others (lengths in m, angles in rad).
#[derive(Debug, Clone, PartialEq)]
pub enum Construction {
    /// `{from: A, length: L, angle: a}`: A + L (cos a, sin a), the angle counter-clockwise
    /// from the x axis, or from the direction P -> Q with `relative_to: [P, Q]`.
    Polar { from: String, length: f64, angle: f64, relative_to: Option<[String; 2]> },
    /// `{circles: [[A, r_A], [B, r_B]], side: left|right}`: the point at r_A from A and r_B
    /// from B, on the given side of the directed line from A to B.
    Circles { circles: [Circle; 2], side: Side },
    /// `{along: [A, B], distance: d}`: A + d (B - A)/|B - A|; or `fraction: f`: A + f (B - A).
    Along { along: [String; 2], distance: Option<f64>, fraction: Option<f64> },
    /// `{line: [P, Q], circle: [C, r], crossing: first|second}`: where the line through P and
    /// Q meets the circle of radius r about C, the first or the second crossing going from P
    /// towards Q.
    LineCircle { line: [String; 2], circle: Circle, crossing: Crossing },
}

/// A circle of a construction: its centre (a point) and its radius (m).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Circle(pub String, #[serde(deserialize_with = "units::length")] pub f64);

/// The side of the directed line from the first centre to the second: left is the
/// counter-clockwise side (positive cross product (B - A) x (P - A), the drawing's y axis up).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    Left,
    Right,
}

/// Which crossing of a line with a circle, going along the line from its first point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Crossing {
    First,
    Second,
}

/// A coordinate's drawn value in a model file: a number (rad or m, or with its unit), or a
/// measure of the drawing.
#[derive(Debug, Clone, PartialEq)]
pub enum ValueSpec {
    /// A number (SI), and whether its unit, if one was written, is an angle's or a length's
    /// (checked against the pair: `"30 mm"` is no value of a revolute pair).
    Number(f64, Option<Motion>),
    /// `{angle: [P, Q]}`: the angle of the line P -> Q from the x axis (rad, in (-pi, pi]).
    Angle([String; 2]),
    /// `{distance: [P, Q]}`: |PQ| (m).
    Distance([String; 2]),
}

/// The fields of a construction as a file writes them, before its form is told.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Fields {
    from: Option<String>,
    #[serde(default, deserialize_with = "units::length")]
    length: Option<f64>,
    #[serde(default, deserialize_with = "units::angle")]
    angle: Option<f64>,
    relative_to: Option<[String; 2]>,
    circles: Option<[Circle; 2]>,
    side: Option<Side>,
    along: Option<[String; 2]>,
    #[serde(default, deserialize_with = "units::length")]
    distance: Option<f64>,
    fraction: Option<f64>,
    line: Option<[String; 2]>,
    circle: Option<Circle>,
    crossing: Option<Crossing>,
}

/// The forms of a construction, for messages.
pub const FORMS: &str = "{from: A, length: L, angle: a} (optionally relative_to: [P, Q]), \
     {circles: [[A, r_A], [B, r_B]], side: left|right}, {along: [A, B], distance: d} or {along: [A, B], fraction: f}, \
     {line: [P, Q], circle: [C, r], crossing: first|second}";

impl Fields {
    fn construction<E: de::Error>(self) -> Result<Construction, E> {
        let Fields {
            from,
            length,
            angle,
            relative_to,
            circles,
            side,
            along,
            distance,
            fraction,
            line,
            circle,
            crossing,
        } = self;
        // Which forms the fields given belong to.
        let forms = [
            from.is_some() || length.is_some() || angle.is_some() || relative_to.is_some(),
            circles.is_some() || side.is_some(),
            along.is_some() || distance.is_some() || fraction.is_some(),
            line.is_some() || circle.is_some() || crossing.is_some(),
        ];
        let missing = |form: &str, what: &str| E::custom(format!("{form} needs {what}; the forms are {FORMS}"));
        match forms {
            [true, false, false, false] => match (from, length, angle) {
                (Some(from), Some(length), Some(angle)) => Ok(Construction::Polar { from, length, angle, relative_to }),
                _ => Err(missing("a point from a point at a length and an angle", "from, length and angle")),
            },
            [false, true, false, false] => match (circles, side) {
                (Some(circles), Some(side)) => Ok(Construction::Circles { circles, side }),
                (None, _) => Err(missing("a point where two circles meet", "circles: [[A, r_A], [B, r_B]]")),
                (Some(_), None) => Err(missing(
                    "a point where two circles meet",
                    "the side it lies on, side: left or right (of the line from the first centre to the second)",
                )),
            },
            [false, false, true, false] => match (along, distance.is_some() != fraction.is_some()) {
                (Some(along), true) => Ok(Construction::Along { along, distance, fraction }),
                _ => Err(missing("a point along a line", "along: [A, B] and one of distance and fraction")),
            },
            [false, false, false, true] => match (line, circle, crossing) {
                (Some(line), Some(circle), Some(crossing)) => Ok(Construction::LineCircle { line, circle, crossing }),
                _ => Err(missing(
                    "a point where a line meets a circle",
                    "line: [P, Q], circle: [C, r] and crossing: first or second (going from P towards Q)",
                )),
            },
            _ => Err(E::custom(format!("a point is given by one construction; the forms are {FORMS}"))),
        }
    }
}

impl<'de> Deserialize<'de> for PointSpec {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct PointVisitor;
        impl<'de> Visitor<'de> for PointVisitor {
            type Value = PointSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "coordinates [x, y] (m) or a construction: {FORMS}")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<PointSpec, A::Error> {
                let xy: [f64; 2] = units::length(de::value::SeqAccessDeserializer::new(seq))?;
                Ok(PointSpec::At(xy))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<PointSpec, A::Error> {
                let fields = Fields::deserialize(de::value::MapAccessDeserializer::new(map))?;
                fields.construction().map(PointSpec::By)
            }
        }
        deserializer.deserialize_any(PointVisitor)
    }
}

impl<'de> Deserialize<'de> for ValueSpec {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Measure {
            angle: Option<[String; 2]>,
            distance: Option<[String; 2]>,
        }
        struct ValueVisitor;
        impl<'de> Visitor<'de> for ValueVisitor {
            type Value = ValueSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number (rad or m), a number with a unit (\"30 deg\", \"120 mm\"), or a measure of the drawing: {angle: [P, Q]} or {distance: [P, Q]}")
            }
            fn visit_f64<E>(self, v: f64) -> Result<ValueSpec, E> {
                Ok(ValueSpec::Number(v, None))
            }
            fn visit_i64<E>(self, v: i64) -> Result<ValueSpec, E> {
                Ok(ValueSpec::Number(v as f64, None))
            }
            fn visit_u64<E>(self, v: u64) -> Result<ValueSpec, E> {
                Ok(ValueSpec::Number(v as f64, None))
            }
            fn visit_str<E: de::Error>(self, text: &str) -> Result<ValueSpec, E> {
                let si: f64 = units::position(de::value::StrDeserializer::<E>::new(text))?;
                // The kind of the unit written (Position's kinds: an angle, then a length).
                let motion = units::read(text, units::Position::KINDS).ok().and_then(|r| r.kind).map(|k| {
                    if k == 0 {
                        Motion::Rotation
                    } else {
                        Motion::Translation
                    }
                });
                Ok(ValueSpec::Number(si, motion))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ValueSpec, A::Error> {
                match Measure::deserialize(de::value::MapAccessDeserializer::new(map))? {
                    Measure { angle: Some(p), distance: None } => Ok(ValueSpec::Angle(p)),
                    Measure { angle: None, distance: Some(p) } => Ok(ValueSpec::Distance(p)),
                    _ => Err(de::Error::custom(
                        "a measure of the drawing is one of {angle: [P, Q]} (rad) and {distance: [P, Q]} (m)",
                    )),
                }
            }
        }
        deserializer.deserialize_any(ValueVisitor)
    }
}
