//! Calibration of the yarn parameters against patterns that should be static equilibria
//! (`docs/results.md`, "Validation against the original", item b; `docs/yarn-model.md` "What the original
//! reference patterns tell").
//!
//! At a pattern's stored state the energy gradient is linear in the stiffness parameters:
//!
//! ∇E = Y a_s + (γY) a_b + (γG) a_t + k_c a_c,
//!
//! with a_s, a_b, a_t, a_c the gradients of the stretching, bending, twisting and contact terms per unit parameter
//! (the contact term for a given quadrature order, exclusion and radius). Angles enter as r·θ (the unit scaling of
//! `docs/micro-solver.md`), so every entry is a force. The overall scale is free (Y = 1e6 Pa fixes it); the best
//! (γY, γG, k_c) ≥ 0 for one pattern or a set of patterns is a small non-negative linear least-squares problem.
//!
//! Residual reported: ‖∇E‖ / ‖∇E_rods‖ with ‖∇E_rods‖ = (‖Y a_s‖² + ‖γY a_b‖² + ‖γG a_t‖²)^½, the size of the rod
//! forces that have to cancel (a pattern balanced by its rods alone still has large individual rod forces).

use crate::contact::ContactError;
use crate::pattern::Pattern;
use crate::rod::{RodState, YarnMaterial};
use crate::tile::{Terms, Tile, Want};
use nalgebra::{DMatrix, DVector};

/// The contact model variant of a calibration: quadrature order, exclusion along the yarn, contact radius factor
/// (contact distance 2·factor·r).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactForm {
    /// Gauss–Legendre points per segment Q of the contact quadrature.
    pub quadrature: usize,
    /// Neighbouring segments on each side along the same yarn that never touch.
    pub exclusion: usize,
    /// Contact radius factor f (contact distance 2 f r).
    pub radius_factor: f64,
}

impl Default for ContactForm {
    fn default() -> Self {
        ContactForm {
            quadrature: 4,
            exclusion: 3,
            radius_factor: 1.0,
        }
    }
}

/// Gradients of each term per unit parameter at a pattern's stored state (θ rows multiplied by 1/r, i.e. with
/// respect to r·θ).
#[derive(Clone, Debug)]
pub struct GradientParts {
    /// a_s: gradient of the stretching term per unit Y.
    pub stretch: DVector<f64>,
    /// a_b: gradient of the bending term per unit γY.
    pub bend: DVector<f64>,
    /// a_t: gradient of the twisting term per unit γG.
    pub twist: DVector<f64>,
    /// a_c: gradient of the contact term per unit k_c.
    pub contact: DVector<f64>,
    /// Number of position rows (the rest are angle rows).
    pub n_positions: usize,
    /// Number of contact pairs with a non-zero energy.
    pub active_pairs: usize,
}

/// The per-unit gradients of `pattern` at its stored state.
pub fn gradient_parts(
    pattern: &Pattern,
    form: &ContactForm,
) -> Result<GradientParts, ContactError> {
    let unit = YarnMaterial {
        young: 1.0,
        shear: 1.0,
        bend_twist_factor: 1.0,
        radius: pattern.radius,
        density: 0.0,
        contact_stiffness: 1.0,
        contact_quadrature: form.quadrature,
        contact_exclusion: form.exclusion,
        contact_radius_factor: form.radius_factor,
        bending: crate::rod::BendingForm::Tan,
    };
    let state = RodState::from_pattern(pattern);
    let mut tile = Tile::new(pattern, &unit);
    tile.contact_radius = pattern.radius * form.radius_factor;
    tile.update_contacts(&state.positions, 0.5 * pattern.radius)?;
    let y = Tile::dofs_of(&state);
    let n = pattern.len();
    let part = |terms: Terms| -> Result<(DVector<f64>, f64), ContactError> {
        let r = tile.evaluate(&state, &y, Want::Gradient, &terms)?;
        let mut g = r.gradient.expect("gradient requested");
        for v in g.iter_mut().skip(3 * n) {
            *v /= pattern.radius;
        }
        Ok((g, r.parts.total()))
    };
    let only = |s, b, t, c| Terms {
        stretch: s,
        bend: b,
        twist: t,
        contact: c,
    };
    let (stretch, _) = part(only(1.0, 0.0, 0.0, 0.0))?;
    let (bend, _) = part(only(0.0, 1.0, 0.0, 0.0))?;
    let (twist, _) = part(only(0.0, 0.0, 1.0, 0.0))?;
    let (contact, _) = part(only(0.0, 0.0, 0.0, 1.0))?;
    let active_pairs = tile.active_contact_pairs(&y)?;
    Ok(GradientParts {
        stretch,
        bend,
        twist,
        contact,
        n_positions: 3 * n,
        active_pairs,
    })
}

/// Stiffness parameters of a calibration (Y fixed by the caller).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stiffness {
    /// Young's modulus Y (Pa).
    pub young: f64,
    /// γY
    pub bend: f64,
    /// γG
    pub twist: f64,
    /// k_c
    pub contact: f64,
}

impl Stiffness {
    /// From the physical parameters.
    pub fn from_material(m: &YarnMaterial) -> Self {
        Stiffness {
            young: m.young,
            bend: m.bend_twist_factor * m.young,
            twist: m.bend_twist_factor * m.shear,
            contact: m.contact_stiffness,
        }
    }
    /// The bending-twisting factor γ = (γY) / Y.
    pub fn gamma(&self) -> f64 {
        self.bend / self.young
    }
    /// The ratio G/Y = (γG) / (γY).
    pub fn shear_over_young(&self) -> f64 {
        self.twist / self.bend
    }
}

/// Relative residual ‖∇E‖ / ‖∇E_rods‖ of one pattern for given stiffnesses (see the module documentation).
pub fn residual(parts: &GradientParts, k: &Stiffness) -> f64 {
    let s = &parts.stretch * k.young;
    let b = &parts.bend * k.bend;
    let t = &parts.twist * k.twist;
    let c = &parts.contact * k.contact;
    let total = &s + &b + &t + &c;
    total.norm() / (s.norm_squared() + b.norm_squared() + t.norm_squared()).sqrt()
}

/// Residual of the angle rows only (twisting against bending; stretching and contact do not act on θ).
pub fn angle_residual(parts: &GradientParts, k: &Stiffness) -> f64 {
    let n = parts.n_positions;
    let b = parts.bend.rows(n, parts.bend.len() - n) * k.bend;
    let t = parts.twist.rows(n, parts.twist.len() - n) * k.twist;
    (&b + &t).norm() / (b.norm_squared() + t.norm_squared()).sqrt()
}

/// G/Y from the angle rows alone: the ratio γG/γY minimising ‖γY a_b^θ + γG a_t^θ‖.
pub fn shear_ratio_from_angles(parts: &GradientParts) -> f64 {
    let n = parts.n_positions;
    let b = parts.bend.rows(n, parts.bend.len() - n);
    let t = parts.twist.rows(n, parts.twist.len() - n);
    -b.dot(&t) / t.norm_squared()
}

/// The best non-negative (γY, γG, k_c) for a set of patterns at fixed Y (sum of squared residual forces, each
/// pattern's rows scaled by its own rod-force size at the default parameters so patterns count equally).
/// `use_contact = false` fits the rod parameters with k_c = 0.
pub fn fit(parts: &[&GradientParts], young: f64, use_contact: bool) -> Stiffness {
    let ncol = if use_contact { 3 } else { 2 };
    let mut ata = DMatrix::<f64>::zeros(ncol, ncol);
    let mut atb = DVector::<f64>::zeros(ncol);
    let default = Stiffness::from_material(&YarnMaterial::default());
    for p in parts {
        let w = {
            let s = p.stretch.norm_squared() * default.young.powi(2)
                + p.bend.norm_squared() * default.bend.powi(2)
                + p.twist.norm_squared() * default.twist.powi(2);
            1.0 / s
        };
        let cols: Vec<&DVector<f64>> = if use_contact {
            vec![&p.bend, &p.twist, &p.contact]
        } else {
            vec![&p.bend, &p.twist]
        };
        for i in 0..ncol {
            atb[i] -= w * cols[i].dot(&p.stretch) * young;
            for j in 0..ncol {
                ata[(i, j)] += w * cols[i].dot(cols[j]);
            }
        }
    }
    // non-negative least squares by enumerating the active sets (at most 3 unknowns)
    let mut best: Option<(f64, DVector<f64>)> = None;
    for mask in 1u32..(1 << ncol) {
        let idx: Vec<usize> = (0..ncol).filter(|i| mask & (1 << i) != 0).collect();
        let a = DMatrix::from_fn(idx.len(), idx.len(), |i, j| ata[(idx[i], idx[j])]);
        let b = DVector::from_fn(idx.len(), |i, _| atb[idx[i]]);
        let Some(sol) = a.lu().solve(&b) else {
            continue;
        };
        if sol.iter().any(|&v| v < 0.0) {
            continue;
        }
        let mut x = DVector::zeros(ncol);
        for (k, &i) in idx.iter().enumerate() {
            x[i] = sol[k];
        }
        // objective up to a constant: xᵀAx − 2bᵀx
        let obj = (x.transpose() * &ata * &x)[0] - 2.0 * atb.dot(&x);
        if best.as_ref().is_none_or(|(o, _)| obj < *o) {
            best = Some((obj, x));
        }
    }
    let x = best.map(|b| b.1).unwrap_or_else(|| DVector::zeros(ncol));
    Stiffness {
        young,
        bend: x[0],
        twist: x[1],
        contact: if use_contact { x[2] } else { 0.0 },
    }
}

/// One row of the calibration table: a pattern under one contact form.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CalibrationRow {
    /// The pattern's name.
    pub pattern: String,
    /// Gauss–Legendre points per segment Q of the contact quadrature.
    pub quadrature: usize,
    /// Contact exclusion along the yarn (segments on each side).
    pub exclusion: usize,
    /// Contact radius factor f.
    pub radius_factor: f64,
    /// Contact pairs with non-zero energy at the stored state.
    pub active_pairs: usize,
    /// G/Y from the angle rows alone.
    pub shear_over_young_from_angles: f64,
    /// ‖∇E‖/‖∇E_rods‖ at the given (default) parameters.
    pub residual_default: f64,
    /// Residual with the joint fit over the calibration set.
    pub residual_joint: f64,
    /// The best parameters for this pattern alone (Y fixed) and the residual they reach.
    pub own_gamma: f64,
    /// The best G/Y for this pattern alone.
    pub own_shear_over_young: f64,
    /// The best k_c (J/m²) for this pattern alone.
    pub own_contact_stiffness: f64,
    /// The residual ‖∇E‖/‖∇E_rods‖ those reach.
    pub residual_own: f64,
    /// The best residual without contact (k_c = 0).
    pub residual_own_no_contact: f64,
}

/// The joint calibration over a set of patterns and the per-pattern rows.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Calibration {
    /// Gauss–Legendre points per segment Q of the contact quadrature.
    pub quadrature: usize,
    /// Contact exclusion along the yarn (segments on each side).
    pub exclusion: usize,
    /// Contact radius factor f.
    pub radius_factor: f64,
    /// Young's modulus Y (Pa), fixed.
    pub young: f64,
    /// The jointly fitted factor γ.
    pub gamma: f64,
    /// The jointly fitted G/Y.
    pub shear_over_young: f64,
    /// The jointly fitted contact stiffness k_c (J/m²).
    pub contact_stiffness: f64,
    /// One row per reported pattern.
    pub rows: Vec<CalibrationRow>,
}

/// Calibrate on `fit_set` (pattern names) for one contact form and report every pattern of `patterns`, with the
/// default parameters of `material` as the "default" column.
pub fn calibrate(
    patterns: &[(String, Pattern)],
    fit_set: &[&str],
    form: &ContactForm,
    material: &YarnMaterial,
) -> Result<Calibration, ContactError> {
    let parts: Vec<GradientParts> = patterns
        .iter()
        .map(|(_, p)| gradient_parts(p, form))
        .collect::<Result<_, _>>()?;
    let chosen: Vec<&GradientParts> = patterns
        .iter()
        .zip(&parts)
        .filter(|((name, _), _)| fit_set.contains(&name.as_str()))
        .map(|(_, g)| g)
        .collect();
    let young = material.young;
    let joint = fit(&chosen, young, true);
    let default = Stiffness::from_material(material);
    let rows = patterns
        .iter()
        .zip(&parts)
        .map(|((name, _), g)| {
            let own = fit(&[g], young, true);
            let own_nc = fit(&[g], young, false);
            CalibrationRow {
                pattern: name.clone(),
                quadrature: form.quadrature,
                exclusion: form.exclusion,
                radius_factor: form.radius_factor,
                active_pairs: g.active_pairs,
                shear_over_young_from_angles: shear_ratio_from_angles(g),
                residual_default: residual(g, &default),
                residual_joint: residual(g, &joint),
                own_gamma: own.gamma(),
                own_shear_over_young: own.shear_over_young(),
                own_contact_stiffness: own.contact,
                residual_own: residual(g, &own),
                residual_own_no_contact: residual(g, &own_nc),
            }
        })
        .collect();
    Ok(Calibration {
        quadrature: form.quadrature,
        exclusion: form.exclusion,
        radius_factor: form.radius_factor,
        young,
        gamma: joint.gamma(),
        shear_over_young: joint.shear_over_young(),
        contact_stiffness: joint.contact,
        rows,
    })
}

/// The periods at which the pattern's stored state is closest to an equilibrium for stiffnesses `k` (the in-plane
/// minimum of Algorithm C1 step 3, restricted to the periods): Gauss–Newton on p ↦ ∇E(p) with a central
/// finite-difference Jacobian (relative step 1e-7), starting from the pattern's periods. Used to correct a
/// pattern whose stored periods are inconsistent with its periodic edges (basket.pyp).
pub fn equilibrium_periods(
    pattern: &Pattern,
    form: &ContactForm,
    k: &Stiffness,
) -> Result<[f64; 2], ContactError> {
    let force = |periods: [f64; 2]| -> Result<DVector<f64>, ContactError> {
        let mut p = pattern.clone();
        p.periods = periods;
        let g = gradient_parts(&p, form)?;
        Ok(&g.stretch * k.young + &g.bend * k.bend + &g.twist * k.twist + &g.contact * k.contact)
    };
    let mut per = pattern.periods;
    for _ in 0..8 {
        let f0 = force(per)?;
        let mut jac = DMatrix::<f64>::zeros(f0.len(), 2);
        for c in 0..2 {
            let h = 1e-7 * per[c];
            let (mut a, mut b) = (per, per);
            a[c] += h;
            b[c] -= h;
            jac.set_column(c, &((force(a)? - force(b)?) / (2.0 * h)));
        }
        let jtj = jac.transpose() * &jac;
        let step = jtj.lu().solve(&(-(jac.transpose() * &f0)));
        let Some(step) = step else { break };
        per = [per[0] + step[0], per[1] + step[1]];
        if step.norm() < 1e-12 * (per[0] + per[1]) {
            break;
        }
    }
    Ok(per)
}
