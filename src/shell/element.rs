//! Triangle energy E_Δ = A·k·ψ(S z(q)), its gradient and Hessian (`docs/cloth-simulator.md`, "Per triangle"), with the
//! scene's modelling choices and the three Hessian options of the note.
//!
//! - k: stiffness multiplier; S = diag(1, 1, 1, β, β, β) with β the bending scale (multiplies II before ψ), as in
//!   the original's config.
//! - "Model only what a scene requires" ([`ElementModel::new`]): without bending, the hinges are not evaluated
//!   at all (II ≡ 0); with only 1D terms (the original's `only1D`) or in-plane terms only, the material is reduced
//!   to those terms once, so ψ evaluates only them.
//! - ∇E = A k Jᵀ S ∇ψ, ∇²E = A k (Jᵀ S ∇²ψ S J + Σ_k (S∇ψ)_k ∇²z_k).
//! - With a fold barrier ([`FoldBarrier`], [`super::fold`]; only with bending) E_Δ also has Σ_i k_f (A/3) β(θ_i)
//!   over its hinges, with ∇ = Σ c β′ ∇θ_i and ∇² = Σ c (β″ ∇θ_i ∇θ_iᵀ + β′ ∇²θ_i); option (b) keeps only the
//!   PSD part c β″ ∇θ_i ∇θ_iᵀ (β″ ≥ 0), option (a) projects the sum.
//! - With a collapse barrier ([`CollapseBarrier`]) its density k_c β_J(J(z)) is added to ψ before the chain rule,
//!   so it takes every path ψ takes (projection of the 6×6 block for (b)).
//!
//! PSD options ([`Psd`]): (a) eigen-projection of the 18×18 local Hessian, eigenvalues clamped at 1e-8 like the
//! original; (b) projection of the 6×6 ∇²ψ only, keeping of the Σ ∂ψ/∂z_k ∇²z_k term only the stretch parts whose
//! weight is ≥ 0 (∇²‖F₀‖ and ∇²‖F₁‖ are PSD because ‖F_c‖ is convex and F is linear in q: a cheap sufficient test
//! for "only where it is PSD"); (c) the exact Hessian, the solver adding a global diagonal shift when the
//! factorisation fails.

use super::fold::{CollapseBarrier, FoldBarrier};
use super::strain::{
    hinge_angles_reference, strain, strain_angles, RestTriangle, StrainChain, NDOF,
};
use crate::material::Material;
use nalgebra::{SMatrix, SymmetricEigen};

/// How the local Hessian is made positive semi-definite (`docs/cloth-simulator.md`, options (a)–(c)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Psd {
    /// (a) eigen-projection of the 18×18 local Hessian
    Full,
    /// (b) projection of ∇²ψ (6×6) plus the PSD stretch parts of Σ ∂ψ/∂z_k ∇²z_k
    Psi,
    /// (c) exact Hessian; global diagonal shift on factorisation failure
    None,
}

/// Eigenvalue floor of option (a), as in the original.
pub const EIGEN_FLOOR: f64 = 1e-8;

/// Which parts of ψ a scene needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelFlags {
    /// evaluate the bending strains (hinges); false: II ≡ 0
    pub bending: bool,
    /// keep only the 1D terms of ψ (the original's `only1D`)
    pub only_1d: bool,
    /// keep only the in-plane terms (s_x, s_a, s_y and their 2D couplings); implies no bending
    pub in_plane_only: bool,
    /// stiffness multiplier k
    pub stiffness: f64,
    /// bending scale β (multiplies II before ψ)
    pub bending_scale: f64,
    /// the fold barrier (acts only with bending)
    pub fold: Option<FoldBarrier>,
    /// the collapse barrier
    pub collapse: Option<CollapseBarrier>,
}

impl Default for ModelFlags {
    fn default() -> Self {
        ModelFlags {
            bending: true,
            only_1d: false,
            in_plane_only: false,
            stiffness: 1.0,
            bending_scale: 1.0,
            fold: None,
            collapse: None,
        }
    }
}

/// The per-triangle model: reduced material, multipliers, PSD option.
#[derive(Clone, Debug)]
pub struct ElementModel {
    /// the material, reduced to the terms the scene needs
    pub material: Material,
    /// whether the bending strains are evaluated
    pub bending: bool,
    /// stiffness multiplier k
    pub stiffness: f64,
    /// bending scale β (multiplies II before ψ)
    pub bending_scale: f64,
    /// how the element Hessians are made positive semi-definite
    pub psd: Psd,
    /// the fold barrier; `None` without bending
    pub fold: Option<FoldBarrier>,
    /// the collapse barrier
    pub collapse: Option<CollapseBarrier>,
}

impl ElementModel {
    /// Reduce `material` to what `flags` require (see the module documentation).
    pub fn new(material: &Material, flags: &ModelFlags, psd: Psd) -> Self {
        let mut m = material.clone();
        let bending = flags.bending && !flags.in_plane_only;
        if flags.only_1d {
            m.terms2d.clear();
        }
        if !bending {
            m.terms1d.retain(|t| t.strain.is_in_plane());
            m.terms2d.retain(|t| t.strains[1].is_in_plane());
        }
        ElementModel {
            material: m,
            bending,
            stiffness: flags.stiffness,
            bending_scale: flags.bending_scale,
            psd,
            fold: flags.fold.filter(|_| bending),
            collapse: flags.collapse,
        }
    }

    #[inline]
    pub(super) fn flaps(&self, flaps: [bool; 3]) -> [bool; 3] {
        if self.bending {
            flaps
        } else {
            [false; 3]
        }
    }

    /// The strain ψ receives: S z.
    #[inline]
    pub(super) fn scaled(&self, z: &[f64; 6]) -> [f64; 6] {
        let b = self.bending_scale;
        [z[0], z[1], z[2], b * z[3], b * z[4], b * z[5]]
    }

    /// ψ(S z) and its derivatives in z-space before the chain rule (S applied by [`Self::weights`]), plus the
    /// collapse barrier's density; `None` when a triangle has collapsed (J ≤ 0).
    #[inline]
    pub(super) fn psi(&self, z: &[f64; 6]) -> Option<crate::material::PsiVgh> {
        let mut p = self.material.eval(&self.scaled(z));
        if let Some(c) = &self.collapse {
            c.add_to(z, &mut p.value, &mut p.grad, &mut p.hess)?;
        }
        Some(p)
    }

    /// ψ(S z) plus the collapse barrier's density; `None` when a triangle has collapsed.
    #[inline]
    fn psi_value(&self, z: &[f64; 6]) -> Option<f64> {
        let v = self.material.value(&self.scaled(z));
        match &self.collapse {
            Some(c) => Some(v + c.value(z)?),
            None => Some(v),
        }
    }

    /// The strain z the model uses (bending zero when off), `None` on a degenerate configuration.
    pub fn strain(
        &self,
        q: &[f64; NDOF],
        rest: &RestTriangle,
        flaps: [bool; 3],
    ) -> Option<[f64; 6]> {
        strain(q, rest, self.flaps(flaps))
    }

    /// E_Δ only; `None` on a degenerate configuration.
    pub fn energy(&self, q: &[f64; NDOF], rest: &RestTriangle, flaps: [bool; 3]) -> Option<f64> {
        let flaps = self.flaps(flaps);
        let mut e;
        if let Some(fold) = &self.fold {
            let (z, angles) = strain_angles(q, rest, flaps)?;
            e = rest.area * self.stiffness * self.psi_value(&z)?;
            for i in (0..3).filter(|&i| flaps[i]) {
                e += fold.weight(rest.area) * fold.profile(angles[i])?[0];
            }
        } else {
            let z = strain(q, rest, flaps)?;
            e = rest.area * self.stiffness * self.psi_value(&z)?;
        }
        e.is_finite().then_some(e)
    }

    /// Add the fold barrier's energy, gradient and (with `hess`) Hessian, the curvature term β′ ∇²θ only when
    /// `curvature`; `None` when a hinge is folded flat (infinite energy).
    fn add_fold(
        &self,
        ch: &StrainChain,
        area: f64,
        grad: &mut [f64; NDOF],
        hess: Option<(&mut [[f64; NDOF]; NDOF], bool)>,
    ) -> Option<f64> {
        let Some(fold) = &self.fold else {
            return Some(0.0);
        };
        let mut active = [None; 3];
        for (i, a) in active.iter_mut().enumerate() {
            if let Some(theta) = ch.hinge_angle(i) {
                let p = fold.profile(theta)?;
                if p[1] != 0.0 || p[2] != 0.0 {
                    *a = Some(p);
                }
            }
        }
        if active.iter().all(Option::is_none) {
            return Some(0.0);
        }
        let c = fold.weight(area);
        let mut e = 0.0;
        let mut scratch = [[0.0; NDOF]; NDOF];
        let (h, curvature) = match hess {
            Some((h, curv)) => (h, curv),
            None => (&mut scratch, false),
        };
        for (i, a) in active.iter().enumerate() {
            if let Some([b, b1, b2]) = *a {
                e += c * b;
                ch.add_hinge_angle_terms(i, c * b1, c * b2, curvature, grad, h);
            }
        }
        Some(e)
    }

    /// E_Δ and ∇E_Δ (written to `grad`).
    pub fn energy_gradient(
        &self,
        q: &[f64; NDOF],
        rest: &RestTriangle,
        flaps: [bool; 3],
        grad: &mut [f64; NDOF],
    ) -> Option<(f64, [f64; 6])> {
        let ch = StrainChain::new(q, rest, self.flaps(flaps))?;
        let p = self.psi(&ch.z)?;
        let (_, w) = self.weights(rest, &p.grad);
        for j in 0..NDOF {
            grad[j] = (0..6).map(|k| w[k] * ch.jac[k][j]).sum();
        }
        let e = rest.area * self.stiffness * p.value + self.add_fold(&ch, rest.area, grad, None)?;
        e.is_finite().then_some((e, ch.z))
    }

    /// c = A k and the weights A k S ∇ψ.
    #[inline]
    pub(super) fn weights(&self, rest: &RestTriangle, g: &[f64; 6]) -> (f64, [f64; 6]) {
        let c = rest.area * self.stiffness;
        let b = self.bending_scale;
        (
            c,
            [
                c * g[0],
                c * g[1],
                c * g[2],
                c * b * g[3],
                c * b * g[4],
                c * b * g[5],
            ],
        )
    }

    /// E_Δ, ∇E_Δ and the (optionally projected) ∇²E_Δ; also returns z. `None` on a degenerate configuration.
    pub fn energy_gradient_hessian(
        &self,
        q: &[f64; NDOF],
        rest: &RestTriangle,
        flaps: [bool; 3],
        grad: &mut [f64; NDOF],
        hess: &mut [[f64; NDOF]; NDOF],
    ) -> Option<(f64, [f64; 6])> {
        let ch = StrainChain::new(q, rest, self.flaps(flaps))?;
        let p = self.psi(&ch.z)?;
        let (c, w) = self.weights(rest, &p.grad);
        let jac = &ch.jac;
        for j in 0..NDOF {
            grad[j] = (0..6).map(|k| w[k] * jac[k][j]).sum();
        }
        // option (a) projects the sum of the material's and the barrier's Hessians
        let base = match self.psd {
            Psd::Full if self.fold_active(&ch) => Psd::None,
            psd => psd,
        };
        self.hessian_into(&ch, &p, c, &w, base, hess);
        let e = c * p.value + self.fold_into(&ch, rest.area, self.psd, grad, hess)?;
        e.is_finite().then_some((e, ch.z))
    }

    /// E_Δ, ∇E_Δ, the exact ∇²E_Δ (`exact`) and the Hessian of the model's PSD option (`projected`; equal to
    /// `exact` for [`Psd::None`]) from one evaluation of the strain chain and ψ.
    pub fn energy_gradient_hessians(
        &self,
        q: &[f64; NDOF],
        rest: &RestTriangle,
        flaps: [bool; 3],
        grad: &mut [f64; NDOF],
        exact: &mut [[f64; NDOF]; NDOF],
        projected: &mut [[f64; NDOF]; NDOF],
    ) -> Option<(f64, [f64; 6])> {
        let ch = StrainChain::new(q, rest, self.flaps(flaps))?;
        let p = self.psi(&ch.z)?;
        let (c, w) = self.weights(rest, &p.grad);
        for j in 0..NDOF {
            grad[j] = (0..6).map(|k| w[k] * ch.jac[k][j]).sum();
        }
        self.hessian_into(&ch, &p, c, &w, Psd::None, exact);
        let mut g2 = *grad;
        let ef = self.fold_into(&ch, rest.area, Psd::None, grad, exact)?;
        match self.psd {
            Psd::None => *projected = *exact,
            Psd::Full => {
                *projected = *exact;
                project18(projected);
            }
            Psd::Psi => {
                self.hessian_into(&ch, &p, c, &w, Psd::Psi, projected);
                self.fold_into(&ch, rest.area, Psd::Psi, &mut g2, projected)?;
            }
        }
        let e = c * p.value + ef;
        e.is_finite().then_some((e, ch.z))
    }

    /// Whether a hinge is folded beyond the barrier's threshold.
    pub(super) fn fold_active(&self, ch: &StrainChain) -> bool {
        self.fold
            .is_some_and(|f| (0..3).any(|i| ch.hinge_angle(i).is_some_and(|t| t.abs() > f.angle)))
    }

    /// The fold barrier's terms added to a gradient and a local Hessian: the exact terms for (c), the PSD part
    /// for (b); for (a) the exact terms, then the projection of the sum (the caller passes the unprojected
    /// material Hessian when a hinge is beyond the threshold). Returns the barrier's energy; `None` when a hinge
    /// is folded flat.
    fn fold_into(
        &self,
        ch: &StrainChain,
        area: f64,
        psd: Psd,
        grad: &mut [f64; NDOF],
        hess: &mut [[f64; NDOF]; NDOF],
    ) -> Option<f64> {
        let e = self.add_fold(ch, area, grad, Some((hess, psd != Psd::Psi)))?;
        if psd == Psd::Full && e != 0.0 {
            project18(hess);
        }
        Some(e)
    }

    /// The local Hessian for PSD option `psd` from the chain, ψ's derivatives, c = A k and the weights w.
    fn hessian_into(
        &self,
        ch: &StrainChain,
        p: &crate::material::PsiVgh,
        c: f64,
        w: &[f64; 6],
        psd: Psd,
        hess: &mut [[f64; NDOF]; NDOF],
    ) {
        let jac = &ch.jac;
        // H6 = c S ∇²ψ S (projected for option (b))
        let s = [
            1.0,
            1.0,
            1.0,
            self.bending_scale,
            self.bending_scale,
            self.bending_scale,
        ];
        let mut h6 = [[0.0; 6]; 6];
        for a in 0..6 {
            for b in 0..6 {
                h6[a][b] = c * s[a] * s[b] * p.hess[a][b];
            }
        }
        if psd == Psd::Psi {
            project6(&mut h6);
        }
        // T = H6 J (6×18), then Jᵀ T; columns of J that are zero (missing flaps) are skipped
        let mut live = [true; NDOF];
        for j in 0..NDOF {
            live[j] = (0..6).any(|k| jac[k][j] != 0.0);
        }
        let mut t = [[0.0; NDOF]; 6];
        for a in 0..6 {
            for j in 0..NDOF {
                if live[j] {
                    t[a][j] = (0..6).map(|b| h6[a][b] * jac[b][j]).sum();
                }
            }
        }
        for i in 0..NDOF {
            for j in 0..NDOF {
                hess[i][j] = if live[i] && live[j] {
                    (0..6).map(|a| jac[a][i] * t[a][j]).sum()
                } else {
                    0.0
                };
            }
        }
        match psd {
            Psd::Psi => {
                let w2 = [w[0].max(0.0), 0.0, w[2].max(0.0), 0.0, 0.0, 0.0];
                ch.add_weighted_hessian(&w2, hess);
            }
            _ => ch.add_weighted_hessian(w, hess),
        }
        if psd == Psd::Full {
            project18(hess);
        }
    }
}

/// Clamp the eigenvalues of a symmetric 6×6 matrix at 0.
/// A Cholesky attempt on the rows that are not identically zero first: when it succeeds the matrix is positive
/// semi-definite and stays as it is, without the eigen-decomposition.
fn project6(h: &mut [[f64; 6]; 6]) {
    if psd6_by_cholesky(h) {
        return;
    }
    let sym = |i: usize, j: usize| 0.5 * (h[i][j] + h[j][i]);
    let m = SMatrix::<f64, 6, 6>::from_fn(sym);
    let eig = SymmetricEigen::new(m);
    if eig.eigenvalues.iter().all(|&l| l >= 0.0) {
        return;
    }
    let l = eig.eigenvalues.map(|l| l.max(0.0));
    let r =
        eig.eigenvectors * SMatrix::<f64, 6, 6>::from_diagonal(&l) * eig.eigenvectors.transpose();
    for i in 0..6 {
        for j in 0..6 {
            h[i][j] = r[(i, j)];
        }
    }
}

/// Clamp the eigenvalues of the symmetric 18×18 local Hessian at [`EIGEN_FLOOR`] (option (a)). A Cholesky
/// attempt on H + floor·I first: when it succeeds every eigenvalue is above −floor (an element Hessian always
/// has the six-dimensional null space of rigid motions, so "above +floor" never holds), and H is returned
/// unchanged (most stretched triangles: at most a 2e-8 difference from the original's clamp, in null-space
/// directions); else H + Σ_{λ_k < floor} (floor − λ_k) v_k v_kᵀ from the eigen-decomposition.
pub fn project18(h: &mut [[f64; NDOF]; NDOF]) {
    let mut m = SMatrix::<f64, NDOF, NDOF>::from_fn(|i, j| 0.5 * (h[i][j] + h[j][i]));
    // columns and rows of unused (missing-flap) dofs are zero: keep them out of the test
    let live: Vec<usize> = (0..NDOF)
        .filter(|&i| (0..NDOF).any(|j| m[(i, j)] != 0.0))
        .collect();
    if cholesky_succeeds::<NDOF>(|i, j| m[(i, j)], &live, EIGEN_FLOOR) {
        return;
    }
    for i in 0..NDOF {
        for j in 0..NDOF {
            h[i][j] = m[(i, j)];
        }
    }
    let eig = SymmetricEigen::new(std::mem::take(&mut m));
    for k in 0..NDOF {
        let l = eig.eigenvalues[k];
        if l < EIGEN_FLOOR {
            let d = EIGEN_FLOOR - l;
            let v = eig.eigenvectors.column(k);
            for i in 0..NDOF {
                let vi = d * v[i];
                for j in 0..NDOF {
                    h[i][j] += vi * v[j];
                }
            }
        }
    }
}

/// Whether [`project6`]'s Cholesky test leaves the symmetric part of `h` as it is (the factorisation over the rows
/// that are not identically zero succeeds).
pub(super) fn psd6_by_cholesky(h: &[[f64; 6]; 6]) -> bool {
    let sym = |i: usize, j: usize| 0.5 * (h[i][j] + h[j][i]);
    let mut live = [0; 6];
    let mut n = 0;
    for i in 0..6 {
        if (0..6).any(|j| h[i][j] != 0.0 || h[j][i] != 0.0) {
            live[n] = i;
            n += 1;
        }
    }
    cholesky_succeeds::<6>(sym, &live[..n], 0.0)
}

/// Whether the Cholesky factorisation of m + shift·I restricted to the rows and columns `live` succeeds (every
/// pivot positive): then every eigenvalue of m on those rows is above −shift.
fn cholesky_succeeds<const N: usize>(
    m: impl Fn(usize, usize) -> f64,
    live: &[usize],
    shift: f64,
) -> bool {
    let n = live.len();
    let mut l = [[0.0; N]; N];
    for a in 0..n {
        for b in 0..=a {
            let mut s = m(live[a], live[b]) + if a == b { shift } else { 0.0 };
            for k in 0..b {
                s -= l[a][k] * l[b][k];
            }
            if a == b {
                if s.is_nan() || s <= 0.0 {
                    return false;
                }
                l[a][a] = s.sqrt();
            } else {
                l[a][b] = s / l[b][b];
            }
        }
    }
    true
}

/// Generic reference twin of E_Δ: A k ψ(S z(q)) from the reference strain chain and the reference material.
pub fn energy_reference<D: crate::real::Real>(
    model: &ElementModel,
    q: &[D],
    rest: &RestTriangle,
    flaps: [bool; 3],
) -> D {
    let z = super::strain::strain_reference(q, rest, model.flaps(flaps));
    let b = model.bending_scale;
    let zs = [
        z[0].clone(),
        z[1].clone(),
        z[2].clone(),
        z[3].clone() * b,
        z[4].clone() * b,
        z[5].clone() * b,
    ];
    let mut psi = model.material.reference(&zs);
    if let Some(c) = &model.collapse {
        psi += c.reference(&z);
    }
    let mut e = psi * (rest.area * model.stiffness);
    if let Some(fold) = &model.fold {
        for theta in hinge_angles_reference(q, model.flaps(flaps))
            .into_iter()
            .flatten()
        {
            e += fold.reference(theta) * fold.weight(rest.area);
        }
    }
    e
}
