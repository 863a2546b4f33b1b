//! A material from a sample file (Algorithm C5; `docs/sampling.md`, "Fitting (C5, C6, C7)"), with the
//! material JSON, the JSON fit report and the PNG plots written, and the per-term error table reported.

use super::inputs::load_plan;
use super::sidecar::{meta_path, read_meta};
use super::{write_file, Event, WorkflowError};
use crate::fit::model::{
    check_records, compare_1d, fit_material, model_error, FitOptions, FitReport,
};
use crate::fit::plot::plot_material_fit;
use crate::fit::FitPreset;
use crate::material::Material;
use crate::sample::{read_samples, Plan, Record};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to fit and where to write it.
pub struct FitJob {
    /// The sample file (JSON lines from `hylc sample`).
    pub samples: PathBuf,
    /// The material file to write.
    pub out: PathBuf,
    /// The JSON fit report to write.
    pub report: PathBuf,
    /// The folder of the PNG plots.
    pub plots: PathBuf,
    /// The plan of the samples (default: the sidecar's, or the built-in plan the ids name).
    pub plan: Option<String>,
    /// Areal density ρ_A in kg/m² (default: the sidecar's).
    pub density: Option<f64>,
    /// Held-out sample files whose Ψ̄ the model must predict.
    pub holdout: Vec<PathBuf>,
    /// Another material to compare the fitted 1D curves with.
    pub compare: Option<PathBuf>,
    /// The fit's options.
    pub options: FitOptions,
    /// Write the plots.
    pub write_plots: bool,
}

impl FitJob {
    /// A job with the default file names beside `samples` (`.material.json`, `.fit.json`, `.plots`) and the
    /// default preset's options ([`FitPreset::Covering`]).
    pub fn beside(samples: &Path) -> Self {
        FitJob {
            samples: samples.to_path_buf(),
            out: samples.with_extension("material.json"),
            report: samples.with_extension("fit.json"),
            plots: samples.with_extension("plots"),
            plan: None,
            density: None,
            holdout: Vec::new(),
            compare: None,
            options: FitPreset::default().options(),
            write_plots: true,
        }
    }
}

/// How the material file `out` names the file `f`: by its name alone when both are in the same folder (so that
/// the material reads the same wherever the folder is), else as given.
fn beside_name(f: &Path, out: &Path) -> String {
    let dir =
        |p: &Path| std::fs::canonicalize(p.parent().filter(|d| !d.as_os_str().is_empty())?).ok();
    match (dir(f), dir(out), f.file_name()) {
        (Some(a), Some(b), Some(name)) if a == b => name.to_string_lossy().into_owned(),
        _ => f.display().to_string(),
    }
}

/// The plan of the samples: the given one, else the sidecar's, else the built-in plan whose hash the ids carry.
pub(super) fn find_plan(
    arg: Option<&str>,
    meta: Option<&serde_json::Map<String, serde_json::Value>>,
    records: &[Record],
    samples: &Path,
) -> Result<Plan, WorkflowError> {
    if let Some(a) = arg {
        return load_plan(a);
    }
    if let Some(p) = meta.and_then(|m| m.get("plan")) {
        return Ok(Plan::from_json(
            &p.to_string(),
            Some(&meta_path(samples).display().to_string()),
        )?);
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
    Err(WorkflowError::Input(format!(
        "{}: the samples come from plan {hash}, which is neither the default nor the reduced plan; pass --plan",
        samples.display()
    )))
}

/// The areal density: the given one, else the sidecar's.
pub(super) fn find_density(
    given: Option<f64>,
    meta: Option<&serde_json::Map<String, serde_json::Value>>,
    samples: &Path,
) -> Result<f64, WorkflowError> {
    let density = match (given, meta.and_then(|m| m.get("density"))) {
        (Some(d), _) => d,
        (None, Some(d)) => d.as_f64().ok_or_else(|| {
            WorkflowError::Input(format!(
                "{}: density: expected a number",
                meta_path(samples).display()
            ))
        })?,
        (None, None) => {
            return Err(WorkflowError::Input(format!(
                "{}: no sidecar {} with the pattern's areal density; pass --density (kg/m²)",
                samples.display(),
                meta_path(samples).display()
            )))
        }
    };
    if !(density.is_finite() && density > 0.0) {
        return Err(WorkflowError::Input(format!(
            "density {density} must be finite and > 0"
        )));
    }
    Ok(density)
}

/// Fit the material of `job.samples`, write the material, the report and (optionally) the plots; the error
/// table and the written files are reported as [`Event::Print`] lines.
pub fn fit_samples(
    job: &FitJob,
    on_event: &mut (dyn FnMut(Event) + Send),
) -> Result<FitReport, WorkflowError> {
    let t0 = Instant::now();
    let samples = job.samples.as_path();
    for f in std::iter::once(samples).chain(job.holdout.iter().map(|h| h.as_path())) {
        if !f.exists() {
            return Err(WorkflowError::Input(format!(
                "{}: no such sample file",
                f.display()
            )));
        }
    }
    let records = read_samples(samples, false)?;
    if records.is_empty() {
        return Err(WorkflowError::Input(format!(
            "{}: no samples",
            samples.display()
        )));
    }
    let meta = read_meta(samples)?;
    let plan = find_plan(job.plan.as_deref(), meta.as_ref(), &records, samples)?;
    let density = find_density(job.density, meta.as_ref(), samples)?;
    let mut material_meta = serde_json::Map::new();
    material_meta.insert(
        "samples".into(),
        serde_json::json!(beside_name(samples, &job.out)),
    );
    if let Some(m) = &meta {
        for key in ["pattern", "pyp hash", "problem", "yarn", "solver"] {
            if let Some(v) = m.get(key) {
                material_meta.insert(key.into(), v.clone());
            }
        }
    }
    let mut fit =
        fit_material(&plan, &records, density, material_meta, &job.options).map_err(|source| {
            WorkflowError::Fit {
                samples: samples.to_path_buf(),
                source,
            }
        })?;
    for h in &job.holdout {
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
            return Err(WorkflowError::Input(format!("{}: no samples", h.display())));
        }
        let fit_error = |source| WorkflowError::Fit {
            samples: h.clone(),
            source,
        };
        check_records(&hr).map_err(fit_error)?;
        let e = model_error(&fit.material, &hr);
        e.check_finite("held-out samples: model")
            .map_err(fit_error)?;
        if let Some(serde_json::Value::Object(m)) = fit.material.extra.get_mut("meta") {
            m.insert(
                "holdout".into(),
                serde_json::json!({"file": beside_name(h, &job.out), "samples": e.n_samples,
                    "rms_rel": e.rms_rel, "max_rel": e.max_rel}),
            );
        }
        fit.report.holdout = Some(e);
    }
    if let Some(c) = &job.compare {
        let other = Material::load(c)?;
        fit.report.compare_1d = Some(compare_1d(&fit, &plan, &records, &other));
    }
    fit.material
        .save(&job.out)
        .map_err(|e| WorkflowError::io(&job.out, "cannot write", e))?;
    let mut value = serde_json::to_value(&fit.report).expect("fit reports serialise");
    value["provenance"] = crate::provenance::Provenance::now().to_json();
    let text = serde_json::to_string_pretty(&value).expect("a JSON value serialises");
    write_file(&job.report, text + "\n")?;

    for line in report_lines(samples, &fit.report, job.compare.as_deref()) {
        on_event(Event::Print(&line));
    }
    on_event(Event::Print(&format!(
        "wrote {} and {}",
        job.out.display(),
        job.report.display()
    )));
    if job.write_plots {
        match plot_material_fit(&job.plots, &fit) {
            Ok(paths) => on_event(Event::Print(&format!(
                "wrote {} plots to {}",
                paths.len(),
                job.plots.display()
            ))),
            Err(e) => on_event(Event::Note(&format!("warning: plots not written: {e}"))),
        }
    }
    on_event(Event::Print(&format!(
        "fit time {:.2} s",
        t0.elapsed().as_secs_f64()
    )));
    Ok(fit.report)
}

/// The fit report as text: the summary line, the per-term error table, the held-out and comparison errors.
pub fn report_lines(samples: &Path, r: &FitReport, compare: Option<&Path>) -> Vec<String> {
    let mut out = vec![
        format!(
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
        ),
        "term            samples  failed  fit RMS   model RMS  model max".to_string(),
    ];
    for t in &r.terms1d {
        out.push(format!(
            "{:<15} {:>7} {:>7}  {:>8.2e}  {:>9.2e}  {:>9.2e}",
            t.strain, t.n_samples, t.n_excluded, t.fit_rms_rel, t.model.rms_rel, t.model.max_rel
        ));
    }
    for t in &r.terms2d {
        out.push(format!(
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
        ));
    }
    out.push(format!(
        "all fitted samples: model RMS {:.2e}, max {:.2e} (relative)",
        r.all.rms_rel, r.all.max_rel
    ));
    if let Some(h) = &r.holdout {
        out.push(format!(
            "held-out samples: {} ({} failed): model RMS {:.2e}, max {:.2e} (relative){}",
            h.n_samples,
            h.n_excluded,
            h.rms_rel,
            h.max_rel,
            h.worst.map_or(String::new(), |(z, p, m)| format!(
                "; worst at z = {z:?}: Ψ̄ = {p:.4e}, ψ = {m:.4e}"
            ))
        ));
    }
    if let Some(cmp) = &r.compare_1d {
        out.push(format!(
            "1D curves f₀ + f_k against {} (relative RMS over its sampled range; common stiffness factor c = {:.4}):",
            compare.map_or(String::new(), |p| p.display().to_string()),
            cmp.common_scale
        ));
        out.push(
            "strain   points  interval             our fit  our samples  f_k alone  best c   c × our fit"
                .to_string(),
        );
        for c in &cmp.ranges {
            out.push(format!(
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
            ));
        }
    }
    out
}
