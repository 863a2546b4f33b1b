//! The runner: one OBJ per frame, one JSON line per step, and the reactions of the held sets as a table.

use super::*;

/// Summary of a run.
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    /// steps taken
    pub steps: usize,
    /// triangles of the mesh
    pub triangles: usize,
    /// vertices of the mesh
    pub vertices: usize,
    /// Newton iterations over all steps
    pub newton_total: usize,
    /// most Newton iterations of one step
    pub newton_max: usize,
    /// steps reported as not converged (0: a step that cannot converge ends the run with an error)
    pub unconverged_steps: usize,
    /// largest residual force at the end of a step (N)
    pub max_residual: f64,
    /// wall time of the run (s)
    pub wall: f64,
    /// the last step's report
    pub last: Option<StepReport>,
}

/// [`run_with`] writing OBJ frames only, every `obj_every` steps (0: none).
pub fn run(
    sim: &mut Simulation,
    tris: &[[usize; 3]],
    steps: usize,
    obj_every: usize,
    out: Option<&Path>,
    progress: impl FnMut(&StepReport),
) -> Result<RunSummary, ShellError> {
    let output = OutputSpec {
        obj_every,
        vtu: false,
    };
    run_with(sim, tris, steps, &output, out, progress)
}

/// Run a built simulation for `steps` steps, writing to `out` (when given): `frame_NNNN.obj` (frame 0 the initial
/// state, a comment header with hylc's version, commit, command line and the frame's time) every
/// `output.obj_every` steps (and `frame_NNNN.vtu` beside it and the series `frames.pvd` with `output.vtu`,
/// [`crate::shell::vtu`]), `provenance.json` (hylc's version and commit, the command line), one JSON line per
/// step to `log.jsonl` and, when the scene holds vertices, the reaction of every held set per step to
/// `handle_forces.csv` (columns `time`, then `NAME_fx`, `NAME_fy`, `NAME_fz`, `NAME_norm` per set, N).
/// `progress` is called after every step.
pub fn run_with(
    sim: &mut Simulation,
    tris: &[[usize; 3]],
    steps: usize,
    output: &OutputSpec,
    out: Option<&Path>,
    mut progress: impl FnMut(&StepReport),
) -> Result<RunSummary, ShellError> {
    run_until(sim, tris, steps, output, out, |r| {
        progress(r);
        true
    })
}

/// [`run_with`] that stops early when `progress` returns false (e.g. on Ctrl-C): the steps done so far are in the
/// files, which are flushed, and the summary's `steps` counts them.
pub fn run_until(
    sim: &mut Simulation,
    tris: &[[usize; 3]],
    steps: usize,
    output: &OutputSpec,
    out: Option<&Path>,
    mut progress: impl FnMut(&StepReport) -> bool,
) -> Result<RunSummary, ShellError> {
    let io = |e: std::io::Error, what: &Path| ShellError::io(what, "cannot write", e);
    let mut frames = Frames::new(output.vtu);
    let mut forces = match out {
        Some(dir) if sim.held_set_names().next().is_some() => {
            let f = dir.join("handle_forces.csv");
            std::fs::create_dir_all(dir)
                .map_err(|e| ShellError::io(dir, "cannot create the folder", e))?;
            let mut w = std::io::BufWriter::new(std::fs::File::create(&f).map_err(|e| io(e, &f))?);
            let mut head = String::from("time");
            for n in sim.held_set_names() {
                for c in ["fx", "fy", "fz", "norm"] {
                    head.push_str(&format!(",{n}_{c}"));
                }
            }
            writeln!(w, "{head}").map_err(|e| io(e, &f))?;
            Some((w, f))
        }
        _ => None,
    };
    let mut log = match out {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .map_err(|e| ShellError::io(dir, "cannot create the folder", e))?;
            let f = dir.join("provenance.json");
            let text = serde_json::to_string_pretty(&frames.provenance.to_json())
                .expect("a JSON value serialises");
            std::fs::write(&f, text).map_err(|e| io(e, &f))?;
            if output.obj_every > 0 {
                frames
                    .write(sim, tris, dir, 0)
                    .map_err(|(e, f)| io(e, &f))?;
            }
            let f = dir.join("log.jsonl");
            Some((
                std::io::BufWriter::new(std::fs::File::create(&f).map_err(|e| io(e, &f))?),
                f,
            ))
        }
        None => None,
    };
    let start = std::time::Instant::now();
    let mut sum = RunSummary {
        steps,
        triangles: sim.stencils.len(),
        vertices: sim.pattern.n,
        newton_total: 0,
        newton_max: 0,
        unconverged_steps: 0,
        max_residual: 0.0,
        wall: 0.0,
        last: None,
    };
    for k in 1..=steps {
        let r = sim.step()?;
        sum.newton_total += r.newton;
        sum.newton_max = sum.newton_max.max(r.newton);
        sum.unconverged_steps += usize::from(!r.converged);
        sum.max_residual = sum.max_residual.max(r.residual);
        if let (Some(dir), Some((w, f))) = (out, log.as_mut()) {
            let line = serde_json::to_string(&r).expect("a step report serialises");
            writeln!(w, "{line}").map_err(|e| io(e, f))?;
            if let Some((w, f)) = forces.as_mut() {
                let mut row = format!("{}", r.time);
                for (_, v) in &r.handle_forces {
                    let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    row.push_str(&format!(",{},{},{},{norm}", v[0], v[1], v[2]));
                }
                writeln!(w, "{row}").map_err(|e| io(e, f))?;
            }
            if output.obj_every > 0 && k % output.obj_every == 0 {
                frames
                    .write(sim, tris, dir, k)
                    .map_err(|(e, f)| io(e, &f))?;
            }
        }
        let go_on = progress(&r);
        sum.last = Some(r);
        if !go_on {
            sum.steps = k;
            break;
        }
    }
    for (mut w, f) in log.into_iter().chain(forces) {
        w.flush().map_err(|e| io(e, &f))?;
    }
    sum.wall = start.elapsed().as_secs_f64();
    Ok(sum)
}

/// The frames of a run: `frame_k.obj` with a provenance header, and with `vtu` also `frame_k.vtu` and the
/// collection `frames.pvd` of every VTU so far with its time (rewritten after each frame, so that a run that
/// stops early leaves a valid series).
struct Frames {
    vtu: bool,
    /// the run's provenance record (also `provenance.json`)
    provenance: crate::provenance::Provenance,
    header: String,
    series: Vec<(f64, String)>,
}

impl Frames {
    fn new(vtu: bool) -> Frames {
        let p = crate::provenance::Provenance::now();
        Frames {
            vtu,
            header: format!(
                "hylc {} (commit {}): {}",
                p.hylc,
                p.commit,
                p.command.join(" ")
            ),
            provenance: p,
            series: vec![],
        }
    }

    /// Frame `k` of the current state; the error with the file it was about.
    fn write(
        &mut self,
        sim: &Simulation,
        tris: &[[usize; 3]],
        dir: &Path,
        k: usize,
    ) -> Result<(), (std::io::Error, std::path::PathBuf)> {
        let f = dir.join(format!("frame_{k:04}.obj"));
        let header = format!("{}\nt = {} s", self.header, sim.time);
        write_obj(&f, &header, &sim.positions(), tris).map_err(|e| (e, f))?;
        if self.vtu {
            let name = format!("frame_{k:04}.vtu");
            let f = dir.join(&name);
            sim.write_vtu(&f, tris).map_err(|e| (e, f))?;
            self.series.push((sim.time, name));
            let f = dir.join("frames.pvd");
            crate::shell::vtu::write_pvd(&f, &self.series).map_err(|e| (e, f))?;
        }
        Ok(())
    }
}
