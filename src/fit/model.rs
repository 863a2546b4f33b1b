//! FITSPLINES (Algorithm C5; `docs/fitting.md`, "Fitting (C5, C6, C7)"): the whole material
//! ψ(z) = f₀ + Σ_k f_k(z_k/σ_k) + Σ_(k,l) f_kl(z_k/σ_k, z_l/σ_l) from the samples of one plan.
//!
//! - Strain scales σ_k = max |z_k| over the plan's samples (1 for a strain the plan never varies).
//! - Failed samples (no Ψ̄) are excluded and counted per term.
//! - f_k = FIT1D on the 1D range of strain k ([`fit1d`]): symmetrised for s_a, minimum at 0 for the in-plane
//!   strains and at argmin p for bending.
//! - f₀ = Ψ̄ of the converged s_a-range sample nearest z = 0 (any sample if none; for the default plan the s_a samples
//!   at ±(√0.7/149)² ≈ ±3e-5, where Ψ̄ is even in s_a, so this is Ψ̄(0) to ~1e-9 relative). The 1D fits' own
//!   values at 0 (the offsets FIT1D removes, the MLS estimates of Ψ̄(0)) are reported next to it: their
//!   deviation from f₀ is a bias of the model along that range, largest on coarse plans.
//! - f_kl = FIT2D on each pair's grid ([`fit2d`]), residual form; (s_x, s_y) is neither quasi-convexified nor
//!   zero-compressed, a stretch axis of any other pair is zero-compressed, an s_a axis is symmetrised, and the
//!   minimum of a bending axis is its argmin. The pair's strains are ordered k < l in the material.
//! - Errors of the whole model ψ against every sample it was fitted to (1D ranges and 2D planes) and, optionally,
//!   against held-out samples ([`model_error`] on any sample file, e.g. the in-plane grid of [`crate::sample::plan::InPlaneGrid`]).
//!
//! The exported material carries a `meta` block (pattern, yarn parameters, plan hash, fit errors) and the
//! original's `"strain shift": [1, 0, 1, 0, 0]`, so the original macro-scale code reads it too.

use super::fit1d::{fit1d_with_stress, Fit1D, Fit1DOptions, MinimumAt, SlopeSource};
use super::fit2d::{fit2d, Fit2D, Fit2DOptions};
use super::FitError;
use crate::material::{Material, Term1D, Term2D};
use crate::sample::{Plan, Record, Sample};
use crate::strain::StrainComponent;
use serde::Serialize;

/// Options of the whole fit; [`Default`] gives the default fit (`docs/fitting.md`). A fitted material records them
/// in its `meta["fit options"]` (the same keys), so that it can be refitted as it was made.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FitOptions {
    /// N_c of FIT1D (default 11)
    pub n_knots_1d: usize,
    /// FIT1D's knot extent as a fraction of each 1D range (default 0.95)
    pub extent_1d: f64,
    /// knots per axis of FIT2D (default 9)
    pub n_knots_2d: usize,
    /// FIT2D knot extent of the in-plane pairs (default 0.9)
    pub extent_2d: f64,
    /// FIT2D knot extent of the pairs with a bending strain (default 0.9; 0.3 for stockinette-like patterns)
    pub extent_2d_bending: f64,
    /// knots per axis of the pairs with a bending strain (default 9; 5 for stockinette-like patterns)
    pub n_knots_2d_bending: usize,
    /// pˣ_min (default 0.001; 0.01 for stockinette-like patterns)
    pub min_slope: f64,
    /// MLS bandwidth factor (default 2)
    pub bandwidth_factor: f64,
    /// symlog ε relative to max |Ψ| (default 1e-3)
    pub eps_rel: f64,
    /// slope source of the 1D terms (default finite differences)
    pub slopes: SlopeSource,
    /// FIT2D's strict patch monotonicity (default true; see [`Fit2DOptions::strict_patches`])
    pub strict_patches: bool,
    /// fit each 1D term to every `thin_1d`-th sample of its range only (default 1: all); the term's model error
    /// is still measured on the whole range, so the other samples are held out (a sampling-density study)
    pub thin_1d: usize,
    /// FIT2D step 7′ instead of 7 on the pairs with one stretch axis ([`Fit2DOptions::compression_residual`];
    /// default false: step 7's zero-compression residual)
    pub compression_residual: bool,
    /// symmetrise the MLS of every term in s_a (default true, FIT1D/FIT2D step 1: Ψ̄ even in s_a);
    /// false fits the two signs of shear separately (the knits' Ψ̄ is not even: honeycomb's rest state carries a
    /// shear stress, and its Ψ̄ at s_a = ±0.75 is 3.43 against 2.31 J/m²)
    pub symmetric_shear: bool,
    /// the central-difference step of the knot slopes of every term, as a fraction of the knot spacing (default
    /// 1e-3; [`Fit1DOptions::fd_step`], [`Fit2DOptions::fd_step`])
    pub fd_step: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            n_knots_1d: 11,
            extent_1d: 0.95,
            n_knots_2d: 9,
            extent_2d: 0.9,
            extent_2d_bending: 0.9,
            n_knots_2d_bending: 9,
            min_slope: 1e-3,
            bandwidth_factor: 2.0,
            eps_rel: 1e-3,
            slopes: SlopeSource::FiniteDifference,
            thin_1d: 1,
            strict_patches: true,
            compression_residual: false,
            symmetric_shear: true,
            fd_step: 1e-3,
        }
    }
}

impl FitOptions {
    /// Settings whose spline knots cover everything sampled, for plans with few 2D samples per axis (the quick
    /// plan of `hylc run`: 6): the knots of every term span the whole sampled range (extent 1; 11 knots per 2D
    /// axis, so no sample lies beyond the knot box, where step 8 holds the residual constant, and no 1D sample
    /// on the linear continuation), the compressed half-plane keeps its residual (FIT2D step 7′), and the MLS
    /// bandwidth is one median spacing instead of two (a 6 × 6 grid's spacing is a third of the range: two
    /// spacings smooth away the biaxial stiffening); the `covering` preset ([`super::FitPreset`]).
    pub fn covering() -> Self {
        FitOptions {
            extent_1d: 1.0,
            bandwidth_factor: 1.0,
            n_knots_2d: 11,
            extent_2d: 1.0,
            n_knots_2d_bending: 11,
            extent_2d_bending: 1.0,
            compression_residual: true,
            ..FitOptions::default()
        }
    }

    /// The method's settings for stockinette-like patterns: pˣ_min = 0.01, and the pairs with a bending strain
    /// with 5 knots per axis on 0.3 of the range (the layout of the original stock1 material; its in-plane pairs
    /// keep 0.9).
    pub fn stockinette_like() -> Self {
        FitOptions {
            extent_2d_bending: 0.3,
            n_knots_2d_bending: 5,
            min_slope: 1e-2,
            ..FitOptions::default()
        }
    }
}

/// Error of the model at a set of samples.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ModelError {
    /// converged samples compared
    pub n_samples: usize,
    /// samples without Ψ̄ (failed solves), not compared
    pub n_excluded: usize,
    /// √(Σ (ψ − Ψ̄)²) / √(Σ Ψ̄²)
    pub rms_rel: f64,
    /// max |ψ − Ψ̄| / max |Ψ̄|
    pub max_rel: f64,
    /// the sample with the largest |ψ − Ψ̄|: (z, Ψ̄, ψ)
    pub worst: Option<([f64; 5], f64, f64)>,
}

impl ModelError {
    /// The first non-finite error (`rms_rel`, `max_rel`), by name.
    fn non_finite(&self) -> Option<&'static str> {
        [("rms_rel", self.rms_rel), ("max_rel", self.max_rel)]
            .into_iter()
            .find(|(_, v)| !v.is_finite())
            .map(|(name, _)| name)
    }

    /// [`FitError::NotFinite`] naming `what` when an error is not finite.
    pub fn check_finite(&self, what: &str) -> Result<(), FitError> {
        match self.non_finite() {
            Some(name) => Err(FitError::NotFinite(format!("{what} {name}"))),
            None => Ok(()),
        }
    }
}

/// One 1D term's report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Term1DReport {
    /// index k of the strain in z = (s_x, s_a, s_y, Π₀₀, Π₁₁)
    pub k: usize,
    /// the strain component of the term
    pub strain: StrainComponent,
    /// samples used / excluded (failed)
    pub n_samples: usize,
    /// samples of the range excluded (failed, no Ψ̄)
    pub n_excluded: usize,
    /// FIT1D's own fit (spline + its offset against Ψ̄)
    pub fit_rms_rel: f64,
    /// FIT1D's largest error relative to max |Ψ̄|
    pub fit_max_rel: f64,
    /// the removed constant (Ψ̄ at the minimum knot)
    pub offset: f64,
    /// index of the minimum knot (the knot at 0, or argmin p for bending)
    pub i_min: usize,
    /// the whole model ψ on this range
    pub model: ModelError,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// One 2D term's report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Term2DReport {
    /// index k of the first strain (k < l)
    pub k0: usize,
    /// index l of the second strain
    pub k1: usize,
    /// the two strain components of the term
    pub strains: [StrainComponent; 2],
    /// samples of the plane used
    pub n_samples: usize,
    /// samples of the plane excluded (failed, no Ψ̄)
    pub n_excluded: usize,
    /// FIT2D's unconverted spline against Ψ̄
    pub fit_rms_rel: f64,
    /// FIT2D's largest error relative to max |Ψ̄|
    pub fit_max_rel: f64,
    /// rounds of twist halving that FIT2D step 5 needed
    pub twist_rounds: usize,
    /// rounds of cross-slope shrinking that FIT2D step 5 needed after the twists
    pub slope_rounds: usize,
    /// patches still failing the monotonicity check of FIT2D step 5
    pub nonmonotone_patches: usize,
    /// patches of the compressed block failing FIT2D step 7′ (only with `compression_residual`)
    #[serde(skip_serializing_if = "is_zero")]
    pub compression_nonmonotone: usize,
    /// the whole model ψ on this plane
    pub model: ModelError,
}

/// The fit report (written as JSON next to the material).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitReport {
    /// the hash of the plan the samples were drawn from
    pub plan_hash: String,
    /// samples of the plan found in the file / converged among them
    pub samples: usize,
    /// converged samples of the plan (those with a Ψ̄)
    pub converged: usize,
    /// the strain scales σ_k = max |z_k| over the plan's samples (1 where the plan never varies z_k)
    pub strain_scale: [f64; 5],
    /// the constant f₀ (J/m²): Ψ̄ of the converged sample nearest z = 0
    pub constant: f64,
    /// the sample f₀ was taken from
    pub constant_at: [f64; 5],
    /// max |offset − f₀| over the three in-plane 1D fits (their MLS estimates of Ψ̄(0))
    pub constant_spread: f64,
    /// the 1D terms' reports, in the material's order
    pub terms1d: Vec<Term1DReport>,
    /// the 2D terms' reports, in the material's order
    pub terms2d: Vec<Term2DReport>,
    /// the model on every sample it was fitted to
    pub all: ModelError,
    /// the model on the held-out samples, when a held-out file was given
    pub holdout: Option<ModelError>,
    /// the 1D curves against another material ([`compare_1d`]), when asked for
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compare_1d: Option<Comparison1D>,
}

/// The data one term was fitted to (for plots): normalised coordinates and Ψ̄ (NaN for failed samples).
#[derive(Clone, Debug)]
pub struct TermData {
    /// normalised coordinate z_k/σ_k of each sample (the first axis of a 2D term)
    pub x: Vec<f64>,
    /// normalised coordinate z_l/σ_l of each sample (empty for a 1D term)
    pub y: Vec<f64>,
    /// Ψ̄ of each sample (J/m²; NaN for failed samples)
    pub psi: Vec<f64>,
}

/// A fitted material with its report and the per-term fits and data.
#[derive(Clone, Debug)]
pub struct MaterialFit {
    /// the fitted material ψ(z)
    pub material: Material,
    /// the fit report
    pub report: FitReport,
    /// the 1D fits: (strain index k, FIT1D result, its data)
    pub fits1d: Vec<(usize, Fit1D, TermData)>,
    /// the 2D fits: (strain indices k, l, FIT2D result, its data)
    pub fits2d: Vec<(usize, usize, Fit2D, TermData)>,
}

/// The material's six-component strain of a five-component sample strain (II₀₁ = 0).
pub fn strain6(z: &[f64; 5]) -> [f64; 6] {
    [z[0], z[1], z[2], z[3], 0.0, z[4]]
}

/// The largest |Ψ̄| (J/m²) and |∂Ψ̄/∂z_k| (J/m² per unit strain; J/m per 1/m for bending) a sample record may
/// carry into a fit. The default yarn (E = 1 MPa, r = 1 mm) gives Ψ̄ of order 10⁻²–10 J/m² over the default
/// plan's ranges, and yarns 10⁵ times stiffer stay below 10⁷; 10¹² leaves ample room while keeping every sum of squares
/// the fit forms (10²⁴ per sample, at most 10⁶ samples per plan) far from overflow, so a fit never turns finite
/// data into NaN. Larger values (a corrupted or hand-edited file) are an error naming the file, the sample and
/// the value ([`check_records`]).
pub const MAX_SAMPLE_VALUE: f64 = 1e12;

/// Whether a Ψ̄ or stress value may enter a fit: finite, |v| ≤ [`MAX_SAMPLE_VALUE`].
fn admissible_value(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX_SAMPLE_VALUE
}

/// Check the records of one sample file before a fit: every Ψ̄ and stress component present is finite with
/// magnitude at most [`MAX_SAMPLE_VALUE`], every strain finite, and an id given twice carries the same result
/// both times (same z, status, Ψ̄ and stresses; such an identical duplicate is fitted once, a differing one is
/// an error naming the id).
pub fn check_records(records: &[Record]) -> Result<(), FitError> {
    let bad = |r: &Record, field: &str, message: String| FitError::BadRecord {
        id: r.id.clone(),
        field: field.to_string(),
        message,
    };
    let mut seen: std::collections::HashMap<&str, &Record> = std::collections::HashMap::new();
    for r in records {
        if let Some(v) = r.z.iter().find(|v| !v.is_finite()) {
            return Err(bad(r, "z", format!("{v} is not finite")));
        }
        if let Some(p) = r.psi.filter(|&p| !admissible_value(p)) {
            return Err(bad(
                r,
                "psi",
                format!("Ψ̄ = {p:e} J/m² is not finite or beyond ±{MAX_SAMPLE_VALUE:e}"),
            ));
        }
        let stress = r.stress.iter().flatten().enumerate();
        if let Some((k, v)) = stress
            .filter_map(|(k, v)| v.map(|v| (k, v)))
            .find(|&(_, v)| !admissible_value(v))
        {
            return Err(bad(
                r,
                &format!("stress[{k}]"),
                format!("{v:e} is not finite or beyond ±{MAX_SAMPLE_VALUE:e}"),
            ));
        }
        if let Some(first) = seen.insert(r.id.as_str(), r) {
            if !first.same_result(r) {
                return Err(bad(
                    r,
                    "id",
                    format!(
                        "listed twice with different results (Ψ̄ {:?} and {:?}, status {:?} and {:?})",
                        first.psi, r.psi, first.status, r.status
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Error of `material` at the converged records (failed ones counted as excluded).
pub fn model_error<'a>(
    material: &Material,
    records: impl IntoIterator<Item = &'a Record>,
) -> ModelError {
    let mut n_excluded = 0;
    let mut err = super::RelError::default();
    let mut compared = Vec::new();
    for r in records {
        let Some(psi) = r.converged_psi() else {
            n_excluded += 1;
            continue;
        };
        let m = material.value(&strain6(&r.z));
        err.add(m, psi);
        compared.push((r.z, psi, m));
    }
    ModelError {
        n_samples: compared.len(),
        n_excluded,
        rms_rel: err.rms_rel(),
        max_rel: err.max_rel(),
        worst: err.worst().map(|i| compared[i]),
    }
}

/// The plan's records by sample index (later duplicates replace earlier ones; indices beyond the plan are
/// dropped).
pub(super) struct ByIndex<'a> {
    records: Vec<Option<&'a Record>>,
}

impl<'a> ByIndex<'a> {
    /// Index `records` by their position in `plan`; a record whose id does not carry the plan's `hash` is an
    /// error.
    pub(super) fn new(plan: &Plan, records: &'a [Record], hash: &str) -> Result<Self, FitError> {
        let n = plan.len();
        let mut by_index: Vec<Option<&Record>> = vec![None; n];
        for r in records {
            if !r.id.starts_with(hash) {
                return Err(FitError::BadOption(format!(
                    "sample {} does not belong to plan {hash} (pass the plan the samples were run with)",
                    r.id
                )));
            }
            if r.index < n {
                by_index[r.index] = Some(r);
            }
        }
        Ok(ByIndex { records: by_index })
    }

    /// The records present, in plan order.
    pub(super) fn present(&self) -> Vec<&'a Record> {
        self.records.iter().flatten().copied().collect()
    }

    /// Ψ̄ of sample `i` (NaN when missing or failed).
    pub(super) fn psi(&self, i: usize) -> f64 {
        self.records[i]
            .and_then(Record::converged_psi)
            .unwrap_or(f64::NAN)
    }

    /// The stress dΨ̄/dX of sample `i` along strain `k` in normalised units X = z_k/σ (NaN when missing).
    pub(super) fn stress(&self, i: usize, k: usize, sigma: f64) -> f64 {
        self.records[i]
            .filter(|r| r.converged_psi().is_some())
            .and_then(|r| r.stress)
            .and_then(|s| s[k])
            .map_or(f64::NAN, |d| d * sigma)
    }

    /// The records present in `range`.
    fn in_range(&self, range: std::ops::Range<usize>) -> Vec<&'a Record> {
        range.filter_map(|i| self.records[i]).collect::<Vec<_>>()
    }
}

/// Strain scales σ_k = max |z_k| over the plan's samples (1 for a strain the plan never varies).
pub(super) fn strain_scales(samples: &[Sample]) -> [f64; 5] {
    let mut sigma = [0.0f64; 5];
    for s in samples {
        for k in 0..5 {
            sigma[k] = sigma[k].max(s.z[k].abs());
        }
    }
    for v in &mut sigma {
        if *v == 0.0 {
            *v = 1.0;
        }
    }
    sigma
}

/// FIT1D's options for strain `k`: symmetrised for s_a, minimum at 0 in-plane and at argmin p for bending.
pub(super) fn options_1d(k: usize, opts: &FitOptions) -> Fit1DOptions {
    Fit1DOptions {
        n_knots: opts.n_knots_1d,
        extent: opts.extent_1d,
        bandwidth_factor: opts.bandwidth_factor,
        eps_rel: opts.eps_rel,
        min_slope: opts.min_slope,
        symmetric: k == 1 && opts.symmetric_shear,
        minimum: if k < 3 {
            MinimumAt::Zero
        } else {
            MinimumAt::Argmin
        },
        fd_step: opts.fd_step,
        slopes: opts.slopes,
    }
}

/// The plan indices of the samples the 1D term of strain `k` is fitted to: every `thin_1d`-th of its range.
pub(super) fn term_indices_1d(plan: &Plan, k: usize, opts: &FitOptions) -> Vec<usize> {
    let range = plan.range_1d(k);
    range
        .clone()
        .filter(|i| (i - range.start).is_multiple_of(opts.thin_1d.max(1)))
        .collect()
}

/// The name of the 1D term of strain `k` in errors and kink reports.
pub(super) fn term_name_1d(k: usize) -> String {
    format!("1D term {} ({})", k, StrainComponent::NAMES[k])
}

/// The name of the 2D term (k0, k1) in errors and kink reports.
pub(super) fn term_name_2d(k0: usize, k1: usize) -> String {
    format!(
        "2D term ({}, {})",
        StrainComponent::NAMES[k0],
        StrainComponent::NAMES[k1]
    )
}

/// The 1D terms f_k: FIT1D on every `thin_1d`-th sample of each strain's 1D range.
fn fit_terms1d(
    plan: &Plan,
    samples: &[Sample],
    by_index: &ByIndex,
    sigma: [f64; 5],
    opts: &FitOptions,
) -> Result<Vec<(usize, Fit1D, TermData)>, FitError> {
    let mut fits1d = Vec::new();
    for k in 0..5 {
        let idx = term_indices_1d(plan, k, opts);
        let x: Vec<f64> = idx.iter().map(|&i| samples[i].z[k] / sigma[k]).collect();
        let psi: Vec<f64> = idx.iter().map(|&i| by_index.psi(i)).collect();
        let stress: Vec<f64> = idx
            .iter()
            .map(|&i| by_index.stress(i, k, sigma[k]))
            .collect();
        let o = options_1d(k, opts);
        let fit = fit1d_with_stress(&x, &psi, Some(&stress), &o).map_err(|e| FitError::Term {
            term: term_name_1d(k),
            source: Box::new(e),
        })?;
        fits1d.push((k, fit, TermData { x, y: vec![], psi }));
    }
    Ok(fits1d)
}

/// The constant f₀ and the strain of the sample it was taken from: Ψ̄ of the converged sample nearest z = 0 in
/// normalised units, among the s_a range's samples when any of them converged (Ψ̄ is even in s_a, so its error is
/// second order), else among all.
pub(super) fn constant_term(
    plan: &Plan,
    present: &[&Record],
    sigma: [f64; 5],
) -> Result<(f64, [f64; 5], usize), FitError> {
    let sa_range = plan.range_1d(1);
    let on_sa = present
        .iter()
        .any(|r| sa_range.contains(&r.index) && r.converged_psi().is_some());
    let nearest = present
        .iter()
        .filter(|r| r.converged_psi().is_some() && (!on_sa || sa_range.contains(&r.index)))
        .map(|r| {
            let d: f64 = (0..5).map(|k| (r.z[k] / sigma[k]).powi(2)).sum();
            (d, *r)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or(FitError::TooFewSamples {
            usable: 0,
            needed: 1,
        })?;
    Ok((
        nearest.1.converged_psi().unwrap_or(0.0),
        nearest.1.z,
        nearest.1.index,
    ))
}

/// FIT2D's options for the pair (k0, k1), k0 < k1: (s_x, s_y) neither quasi-convexified nor zero-compressed, a
/// stretch axis zero-compressed, an s_a axis symmetrised, a bending axis with its minimum at argmin and the
/// bending pairs' knot count and extent.
pub(super) fn options_2d(k0: usize, k1: usize, opts: &FitOptions) -> Fit2DOptions {
    let stretch = |k: usize| k == 0 || k == 2;
    let bending = k1 >= 3;
    Fit2DOptions {
        n_knots: [if bending {
            opts.n_knots_2d_bending
        } else {
            opts.n_knots_2d
        }; 2],
        extent: if bending {
            opts.extent_2d_bending
        } else {
            opts.extent_2d
        },
        bandwidth_factor: opts.bandwidth_factor,
        eps_rel: opts.eps_rel,
        min_slope: opts.min_slope,
        symmetric: [
            k0 == 1 && opts.symmetric_shear,
            k1 == 1 && opts.symmetric_shear,
        ],
        quasi_convex: !(k0 == 0 && k1 == 2),
        minimum_v: if k1 < 3 {
            MinimumAt::Zero
        } else {
            MinimumAt::Argmin
        },
        stretch: [stretch(k0), stretch(k1)],
        fd_step: opts.fd_step,
        strict_patches: opts.strict_patches,
        compression_residual: opts.compression_residual,
    }
}

/// The 2D terms f_kl: FIT2D on each pair's grid, the pair's strains ordered k < l.
fn fit_terms2d(
    plan: &Plan,
    samples: &[Sample],
    by_index: &ByIndex,
    sigma: [f64; 5],
    opts: &FitOptions,
) -> Result<Vec<(usize, usize, Fit2D, TermData)>, FitError> {
    let mut fits2d = Vec::new();
    for (p, [a, b]) in plan.pairs.iter().enumerate() {
        let (ka, kb) = (a.index(), b.index());
        let (k0, k1) = (ka.min(kb), ka.max(kb));
        let idx: Vec<usize> = plan.range_2d(p).collect();
        let x: Vec<f64> = idx.iter().map(|&i| samples[i].z[k0] / sigma[k0]).collect();
        let y: Vec<f64> = idx.iter().map(|&i| samples[i].z[k1] / sigma[k1]).collect();
        let psi: Vec<f64> = idx.iter().map(|&i| by_index.psi(i)).collect();
        let o = options_2d(k0, k1, opts);
        let fit = fit2d(&x, &y, &psi, &o).map_err(|e| FitError::Term {
            term: term_name_2d(k0, k1),
            source: Box::new(e),
        })?;
        fits2d.push((k0, k1, fit, TermData { x, y, psi }));
    }
    Ok(fits2d)
}

/// The material of the fitted terms (the 1D splines and the 2D residuals), without extra keys.
fn assemble(
    density: f64,
    sigma: [f64; 5],
    constant: f64,
    fits1d: &[(usize, Fit1D, TermData)],
    fits2d: &[(usize, usize, Fit2D, TermData)],
) -> Material {
    Material {
        density,
        strain_scale: sigma,
        constant,
        terms1d: fits1d
            .iter()
            .map(|(k, f, _)| Term1D {
                strain: StrainComponent::ALL[*k],
                spline: f.spline.clone(),
            })
            .collect(),
        terms2d: fits2d
            .iter()
            .map(|(k0, k1, f, _)| Term2D {
                strains: [StrainComponent::ALL[*k0], StrainComponent::ALL[*k1]],
                spline: f.residual.clone(),
            })
            .collect(),
        extra: serde_json::Map::new(),
    }
}

/// The per-term reports: each fit's own quality and the whole model's errors on the term's samples.
fn term_reports(
    material: &Material,
    plan: &Plan,
    by_index: &ByIndex,
    fits1d: &[(usize, Fit1D, TermData)],
    fits2d: &[(usize, usize, Fit2D, TermData)],
) -> (Vec<Term1DReport>, Vec<Term2DReport>) {
    let terms1d: Vec<Term1DReport> = fits1d
        .iter()
        .map(|(k, f, _)| Term1DReport {
            k: *k,
            strain: StrainComponent::ALL[*k],
            n_samples: f.report.n_samples,
            n_excluded: f.report.n_excluded,
            fit_rms_rel: f.report.rms_rel,
            fit_max_rel: f.report.max_rel,
            offset: f.offset,
            i_min: f.report.i_min,
            model: model_error(material, by_index.in_range(plan.range_1d(*k))),
        })
        .collect();
    let terms2d: Vec<Term2DReport> = fits2d
        .iter()
        .enumerate()
        .map(|(p, (k0, k1, f, _))| Term2DReport {
            k0: *k0,
            k1: *k1,
            strains: [StrainComponent::ALL[*k0], StrainComponent::ALL[*k1]],
            n_samples: f.report.n_samples,
            n_excluded: f.report.n_excluded,
            fit_rms_rel: f.report.rms_rel,
            fit_max_rel: f.report.max_rel,
            twist_rounds: f.report.twist_rounds,
            slope_rounds: f.report.slope_rounds,
            nonmonotone_patches: f.report.nonmonotone_patches,
            compression_nonmonotone: f.report.compression_nonmonotone,
            model: model_error(material, by_index.in_range(plan.range_2d(p))),
        })
        .collect();
    (terms1d, terms2d)
}

impl FitReport {
    /// [`FitError::NotFinite`] naming the first non-finite number among the constant f₀, the fit and model errors
    /// of every term, of all samples and of the held-out samples: never a NaN in a report of a successful fit.
    pub fn check_finite(&self) -> Result<(), FitError> {
        if !self.constant.is_finite() {
            return Err(FitError::NotFinite("the constant f₀".into()));
        }
        for t in &self.terms1d {
            let what = format!("1D term {}", t.strain.name());
            if !(t.fit_rms_rel.is_finite() && t.fit_max_rel.is_finite()) {
                return Err(FitError::NotFinite(format!("{what}: its fit error")));
            }
            t.model.check_finite(&format!("{what}: model"))?;
        }
        for t in &self.terms2d {
            let what = format!("2D term ({}, {})", t.strains[0].name(), t.strains[1].name());
            if !(t.fit_rms_rel.is_finite() && t.fit_max_rel.is_finite()) {
                return Err(FitError::NotFinite(format!("{what}: its fit error")));
            }
            t.model.check_finite(&format!("{what}: model"))?;
        }
        self.all.check_finite("all samples: model")?;
        if let Some(h) = &self.holdout {
            h.check_finite("held-out samples: model")?;
        }
        Ok(())
    }
}

/// The material's `meta` block: `meta` completed with the plan hash, the fit options and the fit errors.
fn meta_block(
    mut meta: serde_json::Map<String, serde_json::Value>,
    opts: &FitOptions,
    report: &FitReport,
) -> serde_json::Map<String, serde_json::Value> {
    meta.insert("plan".into(), serde_json::json!(report.plan_hash));
    // every option, by the names of `FitOptions`, so that the material can be refitted as it was made
    meta.insert(
        "fit options".into(),
        serde_json::to_value(opts).expect("fit options serialise"),
    );
    meta.insert(
        "fit errors".into(),
        serde_json::json!({
            "samples": report.samples, "converged": report.converged,
            "model_rms_rel": report.all.rms_rel, "model_max_rel": report.all.max_rel,
            "constant_spread": report.constant_spread,
            "holdout": report.holdout.as_ref().map(|h| serde_json::json!({
                "samples": h.n_samples, "rms_rel": h.rms_rel, "max_rel": h.max_rel })),
            "1D": report.terms1d.iter().map(|t| serde_json::json!({
                "strain": t.strain, "rms_rel": t.model.rms_rel, "max_rel": t.model.max_rel,
                "excluded": t.n_excluded })).collect::<Vec<_>>(),
            "2D": report.terms2d.iter().map(|t| serde_json::json!({
                "strains": t.strains, "rms_rel": t.model.rms_rel, "max_rel": t.model.max_rel,
                "excluded": t.n_excluded, "nonmonotone_patches": t.nonmonotone_patches })).collect::<Vec<_>>(),
        }),
    );
    meta
}

/// Fit a material (Algorithm C5) to the records of `plan` (other records are ignored; a record whose id does not
/// carry the plan's hash is an error, as is a plan without 1D ranges). `density` is ρ_A (kg/m²); `meta` goes into
/// the material's `meta` block, completed with the plan hash, the options and the fit errors.
///
/// # Example
///
/// Synthetic records whose Ψ̄ and stresses are the default material's ψ and ∇ψ on a plan of 1D ranges only (15
/// samples each): the fit gives back that material along each range to a few percent.
///
/// ```
/// use hylc::fit::model::strain6;
/// use hylc::fit::{fit_material, FitOptions};
/// use hylc::material::synthetic::default_material;
/// use hylc::sample::{Plan, Record, SampleStart, SampleStatus};
///
/// let truth = default_material();
/// let plan = Plan { count_1d: 15, count_2d: 0, pairs: vec![], ..Plan::default() };
/// let records: Vec<Record> = plan
///     .samples()
///     .into_iter()
///     .map(|s| {
///         let e = truth.eval(&strain6(&s.z));
///         let g = e.grad;
///         Record {
///             id: s.id,
///             index: s.index,
///             z: s.z,
///             psi: Some(e.value),
///             stress: Some([Some(g[0]), Some(g[1]), Some(g[2]), Some(g[3]), Some(g[5])]),
///             status: SampleStatus::Converged,
///             error: None,
///             steps: 1,
///             gradient_norm: Some(0.0),
///             time: 0.0,
///             start: SampleStart::Cold,
///             problem: "0000000000000000".into(),
///             starts: vec![],
///             kept: None,
///             crossings: None,
///             dpsi_dtheta: None,
///             dstress_dtheta: None,
///         }
///     })
///     .collect();
///
/// let fit = fit_material(&plan, &records, 0.25, Default::default(), &FitOptions::covering())?;
/// assert_eq!(fit.report.converged, plan.len());
/// assert_eq!(fit.material.terms1d.len(), 5);
/// for t in &fit.report.terms1d {
///     assert!(t.model.rms_rel < 0.05, "{:?}: {}", t.strain, t.model.rms_rel);
/// }
/// # Ok::<(), hylc::fit::FitError>(())
/// ```
pub fn fit_material(
    plan: &Plan,
    records: &[Record],
    density: f64,
    meta: serde_json::Map<String, serde_json::Value>,
    opts: &FitOptions,
) -> Result<MaterialFit, FitError> {
    let hash = format!("{:016x}", plan.hash());
    if let Some(k) = (0..5).find(|&k| plan.n_1d(k) < 3) {
        return Err(FitError::BadOption(format!(
            "the plan has {} samples on the 1D range of {}; fitting needs at least 3",
            plan.n_1d(k),
            StrainComponent::NAMES[k]
        )));
    }
    let n = plan.len();
    let by_index = ByIndex::new(plan, records, &hash)?;
    let present = by_index.present();
    check_records(records)?;
    let converged = present
        .iter()
        .filter(|r| r.converged_psi().is_some())
        .count();
    let samples = plan.samples();
    let sigma = strain_scales(&samples);

    let fits1d = fit_terms1d(plan, &samples, &by_index, sigma, opts)?;
    let (constant, constant_at, _) = constant_term(plan, &present, sigma)?;
    let spread = fits1d[..3]
        .iter()
        .map(|(_, f, _)| (f.offset - constant).abs())
        .fold(0.0f64, f64::max);
    let fits2d = fit_terms2d(plan, &samples, &by_index, sigma, opts)?;
    let mut material = assemble(density, sigma, constant, &fits1d, &fits2d);

    let (terms1d, terms2d) = term_reports(&material, plan, &by_index, &fits1d, &fits2d);
    let all = model_error(&material, by_index.in_range(0..plan.grid_start()));
    // the plan's own in-plane grid is held out: never fitted, only predicted
    let holdout = plan
        .grid
        .as_ref()
        .map(|_| model_error(&material, by_index.in_range(plan.grid_start()..n)));
    let report = FitReport {
        plan_hash: hash,
        samples: present.len(),
        converged,
        strain_scale: sigma,
        constant,
        constant_at,
        constant_spread: spread,
        terms1d,
        terms2d,
        all,
        holdout,
        compare_1d: None,
    };

    report.check_finite()?;
    let meta = meta_block(meta, opts, &report);
    material.extra.insert(
        "strain shift".into(),
        serde_json::json!([1.0, 0.0, 1.0, 0.0, 0.0]),
    );
    material
        .extra
        .insert("meta".into(), serde_json::Value::Object(meta));
    Ok(MaterialFit {
        material,
        report,
        fits1d,
        fits2d,
    })
}

/// One 1D range compared with another material (validation item 3d).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RangeComparison {
    /// index k of the strain in z
    pub k: usize,
    /// the strain component
    pub strain: StrainComponent,
    /// points compared (the plan's values of the range inside the other material's sampled range)
    pub n_points: usize,
    /// the compared interval of strain k
    pub interval: [f64; 2],
    /// our fitted f₀ + f_k against the other material's f₀ + f_k: RMS of the difference over RMS of theirs
    pub fit_rms_rel: f64,
    /// our converged samples Ψ̄ against the other material's f₀ + f_k (same normalisation)
    pub samples_rms_rel: f64,
    /// the terms alone, f_k against theirs (each material's f₀ removed): the shape of the response without the
    /// energy of the zero-strain state
    pub term_rms_rel: f64,
    /// the least-squares factor c minimising ‖c (f₀ + f_k)_ours − (f₀ + f_k)_theirs‖ on this range
    pub scale: f64,
    /// the fit error after multiplying ours by the common factor of all ranges ([`Comparison1D::common_scale`])
    pub scaled_fit_rms_rel: f64,
    /// our f₀ + f_k and theirs at the two ends of the interval
    pub ends: [[f64; 2]; 2],
}

/// The 1D comparison of two materials.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Comparison1D {
    /// the compared 1D ranges, one per strain the plan varies
    pub ranges: Vec<RangeComparison>,
    /// One factor c for all ranges, minimising Σ_k ‖c ours_k − theirs_k‖² / ‖theirs_k‖². Ψ̄ is exactly
    /// proportional to a common factor on all yarn stiffnesses (Y, G, k_c: the equilibria do not change), so c
    /// estimates the ratio of the other material's stiffness scale to ours, which the equilibrium calibration
    /// cannot see.
    pub common_scale: f64,
}

/// Compare the 1D curves f₀ + f_k of a fitted material with another material's (the original's) along the
/// plan's 1D ranges, restricted to the other material's sampled range (its knot span / 0.95, times its strain
/// scale). `records` supply our own Ψ̄ at the same strains.
pub fn compare_1d(
    fit: &MaterialFit,
    plan: &Plan,
    records: &[Record],
    other: &Material,
) -> Comparison1D {
    let samples = plan.samples();
    let mut psi = vec![None; plan.len()];
    for r in records {
        if r.index < psi.len() {
            psi[r.index] = r.converged_psi();
        }
    }
    let rel = |num: f64, den: f64| (num / den.max(1e-300)).sqrt();
    let mut out = Vec::new();
    let mut values: Vec<Vec<(f64, f64)>> = Vec::new();
    for k in 0..5 {
        let Some(term) = other.terms1d.iter().find(|t| t.strain.index() == k) else {
            continue;
        };
        let t = &term.spline.t;
        let sig = other.strain_scale[k];
        let interval = [t[0] / 0.95 * sig, t[t.len() - 1] / 0.95 * sig];
        let (mut s2, mut so2, mut t2, mut to2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut pts = Vec::new();
        for i in plan.range_1d(k) {
            let z = samples[i].z;
            if z[k] < interval[0] - 1e-12 || z[k] > interval[1] + 1e-12 {
                continue;
            }
            let z6 = strain6(&z);
            let (ours, theirs) = (fit.material.value(&z6), other.value(&z6));
            pts.push((ours, theirs));
            let (fo, ft) = (ours - fit.material.constant, theirs - other.constant);
            t2 += (fo - ft).powi(2);
            to2 += ft * ft;
            if let Some(p) = psi[i].filter(|v| v.is_finite()) {
                s2 += (p - theirs).powi(2);
                so2 += theirs * theirs;
            }
        }
        let d2: f64 = pts.iter().map(|(o, t)| (o - t).powi(2)).sum();
        let o2: f64 = pts.iter().map(|(_, t)| t * t).sum();
        let ot: f64 = pts.iter().map(|(o, t)| o * t).sum();
        let oo: f64 = pts.iter().map(|(o, _)| o * o).sum();
        out.push(RangeComparison {
            k,
            strain: StrainComponent::ALL[k],
            n_points: pts.len(),
            interval,
            fit_rms_rel: rel(d2, o2),
            samples_rms_rel: rel(s2, so2),
            term_rms_rel: rel(t2, to2),
            scale: ot / oo.max(1e-300),
            scaled_fit_rms_rel: f64::NAN,
            ends: match (pts.first(), pts.last()) {
                (Some(a), Some(b)) => [[a.0, a.1], [b.0, b.1]],
                _ => [[f64::NAN; 2]; 2],
            },
        });
        values.push(pts);
    }
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for pts in &values {
        let o2: f64 = pts.iter().map(|(_, t)| t * t).sum::<f64>().max(1e-300);
        num += pts.iter().map(|(o, t)| o * t).sum::<f64>() / o2;
        den += pts.iter().map(|(o, _)| o * o).sum::<f64>() / o2;
    }
    let c = num / den.max(1e-300);
    for (r, pts) in out.iter_mut().zip(&values) {
        let d2: f64 = pts.iter().map(|(o, t)| (c * o - t).powi(2)).sum();
        let o2: f64 = pts.iter().map(|(_, t)| t * t).sum();
        r.scaled_fit_rms_rel = rel(d2, o2);
    }
    Comparison1D {
        ranges: out,
        common_scale: c,
    }
}
