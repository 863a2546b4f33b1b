//! The chain from a cloth observable to the yarn parameters (`docs/sensitivities.md`, "The chain to the yarn"):
//!
//!   dJ/dθₖ = Σ_j (dJ/dc_j)(dc_j/dθₖ) + (d ln m)(dJ) · ∂ln ρ_A/∂θₖ,
//!
//! with dJ/dc the adjoint's material gradient and dc/dθₖ the fit's directional derivative along the samples'
//! ∂Ψ̄ᵢ/∂θₖ and dσᵢ/dθₖ (`hylc sample --sensitivities`; forward mode through the fit as it was configured, one
//! pass per parameter, [`crate::fit::fit_material_tangents`]). The last term is the cloth's mass: the areal density
//! ρ_A = ρ π r² Σ l̄ / (p₁p₂) grows as r², so ∂ln ρ_A/∂r = 2/r, and the adjoint's `mass_scale` is dJ/d ln m.
//! The reference state (rest shape, periods) is held fixed, as in the samples' derivatives.
//!
//! The samples must be those the material was fitted to: the fit is repeated with the options the material
//! records (`meta["fit options"]`) and its coefficients must come out as the material's; the sample file's yarn
//! parameters (its sidecar) must be the given ones.

use super::fit::{find_density, find_plan};
use super::sidecar::read_meta;
use super::WorkflowError;
use crate::fit::model::FitOptions;
use crate::fit::{fit_material_tangents, RecordTangent};
use crate::material::coefficients::MaterialGradient;
use crate::material::Material;
use crate::micro::sensitivity::YarnParameter;
use crate::rod::YarnMaterial;
use crate::sample::read_samples;
use std::path::Path;
use std::time::Instant;

/// dJ/dθ for every yarn parameter, with what the fit's pass reported.
#[derive(Clone, Debug)]
pub struct YarnGradient {
    /// (name of θₖ as in the yarn file, dJ/dθₖ), in the order of [`YarnParameter::ALL`]
    pub values: Vec<(&'static str, f64)>,
    /// the fit's decisions that sit at their switching point (the derivative is one-sided there)
    pub kinks: Vec<String>,
    /// the converged samples the fit used
    pub samples: usize,
    /// wall time of the fit's passes (s)
    pub wall: f64,
}

/// Σ_j a_j b_j over the coefficients of `m`.
fn dot(m: &Material, a: &MaterialGradient, b: &MaterialGradient) -> f64 {
    m.coefficients()
        .into_iter()
        .map(|c| a.get(c) * b.get(c))
        .sum()
}

/// The fit options a material records, or an error naming the file.
fn recorded_options(material: &Material, label: &str) -> Result<FitOptions, WorkflowError> {
    let v = material
        .extra
        .get("meta")
        .and_then(|m| m.get("fit options"));
    let v = v.ok_or_else(|| {
        WorkflowError::Input(format!(
            "{label}: no meta[\"fit options\"]: the material was fitted before fits recorded their options \
             (fit it again with `hylc fit`)"
        ))
    })?;
    serde_json::from_value(v.clone()).map_err(|e| {
        WorkflowError::Input(format!(
            "{label}: meta[\"fit options\"]: {e} (fit it again with `hylc fit`)"
        ))
    })
}

/// The sample file's yarn parameters (its sidecar's `yarn`) must be `yarn` (with the pattern's radius).
fn check_yarn(
    meta: &serde_json::Map<String, serde_json::Value>,
    yarn: &YarnMaterial,
    samples: &Path,
    yarn_label: &str,
) -> Result<(), WorkflowError> {
    let given = serde_json::to_value(yarn).expect("yarn parameters serialise");
    let recorded = meta.get("yarn").ok_or_else(|| {
        WorkflowError::Input(format!(
            "{}: its sidecar records no yarn parameters",
            samples.display()
        ))
    })?;
    for (key, v) in given.as_object().expect("an object") {
        if recorded.get(key) != Some(v) {
            return Err(WorkflowError::Input(format!(
                "--yarn {yarn_label}: {key} = {v}, but {} was sampled with {key} = {}",
                samples.display(),
                recorded
                    .get(key)
                    .map_or("nothing".into(), |r| r.to_string())
            )));
        }
    }
    Ok(())
}

/// dJ/dθ from the material gradient `djdc` of `material` (file `material_label`) and dJ/d ln m `dj_dlnm`,
/// through the samples in `samples` (made with `--sensitivities`) and the yarn parameters `yarn` (file
/// `yarn_label`).
pub fn yarn_gradient(
    material: &Material,
    material_label: &str,
    djdc: &MaterialGradient,
    dj_dlnm: f64,
    samples: &Path,
    yarn: &YarnMaterial,
    yarn_label: &str,
) -> Result<YarnGradient, WorkflowError> {
    let t0 = Instant::now();
    let records = read_samples(samples, false)?;
    let meta = read_meta(samples)?.ok_or_else(|| {
        WorkflowError::Input(format!(
            "{}: no sidecar (.meta.json): the yarn chain needs the plan, density and yarn it records",
            samples.display()
        ))
    })?;
    // a micro problem takes its pattern's radius: the yarn file's stands for it
    let r = sampled_radius(&meta, samples)?;
    let mut yarn = yarn.clone();
    yarn.radius = r;
    check_yarn(&meta, &yarn, samples, yarn_label)?;
    let plan = find_plan(None, Some(&meta), &records, samples)?;
    let density = find_density(None, Some(&meta), samples)?;
    let opts = recorded_options(material, material_label)?;
    let converged = records
        .iter()
        .filter(|r| r.converged_psi().is_some())
        .collect::<Vec<_>>();
    if let Some(r) = converged.iter().find(|r| r.dpsi_dtheta.is_none()) {
        return Err(WorkflowError::Input(format!(
            "{}: sample {} has no dpsi_dtheta: run `hylc sample` on it again with --sensitivities (it adds \
             them to the finished samples)",
            samples.display(),
            r.id
        )));
    }
    let tangents: Vec<Vec<RecordTangent>> = (0..YarnParameter::ALL.len())
        .map(|k| {
            records
                .iter()
                .map(|r| RecordTangent {
                    psi: r.dpsi_dtheta.map_or(0.0, |d| d.to_array()[k]),
                    stress: r.dstress_dtheta.map(|d| d.to_array()[k]),
                })
                .collect()
        })
        .collect();
    let (fit, dcs, kinks) = fit_material_tangents(
        &plan,
        &records,
        density,
        Default::default(),
        &opts,
        &tangents,
    )
    .map_err(|source| WorkflowError::Fit {
        samples: samples.to_path_buf(),
        source,
    })?;
    belongs_together(material, &fit.material, material_label, samples)?;
    let values = YarnParameter::ALL
        .iter()
        .zip(&dcs)
        .map(|(&p, dc)| {
            let mass = if p == YarnParameter::Radius {
                dj_dlnm * 2.0 / r
            } else {
                0.0
            };
            (p.name(), dot(material, djdc, dc) + mass)
        })
        .collect();
    Ok(YarnGradient {
        values,
        kinks: kinks.kinks.iter().map(|k| k.to_string()).collect(),
        samples: converged.len(),
        wall: t0.elapsed().as_secs_f64(),
    })
}

/// The radius the samples were solved with: the pattern's (a micro problem takes its pattern's radius), from the
/// sidecar's `.pyp` text.
fn sampled_radius(
    meta: &serde_json::Map<String, serde_json::Value>,
    samples: &Path,
) -> Result<f64, WorkflowError> {
    let file = super::sidecar::meta_path(samples).display().to_string();
    let text = meta.get("pyp").and_then(|p| p.as_str()).ok_or_else(|| {
        WorkflowError::Input(format!(
            "{file}: no `pyp` (the pattern the samples were solved on)"
        ))
    })?;
    let (p, _) = crate::pattern::Pattern::from_pyp_str(text, &file)?;
    Ok(p.radius)
}

/// The refit must give the material's coefficients (to 1e-12 of the largest): else the material was not fitted
/// to these samples with its recorded options.
fn belongs_together(
    material: &Material,
    refit: &Material,
    material_label: &str,
    samples: &Path,
) -> Result<(), WorkflowError> {
    let (a, b) = (material.coefficients(), refit.coefficients());
    let mismatch = |what: String| {
        WorkflowError::Input(format!(
            "{material_label} and {} do not belong together: {what} (the material is not the fit of these \
             samples with its recorded options)",
            samples.display()
        ))
    };
    if a != b {
        return Err(mismatch(format!(
            "{} coefficients in the material, {} refitted",
            a.len(),
            b.len()
        )));
    }
    let scale = a
        .iter()
        .map(|&c| material.coefficient(c).abs())
        .fold(0.0, f64::max);
    for c in a {
        let (x, y) = (material.coefficient(c), refit.coefficient(c));
        if (x - y).abs() > 1e-12 * scale {
            return Err(mismatch(format!(
                "{c} is {x:e} in the material, {y:e} refitted"
            )));
        }
    }
    Ok(())
}
