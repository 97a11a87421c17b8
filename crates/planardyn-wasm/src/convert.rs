//! Conversions between JavaScript values and the core's slices and results: arguments arrive
//! as `Float64Array`s (checked for length and finiteness, the message naming the argument and
//! what its entries are), results leave as plain objects of numbers, strings and
//! `Float64Array`s (time-major, row after row, as the Python package's arrays are laid out).

use crate::errors::argument_error;
use js_sys::{Array, Float64Array, Object, Reflect};
use wasm_bindgen::prelude::*;

/// A plain JS object built field by field.
pub struct Obj(Object);

impl Obj {
    pub fn new() -> Obj {
        Obj(Object::new())
    }

    /// Set `key` (a field that cannot be set on a fresh plain object is a bug: it is skipped).
    pub fn set(self, key: &str, value: impl Into<JsValue>) -> Obj {
        let _ = Reflect::set(&self.0, &JsValue::from_str(key), &value.into());
        self
    }

    /// Set `key` to a `Float64Array` copy of `values`.
    pub fn f64s(self, key: &str, values: &[f64]) -> Obj {
        self.set(key, f64s(values))
    }

    pub fn build(self) -> JsValue {
        self.0.into()
    }
}

/// A `Float64Array` copy of `values`.
pub fn f64s(values: &[f64]) -> Float64Array {
    Float64Array::from(values)
}

/// A JS array of strings.
pub fn strings<S: AsRef<str>>(values: impl IntoIterator<Item = S>) -> Array {
    values.into_iter().map(|s| JsValue::from_str(s.as_ref())).collect()
}

/// A JS array of any values.
pub fn array(values: impl IntoIterator<Item = JsValue>) -> Array {
    values.into_iter().collect()
}

/// Check an argument of `len` finite values; `what` says what its entries are.
pub fn vector(name: &str, v: &[f64], len: usize, what: &str) -> Result<(), JsValue> {
    if v.len() != len {
        return Err(argument_error(Some(name), format!("{name} needs {len} values ({what}), got {}", v.len())));
    }
    finite(name, v)
}

/// Check that every value of argument `name` is finite.
pub fn finite(name: &str, v: &[f64]) -> Result<(), JsValue> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(argument_error(Some(name), format!("{name}[{i}] = {} is not a finite number", v[i]))),
        None => Ok(()),
    }
}

/// Check rows of `len` values each (N x len, row after row).
pub fn rows(name: &str, v: &[f64], len: usize, what: &str) -> Result<usize, JsValue> {
    if len == 0 || !v.len().is_multiple_of(len) {
        return Err(argument_error(
            Some(name),
            format!("{name} needs rows of {len} values ({what}), got {} values", v.len()),
        ));
    }
    finite(name, v)?;
    Ok(v.len() / len)
}

/// A JS object read into `T` with serde; the message names the argument and the field.
pub fn from_js<T: serde::de::DeserializeOwned>(name: &str, value: JsValue) -> Result<T, JsValue> {
    if value.is_undefined() || value.is_null() {
        return serde_wasm_bindgen::from_value(Object::new().into())
            .map_err(|e| argument_error(Some(name), format!("{name}: {e}")));
    }
    serde_wasm_bindgen::from_value(value).map_err(|e| argument_error(Some(name), format!("{name}: {e}")))
}
