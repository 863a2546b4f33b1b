//! The derivative harness (`hylc check-derivatives`, docs/derivative-harness.md): every registered function's
//! value, gradient and Hessian against automatic differentiation and finite differences.

use crate::errors::HyError;
use crate::progress::{callback, interruptible};
use hylc::checks::registry;
use hylc::diff::{CheckConfig, Report};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// One harness row as a dict.
fn row<'py>(py: Python<'py>, r: &Report) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &r.name)?;
    d.set_item("passed", r.passed())?;
    d.set_item("cases", r.cases)?;
    d.set_item("failures", r.failures)?;
    d.set_item("fd_skipped", r.fd_skipped)?;
    d.set_item("max_value", r.max_value)?;
    d.set_item("max_gradient_ad", r.max_gradient_ad)?;
    d.set_item("max_hessian_ad", r.max_hessian_ad)?;
    d.set_item("max_gradient_fd", r.max_gradient_fd)?;
    d.set_item("max_hessian_fd", r.max_hessian_fd)?;
    d.set_item("worst_ratio", r.worst_ratio)?;
    d.set_item("worst_input", r.worst_input.clone())?;
    Ok(d)
}

/// Run the derivative harness on every registered function, as ``hylc check-derivatives`` does.
///
/// Each function's value, gradient and Hessian are compared with automatic differentiation and with
/// Richardson-extrapolated central differences at ``cases`` random inputs from its own sampler
/// (docs/derivative-harness.md). Functions of the original materials are skipped when ``../shared`` is absent.
///
/// Parameters
/// ----------
/// cases : int, default 1000
///     Random inputs per function.
/// seed : int, default 1
///     Seed of the input generator (each function draws its own stream from it).
/// filter : str, default ""
///     Only the functions whose name contains it (all when empty).
/// progress : callable, optional
///     ``progress(done, total)``: functions checked of those selected, called from the calling thread (GIL
///     held). An exception it raises stops the run after the function in flight and is raised.
///
/// Returns
/// -------
/// list of DerivativeCheck
///     One dict per function, in the registry's order: ``name``, ``passed``, ``cases``, ``failures``,
///     ``fd_skipped`` (cases too close to a kink for finite differences), the largest relative errors
///     ``max_value``, ``max_gradient_ad``, ``max_hessian_ad``, ``max_gradient_fd``, ``max_hessian_fd``,
///     ``worst_ratio`` (the largest error-to-tolerance ratio; ≤ 1 passes) and ``worst_input``.
///
/// Raises
/// ------
/// ValueError
///     ``cases`` is 0, or no registered function matches ``filter``.
/// KeyboardInterrupt
///     Ctrl-C (the run stops after the function in flight).
#[pyfunction]
#[pyo3(signature = (cases=1000, seed=1, filter="", progress=None))]
pub fn check_derivatives<'py>(
    py: Python<'py>,
    cases: usize,
    seed: u64,
    filter: &str,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    if cases == 0 {
        return Err(HyError::value("cases: expected at least 1").into());
    }
    let cfg = CheckConfig {
        cases,
        seed,
        ..CheckConfig::default()
    };
    let progress = callback(progress)?;
    let reports = interruptible(py, progress.as_ref(), |m| {
        let checks: Vec<_> = registry()
            .into_iter()
            .filter(|c| filter.is_empty() || c.name().contains(filter))
            .collect();
        if checks.is_empty() {
            return Err(HyError::value(format!(
                "no registered function matches filter {filter:?}"
            )));
        }
        m.report(0, checks.len());
        let mut reports = Vec::new();
        for c in &checks {
            if m.cancelled() {
                break;
            }
            reports.push(c.check(&cfg));
            m.report(reports.len(), checks.len());
        }
        Ok(reports)
    })?;
    reports.iter().map(|r| row(py, r)).collect()
}
