//! Yarn parameters as a Python dict (the keys of the yarn JSON, `hylc yarn`): missing keys take the defaults,
//! unknown keys and invalid values are errors with the yarn file's messages.

use crate::errors::{HyError, HyResult};
use hylc::rod::YarnMaterial;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::Path;

/// The yarn of an argument: `None` (defaults), a dict of parameters, or a path to a yarn JSON file.
pub fn yarn_of(arg: Option<&Bound<'_, PyAny>>) -> HyResult<YarnMaterial> {
    let Some(obj) = arg.filter(|o| !o.is_none()) else {
        return Ok(YarnMaterial::default());
    };
    if let Ok(path) = obj.extract::<std::path::PathBuf>() {
        return YarnMaterial::load_json(&path).map_err(|e| HyError::from(e).with_prefix("yarn: "));
    }
    let dict = obj.cast::<PyDict>().map_err(|_| {
        HyError::value("yarn: expected a dict of yarn parameters, a file path or None")
    })?;
    let mut value = serde_json::to_value(YarnMaterial::default()).expect("serialises");
    let map = value.as_object_mut().expect("an object");
    for (k, v) in dict.iter() {
        let key: String = k
            .extract()
            .map_err(|_| HyError::value("yarn: keys must be strings"))?;
        let json = if let Ok(i) = v.extract::<i64>() {
            serde_json::json!(i)
        } else if let Ok(x) = v.extract::<f64>() {
            serde_json::json!(x)
        } else if let Ok(t) = v.extract::<String>() {
            // the one text-valued key, `bending` ("tan" or "sin"); the yarn file's parser checks the value
            serde_json::json!(t)
        } else {
            return Err(HyError::value(format!(
                "yarn: {key}: expected a number (or a string for `bending`)"
            )));
        };
        map.insert(key, json);
    }
    YarnMaterial::from_json_str(&value.to_string(), Path::new("yarn"))
        .map_err(|e| HyError::value(e.to_string()))
}

/// The parameters as a dict with every key.
pub fn yarn_dict<'py>(py: Python<'py>, m: &YarnMaterial) -> PyResult<Bound<'py, PyAny>> {
    crate::convert::json_to_py(py, &serde_json::to_value(m).expect("serialises"))
}

/// The default yarn parameters (``hylc yarn``).
///
/// Returns
/// -------
/// dict
///     Every key of the yarn JSON (``young``, ``shear``, ``bend_twist_factor``, ``radius``, ``density``,
///     ``contact_stiffness``, ``contact_quadrature``, ``contact_exclusion``, ``contact_radius_factor``,
///     ``bending``).
#[pyfunction]
pub fn yarn_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    yarn_dict(py, &YarnMaterial::default())
}

/// Read a yarn JSON file (every key required).
///
/// Parameters
/// ----------
/// path : path-like
///     The yarn file.
///
/// Returns
/// -------
/// dict
///     The parameters, as :func:`yarn_defaults` gives them.
///
/// Raises
/// ------
/// FileNotFoundError
///     The file does not exist.
/// ValueError
///     A missing, unknown or invalid key.
#[pyfunction]
pub fn load_yarn<'py>(py: Python<'py>, path: std::path::PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let m = YarnMaterial::load_json(&path).map_err(HyError::from)?;
    yarn_dict(py, &m)
}

/// Write yarn parameters as a yarn JSON file (for ``--yarn FILE``).
///
/// Parameters
/// ----------
/// yarn : dict
///     Yarn parameters; missing keys take the defaults.
/// path : path-like
///     The file to write.
///
/// Raises
/// ------
/// ValueError
///     An unknown or invalid key, or the file cannot be written.
#[pyfunction]
pub fn save_yarn(yarn: &Bound<'_, PyAny>, path: std::path::PathBuf) -> PyResult<()> {
    let m = yarn_of(Some(yarn))?;
    m.save_json(&path).map_err(HyError::from)?;
    Ok(())
}
