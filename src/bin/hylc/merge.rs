//! `hylc merge OUT IN...`: sample files (e.g. shards) into one (`hylc::sample::merge`).

use anyhow::anyhow;
use hylc::sample::merge;
use hylc::workflow::sidecar::meta_path;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Merge sample files (e.g. shards) into one, dropping duplicate ids.
#[derive(clap::Args)]
pub struct Args {
    /// merged sample file
    out: PathBuf,
    /// input sample files
    inputs: Vec<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (out, inputs) = (a.out.as_path(), &a.inputs);
    if inputs.is_empty() {
        anyhow::bail!("merge: no input files");
    }
    let ins: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
    let (n, dup) = merge(out, &ins)?;
    // the first input's sidecar goes with the merged file (shards of one plan and problem share it)
    if let Some(src) = inputs.iter().map(|p| meta_path(p)).find(|p| p.exists()) {
        std::fs::copy(&src, meta_path(out))
            .map_err(|e| anyhow!("{}: cannot copy the sidecar: {e}", src.display()))?;
    }
    println!(
        "{}: {n} samples from {} files ({dup} duplicates dropped)",
        out.display(),
        inputs.len()
    );
    Ok(ExitCode::SUCCESS)
}
