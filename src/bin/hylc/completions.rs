//! `hylc completions SHELL`: a completion script for bash, zsh, fish, elvish or PowerShell on stdout
//! (`clap_complete`), e.g. `hylc completions bash > ~/.local/share/bash-completion/completions/hylc`.

use clap::CommandFactory;
use clap_complete::Shell;
use std::process::ExitCode;

/// Print a shell completion script (bash, zsh, fish, elvish, powershell) for hylc on stdout.
#[derive(clap::Args)]
pub struct Args {
    /// the shell
    #[arg(value_enum)]
    shell: Shell,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let mut cmd = crate::Cli::command();
    clap_complete::generate(a.shell, &mut cmd, "hylc", &mut std::io::stdout());
    Ok(ExitCode::SUCCESS)
}
