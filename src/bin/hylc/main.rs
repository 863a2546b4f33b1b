//! The `hylc` command line (`docs/layout.md`, "Command line"): one module per subcommand,
//! each with its `clap` arguments and a `run` function; the work itself is in the library (`hylc::workflow` and
//! the stages below it). Errors become one line on stderr and exit code 2.

mod args;
mod calibrate;
mod check_derivatives;
mod compare_samples;
mod completions;
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

/// The top-level help: the subcommands by group, one line each (`hylc help COMMAND` for the whole text; a test
/// checks that every subcommand is listed once).
const GROUPED_HELP: &str = "\
{before-help}{about-with-newline}
{usage-heading} {usage}

Pipeline (yarn pattern -> material):
  run                The whole pipeline on a pattern: reference, samples, fit, a drape
  generate           Generate a yarn pattern (stockinette, plain, ...)
  pattern            Load, check and summarise a .pyp pattern
  reference          The pattern's stress-free reference state (C1)
  plan               Write a sampling plan as JSON
  sample             Run a sampling plan (resumable, shardable)
  merge              Merge sample files (e.g. shards)
  fit                Fit a material to a sample file (--preset covering|design)
  material           Evaluate a material's psi and its derivatives at strains
  yarn               The yarn parameters as JSON

Cloth:
  simulate           Simulate a cloth scene (ours, an ARCSim-HYLC file or a built-in)
  gradient           Sensitivities of a scene's observable (adjoint)
  scene-plan         A sampling plan covering the strains a run visited

Micro-scale analysis:
  solve              Solve the micro problem at given strains
  sensitivity        Psi-bar with its derivatives to strain and yarn parameters
  compare-samples    Samples that differ between two sample files
  identify           Identify yarn parameters from the original's data
  calibrate          Yarn parameters that make the original patterns equilibria

Verification and validation:
  check-derivatives  The derivative harness (AD and finite differences)
  validate           Validation against the original's data
  micro-grid         The micro solver against the original displacements
  fuzz               Mutated inputs through every parser and evaluator

Shell:
  completions        A completion script for bash, zsh, fish, elvish or PowerShell

Options:
{options}

'hylc help COMMAND' or 'hylc COMMAND --help' explains a command.
";

#[derive(Parser)]
#[command(name = "hylc", version = VERSION, about = "Homogenized yarn-level cloth", help_template = GROUPED_HELP)]
pub(crate) struct Cli {
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
    Completions(completions::Args),
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
        Command::Completions(a) => completions::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// The grouped top-level help lists every subcommand exactly once, and nothing else.
    #[test]
    fn grouped_help_lists_every_subcommand_once() {
        let listed: Vec<&str> = GROUPED_HELP
            .lines()
            .filter(|l| l.starts_with("  ") && !l.trim_start().starts_with('-'))
            .filter_map(|l| l.split_whitespace().next())
            .collect();
        let mut names: Vec<String> = Cli::command()
            .get_subcommands()
            .map(|c| c.get_name().to_string())
            .collect();
        names.sort();
        let mut sorted: Vec<String> = listed.iter().map(|s| s.to_string()).collect();
        sorted.sort();
        assert_eq!(sorted, names, "listed: {listed:?}");
    }
}
