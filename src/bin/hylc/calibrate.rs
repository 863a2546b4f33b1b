//! `hylc calibrate`: the yarn-parameter calibration against the original reference patterns
//! (`docs/derivative-harness.md` item b; `hylc::validation::calibration`).

use crate::args::{parse_list, OutputArgs};
use anyhow::anyhow;
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use hylc::validation::calibration::{
    calibrate, equilibrium_periods, Calibration, ContactForm, Stiffness,
};
use std::path::PathBuf;
use std::process::ExitCode;

/// Calibrate the yarn parameters so that the original reference patterns are static equilibria: per contact
/// form, the residual force at the defaults, the best parameters per pattern and the joint fit.
#[derive(clap::Args)]
pub struct Args {
    /// folder with the original `.pyp` files (default: ../shared/data/hylc2020/patterns)
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// contact quadrature orders to try (comma-separated)
    #[arg(long, default_value = "4")]
    pub quadrature: String,
    /// contact exclusions (neighbour segments on each side) to try
    #[arg(long, default_value = "3")]
    pub exclusion: String,
    /// contact radius factors to try (contact distance 2 x factor x r)
    #[arg(long, default_value = "1")]
    pub radius_factor: String,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// The original patterns, the set the joint fit uses, and the file names.
const ORIGINALS: [&str; 5] = [
    "basket",
    "satin",
    "slip_stitch_honeycomb",
    "stockinette",
    "cartridge_belt_rib",
];
const FIT_SET: [&str; 3] = ["basket", "satin", "slip_stitch_honeycomb"];

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let dir: PathBuf = match a.dir {
        Some(d) => d,
        None => hylc::shared_dir()
            .map(|s| s.join("data/hylc2020/patterns"))
            .ok_or_else(|| {
                anyhow!("the original patterns were not found: pass --dir or set HYLC_SHARED")
            })?,
    };
    let qs: Vec<usize> = parse_list(&a.quadrature, "quadrature")?;
    let xs: Vec<usize> = parse_list(&a.exclusion, "exclusion")?;
    let rs: Vec<f64> = parse_list(&a.radius_factor, "radius-factor")?;
    let material = YarnMaterial::default();
    let mut patterns: Vec<(String, Pattern)> = Vec::new();
    for name in ORIGINALS {
        let path = dir.join(format!("{name}.pyp"));
        let (mut p, warnings) = Pattern::load_pyp(&path)?;
        if !warnings.is_empty() {
            if let Some(implied) = p.implied_periods() {
                // the rest lengths imply the periods to ~1e-4; the equilibrium (zero macro stress) fixes them
                let stored = p.periods;
                p.periods = implied;
                let eq = equilibrium_periods(
                    &p,
                    &ContactForm::default(),
                    &Stiffness::from_material(&material),
                )
                .map_err(|e| anyhow!("{name}: {e}"))?;
                println!(
                    "{name}: stored periods {:.7} x {:.7} m are inconsistent with the periodic edges; \
                     the rest lengths imply {:.7} x {:.7} m; the equilibrium periods at the defaults are \
                     {:.7} x {:.7} m ({:+.3} %, {:+.3} % from the stored ones): using those",
                    stored[0],
                    stored[1],
                    implied[0],
                    implied[1],
                    eq[0],
                    eq[1],
                    100.0 * (eq[0] / stored[0] - 1.0),
                    100.0 * (eq[1] / stored[1] - 1.0)
                );
                p.periods = eq;
            }
        }
        patterns.push((name.to_string(), p));
    }
    println!(
        "defaults: Y = {:.3e} Pa, G/Y = {}, gamma = {}, k_c = {} J/m^2; joint fit over {}",
        material.young,
        material.shear / material.young,
        material.bend_twist_factor,
        material.contact_stiffness,
        FIT_SET.join(", ")
    );
    println!("residual = |grad E| / |grad E_rods| at the stored state (angles as r*theta)");
    let mut all: Vec<Calibration> = Vec::new();
    for &q in &qs {
        for &x in &xs {
            for &rf in &rs {
                let form = ContactForm {
                    quadrature: q,
                    exclusion: x,
                    radius_factor: rf,
                };
                let c = calibrate(&patterns, &FIT_SET, &form, &material)
                    .map_err(|e| anyhow!("calibration Q={q} exclusion={x}: {e}"))?;
                println!(
                    "\nQ = {q}, exclusion = {x}, contact radius x{rf}: joint fit gamma = {:.4}, G/Y = {:.4}, k_c = {:.1} J/m^2",
                    c.gamma, c.shear_over_young, c.contact_stiffness
                );
                println!(
                    "{:<22} {:>6} {:>9} {:>9} {:>9} | {:>7} {:>7} {:>8} {:>9} {:>9}",
                    "pattern",
                    "pairs",
                    "G/Y(th)",
                    "res.def",
                    "res.joint",
                    "own γ",
                    "own G/Y",
                    "own k_c",
                    "res.own",
                    "no cont."
                );
                for r in &c.rows {
                    println!(
                        "{:<22} {:>6} {:>9.4} {:>9.4} {:>9.4} | {:>7.4} {:>7.4} {:>8.1} {:>9.4} {:>9.4}",
                        r.pattern,
                        r.active_pairs,
                        r.shear_over_young_from_angles,
                        r.residual_default,
                        r.residual_joint,
                        r.own_gamma,
                        r.own_shear_over_young,
                        r.own_contact_stiffness,
                        r.residual_own,
                        r.residual_own_no_contact
                    );
                }
                all.push(c);
            }
        }
    }
    if let Some(path) = a.output.write_report(&all)? {
        println!("\nwrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
