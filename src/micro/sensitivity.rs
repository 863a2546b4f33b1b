//! Equilibrium sensitivities to the yarn parameters (docs/yarn-parameters.md; `docs/micro-solver.md`, section 5):
//! dy*/dθ for every continuous yarn parameter θ by the implicit-function theorem at a converged equilibrium,
//! with one factorisation of the Newton matrix.
//!
//! At a constrained equilibrium ∇_y E(y*, θ) + Aᵀλ = 0, A y* = const (A does not depend on θ), so
//!
//! [H Aᵀ; A 0] [dy*/dθ; dλ/dθ] = [−∂(∇_y E)/∂θ; 0],
//!
//! solved as the solver solves its Newton steps (unit scaling r θ for the angles, μ at 1e-10 of the largest
//! diagonal entry, three steps of iterative refinement against the unshifted H; [`KktSolver::solve_refined`]).
//! Where H + μI does not factorise (H positive definite only on the constraint space, e.g. when a slide
//! constraint holds a yarn back), projected conjugate gradients on the constraint space with the factorisation
//! of a larger shift as preconditioner ([`KktSolver::solve_projected`]); where H is indefinite even there (the
//! solver stopped at a saddle), a dense LU factorisation of the KKT matrix.
//!
//! Mixed derivatives ∂(∇_y E)/∂θ ([`parameter_mixed_gradients`]): with E = Y e_s + γY e_b + γG e_t + k_c e_c(ρ)
//! (e_* the energies per unit parameter, stretching ∝ r², bending and twisting ∝ r⁴, ρ = f r the contact radius),
//! the gradients are linear in Y, G, γ, k_c:
//! ∂/∂Y = g_s + γ g_b, ∂/∂G = γ g_t, ∂/∂γ = Y g_b + G g_t, ∂/∂k_c = g_c,
//! and the radii enter through ∂/∂f = r k_c ∂g_c/∂ρ and ∂/∂r = (2/r) Y g_s + (4/r)(γY g_b + γG g_t) + f k_c ∂g_c/∂ρ,
//! with ∂g_c/∂ρ the contact kernel's mixed radius derivative ([`Tile::contact_radius_derivatives`], a row of the
//! derivative harness).

use super::elimination::Elimination;
use super::linear::{FactorError, KktSolver};
use super::solver::{MicroError, MicroProblem, MicroState, Solution};
use crate::rod::YarnMaterial;
use crate::tile::{Terms, Tile, Want};

/// The continuous yarn parameters θ of the sensitivities, in the order of [`YarnParameter::ALL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum YarnParameter {
    /// Young's modulus Y (Pa).
    Young,
    /// Shear modulus G (Pa).
    Shear,
    /// Bending and twisting factor γ.
    BendTwistFactor,
    /// Contact stiffness k_c (J/m²).
    ContactStiffness,
    /// Contact radius factor f (contact distance 2 f r).
    ContactRadiusFactor,
    /// Yarn radius r (m): the stiffnesses (r², r⁴) and the contact radius f r; the positions stay.
    Radius,
}

impl YarnParameter {
    /// Every parameter, in the order of the sensitivities.
    pub const ALL: [YarnParameter; 6] = [
        YarnParameter::Young,
        YarnParameter::Shear,
        YarnParameter::BendTwistFactor,
        YarnParameter::ContactStiffness,
        YarnParameter::ContactRadiusFactor,
        YarnParameter::Radius,
    ];

    /// The key of the parameter in the yarn JSON.
    pub fn name(self) -> &'static str {
        match self {
            YarnParameter::Young => "young",
            YarnParameter::Shear => "shear",
            YarnParameter::BendTwistFactor => "bend_twist_factor",
            YarnParameter::ContactStiffness => "contact_stiffness",
            YarnParameter::ContactRadiusFactor => "contact_radius_factor",
            YarnParameter::Radius => "radius",
        }
    }

    /// The parameter's value in `m`.
    pub fn get(self, m: &YarnMaterial) -> f64 {
        match self {
            YarnParameter::Young => m.young,
            YarnParameter::Shear => m.shear,
            YarnParameter::BendTwistFactor => m.bend_twist_factor,
            YarnParameter::ContactStiffness => m.contact_stiffness,
            YarnParameter::ContactRadiusFactor => m.contact_radius_factor,
            YarnParameter::Radius => m.radius,
        }
    }

    /// Set the parameter in `m` (the radius of a micro problem is its pattern's: set both).
    pub fn set(self, m: &mut YarnMaterial, v: f64) {
        match self {
            YarnParameter::Young => m.young = v,
            YarnParameter::Shear => m.shear = v,
            YarnParameter::BendTwistFactor => m.bend_twist_factor = v,
            YarnParameter::ContactStiffness => m.contact_stiffness = v,
            YarnParameter::ContactRadiusFactor => m.contact_radius_factor = v,
            YarnParameter::Radius => m.radius = v,
        }
    }
}

/// The tile of a state at its strain with its contact candidates found (broad-phase margin of the solver).
fn tile_at<'p>(
    problem: &'p MicroProblem,
    state: &MicroState,
    material: &YarnMaterial,
) -> Result<Tile<'p>, MicroError> {
    let p = &problem.pattern;
    let elim = Elimination::in_family(p, &state.strain, state.family);
    let mut tile = Tile::new(p, material);
    elim.apply_to(&mut tile);
    let x = tile.home_positions(&state.y);
    tile.update_contacts(&x, problem.options.contact_margin * p.radius)?;
    Ok(tile)
}

/// ∂(∇_y E)/∂θ (tile dofs, N per unit parameter for positions, N m for angles) at a state, for every parameter
/// of [`YarnParameter::ALL`] (module docs).
pub fn parameter_mixed_gradients(
    problem: &MicroProblem,
    state: &MicroState,
) -> Result<Vec<Vec<f64>>, MicroError> {
    let m = &problem.material;
    let r = problem.pattern.radius;
    let unit = YarnMaterial {
        young: 1.0,
        shear: 1.0,
        bend_twist_factor: 1.0,
        contact_stiffness: 1.0,
        ..m.clone()
    };
    let tile = tile_at(problem, state, &unit)?;
    let part = |stretch, bend, twist, contact| -> Result<Vec<f64>, MicroError> {
        let terms = Terms {
            stretch,
            bend,
            twist,
            contact,
        };
        let ev = tile.evaluate(&state.frames, &state.y, Want::Gradient, &terms)?;
        Ok(ev.gradient.expect("asked for").iter().copied().collect())
    };
    let gs = part(1.0, 0.0, 0.0, 0.0)?;
    let gb = part(0.0, 1.0, 0.0, 0.0)?;
    let gt = part(0.0, 0.0, 1.0, 0.0)?;
    let gc = part(0.0, 0.0, 0.0, 1.0)?;
    let (_, gcr) = tile.contact_radius_derivatives(&state.y)?;
    let (y, g, ga, kc, f) = (
        m.young,
        m.shear,
        m.bend_twist_factor,
        m.contact_stiffness,
        m.contact_radius_factor,
    );
    let nd = gs.len();
    let combine = |w: [f64; 5]| -> Vec<f64> {
        (0..nd)
            .map(|i| w[0] * gs[i] + w[1] * gb[i] + w[2] * gt[i] + w[3] * gc[i] + w[4] * gcr[i])
            .collect()
    };
    Ok(YarnParameter::ALL
        .iter()
        .map(|p| match p {
            YarnParameter::Young => combine([1.0, ga, 0.0, 0.0, 0.0]),
            YarnParameter::Shear => combine([0.0, 0.0, ga, 0.0, 0.0]),
            YarnParameter::BendTwistFactor => combine([0.0, y, g, 0.0, 0.0]),
            YarnParameter::ContactStiffness => combine([0.0, 0.0, 0.0, 1.0, 0.0]),
            YarnParameter::ContactRadiusFactor => combine([0.0, 0.0, 0.0, 0.0, r * kc]),
            YarnParameter::Radius => {
                combine([2.0 * y / r, 4.0 * ga * y / r, 4.0 * ga * g / r, 0.0, f * kc])
            }
        })
        .collect())
}

/// −H⁻¹ b_k on the constraint space for each right-hand side b_k (tile dofs), with one factorisation of the
/// Newton matrix H at `state` (module docs): the first-order change of the equilibrium under a change of the
/// gradient by b_k.
pub fn equilibrium_response(
    problem: &MicroProblem,
    state: &MicroState,
    rhs: &[Vec<f64>],
) -> Result<Vec<Vec<f64>>, MicroError> {
    let p = &problem.pattern;
    let n = p.len();
    let nd = 4 * n;
    let r = p.radius;
    let tile = tile_at(problem, state, &problem.material)?;
    let ev = tile.evaluate(&state.frames, &state.y, Want::Hessian, &Terms::ALL)?;
    let scale = |i: usize| if i < 3 * n { 1.0 } else { 1.0 / r };
    let lower: Vec<(usize, usize, f64)> = ev
        .hessian
        .expect("asked for")
        .into_iter()
        .filter(|&(i, j, _)| i >= j)
        .map(|(i, j, v)| (i, j, v * scale(i) * scale(j)))
        .collect();
    let diag_max = lower
        .iter()
        .filter(|t| t.0 == t.1)
        .fold(0.0f64, |m, t| m.max(t.2.abs()))
        .max(problem.material.stretch_stiffness() / r);
    let bs: Vec<Vec<f64>> = rhs
        .iter()
        .map(|v| v.iter().enumerate().map(|(i, x)| x * scale(i)).collect())
        .collect();
    let mut kkt = KktSolver::default();
    // the solver's Newton direction: δ = −H_s⁻¹ S b, and dy = S δ; where H is positive definite only on the
    // constraint space, projected conjugate gradients with the factorisation of H + μI
    let delta = match kkt.solve_refined(nd, &lower, 1e-10 * diag_max, &bs, problem.constraints(), 3)
    {
        Ok(d) => d,
        Err(FactorError::NotPositiveDefinite) => {
            match kkt.solve_projected(1e-10 * diag_max, &bs, problem.constraints(), 1e-13, 2000) {
                Ok(d) => d,
                // H indefinite on the constraint space (a saddle the solver stopped at): the KKT matrix itself
                Err(_) => dense_kkt(nd, &lower, problem.constraints(), &bs)?,
            }
        }
        Err(e) => return Err(MicroError::Linear(e)),
    };
    Ok(delta
        .into_iter()
        .map(|d| d.iter().enumerate().map(|(i, x)| x * scale(i)).collect())
        .collect())
}

/// The solutions δ of [H Aᵀ; A 0] [δ; λ] = [−b; 0] by a dense LU factorisation of the KKT matrix (`lower`: the
/// lower triangle of H as triplets, duplicates summed): the fallback for an H that is indefinite on the
/// constraint space, where neither the Cholesky factorisation nor conjugate gradients apply. An error when the
/// KKT matrix is singular (a free mode at the equilibrium).
fn dense_kkt(
    nd: usize,
    lower: &[(usize, usize, f64)],
    a: &[Vec<f64>],
    rhs: &[Vec<f64>],
) -> Result<Vec<Vec<f64>>, MicroError> {
    let m = a.len();
    let mut k = nalgebra::DMatrix::<f64>::zeros(nd + m, nd + m);
    for &(i, j, v) in lower {
        k[(i, j)] += v;
        if i != j {
            k[(j, i)] += v;
        }
    }
    for (r, row) in a.iter().enumerate() {
        for (i, &v) in row.iter().enumerate() {
            k[(nd + r, i)] = v;
            k[(i, nd + r)] = v;
        }
    }
    let lu = k.lu();
    rhs.iter()
        .map(|b| {
            let v = nalgebra::DVector::from_fn(nd + m, |i, _| if i < nd { -b[i] } else { 0.0 });
            let x = lu.solve(&v).filter(|x| x.iter().all(|v| v.is_finite())).ok_or_else(|| {
                MicroError::Linear(FactorError::Other(
                    "the KKT matrix at the equilibrium is singular (a free mode): no sensitivities".into(),
                ))
            })?;
            Ok(x.rows(0, nd).iter().copied().collect())
        })
        .collect()
}

/// dy*/dθ (tile dofs: ũ in m, θ in rad, per unit parameter) at a converged equilibrium, one vector per
/// parameter of [`YarnParameter::ALL`].
pub fn equilibrium_sensitivities(
    problem: &MicroProblem,
    sol: &Solution,
) -> Result<Vec<Vec<f64>>, MicroError> {
    sol.psi().map_err(|source| MicroError::NeedsEquilibrium {
        what: "equilibrium sensitivities",
        source,
    })?;
    let b = parameter_mixed_gradients(problem, &sol.state)?;
    equilibrium_response(problem, &sol.state, &b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dense KKT fallback agrees with the sparse constrained solve on a positive definite H, and solves an H
    /// that is indefinite on the constraint space to round-off.
    #[test]
    fn dense_kkt_matches_the_sparse_solve_and_handles_an_indefinite_h() {
        let n = 6;
        let tri = |d: &[f64]| -> Vec<(usize, usize, f64)> {
            let mut t: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, d[i])).collect();
            t.extend((1..n).map(|i| (i, i - 1, -0.5)));
            t
        };
        let a = vec![vec![1.0, 1.0, 1.0, 1.0, 1.0, 1.0]];
        let b: Vec<Vec<f64>> = vec![(0..n).map(|i| (i as f64).sin()).collect()];
        let spd = tri(&[3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        let sparse = KktSolver::default()
            .solve_refined(n, &spd, 0.0, &b, &a, 0)
            .unwrap();
        let dense = dense_kkt(n, &spd, &a, &b).unwrap();
        for i in 0..n {
            assert!((sparse[0][i] - dense[0][i]).abs() < 1e-13);
        }
        // indefinite on the null space of A: residual of the KKT equations
        let ind = tri(&[3.0, -4.0, 5.0, 6.0, 7.0, 8.0]);
        let x = dense_kkt(n, &ind, &a, &b).unwrap().pop().unwrap();
        let mut h = nalgebra::DMatrix::<f64>::zeros(n, n);
        for &(i, j, v) in &ind {
            h[(i, j)] += v;
            if i != j {
                h[(j, i)] += v;
            }
        }
        let hx: nalgebra::DVector<f64> = &h * nalgebra::DVector::from_column_slice(&x);
        // H x + b is parallel to the constraint row (Aᵀλ), and A x = 0
        let r: Vec<f64> = (0..n).map(|i| hx[i] + b[0][i]).collect();
        let lambda = r.iter().sum::<f64>() / n as f64;
        assert!(r.iter().all(|v| (v - lambda).abs() < 1e-12), "{r:?}");
        assert!(x.iter().sum::<f64>().abs() < 1e-13);
    }
}
