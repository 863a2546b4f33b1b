//! `hylc solve PATTERN --z …`: the micro solver on one pattern at one or more strains (`docs/micro-solver.md`;
//! `hylc::micro`).

use crate::args::{exit, PredictorArg, SolverArgs, YarnArgs};
use crate::strain::{load_pattern_noted, parse_strain};
use anyhow::anyhow;
use hylc::micro::envelope::strain_derivatives;
use hylc::micro::solver::world_positions;
use hylc::micro::{CrossingGuard, MacroStrain, MicroProblem, Predictor, Solution, SolverOptions};
use hylc::strain::StrainComponent;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Solve the micro problem of a pattern at one or more macro strains (warm-started from the previous one unless
/// --cold): status, Newton steps, Ψ̄, homogenized stress, time and where it went.
#[derive(clap::Args)]
pub struct Args {
    /// `.pyp` file, or a generated kind (plain, twill, satin, basket, stockinette)
    pattern: String,
    /// strain s_x,s_a,s_y[,II00,II11] (repeatable; default zero)
    #[arg(long = "z", allow_hyphen_values = true)]
    z: Vec<String>,
    /// start every strain from the reference state
    #[arg(long)]
    cold: bool,
    /// warm start from the previous solution only (no extrapolation along the chain; `--predictor none`)
    #[arg(long)]
    no_predictor: bool,
    /// predictor of warm starts along the chain: secant (from the two previous solutions) or none
    #[arg(long, value_enum, default_value_t = PredictorArg::Secant)]
    predictor: PredictorArg,
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    yarn: YarnArgs,
    /// no per-yarn slide constraints (an option of the original solver, kept to reproduce it)
    #[arg(long)]
    no_slide_constraints: bool,
    /// write the yarn centre lines as OBJ polylines (one file per strain when several)
    #[arg(long)]
    obj: Option<PathBuf>,
    /// one JSON object per strain
    #[arg(long)]
    json: bool,
    /// print one line per Newton step to stderr
    #[arg(long)]
    trace: bool,
    /// Gauss points per segment of the contact quadrature (default: the yarn's)
    #[arg(long)]
    quadrature: Option<usize>,
}

/// `hylc solve`: exit code 3 when a solve did not converge.
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    if a.trace {
        // the solver's per-step lines (`tracing` events at info level) as plain lines on stderr
        tracing_subscriber::fmt()
            .with_writer(std::io::stderr)
            .without_time()
            .with_level(false)
            .with_target(false)
            .init();
    }
    let options = SolverOptions {
        trace: a.trace,
        slide_constraints: !a.no_slide_constraints,
        ..a.solver.options()
    };
    let predictor = if a.no_predictor {
        Predictor::None
    } else {
        a.predictor.into()
    };
    let (cold, json_out) = (a.cold, a.json);
    let p = load_pattern_noted(&a.pattern)?;
    let mut yarn = a.yarn.material()?;
    a.yarn.warn_radius(&yarn, &a.pattern, p.radius);
    if let Some(q) = a.quadrature {
        if q == 0 {
            anyhow::bail!("--quadrature: expected at least 1 point per segment");
        }
        yarn.contact_quadrature = q;
    }
    let problem = MicroProblem::new(p, &yarn, options);
    let strains: Vec<MacroStrain> = if a.z.is_empty() {
        vec![MacroStrain::ZERO]
    } else {
        a.z.iter()
            .map(|s| parse_strain(s))
            .collect::<Result<_, _>>()?
    };
    let mut all_ok = true;
    let mut prev: Option<Solution> = None;
    let mut before: Option<Solution> = None;
    for (k, strain) in strains.iter().enumerate() {
        // warm start from the previous solution, extrapolated along the chain by the predictor
        let tp = std::time::Instant::now();
        let predicted = match (&before, &prev, predictor) {
            (Some(a), Some(b), Predictor::Secant)
                if !cold && a.psi().is_ok() && b.psi().is_ok() =>
            {
                problem.predict(&a.state, &b.state, strain)?
            }
            _ => None,
        };
        let predict_time = tp.elapsed().as_secs_f64();
        let start = if cold {
            None
        } else {
            predicted.as_ref().or(prev.as_ref().map(|s| &s.state))
        };
        let sol = problem.solve(strain, start)?;
        let r = report(&problem, &sol, predicted.is_some(), predict_time);
        if json_out {
            println!("{r}");
        } else {
            println!(
                "z = {}: {} in {} steps, {:.3} s; Ψ̄ = {}; ‖g‖∞ = {:.2e} N",
                strain,
                sol.status,
                sol.steps,
                sol.time,
                sol.psi()
                    .map(|v| format!("{v:.6e} J/m²"))
                    .unwrap_or_else(|e| format!("none ({e})")),
                sol.gradient_norm
            );
            if let Some(s) = r["stress"].as_object() {
                let parts: Vec<String> = s
                    .iter()
                    .map(|(n, v)| {
                        format!(
                            "{n} {}",
                            v.as_f64().map(|x| format!("{x:.5e}")).unwrap_or("-".into())
                        )
                    })
                    .collect();
                println!("  stress ∂Ψ̄/∂z: {}", parts.join(", "));
            }
            if problem.options.crossings != CrossingGuard::Off {
                println!(
                    "  yarn crossings: {} along the path ({} pairs not cancelling), {} line-search trials rejected",
                    sol.crossings.len(),
                    sol.net_crossings(),
                    sol.rejected_crossings
                );
            }
            let t = &sol.timings;
            println!(
                "  time: start {:.3} s, assembly {:.3} s, contact {:.3} s, factorisation {:.3} s, line search {:.3} s",
                t.start, t.assembly, t.contact, t.factorization, t.line_search
            );
        }
        all_ok &= sol.psi().is_ok();
        if let Some(path) = &a.obj {
            let path = if strains.len() > 1 {
                path.with_extension(format!("{k}.obj"))
            } else {
                path.to_path_buf()
            };
            write_obj(&problem, &sol, &path)?;
        }
        before = prev.take();
        prev = Some(sol);
    }
    Ok(exit(all_ok, 3))
}

fn report(
    problem: &MicroProblem,
    sol: &Solution,
    predicted: bool,
    predict_time: f64,
) -> serde_json::Value {
    let t = &sol.timings;
    let stress = strain_derivatives(problem, &sol.state).ok();
    json!({
        "strain": sol.state.strain.0,
        "status": sol.status.to_string(),
        "psi": sol.psi().ok(),
        "energy": {
            "stretch": sol.energy.stretch, "bend": sol.energy.bend,
            "twist": sol.energy.twist, "contact": sol.energy.contact,
        },
        "stress": stress.map(|s| StrainComponent::NAMES.iter().zip(s).map(|(n, v)| (n.to_string(), json!(v))).collect::<serde_json::Map<_, _>>()),
        "steps": sol.steps,
        "gradient_norm": sol.gradient_norm,
        "time": sol.time,
        "predicted": predicted,
        "crossings": (problem.options.crossings != CrossingGuard::Off).then(|| json!({
            "events": sol.crossings.len(), "net": sol.net_crossings(), "rejected": sol.rejected_crossings,
        })),
        "timings": { "predictor": predict_time, "start": t.start, "assembly": t.assembly, "contact": t.contact,
                     "factorization": t.factorization, "line_search": t.line_search },
    })
}

/// The yarn centre lines of a solution as OBJ polylines (one `l` element per yarn, home tile).
fn write_obj(problem: &MicroProblem, sol: &Solution, path: &Path) -> anyhow::Result<()> {
    let p = &problem.pattern;
    let x = world_positions(p, &sol.state);
    let mut s = String::new();
    s.push_str(&format!("# hylc solve: strain {}\n", sol.state.strain));
    for v in &x {
        s.push_str(&format!("v {} {} {}\n", v.x, v.y, v.z));
    }
    let elim = hylc::micro::Elimination::in_family(p, &sol.state.strain, sol.state.family);
    let mut extra = x.len();
    for yarn in p.yarns() {
        let mut line = String::from("l");
        for &v in &yarn {
            line.push_str(&format!(" {}", v + 1));
        }
        // close the yarn through the copy of its first vertex when it leaves the tile
        let last = *yarn.last().expect("yarns are non-empty");
        let e = &p.edges[last];
        if e.offset == [0, 0] {
            line.push_str(&format!(" {}", e.end + 1));
        } else {
            let u = hylc::micro::solver::local(&sol.state.y, e.end);
            let c = elim.position(e.end, e.offset, &u);
            s.push_str(&format!("v {} {} {}\n", c.x, c.y, c.z));
            extra += 1;
            line.push_str(&format!(" {extra}"));
        }
        s.push_str(&line);
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| anyhow!("{}: cannot write: {e}", path.display()))
}
