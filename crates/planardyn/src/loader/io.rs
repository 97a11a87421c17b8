//! Reading model files: YAML or JSON text to a validated [`Mechanism`], with errors that
//! name the file and the field path (`bodies.crank.mass`) thanks to `serde_path_to_error`,
//! put in plain words by [`super::parse_errors`].

use super::parse_errors::Input;
use super::{locate, nesting, tags, Format};
use crate::model::construct;
use crate::model::spec::{PointSpec, ValueSpec};
use crate::model::{Mechanism, MechanismSpec};
use crate::units;
use crate::ModelError;
use std::path::Path;

/// A model file as written.
type FileSpec = MechanismSpec<PointSpec, ValueSpec>;

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
    super::build(spec, source).map_err(|e| with_line(e, text, format))
}

/// Parse model text into its specification without validating it: quantities with units
/// in SI, the points given by construction placed and the coordinates' values given as
/// measures of the drawing measured (`model::construct`).
pub fn parse_spec(text: &str, format: Format, source: &str) -> Result<MechanismSpec, ModelError> {
    parse_spec_constructed(text, format, source).map(|(spec, _)| spec)
}

/// [`parse_spec`], and the names of the points the text gives by construction (for the
/// reports of what the loader derived).
pub fn parse_spec_constructed(
    text: &str,
    format: Format,
    source: &str,
) -> Result<(MechanismSpec, Vec<String>), ModelError> {
    let file = parse_file(text, format, source)?;
    let constructed =
        file.points.0.iter().filter(|(_, p)| matches!(p, PointSpec::By(_))).map(|(n, _)| n.clone()).collect();
    let spec = construct::resolve(file, source).map_err(|e| with_line(e, text, format))?;
    Ok((spec, constructed))
}

/// A check's error with where its field is written, as a parse error's:
/// `bodies.crank.mass: mass must be > 0 kg, got -1 (line 26 column 11)`, before the fix
/// where the message gives one (`...; fix`). Data (`Format::Data`) has no lines: its field path only.
pub(super) fn with_line(e: ModelError, text: &str, format: Format) -> ModelError {
    let ModelError::Invalid { source_name, path, message } = e else { return e };
    let message = match (locate::field_line(text, format, &path), message.split_once("; ")) {
        (Some((line, column)), Some((what, fix))) => format!("{what} (line {line} column {column}); {fix}"),
        (Some((line, column)), None) => format!("{message} (line {line} column {column})"),
        (None, _) => message,
    };
    ModelError::Invalid { source_name, path, message }
}

/// The model text as written: points and coordinate values also by construction.
fn parse_file(text: &str, format: Format, source: &str) -> Result<FileSpec, ModelError> {
    let input = Input { text, format, source };
    match format {
        Format::Json | Format::Data => {
            let de = &mut serde_json::Deserializer::from_str(text);
            serde_path_to_error::deserialize(de).map_err(|e| {
                let located = format == Format::Json && e.inner().line() > 0;
                let at = located.then(|| (e.inner().line(), e.inner().column()));
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
            units::reading_yaml(|| serde_path_to_error::deserialize(de)).map_err(|e| {
                let at = e.inner().location().map(|l| (l.line(), l.column()));
                input.error(e.path(), &e.inner().to_string(), at)
            })
        }
    }
}
