//! `hylc reference PATTERN --out REF.pyp`: Algorithm C1 on a pattern (`docs/micro-solver.md`, section 6;
//! `hylc::micro::reference`), written as `.pyp`.

use crate::args::{ConstructionArg, OutputArgs, YarnArgs};
use crate::strain::load_pattern_noted;
use hylc::workflow::inputs::reference_of;
use std::path::PathBuf;
use std::process::ExitCode;

/// Compute the reference state of a pattern (Algorithm C1: stress-free state, tension, zero-stress periods,
/// centring) and write it as `.pyp`.
#[derive(clap::Args)]
pub struct Args {
    /// `.pyp` file or generated kind
    pattern: String,
    /// knitted or woven (selects the tension factors; inferred for generated kinds)
    #[arg(long, value_enum)]
    construction: Option<ConstructionArg>,
    /// skip the stress-free state and the tension (re-equilibrate a pattern that is already a reference
    /// state, e.g. an original `.pyp` with this project's yarn model): zero-stress periods and centring only
    #[arg(long)]
    equilibrate_only: bool,
    /// output `.pyp` file
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    output: OutputArgs,
    #[command(flatten)]
    yarn: YarnArgs,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (pattern, equilibrate_only, out) = (a.pattern.as_str(), a.equilibrate_only, &a.out);
    let yarn = a.yarn.material()?;
    let p = load_pattern_noted(pattern)?;
    a.yarn.warn_radius(&yarn, pattern, p.radius);
    let (q, report, construction) = reference_of(
        pattern,
        &p,
        &yarn,
        a.construction.map(Into::into),
        equilibrate_only,
    )?;
    q.save_pyp(out)?;
    println!(
        "{pattern} ({}): {} stress-free round(s) (relaxed energy {:.2e} J); zero-stress periods \
         {:.6e} x {:.6e} m (strain {:+.4}%, {:+.4}%, {} Newton steps, residual tile forces {:.1e}, {:.1e} N); \
         Ψ̄(0) = {:.6e} J/m²; {:.2} s; wrote {}",
        if equilibrate_only {
            "equilibrated only".to_string()
        } else {
            format!("{construction:?}")
        },
        report.rounds,
        report.stress_free_energy,
        report.periods_out[0],
        report.periods_out[1],
        100.0 * report.period_strain[0],
        100.0 * report.period_strain[1],
        report.period_steps,
        report.residual_force[0],
        report.residual_force[1],
        report.psi,
        report.time,
        out.display()
    );
    a.output.write_report(&report)?;
    Ok(ExitCode::SUCCESS)
}
