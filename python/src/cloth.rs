//! Cloth scenes (Algorithm C8, `hylc simulate`): run a scene file or built-in and return its step log as arrays
//! and its final state.

use crate::arrays::to_2d;
use crate::errors::{detached, HyError};
use hylc::shell::scene::run_with;
use hylc::shell::solver::StepReport;
use hylc::workflow::simulate::{prepare, Overrides, TimeTol};
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

/// Run a cloth scene (a scene JSON file, an ARCSim scene file or a built-in: stretch-x, stretch-y, drape-x,
/// drape-y, hanging) as `hylc simulate` does, with its overrides. With `out`, the frames (`frame_NNNN.obj`) and
/// `log.jsonl` are written there as well. Returns a dict: the step log as (steps,) arrays (`step`, `time`,
/// `newton`, `residual`, energies, …; `strain_*` (steps, 6); `handle_forces` name → (steps, 3)), `positions`
/// (vertices, 3) and `triangles` (triangles, 3) of the final state, and `summary` (steps, Newton iterations,
/// wall time). `time_tol` (m) chooses substeps by their estimated error, as the scene's `solver.time_tol`, and
/// `"off"` turns that off. A step that fails even at the smallest substep raises `SimulationError`.
#[pyfunction]
#[pyo3(signature = (scene, out=None, material=None, duration=None, dt=None, edge=None, time_tol=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    scene: &str,
    out: Option<PathBuf>,
    material: Option<String>,
    duration: Option<f64>,
    dt: Option<f64>,
    edge: Option<f64>,
    time_tol: Option<TolArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let time_tol = time_tol.map(TolArg::parse).transpose()?;
    let ov = Overrides {
        material,
        duration,
        dt,
        edge,
        time_tol,
        ..Default::default()
    };
    let path = std::path::Path::new(scene);
    if path.extension().is_some() && !path.exists() {
        return Err(HyError::new(
            crate::errors::Kind::NotFound,
            format!("scene: {scene}: no such scene file"),
        )
        .into());
    }
    let (log, summary, positions, triangles) = detached(py, || {
        let (sc, dir) = prepare(scene, &ov)?;
        let (mut sim, tris) = sc.build(scene, &dir).map_err(HyError::from)?;
        let mut log = Vec::new();
        let summary = run_with(
            &mut sim,
            &tris,
            sc.steps(),
            &sc.output,
            out.as_deref(),
            |r| log.push(r.clone()),
        )?;
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
