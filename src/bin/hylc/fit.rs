//! `hylc fit`: a material from a sample file (Algorithm C5; `04-sampling-fitting.md`, "Fitting (C5, C6, C7)";
//! `hylc::fit::model`), with the JSON fit report and PNG plots.

use crate::sample::{load_plan, meta_path};
use hylc::fit::model::{compare_1d, fit_material, model_error, FitOptions, FitReport};
use hylc::fit::plot::plot_material_fit;
use hylc::fit::SlopeSource;
use hylc::material::Material;
use hylc::sample::{read_samples, Plan, Record};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Settings of `hylc fit` besides the file names.
pub struct FitArgs {
    pub plan: Option<String>,
    pub density: Option<f64>,
    pub holdout: Vec<PathBuf>,
    pub compare: Option<PathBuf>,
    pub options: FitOptions,
    pub plots: bool,
}

/// The slope source by name.
pub fn parse_slopes(s: &str) -> Result<SlopeSource, String> {
    match s {
        "fd" => Ok(SlopeSource::FiniteDifference),
        "stress" => Ok(SlopeSource::Stress),
        _ => Err(format!("--slopes: expected fd or stress, got {s:?}")),
    }
}

/// The sidecar written by `hylc sample`, if there is one.
fn read_meta(samples: &Path) -> Result<Option<serde_json::Map<String, serde_json::Value>>, String> {
    let path = meta_path(samples);
    match std::fs::read_to_string(&path) {
        Ok(text) => match serde_json::from_str::<serde_json::Value>(&text) {
            Ok(serde_json::Value::Object(m)) => Ok(Some(m)),
            Ok(_) => Err(format!("{}: expected a JSON object", path.display())),
            Err(e) => Err(format!("{}: not JSON: {e}", path.display())),
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(format!("{}: cannot read: {e}", path.display())),
    }
}

/// The plan of the samples: `--plan`, else the sidecar's, else the built-in plan whose hash the ids carry.
fn find_plan(
    arg: Option<&str>,
    meta: Option<&serde_json::Map<String, serde_json::Value>>,
    records: &[Record],
    samples: &Path,
) -> Result<Plan, String> {
    if let Some(a) = arg {
        return load_plan(a);
    }
    if let Some(p) = meta.and_then(|m| m.get("plan")) {
        return Plan::from_json(
            &p.to_string(),
            Some(&meta_path(samples).display().to_string()),
        )
        .map_err(|e| e.to_string());
    }
    let hash = records
        .first()
        .and_then(|r| r.id.split('-').next())
        .unwrap_or_default()
        .to_string();
    for p in [Plan::default(), Plan::reduced()] {
        if format!("{:016x}", p.hash()) == hash {
            return Ok(p);
        }
    }
    Err(format!(
        "{}: the samples come from plan {hash}, which is neither the default nor the reduced plan; pass --plan",
        samples.display()
    ))
}

/// `hylc fit`.
pub fn fit(
    samples: &Path,
    out: &Path,
    report: &Path,
    plots: &Path,
    args: FitArgs,
) -> Result<FitReport, String> {
    let t0 = Instant::now();
    let records = read_samples(samples, false)?;
    if records.is_empty() {
        return Err(format!("{}: no samples", samples.display()));
    }
    let meta = read_meta(samples)?;
    let plan = find_plan(args.plan.as_deref(), meta.as_ref(), &records, samples)?;
    let density = match (args.density, meta.as_ref().and_then(|m| m.get("density"))) {
        (Some(d), _) => d,
        (None, Some(d)) => d.as_f64().ok_or_else(|| {
            format!(
                "{}: density: expected a number",
                meta_path(samples).display()
            )
        })?,
        (None, None) => {
            return Err(format!(
                "{}: no sidecar {} with the pattern's areal density; pass --density (kg/m²)",
                samples.display(),
                meta_path(samples).display()
            ))
        }
    };
    if !(density.is_finite() && density > 0.0) {
        return Err(format!("density {density} must be finite and > 0"));
    }
    let mut material_meta = serde_json::Map::new();
    material_meta.insert(
        "samples".into(),
        serde_json::json!(samples.display().to_string()),
    );
    if let Some(m) = &meta {
        for key in ["pattern", "pyp hash", "problem", "yarn", "solver"] {
            if let Some(v) = m.get(key) {
                material_meta.insert(key.into(), v.clone());
            }
        }
    }
    let mut fit = fit_material(&plan, &records, density, material_meta, &args.options)
        .map_err(|e| format!("{}: {e}", samples.display()))?;
    for h in &args.holdout {
        let mut hr = read_samples(h, false)?;
        // a file from a plan with an in-plane grid contributes its grid samples only
        if let Some(hp) = read_meta(h)?
            .and_then(|m| m.get("plan").cloned())
            .and_then(|p| Plan::from_json(&p.to_string(), None).ok())
        {
            if hp.grid.is_some() {
                hr.retain(|r| r.index >= hp.grid_start());
            }
        }
        if hr.is_empty() {
            return Err(format!("{}: no samples", h.display()));
        }
        let e = model_error(&fit.material, &hr);
        if let Some(serde_json::Value::Object(m)) = fit.material.extra.get_mut("meta") {
            m.insert(
                "holdout".into(),
                serde_json::json!({"file": h.display().to_string(), "samples": e.n_samples,
                    "rms_rel": e.rms_rel, "max_rel": e.max_rel}),
            );
        }
        fit.report.holdout = Some(e);
    }
    if let Some(c) = &args.compare {
        let other = Material::load(c).map_err(|e| e.to_string())?;
        fit.report.compare_1d = Some(compare_1d(&fit, &plan, &records, &other));
    }
    fit.material
        .save(out)
        .map_err(|e| format!("{}: cannot write: {e}", out.display()))?;
    let text = serde_json::to_string_pretty(&fit.report).map_err(|e| e.to_string())?;
    std::fs::write(report, text + "\n")
        .map_err(|e| format!("{}: cannot write: {e}", report.display()))?;

    let r = &fit.report;
    println!(
        "{}: plan {}, {} samples, {} converged; σ = {:?}, f₀ = {:.6e} J/m² (sample at {:?}; in-plane 1D fits \
         at 0 differ by up to {:.2e})",
        samples.display(),
        r.plan_hash,
        r.samples,
        r.converged,
        r.strain_scale,
        r.constant,
        r.constant_at,
        r.constant_spread
    );
    println!("term            samples  failed  fit RMS   model RMS  model max");
    for t in &r.terms1d {
        println!(
            "{:<15} {:>7} {:>7}  {:>8.2e}  {:>9.2e}  {:>9.2e}",
            t.strain, t.n_samples, t.n_excluded, t.fit_rms_rel, t.model.rms_rel, t.model.max_rel
        );
    }
    for t in &r.terms2d {
        println!(
            "{:<15} {:>7} {:>7}  {:>8.2e}  {:>9.2e}  {:>9.2e}{}",
            format!("{}×{}", t.strains[0], t.strains[1]),
            t.n_samples,
            t.n_excluded,
            t.fit_rms_rel,
            t.model.rms_rel,
            t.model.max_rel,
            if t.nonmonotone_patches > 0 {
                format!("  ({} non-monotone patches)", t.nonmonotone_patches)
            } else {
                String::new()
            }
        );
    }
    println!(
        "all fitted samples: model RMS {:.2e}, max {:.2e} (relative)",
        r.all.rms_rel, r.all.max_rel
    );
    if let Some(h) = &r.holdout {
        println!(
            "held-out samples: {} ({} failed): model RMS {:.2e}, max {:.2e} (relative){}",
            h.n_samples,
            h.n_excluded,
            h.rms_rel,
            h.max_rel,
            h.worst.map_or(String::new(), |(z, p, m)| format!(
                "; worst at z = {z:?}: Ψ̄ = {p:.4e}, ψ = {m:.4e}"
            ))
        );
    }
    if let Some(cmp) = &r.compare_1d {
        println!(
            "1D curves f₀ + f_k against {} (relative RMS over its sampled range; common stiffness factor c = {:.4}):",
            args.compare.as_ref().map_or(String::new(), |p| p.display().to_string()),
            cmp.common_scale
        );
        println!("strain   points  interval             our fit  our samples  f_k alone  best c   c × our fit");
        for c in &cmp.ranges {
            println!(
                "{:<8} {:>6}  [{:>8.3}, {:>8.3}]  {:>7.3}  {:>11.3}  {:>9.3}  {:>6.4}  {:>11.3}",
                c.strain,
                c.n_points,
                c.interval[0],
                c.interval[1],
                c.fit_rms_rel,
                c.samples_rms_rel,
                c.term_rms_rel,
                c.scale,
                c.scaled_fit_rms_rel
            );
        }
    }
    println!("wrote {} and {}", out.display(), report.display());
    if args.plots {
        match plot_material_fit(plots, &fit) {
            Ok(paths) => println!("wrote {} plots to {}", paths.len(), plots.display()),
            Err(e) => eprintln!("warning: plots not written: {e}"),
        }
    }
    println!("fit time {:.2} s", t0.elapsed().as_secs_f64());
    Ok(fit.report)
}
