//! Sampling (Algorithm C4, docs/sampling.md): the built-in plans (`hylc plan`), a plan's samples, and running a
//! plan on a pattern to a sample file (`hylc sample`), resumable, with progress and Ctrl-C.

use crate::arrays::to_2d;
use crate::convert::json_to_py;
use crate::errors::{detached, HyError, HyResult, Kind};
use crate::pattern::pattern_of;
use crate::progress::{callback, interruptible};
use crate::yarn::yarn_of;
use hylc::micro::{CrossingGuard, MicroProblem, Predictor, SolverOptions, StepRule};
use hylc::sample::{parse_shard, run_plan_until, Plan, RunOptions, Starts};
use hylc::workflow::inputs::load_plan;
use hylc::workflow::sidecar::write_meta;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// How a dict plan is named in messages.
const DICT_LABEL: &str = "plan (a dict)";

/// A plan argument: a built-in name (`default`, `reduced`, `quick`, `holdout`), a plan JSON file, or a dict with
/// the plan JSON's layout (validated as a file is).
pub fn plan_of(obj: &Bound<'_, PyAny>) -> PyResult<Plan> {
    if obj.cast::<PyDict>().is_ok() {
        let text: String = obj
            .py()
            .import("json")?
            .call_method1("dumps", (obj,))
            .map_err(|e| HyError::value(format!("plan: the dict is not JSON: {e}")))?
            .extract()?;
        return Ok(Plan::from_json(&text, Some(DICT_LABEL)).map_err(HyError::from)?);
    }
    let arg: PathBuf = obj.extract().map_err(|_| {
        HyError::value(
            "plan: expected a plan name (default, reduced, quick, holdout), a plan file or a dict",
        )
    })?;
    let arg = arg.display().to_string();
    Ok(load_plan(&arg).map_err(HyError::from)?)
}

/// A sampling plan as a dict (the plan JSON's layout), as ``hylc plan --write`` writes it.
///
/// Parameters
/// ----------
/// plan : str, path-like or dict, default "default"
///     A built-in plan: ``"default"`` (150 per 1D range, 50×50 grids), ``"reduced"`` (30 per 1D range, 10×10
///     grids), ``"quick"`` (``hylc run``'s: 30 per 1D range, 6×6 grids) or ``"holdout"`` (the 9×9×9 in-plane
///     grid only); or a plan JSON file, or a dict (validated and completed).
/// write : path-like, optional
///     Also write the plan there as JSON (pretty-printed, as ``hylc plan --write``).
///
/// Returns
/// -------
/// PlanDict
///     ``ranges`` (per strain [min, max]), ``count_1d``, ``count_2d``, ``pairs`` and the optional
///     ``ranges_2d``, ``grid``, ``counts_1d``, ``counts_2d``; it can be changed and passed to :func:`sample`
///     or :func:`plan_samples`.
///
/// Raises
/// ------
/// ValueError
///     A name that is neither a built-in plan nor a file.
/// SampleError
///     A plan file or dict that is not a valid plan (the message names the field).
#[pyfunction]
#[pyo3(signature = (plan=None, write=None))]
pub fn plan<'py>(
    py: Python<'py>,
    plan: Option<&Bound<'py, PyAny>>,
    write: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let p = match plan {
        Some(obj) => plan_of(obj)?,
        None => Plan::default(),
    };
    let value =
        serde_json::to_value(&p).map_err(|e| HyError::new(Kind::Internal, e.to_string()))?;
    if let Some(path) = write {
        let text = serde_json::to_string_pretty(&p).expect("a plan serialises");
        std::fs::write(&path, text + "\n").map_err(|e| {
            HyError::from_library(Kind::Value, &e)
                .with_prefix(&format!("{}: cannot write: ", path.display()))
        })?;
    }
    json_to_py(py, &value)
}

/// The samples of a plan in its order, with their ids, and its hash.
///
/// Parameters
/// ----------
/// plan : str, path-like or dict
///     As :func:`plan` takes it.
///
/// Returns
/// -------
/// PlanSamples
///     ``hash`` (the plan hash, 16 hex digits, as ``hylc plan`` prints it), ``ids`` (N,) the samples' ids
///     (``HASH-INDEX``, as in the sample file), ``z`` (N, 5) the strains (s_x, s_a, s_y, II00, II11) and
///     ``chains`` the number of warm-started continuation chains.
///
/// Raises
/// ------
/// ValueError, SampleError
///     As :func:`plan`.
#[pyfunction]
pub fn plan_samples<'py>(
    py: Python<'py>,
    plan: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = plan_of(plan)?;
    let (samples, chains) = detached(py, || {
        p.validate().map_err(HyError::from)?;
        Ok((p.samples(), p.chains().len()))
    })?;
    let d = PyDict::new(py);
    d.set_item("hash", format!("{:016x}", p.hash()))?;
    d.set_item(
        "ids",
        samples.iter().map(|s| s.id.clone()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "z",
        to_2d(py, &samples.iter().map(|s| s.z).collect::<Vec<_>>()),
    )?;
    d.set_item("chains", chains)?;
    Ok(d)
}

/// `shard` as Python gives it: "k/n" or (k, n).
#[derive(FromPyObject)]
pub enum ShardArg {
    Text(String),
    Pair(usize, usize),
}

impl ShardArg {
    fn parse(self) -> HyResult<(usize, usize)> {
        let text = match self {
            ShardArg::Text(t) => t,
            ShardArg::Pair(k, n) => format!("{k}/{n}"),
        };
        parse_shard(&text).map_err(|e| HyError::value(format!("shard: {e}")))
    }
}

/// One of `choices` (its value) by name; the error names the argument and the choices.
fn choice<T: Copy>(name: &str, given: &str, choices: &[(&str, T)]) -> HyResult<T> {
    choices
        .iter()
        .find(|(n, _)| *n == given)
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let names: Vec<&str> = choices.iter().map(|(n, _)| *n).collect();
            HyError::value(format!(
                "{name}: expected one of {}, got {given:?}",
                names.join(", ")
            ))
        })
}

/// The micro solver's options of `hylc sample`: the stopping rules and the crossing guard, `reject` by default
/// with several starts (a start that pulls yarns through each other ends in another fabric).
fn solver_options(
    tolerance: f64,
    max_steps: usize,
    time_limit: Option<f64>,
    crossings: Option<&str>,
    inertia: bool,
    starts: Starts,
) -> HyResult<SolverOptions> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(HyError::value(format!(
            "tolerance: expected a positive number, got {tolerance}"
        )));
    }
    let guards = [
        ("off", CrossingGuard::Off),
        ("count", CrossingGuard::Count),
        ("reject", CrossingGuard::Reject),
    ];
    let crossings = match crossings {
        Some(c) => choice("crossings", c, &guards)?,
        None if starts != Starts::Warm => CrossingGuard::Reject,
        None => CrossingGuard::default(),
    };
    Ok(SolverOptions {
        tolerance,
        max_steps,
        time_limit,
        crossings,
        step_rule: if inertia {
            StepRule::Inertia
        } else {
            StepRule::Shift
        },
        ..Default::default()
    })
}

/// Run a sampling plan on a pattern, appending to a JSON-lines sample file, as ``hylc sample`` does.
///
/// Chains of warm-started solves run in parallel; every record is written and synced as it is solved, and
/// samples already in the file are skipped, so an interrupted run (Ctrl-C, ``limit``) resumes where it stopped
/// and writes the same records as an uninterrupted one. The sidecar ``OUT.meta.json`` (pattern, plan, yarn,
/// solver) is written too, for :func:`fit`.
///
/// Parameters
/// ----------
/// pattern : Pattern, str or path-like
///     A Pattern, a ``.pyp`` file or a generated kind (plain, twill, satin, basket, stockinette).
/// out : path-like
///     The sample file (JSON lines; created or appended to).
/// plan : str, path-like or dict, default "default"
///     As :func:`plan` takes it.
/// yarn : dict, path-like or None
///     Yarn parameters (a dict, missing keys the defaults; a yarn JSON file; None for the defaults).
/// cold : bool, default False
///     Start every sample from the reference state.
/// shard : str or (int, int), optional
///     Run shard k of n (``"k/n"`` or ``(k, n)``: the chains with index ≡ k mod n).
/// limit : int, optional
///     Stop after writing this many samples.
/// predictor : {"secant", "none"}, default "secant"
///     The predictor of warm starts along a chain.
/// starts : {"warm", "warm+cold", "all"}, default "warm"
///     The starts of every sample (docs/sampling.md, "Multi-start").
/// disagreement : float, optional
///     ``starts="all"``: the relative difference of the warm and cold Ψ̄ above which the reversed chain is
///     tried (default 1e-6, the library's).
/// sensitivities : bool, default False
///     Store ∂Ψ̄/∂θ and dσ/dθ of the six yarn parameters in every converged record (and add them to the
///     finished records that lack them).
/// tolerance, max_steps, time_limit : float, int, float
///     The micro solver's stopping rules (defaults 1e-8, 2000, none).
/// crossings : {"off", "count", "reject"}, optional
///     The yarn-crossing guard (default off, ``reject`` with several starts).
/// inertia : bool, default True
///     The inertia-controlled Newton steps (False = ``--no-inertia``, for files made before them).
/// progress : callable, optional
///     ``progress(done, total)``: records written by this run of those it will write, called from the calling
///     thread (GIL held) with the latest counts at most every 0.05 s and at the end. An exception it raises
///     stops the run after the solves in flight and is raised.
///
/// Returns
/// -------
/// SampleSummary
///     ``plan_hash``, ``selected`` (samples of the selected chains), ``already_done``, ``written``,
///     ``converged``, ``replayed`` (re-solved for warm starts), ``sensitivities``,
///     ``lacking_sensitivities``, ``sensitivities_added`` and ``time`` (s), as ``hylc sample`` prints them.
///
/// Raises
/// ------
/// ValueError
///     A bad argument (a plan name, ``shard``, ``starts`` with ``cold``, a yarn parameter).
/// FileNotFoundError
///     A pattern or plan file that does not exist.
/// SampleError
///     A plan that is not valid, ``starts`` other than warm with ``cold``, or a sample file of another
///     problem (pattern, yarn or solver settings).
/// KeyboardInterrupt
///     Ctrl-C (noticed within 0.05 s; the records written so far stay, a later call resumes).
#[pyfunction]
#[pyo3(signature = (pattern, out, plan=None, *, yarn=None, cold=false, shard=None, limit=None, predictor="secant", starts="warm", disagreement=None, sensitivities=false, tolerance=1e-8, max_steps=2000, time_limit=None, crossings=None, inertia=true, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn sample<'py>(
    py: Python<'py>,
    pattern: &Bound<'py, PyAny>,
    out: PathBuf,
    plan: Option<&Bound<'py, PyAny>>,
    yarn: Option<&Bound<'py, PyAny>>,
    cold: bool,
    shard: Option<ShardArg>,
    limit: Option<usize>,
    predictor: &str,
    starts: &str,
    disagreement: Option<f64>,
    sensitivities: bool,
    tolerance: f64,
    max_steps: usize,
    time_limit: Option<f64>,
    crossings: Option<&str>,
    inertia: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let plan = match plan {
        Some(obj) => plan_of(obj)?,
        None => Plan::default(),
    };
    let shard = shard.map(ShardArg::parse).transpose()?;
    let predictor = choice(
        "predictor",
        predictor,
        &[("secant", Predictor::Secant), ("none", Predictor::None)],
    )?;
    let starts = choice(
        "starts",
        starts,
        &[
            ("warm", Starts::Warm),
            ("warm+cold", Starts::WarmCold),
            ("all", Starts::All),
        ],
    )?;
    let options = solver_options(tolerance, max_steps, time_limit, crossings, inertia, starts)?;
    let p = pattern_of(pattern)?;
    let yarn = yarn_of(yarn)?;
    let progress = callback(progress)?;
    let opts = RunOptions {
        cold,
        shard,
        limit,
        predictor,
        starts,
        disagreement,
        sensitivities,
    };
    let s = interruptible(py, progress.as_ref(), |m| {
        let problem = MicroProblem::new(p.inner.clone(), &yarn, options);
        write_meta(&out, &p.source, &plan, &problem)?;
        let report = |done, total| m.report(done, total);
        Ok(run_plan_until(
            &problem,
            &plan,
            &out,
            &opts,
            &report,
            m.cancel_flag(),
        )?)
    })?;
    let d = PyDict::new(py);
    d.set_item("plan_hash", format!("{:016x}", plan.hash()))?;
    d.set_item("selected", s.selected)?;
    d.set_item("already_done", s.already_done)?;
    d.set_item("written", s.written)?;
    d.set_item("converged", s.converged)?;
    d.set_item("replayed", s.replayed)?;
    d.set_item("sensitivities", s.sensitivities)?;
    d.set_item("lacking_sensitivities", s.lacking_sensitivities)?;
    d.set_item("sensitivities_added", s.sensitivities_added)?;
    d.set_item("time", s.time)?;
    Ok(d)
}
