//! `hylc sample`, `hylc merge`, `hylc plan`: sampling plans on one pattern
//! (`04-sampling-fitting.md`, section "Sampling plan (C4)"; `hylc::sample`).

use crate::micro::load_pattern;
use hylc::micro::{MicroProblem, SolverOptions};
use hylc::rod::YarnMaterial;
use hylc::sample::{merge, parse_shard, run_plan, Plan, RunOptions};
use std::path::{Path, PathBuf};

/// A plan by name (`default`, `reduced`) or JSON file.
pub fn load_plan(arg: &str) -> Result<Plan, String> {
    match arg {
        "default" => Ok(Plan::default()),
        "reduced" => Ok(Plan::reduced()),
        _ => Plan::load(Path::new(arg)).map_err(|e| e.to_string()),
    }
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
    println!(
        "{}: {n} samples from {} files ({dup} duplicates dropped)",
        out.display(),
        inputs.len()
    );
    Ok(())
}

/// `hylc plan --write FILE [--reduced]`.
pub fn plan_cmd(write: &Path, reduced: bool) -> Result<(), String> {
    let plan = if reduced {
        Plan::reduced()
    } else {
        Plan::default()
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
