//! The loader, on top of the core (as MuJoCo's compiler sits above its engine): model files
//! read into a [`MechanismSpec`] (YAML or JSON, errors that name the file, the field and the
//! fix), and a specification validated into a [`Mechanism`](crate::Mechanism), with the checks that need the
//! layers below the loader (the assembly at q0, the rank of the constraints, the integrators'
//! names) after the model's own.

mod io;
mod locate;
mod nesting;
mod parse_errors;
mod tags;
mod validate;

use io::with_line;
pub use io::{load, loads, parse_spec, parse_spec_constructed};
pub use validate::build;

use crate::structure::{structure, Structure};
use crate::ModelError;
use std::path::Path;

/// The text format of a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Yaml,
    Json,
    /// JSON serialised from a model given as data (a Python dict): read as JSON, its errors
    /// located by their field path alone, not by a line of a text its user never wrote.
    Data,
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

/// The structural analysis of model text at its drawing, also when it does not build because
/// its mobility differs from its number of coordinates or it does not assemble at `q0`
/// (what a structural analysis is for). Every other check of the loader applies; its errors
/// are located as [`loads`]'s.
pub fn analyse_spec(text: &str, format: Format, source: &str) -> Result<Structure, ModelError> {
    let mech = validate::drawing(parse_spec(text, format, source)?, source).map_err(|e| with_line(e, text, format))?;
    Ok(structure(&mech, &mech.x0))
}
