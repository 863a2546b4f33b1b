//! `hylc identify PATTERN.pyp`: the yarn parameters from the original's data by Levenberg–Marquardt with the
//! solver's own derivatives (docs/yarn-parameters.md; `hylc::validation::identify`).

use crate::args::{parse_list, SolverArgs, YarnArgs};
use crate::strain::load_pattern_noted;
use anyhow::{anyhow, bail};
use hylc::material::Material;
use hylc::micro::SolverOptions;
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use hylc::strain::StrainComponent;
use hylc::validation::grid::{grid_coords, GridData, GRID_LEN};
use hylc::validation::identify::conventions::{check_conventions, ConventionRow};
use hylc::validation::identify::held_out::{curve_points, held_out, study, HeldOut};
use hylc::validation::identify::plot::{plot_study, write_plots};
use hylc::validation::identify::residuals::{CurveTarget, GridTarget};
use hylc::validation::identify::{
    identify, stored_state_pattern, Breakdown, Identification, IdentifyError, IdentifyOptions,
    Iteration, Residuals, StoredTarget, BOUNDS, UNKNOWNS, UNKNOWN_KEYS,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Identify the yarn parameters of a pattern from the original's data: Levenberg–Marquardt on (a) the
/// equilibrium residual at the stored state, (b) the original's displacements at grid points near z = 0,
/// (c) the original material's 1D curve(s); after a check of the conventions. Writes the identified yarn JSON,
/// a JSON report and plots.
#[derive(clap::Args)]
pub struct Args {
    /// `.pyp` file of the original pattern
    pattern: String,
    /// displacement folder with `axes.txt` and `data.npy` (residual b, the conventions check, --validate)
    #[arg(long)]
    data: Option<PathBuf>,
    /// the original material JSON (residual c, --validate)
    #[arg(long)]
    material: Option<PathBuf>,
    /// residual sets: a (stored-state equilibrium), b (grid displacements), c (1D curves of the material)
    #[arg(long, default_value = "a,b,c")]
    residuals: String,
    /// weights of a, b, c
    #[arg(long, default_value = "1,1,1")]
    weights: String,
    /// grid points of b: those within this index distance of z = 0 (1: the six nearest), or `all`
    #[arg(long, default_value = "1")]
    grid_steps: String,
    /// strain components of c (s_x, s_a, s_y, II00, II11)
    #[arg(long, default_value = "s_x")]
    curve_terms: String,
    /// points per 1D curve in c (evenly over the original's range)
    #[arg(long, default_value_t = 8)]
    curve_points: usize,
    /// unknowns held at their start value: young, gamma, shear_ratio, contact, radius_factor
    #[arg(long, value_delimiter = ',')]
    fix: Vec<String>,
    /// Levenberg–Marquardt iteration limit
    #[arg(long, default_value_t = 30)]
    max_iterations: usize,
    /// skip the conventions check
    #[arg(long)]
    no_conventions: bool,
    /// also compare the full 9×9×9 grid and the five 1D curves before and after (the validation numbers; several
    /// minutes per grid)
    #[arg(long)]
    validate: bool,
    /// keep the `.pyp` file's periods even where they disagree with the rest lengths (by default the implied
    /// periods are used, as in `hylc solve` and `hylc micro-grid`)
    #[arg(long)]
    file_periods: bool,
    /// also write what drives the fit: θ ∂Ψ̄/∂θ along the original's five 1D ranges at the identified
    /// parameters (study.png, and in the report)
    #[arg(long)]
    study: bool,
    /// output folder (default out/identify/PATTERN-STEM)
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    yarn: YarnArgs,
}

/// `hylc identify`: exit code 2 on bad input, 3 when a solve the residuals need does not converge at the start.
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let yarn = a.yarn.material()?;
    let mut choice = ResidualChoice::parse(&a)?;
    let inputs = Inputs::load(&a, &yarn, &choice)?;
    choice.hold_stiffness_scale();
    let solver = a.solver.options();
    let out = &inputs.out;
    std::fs::create_dir_all(out).map_err(|e| anyhow!("{}: cannot create: {e}", out.display()))?;
    // item 4: conventions first
    let conventions = match (&inputs.data, a.no_conventions) {
        (Some(d), false) => {
            let file_pattern = inputs.file_pattern.as_ref();
            let rows = check_conventions(&inputs.pattern, file_pattern, &yarn, &solver, d)
                .map_err(|e| anyhow!("{}: conventions check: {e}", a.pattern))?;
            print_conventions(&rows);
            rows
        }
        _ => vec![],
    };
    let residuals = residuals(&a, &choice, &inputs)?;
    let options = IdentifyOptions {
        free: choice.free,
        max_iterations: a.max_iterations,
        solver: solver.clone(),
        ..Default::default()
    };
    print_start(&a.pattern, &inputs.pattern, &choice);
    let pattern = &inputs.pattern;
    let result = match identify(pattern, &yarn, &residuals, &options, &mut print_iteration) {
        Ok(r) => r,
        Err(e @ IdentifyError::NotConverged { .. }) => {
            eprintln!("error: {}: {e}", a.pattern);
            return Ok(ExitCode::from(3));
        }
        Err(e) => return Err(anyhow!("{}: {e}", a.pattern)),
    };
    print_result(&result);
    let yarn_path = out.join("identified.yarn.json");
    result.identified.save_json(&yarn_path)?;
    // item 5: the held-out numbers before and after
    let validation = validate(&a, &inputs, &result, &solver)?;
    write_plots(out, &inputs.stem, &result, validation.as_deref())?;
    let study_curves = match (&inputs.original, a.study) {
        (Some(m), true) => {
            let curves = study(pattern, &result.identified, &solver, m, 12)
                .map_err(|e| anyhow!("{}: study: {e}", a.pattern))?;
            plot_study(out, &inputs.stem, &curves)?;
            Some(curves)
        }
        (None, true) => bail!("--study needs --material FILE"),
        _ => None,
    };
    let report = serde_json::json!({
        "pattern": a.pattern,
        "data": a.data,
        "material": a.material,
        "residuals": choice.sets,
        "weights": choice.weights,
        "conventions": conventions,
        "identification": result,
        "validation": validation,
        "study": study_curves,
    });
    let path = out.join("report.json");
    std::fs::write(&path, serde_json::to_string_pretty(&report)? + "\n")
        .map_err(|e| anyhow!("{}: cannot write: {e}", path.display()))?;
    println!(
        "wrote {}, {} and the plots in {}",
        yarn_path.display(),
        path.display(),
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// The residual sets switched on (`--residuals`), their weights and the free unknowns (`--fix`).
struct ResidualChoice {
    sets: Vec<String>,
    weights: Vec<f64>,
    free: [bool; 5],
}

impl ResidualChoice {
    fn parse(a: &Args) -> anyhow::Result<ResidualChoice> {
        let sets: Vec<String> = parse_list(&a.residuals, "residuals")?;
        for s in &sets {
            if !["a", "b", "c"].contains(&s.as_str()) {
                bail!("--residuals: unknown set {s:?} (expected a, b or c)");
            }
        }
        let weights: Vec<f64> = parse_list(&a.weights, "weights")?;
        if weights.len() != 3 || weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            bail!(
                "--weights: expected three positive numbers (a, b, c), got {:?}",
                a.weights
            );
        }
        let mut free = [true; 5];
        for f in &a.fix {
            let k = UNKNOWN_KEYS.iter().position(|k| k == f).ok_or_else(|| {
                anyhow!(
                    "--fix: unknown {f:?} (expected one of {})",
                    UNKNOWN_KEYS.join(", ")
                )
            })?;
            free[k] = false;
        }
        Ok(ResidualChoice {
            sets,
            weights,
            free,
        })
    }

    /// Whether the residual set `s` (a, b or c) is on.
    fn on(&self, s: &str) -> bool {
        self.sets.iter().any(|x| x == s)
    }

    /// Without residual c nothing fixes the stiffness scale: ln Y is held fixed (with a note) when both it and
    /// k_c are free.
    fn hold_stiffness_scale(&mut self) {
        if !self.on("c") && self.free[0] && self.free[3] {
            eprintln!(
                "note: without residual c nothing fixes the stiffness scale (an equilibrium does not change when \
                 every stiffness scales together): ln Y is held fixed"
            );
            self.free[0] = false;
        }
    }
}

/// What the identification reads: the pattern (with the implied periods unless `--file-periods`), the pattern of
/// the stored state, the file's pattern when its periods differ, the original's displacements and material, and
/// the output folder.
struct Inputs {
    stem: String,
    out: PathBuf,
    pattern: Pattern,
    stored_pattern: Pattern,
    file_pattern: Option<Pattern>,
    data: Option<GridData>,
    original: Option<Material>,
}

impl Inputs {
    fn load(a: &Args, yarn: &YarnMaterial, choice: &ResidualChoice) -> anyhow::Result<Inputs> {
        let stem = Path::new(&a.pattern)
            .file_stem()
            .map_or("pattern".to_string(), |s| s.to_string_lossy().into_owned());
        let out = a
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/identify").join(&stem));
        let loaded = Pattern::load_pyp(&a.pattern).ok();
        let pattern = match (&loaded, a.file_periods) {
            (Some((p, _)), true) => p.clone(),
            _ => load_pattern_noted(&a.pattern)?,
        };
        let stored_pattern = match &loaded {
            Some((p, warnings)) => stored_state_pattern(p.clone(), !warnings.is_empty(), yarn)
                .map_err(|e| {
                    anyhow!(
                        "{}: equilibrium periods of the stored state: {e}",
                        a.pattern
                    )
                })?,
            None => pattern.clone(),
        };
        let file_pattern = loaded.map(|p| p.0).filter(|p| p.periods != pattern.periods);
        let data = match &a.data {
            Some(dir) => {
                let d = GridData::load(dir)?;
                d.check_pattern(&pattern)
                    .map_err(|e| anyhow!("{} with {}: {e}", a.pattern, dir.display()))?;
                Some(d)
            }
            None if choice.on("b") || a.validate => {
                bail!("--residuals b and --validate need --data DIR")
            }
            None => None,
        };
        let original = match &a.material {
            Some(path) => Some(Material::load(path)?),
            None if choice.on("c") || a.validate => {
                bail!("--residuals c and --validate need --material FILE")
            }
            None => None,
        };
        Ok(Inputs {
            stem,
            out,
            pattern,
            stored_pattern,
            file_pattern,
            data,
            original,
        })
    }
}

/// The switched-on residual sets with their targets and weights.
fn residuals(a: &Args, choice: &ResidualChoice, inputs: &Inputs) -> anyhow::Result<Residuals> {
    let weights = &choice.weights;
    let grid = match (&inputs.data, choice.on("b")) {
        (Some(d), true) => Some(GridTarget {
            points: grid_points(d, &a.grid_steps)?,
            data: d.clone(),
            weight: weights[1],
        }),
        _ => None,
    };
    let curve = match (&inputs.original, choice.on("c")) {
        (Some(m), true) => Some(curve_target(
            m,
            &a.curve_terms,
            a.curve_points,
            inputs.pattern.radius,
            weights[2],
        )?),
        _ => None,
    };
    Ok(Residuals {
        stored: choice.on("a").then(|| StoredTarget {
            pattern: inputs.stored_pattern.clone(),
            weight: weights[0],
        }),
        grid,
        curve,
    })
}

/// The line before the iterations: the pattern, the unknowns (fixed ones marked) and the residual sets.
fn print_start(name: &str, pattern: &Pattern, choice: &ResidualChoice) {
    let free = choice.free;
    println!(
        "{}: {} vertices, r = {:.4e} m; unknowns {}; residuals {}",
        name,
        pattern.len(),
        pattern.radius,
        (0..5)
            .map(|k| format!("{}{}", UNKNOWNS[k], if free[k] { "" } else { " (fixed)" }))
            .collect::<Vec<_>>()
            .join(", "),
        choice.sets.join(",")
    );
}

/// `--validate`: the full grid and the five 1D curves at the start and the identified parameters.
fn validate(
    a: &Args,
    inputs: &Inputs,
    result: &Identification,
    solver: &SolverOptions,
) -> anyhow::Result<Option<Vec<HeldOut>>> {
    if !a.validate {
        return Ok(None);
    }
    let d = inputs.data.as_ref().expect("checked above");
    let m = inputs.original.as_ref().expect("checked above");
    let mut rows = Vec::new();
    for (label, y) in [("start", &result.start), ("identified", &result.identified)] {
        eprintln!("validation ({label}): full grid and five 1D curves …");
        let h = held_out(&inputs.pattern, y, solver, Some(d), m, 12, &|| {})
            .map_err(|e| anyhow!("{}: validation: {e}", a.pattern))?;
        print_held_out(label, &h);
        rows.push(h);
    }
    Ok(Some(rows))
}

/// The compared grid points of residual b: within `steps` index steps of the start point, or all.
fn grid_points(data: &GridData, steps: &str) -> anyhow::Result<Vec<usize>> {
    let g0 = data.zero_point();
    let max = if steps == "all" {
        usize::MAX
    } else {
        steps
            .parse::<usize>()
            .ok()
            .filter(|&k| k >= 1)
            .ok_or_else(|| {
                anyhow!("--grid-steps: expected a positive integer or `all`, got {steps:?}")
            })?
    };
    let c0 = grid_coords(g0);
    Ok((0..GRID_LEN)
        .filter(|&g| {
            let c = grid_coords(g);
            let d: usize = (0..3).map(|k| c[k].abs_diff(c0[k])).sum();
            d >= 1 && d <= max
        })
        .collect())
}

/// Residual c over the given components of the original material.
fn curve_target(
    m: &Material,
    terms: &str,
    count: usize,
    radius: f64,
    weight: f64,
) -> anyhow::Result<CurveTarget> {
    let comps: Vec<StrainComponent> = parse_list(terms, "curve-terms")?;
    if count < 2 {
        bail!("--curve-points: expected at least 2, got {count}");
    }
    let mut points = Vec::new();
    for c in &comps {
        let k = c.index();
        let pts = curve_points(m, k, count, radius);
        if pts.is_empty() {
            bail!(
                "--curve-terms: the material has no 1D term {}",
                StrainComponent::NAMES[k]
            );
        }
        points.extend(pts);
    }
    Ok(CurveTarget::new(&points, weight))
}

fn print_conventions(rows: &[ConventionRow]) {
    println!("conventions at the six grid points nearest z = 0 (position error RMS in r, θ error RMS in rad):");
    for r in rows {
        println!(
            "  {:<32} position {:>8.4}  θ {:>8.4}",
            r.name, r.position_rms, r.theta_rms
        );
    }
    let best = rows
        .iter()
        .filter(|r| r.name != "theta sign flipped")
        .min_by(|a, b| a.position_rms.total_cmp(&b.position_rms));
    if let (Some(b), Some(base)) = (best, rows.first()) {
        if b.name == base.name {
            println!("  kept: as implemented (no switched convention lowers the position error)");
        } else {
            println!(
                "  lowest position error: {} ({:.4} r against {:.4} r as implemented)",
                b.name, b.position_rms, base.position_rms
            );
        }
    }
}

fn breakdown_line(b: &Breakdown) -> String {
    let f = |v: Option<f64>, unit: &str| v.map_or("-".into(), |v| format!("{v:.4}{unit}"));
    format!(
        "cost {:.4e}; a (stored-state residual) {}; b (grid RMS) {}; c (curve rel. RMS) {}",
        b.cost,
        f(b.stored_residual, ""),
        f(b.grid_rms, " r"),
        f(b.curve_rel_rms, "")
    )
}

fn print_iteration(it: &Iteration) {
    let q: Vec<String> = it
        .unknowns
        .iter()
        .map(|v| format!("{:.4}", v.exp()))
        .collect();
    println!(
        "  iteration {:>2}: {}; (Y, γ, G/Y, k_c, f) = ({}); λ {:.0e}, {} rejected{}; {:.1} s",
        it.iteration,
        breakdown_line(&it.breakdown),
        q.join(", "),
        it.lambda,
        it.rejected,
        if it.clamped.is_empty() {
            String::new()
        } else {
            format!(", clamped to the admissible box: {}", it.clamped.join(", "))
        },
        it.time
    );
    for r in &it.rejections {
        println!("      rejected {r}");
    }
}

fn print_result(r: &Identification) {
    println!(
        "stopped: {} ({} residuals, {:.1} s)",
        r.stopped, r.residual_count, r.time
    );
    println!("before: {}", breakdown_line(&r.before));
    println!("after:  {}", breakdown_line(&r.after));
    let value = |k: usize| -> f64 {
        match k {
            0 => r.identified.young,
            1 => r.identified.bend_twist_factor,
            2 => r.identified.shear / r.identified.young,
            3 => r.identified.contact_stiffness,
            _ => r.identified.contact_radius_factor,
        }
    };
    for k in 0..5 {
        let se = match r.standard_errors[k] {
            Some(s) if s.is_finite() => {
                format!("± {:.2} % (standard error of {})", 100.0 * s, UNKNOWNS[k])
            }
            Some(_) => "not identifiable from these residuals".into(),
            None => "fixed".into(),
        };
        println!(
            "  {:<14} {:>12.5e}  {se}  [admissible {:.0e} … {:.0e}]",
            UNKNOWN_KEYS[k],
            value(k),
            BOUNDS[k][0],
            BOUNDS[k][1]
        );
    }
    println!("  correlations ({}):", UNKNOWN_KEYS.join(", "));
    for row in &r.correlations {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:>6.2}")).collect();
        println!("    {}", cells.join(" "));
    }
}

fn print_held_out(label: &str, h: &HeldOut) {
    let curves: Vec<String> = h
        .curves
        .iter()
        .map(|c| format!("{} {:.1} %", c.component, 100.0 * c.rel_rms))
        .collect();
    println!(
        "  {label}: full grid RMS {} r, max {} r ({} / 729 converged); 1D curves (relative RMS): {}",
        h.grid_rms.map_or("-".into(), |v| format!("{v:.3}")),
        h.grid_max.map_or("-".into(), |v| format!("{v:.2}")),
        h.grid_converged.unwrap_or(0),
        curves.join(", ")
    );
}
