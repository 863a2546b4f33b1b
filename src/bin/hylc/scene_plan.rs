//! `hylc scene-plan LOG... --write PLAN`: a sampling plan covering only what one or more cloth runs visited
//! (`docs/cloth-simulator.md`, "model only what a scene requires"; `hylc::sample::scene`).

use anyhow::anyhow;
use hylc::sample::scene::{scene_plan, StrainExtent};
use hylc::strain::StrainComponent;
use hylc::workflow::inputs::load_plan;
use std::path::PathBuf;
use std::process::ExitCode;

/// Write a sampling plan covering only the strains one or more macro runs visited (their `log.jsonl`), plus a
/// margin, at the sample spacing of a base plan ("model only what a scene requires").
#[derive(clap::Args)]
pub struct Args {
    /// `log.jsonl` files of `hylc simulate` runs
    #[arg(required = true)]
    logs: Vec<PathBuf>,
    /// plan file to write
    #[arg(long)]
    write: PathBuf,
    /// base plan whose ranges clip and whose spacing is kept: default, reduced, quick or a plan file
    #[arg(long, default_value = "default")]
    base: String,
    /// margin added on each side, as a fraction of each visited interval
    #[arg(long, default_value_t = 0.1)]
    margin: f64,
    /// cover every triangle's strains (the logs' min/max) instead of the 1st to 99th percentiles
    #[arg(long)]
    all_triangles: bool,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (logs, write, base, margin, outliers) = (
        &a.logs,
        a.write.as_path(),
        a.base.as_str(),
        a.margin,
        a.all_triangles,
    );
    if !(margin.is_finite() && margin >= 0.0) {
        anyhow::bail!("--margin {margin}: expected a finite fraction ≥ 0");
    }
    let base_plan = load_plan(base)?;
    let mut ext = StrainExtent::empty();
    for l in logs {
        StrainExtent::read_log(l, &mut ext, outliers)?;
    }
    let (plan, r) = scene_plan(&base_plan, &ext, margin);
    plan.validate().map_err(|e| anyhow!("scene plan: {e}"))?;
    let text = serde_json::to_string_pretty(&plan)?;
    std::fs::write(write, text + "\n")
        .map_err(|e| anyhow!("{}: cannot write: {e}", write.display()))?;
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
            StrainComponent::NAMES[k],
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
    Ok(ExitCode::SUCCESS)
}
