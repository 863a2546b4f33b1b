//! `hylc simulate SCENE`: run a cloth scene (a JSON file or a built-in; `hylc::workflow::simulate`) with a
//! progress bar, writing an OBJ per frame, a JSON-lines log per step and a PNG snapshot of the final state.

use crate::printer::Printer;
use clap::ValueEnum;
use hylc::shell::solver::Integrator;
use hylc::shell::Psd;
use hylc::workflow::simulate::{
    diverged, execute, prepare_noted, snapshot, summary_line, Overrides, TimeTol,
};
use std::path::PathBuf;
use std::process::ExitCode;

/// Simulate a cloth scene: a scene JSON file, an ARCSim-HYLC scene file (converted; warnings name the keys it
/// ignores) or a built-in (stretch-x, stretch-y, drape-x, drape-y, hanging).
/// Writes frame_NNNN.obj per frame, log.jsonl (one JSON object per step), handle_forces.csv and provenance.json
/// (version, commit, command line) to the output folder. Exit code 0:
/// complete (every step converged); 2: bad input; 3: did not converge (a step failed even with its time step
/// halved `solver.max_halvings` times, or a residual or energy became non-finite; the run stops there and keeps
/// what it wrote).
#[derive(clap::Args)]
pub struct Args {
    /// scene JSON file or built-in name
    scene: String,
    /// output folder
    #[arg(long, default_value = "out/simulate")]
    out: PathBuf,
    /// material JSON (or `default`) instead of the scene's
    #[arg(long)]
    material: Option<String>,
    /// simulated time (s) instead of the scene's
    #[arg(long)]
    duration: Option<f64>,
    /// time step (s) instead of the scene's: one frame (OBJ and log line) per step
    #[arg(long)]
    dt: Option<f64>,
    /// choose substeps by accuracy: the largest estimated local error of a substep, in metres, or `off`
    /// (substeps shorten only when Newton fails); the scene's solver.time_tol (off in our scenes, 1e-4 in the
    /// original's)
    #[arg(long, value_name = "METRES|off")]
    time_tol: Option<TimeTol>,
    /// the scheme of a substep: implicit-euler (Newton to the force tolerance), bdf2 (second order, the same
    /// Newton solve) or linearized (the original simulator's: one Newton step, no line search; with --substeps
    /// set to the original's frame_steps it takes the original's steps)
    #[arg(long, value_enum)]
    integrator: Option<IntegratorArg>,
    /// equal substeps per step (the original's frame_steps), before any adaptive halving
    #[arg(long, value_name = "N")]
    substeps: Option<u32>,
    /// edge length (m) of a rectangle mesh instead of the scene's
    #[arg(long)]
    edge: Option<f64>,
    /// Hessian projection: full (18x18 eigen-projection), psi (6x6 only) or none (diagonal shift)
    #[arg(long, value_enum)]
    psd: Option<PsdArg>,
    /// switch bending off (II = 0; the hinges are not evaluated)
    #[arg(long)]
    no_bending: bool,
    /// use only the 1D terms of the material (the original's only1D)
    #[arg(long)]
    only_1d: bool,
    /// use only the in-plane terms of the material (implies no bending)
    #[arg(long)]
    in_plane_only: bool,
    /// frames: obj (frame_NNNN.obj), or vtu (also frame_NNNN.vtu beside each OBJ with ψ and the six strains per
    /// triangle and the velocity per vertex, and the ParaView series frames.pvd with their times)
    #[arg(long, value_enum, default_value = "obj")]
    format: FormatArg,
    /// no progress bar
    #[arg(long)]
    quiet: bool,
    /// print the scene (after overrides) as JSON and exit; an ARCSim scene prints converted to our format (its
    /// paths relative to its folder: save it there)
    #[arg(long)]
    print: bool,
}

/// The frames' format.
#[derive(ValueEnum, Clone, Copy, Debug)]
enum FormatArg {
    Obj,
    Vtu,
}

/// The scheme of a substep (`hylc::shell::solver::Integrator`).
#[derive(ValueEnum, Clone, Copy, Debug)]
enum IntegratorArg {
    ImplicitEuler,
    Bdf2,
    Linearized,
}

impl From<IntegratorArg> for Integrator {
    fn from(i: IntegratorArg) -> Self {
        match i {
            IntegratorArg::ImplicitEuler => Integrator::ImplicitEuler,
            IntegratorArg::Bdf2 => Integrator::Bdf2,
            IntegratorArg::Linearized => Integrator::Linearized,
        }
    }
}

/// The Hessian projection (`hylc::shell::Psd`).
#[derive(ValueEnum, Clone, Copy, Debug)]
enum PsdArg {
    Full,
    Psi,
    None,
}

impl From<PsdArg> for Psd {
    fn from(p: PsdArg) -> Self {
        match p {
            PsdArg::Full => Psd::Full,
            PsdArg::Psi => Psd::Psi,
            PsdArg::None => Psd::None,
        }
    }
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let ov = Overrides {
        material: a.material,
        duration: a.duration,
        dt: a.dt,
        time_tol: a.time_tol,
        integrator: a.integrator.map(Into::into),
        substeps: a.substeps,
        edge: a.edge,
        psd: a.psd.map(Into::into),
        no_bending: a.no_bending,
        only_1d: a.only_1d,
        in_plane_only: a.in_plane_only,
        vtu: matches!(a.format, FormatArg::Vtu),
    };
    let mut printer = Printer::new(a.quiet);
    let (scene, dir) = prepare_noted(&a.scene, &ov, &mut |e| printer.show(e))?;
    if a.print {
        println!("{}", serde_json::to_string_pretty(&scene)?);
        return Ok(ExitCode::SUCCESS);
    }
    let o = match execute(&scene, &a.scene, &dir, &a.out, &mut |e| printer.show(e)) {
        Ok(o) => o,
        Err(e) if diverged(&e) => {
            eprintln!("error: {e}");
            return Ok(ExitCode::from(3));
        }
        Err(e) => return Err(e.into()),
    };
    println!("{}", summary_line(&o.summary));
    if let Some(r) = &o.summary.last {
        for (name, f) in &r.handle_forces {
            println!(
                "handle {name}: force [{:.5}, {:.5}, {:.5}] N at t = {:.3} s",
                f[0], f[1], f[2], r.time
            );
        }
        println!(
            "final energies: elastic {:.4e} J, kinetic {:.4e} J, gravity {:.4e} J, obstacles {:.4e} J",
            r.energy_elastic, r.energy_kinetic, r.energy_gravity, r.energy_obstacles
        );
    }
    let png = a.out.join("snapshot.png");
    snapshot(&png, &o)?;
    println!("wrote {} (the final state)", png.display());
    Ok(ExitCode::SUCCESS)
}
