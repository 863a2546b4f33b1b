//! A cloth scene (Algorithm C8; `docs/cloth-simulator.md`, `crate::shell::scene`) with command-line style overrides: its
//! frames (`frame_NNNN.obj`), its step log (`log.jsonl`) and a PNG snapshot of the final state.

use super::warnings::{coarse_mesh, StrainVisits};
use super::{Event, WorkflowError};
use crate::shell::render::{write_png, Layer, View};
use crate::shell::scene::{run_with, MeshSpec, RunSummary, Scene};
use crate::shell::{Psd, ShellError};
use std::path::{Path, PathBuf};

/// Overrides of a scene's settings (each `None`/`false` keeps the scene's).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// A material file (relative to the working directory) or `default`.
    pub material: Option<String>,
    /// The scene's duration (s).
    pub duration: Option<f64>,
    /// The scene's time step (s).
    pub dt: Option<f64>,
    /// `solver.time_tol`: the largest estimated local error of a substep, or off.
    pub time_tol: Option<TimeTol>,
    /// The scheme of a substep, `solver.integrator`.
    pub integrator: Option<crate::shell::solver::Integrator>,
    /// Equal substeps per step, `solver.substeps`.
    pub substeps: Option<u32>,
    /// The edge length of a rectangle mesh.
    pub edge: Option<f64>,
    /// The PSD option of the element Hessians.
    pub psd: Option<Psd>,
    /// Turn bending off (`model.bending = false`).
    pub no_bending: bool,
    /// Keep only the 1D terms of ψ (`model.only_1d`).
    pub only_1d: bool,
    /// Keep only the in-plane terms of ψ (`model.in_plane_only`).
    pub in_plane_only: bool,
    /// also a `.vtu` frame (ψ and the strain per triangle) beside each OBJ, `output.vtu`
    pub vtu: bool,
}

/// How substeps are chosen (`docs/cloth-simulator.md`, "Substeps chosen by accuracy"): by their estimated local
/// error, at most `Metres(τ)`, or `Off` (they shorten only when Newton fails). Read from `off` or a length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeTol {
    /// No tolerance: substeps shorten only when Newton fails.
    Off,
    /// The largest estimated local error of a substep (m).
    Metres(f64),
}

impl std::str::FromStr for TimeTol {
    type Err = String;

    fn from_str(s: &str) -> Result<TimeTol, String> {
        if s == "off" {
            return Ok(TimeTol::Off);
        }
        match s.parse::<f64>() {
            Ok(t) if t.is_finite() && t > 0.0 => Ok(TimeTol::Metres(t)),
            _ => Err(format!(
                "expected a positive length (m) or `off`, got `{s}`"
            )),
        }
    }
}

/// The scene `scene_arg` (a JSON file or a built-in) after the overrides, with the folder its relative paths
/// start from. An ARCSim scene file is converted (docs/arcsim.md; [`crate::shell::arcsim`]); its conversion warnings are
/// dropped here ([`prepare_noted`] reports them).
pub fn prepare(scene_arg: &str, ov: &Overrides) -> Result<(Scene, PathBuf), WorkflowError> {
    prepare_noted(scene_arg, ov, &mut |_| {})
}

/// [`prepare`], reporting the warnings of an ARCSim scene's conversion (docs/arcsim.md: one line per ignored or unknown
/// key) as [`Event::Note`]s.
pub fn prepare_noted(
    scene_arg: &str,
    ov: &Overrides,
    on_event: &mut dyn FnMut(Event),
) -> Result<(Scene, PathBuf), WorkflowError> {
    let (mut scene, dir, warnings) = crate::shell::arcsim::load_scene(scene_arg)?;
    for w in &warnings {
        on_event(Event::Note(w));
    }
    override_scene(&mut scene, ov, on_event)?;
    Ok((scene, dir))
}

/// Apply the overrides `ov` to a loaded scene (as [`prepare_noted`] does after loading; for a scene built in memory,
/// e.g. from a JSON value), reporting a duration of 0 as an [`Event::Note`].
pub fn override_scene(
    scene: &mut Scene,
    ov: &Overrides,
    on_event: &mut dyn FnMut(Event),
) -> Result<(), WorkflowError> {
    if let Some(m) = &ov.material {
        // a path given on the command line is relative to the working directory
        scene.material = if m == "default" {
            m.clone()
        } else {
            std::fs::canonicalize(m)
                .map_err(|e| WorkflowError::Input(format!("--material {m}: {e}")))?
                .display()
                .to_string()
        };
    }
    if let Some(d) = ov.duration {
        scene.duration = d;
    }
    if let Some(dt) = ov.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(WorkflowError::Input(format!(
                "--dt {dt}: expected a positive step (s)"
            )));
        }
        scene.dt = dt;
    }
    match ov.time_tol {
        Some(TimeTol::Metres(tol)) if !(tol.is_finite() && tol > 0.0) => {
            return Err(WorkflowError::Input(format!(
                "--time-tol {tol}: expected a positive length (m) or `off`"
            )));
        }
        Some(TimeTol::Metres(tol)) => scene.solver.time_tol = Some(tol),
        Some(TimeTol::Off) => scene.solver.time_tol = None,
        None => {}
    }
    if let Some(i) = ov.integrator {
        scene.solver.integrator = i;
    }
    if let Some(k) = ov.substeps {
        if k == 0 {
            return Err(WorkflowError::Input(
                "--substeps 0: expected at least one substep per step".into(),
            ));
        }
        scene.solver.substeps = k;
    }
    if let Some(e) = ov.edge {
        match &mut scene.mesh {
            MeshSpec::Rectangle { edge, .. } => *edge = e,
            _ => {
                return Err(WorkflowError::Input(
                    "--edge applies to rectangle meshes only".into(),
                ))
            }
        }
    }
    if let Some(p) = ov.psd {
        scene.psd = p;
    }
    scene.model.bending &= !ov.no_bending;
    scene.model.only_1d |= ov.only_1d;
    scene.model.in_plane_only |= ov.in_plane_only;
    scene.output.vtu |= ov.vtu;
    if scene.duration == 0.0 {
        on_event(Event::Note(
            "warning: duration 0 s: no step is simulated, only frame 0 (the initial state) is written",
        ));
    }
    Ok(())
}

/// The end state of a simulation: its summary, the final positions and the triangles.
pub struct Outcome {
    /// the run's summary
    pub summary: RunSummary,
    /// the final vertex positions (m)
    pub positions: Vec<[f64; 3]>,
    /// the mesh's triangles
    pub triangles: Vec<[usize; 3]>,
    /// the obstacles' surfaces (spheres and meshes; planes have none), for pictures
    pub obstacles: Vec<crate::shell::mesh::Surface>,
}

/// Build and run a scene, writing the frames and the log to `out`; reports the scene as an [`Event::Print`]
/// line and every step as an [`Event::Step`], and as [`Event::Note`]s a mesh too coarse to bend before the run
/// ([`super::warnings::coarse_mesh`]) and strains outside the material's knots after it
/// ([`super::warnings::StrainVisits`]).
pub fn execute(
    scene: &Scene,
    scene_arg: &str,
    dir: &Path,
    out: &Path,
    on_event: &mut (dyn FnMut(Event) + Send),
) -> Result<Outcome, WorkflowError> {
    let (mut sim, tris) = scene.build(scene_arg, dir)?;
    let steps = scene.steps();
    if let Some(w) = coarse_mesh(&sim.positions(), &tris) {
        on_event(Event::Note(&w.to_string()));
    }
    on_event(Event::Print(&format!(
        "scene {scene_arg}: {} triangles, {} vertices, {} free dofs, {} steps of {:.4} s{}; output in {}",
        tris.len(),
        sim.pattern.n,
        3 * sim.pattern.nfree,
        steps,
        scene.dt,
        if scene.quasi_static { " (quasi-static)" } else { "" },
        out.display()
    )));
    let mut visits = StrainVisits::new(&sim.model);
    let summary = run_reporting(
        &mut sim,
        &tris,
        steps,
        &scene.output,
        Some(out),
        Some(&mut visits),
        on_event,
    )?;
    if let Some(w) = visits.warning(Some(&out.join("log.jsonl"))) {
        on_event(Event::Note(&w.to_string()));
    }
    Ok(Outcome {
        summary,
        positions: sim.positions(),
        triangles: tris,
        obstacles: sim.obstacle_surfaces(),
    })
}

/// [`run_with`] reporting every step as an [`Event::Step`], and adding it to `visits` when given.
pub(crate) fn run_reporting(
    sim: &mut crate::shell::solver::Simulation,
    tris: &[[usize; 3]],
    steps: usize,
    output: &crate::shell::scene::OutputSpec,
    out: Option<&Path>,
    mut visits: Option<&mut StrainVisits>,
    on_event: &mut (dyn FnMut(Event) + Send),
) -> Result<RunSummary, ShellError> {
    let mut done = 0;
    run_with(sim, tris, steps, output, out, |r| {
        done += 1;
        if let Some(v) = visits.as_deref_mut() {
            v.add(r);
        }
        on_event(Event::Step {
            done,
            total: steps,
            time: r.time,
            newton: r.newton,
            residual: r.residual,
        });
    })
}

/// Write a PNG snapshot of the cloth (blue-grey) with the obstacles' surfaces (light grey).
pub fn snapshot(path: &Path, o: &Outcome) -> Result<(), WorkflowError> {
    let mut layers = vec![Layer {
        positions: &o.positions,
        triangles: &o.triangles,
        color: [70, 110, 170],
    }];
    for (x, t) in &o.obstacles {
        layers.push(Layer {
            positions: x,
            triangles: t,
            color: [215, 215, 205],
        });
    }
    Ok(write_png(path, &layers, &View::default())?)
}

/// Whether `e` is a simulation that diverged (a non-finite residual or energy, [`ShellError::NonFiniteState`]) or
/// a step that did not converge at the smallest substep ([`ShellError::StepFailed`]):
/// the computation did not converge (exit code 3), as opposed to bad input (exit code 2).
pub fn diverged(e: &WorkflowError) -> bool {
    matches!(
        e,
        WorkflowError::Shell(ShellError::NonFiniteState { .. } | ShellError::StepFailed { .. })
    )
}

/// One-line summary of a finished run.
pub fn summary_line(s: &RunSummary) -> String {
    format!(
        "{} steps in {:.2} s wall ({:.3} s per step); Newton iterations: {} total, {} at most; {} steps not converged; largest final residual {:.2e} N",
        s.steps,
        s.wall,
        s.wall / s.steps.max(1) as f64,
        s.newton_total,
        s.newton_max,
        s.unconverged_steps,
        s.max_residual
    )
}
