//! The one place where Rust errors become JavaScript errors: a JS `Error` whose `name` is the
//! class the Python package raises for the same failure, with that class's attributes as
//! properties:
//!
//! ```text
//! ModelError        field (e.g. 'bodies.crank.mass', or 'line 3 column 5'), line (1-based or
//!                   undefined), source
//! ArgumentError     argument (its name, or undefined)
//! AssemblyError     residual, iterations
//! SingularityError  kind ('type_ii', 'passive', ...), sigmaMin
//! SimulationError   invalid options or a drive that failed
//! PlanardynError    anything else
//! ```
//!
//! A panic cannot be caught on `wasm32-unknown-unknown` (it aborts: the call throws a
//! `RuntimeError: unreachable`); [`install_panic_hook`] keeps its message, which the page
//! reads with `lastPanic()` to report the bug, and then makes a new instance of the module.

use js_sys::{Error as JsError, Reflect};
use planardyn::error::Setting;
use planardyn::{Error, KinematicsError, ModelError};
use std::cell::RefCell;
use wasm_bindgen::prelude::*;

thread_local! {
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Keep every panic's message for [`last_panic`].
pub fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        LAST_PANIC.with(|p| *p.borrow_mut() = Some(info.to_string()));
    }));
}

/// The message of the last panic (a bug in planardyn), if one happened.
#[wasm_bindgen(js_name = lastPanic)]
pub fn last_panic() -> Option<String> {
    LAST_PANIC.with(|p| p.borrow().clone())
}

fn error(name: &str, message: &str, props: &[(&str, JsValue)]) -> JsValue {
    let e = JsError::new(message);
    e.set_name(name);
    for (k, v) in props {
        // A property that cannot be set only loses detail: the message has it all.
        let _ = Reflect::set(&e, &JsValue::from_str(k), v);
    }
    e.into()
}

/// The 1-based line a loader's location names ("line 3 column 5"), in its field or message.
fn line_of(field: &str, message: &str) -> Option<u32> {
    [field, message].iter().find_map(|s| {
        let rest = &s[s.find("line ")? + 5..];
        let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
        digits.parse().ok()
    })
}

/// A model that does not build: `ModelError` with `field`, `line` and `source`.
pub fn model_error(e: &ModelError) -> JsValue {
    let (source, field, message) = match e {
        ModelError::Parse { source_name, path, message } | ModelError::Invalid { source_name, path, message } => {
            (source_name.as_str(), path.as_str(), message.as_str())
        }
        _ => ("", e.path(), ""),
    };
    let line = line_of(field, message).map_or(JsValue::UNDEFINED, JsValue::from);
    let props = [("field", field.into()), ("line", line), ("source", source.into())];
    error("ModelError", &e.to_string(), &props)
}

/// An argument the engine cannot compute with: `ArgumentError` naming it.
pub fn argument_error(name: Option<&str>, message: impl AsRef<str>) -> JsValue {
    let argument = name.map_or(JsValue::UNDEFINED, JsValue::from_str);
    error("ArgumentError", message.as_ref(), &[("argument", argument)])
}

fn kinematics_error(e: &KinematicsError) -> JsValue {
    let message = e.to_string();
    match e {
        KinematicsError::AssemblyFailed { residual, iterations } => error(
            "AssemblyError",
            &message,
            &[("residual", (*residual).into()), ("iterations", (*iterations as f64).into())],
        ),
        KinematicsError::Singular { kind, sigma_min } => error(
            "SingularityError",
            &message,
            &[("kind", kind.name().into()), ("sigmaMin", sigma_min.map_or(JsValue::NULL, JsValue::from))],
        ),
        KinematicsError::BadArgument { name, .. } => argument_error(Some(name), message),
        KinematicsError::Overflow { .. } => argument_error(None, message),
        _ => error("PlanardynError", &message, &[]),
    }
}

/// Any core error as the JS error of its class.
pub fn core_error(e: &Error) -> JsValue {
    match e {
        Error::Model(m) => model_error(m),
        Error::Kinematics(k) => kinematics_error(k),
        // t_end is an argument of every run; the other settings are solver options.
        Error::Setting(s) if s.setting == Setting::TEnd => argument_error(Some(s.setting.name()), s.to_string()),
        Error::Setting(_) | Error::Options(_) | Error::Drive { .. } => error("SimulationError", &e.to_string(), &[]),
        Error::BranchUndecided { sigma_min, .. } => {
            error("SingularityError", &e.to_string(), &[("kind", "type_ii".into()), ("sigmaMin", (*sigma_min).into())])
        }
        _ => error("PlanardynError", &e.to_string(), &[]),
    }
}

/// A core result with its error mapped.
pub fn js<T, E: Into<Error>>(r: Result<T, E>) -> Result<T, JsValue> {
    r.map_err(|e| core_error(&e.into()))
}

#[cfg(test)]
mod tests {
    use super::line_of;

    #[test]
    fn line_from_field_or_message() {
        assert_eq!(line_of("line 3 column 5", "did not find expected key"), Some(3));
        assert_eq!(line_of("bodies.crank", "expected a number (line 12 column 9)"), Some(12));
        assert_eq!(line_of("bodies.crank.mass", "mass must be positive"), None);
    }
}
