//! `hylc compare-samples A.jsonl B.jsonl [--rel 1e-6]`: the agreement of two sample files of one plan, e.g.
//! warm-first against cold-first (docs/sampling.md; `hylc::sample::compare`).

use anyhow::bail;
use hylc::sample::{compare, read_samples};
use std::path::PathBuf;
use std::process::ExitCode;

/// List the samples converged in both files whose Ψ̄ differ by more than a relative tolerance (both energies),
/// with counts; exit code 3 when there is any.
#[derive(clap::Args)]
pub struct Args {
    /// first sample file
    a: PathBuf,
    /// second sample file
    b: PathBuf,
    /// relative tolerance |Ψ̄_a − Ψ̄_b| / max(|Ψ̄_a|, |Ψ̄_b|)
    #[arg(long, default_value_t = 1e-6)]
    rel: f64,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    if !(a.rel.is_finite() && a.rel >= 0.0) {
        bail!("--rel: expected a finite tolerance ≥ 0, got {}", a.rel);
    }
    for p in [&a.a, &a.b] {
        if !p.exists() {
            bail!("{}: no such sample file", p.display());
        }
    }
    let ra = read_samples(&a.a, false)?;
    let rb = read_samples(&a.b, false)?;
    let c = compare(&ra, &rb, a.rel);
    if !c.differ.is_empty() {
        println!("index\tid\tz\tpsi_a\tpsi_b\trelative");
    }
    for d in &c.differ {
        println!(
            "{}\t{}\t{:?}\t{:.17e}\t{:.17e}\t{:.3e}",
            d.index, d.id, d.z, d.psi_a, d.psi_b, d.relative
        );
    }
    let max = c.differ.iter().map(|d| d.relative).fold(0.0, f64::max);
    println!(
        "{} common samples ({} only in {}, {} only in {}): {} converged in both, {} agree to {:e}, {} differ \
         (max relative {:.3e}); {} converged in one only, {} in neither",
        c.common,
        c.only_a,
        a.a.display(),
        c.only_b,
        a.b.display(),
        c.both_converged,
        c.agree,
        a.rel,
        c.differ.len(),
        max,
        c.one_converged,
        c.neither_converged
    );
    Ok(if c.differ.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(3)
    })
}
