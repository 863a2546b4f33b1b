//! Identification of the yarn parameters from the original's data with the solver's own derivatives (docs/yarn-parameters.md,
//! "Identifying the yarn parameters").
//!
//! Unknowns q = (ln Y, ln γ, ln G/Y, ln k_c, ln f) (f the contact radius factor; each can be held fixed), on a
//! box of admissible values ([`BOUNDS`]): a trial step that leaves it is clamped to it, and the iteration says so.
//! Residuals ([`residuals`]): (a) the equilibrium residual at the stored state, (b) the original's displacement
//! fields at chosen grid points, (c) the original material's 1D curve at chosen strains; each switchable with a
//! weight. Note that (a) and (b) do not change when all stiffnesses scale together (an equilibrium is invariant
//! under E → s E): only (c) fixes the stiffness scale, and without it ln Y (or ln k_c) is held fixed.
//!
//! Levenberg–Marquardt: the step solves (JᵀJ + λ diag JᵀJ) δ = −Jᵀr on the free unknowns, scaled down to at most
//! `max_step` in every unknown (a trust region in ln θ: poorly determined directions otherwise ask for steps of
//! several decades that no solve survives); a step that lowers the
//! cost ½‖r‖² is accepted and λ shrinks ×10, otherwise (or when a solve does not converge) λ grows ×10 and the
//! step is retried (at most 12 times). Stops when the relative decrease of the cost is below `cost_tolerance`,
//! the largest step below `step_tolerance`, or after `max_iterations`. Standard errors from the covariance
//! σ² (JᵀJ)⁻¹ with σ² = ‖r‖²/(m − p) at the solution, and the correlations.

pub mod conventions;
pub mod held_out;
pub mod plot;
pub mod residuals;

use crate::contact::ContactError;
use crate::micro::{MacroStrain, MicroError, MicroProblem, SolverOptions, Status};
use crate::pattern::Pattern;
use crate::rod::YarnMaterial;
use crate::validation::grid::GridError;
use nalgebra::{DMatrix, DVector};
use residuals::{curve_residual, grid_residual, stored_state, CurveTarget, GridTarget, WarmStates};
use serde::Serialize;
use std::time::Instant;

/// Names of the unknowns q, in order.
pub const UNKNOWNS: [&str; 5] = ["ln Y", "ln gamma", "ln G/Y", "ln k_c", "ln f"];

/// Short names of the unknowns for `--fix` (`young`, `gamma`, `shear_ratio`, `contact`, `radius_factor`).
pub const UNKNOWN_KEYS: [&str; 5] = ["young", "gamma", "shear_ratio", "contact", "radius_factor"];

/// The admissible box of the unknowns: Y ∈ [1e2, 1e12] Pa, γ ∈ [1e-4, 10], G/Y ∈ [1e-3, 10],
/// k_c ∈ [1e-3, 1e7] J/m², f ∈ [0.5, 1.5].
pub const BOUNDS: [[f64; 2]; 5] = [
    [1e2, 1e12],
    [1e-4, 10.0],
    [1e-3, 10.0],
    [1e-3, 1e7],
    [0.5, 1.5],
];

/// Identification failed.
#[derive(Debug, thiserror::Error)]
pub enum IdentifyError {
    /// The original's micro grid could not be read.
    #[error(transparent)]
    Grid(#[from] GridError),
    /// A micro problem could not be set up or solved.
    #[error(transparent)]
    Micro(#[from] MicroError),
    /// The contact quadrature could not be set up.
    #[error("contact: {0}")]
    Contact(#[from] ContactError),
    /// A solve the residuals need did not converge.
    #[error("{what} at {strain}: the micro solve did not converge ({status})")]
    NotConverged {
        /// Which residual's solve (e.g. a grid point or curve strain).
        what: String,
        /// The macro strain of the solve.
        strain: MacroStrain,
        /// How the solve ended.
        status: Status,
    },
    /// Bad input: the argument or file at fault and why.
    #[error("{0}")]
    Input(String),
    /// A plot could not be drawn or written.
    #[error("{}: cannot draw the plot: {message}", path.display())]
    Plot {
        /// The plot file.
        path: std::path::PathBuf,
        /// The plotting library's message.
        message: String,
    },
}

/// The unknowns q of a yarn material.
pub fn unknowns_of(m: &YarnMaterial) -> [f64; 5] {
    [
        m.young.ln(),
        m.bend_twist_factor.ln(),
        (m.shear / m.young).ln(),
        m.contact_stiffness.ln(),
        m.contact_radius_factor.ln(),
    ]
}

/// The yarn material with unknowns q (every other field from `base`).
pub fn material_of(q: &[f64; 5], base: &YarnMaterial) -> YarnMaterial {
    YarnMaterial {
        young: q[0].exp(),
        bend_twist_factor: q[1].exp(),
        shear: (q[0] + q[2]).exp(),
        contact_stiffness: q[3].exp(),
        contact_radius_factor: q[4].exp(),
        ..base.clone()
    }
}

/// Clamp q into [`BOUNDS`]; the names of the clamped unknowns.
pub fn clamp(q: &mut [f64; 5]) -> Vec<&'static str> {
    let mut hit = Vec::new();
    for k in 0..5 {
        let (lo, hi) = (BOUNDS[k][0].ln(), BOUNDS[k][1].ln());
        if q[k] < lo || q[k] > hi {
            q[k] = q[k].clamp(lo, hi);
            hit.push(UNKNOWNS[k]);
        }
    }
    hit
}

/// Residual (a): the pattern whose stored state is compared (its periods may differ from the solves' pattern:
/// [`stored_state_pattern`]) and the weight.
pub struct StoredTarget {
    /// The pattern whose stored state (a) is compared.
    pub pattern: Pattern,
    /// Weight of residual (a).
    pub weight: f64,
}

/// The pattern of residual (a) as `hylc calibrate` takes it: the file's pattern, and where its stored periods
/// disagree with its periodic edges (basket), the periods at which the stored state is closest to an equilibrium
/// for the start parameters ([`crate::validation::calibration::equilibrium_periods`], kept fixed during the fit).
pub fn stored_state_pattern(
    mut file: Pattern,
    inconsistent: bool,
    start: &YarnMaterial,
) -> Result<Pattern, IdentifyError> {
    use crate::validation::calibration::{equilibrium_periods, ContactForm, Stiffness};
    if inconsistent {
        if let Some(implied) = file.implied_periods() {
            file.periods = implied;
            let form = ContactForm {
                quadrature: start.contact_quadrature,
                exclusion: start.contact_exclusion,
                radius_factor: start.contact_radius_factor,
            };
            file.periods = equilibrium_periods(&file, &form, &Stiffness::from_material(start))?;
        }
    }
    Ok(file)
}

/// The residual sets of one identification.
pub struct Residuals {
    /// (a), or `None` when off.
    pub stored: Option<StoredTarget>,
    /// (b)
    pub grid: Option<GridTarget>,
    /// (c)
    pub curve: Option<CurveTarget>,
}

/// Settings of [`identify`].
#[derive(Clone, Debug)]
pub struct IdentifyOptions {
    /// Which unknowns move (the others stay at the start value).
    pub free: [bool; 5],
    /// Levenberg–Marquardt iterations at most.
    pub max_iterations: usize,
    /// Stop when the relative decrease of the cost ½‖r‖² is below this.
    pub cost_tolerance: f64,
    /// Stop when the largest step of an unknown (in ln θ) is below this.
    pub step_tolerance: f64,
    /// Initial λ.
    pub lambda: f64,
    /// Largest change of any unknown in one step (a trust region in ln θ; a longer step is scaled down).
    pub max_step: f64,
    /// Options of the micro solves.
    pub solver: SolverOptions,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        IdentifyOptions {
            free: [true; 5],
            max_iterations: 30,
            cost_tolerance: 1e-6,
            step_tolerance: 1e-5,
            lambda: 1e-3,
            max_step: 0.5,
            solver: SolverOptions::default(),
        }
    }
}

/// The residuals' sizes at one parameter set.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Breakdown {
    /// ½‖r‖² (weighted).
    pub cost: f64,
    /// (a) ‖∇E‖ / ‖∇E_rods‖ at the stored state.
    pub stored_residual: Option<f64>,
    /// (b) RMS position error over the compared grid points and vertices (r).
    pub grid_rms: Option<f64>,
    /// (b) per compared point: (s_x, s_a, s_y) and its RMS position error (r).
    pub grid_points: Vec<([f64; 3], f64)>,
    /// (c) relative RMS error of Ψ̄ against the original's 1D curve.
    pub curve_rel_rms: Option<f64>,
}

/// Residual vector, Jacobian (m × 5) and breakdown at one parameter set.
pub struct Evaluation {
    /// The weighted residual vector r (m entries).
    pub residual: Vec<f64>,
    /// The Jacobian ∂r/∂q, one row of 5 per residual.
    pub jacobian: Vec<[f64; 5]>,
    /// The residuals' sizes.
    pub breakdown: Breakdown,
}

/// Evaluate every switched-on residual set at `material` (warm-starting from and updating `warm`).
pub fn evaluate(
    pattern: &Pattern,
    material: &YarnMaterial,
    sets: &Residuals,
    solver: &SolverOptions,
    warm: &mut WarmStates,
) -> Result<Evaluation, IdentifyError> {
    let mut residual = Vec::new();
    let mut jacobian = Vec::new();
    let mut b = Breakdown::default();
    if let Some(t) = &sets.stored {
        let (r, j, v) = stored_state(&t.pattern, material, t.weight)?;
        residual.extend(r);
        jacobian.extend(j);
        b.stored_residual = Some(v);
    }
    if sets.grid.is_some() || sets.curve.is_some() {
        let problem = MicroProblem::new(pattern.clone(), material, solver.clone());
        if let Some(t) = &sets.grid {
            let g = grid_residual(&problem, t, warm, true)?;
            residual.extend(g.residual);
            jacobian.extend(g.jacobian);
            b.grid_rms = Some(g.rms);
            b.grid_points = g.per_point;
        }
        if let Some(t) = &sets.curve {
            let (r, j, v) = curve_residual(&problem, t, &mut warm.curve, true)?;
            residual.extend(r);
            jacobian.extend(j);
            b.curve_rel_rms = Some(v);
        }
    }
    b.cost = 0.5 * residual.iter().map(|v| v * v).sum::<f64>();
    Ok(Evaluation {
        residual,
        jacobian,
        breakdown: b,
    })
}

/// One Levenberg–Marquardt iteration as reported.
#[derive(Clone, Debug, Serialize)]
pub struct Iteration {
    /// Iteration number (0: the start).
    pub iteration: usize,
    /// The unknowns q = (ln Y, ln γ, ln G/Y, ln k_c, ln f) after the iteration.
    pub unknowns: [f64; 5],
    /// The residuals' sizes after the iteration.
    pub breakdown: Breakdown,
    /// λ of the accepted step.
    pub lambda: f64,
    /// Rejected trials before the accepted one.
    pub rejected: usize,
    /// Why each was rejected (the trial's cost, or the solve that failed).
    pub rejections: Vec<String>,
    /// Unknowns clamped to the admissible box in the accepted step.
    pub clamped: Vec<&'static str>,
    /// Wall time since the start (s).
    pub time: f64,
}

/// The outcome of [`identify`].
#[derive(Clone, Debug, Serialize)]
pub struct Identification {
    /// The start parameters.
    pub start: YarnMaterial,
    /// The identified parameters.
    pub identified: YarnMaterial,
    /// The identified unknowns q = (ln Y, ln γ, ln G/Y, ln k_c, ln f).
    pub unknowns: [f64; 5],
    /// Which unknowns moved.
    pub free: [bool; 5],
    /// Standard errors of the free unknowns (of ln θ: relative errors of the parameters); `None` when fixed.
    pub standard_errors: [Option<f64>; 5],
    /// Correlations of the unknowns (fixed ones: zero rows).
    pub correlations: [[f64; 5]; 5],
    /// The residuals' sizes at the start.
    pub before: Breakdown,
    /// The residuals' sizes at the identified parameters.
    pub after: Breakdown,
    /// The accepted iterations, the start first.
    pub iterations: Vec<Iteration>,
    /// Why the iteration stopped.
    pub stopped: String,
    /// Number m of residuals.
    pub residual_count: usize,
    /// Wall time (s).
    pub time: f64,
}

/// Levenberg–Marquardt on the switched-on residuals from `start` (module docs). `report` is called after the
/// start evaluation (iteration 0) and after each accepted step.
pub fn identify(
    pattern: &Pattern,
    start: &YarnMaterial,
    sets: &Residuals,
    options: &IdentifyOptions,
    report: &mut dyn FnMut(&Iteration),
) -> Result<Identification, IdentifyError> {
    let t0 = Instant::now();
    let mut q = unknowns_of(start);
    let clamped0 = clamp(&mut q);
    let base = material_of(&q, start);
    let mut warm = WarmStates::default();
    let mut ev = evaluate(pattern, &base, sets, &options.solver, &mut warm)?;
    let before = ev.breakdown.clone();
    let free: Vec<usize> = (0..5).filter(|&k| options.free[k]).collect();
    let mut lambda = options.lambda;
    let mut iterations = vec![Iteration {
        iteration: 0,
        unknowns: q,
        breakdown: ev.breakdown.clone(),
        lambda,
        rejected: 0,
        rejections: vec![],
        clamped: clamped0,
        time: t0.elapsed().as_secs_f64(),
    }];
    report(&iterations[0]);
    let mut stopped = format!("{} iterations", options.max_iterations);
    let fit = Fit {
        pattern,
        start,
        sets,
        options,
    };
    for it in 1..=options.max_iterations {
        let Search {
            accepted,
            lambda: searched,
            rejected,
            reasons,
        } = fit.search(&ev, &free, q, &warm, lambda);
        lambda = searched;
        let Some(a) = accepted else {
            stopped = format!(
                "no step lowered the cost (λ = {lambda:.1e}; last: {})",
                reasons.last().map_or("-", |s| s.as_str())
            );
            break;
        };
        let decrease = (ev.breakdown.cost - a.ev.breakdown.cost) / ev.breakdown.cost.max(1e-300);
        q = a.q;
        ev = a.ev;
        warm = a.warm;
        let row = Iteration {
            iteration: it,
            unknowns: q,
            breakdown: ev.breakdown.clone(),
            lambda,
            rejected,
            rejections: reasons,
            clamped: a.clamped,
            time: t0.elapsed().as_secs_f64(),
        };
        report(&row);
        iterations.push(row);
        lambda = (lambda / 10.0).max(1e-12);
        if decrease < options.cost_tolerance {
            stopped = format!("relative cost decrease {decrease:.1e} below the tolerance");
            break;
        }
        if a.step < options.step_tolerance {
            stopped = format!("largest step {:.1e} below the tolerance", a.step);
            break;
        }
    }
    let (standard_errors, correlations) = covariance(&ev, &free);
    Ok(Identification {
        start: base,
        identified: material_of(&q, start),
        unknowns: q,
        free: options.free,
        standard_errors,
        correlations,
        before,
        after: ev.breakdown.clone(),
        iterations,
        stopped,
        residual_count: ev.residual.len(),
        time: t0.elapsed().as_secs_f64(),
    })
}

/// What a Levenberg–Marquardt step is tried on: the pattern, the start material (the parameters that are not
/// unknowns), the residual sets and the options.
struct Fit<'a> {
    pattern: &'a Pattern,
    start: &'a YarnMaterial,
    sets: &'a Residuals,
    options: &'a IdentifyOptions,
}

/// A step the damped search accepted: the new unknowns, their evaluation and warm states, the unknowns clamped
/// to the admissible box, and the largest change of an unknown.
struct Accepted {
    q: [f64; 5],
    ev: Evaluation,
    warm: WarmStates,
    clamped: Vec<&'static str>,
    step: f64,
}

/// The damped search of one iteration: the accepted step (if any), λ after the search, the trials rejected and
/// why.
struct Search {
    accepted: Option<Accepted>,
    lambda: f64,
    rejected: usize,
    reasons: Vec<String>,
}

impl Fit<'_> {
    /// Damped Gauss–Newton steps from `q` (evaluated as `ev`), λ growing ×10 after each step that fails to lower
    /// the cost (or whose solve fails), at most 13 trials; each step is shortened to `max_step` and clamped to the
    /// admissible box.
    fn search(
        &self,
        ev: &Evaluation,
        free: &[usize],
        q: [f64; 5],
        warm: &WarmStates,
        mut lambda: f64,
    ) -> Search {
        let options = self.options;
        let (jtj, jtr) = normal_equations(ev, free);
        let mut rejected = 0;
        let mut reasons = Vec::new();
        while rejected <= 12 {
            let mut a = jtj.clone();
            for i in 0..free.len() {
                a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
            }
            let Some(delta) = a.cholesky().map(|c| c.solve(&(-&jtr))) else {
                lambda *= 10.0;
                rejected += 1;
                continue;
            };
            let longest = delta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let shrink = if longest > options.max_step {
                options.max_step / longest
            } else {
                1.0
            };
            let mut trial = q;
            for (i, &k) in free.iter().enumerate() {
                trial[k] += shrink * delta[i];
            }
            let clamped = clamp(&mut trial);
            let mut trial_warm = warm.clone();
            let m = material_of(&trial, self.start);
            match evaluate(
                self.pattern,
                &m,
                self.sets,
                &options.solver,
                &mut trial_warm,
            ) {
                Ok(e) if e.breakdown.cost < ev.breakdown.cost => {
                    let step = (0..5).map(|k| (trial[k] - q[k]).abs()).fold(0.0, f64::max);
                    let accepted = Accepted {
                        q: trial,
                        ev: e,
                        warm: trial_warm,
                        clamped,
                        step,
                    };
                    return Search {
                        accepted: Some(accepted),
                        lambda,
                        rejected,
                        reasons,
                    };
                }
                // a higher cost or a solve that did not converge: a shorter step
                other => {
                    reasons.push(match other {
                        Ok(e) => format!("λ {lambda:.0e}: cost {:.4e}", e.breakdown.cost),
                        Err(e) => format!("λ {lambda:.0e}: {e}"),
                    });
                    lambda *= 10.0;
                    rejected += 1;
                }
            }
        }
        Search {
            accepted: None,
            lambda,
            rejected,
            reasons,
        }
    }
}

/// JᵀJ and Jᵀr over the free columns.
fn normal_equations(ev: &Evaluation, free: &[usize]) -> (DMatrix<f64>, DVector<f64>) {
    let p = free.len();
    let mut jtj = DMatrix::zeros(p, p);
    let mut jtr = DVector::zeros(p);
    for (row, r) in ev.jacobian.iter().zip(&ev.residual) {
        for (i, &a) in free.iter().enumerate() {
            jtr[i] += row[a] * r;
            for (j, &b) in free.iter().enumerate() {
                jtj[(i, j)] += row[a] * row[b];
            }
        }
    }
    (jtj, jtr)
}

/// Standard errors and correlations from σ² (JᵀJ)⁻¹ (pseudo-inverse: an unidentifiable direction shows as an
/// infinite standard error).
fn covariance(ev: &Evaluation, free: &[usize]) -> ([Option<f64>; 5], [[f64; 5]; 5]) {
    let (jtj, _) = normal_equations(ev, free);
    let m = ev.residual.len();
    let p = free.len();
    let sigma2 = 2.0 * ev.breakdown.cost / (m.saturating_sub(p).max(1)) as f64;
    let mut se = [None; 5];
    let mut corr = [[0.0; 5]; 5];
    if p == 0 {
        return (se, corr);
    }
    let svd = jtj.clone().svd(true, true);
    let smax = svd.singular_values.max();
    // unknowns with a component along a direction JᵀJ does not see are not identifiable
    let vt = svd.v_t.clone().expect("asked for");
    let unseen: Vec<bool> = (0..p)
        .map(|i| {
            svd.singular_values
                .iter()
                .enumerate()
                .any(|(k, &s)| s <= 1e-12 * smax && vt[(k, i)].abs() > 1e-6)
        })
        .collect();
    let inv = svd
        .pseudo_inverse(1e-12 * smax)
        .unwrap_or_else(|_| DMatrix::zeros(p, p));
    for (i, &a) in free.iter().enumerate() {
        let v = sigma2 * inv[(i, i)];
        se[a] = Some(if unseen[i] {
            f64::INFINITY
        } else {
            v.max(0.0).sqrt()
        });
        for (j, &b) in free.iter().enumerate() {
            let d = (inv[(i, i)] * inv[(j, j)]).sqrt();
            corr[a][b] = if d > 0.0 { inv[(i, j)] / d } else { 0.0 };
        }
    }
    (se, corr)
}
