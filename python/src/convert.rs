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

/// Whether `v` is a number or a (nested, rectangular) array of numbers.
fn numeric(v: &serde_json::Value) -> Option<Vec<usize>> {
    match v {
        serde_json::Value::Number(_) => Some(vec![]),
        serde_json::Value::Array(a) if !a.is_empty() => {
            let first = numeric(&a[0])?;
            a[1..]
                .iter()
                .all(|e| numeric(e).as_ref() == Some(&first))
                .then(|| [vec![a.len()], first].concat())
        }
        _ => None,
    }
}

/// A JSON value as Python objects with every non-empty rectangular array of numbers a float numpy array
/// (dicts of numpy arrays).
pub fn json_to_numpy<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    match v {
        serde_json::Value::Object(m) => {
            let d = pyo3::types::PyDict::new(py);
            for (k, e) in m {
                d.set_item(k, json_to_numpy(py, e)?)?;
            }
            Ok(d.into_any())
        }
        serde_json::Value::Array(a) => match numeric(v) {
            Some(shape) if !shape.is_empty() => {
                let np = py.import("numpy")?;
                let kw = pyo3::types::PyDict::new(py);
                kw.set_item("dtype", "float64")?;
                np.call_method("asarray", (json_to_py(py, v)?,), Some(&kw))
            }
            _ => {
                let items = a
                    .iter()
                    .map(|e| json_to_numpy(py, e))
                    .collect::<PyResult<Vec<_>>>()?;
                Ok(pyo3::types::PyList::new(py, items)?.into_any())
            }
        },
        _ => json_to_py(py, v),
    }
}
