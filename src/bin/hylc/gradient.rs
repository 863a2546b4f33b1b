//! `hylc gradient SCENE --observable OBS`: dJ/dp of one observable of a scene by an adjoint solve
//! (`hylc::workflow::gradient`, docs/sensitivities.md), written to `OUT/gradient.json`.

use crate::args::YarnArgs;
use crate::printer::Printer;
use hylc::workflow::gradient::{gradient, no_gradient, GradientOptions, YarnChainInput};
use hylc::workflow::simulate::{prepare_noted, Overrides};
use std::path::PathBuf;
use std::process::ExitCode;

/// Sensitivities of a scene: dJ/dp of one observable for the scene's stiffness, bending scale, mass and gravity,
/// every held set's translation and keyframe offsets, every obstacle's translation and every coefficient of the
/// material, by one adjoint solve at a quasi-static equilibrium or the discrete adjoint of a dynamic run's
/// implicit Euler substeps (damping, air drag and lagged friction included; docs/sensitivities.md). Writes OUT/gradient.json
/// (the material's gradient in the material file's layout) and the run's frames and log. Exit code 0: done;
/// 2: bad input (or settings the adjoint does not follow); 3: no gradient exists (the last step did not
/// converge, or an equilibrium is not a strict minimum).
#[derive(clap::Args)]
pub struct Args {
    /// scene JSON file, ARCSim scene file or built-in name
    scene: String,
    /// the observable J: com-x|y|z (mass-weighted centre), energy (elastic), handle-force:NAME:x|y|z (the
    /// reaction of a held set), target:FILE.obj (½ Σ|x − x̂|² against an OBJ with the scene's vertices)
    #[arg(long)]
    observable: String,
    /// the time (s) at which J is taken: the step nearest it (default: the last step)
    #[arg(long, value_name = "SECONDS")]
    at: Option<f64>,
    /// material JSON (or `default`) instead of the scene's
    #[arg(long)]
    material: Option<String>,
    /// output folder
    #[arg(long, default_value = "out/gradient")]
    out: PathBuf,
    /// also central differences of re-solves (two per parameter; the solves tightened to 1e-10 N) for the
    /// scene's scalars, the held sets' keyframes, the obstacles and the material's largest coefficients
    #[arg(long)]
    check: bool,
    /// how many material coefficients --check compares (those with the largest |c dJ/dc|)
    #[arg(long, default_value_t = 5, value_name = "N")]
    check_coefficients: usize,
    /// the sample file the material was fitted to, made with `hylc sample --sensitivities`: adds dJ/dθ for
    /// every yarn parameter (the reference state held fixed; docs/sensitivities.md, "The chain to the yarn")
    #[arg(long, value_name = "SAMPLES.jsonl")]
    samples: Option<PathBuf>,
    #[command(flatten)]
    yarn: YarnArgs,
    /// no progress bar
    #[arg(long)]
    quiet: bool,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let ov = Overrides {
        material: a.material,
        ..Default::default()
    };
    let mut printer = Printer::new(a.quiet);
    let (scene, dir) = prepare_noted(&a.scene, &ov, &mut |e| printer.show(e))?;
    let opts = GradientOptions {
        observable: a.observable,
        cotangent: None,
        at: a.at,
        check: a.check,
        check_coefficients: a.check_coefficients,
        yarn: match a.samples {
            Some(samples) => Some(YarnChainInput {
                samples,
                yarn: a.yarn.material()?,
                yarn_label: a
                    .yarn
                    .yarn
                    .as_ref()
                    .map_or("(defaults)".into(), |p| p.display().to_string()),
            }),
            None => None,
        },
    };
    let o = match gradient(&scene, &a.scene, &dir, &a.out, &opts, &mut |e| {
        printer.show(e)
    }) {
        Ok(o) => o,
        Err(e) if no_gradient(&e) => {
            eprintln!("error: {e}");
            return Ok(ExitCode::from(3));
        }
        Err(e) => return Err(e.into()),
    };
    let s = &o.sensitivity;
    println!(
        "{} = {:.6e} at t = {:.4} s (largest free residual {:.2e} N); forward solve {:.2} s, gradient {:.3} s",
        opts.observable, s.value, o.time, s.residual, o.wall_forward, o.wall_gradient
    );
    println!(
        "dJ/d stiffness {:.6e}, bending_scale {:.6e}, mass {:.6e}, gravity [{:.6e}, {:.6e}, {:.6e}]",
        s.stiffness,
        s.bending_scale,
        s.mass_multiplier(scene.model.mass),
        s.gravity[0],
        s.gravity[1],
        s.gravity[2]
    );
    for h in &s.held {
        let t = h.translation;
        println!(
            "dJ/d translation of {}: [{:.6e}, {:.6e}, {:.6e}]",
            h.name, t[0], t[1], t[2]
        );
    }
    for (i, t) in s.obstacles.iter().enumerate() {
        println!(
            "dJ/d translation of obstacle {i}: [{:.6e}, {:.6e}, {:.6e}]",
            t[0], t[1], t[2]
        );
    }
    if let Some(y) = &o.yarn {
        let parts: Vec<String> = y
            .values
            .iter()
            .map(|(k, v)| format!("{k} {v:.6e}"))
            .collect();
        println!(
            "dJ/dθ (yarn, through {} samples and the fit, reference state held fixed): {}",
            y.samples,
            parts.join(", ")
        );
        if !y.kinks.is_empty() {
            println!(
                "the fit has {} decisions at their switching point (one-sided derivatives), first: {}",
                y.kinks.len(),
                y.kinks[0]
            );
        }
    }
    if !o.check.is_empty() {
        println!(
            "{:<44} {:>14} {:>14} {:>9}",
            "parameter", "adjoint", "difference", "error"
        );
        for r in &o.check {
            println!(
                "{:<44} {:>14.6e} {:>14.6e} {:>9.1e}",
                r.parameter, r.adjoint, r.difference, r.error
            );
        }
    }
    println!("wrote {}", a.out.join("gradient.json").display());
    Ok(ExitCode::SUCCESS)
}
