//! planardyn as WebAssembly (wasm-bindgen glue only, as `planardyn-py` is for Python): the
//! browser app's engine. Conversions live in `convert.rs`, the mapping of errors to JS errors
//! in `errors.rs` (the only place), the `Mechanism` class in `mechanism.rs`, and the bodies of
//! its runs in `simulate.rs` and of its compliant analyses in `elastic.rs`; the mechanics is
//! the core's (`planardyn`). Built for `wasm32-unknown-unknown` by `./dev app`; on other targets it compiles (for clippy) but
//! exports nothing usable.

mod convert;
mod elastic;
mod errors;
mod mechanism;
mod simulate;

use planardyn::Format;
use wasm_bindgen::prelude::*;

/// Keep the message of a panic for `lastPanic()` (wasm-bindgen runs this on instantiation).
#[wasm_bindgen(start)]
pub fn start() {
    errors::install_panic_hook();
}

/// The engine's version (the planardyn crates').
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// Build a mechanism from model text; `format` is "yaml" or "json", `source` names it in
/// messages. A model that does not build throws a `ModelError` with `field` and `line`.
#[wasm_bindgen]
pub fn load(text: &str, format: &str, source: &str) -> Result<mechanism::WasmMechanism, JsValue> {
    let format = match format.to_ascii_lowercase().as_str() {
        "yaml" | "yml" => Format::Yaml,
        "json" => Format::Json,
        other => {
            return Err(errors::argument_error(
                Some("format"),
                format!("format must be 'yaml' or 'json', got {other:?}"),
            ))
        }
    };
    let mech = planardyn::loads(text, format, source).map_err(|e| errors::model_error(&e))?;
    Ok(mechanism::WasmMechanism::new(mech))
}
