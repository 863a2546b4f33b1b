//! The main job end to end (`docs/layout.md`, "Command line"; the pipeline of
//! `../shared/seed/hylc_pseudocode.txt`, C1 → C4 → C5–C7 → C8). For each pattern: generate it, compute its
//! reference state (C1), run a sampling plan and a small held-out in-plane grid (C4), fit the material
//! (C5–C7), and drape a cloth with it (C8); report a per-stage summary and write everything to one folder.
//!
//! Long work resumes: a rerun with the same folder reuses the reference state and skips finished samples
//! (`fresh` starts over).

use super::fit::{fit_samples, FitJob};
use super::inputs::{construction_of, load_pattern, load_plan};
use super::sidecar::{meta_path, write_meta};
use super::simulate::{execute, prepare_noted, snapshot, summary_line, Outcome, Overrides};
use super::{write_file, Event, WorkflowError};
use crate::fit::model::{FitOptions, FitReport};
use crate::micro::reference::{reference_state, Construction, ReferenceOptions};
use crate::micro::{CrossingGuard, MicroProblem, SolverOptions};
use crate::pattern::Pattern;
use crate::rod::YarnMaterial;
use crate::sample::plan::{fnv1a64, InPlaneGrid};
use crate::sample::run::problem_hash;
use crate::sample::{read_samples, run_plan_with, Plan, RunOptions, RunSummary};
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// Settings of the main job (`hylc run`).
#[derive(Clone, Debug)]
pub struct RunConfig {
    /// The output folder.
    pub out: PathBuf,
    /// Generated kinds or `.pyp` files.
    pub patterns: Vec<String>,
    /// `quick`, `reduced`, `default` or a plan file.
    pub plan: String,
    /// A built-in scene or a scene file.
    pub scene: String,
    /// Edge length (m) of the scene's rectangle mesh.
    pub edge: Option<f64>,
    /// Simulated time (s) instead of the scene's.
    pub duration: Option<f64>,
    /// Time step of the cloth simulation (s).
    pub dt: f64,
    /// Delete the output folder first instead of resuming.
    pub fresh: bool,
    /// The construction of `.pyp` patterns (generated kinds know theirs).
    pub construction: Option<Construction>,
    /// The yarn parameters of every solve (reference state, sampling, held-out grid); `hylc run --yarn FILE`.
    pub yarn: YarnMaterial,
    /// The fit's settings ([`FitOptions::covering`] by default).
    pub fit: FitOptions,
}

impl Default for RunConfig {
    /// The defaults of `hylc run`: the generated stockinette, the quick plan, the `drape-x` scene at 1 cm edges
    /// and 1/60 s (adaptive substeps inside), in `out/run`.
    fn default() -> Self {
        RunConfig {
            out: PathBuf::from("out/run"),
            patterns: vec!["stockinette".into()],
            plan: "quick".into(),
            scene: "drape-x".into(),
            edge: Some(0.01),
            duration: None,
            dt: 1.0 / 60.0,
            fresh: false,
            construction: None,
            yarn: YarnMaterial::default(),
            fit: FitOptions::covering(),
        }
    }
}

/// The held-out check of the main job: 27 in-plane points off the sampled planes (every other interior value of
/// the original 9×9×9 grid: s_x, s_y ∈ {−0.1, 1/6, 1/2}, s_a ∈ {−0.35, 0, 0.35}).
pub fn run_holdout_plan() -> Plan {
    let g = InPlaneGrid::original();
    let pick = |v: &[f64]| vec![v[1], v[3], v[5]];
    Plan {
        grid: Some(InPlaneGrid {
            s_x: pick(&g.s_x),
            s_a: vec![g.s_a[2], g.s_a[4], g.s_a[6]],
            s_y: pick(&g.s_y),
        }),
        ..Plan::holdout()
    }
}

/// A log that reports each line as an [`Event::Log`] and keeps it in `run.log`.
struct Log<'a> {
    file: std::fs::File,
    path: PathBuf,
    on_event: &'a mut (dyn FnMut(Event) + Send),
}

impl Log<'_> {
    fn line(&mut self, text: &str) -> Result<(), WorkflowError> {
        (self.on_event)(Event::Log(text));
        writeln!(self.file, "{text}").map_err(|e| WorkflowError::io(&self.path, "cannot write", e))
    }

    /// An event that is not part of the log.
    fn event(&mut self, e: Event) {
        (self.on_event)(e)
    }

    /// Run `plan` with its progress reported as [`Event::Samples`] (from the worker threads).
    fn sample(
        &mut self,
        problem: &MicroProblem,
        plan: &Plan,
        out: &Path,
        opts: &RunOptions,
    ) -> Result<RunSummary, WorkflowError> {
        let on_event = Mutex::new(&mut *self.on_event);
        let progress = |done, todo| {
            if let Ok(mut f) = on_event.lock() {
                f(Event::Samples { done, todo })
            }
        };
        Ok(run_plan_with(problem, plan, out, opts, &progress)?)
    }
}

/// What one pattern's pipeline produced.
struct PatternRun {
    name: String,
    stages: Vec<(&'static str, f64)>,
    summary: serde_json::Value,
}

/// The main job: every pattern of `args` through every stage, reported through `on_event`. Returns the summary
/// that it also writes to `summary.json` (drape steps that ended at the Newton cap are reported, not failed).
pub fn run(
    args: &RunConfig,
    on_event: &mut (dyn FnMut(Event) + Send),
) -> Result<serde_json::Value, WorkflowError> {
    let t0 = Instant::now();
    check_inputs(args)?;
    if args.fresh && args.out.exists() {
        std::fs::remove_dir_all(&args.out)
            .map_err(|e| WorkflowError::io(&args.out, "cannot remove", e))?;
    }
    std::fs::create_dir_all(&args.out)
        .map_err(|e| WorkflowError::io(&args.out, "cannot create", e))?;
    let log_path = args.out.join("run.log");
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log_path)
        .map_err(|e| WorkflowError::io(&log_path, "cannot open", e))?;
    let mut log = Log {
        file,
        path: log_path.clone(),
        on_event,
    };
    log.line(&format!(
        "hylc run: patterns {}, plan {}, scene {}; output in {}",
        args.patterns.join(", "),
        args.plan,
        args.scene,
        args.out.display()
    ))?;
    let mut runs = Vec::new();
    for p in &args.patterns {
        runs.push(run_pattern(args, p, &mut log)?);
    }
    let total = t0.elapsed().as_secs_f64();
    log.line("")?;
    log.line("summary (wall time per stage, s):")?;
    log.line(&format!(
        "{:<14} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "pattern", "generate", "reference", "sample", "fit", "simulate", "total"
    ))?;
    for r in &runs {
        let t: Vec<f64> = r.stages.iter().map(|s| s.1).collect();
        log.line(&format!(
            "{:<14} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
            r.name,
            t[0],
            t[1],
            t[2],
            t[3],
            t[4],
            t.iter().sum::<f64>()
        ))?;
    }
    for r in &runs {
        let s = &r.summary;
        log.line(&format!(
            "{}: fit RMS {:.2e} (max {:.2e}) over {} samples; held-out in-plane grid RMS {:.2e} (max {:.2e}); \
             drape: {}",
            r.name,
            s["fit"]["all_rms_rel"].as_f64().unwrap_or(f64::NAN),
            s["fit"]["all_max_rel"].as_f64().unwrap_or(f64::NAN),
            s["fit"]["samples"],
            s["fit"]["holdout_rms_rel"].as_f64().unwrap_or(f64::NAN),
            s["fit"]["holdout_max_rel"].as_f64().unwrap_or(f64::NAN),
            s["simulate"]["line"].as_str().unwrap_or("")
        ))?;
        log.line(&format!(
            "  outputs: {}",
            s["outputs"]
                .as_object()
                .map(|o| o
                    .iter()
                    .map(|(k, v)| format!("{k} {}", v.as_str().unwrap_or("")))
                    .collect::<Vec<_>>()
                    .join(", "))
                .unwrap_or_default()
        ))?;
    }
    log.line(&format!("total {total:.1} s; log {}", log_path.display()))?;
    let summary = json!({
        "patterns": runs.iter().map(|r| (r.name.clone(), r.summary.clone())).collect::<serde_json::Map<_, _>>(),
        "plan": args.plan, "scene": args.scene, "total_time": total,
    });
    let path = args.out.join("summary.json");
    write_file(
        &path,
        serde_json::to_string_pretty(&summary).expect("JSON values serialise") + "\n",
    )?;
    Ok(summary)
}

/// Every input of a run checked before anything is computed or written: each pattern (a file or a generated
/// kind, with its construction), the plan (a name or a file) and the scene (a built-in or a file).
fn check_inputs(args: &RunConfig) -> Result<(), WorkflowError> {
    for p in &args.patterns {
        load_pattern(p)?;
        construction_of(p, args.construction)?;
    }
    load_plan(&args.plan)?;
    crate::shell::arcsim::load_scene(&args.scene)?;
    Ok(())
}

/// The name of a pattern argument as a folder name (`stockinette`, `my.pyp` → `my`).
fn folder_name(arg: &str) -> String {
    Path::new(arg)
        .file_stem()
        .map_or_else(|| arg.to_string(), |s| s.to_string_lossy().to_string())
}

/// One pattern through every stage, in the folder `args.out/<name>`.
fn run_pattern(args: &RunConfig, arg: &str, log: &mut Log) -> Result<PatternRun, WorkflowError> {
    let name = folder_name(arg);
    let dir = args.out.join(&name);
    std::fs::create_dir_all(&dir).map_err(|e| WorkflowError::io(&dir, "cannot create", e))?;
    let mut stages = Vec::new();
    log.line(&format!("\n== {name}"))?;

    let t = Instant::now();
    let (pattern, pattern_hash) = stage_pattern(arg, &dir, log)?;
    stages.push(("generate", t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let construction = construction_of(arg, args.construction)?;
    let reference = stage_reference(
        &name,
        &dir,
        &pattern,
        &pattern_hash,
        construction,
        &args.yarn,
        log,
    )?;
    stages.push(("reference", t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let sampled = stage_sample(args, &dir, log)?;
    stages.push(("sample", t.elapsed().as_secs_f64()));

    // 4. fitting (C5–C7)
    let t = Instant::now();
    let job = FitJob {
        out: dir.join("material.json"),
        report: dir.join("fit.json"),
        plots: dir.join("plots"),
        holdout: vec![dir.join("holdout.jsonl")],
        options: args.fit.clone(),
        ..FitJob::beside(&dir.join("samples.jsonl"))
    };
    let report: FitReport = fit_samples(&job, &mut |e| log.event(e))?;
    stages.push(("fit", t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let (drape, line) = stage_drape(args, &dir, &job.out, log)?;
    stages.push(("simulate", t.elapsed().as_secs_f64()));

    let summary = pattern_summary(
        args, arg, &dir, &reference, &stages, &sampled, &report, &drape, line,
    );
    Ok(PatternRun {
        name,
        stages,
        summary,
    })
}

/// Stage 1, the pattern, written to `pattern.pyp`; with the hash of its `.pyp` text.
fn stage_pattern(arg: &str, dir: &Path, log: &mut Log) -> Result<(Pattern, String), WorkflowError> {
    let loaded = load_pattern(arg)?;
    if let Some(note) = loaded.note(arg) {
        log.event(Event::Note(&note));
    }
    let pattern = loaded.pattern;
    let pattern_path = dir.join("pattern.pyp");
    pattern.save_pyp(&pattern_path)?;
    let pattern_hash = format!("{:016x}", fnv1a64(pattern.to_pyp_string().as_bytes()));
    log.line(&format!(
        "pattern: {} vertices, {} yarns, periods {:.4e} × {:.4e} m, wrote {}",
        pattern.positions.len(),
        pattern.yarns().len(),
        pattern.periods[0],
        pattern.periods[1],
        pattern_path.display()
    ))?;
    Ok((pattern, pattern_hash))
}

/// Stage 2, the reference state (C1) in `reference.pyp`, reused when the pattern and the yarn parameters are
/// unchanged (a `reference.json` from before yarn files counts as made with the default yarn); returns the
/// contents of `reference.json` (pattern hash, construction, yarn, report).
fn stage_reference(
    name: &str,
    dir: &Path,
    pattern: &Pattern,
    pattern_hash: &str,
    construction: Construction,
    yarn: &YarnMaterial,
    log: &mut Log,
) -> Result<serde_json::Value, WorkflowError> {
    let yarn_json = serde_json::to_value(yarn).expect("yarn parameters serialise");
    let ref_path = dir.join("reference.pyp");
    let ref_json = dir.join("reference.json");
    let reused = std::fs::read_to_string(&ref_json)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .filter(|v| v["pattern hash"] == pattern_hash && ref_path.exists())
        .filter(|v| match v.get("yarn") {
            Some(recorded) => *recorded == yarn_json,
            None => *yarn == YarnMaterial::default(),
        });
    if let Some(v) = reused {
        log.line(&format!(
            "reference: reused {} (pattern unchanged)",
            ref_path.display()
        ))?;
        return Ok(v);
    }
    let (q, report) = reference_state(
        pattern,
        yarn,
        construction,
        &SolverOptions::default(),
        &ReferenceOptions::default(),
    )
    .map_err(|source| WorkflowError::Reference {
        pattern: name.to_string(),
        source,
    })?;
    q.save_pyp(&ref_path)?;
    let v = json!({"pattern hash": pattern_hash, "construction": format!("{construction:?}"),
                   "yarn": yarn_json, "report": report});
    write_file(
        &ref_json,
        serde_json::to_string_pretty(&v).expect("JSON values serialise") + "\n",
    )?;
    log.line(&format!(
        "reference ({construction:?}): periods {:.4e} × {:.4e} m (strain {:+.2} %, {:+.2} %), \
         Ψ̄(0) = {:.4e} J/m², wrote {}",
        report.periods_out[0],
        report.periods_out[1],
        100.0 * report.period_strain[0],
        100.0 * report.period_strain[1],
        report.psi,
        ref_path.display()
    ))?;
    Ok(v)
}

/// What the sampling stage did: the plan, its run and the held-out grid's run.
struct Sampled {
    plan: Plan,
    plan_run: RunSummary,
    holdout_run: RunSummary,
}

/// A sample file of an earlier run whose records were solved for another problem (e.g. by a version before the
/// crossing guard, or with other yarn parameters) or belong to another plan (e.g. `--plan reduced` after `quick`)
/// cannot be resumed: it is renamed to `<name>.<hash>.jsonl` (the other problem's or plan's hash), with its
/// sidecar, and logged, so the run starts that file over without losing it.
fn set_aside_stale(
    file: &Path,
    problem: &MicroProblem,
    plan: &Plan,
    log: &mut Log,
) -> Result<(), WorkflowError> {
    if !file.exists() {
        return Ok(());
    }
    let hash = problem_hash(problem);
    let plan_hash = format!("{:016x}", plan.hash());
    let records = read_samples(file, true)?;
    let stale = records.iter().find_map(|r| {
        if r.problem != hash {
            Some((r.problem.clone(), "another problem", hash.as_str()))
        } else if !r.id.starts_with(&plan_hash) {
            let other = r.id.split('-').next().unwrap_or_default().to_string();
            Some((other, "another plan", plan_hash.as_str()))
        } else {
            None
        }
    });
    let Some((other, what, this)) = stale else {
        return Ok(());
    };
    let stem = file.with_extension("");
    let aside = stem.with_extension(format!("{other}.jsonl"));
    std::fs::rename(file, &aside).map_err(|e| WorkflowError::io(file, "cannot rename", e))?;
    let meta = meta_path(file);
    if meta.exists() {
        let meta_aside = stem.with_extension(format!("{other}.meta.json"));
        std::fs::rename(&meta, &meta_aside)
            .map_err(|e| WorkflowError::io(&meta, "cannot rename", e))?;
    }
    let why = if what == "another problem" {
        "pattern, yarn parameters or solver settings differ"
    } else {
        "the plan differs"
    };
    log.line(&format!(
        "samples: {} was solved for {what} ({other}; this run {this}: {why}); moved to {} and started over",
        file.display(),
        aside.display()
    ))
}

/// Stage 3, sampling (C4): the plan into `samples.jsonl` and the held-out grid into `holdout.jsonl`, resumable.
fn stage_sample(args: &RunConfig, dir: &Path, log: &mut Log) -> Result<Sampled, WorkflowError> {
    let t = Instant::now();
    let ref_path = dir.join("reference.pyp");
    let (q, _) = Pattern::load_pyp(&ref_path)?;
    // the crossing guard: no sample (and no chain start) of another fabric (docs/sampling.md)
    let options = SolverOptions {
        crossings: CrossingGuard::Reject,
        ..Default::default()
    };
    let problem = MicroProblem::new(q, &args.yarn, options);
    let plan = load_plan(&args.plan)?;
    let samples = dir.join("samples.jsonl");
    let holdout = dir.join("holdout.jsonl");
    let hplan = run_holdout_plan();
    for (file, p) in [(&samples, &plan), (&holdout, &hplan)] {
        set_aside_stale(file, &problem, p, log)?;
    }
    let ref_arg = ref_path.display().to_string();
    write_meta(&samples, &ref_arg, &plan, &problem)?;
    let opts = RunOptions {
        cold: false,
        shard: None,
        limit: None,
        predictor: Default::default(),
        starts: Default::default(),
        disagreement: None,
        sensitivities: false,
    };
    let sp = log.sample(&problem, &plan, &samples, &opts)?;
    write_meta(&holdout, &ref_arg, &hplan, &problem)?;
    let sh = log.sample(&problem, &hplan, &holdout, &opts)?;
    log.line(&format!(
        "samples: plan {:016x}: {} samples ({} from an earlier run, {} solved, {} of them converged); held-out \
         grid: {} ({} solved, {} converged); {:.1} s; wrote {} and {}",
        plan.hash(),
        sp.selected,
        sp.already_done,
        sp.written,
        sp.converged,
        sh.selected,
        sh.written,
        sh.converged,
        t.elapsed().as_secs_f64(),
        samples.display(),
        holdout.display()
    ))?;
    Ok(Sampled {
        plan,
        plan_run: sp,
        holdout_run: sh,
    })
}

/// Stage 5, the drape (C8) with the fitted `material`: frames in `simulate/`, `snapshot.png`; with its summary line.
fn stage_drape(
    args: &RunConfig,
    dir: &Path,
    material: &Path,
    log: &mut Log,
) -> Result<(Outcome, String), WorkflowError> {
    let ov = Overrides {
        material: Some(material.display().to_string()),
        duration: args.duration,
        dt: Some(args.dt),
        edge: args.edge,
        ..Overrides::default()
    };
    let (mut scene, scene_dir) = prepare_noted(&args.scene, &ov, &mut |e| log.event(e))?;
    // frames at 60 per simulated second whatever the step
    scene.output.obj_every = ((1.0 / 60.0) / args.dt).round().max(1.0) as usize;
    let sim_dir = dir.join("simulate");
    let o = execute(&scene, &args.scene, &scene_dir, &sim_dir, &mut |e| {
        log.event(e)
    })?;
    let png = dir.join("snapshot.png");
    snapshot(&png, &o)?;
    let line = summary_line(&o.summary);
    log.line(&format!("simulate {}: {line}", args.scene))?;
    Ok((o, line))
}

/// One pattern's entry of `summary.json`.
#[allow(clippy::too_many_arguments)]
fn pattern_summary(
    args: &RunConfig,
    arg: &str,
    dir: &Path,
    reference: &serde_json::Value,
    stages: &[(&str, f64)],
    sampled: &Sampled,
    report: &FitReport,
    o: &Outcome,
    line: String,
) -> serde_json::Value {
    let s = |f: &str| dir.join(f).display().to_string();
    let (sp, sh) = (&sampled.plan_run, &sampled.holdout_run);
    let h = report.holdout.as_ref();
    let last = o.summary.last.as_ref();
    json!({
        "pattern": arg,
        "construction": reference["construction"],
        "reference": reference["report"],
        "stages": stages.iter().map(|(k, v)| (k.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
        "samples": {"plan": format!("{:016x}", sampled.plan.hash()), "selected": sp.selected,
                    "already_done": sp.already_done, "written": sp.written, "converged": sp.converged,
                    "holdout": sh.selected},
        "fit": {"samples": report.samples, "converged": report.converged,
                "all_rms_rel": report.all.rms_rel, "all_max_rel": report.all.max_rel,
                "holdout_rms_rel": h.map(|e| e.rms_rel), "holdout_max_rel": h.map(|e| e.max_rel),
                "constant": report.constant},
        "simulate": {"scene": args.scene, "line": line, "steps": o.summary.steps,
                     "triangles": o.summary.triangles, "newton_total": o.summary.newton_total,
                     "unconverged_steps": o.summary.unconverged_steps,
                     "max_residual": o.summary.max_residual, "wall": o.summary.wall,
                     "final_kinetic": last.map(|r| r.energy_kinetic),
                     "final_elastic": last.map(|r| r.energy_elastic)},
        "outputs": {"pattern": s("pattern.pyp"), "reference": s("reference.pyp"), "samples": s("samples.jsonl"),
                    "material": s("material.json"), "fit report": s("fit.json"), "plots": s("plots"),
                    "frames": s("simulate"), "snapshot": s("snapshot.png")},
    })
}
