//! `hylc fuzz`: the fuzz suite (`hylc::validation::fuzz`) at any size, with counts per format; `validation/fuzz.sh`
//! runs 10⁶ cases per format.

use crate::args::exit;
use clap::ValueEnum;
use hylc::validation::fuzz::{run, Format, CASE_BUDGET};
use indicatif::ProgressBar;
use std::process::ExitCode;
use std::time::Instant;

/// Run the fuzz suite: mutated inputs of each format through the library's parsers and evaluators; prints the
/// counts (accepted, rejected, non-finite, panics, slow) and exits 1 when any case panicked, gave a non-finite
/// number or exceeded its time budget.
#[derive(clap::Args)]
pub struct Args {
    /// the formats (comma-separated)
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "pyp,material,plan,scene,samples"
    )]
    format: Vec<FormatArg>,
    /// cases per format
    #[arg(long, default_value_t = 10_000)]
    cases: usize,
    /// seed of the mutators
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(ValueEnum, Clone, Copy, Debug)]
enum FormatArg {
    Pyp,
    Material,
    Plan,
    Scene,
    Samples,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Self {
        match f {
            FormatArg::Pyp => Format::Pyp,
            FormatArg::Material => Format::Material,
            FormatArg::Plan => Format::Plan,
            FormatArg::Scene => Format::Scene,
            FormatArg::Samples => Format::Samples,
        }
    }
}

pub fn run_cmd(a: Args) -> anyhow::Result<ExitCode> {
    let dir = std::env::temp_dir().join(format!("hylc-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", dir.display()))?;
    println!(
        "cases per format {}, seed {}; rejected = a typed error; slow = over {} s",
        a.cases,
        a.seed,
        CASE_BUDGET.as_secs()
    );
    let mut failed = 0;
    for f in &a.format {
        let format = Format::from(*f);
        let bar = ProgressBar::new(a.cases as u64);
        let t = Instant::now();
        let r = run(format, a.cases, a.seed, &dir, &mut |n| {
            bar.set_position(n as u64)
        });
        bar.finish_and_clear();
        println!(
            "{}: {} ({:.0} s)",
            format.name(),
            r.counts(),
            t.elapsed().as_secs_f64()
        );
        for (case, muts, what) in &r.failures {
            eprintln!("{}: case {case} ({muts:?}): {what}", format.name());
        }
        failed += r.failed();
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(exit(failed == 0, 1))
}
