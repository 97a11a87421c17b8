//! YAML tags (`!foo 3`) are not part of the model format: the YAML parser reads a number or
//! a name through a tag it does not know and drops the tag, so a file that means something
//! by one would be read silently otherwise. A first pass over the text finds them.

use serde::de::{self, Deserialize, Deserializer, EnumAccess, MapAccess, SeqAccess, Visitor};
use std::fmt;

/// Starts the error raised at a tag, to tell it from the parser's own errors (which the
/// model's own pass reports, with its field).
pub(super) const FOUND: &str = "YAML tag ";

/// Any YAML value without a tag of its own (the core tags `!!str`, `!!float`... are read as
/// their values).
pub(super) struct Untagged;

impl<'de> Deserialize<'de> for Untagged {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(UntaggedVisitor)
    }
}

struct UntaggedVisitor;

impl<'de> Visitor<'de> for UntaggedVisitor {
    type Value = Untagged;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a YAML value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_i128<E>(self, _: i128) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_u128<E>(self, _: u128) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_str<E>(self, _: &str) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_unit<E>(self) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_none<E>(self) -> Result<Untagged, E> {
        Ok(Untagged)
    }
    fn visit_some<D: Deserializer<'de>>(self, deserializer: D) -> Result<Untagged, D::Error> {
        Untagged::deserialize(deserializer)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Untagged, A::Error> {
        while seq.next_element::<Untagged>()?.is_some() {}
        Ok(Untagged)
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Untagged, A::Error> {
        while map.next_entry::<Untagged, Untagged>()?.is_some() {}
        Ok(Untagged)
    }
    /// The YAML parser gives a value with a tag of its own as an enum named by the tag.
    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<Untagged, A::Error> {
        let (tag, _) = data.variant::<String>()?;
        Err(de::Error::custom(format!("{FOUND}`!{}`", tag.trim_start_matches('!'))))
    }
}

/// The first tag in a YAML `text`, refused with its field, line and column; the text's other
/// errors are left to the model's own pass.
pub(super) fn refuse(text: &str, source: &str) -> Result<(), crate::ModelError> {
    let de = serde_yaml_ng::Deserializer::from_str(text);
    let Err(e) = serde_path_to_error::deserialize::<_, Untagged>(de) else { return Ok(()) };
    let message = e.inner().to_string();
    let Some(tag) = message.find(FOUND).map(|i| &message[i + FOUND.len()..]) else { return Ok(()) };
    let tag = tag.split_whitespace().next().unwrap_or(tag);
    let (line, column) = e.inner().location().map_or((1, 1), |l| (l.line(), l.column().max(1)));
    let field = super::parse_errors::field_path(e.path());
    let (path, at) = if field.is_empty() {
        (format!("line {line} column {column}"), String::new())
    } else {
        (field, format!(" (line {line} column {column})"))
    };
    Err(crate::ModelError::Parse {
        source_name: source.to_string(),
        path,
        message: format!(
            "the YAML tag {tag} is not part of the model format{at}; remove it and write the value alone (see `planardyn docs model-format`)"
        ),
    })
}
