//! `hylc sample`, `hylc merge`, `hylc plan`: sampling plans on one pattern
//! (`04-sampling-fitting.md`, section "Sampling plan (C4)"; `hylc::sample`).

use crate::micro::load_pattern;
use hylc::micro::{MicroProblem, SolverOptions};
use hylc::rod::YarnMaterial;
use hylc::sample::run::problem_hash;
use hylc::sample::{merge, parse_shard, run_plan, Plan, RunOptions};
use std::path::{Path, PathBuf};

/// A plan by name (`default`, `reduced`) or JSON file.
pub fn load_plan(arg: &str) -> Result<Plan, String> {
    match arg {
        "default" => Ok(Plan::default()),
        "reduced" => Ok(Plan::reduced()),
        "quick" => Ok(Plan::quick()),
        "holdout" => Ok(Plan::holdout()),
        _ => Plan::load(Path::new(arg)).map_err(|e| e.to_string()),
    }
}

/// The sidecar of a sample file: `samples.jsonl` → `samples.meta.json`.
pub fn meta_path(samples: &Path) -> PathBuf {
    samples.with_extension("meta.json")
}

/// Write the sidecar of a sample file: the plan, the pattern (its `.pyp` text), the yarn parameters, the solver
/// settings, the problem hash and the pattern's areal density, which `hylc fit` reads.
pub fn write_meta(
    out: &Path,
    arg: &str,
    plan: &Plan,
    problem: &MicroProblem,
) -> Result<(), String> {
    let m = &problem.material;
    let pyp = problem.pattern.to_pyp_string();
    let meta = serde_json::json!({
        "pattern": arg,
        "pyp hash": format!("{:016x}", hylc::sample::plan::fnv1a64(pyp.as_bytes())),
        "problem": problem_hash(problem),
        "plan": plan,
        "density": problem.pattern.areal_density(m.density),
        "yarn": {
            "young": m.young, "shear": m.shear, "bend_twist_factor": m.bend_twist_factor, "radius": m.radius,
            "density": m.density, "contact_stiffness": m.contact_stiffness,
            "contact_quadrature": m.contact_quadrature, "contact_exclusion": m.contact_exclusion,
        },
        "solver": problem.options,
        "periods": problem.pattern.periods,
        "pyp": pyp,
    });
    let path = meta_path(out);
    let text = serde_json::to_string_pretty(&meta).map_err(|e| e.to_string())?;
    std::fs::write(&path, text + "\n").map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

/// `hylc sample`: run a plan on a pattern; true when every written sample converged.
pub fn sample(
    pattern: &str,
    plan: &str,
    out: &Path,
    cold: bool,
    shard: Option<&str>,
    limit: Option<usize>,
    options: SolverOptions,
) -> Result<bool, String> {
    let plan = load_plan(plan)?;
    let shard = shard.map(parse_shard).transpose()?;
    let p = load_pattern(pattern)?;
    let problem = MicroProblem::new(p, &YarnMaterial::default(), options);
    write_meta(out, pattern, &plan, &problem)?;
    let s = run_plan(
        &problem,
        &plan,
        out,
        &RunOptions {
            cold,
            shard,
            limit,
            progress: true,
        },
    )?;
    println!(
        "{}: plan {:016x}, {} samples selected{}, {} already done, {} written ({} converged, {} not), \
         {} re-solved for warm starts, {:.1} s",
        out.display(),
        plan.hash(),
        s.selected,
        shard.map_or(String::new(), |(k, n)| format!(" (shard {k}/{n})")),
        s.already_done,
        s.written,
        s.converged,
        s.written - s.converged,
        s.replayed,
        s.time
    );
    Ok(s.written == s.converged)
}

/// `hylc merge OUT IN...`.
pub fn merge_cmd(out: &Path, inputs: &[PathBuf]) -> Result<(), String> {
    if inputs.is_empty() {
        return Err("merge: no input files".into());
    }
    let ins: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    let (n, dup) = merge(out, &ins)?;
    // the first input's sidecar goes with the merged file (shards of one plan and problem share it)
    if let Some(src) = inputs.iter().map(|p| meta_path(p)).find(|p| p.exists()) {
        std::fs::copy(&src, meta_path(out))
            .map_err(|e| format!("{}: cannot copy the sidecar: {e}", src.display()))?;
    }
    println!(
        "{}: {n} samples from {} files ({dup} duplicates dropped)",
        out.display(),
        inputs.len()
    );
    Ok(())
}

/// `hylc plan --write FILE [--reduced | --holdout]`.
pub fn plan_cmd(write: &Path, reduced: bool, holdout: bool) -> Result<(), String> {
    let plan = match (reduced, holdout) {
        (true, true) => return Err("plan: --reduced and --holdout exclude each other".into()),
        (true, false) => Plan::reduced(),
        (false, true) => Plan::holdout(),
        (false, false) => Plan::default(),
    };
    let text = serde_json::to_string_pretty(&plan).map_err(|e| e.to_string())?;
    std::fs::write(write, text + "\n").map_err(|e| format!("{}: {e}", write.display()))?;
    println!(
        "{}: plan {:016x}, {} samples ({} per 1D range, {}×{} grids on {} pairs)",
        write.display(),
        plan.hash(),
        plan.len(),
        plan.count_1d,
        plan.count_2d,
        plan.count_2d,
        plan.pairs.len()
    );
    Ok(())
}

/// `hylc scene-plan LOG... --write PLAN [--base B] [--margin M] [--all-triangles]`.
pub fn scene_plan_cmd(
    logs: &[PathBuf],
    write: &Path,
    base: &str,
    margin: f64,
    outliers: bool,
) -> Result<(), String> {
    use hylc::sample::scene::{scene_plan, StrainExtent};
    if !(margin.is_finite() && margin >= 0.0) {
        return Err(format!("--margin {margin}: expected a finite fraction ≥ 0"));
    }
    let base_plan = load_plan(base)?;
    let mut ext = StrainExtent::empty();
    for l in logs {
        StrainExtent::read_log(l, &mut ext, outliers)?;
    }
    let (plan, r) = scene_plan(&base_plan, &ext, margin);
    plan.validate().map_err(|e| format!("scene plan: {e}"))?;
    let text = serde_json::to_string_pretty(&plan).map_err(|e| e.to_string())?;
    std::fs::write(write, text + "\n").map_err(|e| format!("{}: {e}", write.display()))?;
    println!(
        "{} steps from {} log(s), {}; margin {margin}; base plan {base} ({} samples)",
        ext.steps,
        logs.len(),
        if outliers {
            "extremes over every triangle"
        } else {
            "1st to 99th percentile over the triangles"
        },
        r.base_samples
    );
    println!(
        "strain   visited                   plan range                share of base spacing axis"
    );
    for k in 0..5 {
        println!(
            "{:<8} [{:>9.4}, {:>9.4}]   [{:>9.4}, {:>9.4}]   {:>5.1} %",
            hylc::micro::strain::STRAIN_NAMES[k],
            r.visited[k][0],
            r.visited[k][1],
            r.ranges[k][0],
            r.ranges[k][1],
            100.0 * r.fraction[k]
        );
    }
    println!(
        "{}: plan {:016x}, {} samples (1D ranges {}; grids {}): {} fewer solves than the base plan ({:.1} % of it)",
        write.display(),
        plan.hash(),
        plan.len(),
        (0..5)
            .map(|k| plan.n_1d(k).to_string())
            .collect::<Vec<_>>()
            .join(", "),
        (0..plan.pairs.len())
            .map(|p| {
                let [a, b] = plan.n_2d(p);
                format!("{}×{} {a}×{b}", plan.pairs[p][0], plan.pairs[p][1])
            })
            .collect::<Vec<_>>()
            .join(", "),
        r.base_samples - r.samples,
        100.0 * r.samples as f64 / r.base_samples.max(1) as f64
    );
    Ok(())
}
