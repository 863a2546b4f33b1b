//! `hylc plan --write FILE`: a built-in sampling plan as JSON (`docs/sampling.md`, "Sampling plan (C4)").

use anyhow::anyhow;
use hylc::sample::Plan;
use std::path::PathBuf;
use std::process::ExitCode;

/// Write the default sampling plan (or the reduced one) as JSON.
#[derive(clap::Args)]
pub struct Args {
    /// plan file to write
    #[arg(long)]
    write: PathBuf,
    /// the reduced plan (30 per 1D range, 10×10 grids)
    #[arg(long)]
    reduced: bool,
    /// the held-out plan: only the 9×9×9 in-plane grid of the original displacement data
    #[arg(long)]
    holdout: bool,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let write = a.write.as_path();
    let plan = match (a.reduced, a.holdout) {
        (true, true) => anyhow::bail!("plan: --reduced and --holdout exclude each other"),
        (true, false) => Plan::reduced(),
        (false, true) => Plan::holdout(),
        (false, false) => Plan::default(),
    };
    let text = serde_json::to_string_pretty(&plan)?;
    std::fs::write(write, text + "\n")
        .map_err(|e| anyhow!("{}: cannot write: {e}", write.display()))?;
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
    Ok(ExitCode::SUCCESS)
}
