//! The validation numbers of an identified parameter set (docs/yarn-parameters.md): the full 9×9×9 grid against
//! the original's displacements (RMS / max position error, per axis value) and the original material's five 1D
//! curves against our Ψ̄ (relative RMS over the original's range, no free factor).

use super::residuals::curve_values;
use super::IdentifyError;
use crate::fit::model::strain6;
use crate::material::Material;
use crate::micro::{MacroStrain, MicroProblem, SolverOptions};
use crate::pattern::Pattern;
use crate::rod::YarnMaterial;
use crate::strain::StrainComponent;
use crate::validation::grid::{run_grid, summarize, GridData, GridOptions, GridSummary, AXIS_LEN};
use serde::Serialize;

/// One 1D curve: strains, the original's ψ, our Ψ̄, and the relative RMS error.
#[derive(Clone, Debug, Serialize)]
pub struct CurveComparison {
    /// The strain component along which the curve runs.
    pub component: &'static str,
    /// The strains of the points.
    pub strains: Vec<f64>,
    /// The original material's ψ at the points (J/m²).
    pub original: Vec<f64>,
    /// Our Ψ̄ at the points (J/m²; NaN where the solve failed).
    pub ours: Vec<f64>,
    /// ‖Ψ̄ − ψ‖ / ‖ψ‖ over the points (RMS ratio).
    pub rel_rms: f64,
}

/// The original material's sampled range of component k (its knot span / 0.95 times its strain scale, as the
/// fit report compares), `None` when it has no 1D term k.
pub fn original_interval(material: &Material, k: usize) -> Option<[f64; 2]> {
    let term = material.terms1d.iter().find(|t| t.strain.index() == k)?;
    let t = &term.spline.t;
    let sig = material.strain_scale[k];
    Some([t[0] / 0.95 * sig, t[t.len() - 1] / 0.95 * sig])
}

/// `count` strains along component k, evenly over the original's range, and the original's ψ there; strains our
/// solver cannot take (outside the admissible set for the pattern's radius) are left out.
pub fn curve_points(
    material: &Material,
    k: usize,
    count: usize,
    radius: f64,
) -> Vec<(MacroStrain, f64)> {
    let Some([lo, hi]) = original_interval(material, k) else {
        return vec![];
    };
    (0..count)
        .filter_map(|i| {
            let s = lo + (hi - lo) * i as f64 / (count.max(2) - 1) as f64;
            let mut z = [0.0; 5];
            z[k] = s;
            let strain = MacroStrain(z);
            strain.validate_for_radius(radius).ok()?;
            Some((strain, material.value(&strain6(&z))))
        })
        .collect()
}

/// Our Ψ̄ along the original's 1D range of component k, against the original's ψ.
pub fn compare_curve(
    problem: &MicroProblem,
    original: &Material,
    k: usize,
    count: usize,
) -> Result<Option<CurveComparison>, IdentifyError> {
    let pts = curve_points(original, k, count, problem.pattern.radius);
    if pts.is_empty() {
        return Ok(None);
    }
    let strains: Vec<MacroStrain> = pts.iter().map(|p| p.0).collect();
    let mut warm = Vec::new();
    let ours: Vec<f64> = curve_values(problem, &strains, &mut warm, false)?
        .into_iter()
        .map(|v| v.0)
        .collect();
    let theirs: Vec<f64> = pts.iter().map(|p| p.1).collect();
    let d2: f64 = ours.iter().zip(&theirs).map(|(a, b)| (a - b).powi(2)).sum();
    let o2: f64 = theirs.iter().map(|b| b * b).sum();
    Ok(Some(CurveComparison {
        component: StrainComponent::NAMES[k],
        strains: strains.iter().map(|z| z.0[k]).collect(),
        original: theirs,
        ours,
        rel_rms: (d2 / o2.max(1e-300)).sqrt(),
    }))
}

/// The item-5 numbers of one parameter set.
#[derive(Clone, Debug, Serialize)]
pub struct HeldOut {
    /// The yarn parameters.
    pub yarn: YarnMaterial,
    /// Full-grid position error RMS and max (r), None when the grid was not run.
    pub grid_rms: Option<f64>,
    /// Full-grid position error maximum (r).
    pub grid_max: Option<f64>,
    /// Grid points that converged.
    pub grid_converged: Option<usize>,
    /// RMS position error per axis value (rows s_x, s_a, s_y).
    pub grid_rms_by_axis: Option<[[f64; AXIS_LEN]; 3]>,
    /// The grid's axis values (rows s_x, s_a, s_y).
    pub axes: Option<[[f64; AXIS_LEN]; 3]>,
    /// The 1D curves against the original material.
    pub curves: Vec<CurveComparison>,
}

/// Run the full grid (when `grid` is given) and the five 1D curves (`curve_count` points each) at `yarn`.
pub fn held_out(
    pattern: &Pattern,
    yarn: &YarnMaterial,
    solver: &SolverOptions,
    grid: Option<&GridData>,
    original: &Material,
    curve_count: usize,
    progress: &(dyn Fn() + Sync),
) -> Result<HeldOut, IdentifyError> {
    let problem = MicroProblem::new(pattern.clone(), yarn, solver.clone());
    let summary: Option<GridSummary> = match grid {
        Some(data) => {
            let run = run_grid(&problem, data, &GridOptions::default(), progress)?;
            Some(summarize(&problem, data, &run))
        }
        None => None,
    };
    let mut curves = Vec::new();
    for k in 0..5 {
        if let Some(c) = compare_curve(&problem, original, k, curve_count)? {
            curves.push(c);
        }
    }
    Ok(HeldOut {
        yarn: problem.material.clone(),
        grid_rms: summary.as_ref().map(|s| s.position_error.rms),
        grid_max: summary.as_ref().map(|s| s.position_error.max),
        grid_converged: summary.as_ref().map(|s| s.converged),
        grid_rms_by_axis: summary.as_ref().map(|s| s.position_error_rms_by_axis),
        axes: grid.map(|d| d.axes),
        curves,
    })
}

/// What drives the fit along one 1D range (docs/yarn-parameters.md): θ ∂Ψ̄/∂θ (J/m² per unit ln θ) at each strain for
/// θ = Y, G, γ, k_c, f (envelope theorem at the equilibrium).
#[derive(Clone, Debug, Serialize)]
pub struct StudyCurve {
    /// The strain component along which the curve runs.
    pub component: &'static str,
    /// The strains of the points.
    pub strains: Vec<f64>,
    /// Ψ̄ at the points (J/m²).
    pub psi: Vec<f64>,
    /// Per parameter (Y, G, γ, k_c, f), one value per strain.
    pub dpsi_dlog: [Vec<f64>; 5],
}

/// Names of the parameters of [`StudyCurve::dpsi_dlog`].
pub const STUDY_PARAMETERS: [&str; 5] = ["Y", "G", "gamma", "k_c", "f"];

/// θ ∂Ψ̄/∂θ along the original's five 1D ranges (`count` points each) at `yarn`.
pub fn study(
    pattern: &Pattern,
    yarn: &YarnMaterial,
    solver: &SolverOptions,
    original: &Material,
    count: usize,
) -> Result<Vec<StudyCurve>, IdentifyError> {
    let problem = MicroProblem::new(pattern.clone(), yarn, solver.clone());
    let m = &problem.material;
    let scale = [
        m.young,
        m.shear,
        m.bend_twist_factor,
        m.contact_stiffness,
        m.contact_radius_factor,
    ];
    let mut out = Vec::new();
    for k in 0..5 {
        let pts = curve_points(original, k, count, pattern.radius);
        if pts.is_empty() {
            continue;
        }
        let strains: Vec<MacroStrain> = pts.iter().map(|p| p.0).collect();
        let mut warm = Vec::new();
        let vals = curve_values(&problem, &strains, &mut warm, true)?;
        out.push(StudyCurve {
            component: StrainComponent::NAMES[k],
            strains: strains.iter().map(|z| z.0[k]).collect(),
            psi: vals.iter().map(|v| v.0).collect(),
            dpsi_dlog: std::array::from_fn(|j| {
                vals.iter()
                    .map(|v| v.1.map_or(f64::NAN, |d| scale[j] * d[j]))
                    .collect()
            }),
        });
    }
    Ok(out)
}
