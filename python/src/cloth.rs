//! Cloth scenes (Algorithm C8, `hylc simulate`): run a scene file, built-in or dict and return its step log as
//! arrays and its final state.

use crate::arrays::to_2d;
use crate::errors::HyError;
use crate::progress::{callback, interruptible};
use crate::scene::SceneArg;
use hylc::shell::scene::run_until;
use hylc::shell::solver::StepReport;
use hylc::workflow::simulate::{Overrides, TimeTol};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// The columns of the step log as (N,) arrays.
fn log_columns<'py>(py: Python<'py>, log: &[StepReport], d: &Bound<'py, PyDict>) -> PyResult<()> {
    let col = |f: &dyn Fn(&StepReport) -> f64| PyArray1::from_vec(py, log.iter().map(f).collect());
    d.set_item("step", col(&|r| r.step as f64))?;
    d.set_item("time", col(&|r| r.time))?;
    d.set_item("newton", col(&|r| r.newton as f64))?;
    d.set_item("substeps", col(&|r| r.substeps as f64))?;
    d.set_item("dt_min", col(&|r| r.dt_min))?;
    d.set_item("rejected", col(&|r| r.rejected as f64))?;
    d.set_item("error_estimate", col(&|r| r.error_estimate))?;
    d.set_item("residual", col(&|r| r.residual))?;
    d.set_item("energy_elastic", col(&|r| r.energy_elastic))?;
    d.set_item("energy_kinetic", col(&|r| r.energy_kinetic))?;
    d.set_item("energy_gravity", col(&|r| r.energy_gravity))?;
    d.set_item("energy_obstacles", col(&|r| r.energy_obstacles))?;
    d.set_item("shift", col(&|r| r.shift))?;
    d.set_item("wall", col(&|r| r.wall))?;
    let rows =
        |f: &dyn Fn(&StepReport) -> [f64; 6]| to_2d(py, &log.iter().map(f).collect::<Vec<_>>());
    d.set_item("strain_min", rows(&|r| r.strain_min))?;
    d.set_item("strain_max", rows(&|r| r.strain_max))?;
    d.set_item("strain_p01", rows(&|r| r.strain_p01))?;
    d.set_item("strain_p99", rows(&|r| r.strain_p99))?;
    let handles = PyDict::new(py);
    for (k, (name, _)) in log
        .first()
        .map_or(&[][..], |r| &r.handle_forces[..])
        .iter()
        .enumerate()
    {
        let f: Vec<[f64; 3]> = log.iter().map(|r| r.handle_forces[k].1).collect();
        handles.set_item(name, to_2d(py, &f))?;
    }
    d.set_item("handle_forces", handles)?;
    Ok(())
}

/// `time_tol` as Python gives it: a length or the word `off`.
#[derive(FromPyObject)]
pub enum TolArg {
    Metres(f64),
    Word(String),
}

impl TolArg {
    fn parse(self) -> PyResult<TimeTol> {
        let text = match self {
            TolArg::Metres(t) => t.to_string(),
            TolArg::Word(w) => w,
        };
        text.parse::<TimeTol>()
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(format!("time_tol: {e}")))
    }
}

/// Run a cloth scene as ``hylc simulate`` does, with its overrides.
///
/// Parameters
/// ----------
/// scene : str, path-like or dict
///     A scene JSON file, an ARCSim scene file, a built-in (``stretch-x``, ``stretch-y``, ``drape-x``,
///     ``drape-y``, ``hanging``) or a dict with the scene JSON's layout (:func:`load_scene` gives one; its
///     relative paths start from the working directory).
/// out : path-like, optional
///     A folder for the frames (``frame_NNNN.obj``), ``log.jsonl``, ``handle_forces.csv`` and
///     ``provenance.json``; nothing is written without it.
/// material : str, optional
///     A material file (relative to the working directory) or ``"default"`` instead of the scene's.
/// duration, dt : float, optional
///     The simulated time and the step (s) instead of the scene's.
/// edge : float, optional
///     The edge length (m) of a rectangle mesh.
/// time_tol : float or "off", optional
///     The largest estimated local error (m) of a substep (the scene's ``solver.time_tol``); ``"off"`` makes
///     substeps shorten only when Newton fails.
/// vtu : bool, default False
///     Also a ``frame_NNNN.vtu`` beside each OBJ frame and the series ``frames.pvd`` (``--format vtu``).
/// progress : callable, optional
///     ``progress(done, total)`` with the time steps done of the scene's, called from the calling thread
///     (GIL held) with the latest counts at most every 0.05 s and after the last step. An exception it raises
///     stops the run after the step in flight and is raised.
///
/// Returns
/// -------
/// SimulationResult
///     The step log as (steps,) arrays (``step``, ``time``, ``newton``, ``substeps``, ``dt_min``,
///     ``rejected``, ``error_estimate``, ``residual``, ``energy_*``, ``shift``, ``wall``), ``strain_min``,
///     ``strain_max``, ``strain_p01``, ``strain_p99`` (steps, 6), ``handle_forces`` (name → (steps, 3) N),
///     ``positions`` (vertices, 3) and ``triangles`` (triangles, 3, int64) of the final state, and ``summary``
///     (steps, triangles, vertices, Newton iterations, largest residual, wall time).
///
/// Raises
/// ------
/// FileNotFoundError
///     A scene file that does not exist.
/// ValueError
///     A bad override (``dt``, ``time_tol``, ``edge`` of a mesh file).
/// SimulationError
///     A scene that is not valid, or a step that fails even at the smallest substep.
/// KeyboardInterrupt
///     Ctrl-C during the run (noticed within 0.05 s; the run stops after the step in flight, the files written
///     so far stay complete).
#[pyfunction]
#[pyo3(signature = (scene, out=None, material=None, duration=None, dt=None, edge=None, time_tol=None, vtu=false, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    out: Option<PathBuf>,
    material: Option<String>,
    duration: Option<f64>,
    dt: Option<f64>,
    edge: Option<f64>,
    time_tol: Option<TolArg>,
    vtu: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let time_tol = time_tol.map(TolArg::parse).transpose()?;
    let ov = Overrides {
        material,
        duration,
        dt,
        edge,
        time_tol,
        vtu,
        ..Default::default()
    };
    let arg = SceneArg::of(scene)?;
    let progress = callback(progress)?;
    let (log, summary, positions, triangles) = interruptible(py, progress.as_ref(), |m| {
        let (sc, dir) = arg.prepare(&ov)?;
        let (mut sim, tris) = sc.build(arg.label(), &dir).map_err(HyError::from)?;
        let steps = sc.steps();
        m.report(0, steps);
        let mut log = Vec::new();
        let summary = run_until(&mut sim, &tris, steps, &sc.output, out.as_deref(), |r| {
            log.push(r.clone());
            m.report(log.len(), steps);
            !m.cancelled()
        })?;
        Ok((log, summary, sim.positions(), tris))
    })?;
    let d = PyDict::new(py);
    log_columns(py, &log, &d)?;
    d.set_item("positions", to_2d(py, &positions))?;
    let tri: Vec<[f64; 3]> = triangles.iter().map(|t| t.map(|i| i as f64)).collect();
    let tri: Bound<'py, PyArray2<f64>> = to_2d(py, &tri);
    d.set_item("triangles", tri.call_method1("astype", ("int64",))?)?;
    let s = PyDict::new(py);
    s.set_item("steps", summary.steps)?;
    s.set_item("triangles", summary.triangles)?;
    s.set_item("vertices", summary.vertices)?;
    s.set_item("newton_total", summary.newton_total)?;
    s.set_item("newton_max", summary.newton_max)?;
    s.set_item("unconverged_steps", summary.unconverged_steps)?;
    s.set_item("max_residual", summary.max_residual)?;
    s.set_item("wall", summary.wall)?;
    d.set_item("summary", s)?;
    Ok(d)
}
