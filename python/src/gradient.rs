//! Sensitivities of a cloth scene (`hylc gradient`, docs/sensitivities.md): dJ/dp of an observable, or the
//! vector–Jacobian product of a cotangent on the final positions, by an adjoint solve.

use crate::arrays::rows;
use crate::convert::json_to_numpy;
use crate::errors::{detached, HyError};
use crate::yarn::yarn_of;
use hylc::workflow::gradient::{gradient as run_gradient, GradientOptions, YarnChainInput};
use hylc::workflow::simulate::{prepare, Overrides};
use pyo3::prelude::*;
use std::path::PathBuf;

/// dJ/dp of a scene (a scene JSON file, an ARCSim scene or a built-in) at its last step, as `hylc gradient`
/// computes it (a quasi-static equilibrium by one adjoint solve, a dynamic run by the discrete adjoint of its
/// implicit Euler substeps): `observable` is `com-x|y|z`, `energy`, `handle-force:NAME:x|y|z` or
/// `target:FILE.obj`; or, instead, `cotangent` (vertices, 3) gives J = Σ w_v · x_v, so that the result is the
/// vector–Jacobian product wᵀ dx*/dp. `at` (s) picks the step nearest it (default the last); `check` adds
/// central differences of re-solves. Returns the content of `gradient.json` as dicts of numpy arrays:
/// `value`, `time`, `residual`, `scene` (`stiffness`, `bending_scale`, `mass`, `gravity`), `held` (per held set
/// `translation` (3,) and `keyframes` (k, 3)), `obstacles` (n, 3), `material` (the material file's layout with
/// dJ/dc in place of each coefficient) and `check`. With `samples` (the sample file the material was fitted to,
/// made with `sensitivities`) and `yarn` (its yarn parameters: a dict, a file or None for the defaults) also
/// `yarn` (name → dJ/dθ) and `yarn_chain` (the fit's kinks, samples used). The frames and the log go to `out`
/// (a temporary folder by default).
#[pyfunction]
#[pyo3(signature = (scene, observable=None, cotangent=None, at=None, material=None, out=None, check=false, samples=None, yarn=None))]
#[allow(clippy::too_many_arguments)]
pub fn gradient<'py>(
    py: Python<'py>,
    scene: &str,
    observable: Option<String>,
    cotangent: Option<Bound<'py, PyAny>>,
    at: Option<f64>,
    material: Option<String>,
    out: Option<PathBuf>,
    check: bool,
    samples: Option<PathBuf>,
    yarn: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let yarn_chain = match samples {
        Some(samples) => {
            let yarn_label = match &yarn {
                Some(y) if y.extract::<PathBuf>().is_ok() => {
                    y.extract::<PathBuf>()?.display().to_string()
                }
                Some(_) => "yarn (a dict)".to_string(),
                None => "the default yarn".to_string(),
            };
            Some(YarnChainInput {
                samples,
                yarn: yarn_of(yarn.as_ref())?,
                yarn_label,
            })
        }
        None if yarn.is_some() => {
            return Err(
                HyError::value("gradient: yarn needs samples (the material's sample file)").into(),
            )
        }
        None => None,
    };
    let cotangent = match cotangent {
        Some(c) => {
            let r = rows(&c, "cotangent", &[3])?;
            Some(r.iter().map(|w| [w[0], w[1], w[2]]).collect::<Vec<_>>())
        }
        None => None,
    };
    let observable = match (observable, &cotangent) {
        (Some(o), None) => o,
        (None, Some(_)) => "cotangent".to_string(),
        _ => {
            return Err(
                HyError::value("gradient: give exactly one of observable and cotangent").into(),
            )
        }
    };
    let opts = GradientOptions {
        observable,
        cotangent,
        at,
        check,
        check_coefficients: 5,
        yarn: yarn_chain,
    };
    let ov = Overrides {
        material,
        ..Default::default()
    };
    let json = detached(py, || {
        let (sc, dir) = prepare(scene, &ov)?;
        let tmp;
        let folder = match &out {
            Some(o) => o.clone(),
            None => {
                tmp = std::env::temp_dir().join(format!("hylc-gradient-{}", std::process::id()));
                tmp.clone()
            }
        };
        let o = run_gradient(&sc, scene, &dir, &folder, &opts, &mut |_| {})?;
        if out.is_none() {
            let _ = std::fs::remove_dir_all(&folder);
        }
        Ok(o.json)
    })?;
    json_to_numpy(py, &json)
}
