//! The residual sets of `hylc identify` (docs/yarn-parameters.md) with their Jacobians with respect to the yarn
//! parameters, from the solver's own derivatives:
//!
//! - (a) the equilibrium residual at the pattern's stored state: r_a = w_a ∇E / N with
//!   N² = ‖Y a_s‖² + ‖γY a_b‖² + ‖γG a_t‖² (the measure of [`crate::validation::calibration`], scale-free in the
//!   stiffnesses), θ rows as forces on r θ;
//! - (b) the original's displacement fields at a set of grid points, compared as `micro-grid` compares them:
//!   per grid point g ≠ g₀ and vertex, (ours_g − ours_g₀) − (orig_g − orig_g₀) of (dξ₁, dξ₂, dh) in units of r,
//!   weighted w_b / √(points · vertices) so that its sum of squares is w_b² times the squared RMS error; the
//!   Jacobian chains the equilibrium sensitivities dy*/dθ ([`crate::micro::sensitivity`]) through the linear map
//!   from the unknowns to the compared rows ([`counterpart_derivative`]);
//! - (c) the original material's 1D curves ψ(z) = f₀ + f_k(z_k) at strains z along one or more axes: (Ψ̄(z) −
//!   ψ(z)) / RMS(ψ along that axis) weighted w_c / √points (sum of squares w_c² times the squared relative RMS
//!   error); the Jacobian is
//!   the envelope theorem's ∂Ψ̄/∂θ ([`crate::micro::envelope::parameter_derivatives`]).

use super::IdentifyError;
use crate::micro::envelope::parameter_derivatives;
use crate::micro::sensitivity::equilibrium_sensitivities;
use crate::micro::{MacroStrain, MicroProblem, MicroState, Status};
use crate::pattern::Pattern;
use crate::rod::YarnMaterial;
use crate::tile::{Terms, Tile, Want};
use crate::validation::grid::{counterpart, GridData};
use nalgebra::DVector;
use rayon::prelude::*;

/// The derivative of the compared rows (dξ₁, dξ₂, dh, dθ) of a state at an in-plane strain along a change `dy`
/// of its unknowns (tile dofs): the map of [`counterpart`] is affine in the unknowns, so this is the counterpart
/// of the state with unknowns dy (and the reference angles) taken as a displacement. `None` for a bending strain.
pub fn counterpart_derivative(
    pattern: &Pattern,
    state: &MicroState,
    dy: &[f64],
) -> Option<Vec<[f64; 4]>> {
    let n = pattern.len();
    let mut y = dy.to_vec();
    for v in 0..n {
        y[3 * n + v] += pattern.theta[v];
    }
    let s = MicroState { y, ..state.clone() };
    counterpart(pattern, &s)
}

/// One residual set at one parameter set: residuals, Jacobian rows (∂/∂q), and its size measure.
pub type Part = (Vec<f64>, Vec<[f64; 5]>, f64);

/// Ψ̄ at one strain with ∂Ψ̄/∂(Y, G, γ, k_c, f, r) when asked for.
pub type CurveValue = (f64, Option<[f64; 6]>);

/// ∂/∂q of (Y, G, γ, k_c, f) for the unknowns q = (ln Y, ln γ, ln G/Y, ln k_c, ln f): row k holds the factors
/// with which the parameter derivatives ∂/∂(Y, G, γ, k_c, f) combine into ∂/∂q_k.
pub fn chain(m: &YarnMaterial) -> [[f64; 5]; 5] {
    let (y, g, ga, kc, f) = (
        m.young,
        m.shear,
        m.bend_twist_factor,
        m.contact_stiffness,
        m.contact_radius_factor,
    );
    [
        [y, g, 0.0, 0.0, 0.0],
        [0.0, 0.0, ga, 0.0, 0.0],
        [0.0, g, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, kc, 0.0],
        [0.0, 0.0, 0.0, 0.0, f],
    ]
}

/// Combine per-parameter derivatives (Y, G, γ, k_c, f, …) into derivatives with respect to q.
fn to_q(c: &[[f64; 5]; 5], d: &[f64]) -> [f64; 5] {
    std::array::from_fn(|k| (0..5).map(|j| c[k][j] * d[j]).sum())
}

/// Residual (a) and its Jacobian with respect to q (5 columns).
pub fn stored_state(
    pattern: &Pattern,
    material: &YarnMaterial,
    weight: f64,
) -> Result<Part, IdentifyError> {
    let unit = YarnMaterial {
        young: 1.0,
        shear: 1.0,
        bend_twist_factor: 1.0,
        contact_stiffness: 1.0,
        ..material.clone()
    };
    let (state, tile, y) = Tile::at_rest_state(pattern, &unit)?;
    let n = pattern.len();
    let r = pattern.radius;
    let scaled = |g: DVector<f64>| -> Vec<f64> {
        g.iter()
            .enumerate()
            .map(|(i, v)| if i < 3 * n { *v } else { v / r })
            .collect()
    };
    let part = |s, b, t, c| -> Result<Vec<f64>, IdentifyError> {
        let terms = Terms {
            stretch: s,
            bend: b,
            twist: t,
            contact: c,
        };
        let ev = tile.evaluate(&state, &y, Want::Gradient, &terms)?;
        Ok(scaled(ev.gradient.expect("asked for")))
    };
    let (a_s, a_b, a_t, a_c) = (
        part(1.0, 0.0, 0.0, 0.0)?,
        part(0.0, 1.0, 0.0, 0.0)?,
        part(0.0, 0.0, 1.0, 0.0)?,
        part(0.0, 0.0, 0.0, 1.0)?,
    );
    let a_cr = scaled(tile.contact_radius_derivatives(&y)?.1);
    let m = material;
    let (yg, g, ga, kc) = (m.young, m.shear, m.bend_twist_factor, m.contact_stiffness);
    let nd = a_s.len();
    let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
    let total: Vec<f64> = (0..nd)
        .map(|i| yg * a_s[i] + ga * yg * a_b[i] + ga * g * a_t[i] + kc * a_c[i])
        .collect();
    // the size of the rod forces that have to cancel: N² = ‖Y a_s‖² + ‖γY a_b‖² + ‖γG a_t‖²
    let (ss, bb, tt) = (dot(&a_s, &a_s), dot(&a_b, &a_b), dot(&a_t, &a_t));
    let norm = (yg * yg * ss + (ga * yg).powi(2) * bb + (ga * g).powi(2) * tt).sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return Err(IdentifyError::Input(
            "the rod forces at the stored state are zero: the stored-state residual is undefined"
                .into(),
        ));
    }
    // ∂∇E/∂(Y, G, γ, k_c, f) and ∂N/∂(Y, G, γ, k_c, f)
    let d_total: [Vec<f64>; 5] = [
        (0..nd).map(|i| a_s[i] + ga * a_b[i]).collect(),
        (0..nd).map(|i| ga * a_t[i]).collect(),
        (0..nd).map(|i| yg * a_b[i] + g * a_t[i]).collect(),
        a_c.clone(),
        (0..nd).map(|i| kc * r * a_cr[i]).collect(),
    ];
    let d_norm: [f64; 5] = [
        (yg * ss + ga * ga * yg * bb) / norm,
        ga * ga * g * tt / norm,
        (ga * yg * yg * bb + ga * g * g * tt) / norm,
        0.0,
        0.0,
    ];
    let c = chain(m);
    let mut res = Vec::with_capacity(nd);
    let mut jac = Vec::with_capacity(nd);
    for i in 0..nd {
        res.push(weight * total[i] / norm);
        let d: [f64; 5] = std::array::from_fn(|j| {
            weight * (d_total[j][i] / norm - total[i] * d_norm[j] / (norm * norm))
        });
        jac.push(to_q(&c, &d));
    }
    let value = total.iter().map(|v| v * v).sum::<f64>().sqrt() / norm;
    Ok((res, jac, value))
}

/// The original's displacement data at a set of grid points (residual b).
pub struct GridTarget {
    /// The original's displacements.
    pub data: GridData,
    /// Compared grid points (indices), the start point excluded.
    pub points: Vec<usize>,
    /// Weight of residual (b).
    pub weight: f64,
}

/// Points along one or more strain axes with the original material's ψ there (residual c).
pub struct CurveTarget {
    /// The strains of the points.
    pub strains: Vec<MacroStrain>,
    /// The original material's ψ at the points (J/m²).
    pub values: Vec<f64>,
    /// Per point: the RMS of the original's values along its axis (each curve's errors are relative to its own
    /// size, so a bending curve of 0.1 J/m² counts as much as a stretching curve of 30 J/m²).
    pub scales: Vec<f64>,
    /// Weight of residual (c).
    pub weight: f64,
}

impl CurveTarget {
    /// The target of points (strain, original ψ) on 1D curves (each strain with one non-zero component).
    pub fn new(points: &[(MacroStrain, f64)], weight: f64) -> Self {
        let axis = |z: &MacroStrain| {
            (0..5)
                .max_by(|&a, &b| z.0[a].abs().total_cmp(&z.0[b].abs()))
                .unwrap_or(0)
        };
        let scales = points
            .iter()
            .map(|(z, _)| {
                let k = axis(z);
                let same: Vec<f64> = points
                    .iter()
                    .filter(|p| axis(&p.0) == k)
                    .map(|p| p.1 * p.1)
                    .collect();
                (same.iter().sum::<f64>() / same.len() as f64).sqrt()
            })
            .collect();
        CurveTarget {
            strains: points.iter().map(|p| p.0).collect(),
            values: points.iter().map(|p| p.1).collect(),
            scales,
            weight,
        }
    }
}

/// Converged states kept between evaluations for warm starts: (b) the start point and the compared points,
/// (c) the curve points.
#[derive(Clone, Default)]
pub struct WarmStates {
    /// (b) the state at the grid's start point.
    pub grid_zero: Option<MicroState>,
    /// (b) the state at each compared point.
    pub grid: Vec<Option<MicroState>>,
    /// (c) the state at each curve point.
    pub curve: Vec<Option<MicroState>>,
}

/// A solve that has to converge for the residual to exist.
fn solve(
    problem: &MicroProblem,
    z: &MacroStrain,
    start: Option<&MicroState>,
    what: &str,
) -> Result<crate::micro::Solution, IdentifyError> {
    let sol = problem.solve(z, start)?;
    if sol.status != Status::Converged {
        // one cold retry when a warm start fails
        if start.is_some() {
            let cold = problem.solve(z, None)?;
            if cold.status == Status::Converged {
                return Ok(cold);
            }
        }
        return Err(IdentifyError::NotConverged {
            what: what.to_string(),
            strain: *z,
            status: sol.status,
        });
    }
    Ok(sol)
}

/// Residual (b) with its Jacobian (when `jacobian`); its RMS error (r) as the third value and the RMS error per
/// compared point ((s_x, s_a, s_y), r) as the fourth. Updates `warm`.
pub fn grid_residual(
    problem: &MicroProblem,
    target: &GridTarget,
    warm: &mut WarmStates,
    jacobian: bool,
) -> Result<GridResidual, IdentifyError> {
    let p = &problem.pattern;
    let n = p.len();
    let r = p.radius;
    let data = &target.data;
    let g0 = data.zero_point();
    let z0 = data.strain(g0);
    let sol0 = solve(problem, &z0, warm.grid_zero.as_ref(), "grid start point")?;
    warm.grid.resize(target.points.len(), None);
    let starts: Vec<Option<MicroState>> = warm.grid.clone();
    let solved: Vec<Result<crate::micro::Solution, IdentifyError>> = target
        .points
        .par_iter()
        .zip(starts.par_iter())
        .map(|(&g, start)| {
            let from = start.as_ref().unwrap_or(&sol0.state);
            solve(problem, &data.strain(g), Some(from), "grid point")
        })
        .collect();
    let solved: Vec<crate::micro::Solution> = solved.into_iter().collect::<Result<_, _>>()?;
    let c = chain(&problem.material);
    let rows = |s: &MicroState| counterpart(p, s).expect("grid strains are in-plane");
    let ours0 = rows(&sol0.state);
    // dy*/dθ at the start point, as compared rows
    let deriv_rows = |sol: &crate::micro::Solution| -> Result<Vec<Vec<[f64; 4]>>, IdentifyError> {
        let dy = equilibrium_sensitivities(problem, sol)?;
        Ok(dy
            .iter()
            .take(5)
            .map(|d| counterpart_derivative(p, &sol.state, d).expect("in-plane"))
            .collect())
    };
    let d0 = if jacobian {
        Some(deriv_rows(&sol0)?)
    } else {
        None
    };
    let d_points: Vec<Option<Vec<Vec<[f64; 4]>>>> = if jacobian {
        solved
            .par_iter()
            .map(|s| deriv_rows(s).map(Some))
            .collect::<Result<_, _>>()?
    } else {
        vec![None; solved.len()]
    };
    let count = (target.points.len() * n).max(1) as f64;
    let w = target.weight / count.sqrt();
    let mut res = Vec::new();
    let mut jac = Vec::new();
    let mut sum2 = 0.0;
    let mut per_point = Vec::with_capacity(solved.len());
    for (k, (&g, sol)) in target.points.iter().zip(&solved).enumerate() {
        let ours = rows(&sol.state);
        let before = sum2;
        for v in 0..n {
            let (o, o0) = (data.row(g, v), data.row(g0, v));
            for comp in 0..3 {
                let e = ((ours[v][comp] - ours0[v][comp]) - (o[comp] - o0[comp])) / r;
                sum2 += e * e;
                res.push(w * e);
                if let (Some(d0), Some(dp)) = (&d0, &d_points[k]) {
                    let d: Vec<f64> = (0..5)
                        .map(|j| (dp[j][v][comp] - d0[j][v][comp]) / r)
                        .collect();
                    jac.push(to_q(&c, &d).map(|x| w * x));
                }
            }
        }
        let z = data.strain(g).0;
        per_point.push(([z[0], z[1], z[2]], ((sum2 - before) / n as f64).sqrt()));
    }
    warm.grid_zero = Some(sol0.state);
    warm.grid = solved.into_iter().map(|s| Some(s.state)).collect();
    Ok(GridResidual {
        residual: res,
        jacobian: jac,
        rms: (sum2 / count).sqrt(),
        per_point,
    })
}

/// Residual (b) at one parameter set ([`grid_residual`]).
pub struct GridResidual {
    /// The weighted residuals.
    pub residual: Vec<f64>,
    /// Their Jacobian ∂r/∂q, one row per residual.
    pub jacobian: Vec<[f64; 5]>,
    /// RMS position error over the compared points and vertices (r).
    pub rms: f64,
    /// Per compared point: (s_x, s_a, s_y) and its RMS position error (r).
    pub per_point: Vec<([f64; 3], f64)>,
}

/// Our Ψ̄ at the curve points (continuation from z = 0 outwards), with ∂Ψ̄/∂θ when `jacobian`.
pub fn curve_values(
    problem: &MicroProblem,
    strains: &[MacroStrain],
    warm: &mut Vec<Option<MicroState>>,
    jacobian: bool,
) -> Result<Vec<CurveValue>, IdentifyError> {
    warm.resize(strains.len(), None);
    // visit by distance from z = 0 so that each point can start from a nearer one
    let mut order: Vec<usize> = (0..strains.len()).collect();
    let size = |z: &MacroStrain| z.0.iter().map(|v| v * v).sum::<f64>();
    order.sort_by(|&a, &b| size(&strains[a]).total_cmp(&size(&strains[b])));
    let mut out = vec![(f64::NAN, None); strains.len()];
    // the last converged state per (axis, sign): each point starts from its nearer neighbour on its own branch
    let mut last: std::collections::HashMap<(usize, bool), MicroState> = Default::default();
    for i in order {
        let z = &strains[i];
        let axis = (0..5)
            .max_by(|&a, &b| z.0[a].abs().total_cmp(&z.0[b].abs()))
            .unwrap_or(0);
        let branch = (axis, z.0[axis] >= 0.0);
        let start = warm[i].as_ref().or(last.get(&branch));
        let sol = solve(problem, z, start, "1D curve point")?;
        let psi = sol.psi().map_err(|e| IdentifyError::Input(e.to_string()))?;
        let d = if jacobian {
            Some(parameter_derivatives(problem, &sol)?)
        } else {
            None
        };
        out[i] = (psi, d);
        last.insert(branch, sol.state.clone());
        warm[i] = Some(sol.state);
    }
    Ok(out)
}

/// Residual (c) with its Jacobian (when `jacobian`); the relative RMS error as the third value.
pub fn curve_residual(
    problem: &MicroProblem,
    target: &CurveTarget,
    warm: &mut Vec<Option<MicroState>>,
    jacobian: bool,
) -> Result<Part, IdentifyError> {
    let vals = curve_values(problem, &target.strains, warm, jacobian)?;
    let count = target.values.len().max(1) as f64;
    let c = chain(&problem.material);
    let mut res = Vec::new();
    let mut jac = Vec::new();
    let mut sum2 = 0.0;
    for (((psi, d), want), scale) in vals.iter().zip(&target.values).zip(&target.scales) {
        let w = target.weight / (scale.max(1e-300) * count.sqrt());
        let e = (psi - want) / scale.max(1e-300);
        sum2 += e * e;
        res.push(w * (psi - want));
        if let Some(d) = d {
            jac.push(to_q(&c, &d[..5]).map(|x| w * x));
        }
    }
    Ok((res, jac, (sum2 / count).sqrt()))
}
