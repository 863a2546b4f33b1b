//! Scene arguments: a scene JSON file, an ARCSim scene file, a built-in name, or a dict with the scene JSON's
//! layout (relative paths in a dict start from the working directory); and `load_scene`, a scene as a dict.

use crate::convert::json_to_py;
use crate::errors::{detached, HyError, HyResult, Kind};
use hylc::shell::scene::Scene;
use hylc::workflow::simulate::{override_scene, prepare, Overrides};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// How a dict scene is named in messages.
const DICT_LABEL: &str = "scene (a dict)";

/// A scene argument, read from Python (no library work yet).
pub enum SceneArg {
    /// A file or a built-in, as `hylc simulate SCENE` takes it.
    Named(String),
    /// The JSON text of a dict.
    Json(String),
}

impl SceneArg {
    /// The scene argument `obj`: a dict, or a str / path-like naming a file or a built-in.
    pub fn of(obj: &Bound<'_, PyAny>) -> PyResult<SceneArg> {
        if obj.cast::<PyDict>().is_ok() {
            let text: String = obj
                .py()
                .import("json")?
                .call_method1("dumps", (obj,))
                .map_err(|e| HyError::value(format!("scene: the dict is not JSON: {e}")))?
                .extract()?;
            return Ok(SceneArg::Json(text));
        }
        let path: PathBuf = obj.extract().map_err(|_| {
            HyError::value("scene: expected a scene file, a built-in name or a dict")
        })?;
        let name = path.display().to_string();
        if path.extension().is_some() && !path.exists() {
            return Err(
                HyError::new(Kind::NotFound, format!("scene: {name}: no such scene file")).into(),
            );
        }
        Ok(SceneArg::Named(name))
    }

    /// How the scene is named in messages and reports.
    pub fn label(&self) -> &str {
        match self {
            SceneArg::Named(n) => n,
            SceneArg::Json(_) => DICT_LABEL,
        }
    }

    /// The scene after the overrides, with the folder its relative paths start from (the working directory for a
    /// dict), as `hylc simulate` prepares it.
    pub fn prepare(&self, ov: &Overrides) -> HyResult<(Scene, PathBuf)> {
        match self {
            SceneArg::Named(n) => Ok(prepare(n, ov)?),
            SceneArg::Json(text) => {
                let mut scene = Scene::from_json_str(text, DICT_LABEL)?;
                override_scene(&mut scene, ov, &mut |_| {})?;
                Ok((scene, Path::new("").to_path_buf()))
            }
        }
    }
}

/// The scene as a dict, with every setting (defaults filled in), as `hylc simulate SCENE --print` prints it.
///
/// Parameters
/// ----------
/// scene : str, path-like or dict
///     A scene JSON file, an ARCSim scene file (converted), a built-in (``stretch-x``, ``stretch-y``,
///     ``drape-x``, ``drape-y``, ``hanging``) or a dict with the scene JSON's layout.
///
/// Returns
/// -------
/// dict
///     The scene JSON's layout (``mesh``, ``material``, ``duration``, ``dt``, ``solver``, ``output``, ...);
///     it can be changed and passed to :func:`simulate` or :func:`gradient`.
///
/// Raises
/// ------
/// FileNotFoundError
///     A scene file that does not exist.
/// SimulationError
///     A scene that is not valid JSON of a scene, or an unknown built-in.
#[pyfunction]
pub fn load_scene<'py>(py: Python<'py>, scene: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let arg = SceneArg::of(scene)?;
    let value = detached(py, || {
        let (s, _) = arg.prepare(&Overrides::default())?;
        serde_json::to_value(&s).map_err(|e| HyError::new(Kind::Internal, e.to_string()))
    })?;
    json_to_py(py, &value)
}
