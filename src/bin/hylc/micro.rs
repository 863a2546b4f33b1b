//! `hylc solve`, `hylc reference`, `hylc sensitivity`: the micro solver on one pattern
//! (`03-homogenization.md`; `hylc::micro`).

use hylc::generate::default_pattern;
use hylc::micro::envelope::{parameter_derivatives, strain_derivatives, PARAMETER_NAMES};
use hylc::micro::solver::world_positions;
use hylc::micro::strain::STRAIN_NAMES;
use hylc::micro::{MacroStrain, MicroProblem, Solution, SolverOptions};
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use serde_json::json;
use std::path::Path;

/// A pattern from a `.pyp` file, or a generated one by kind name (`plain`, `twill`, `satin`, `basket`,
/// `stockinette`). A file whose periods disagree with its rest lengths is used at the implied periods (with a
/// note on stderr).
pub fn load_pattern(arg: &str) -> Result<Pattern, String> {
    let path = Path::new(arg);
    if path.extension().is_some_and(|e| e == "pyp") || path.exists() {
        let (p, replaced) =
            Pattern::load_pyp_at_implied_periods(path).map_err(|e| e.to_string())?;
        if let Some(stored) = replaced {
            eprintln!(
                "note: {arg}: periods {stored:?} disagree with the rest lengths; using the implied periods {:?}",
                p.periods
            );
        }
        Ok(p)
    } else {
        default_pattern(arg).map_err(|e| format!("{arg}: not a file, and {e}"))
    }
}

/// Parse "sx,sa,sy[,II00,II11]".
pub fn parse_strain(text: &str) -> Result<MacroStrain, String> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| format!("--z: cannot parse {s:?} in {text:?}"))
        })
        .collect::<Result<_, _>>()?;
    match v.len() {
        3 => Ok(MacroStrain::in_plane(v[0], v[1], v[2])),
        5 => Ok(MacroStrain::new(v[0], v[1], v[2], v[3], v[4])),
        k => Err(format!(
            "--z: expected 3 (s_x,s_a,s_y) or 5 (s_x,s_a,s_y,II00,II11) numbers, got {k} in {text:?}"
        )),
    }
}

fn report(problem: &MicroProblem, sol: &Solution) -> serde_json::Value {
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
        "stress": stress.map(|s| STRAIN_NAMES.iter().zip(s).map(|(n, v)| (n.to_string(), json!(v))).collect::<serde_json::Map<_, _>>()),
        "steps": sol.steps,
        "gradient_norm": sol.gradient_norm,
        "time": sol.time,
        "timings": { "start": t.start, "assembly": t.assembly, "contact": t.contact,
                     "factorization": t.factorization, "line_search": t.line_search },
    })
}

/// The construction of a pattern argument (it selects C1's tension factors): the flag when given, else knitted
/// for the generated stockinette and woven for the other generated kinds; a file needs the flag.
pub fn construction_of(
    arg: &str,
    flag: Option<&str>,
) -> Result<hylc::micro::reference::Construction, String> {
    use hylc::micro::reference::Construction;
    match flag {
        Some("knitted") | Some("knit") => Ok(Construction::Knitted),
        Some("woven") | Some("weave") => Ok(Construction::Woven),
        Some(other) => Err(format!(
            "--construction: expected knitted or woven, got {other:?}"
        )),
        None if Path::new(arg).exists() => Err(format!(
            "{arg}: pass --construction knitted|woven (it selects the tension factors)"
        )),
        None if arg == "stockinette" => Ok(Construction::Knitted),
        None => Ok(Construction::Woven),
    }
}

/// `hylc solve`.
#[allow(clippy::too_many_arguments)]
pub fn solve(
    pattern: &str,
    z: &[String],
    cold: bool,
    predictor: bool,
    options: SolverOptions,
    obj: Option<&Path>,
    json_out: bool,
    quadrature: Option<usize>,
) -> Result<bool, String> {
    let p = load_pattern(pattern)?;
    let mut yarn = YarnMaterial::default();
    if let Some(q) = quadrature {
        if q == 0 {
            return Err("--quadrature: expected at least 1 point per segment".into());
        }
        yarn.contact_quadrature = q;
    }
    let problem = MicroProblem::new(p, &yarn, options);
    let strains: Vec<MacroStrain> = if z.is_empty() {
        vec![MacroStrain::ZERO]
    } else {
        z.iter()
            .map(|s| parse_strain(s))
            .collect::<Result<_, _>>()?
    };
    let mut all_ok = true;
    let mut prev: Option<Solution> = None;
    let mut before: Option<Solution> = None;
    for (k, strain) in strains.iter().enumerate() {
        // warm start from the previous solution, extrapolated along the chain when two are available
        let predicted = match (&before, &prev) {
            (Some(a), Some(b)) if !cold && predictor && a.psi().is_ok() && b.psi().is_ok() => {
                problem
                    .predict(&a.state, &b.state, strain)
                    .map_err(|e| e.to_string())?
            }
            _ => None,
        };
        let start = if cold {
            None
        } else {
            predicted.as_ref().or(prev.as_ref().map(|s| &s.state))
        };
        let sol = problem.solve(strain, start).map_err(|e| e.to_string())?;
        let r = report(&problem, &sol);
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
            let t = &sol.timings;
            println!(
                "  time: start {:.3} s, assembly {:.3} s, contact {:.3} s, factorisation {:.3} s, line search {:.3} s",
                t.start, t.assembly, t.contact, t.factorization, t.line_search
            );
        }
        all_ok &= sol.psi().is_ok();
        if let Some(path) = obj {
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
    Ok(all_ok)
}

/// The yarn centre lines of a solution as OBJ polylines (one `l` element per yarn, home tile).
pub fn write_obj(problem: &MicroProblem, sol: &Solution, path: &Path) -> Result<(), String> {
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
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

/// `hylc sensitivity`: Ψ̄ and its derivatives with respect to the strain and the yarn parameters at one strain.
pub fn sensitivity(pattern: &str, z: &str, options: SolverOptions) -> Result<bool, String> {
    let p = load_pattern(pattern)?;
    let problem = MicroProblem::new(p, &YarnMaterial::default(), options);
    let strain = parse_strain(z)?;
    let sol = problem.solve(&strain, None).map_err(|e| e.to_string())?;
    let psi = sol.psi().map_err(|e| e.to_string())?;
    let ds = strain_derivatives(&problem, &sol.state).map_err(|e| e.to_string())?;
    let dp = parameter_derivatives(&problem, &sol).map_err(|e| e.to_string())?;
    println!("Ψ̄ = {psi:.6e} J/m² ({} steps)", sol.steps);
    for (n, v) in STRAIN_NAMES.iter().zip(ds) {
        match v {
            Some(v) => println!("  ∂Ψ̄/∂{n} = {v:.6e}"),
            None => println!("  ∂Ψ̄/∂{n}: not available (bending along the other axis)"),
        }
    }
    for (n, v) in PARAMETER_NAMES.iter().zip(dp) {
        println!("  ∂Ψ̄/∂{n} = {v:.6e}");
    }
    let st =
        hylc::micro::envelope::strain_stiffness(&problem, &sol.state).map_err(|e| e.to_string())?;
    let names: Vec<&str> = st.components.iter().map(|&k| STRAIN_NAMES[k]).collect();
    println!("  d²Ψ̄/dz² over ({}):", names.join(", "));
    for i in 0..names.len() {
        let row: Vec<String> = (0..names.len())
            .map(|j| format!("{:>13.5e}", st.hessian[(i, j)]))
            .collect();
        println!("    {}", row.join(" "));
    }
    Ok(true)
}

/// `hylc reference`: Algorithm C1 on a pattern, written as `.pyp`.
pub fn reference(
    pattern: &str,
    construction: Option<&str>,
    equilibrate_only: bool,
    out: &Path,
    json_out: Option<&Path>,
) -> Result<bool, String> {
    use hylc::micro::reference::{reference_state, Construction, ReferenceOptions};
    let p = load_pattern(pattern)?;
    let construction = if equilibrate_only && construction.is_none() {
        Construction::Woven
    } else {
        construction_of(pattern, construction)?
    };
    let (q, report) = reference_state(
        &p,
        &YarnMaterial::default(),
        construction,
        &SolverOptions::default(),
        &ReferenceOptions {
            stress_free_and_tension: !equilibrate_only,
            ..Default::default()
        },
    )
    .map_err(|e| format!("{pattern}: {e}"))?;
    q.save_pyp(out).map_err(|e| e.to_string())?;
    println!(
        "{pattern} ({}): {} stress-free round(s) (relaxed energy {:.2e} J); zero-stress periods \
         {:.6e} x {:.6e} m (strain {:+.4}%, {:+.4}%, {} Newton steps, residual tile forces {:.1e}, {:.1e} N); \
         Ψ̄(0) = {:.6e} J/m²; {:.2} s; wrote {}",
        if equilibrate_only {
            "equilibrated only".to_string()
        } else {
            format!("{construction:?}")
        },
        report.rounds,
        report.stress_free_energy,
        report.periods_out[0],
        report.periods_out[1],
        100.0 * report.period_strain[0],
        100.0 * report.period_strain[1],
        report.period_steps,
        report.residual_force[0],
        report.residual_force[1],
        report.psi,
        report.time,
        out.display()
    );
    if let Some(path) = json_out {
        let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(true)
}
