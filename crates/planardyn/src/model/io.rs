//! Reading model files: YAML or JSON text to a validated [`Mechanism`], with errors that
//! name the file and the field path (`bodies.crank.mass`) thanks to `serde_path_to_error`.

use super::{Mechanism, MechanismSpec};
use crate::ModelError;
use std::path::Path;

/// The text format of a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Yaml,
    Json,
}

impl Format {
    /// The format a file name implies: `.json` is JSON, anything else YAML (a superset).
    pub fn from_path(path: &Path) -> Format {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("json") => Format::Json,
            _ => Format::Yaml,
        }
    }
}

/// Load a model file (`.yaml`, `.yml` or `.json`).
pub fn load(path: impl AsRef<Path>) -> Result<Mechanism, ModelError> {
    let path = path.as_ref();
    let source = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| ModelError::Parse {
        source_name: source.clone(),
        path: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    loads(&text, Format::from_path(path), &source)
}

/// Parse model text; `source` names it in error messages.
pub fn loads(text: &str, format: Format, source: &str) -> Result<Mechanism, ModelError> {
    let spec = parse_spec(text, format, source)?;
    Mechanism::new(spec, source)
}

/// Parse model text into its specification without validating it.
pub fn parse_spec(text: &str, format: Format, source: &str) -> Result<MechanismSpec, ModelError> {
    let parse_error = |path: String, message: String| {
        let path = if path == "." { String::new() } else { path };
        // The YAML parser already prefixes its messages with the path: keep it once.
        let message = message.strip_prefix(&format!("{path}: ")).map(str::to_string).unwrap_or(message);
        ModelError::Parse { source_name: source.to_string(), path, message }
    };
    match format {
        Format::Json => {
            let de = &mut serde_json::Deserializer::from_str(text);
            serde_path_to_error::deserialize(de)
                .map_err(|e| parse_error(e.path().to_string(), e.inner().to_string()))
        }
        Format::Yaml => {
            let de = serde_yaml_ng::Deserializer::from_str(text);
            serde_path_to_error::deserialize(de)
                .map_err(|e| parse_error(e.path().to_string(), e.inner().to_string()))
        }
    }
}
