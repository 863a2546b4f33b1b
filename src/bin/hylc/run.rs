//! `hylc run`: the main job end to end (`hylc::workflow::pipeline`), printed as it goes, with a progress bar for
//! the drape.

use crate::args::{ConstructionArg, PresetArg, YarnArgs};
use crate::printer::Printer;
use hylc::workflow::inputs::load_pattern;
use hylc::workflow::pipeline::{self, RunConfig};
use hylc::workflow::simulate::diverged;
use std::path::PathBuf;
use std::process::ExitCode;

/// The main job end to end: generate a stockinette (or the given patterns), compute its reference state, run the
/// quick sampling plan and a 27-point held-out grid, fit the material, drape a cloth with it; prints a summary
/// and writes everything to the output folder. A rerun resumes (finished samples are kept). Exit code 0:
/// complete (drape steps at the Newton cap are a note); 2: bad input; 3: the drape diverged (a non-finite residual
/// or energy).
#[derive(clap::Args)]
pub struct Args {
    /// output folder
    #[arg(long, default_value = "out/run")]
    out: PathBuf,
    /// patterns: generated kinds (stockinette, plain, twill, satin, basket) or .pyp files, comma-separated
    #[arg(long, default_value = "stockinette", value_delimiter = ',')]
    pattern: Vec<String>,
    /// construction of .pyp files (knitted or woven); generated kinds know theirs
    #[arg(long, value_enum)]
    construction: Option<ConstructionArg>,
    /// sampling plan: quick (474 samples), reduced (1 050), default (23 250) or a plan file
    #[arg(long, default_value = "quick")]
    plan: String,
    /// the cloth scene (a built-in or a scene file)
    #[arg(long, default_value = "drape-x")]
    scene: String,
    /// edge length (m) of the scene's rectangle mesh (default: 1 cm, 1 800 triangles)
    #[arg(long, default_value_t = 0.01)]
    edge: f64,
    /// simulated time (s) instead of the scene's
    #[arg(long)]
    duration: Option<f64>,
    /// time step of the cloth simulation (s); 1/60 by default, with adaptive substeps inside a step when Newton
    /// does not converge (down to 1/64 of it)
    #[arg(long, default_value_t = 1.0 / 60.0, hide_default_value = true)]
    dt: f64,
    /// delete the output folder first instead of resuming
    #[arg(long)]
    fresh: bool,
    /// the fit's settings, as `hylc fit --preset` (docs/fitting.md, "Presets"): covering (knots over the
    /// whole sampled range), design (the method's own, for dense plans) or design-stockinette
    #[arg(long, value_enum, default_value = "covering")]
    preset: PresetArg,
    #[command(flatten)]
    yarn: YarnArgs,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let yarn = a.yarn.material()?;
    for arg in &a.pattern {
        // a pattern that does not load is the pipeline's error, reported there
        if let Ok(loaded) = load_pattern(arg) {
            a.yarn.warn_radius(&yarn, arg, loaded.pattern.radius);
        }
    }
    let config = RunConfig {
        out: a.out,
        patterns: a.pattern,
        plan: a.plan,
        scene: a.scene,
        edge: Some(a.edge),
        duration: a.duration,
        dt: a.dt,
        fresh: a.fresh,
        construction: a.construction.map(Into::into),
        yarn,
        fit: hylc::fit::FitPreset::from(a.preset).options(),
    };
    let mut printer = Printer::default();
    match pipeline::run(&config, &mut |e| printer.show(e)) {
        Ok(_) => Ok(ExitCode::SUCCESS),
        // the drape diverged: the computation did not converge (exit 3); steps at the Newton cap are only a note
        Err(e) if diverged(&e) => {
            eprintln!("error: {e}");
            Ok(ExitCode::from(3))
        }
        Err(e) => Err(e.into()),
    }
}
