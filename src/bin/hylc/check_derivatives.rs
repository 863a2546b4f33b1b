//! `hylc check-derivatives`: the derivative harness (`hylc::diff`) on every registered function
//! (`hylc::checks`; `docs/derivative-harness.md`).

use hylc::checks::run_all;
use hylc::diff::{format_table, CheckConfig};
use std::process::ExitCode;
use std::time::Instant;

/// Run the derivative harness on every registered function; exits non-zero on any failure.
#[derive(clap::Args)]
pub struct Args {
    /// random inputs per function
    #[arg(long, default_value_t = 1000)]
    cases: usize,
    /// seed of the input generator
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// only functions whose name contains this
    #[arg(long, default_value = "")]
    filter: String,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (cases, seed, filter) = (a.cases, a.seed, a.filter.as_str());
    let cfg = CheckConfig {
        cases,
        seed,
        ..CheckConfig::default()
    };
    let t0 = Instant::now();
    let reports = run_all(&cfg, filter);
    if reports.is_empty() {
        anyhow::bail!("no registered function matches filter {filter:?}");
    }
    print!("{}", format_table(&reports));
    let failed: Vec<&str> = reports
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.name.as_str())
        .collect();
    let tol = cfg.tolerances;
    println!(
        "tolerances (relative, normwise): value {:.0e}, gradient/AD {:.0e}, Hessian/AD {:.0e}, gradient/FD {:.0e}, \
         Hessian/FD {:.0e}; 'worst' is the largest error/tolerance ratio",
        tol.value, tol.gradient_ad, tol.hessian_ad, tol.gradient_fd, tol.hessian_fd
    );
    if hylc::shared_dir().is_none() {
        println!("note: ../shared not found: rows for the original materials were skipped");
    }
    println!(
        "{} functions, {} cases each, seed {seed}, {:.1} s",
        reports.len(),
        cases,
        t0.elapsed().as_secs_f64()
    );
    if failed.is_empty() {
        println!("check-derivatives: {} passed, 0 failed", reports.len());
        Ok(ExitCode::SUCCESS)
    } else {
        println!(
            "check-derivatives: {} passed, {} failed ({})",
            reports.len() - failed.len(),
            failed.len(),
            failed.join(", ")
        );
        Ok(ExitCode::FAILURE)
    }
}
