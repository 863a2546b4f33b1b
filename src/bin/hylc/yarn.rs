//! `hylc yarn [FILE]`: the yarn parameters as JSON (`hylc::rod::YarnMaterial`; docs/yarn-parameters.md).

use hylc::rod::YarnMaterial;
use std::path::PathBuf;
use std::process::ExitCode;

/// Print the default yarn parameters as JSON (the form `--yarn FILE` reads), or check a yarn file and print it
/// with every key.
#[derive(clap::Args)]
pub struct Args {
    /// a yarn file to check (default: print the defaults)
    file: Option<PathBuf>,
    /// write the JSON to this file instead of standard output
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let m = match &a.file {
        None => YarnMaterial::default(),
        Some(path) => YarnMaterial::load_json(path)?,
    };
    match &a.out {
        Some(path) => {
            m.save_json(path)?;
            println!("wrote {}", path.display());
        }
        None => print!("{}", m.to_json_string()),
    }
    Ok(ExitCode::SUCCESS)
}
