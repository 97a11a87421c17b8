//! Reading model files: YAML or JSON text to a validated [`Mechanism`], with errors that
//! name the file and the field path (`bodies.crank.mass`) thanks to `serde_path_to_error`,
//! put in plain words by [`super::parse_errors`].

use super::parse_errors::Input;
use super::{nesting, tags, Format};
use crate::model::{Mechanism, MechanismSpec};
use crate::ModelError;
use std::path::Path;

/// Load a model file (`.yaml`, `.yml` or `.json`).
pub fn load(path: impl AsRef<Path>) -> Result<Mechanism, ModelError> {
    let path = path.as_ref();
    let source = path.display().to_string();
    let error = |path: String, message: String| ModelError::Parse { source_name: source.clone(), path, message };
    let bytes = std::fs::read(path)
        .map_err(|e| error("<file>".into(), format!("cannot read the file: {e}; check its name and permissions")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line_start = valid.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let (line, column) = (
            valid.iter().filter(|&&b| b == b'\n').count() + 1,
            String::from_utf8_lossy(&valid[line_start..]).chars().count() + 1,
        );
        error(format!("line {line} column {column}"), "the file is not UTF-8 text; save it as UTF-8".into())
    })?;
    loads(&text, Format::from_path(path), &source)
}

/// Parse model text; `source` names it in error messages.
pub fn loads(text: &str, format: Format, source: &str) -> Result<Mechanism, ModelError> {
    let spec = parse_spec(text, format, source)?;
    super::build(spec, source)
}

/// Parse model text into its specification without validating it.
pub fn parse_spec(text: &str, format: Format, source: &str) -> Result<MechanismSpec, ModelError> {
    let input = Input { text, format, source };
    match format {
        Format::Json => {
            let de = &mut serde_json::Deserializer::from_str(text);
            serde_path_to_error::deserialize(de).map_err(|e| {
                let at = (e.inner().line() > 0).then(|| (e.inner().line(), e.inner().column()));
                input.error(e.path(), &e.inner().to_string(), at)
            })
        }
        Format::Yaml => {
            if let Some((line, column)) = nesting::too_deep(text) {
                return Err(ModelError::Parse {
                    source_name: source.to_string(),
                    path: format!("line {line} column {column}"),
                    message: format!(
                        "the text nests deeper than {} levels, where a model file needs about 6; \
                         check the brackets and the indentation there",
                        nesting::MAX_NESTING
                    ),
                });
            }
            tags::refuse(text, source)?;
            let de = serde_yaml_ng::Deserializer::from_str(text);
            serde_path_to_error::deserialize(de).map_err(|e| {
                let at = e.inner().location().map(|l| (l.line(), l.column()));
                input.error(e.path(), &e.inner().to_string(), at)
            })
        }
    }
}
