//! Sensitivities of a cloth scene (`hylc gradient`, docs/sensitivities.md): dJ/dp of an observable, or the
//! vector–Jacobian product of a cotangent on the final positions, by an adjoint solve.

use crate::arrays::rows;
use crate::convert::json_to_numpy;
use crate::errors::{detached, HyError};
use crate::scene::SceneArg;
use crate::yarn::yarn_of;
use hylc::workflow::gradient::{gradient as run_gradient, GradientOptions, YarnChainInput};
use hylc::workflow::simulate::Overrides;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Sensitivities dJ/dp of a scene's observable at one step, as ``hylc gradient`` computes them.
///
/// A quasi-static equilibrium is differentiated by one adjoint solve, a dynamic run by the discrete adjoint of
/// its implicit Euler substeps (docs/sensitivities.md).
///
/// Parameters
/// ----------
/// scene : str, path-like or dict
///     A scene JSON file, an ARCSim scene, a built-in or a dict with the scene JSON's layout.
/// observable : str, optional
///     ``com-x``, ``com-y``, ``com-z``, ``energy``, ``handle-force:NAME:x|y|z`` or ``target:FILE.obj``.
/// cotangent : array_like, optional
///     Instead of ``observable``: weights w (vertices, 3), J = Σ w_v · x_v, so that the result is the
///     vector–Jacobian product wᵀ dx*/dp.
/// at : float, optional
///     The time (s) of the step to differentiate (the nearest step; default the last).
/// material : str, optional
///     A material file or ``"default"`` instead of the scene's.
/// out : path-like, optional
///     A folder for the frames, the log and ``gradient.json`` (a temporary folder, removed, by default).
/// check : bool, default False
///     Also central differences of re-solves for a few coefficients (``check`` in the result).
/// samples : path-like, optional
///     The sample file the material was fitted to (made with ``sensitivities=True``): adds dJ/dθ of the yarn
///     parameters through the fit (``yarn``, ``yarn_chain``).
/// yarn : dict, path-like or None
///     The yarn parameters of ``samples`` (a dict, a yarn JSON file, or None for the defaults).
///
/// Returns
/// -------
/// GradientResult
///     The content of ``gradient.json`` with numeric lists as numpy arrays: ``value``, ``time``, ``residual``,
///     ``scene`` (``stiffness``, ``bending_scale``, ``mass``, ``gravity``), ``held`` (per held set
///     ``translation`` (3,) and ``keyframes`` (k, 3)), ``obstacles``, ``material`` (the material file's layout
///     with dJ/dc in place of each coefficient), ``check``, and with ``samples`` ``yarn`` (name → dJ/dθ) and
///     ``yarn_chain``.
///
/// Raises
/// ------
/// ValueError
///     Not exactly one of ``observable`` and ``cotangent``; a cotangent of the wrong shape; ``yarn`` without
///     ``samples``; a scene the adjoint does not cover (e.g. damping).
/// FileNotFoundError
///     A scene or sample file that does not exist.
/// SimulationError
///     A scene that is not valid or whose step did not converge.
#[pyfunction]
#[pyo3(signature = (scene, observable=None, cotangent=None, at=None, material=None, out=None, check=false, samples=None, yarn=None))]
#[allow(clippy::too_many_arguments)]
pub fn gradient<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
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
    let arg = SceneArg::of(scene)?;
    let json = detached(py, || {
        let (sc, dir) = arg.prepare(&ov)?;
        let tmp;
        let folder = match &out {
            Some(o) => o.clone(),
            None => {
                tmp = std::env::temp_dir().join(format!("hylc-gradient-{}", std::process::id()));
                tmp.clone()
            }
        };
        let o = run_gradient(&sc, arg.label(), &dir, &folder, &opts, &mut |_| {})?;
        if out.is_none() {
            let _ = std::fs::remove_dir_all(&folder);
        }
        Ok(o.json)
    })?;
    json_to_numpy(py, &json)
}
