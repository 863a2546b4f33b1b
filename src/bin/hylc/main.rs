//! The `hylc` command line (`docs/layout.md`, "Command line"): one module per subcommand,
//! each with its `clap` arguments and a `run` function; the work itself is in the library (`hylc::workflow` and
//! the stages below it). Errors become one line on stderr and exit code 2.

mod args;
mod calibrate;
mod check_derivatives;
mod compare_samples;
mod fit;
mod fuzz;
mod generate;
mod gradient;
mod identify;
mod material;
mod merge;
mod micro_grid;
mod pattern;
mod plan;
mod printer;
mod reference;
mod run;
mod sample;
mod scene_plan;
mod sensitivity;
mod simulate;
mod solve;
mod strain;
mod validate;
mod yarn;

use clap::{Parser, Subcommand};

/// `hylc --version`: the version and the commit it was built from.
const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("HYLC_COMMIT"),
    ")"
);
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "hylc", version = VERSION, about = "Homogenized yarn-level cloth")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    Run(run::Args),
    Validate(validate::Args),
    CheckDerivatives(check_derivatives::Args),
    Material(material::Args),
    Pattern(pattern::Args),
    Generate(generate::Args),
    Solve(solve::Args),
    Sample(sample::Args),
    Merge(merge::Args),
    CompareSamples(compare_samples::Args),
    ScenePlan(scene_plan::Args),
    Plan(plan::Args),
    Fit(fit::Args),
    Reference(reference::Args),
    Sensitivity(sensitivity::Args),
    MicroGrid(micro_grid::Args),
    Calibrate(calibrate::Args),
    Identify(identify::Args),
    Fuzz(fuzz::Args),
    Simulate(simulate::Args),
    Gradient(gradient::Args),
    Yarn(yarn::Args),
}

/// The command line, or exit: help and version are printed as clap prints them, a usage error as one line
/// (exit code 2, like every other error).
fn parse() -> Result<Cli, ExitCode> {
    use clap::error::ErrorKind;
    Cli::try_parse().map_err(|e| match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
        _ => {
            let text = e.render().to_string();
            let parts: Vec<&str> = text
                .lines()
                .map(str::trim)
                .filter(|l| {
                    !(l.is_empty()
                        || l.starts_with("Usage:")
                        || l.starts_with("For more information"))
                })
                .collect();
            eprintln!("{}", parts.join(" "));
            ExitCode::from(2)
        }
    })
}

/// Output piped into a reader that closes early (`hylc material … --json | head`) ends the process quietly, as
/// for other Unix tools, instead of a panic in `println!` on the broken pipe: Rust ignores SIGPIPE by default.
fn default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first in `main`, before any other thread exists; SIG_DFL is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    default_sigpipe();
    let cli = match parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    let result = match cli.command {
        Command::Run(a) => run::run(a),
        Command::Validate(a) => validate::run(a),
        Command::CheckDerivatives(a) => check_derivatives::run(a),
        Command::Material(a) => material::run(a),
        Command::Pattern(a) => pattern::run(a),
        Command::Generate(a) => generate::run(a),
        Command::Solve(a) => solve::run(a),
        Command::Sample(a) => sample::run(a),
        Command::Merge(a) => merge::run(a),
        Command::CompareSamples(a) => compare_samples::run(a),
        Command::ScenePlan(a) => scene_plan::run(a),
        Command::Plan(a) => plan::run(a),
        Command::Fit(a) => fit::run(a),
        Command::Reference(a) => reference::run(a),
        Command::Sensitivity(a) => sensitivity::run(a),
        Command::MicroGrid(a) => micro_grid::run(a),
        Command::Calibrate(a) => calibrate::run(a),
        Command::Identify(a) => identify::run(a),
        Command::Fuzz(a) => fuzz::run_cmd(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Gradient(a) => gradient::run(a),
        Command::Yarn(a) => yarn::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
