//! `hylc simulate SCENE`: run a cloth scene (a JSON file or a built-in; `hylc::shell::scene`) with a progress
//! bar, writing an OBJ per frame, a JSON-lines log per step and a PNG snapshot of the final state.

use hylc::shell::render::{sphere_mesh, write_png, Layer, View};
use hylc::shell::scene::{run, RunSummary, Scene};
use hylc::shell::solver::Obstacle;
use hylc::shell::Psd;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Command-line overrides of a scene.
pub struct Overrides {
    pub material: Option<String>,
    pub duration: Option<f64>,
    pub dt: Option<f64>,
    pub edge: Option<f64>,
    pub psd: Option<String>,
    pub no_bending: bool,
    pub only_1d: bool,
    pub in_plane_only: bool,
    pub quiet: bool,
    pub print: bool,
}

/// The scene after the command-line overrides, with the folder its relative paths start from.
pub fn prepare(scene_arg: &str, ov: &Overrides) -> Result<(Scene, PathBuf), String> {
    let (mut scene, dir) = Scene::load(scene_arg).map_err(|e| e.to_string())?;
    if let Some(m) = &ov.material {
        // a path given on the command line is relative to the working directory
        scene.material = if m == "default" {
            m.clone()
        } else {
            std::fs::canonicalize(m)
                .map_err(|e| format!("--material {m}: {e}"))?
                .display()
                .to_string()
        };
    }
    if let Some(d) = ov.duration {
        scene.duration = d;
    }
    if let Some(dt) = ov.dt {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(format!("--dt {dt}: expected a positive step (s)"));
        }
        scene.dt = dt;
    }
    if let Some(e) = ov.edge {
        match &mut scene.mesh {
            hylc::shell::scene::MeshSpec::Rectangle { edge, .. } => *edge = e,
            _ => return Err("--edge applies to rectangle meshes only".into()),
        }
    }
    if let Some(p) = &ov.psd {
        scene.psd = match p.as_str() {
            "full" => Psd::Full,
            "psi" => Psd::Psi,
            "none" => Psd::None,
            _ => return Err(format!("--psd: expected full, psi or none, got {p:?}")),
        };
    }
    scene.model.bending &= !ov.no_bending;
    scene.model.only_1d |= ov.only_1d;
    scene.model.in_plane_only |= ov.in_plane_only;
    Ok((scene, dir))
}

/// The end state of a simulation: its summary, the final positions and the triangles.
pub struct Outcome {
    pub summary: RunSummary,
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[usize; 3]>,
}

/// Build and run a scene with a progress bar (hidden when `quiet`), writing the frames and the log to `out`.
pub fn execute(
    scene: &Scene,
    scene_arg: &str,
    dir: &Path,
    out: &Path,
    quiet: bool,
) -> Result<Outcome, String> {
    let (mut sim, tris) = scene.build(scene_arg, dir).map_err(|e| e.to_string())?;
    let steps = scene.steps();
    println!(
        "scene {scene_arg}: {} triangles, {} vertices, {} free dofs, {} steps of {:.4} s{}; output in {}",
        tris.len(),
        sim.pattern.n,
        3 * sim.pattern.nfree,
        steps,
        scene.dt,
        if scene.quasi_static { " (quasi-static)" } else { "" },
        out.display()
    );
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(steps as u64)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} steps, {elapsed} elapsed, eta {eta} {msg}",
        )
        .expect("valid template"),
    );
    let summary = run(
        &mut sim,
        &tris,
        steps,
        scene.output.obj_every,
        Some(out),
        |r| {
            bar.set_message(format!(
                "t = {:.3} s, {} Newton, residual {:.1e} N",
                r.time, r.newton, r.residual
            ));
            bar.inc(1);
        },
    )
    .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    Ok(Outcome {
        summary,
        positions: sim.positions(),
        triangles: tris,
    })
}

/// Write a PNG snapshot of the cloth (blue-grey) with the scene's sphere obstacles (light grey).
pub fn snapshot(path: &Path, scene: &Scene, o: &Outcome) -> Result<(), String> {
    let spheres: Vec<_> = scene
        .obstacles
        .iter()
        .filter_map(|ob| match ob {
            Obstacle::Sphere { center, radius } => Some(sphere_mesh(*center, *radius, 48)),
            Obstacle::Plane { .. } => None,
        })
        .collect();
    let mut layers = vec![Layer {
        positions: &o.positions,
        triangles: &o.triangles,
        color: [70, 110, 170],
    }];
    for (x, t) in &spheres {
        layers.push(Layer {
            positions: x,
            triangles: t,
            color: [215, 215, 205],
        });
    }
    write_png(path, &layers, &View::default())
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

/// `hylc simulate`.
pub fn run_cmd(scene_arg: &str, out: &Path, ov: &Overrides) -> Result<ExitCode, String> {
    let (scene, dir) = prepare(scene_arg, ov)?;
    if ov.print {
        println!(
            "{}",
            serde_json::to_string_pretty(&scene).expect("scenes serialise")
        );
        return Ok(ExitCode::SUCCESS);
    }
    let o = execute(&scene, scene_arg, &dir, out, ov.quiet)?;
    println!("{}", summary_line(&o.summary));
    if let Some(r) = &o.summary.last {
        for (name, f) in &r.handle_forces {
            println!(
                "handle {name}: force [{:.5}, {:.5}, {:.5}] N at t = {:.3} s",
                f[0], f[1], f[2], r.time
            );
        }
        println!(
            "final energies: elastic {:.4e} J, kinetic {:.4e} J, gravity {:.4e} J, obstacles {:.4e} J",
            r.energy_elastic, r.energy_kinetic, r.energy_gravity, r.energy_obstacles
        );
    }
    let png = out.join("snapshot.png");
    snapshot(&png, &scene, &o)?;
    println!("wrote {} (the final state)", png.display());
    Ok(ExitCode::SUCCESS)
}
