//! The directional derivative of the whole fit (`docs/sensitivities.md`, "The tangent of the fit"): c = F(Ψ̄, σ)
//! maps the samples' values Ψ̄ᵢ (and their stresses σᵢ where the slopes come from them) to the material's
//! coefficients c; [`fit_material_tangent`] returns ċ = ∂F/∂(Ψ̄, σ) · (Ψ̄̇, σ̇) for given tangents, exact for the
//! branch the fit took.
//!
//! The fit is [`fit_material`] itself, then one pass of the same numerical core (FIT1D, FIT2D and the constant
//! f₀) per tangent on [`Dual64`] numbers seeded with Ψ̄ᵢ + Ψ̄̇ᵢ ε. What depends on the strains only (strain scales,
//! knots, MLS weights, the sample nearest z = 0 for f₀) is the same in both, and every decision on values (the
//! argmax of ε, the argmin of a minimum knot, the branches of max/min, the Fritsch–Carlson tests, the patch
//! certificates and their repair rounds) is taken on the real parts, which equal the `f64` fit's bit for bit
//! (checked: a pass whose real parts differ is an error). So ċ is the derivative of the active branch, and the
//! [`KinkReport`] lists the decisions within a relative 1e-9 of switching, where the derivative is one-sided.

use super::fit1d::fit1d_core;
use super::fit2d::fit2d_core;
use super::model::{
    constant_term, fit_material, options_1d, options_2d, strain_scales, term_indices_1d,
    term_name_1d, term_name_2d, ByIndex, FitOptions, MaterialFit,
};
use super::scalar::{FitScalar, KinkReport, Kinks};
use super::FitError;
use crate::material::coefficients::MaterialGradient;
use crate::sample::{Plan, Record};
use num_dual::Dual64;

/// The tangent of one record's values: Ψ̄̇ and, per strain, σ̇ = ∂Ψ̄̇/∂z_k (J/m² per unit strain, the record's
/// own units; `None` where the record has no stress or its tangent is 0). Used only where the fit uses the value:
/// Ψ̄̇ of a converged record, σ̇ when the slopes come from the stresses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RecordTangent {
    /// Ψ̄̇, the tangent of Ψ̄ (J/m²)
    pub psi: f64,
    /// σ̇ per strain component (`None` where the record has no stress)
    pub stress: Option<[Option<f64>; 5]>,
}

/// [`fit_material`] and its directional derivative along `tangents` (one per record, in the order of `records`):
/// the fit, ċ in the material's layout ([`MaterialGradient`], one number per coefficient) and the kinks of the
/// pass. Errors: those of [`fit_material`], a tangent count different from the record count, a non-finite
/// tangent, and [`FitError::Branch`] should the pass's real parts leave the fit's branch.
pub fn fit_material_tangent(
    plan: &Plan,
    records: &[Record],
    density: f64,
    meta: serde_json::Map<String, serde_json::Value>,
    opts: &FitOptions,
    tangents: &[RecordTangent],
) -> Result<(MaterialFit, MaterialGradient, KinkReport), FitError> {
    let (fit, mut grads, kinks) = fit_material_tangents(
        plan,
        records,
        density,
        meta,
        opts,
        std::slice::from_ref(&tangents.to_vec()),
    )?;
    let g = grads.pop().expect("one tangent, one gradient");
    Ok((fit, g, kinks))
}

/// [`fit_material_tangent`] for several tangent directions (one pass each, the fit made once): the fit, one ċ
/// per direction, and the kinks of all passes (each decision listed once).
pub fn fit_material_tangents(
    plan: &Plan,
    records: &[Record],
    density: f64,
    meta: serde_json::Map<String, serde_json::Value>,
    opts: &FitOptions,
    tangents: &[Vec<RecordTangent>],
) -> Result<(MaterialFit, Vec<MaterialGradient>, KinkReport), FitError> {
    for t in tangents {
        check_tangents(records, t)?;
    }
    let fit = fit_material(plan, records, density, meta, opts)?;
    let mut report = KinkReport::default();
    let mut grads = Vec::with_capacity(tangents.len());
    for t in tangents {
        let (g, k) = tangent_pass(plan, records, opts, t, &fit)?;
        grads.push(g);
        report.merge(k);
    }
    Ok((fit, grads, report))
}

/// One tangent per record, every component finite.
fn check_tangents(records: &[Record], tangents: &[RecordTangent]) -> Result<(), FitError> {
    if tangents.len() != records.len() {
        return Err(FitError::BadOption(format!(
            "{} tangents for {} records (need one per record)",
            tangents.len(),
            records.len()
        )));
    }
    for (r, t) in records.iter().zip(tangents) {
        let stress = t.stress.iter().flatten().flatten();
        if !t.psi.is_finite() || stress.clone().any(|v| !v.is_finite()) {
            return Err(FitError::BadRecord {
                id: r.id.clone(),
                field: "tangent".into(),
                message: format!("not finite: {t:?}"),
            });
        }
    }
    Ok(())
}

/// The dual values of the plan's samples: Ψ̄ᵢ + Ψ̄̇ᵢ ε (NaN for failed or missing samples, as in the fit) and
/// the stresses in normalised units, σᵢ σ_k + σ̇ᵢ σ_k ε.
struct DualSamples<'a> {
    by_index: ByIndex<'a>,
    /// per plan index, the tangent of the record the fit uses
    tangent: Vec<Option<&'a RecordTangent>>,
}

impl<'a> DualSamples<'a> {
    fn new(
        plan: &Plan,
        records: &'a [Record],
        tangents: &'a [RecordTangent],
    ) -> Result<Self, FitError> {
        let hash = format!("{:016x}", plan.hash());
        let by_index = ByIndex::new(plan, records, &hash)?;
        // later duplicates replace earlier ones, as in ByIndex
        let mut tangent = vec![None; plan.len()];
        for (r, t) in records.iter().zip(tangents) {
            if r.index < tangent.len() {
                tangent[r.index] = Some(t);
            }
        }
        Ok(DualSamples { by_index, tangent })
    }

    fn psi(&self, i: usize) -> Dual64 {
        Dual64::new(self.by_index.psi(i), self.tangent[i].map_or(0.0, |t| t.psi))
    }

    fn stress(&self, i: usize, k: usize, sigma: f64) -> Dual64 {
        let d = self.tangent[i]
            .and_then(|t| t.stress)
            .and_then(|s| s[k])
            .unwrap_or(0.0);
        Dual64::new(self.by_index.stress(i, k, sigma), d * sigma)
    }
}

/// One dual pass: ċ and the kinks, checking that the real parts are the fit's coefficients.
fn tangent_pass(
    plan: &Plan,
    records: &[Record],
    opts: &FitOptions,
    tangents: &[RecordTangent],
    fit: &MaterialFit,
) -> Result<(MaterialGradient, KinkReport), FitError> {
    let ds = DualSamples::new(plan, records, tangents)?;
    let samples = plan.samples();
    let sigma = strain_scales(&samples);
    let material = &fit.material;
    let mut grad = MaterialGradient::zeros(material);
    let mut report = KinkReport::default();
    let mut branch = Branch::default();

    let present = ds.by_index.present();
    let (constant, _, at) = constant_term(plan, &present, sigma)?;
    branch.check("the constant f₀", constant, material.constant);
    grad.constant = ds.tangent[at].map_or(0.0, |t| t.psi);

    for (term, k) in (0..5).enumerate() {
        let idx = term_indices_1d(plan, k, opts);
        let x: Vec<f64> = idx.iter().map(|&i| samples[i].z[k] / sigma[k]).collect();
        let psi: Vec<Dual64> = idx.iter().map(|&i| ds.psi(i)).collect();
        let stress: Vec<Dual64> = idx.iter().map(|&i| ds.stress(i, k, sigma[k])).collect();
        let name = term_name_1d(k);
        let mut kinks = Kinks::on(&name);
        let core = fit1d_core(&x, &psi, Some(&stress), &options_1d(k, opts), &mut kinks)
            .map_err(|e| term_error(&name, e))?;
        let sp = &material.terms1d[term].spline;
        branch.check_all(&name, &core.p, &sp.p);
        branch.check_all(&name, &core.m, &sp.m);
        grad.terms1d[term] = [tangents_of(&core.p), tangents_of(&core.m)];
        report.kinks.append(&mut kinks.found);
    }

    for (term, [a, b]) in plan.pairs.iter().enumerate() {
        let (ka, kb) = (a.index(), b.index());
        let (k0, k1) = (ka.min(kb), ka.max(kb));
        let idx: Vec<usize> = plan.range_2d(term).collect();
        let x: Vec<f64> = idx.iter().map(|&i| samples[i].z[k0] / sigma[k0]).collect();
        let y: Vec<f64> = idx.iter().map(|&i| samples[i].z[k1] / sigma[k1]).collect();
        let psi: Vec<Dual64> = idx.iter().map(|&i| ds.psi(i)).collect();
        let name = term_name_2d(k0, k1);
        let mut kinks = Kinks::on(&name);
        let core = fit2d_core(&x, &y, &psi, &options_2d(k0, k1, opts), &mut kinks)
            .map_err(|e| term_error(&name, e))?;
        let r = &core.residual;
        let sp = &material.terms2d[term].spline;
        for (dual, fitted) in [
            (&r.p, &sp.p),
            (&r.mu, &sp.mu),
            (&r.mv, &sp.mv),
            (&r.muv, &sp.muv),
        ] {
            branch.check_all(&name, dual, fitted);
        }
        grad.terms2d[term] = [&r.p, &r.mu, &r.mv, &r.muv].map(|a| tangents_of(a));
        report.kinks.append(&mut kinks.found);
    }
    branch.result()?;
    Ok((grad, report))
}

fn term_error(term: &str, e: FitError) -> FitError {
    FitError::Term {
        term: term.to_string(),
        source: Box::new(e),
    }
}

fn tangents_of(a: &[Dual64]) -> Vec<f64> {
    a.iter().map(|v| v.eps).collect()
}

/// The first coefficient whose real part in the dual pass differs from the fit's.
#[derive(Default)]
struct Branch {
    first: Option<String>,
}

impl Branch {
    fn check(&mut self, what: &str, dual: f64, fitted: f64) {
        if self.first.is_none() && dual != fitted {
            self.first = Some(format!("{what}: {dual:e} against the fit's {fitted:e}"));
        }
    }

    fn check_all<T: FitScalar>(&mut self, what: &str, dual: &[T], fitted: &[f64]) {
        for (i, (d, f)) in dual.iter().zip(fitted).enumerate() {
            self.check(&format!("{what}, coefficient {i}"), d.value(), *f);
        }
    }

    fn result(self) -> Result<(), FitError> {
        self.first.map_or(Ok(()), |s| Err(FitError::Branch(s)))
    }
}
