//! JSON values (the library's reports) as Python objects, through Python's own `json` module.

use pyo3::prelude::*;

/// A JSON value as the dict/list/number/str Python's `json.loads` makes of it.
pub fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (v.to_string(),))
}

/// A serialisable report as a Python dict.
pub fn report<'py, T: serde::Serialize>(py: Python<'py>, r: &T) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(r)
        .map_err(|e| crate::errors::HyError::new(crate::errors::Kind::Internal, e.to_string()))?;
    json_to_py(py, &v)
}
