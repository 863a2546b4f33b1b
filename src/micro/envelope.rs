//! Derivatives of Ψ̄ at an equilibrium by the envelope theorem (`docs/micro-solver.md`, section 5):
//! dΨ̄/dp = (1/(p₁p₂)) ∂E/∂p (y*, p) at fixed unknowns, for the strain components and the yarn parameters.
//!
//! Strain: at fixed y every vertex copy moves with the map, x = T_o(b_v(z) + R_v(z) ũ_v). Split into the motion
//! of the home copies (contracted with the assembled gradient in world coordinates) and the change of the tile
//! transforms, δx = ω_o × x + v_o per offset o (contracted with the force and moment resultants of the stencils
//! on copies, [`Tile::offset_resultants`], which include the turning of the copies' stored frames). The
//! z-derivatives of b_v, R_v and T_o come from num-dual through the generic surface maps.
//!
//! Parameters: the rod energies are linear in Y (stretching, bending), G (twisting), γ (bending and twisting) and
//! k_c (contact), so their derivatives are the energies of the same state with that parameter set to 1; the
//! radius enters as r² (stretching), r⁴ (bending, twisting) and through the contact kernel at the contact radius
//! ρ = f r ([`PairKernel::radius_derivative`]), which is also how the contact radius factor f enters.

use super::elimination::Elimination;
use super::sensitivity::YarnParameter;
use super::solver::{local, MicroError, MicroProblem, MicroState, Solution};
use super::strain::Family;
use super::surface::SurfaceMap;
use crate::contact::PairKernel;
use crate::tile::{Terms, Tile, Want};
use nalgebra::{Matrix3, Vector3};
use num_dual::Dual64;

/// The yarn parameters of [`parameter_derivatives`], in order (those of
/// [`YarnParameter::ALL`](super::sensitivity::YarnParameter::ALL)).
pub const PARAMETER_NAMES: [&str; 6] = [
    "young",
    "shear",
    "bend_twist_factor",
    "contact_stiffness",
    "contact_radius_factor",
    "radius",
];

/// ∂E/∂z_j (J per unit strain, one tile) at fixed unknowns of a state in its family, for the components that
/// family parametrises (`BendY`: s_x, s_a, s_y, Π₁₁; `BendX`: s_x, s_a, s_y, Π₀₀; the other entry is `None`).
pub fn energy_strain_gradient(
    problem: &MicroProblem,
    state: &MicroState,
) -> Result<[Option<f64>; 5], MicroError> {
    let p = &problem.pattern;
    let n = p.len();
    let elim = Elimination::in_family(p, &state.strain, state.family);
    let mut tile: Tile = problem.tile(&elim);
    let x = tile.home_positions(&state.y);
    tile.update_contacts(&x, problem.options.contact_margin * p.radius)?;
    let ev = tile.evaluate(&state.frames, &state.y, Want::Gradient, &Terms::ALL)?;
    let g = ev.gradient.expect("asked for");
    let res = tile.offset_resultants(&state.frames, &state.y, &Terms::ALL)?;
    let mut out = [None; 5];
    for (j, slot) in out.iter_mut().enumerate() {
        let skip = match state.family {
            Family::BendY => j == 3,
            Family::BendX => j == 4,
        };
        if skip {
            continue;
        }
        let z: [Dual64; 5] =
            std::array::from_fn(|k| Dual64::new(state.strain.0[k], if k == j { 1.0 } else { 0.0 }));
        let map = SurfaceMap::new(&z, state.family);
        let mut d = 0.0;
        // home copies: g_x · ∂x_v/∂z with g_x = R_v g_ũ
        for v in 0..n {
            let u = local(&state.y, v).map(Dual64::from);
            let xi = p.positions[v];
            let xd = map.point([xi.x, xi.y], xi.z, &[u.x, u.y, u.z]);
            let gx = elim.dofs.rotation[v] * Vector3::new(g[3 * v], g[3 * v + 1], g[3 * v + 2]);
            d += (0..3).map(|c| gx[c] * xd[c].eps).sum::<f64>();
        }
        // tile transforms: δx = ω × x + v_o
        for (o, f, m) in &res {
            let delta = [o[0] as f64 * p.periods[0], o[1] as f64 * p.periods[1]];
            let (phi, r) = map.frame(delta);
            let rot = Matrix3::from_fn(|a, b| r[a][b].re);
            let drot = Matrix3::from_fn(|a, b| r[a][b].eps);
            let w = drot * rot.transpose();
            let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
            let t = Vector3::from_fn(|a, _| phi[a].re);
            let dt = Vector3::from_fn(|a, _| phi[a].eps);
            let vo = dt - omega.cross(&t);
            d += omega.dot(m) + vo.dot(f);
        }
        *slot = Some(d);
    }
    Ok(out)
}

/// The homogenized stress ∂Ψ̄/∂z (J/m² per unit strain) at an equilibrium. At zero curvature both bending
/// components are given (the Π₀₀ one through the `BendX` family, which at zero curvature is the plane turned
/// in-plane); under bending along one axis the other component is `None` (not a supported strain direction).
pub fn strain_derivatives(
    problem: &MicroProblem,
    state: &MicroState,
) -> Result<[Option<f64>; 5], MicroError> {
    let area = problem.pattern.periods[0] * problem.pattern.periods[1];
    let mut d = energy_strain_gradient(problem, state)?;
    if state.family == Family::BendY && state.strain.0[4] == 0.0 {
        let mut other = state.clone();
        problem.switch_family(&mut other, Family::BendX);
        d[3] = energy_strain_gradient(problem, &other)?[3];
    }
    Ok(d.map(|v| v.map(|v| v / area)))
}

/// ∂Ψ̄/∂(Y, G, γ, k_c, f, r) (J/m² per unit parameter; f the contact radius factor) at a converged equilibrium.
/// The constraints do not depend on the parameters, so these are also the total derivatives dΨ̄/dθ.
pub fn parameter_derivatives(
    problem: &MicroProblem,
    sol: &Solution,
) -> Result<[f64; 6], MicroError> {
    sol.psi().map_err(|source| MicroError::NeedsEquilibrium {
        what: "parameter derivatives",
        source,
    })?;
    derivatives_at(problem, &sol.state, Some(&sol.energy), sol.area)
}

/// [`parameter_derivatives`] at a state known to be a converged equilibrium (e.g. the kept state of a sample),
/// the energy parts taken from the energies per unit parameter: E_s = Y e_s, E_b = γY e_b, E_t = γG e_t.
pub fn parameter_derivatives_at(
    problem: &MicroProblem,
    state: &MicroState,
) -> Result<[f64; 6], MicroError> {
    let area = problem.pattern.periods[0] * problem.pattern.periods[1];
    derivatives_at(problem, state, None, area)
}

/// The body of [`parameter_derivatives`]: `energy` the energy parts at the state (from the unit energies when
/// `None`), `area` = p₁ p₂.
fn derivatives_at(
    problem: &MicroProblem,
    state: &MicroState,
    energy: Option<&crate::tile::EnergyParts>,
    area: f64,
) -> Result<[f64; 6], MicroError> {
    let p = &problem.pattern;
    let m = &problem.material;
    let elim = Elimination::in_family(p, &state.strain, state.family);
    let mut unit = m.clone();
    unit.young = 1.0;
    unit.shear = 1.0;
    unit.bend_twist_factor = 1.0;
    unit.contact_stiffness = 1.0;
    let mut tile = Tile::new(p, &unit);
    elim.apply_to(&mut tile);
    let x = tile.home_positions(&state.y);
    tile.update_contacts(&x, problem.options.contact_margin * p.radius)?;
    let e1 = tile
        .evaluate(&state.frames, &state.y, Want::Value, &Terms::ALL)?
        .parts;
    // radii: the contact kernel's own derivative at the contact radius ρ = f r
    let kernel = PairKernel::new(
        m.contact_stiffness,
        tile.contact_radius,
        m.contact_quadrature,
    )?;
    let y = &state.y;
    let mut dc_dr = 0.0;
    for pair in &tile.contacts {
        let pts = pair.points(&tile).map(|(v, o)| tile.position(y, v, o));
        dc_dr += kernel.radius_derivative(
            &pts,
            p.edges[pair.a].rest_length,
            p.edges[pair.b].rest_length,
        )?;
    }
    let (yg, g, ga, r, f) = (
        m.young,
        m.shear,
        m.bend_twist_factor,
        p.radius,
        m.contact_radius_factor,
    );
    let (stretch, bend, twist) = match energy {
        Some(e) => (e.stretch, e.bend, e.twist),
        None => (yg * e1.stretch, ga * yg * e1.bend, ga * g * e1.twist),
    };
    Ok([
        (e1.stretch + ga * e1.bend) / area,
        ga * e1.twist / area,
        (yg * e1.bend + g * e1.twist) / area,
        e1.contact / area,
        r * dc_dr / area,
        (2.0 * stretch / r + 4.0 * (bend + twist) / r + f * dc_dr) / area,
    ])
}

/// The relative step of the directional differences of [`stress_parameter_derivatives`]: t_k = 1e-5 |θ_k|.
pub const STRESS_PARAMETER_STEP: f64 = 1e-5;

/// The total derivatives dσ/dθ_k of the stress σ = ∂Ψ̄/∂z ([`strain_derivatives`]) along the equilibrium, for
/// every parameter of [`YarnParameter::ALL`], given dy*/dθ_k (`dy`, from
/// [`equilibrium_sensitivities`](super::sensitivity::equilibrium_sensitivities)):
///
/// dσ/dθ_k = ∂σ/∂θ_k + (∂σ/∂y) dy*/dθ_k ≈ [σ(θ + t_k e_k, y* + t_k dy_k) − σ(θ − t_k e_k, y* − t_k dy_k)] / (2 t_k),
///
/// a central difference (t_k = [`STRESS_PARAMETER_STEP`] |θ_k|) of the analytic envelope stress at fixed stored
/// frames along the line through the equilibrium in the direction of its first-order response. A component
/// that [`strain_derivatives`] leaves `None` is `None`.
pub fn stress_parameter_derivatives(
    problem: &MicroProblem,
    state: &MicroState,
    dy: &[Vec<f64>],
) -> Result<Vec<[Option<f64>; 5]>, MicroError> {
    let mut out = Vec::with_capacity(YarnParameter::ALL.len());
    for (param, d) in YarnParameter::ALL.iter().zip(dy) {
        let v0 = param.get(&problem.material);
        let t = STRESS_PARAMETER_STEP * v0.abs();
        let at = |sign: f64| -> Result<[Option<f64>; 5], MicroError> {
            let mut m = problem.material.clone();
            param.set(&mut m, v0 + sign * t);
            let mut pat = problem.pattern.clone();
            if *param == YarnParameter::Radius {
                pat.radius = v0 + sign * t;
            }
            let q = MicroProblem::new(pat, &m, problem.options.clone());
            let mut s = state.clone();
            s.y.iter_mut().zip(d).for_each(|(y, d)| *y += sign * t * d);
            strain_derivatives(&q, &s)
        };
        let (plus, minus) = (at(1.0)?, at(-1.0)?);
        out.push(std::array::from_fn(|j| match (plus[j], minus[j]) {
            (Some(a), Some(b)) => Some((a - b) / (2.0 * t)),
            _ => None,
        }));
    }
    Ok(out)
}

/// Second derivatives of Ψ̄ with respect to the strain components of a state's family, and the sensitivity of
/// the equilibrium unknowns (`docs/micro-solver.md`, section 5).
#[derive(Clone, Debug)]
pub struct StrainStiffness {
    /// The strain components (indices into z) of the rows and columns.
    pub components: Vec<usize>,
    /// d²Ψ̄/dz_i dz_j (J/m² per unit strain²).
    pub hessian: nalgebra::DMatrix<f64>,
    /// dy*/dz_k in the tile's dof layout (ũ in m, θ in rad), one vector per component.
    pub dy: Vec<Vec<f64>>,
}

/// The reduced gradient (tile dofs) of a state at its own strain.
pub(crate) fn gradient_at(
    problem: &MicroProblem,
    state: &MicroState,
) -> Result<Vec<f64>, MicroError> {
    let p = &problem.pattern;
    let elim = Elimination::in_family(p, &state.strain, state.family);
    let mut tile = problem.tile(&elim);
    let x = tile.home_positions(&state.y);
    tile.update_contacts(&x, problem.options.contact_margin * p.radius)?;
    let ev = tile.evaluate(&state.frames, &state.y, Want::Gradient, &Terms::ALL)?;
    Ok(ev.gradient.expect("asked for").iter().copied().collect())
}

/// d²Ψ̄/dz² = (1/A)(∂²E/∂z² − (∂²E/∂y∂z)ᵀ H⁻¹ ∂²E/∂y∂z) and dy*/dz = −H⁻¹ ∂²E/∂y∂z on the constraint space, with
/// one factorisation of the Newton matrix H (unit scaling and μ floor as in the solver). The mixed derivatives
/// ∂²E/∂y∂z and ∂²E/∂z² are central differences (step 1e-5 in strain, 1e-5/max(p) in curvature) of the analytic
/// reduced gradient and of the analytic envelope gradient at fixed unknowns, the frames moved with the strain as
/// in a warm start. The components are those of the state's family (`BendY`: s_x, s_a, s_y, Π₁₁; `BendX`: s_x,
/// s_a, s_y, Π₀₀).
pub fn strain_stiffness(
    problem: &MicroProblem,
    state: &MicroState,
) -> Result<StrainStiffness, MicroError> {
    let p = &problem.pattern;
    let nd = 4 * p.len();
    let area = p.periods[0] * p.periods[1];
    let components: Vec<usize> = match state.family {
        Family::BendY => vec![0, 1, 2, 4],
        Family::BendX => vec![0, 1, 2, 3],
    };
    let pmax = p.periods[0].max(p.periods[1]);
    let k = components.len();
    let mut b: Vec<Vec<f64>> = Vec::with_capacity(k);
    let mut ezz = nalgebra::DMatrix::zeros(k, k);
    for (col, &j) in components.iter().enumerate() {
        let h = if j < 3 { 1e-5 } else { 1e-5 / pmax };
        let moved = |sign: f64| -> Result<MicroState, MicroError> {
            let mut s = state.clone();
            let mut z = s.strain;
            z.0[j] += sign * h;
            problem.move_to(&mut s, &z)?;
            Ok(s)
        };
        let (sp, sm) = (moved(1.0)?, moved(-1.0)?);
        let (gp, gm) = (gradient_at(problem, &sp)?, gradient_at(problem, &sm)?);
        b.push((0..nd).map(|i| (gp[i] - gm[i]) / (2.0 * h)).collect());
        let (dp, dm) = (
            energy_strain_gradient(problem, &sp)?,
            energy_strain_gradient(problem, &sm)?,
        );
        for (row, &i) in components.iter().enumerate() {
            ezz[(row, col)] =
                (dp[i].expect("family component") - dm[i].expect("family component")) / (2.0 * h);
        }
    }
    let ezz = (&ezz + ezz.transpose()) * 0.5;

    // dy/dz_k = −H⁻¹ b_k with one factorisation; bᵀH⁻¹b = −b_i · dy_j
    let dy = super::sensitivity::equilibrium_response(problem, state, &b)?;
    let mut hessian = nalgebra::DMatrix::zeros(k, k);
    for i in 0..k {
        for j in 0..k {
            let bkb: f64 = -b[i].iter().zip(&dy[j]).map(|(a, d)| a * d).sum::<f64>();
            hessian[(i, j)] = (ezz[(i, j)] - bkb) / area;
        }
    }
    let hessian = (&hessian + hessian.transpose()) * 0.5;
    Ok(StrainStiffness {
        components,
        hessian,
        dy,
    })
}
