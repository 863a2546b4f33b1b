//! `hylc material FILE --z …`: ψ, ∇ψ, ∇²ψ of a material (`hylc::material`; `docs/material.md`).

use anyhow::anyhow;
use hylc::material::synthetic::default_material;
use hylc::material::{Material, PsiVgh};
use hylc::strain::Strain6;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Evaluate ψ, ∇ψ, ∇²ψ of a material file at given strains z = (s_x, s_a, s_y, II00, II01, II11).
#[derive(clap::Args)]
pub struct Args {
    /// material JSON (original HYLC format), or `default` for the embedded default material
    file: String,
    /// a strain as six comma-separated numbers (repeatable)
    #[arg(
        long = "z",
        value_name = "SX,SA,SY,II00,II01,II11",
        allow_hyphen_values = true
    )]
    z: Vec<String>,
    /// a file with one strain per line (six numbers separated by commas or spaces; `#` starts a comment)
    #[arg(long)]
    z_file: Option<PathBuf>,
    /// print one JSON object per strain instead of text
    #[arg(long)]
    json: bool,
    /// write the material back out (e.g. `default` to a file)
    #[arg(long)]
    write: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let mat = load_material(&a.file)?;
    let mut strains = Vec::new();
    for (i, s) in a.z.iter().enumerate() {
        strains.push(
            s.parse::<Strain6>()
                .map_err(|e| anyhow!("--z #{} {s:?}: {e}", i + 1))?
                .0,
        );
    }
    if let Some(path) = &a.z_file {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow!("{}: cannot read: {e}", path.display()))?;
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            strains.push(
                line.parse::<Strain6>()
                    .map_err(|e| anyhow!("{}:{}: {e}", path.display(), n + 1))?
                    .0,
            );
        }
    }
    if let Some(out) = &a.write {
        mat.save(out)
            .map_err(|e| anyhow!("{}: cannot write: {e}", out.display()))?;
        eprintln!("wrote {}", out.display());
    }
    if strains.is_empty() && a.write.is_none() {
        anyhow::bail!("no strains given: use --z SX,SA,SY,II00,II01,II11 or --z-file FILE");
    }
    // every strain is checked before anything is printed: an out-of-range strain is bad input (exit 2)
    let mut results = Vec::with_capacity(strains.len());
    for (i, z) in strains.iter().enumerate() {
        results.push(
            mat.eval_checked(z)
                .map_err(|e| anyhow!("strain #{}: {e}", i + 1))?,
        );
    }
    for (z, r) in strains.iter().zip(results) {
        if a.json {
            println!("{}", psi_json(z, &r));
        } else {
            print_psi(z, &r);
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn load_material(file: &str) -> anyhow::Result<Material> {
    if file == "default" {
        Ok(default_material())
    } else {
        Ok(Material::load(Path::new(file))?)
    }
}

fn psi_json(z: &[f64; 6], r: &PsiVgh) -> String {
    serde_json::json!({ "z": z, "psi": r.value, "grad": r.grad, "hess": r.hess }).to_string()
}

fn print_psi(z: &[f64; 6], r: &PsiVgh) {
    println!("z      = [{}]", fmt_row(z));
    println!("psi    = {:.12e} J/m^2", r.value);
    println!("grad   = [{}]", fmt_row(&r.grad));
    for (i, row) in r.hess.iter().enumerate() {
        println!(
            "{} [{}]",
            if i == 0 { "hess   =" } else { "        " },
            fmt_row(row)
        );
    }
    println!();
}

fn fmt_row(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:>13.6e}"))
        .collect::<Vec<_>>()
        .join(" ")
}
