//! The model file: a mechanism described as it is drawn (YAML or JSON, one schema).
//!
//! These plain structs are what a file deserialises to and what a Rust user fills in to
//! describe a mechanism in code; [`crate::build`] validates them. The schema is
//! documented field by field in `docs/model-format.md` and `schema/planardyn-model.schema.json`.
//! Units are SI throughout: m, kg, kg m^2, s, rad, N, N m. A file may give a quantity as a
//! number with its unit (`"120 mm"`, `"30 deg"`: the fields' `deserialize_with` read them,
//! [`crate::units`]), and points and coordinate values by construction
//! ([`MechanismSpec<PointSpec, ValueSpec>`], the form the loader reads and resolves into
//! this one).

pub use super::compliance::ComplianceSpec;
pub use super::construction::{Circle, Construction, Crossing, PointSpec, Side, ValueSpec};
pub use super::loads::LoadSpec;
use crate::units::{self, Motion};
use indexmap::IndexMap;
use serde::de::{Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::marker::PhantomData;

/// The other names a file may give a field by (the `alias`es below): (field, alias), for
/// locating a field's error in the text (`loader::locate`).
pub const FIELD_ALIASES: &[(&str, &str)] = &[
    ("points", "points_at_t0"),
    ("ground", "fixed_points"),
    ("inertia", "inertia_about_com"),
    ("about", "role"),
    ("point_mass", "point_mass_at"),
];

/// A whole mechanism: its points coordinates [x, y] (m) and its coordinates' drawn values
/// numbers (rad or m). `MechanismSpec<PointSpec, ValueSpec>` is a model file as written,
/// points and values also by construction, which the loader resolves into this.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MechanismSpec<P = [f64; 2], V = f64> {
    /// A human-readable name.
    pub name: String,
    /// Free text: where the data come from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub about: Option<String>,
    /// Only "SI" is accepted (m, kg, s, rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<String>,
    /// Gravity vector [g_x, g_y] in m/s^2 (default none).
    #[serde(default, deserialize_with = "units::acceleration")]
    pub gravity: [f64; 2],
    /// Named points and their global coordinates [x, y] (m) in the drawn configuration.
    #[serde(alias = "points_at_t0")]
    pub points: NamedMap<P>,
    /// The points carried by the fixed body `ground`.
    #[serde(default, alias = "fixed_points")]
    pub ground: Vec<String>,
    /// The mobile bodies, by name, in the order their coordinates are stored.
    pub bodies: NamedMap<BodySpec>,
    /// Kinematic pairs (joints).
    #[serde(deserialize_with = "units::tagged")]
    pub pairs: Vec<PairSpec>,
    /// Generalized coordinates: the input pairs, one per degree of freedom.
    pub coordinates: Vec<CoordinateSpec<V>>,
    /// Drive efforts on the coordinates (torque for an angle, force for a displacement).
    #[serde(default)]
    pub drives: Vec<DriveSpec>,
    /// External loads and force elements (one kind a file: `model::loads`).
    #[serde(default, deserialize_with = "units::tagged")]
    pub loads: Vec<LoadSpec>,
    /// Motors with their transmissions, one per driven coordinate (docs/actuators.md).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub actuators: Vec<ActuatorSpec>,
    /// Transmission, pair and link compliances (`model::compliance`, docs/stiffness.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compliance: Option<ComplianceSpec>,
    /// Default simulation settings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulate: Option<SimulateSpec>,
}

/// A mobile body. Its inertia is given either directly (`mass`, `inertia`, `com`), as a
/// uniform bar, or as a list of `parts` that are summed (a point mass is a part).
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// The points this body carries. The body's angle is that of the line from its first to
    /// its second point (0 for a body with a single point).
    pub points: Vec<String>,
    #[serde(default, deserialize_with = "units::mass", skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// Moment of inertia about the centre of mass (kg m^2).
    #[serde(
        default,
        alias = "inertia_about_com",
        deserialize_with = "units::inertia",
        skip_serializing_if = "Option::is_none"
    )]
    pub inertia: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com: Option<Location>,
    /// Mass spread uniformly along the segment between two points: centre of mass at the
    /// midpoint, inertia m L^2 / 12.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uniform_bar: Option<[String; 2]>,
    /// Parts summed with the parallel-axis theorem.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub parts: Option<Vec<PartSpec>>,
    /// Free text.
    #[serde(default, alias = "role", skip_serializing_if = "Option::is_none")]
    pub about: Option<String>,
}

/// One part of a body: a general rigid part, a uniform bar or a point mass.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PartSpec {
    #[serde(deserialize_with = "units::mass")]
    pub mass: f64,
    #[serde(
        default,
        alias = "inertia_about_com",
        deserialize_with = "units::inertia",
        skip_serializing_if = "Option::is_none"
    )]
    pub inertia: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com: Option<Location>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uniform_bar: Option<[String; 2]>,
    #[serde(default, alias = "point_mass_at", skip_serializing_if = "Option::is_none")]
    pub point_mass: Option<String>,
}

/// A location in the drawing: coordinates [x, y] (m) or the name of a point.
#[derive(Debug, Clone, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Location {
    Coords([f64; 2]),
    Point(String),
}

impl<'de> Deserialize<'de> for Location {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct LocationVisitor;
        impl<'de> Visitor<'de> for LocationVisitor {
            type Value = Location;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a point name or coordinates [x, y] (m)")
            }
            fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<Location, E> {
                Ok(Location::Point(name.to_string()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Location, A::Error> {
                units::length(serde::de::value::SeqAccessDeserializer::new(seq)).map(Location::Coords)
            }
        }
        deserializer.deserialize_any(LocationVisitor)
    }
}

/// A kinematic pair between two bodies (`ground` is the fixed body).
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum PairSpec {
    /// Revolute pair (hinge) at a point both bodies carry.
    Revolute {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        at: String,
        bodies: [String; 2],
    },
    /// Prismatic pair (slider): the second body translates along a guide fixed to the first,
    /// through a point both carry, without relative rotation. The guide direction is `axis`
    /// [d_x, d_y] in the drawing, or the line `along` [from, to] between two points.
    Prismatic {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        at: String,
        bodies: [String; 2],
        #[serde(default, skip_serializing_if = "Option::is_none")]
        axis: Option<[f64; 2]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        along: Option<[String; 2]>,
    },
    /// Gear pair: the pitch circles of a's and b's gears roll on each other without slip
    /// (one constraint row). The gears are centred at `centers` [A, B], points fixed in the
    /// `carrier` (default `ground`), with pitch radii `radii` [r_a, r_b]; `internal: true`
    /// for a pinion meshing inside a ring gear. A rack and pinion: `rack: [P, Q]`, b's pitch
    /// line through two of its points, with `centers: [A]` and `radii: [r_a]`.
    Gear {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        bodies: [String; 2],
        centers: Vec<String>,
        #[serde(deserialize_with = "units::length")]
        radii: Vec<f64>,
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        internal: bool,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        carrier: Option<String>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rack: Option<[String; 2]>,
    },
    /// Pin-in-slot pair: the second body's pin `at` slides along a slot fixed to the first
    /// and turns freely (one constraint row). The slot's direction is `axis` [d_x, d_y] in
    /// the drawing, or the line `along` [from, to] between two points (then also its drawn
    /// extent).
    Slot {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        at: String,
        bodies: [String; 2],
        #[serde(default, skip_serializing_if = "Option::is_none")]
        axis: Option<[f64; 2]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        along: Option<[String; 2]>,
    },
}

impl PairSpec {
    /// The name the file gave the pair, if any.
    pub fn name(&self) -> Option<&str> {
        match self {
            PairSpec::Revolute { name, .. }
            | PairSpec::Prismatic { name, .. }
            | PairSpec::Gear { name, .. }
            | PairSpec::Slot { name, .. } => name.as_deref(),
        }
    }

    /// Whether the pair's coordinate is an angle or a displacement (a gear pair has none).
    pub fn motion(&self) -> Option<Motion> {
        match self {
            PairSpec::Revolute { .. } => Some(Motion::Rotation),
            PairSpec::Prismatic { .. } | PairSpec::Slot { .. } => Some(Motion::Translation),
            PairSpec::Gear { .. } => None,
        }
    }
}

/// A generalized coordinate: the relative angle (rad) of a revolute pair or the displacement
/// (m) of a prismatic or slot pair, of the second body relative to the first (a gear pair
/// has none).
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CoordinateSpec<V = f64> {
    pub name: String,
    /// The name of the input pair.
    pub pair: String,
    /// The coordinate's value in the drawing (e.g. the absolute angle of a crank line).
    pub value: V,
    /// Start the simulation here instead of at the drawing (as `value`: a number, with its unit,
    /// or a measure of the drawing in a file).
    #[serde(default = "Option::default", skip_serializing_if = "Option::is_none")]
    pub q0: Option<V>,
    /// Initial rate (rad/s or m/s), default 0.
    #[serde(default, deserialize_with = "units::rate")]
    pub qd0: f64,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub about: Option<String>,
}

/// A drive on one coordinate: an effort (a constant, or a time table interpolated linearly,
/// held at its end values outside the table), or a motion the coordinate is made to follow.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    pub coordinate: String,
    #[serde(default, deserialize_with = "units::effort", skip_serializing_if = "Option::is_none")]
    pub effort: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<TableSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionSpec>,
}

/// A prescribed motion: a constant rate from the start value (rad/s or m/s), or a table of
/// times (s) and positions (rad or m) through which a C2 cubic spline runs.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    #[serde(default, deserialize_with = "units::rate", skip_serializing_if = "Option::is_none")]
    pub speed: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<MotionTableSpec>,
}

/// A motion table: times (s, increasing) and positions (rad or m), of equal length.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MotionTableSpec {
    #[serde(deserialize_with = "units::time")]
    pub t: Vec<f64>,
    #[serde(deserialize_with = "units::position")]
    pub q: Vec<f64>,
}

/// A time table: times (s, increasing) and efforts (N m or N), of equal length.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    #[serde(deserialize_with = "units::time")]
    pub t: Vec<f64>,
    #[serde(deserialize_with = "units::effort")]
    pub effort: Vec<f64>,
}

/// A motor driving a coordinate through a transmission of ratio n (motor angle = n q): the
/// file's drive effort on that coordinate is then the motor torque (N m, motor side). Or a
/// redundant actuator on a pair (`pair`), without transmission.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSpec {
    /// The driven coordinate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
    /// Or a driven pair that is not a coordinate's: a redundant actuator (more actuators
    /// than degrees of freedom), an ideal effort source on the pair's relative coordinate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pair: Option<String>,
    /// A name for reports (default: the coordinate's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Transmission ratio n (motor rad per coordinate rad, or per metre of a displacement).
    #[serde(default = "one")]
    pub gear_ratio: f64,
    /// Transmission efficiency eta in (0, 1], while motoring.
    #[serde(default = "one")]
    pub efficiency: f64,
    /// Back-drive efficiency eta_b in [0, 1], while the load drives the motor (default eta;
    /// 0: self-locking, the gear holds the load).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backdrive_efficiency: Option<f64>,
    /// Rotor (and gearbox input) inertia J (kg m^2, motor side), before the gear: its
    /// kinetic energy 1/2 J (omega_housing + n qd)^2.
    #[serde(default, deserialize_with = "units::inertia")]
    pub rotor_inertia: f64,
    /// Motor-side viscous friction (N m s/rad).
    #[serde(default, deserialize_with = "units::torsional_damping")]
    pub viscous: f64,
    /// Motor-side Coulomb friction torque (N m).
    #[serde(default, deserialize_with = "units::torque")]
    pub coulomb: f64,
    /// Motor speed (rad/s) below which the regularised Coulomb torque fades (default 1e-2).
    #[serde(default, deserialize_with = "units::angular_speed", skip_serializing_if = "Option::is_none")]
    pub stiction_speed: Option<f64>,
    /// The motor's limits, for the sizing report.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<LimitsSpec>,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub about: Option<String>,
}

fn one() -> f64 {
    1.0
}

/// A motor's limits, motor side: torques (N m), speeds (rad/s). The torque available at a
/// speed is `torque_speed` interpolated linearly, or the peak torque up to `corner_speed`
/// falling linearly to zero at `max_speed`, or the peak torque.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    #[serde(default, deserialize_with = "units::torque", skip_serializing_if = "Option::is_none")]
    pub peak_torque: Option<f64>,
    /// The RMS torque the motor carries without overheating.
    #[serde(default, deserialize_with = "units::torque", skip_serializing_if = "Option::is_none")]
    pub continuous_torque: Option<f64>,
    #[serde(default, deserialize_with = "units::angular_speed", skip_serializing_if = "Option::is_none")]
    pub max_speed: Option<f64>,
    #[serde(default, deserialize_with = "units::angular_speed", skip_serializing_if = "Option::is_none")]
    pub corner_speed: Option<f64>,
    /// Points [speed, torque] of the envelope, speeds increasing from 0.
    #[serde(default, deserialize_with = "units::speed_torque", skip_serializing_if = "Option::is_none")]
    pub torque_speed: Option<Vec<[f64; 2]>>,
}

/// Default settings for `simulate`.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SimulateSpec {
    #[serde(default, deserialize_with = "units::time", skip_serializing_if = "Option::is_none")]
    pub t_end: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    /// Step of the fixed-step method (s).
    #[serde(default, deserialize_with = "units::time", skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    /// Spacing of the output times (s); default: every accepted step.
    #[serde(default, deserialize_with = "units::time", skip_serializing_if = "Option::is_none")]
    pub output_dt: Option<f64>,
}

/// An ordered map from names to values that rejects a name given twice
/// (serde's maps silently keep the last one).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct NamedMap<T>(pub IndexMap<String, T>);

impl<T> Default for NamedMap<T> {
    fn default() -> Self {
        NamedMap(IndexMap::new())
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for NamedMap<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct MapVisitor<T>(PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for MapVisitor<T> {
            type Value = NamedMap<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a map from names to entries")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut out = IndexMap::new();
                while let Some(key) = map.next_key::<String>()? {
                    if out.contains_key(&key) {
                        return Err(serde::de::Error::custom(format!(
                            "duplicate name '{key}': every name must be unique"
                        )));
                    }
                    let value = map.next_value()?;
                    out.insert(key, value);
                }
                Ok(NamedMap(out))
            }
        }
        deserializer.deserialize_map(MapVisitor(PhantomData))
    }
}
