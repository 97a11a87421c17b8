//! Quantities in serde: the functions a model's field names in `deserialize_with` (its type
//! stays a plain SI `f64`), reading a number or a string with a unit of the field's kind.

use super::{read, Quantity, UnitError};
use super::{AngularSpeed, Torque};
use serde::de::{self, Deserialize, Deserializer, Unexpected, Visitor};
use std::cell::Cell;
use std::fmt;
use std::marker::PhantomData;

/// Starts the message of a text that is not a quantity of its field, to tell it from the
/// parsers' own errors (`loader::parse_errors` takes it off), and parts its fix from it.
pub const MARK: &str = "quantity: ";
pub const FIX: &str = " / fix: ";

thread_local! {
    static YAML_SCALARS: Cell<bool> = const { Cell::new(false) };
}

/// Run `f`, a deserialisation of YAML, with each quantity read from its scalar's text. serde
/// gives a type no access to the format, and YAML's `deserialize_any` reads `0x10` as the
/// integer 16, which a field of the model refuses (it takes decimal numbers only, as ever):
/// the text tells them apart. (JSON has no such forms, and there `deserialize_any` gives
/// numbers and strings as they are.)
pub fn reading_yaml<T>(f: impl FnOnce() -> T) -> T {
    let _restore = Restore(YAML_SCALARS.replace(true));
    f()
}

/// Puts the thread's YAML switch back as it was, also on unwinding.
struct Restore(bool);

impl Drop for Restore {
    fn drop(&mut self) {
        YAML_SCALARS.set(self.0);
    }
}

/// `deserialize_with` of a list of entries tagged by their `type` (pairs, loads): serde
/// buffers each entry to read its tag first, and the buffer holds the YAML parser's numbers,
/// not its scalars' text, so the entries are read as JSON is (a hexadecimal integer there
/// is the integer, as it was before units).
pub fn tagged<'de, D: Deserializer<'de>, T: Deserialize<'de>>(deserializer: D) -> Result<T, D::Error> {
    let _restore = Restore(YAML_SCALARS.replace(false));
    T::deserialize(deserializer)
}

/// A quantity of kind Q read from a model file, in SI.
struct Si<Q>(f64, PhantomData<Q>);

impl<'de, Q: Quantity> Deserialize<'de> for Si<Q> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let visitor = SiVisitor::<Q>(PhantomData);
        let si = if YAML_SCALARS.get() {
            deserializer.deserialize_str(visitor)
        } else {
            deserializer.deserialize_any(visitor)
        }?;
        Ok(Si(si, PhantomData))
    }
}

struct SiVisitor<Q>(PhantomData<Q>);

impl<'de, Q: Quantity> Visitor<'de> for SiVisitor<Q> {
    type Value = f64;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a number ({}) or a number with a unit (\"{}\")", Q::KINDS[0].si, super::example(Q::KINDS[0]))
    }
    fn visit_f64<E>(self, v: f64) -> Result<f64, E> {
        Ok(v)
    }
    fn visit_i64<E>(self, v: i64) -> Result<f64, E> {
        Ok(v as f64)
    }
    fn visit_u64<E>(self, v: u64) -> Result<f64, E> {
        Ok(v as f64)
    }
    fn visit_str<E: de::Error>(self, text: &str) -> Result<f64, E> {
        if YAML_SCALARS.get() {
            if let Some(v) = yaml_special(text, &self)? {
                return Ok(v);
            }
        }
        match read(text, Q::KINDS) {
            Ok(reading) => Ok(reading.si),
            // The loader explains a number beyond a double's range from this form.
            Err(UnitError::Overflow) => Err(E::invalid_type(Unexpected::Str(text), &self)),
            Err(e) => {
                let (what, fix) = e.message(text, Q::KINDS);
                Err(E::custom(format!("{MARK}{what}{FIX}{fix}")))
            }
        }
    }
}

/// The YAML numbers that are not decimal: `.inf`, `.nan` (read, for the model's checks to
/// refuse as not finite, as ever), and integers in another radix (refused as the YAML parser
/// reads them, an integer, which the loader explains).
fn yaml_special<E: de::Error>(text: &str, expected: &dyn de::Expected) -> Result<Option<f64>, E> {
    let (negative, unsigned) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text.strip_prefix('+').unwrap_or(text)),
    };
    let sign = if negative { -1.0 } else { 1.0 };
    match unsigned {
        ".inf" | ".Inf" | ".INF" => return Ok(Some(sign * f64::INFINITY)),
        ".nan" | ".NaN" | ".NAN" if text == unsigned => return Ok(Some(f64::NAN)),
        _ => {}
    }
    for (prefix, radix) in [("0x", 16), ("0o", 8), ("0b", 2)] {
        if let Some(n) = unsigned.strip_prefix(prefix).and_then(|d| u64::from_str_radix(d, radix).ok()) {
            let unexpected = match i64::try_from(n) {
                Ok(n) if negative => Unexpected::Signed(-n),
                _ => Unexpected::Unsigned(n),
            };
            return Err(E::invalid_type(unexpected, expected));
        }
    }
    Ok(None)
}

/// The shapes a quantity field takes: a number, an optional one, a pair [x, y], a list.
pub trait Shape<Q>: Sized {
    fn read<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error>;
}

impl<Q: Quantity> Shape<Q> for f64 {
    fn read<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Si::<Q>::deserialize(deserializer).map(|s| s.0)
    }
}

impl<Q: Quantity> Shape<Q> for Option<f64> {
    fn read<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Option::<Si<Q>>::deserialize(deserializer).map(|s| s.map(|s| s.0))
    }
}

impl<Q: Quantity> Shape<Q> for [f64; 2] {
    fn read<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        <[Si<Q>; 2]>::deserialize(deserializer).map(|[a, b]| [a.0, b.0])
    }
}

impl<Q: Quantity> Shape<Q> for Option<[f64; 2]> {
    fn read<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Option::<[Si<Q>; 2]>::deserialize(deserializer).map(|s| s.map(|[a, b]| [a.0, b.0]))
    }
}

impl<Q: Quantity> Shape<Q> for Vec<f64> {
    fn read<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Vec::<Si<Q>>::deserialize(deserializer).map(|v| v.into_iter().map(|s| s.0).collect())
    }
}

macro_rules! readers {
    ($($name:ident: $q:ident),* $(,)?) => {$(
        #[doc = concat!("`deserialize_with` of a field of kind [`", stringify!($q), "`](super::", stringify!($q), ").")]
        pub fn $name<'de, D: Deserializer<'de>, T: Shape<super::$q>>(deserializer: D) -> Result<T, D::Error> {
            T::read(deserializer)
        }
    )*};
}

readers! {
    length: Length, angle: Angle, mass: Mass, inertia: Inertia, force: Force, torque: Torque, time: Time,
    speed: Speed, angular_speed: AngularSpeed, acceleration: Acceleration, stiffness: Stiffness,
    damping: Damping, torsional_damping: TorsionalDamping, torsional_stiffness: TorsionalStiffness, position: Position, rate: Rate, effort: Effort,
    pair_stiffness: PairStiffness, pair_damping: PairDamping,
}

/// `deserialize_with` of a motor's torque-speed envelope: points [speed, torque].
pub fn speed_torque<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
    let points = Option::<Vec<(Si<AngularSpeed>, Si<Torque>)>>::deserialize(deserializer)?;
    Ok(points.map(|p| p.into_iter().map(|(w, t)| [w.0, t.0]).collect()))
}
