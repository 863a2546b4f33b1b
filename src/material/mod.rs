//! The spline material ψ(z) of the original method (`docs/material.md`, "Material ψ(z)"; file format in
//! `docs/material.md`, "Material JSON").
//!
//! z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁), σ the five strain scales, L = [[II₀₀, II₀₁], [II₀₁, II₁₁]]:
//!
//! ψ(z) = C₀ + Σ_{k≤2} f_k(z_k/σ_k) + [f₃(L/σ₃)]₀₀ + [f₄(L/σ₄)]₁₁
//!        + Σ_{(k,l), l≤2} f_kl(z_k/σ_k, z_l/σ_l) + Σ_(k,3) [f_k3(z_k/σ_k, L/σ₃)]₀₀ + Σ_(k,4) [f_k4(z_k/σ_k, L/σ₄)]₁₁
//!
//! with the matrix functions in divided-difference form ([`spectral`]). [`Material::eval`] is the fast path
//! (value, gradient, Hessian), [`Material::reference`] its generic twin for the derivative harness.

pub mod coefficients;
pub mod hermite;
pub mod json;
pub mod spectral;
pub mod synthetic;

pub use hermite::{Hermite1D, Hermite2D};
pub use json::MaterialError;

use crate::real::Real;
use hermite::{basis_piece, basis_weights, piece_from_index};
use spectral::spectral_00_reference;

use crate::strain::compact;
pub use crate::strain::{Strain6, StrainComponent};

/// A 1D term f_k of the material: k is its strain (the file's index k = 0…4: s_x, s_a, s_y, Π₀₀, Π₁₁).
#[derive(Clone, Debug)]
pub struct Term1D {
    /// the strain component k
    pub strain: StrainComponent,
    /// the spline f_k of z_k/σ_k (J/m²)
    pub spline: Hermite1D,
}

/// A 2D term f_kl of the material: strains (k, l), k in-plane, l after k.
#[derive(Clone, Debug)]
pub struct Term2D {
    /// the strain components (k, l)
    pub strains: [StrainComponent; 2],
    /// the spline f_kl of (z_k/σ_k, z_l/σ_l) (J/m²)
    pub spline: Hermite2D,
}

/// A spline material: the original's format plus anything else the file carried (kept for writing).
#[derive(Clone, Debug)]
pub struct Material {
    /// areal mass density ρ_A (kg/m²)
    pub density: f64,
    /// σ for k = 0..4
    pub strain_scale: [f64; 5],
    /// C₀
    pub constant: f64,
    /// the 1D terms f_k
    pub terms1d: Vec<Term1D>,
    /// the 2D terms f_kl
    pub terms2d: Vec<Term2D>,
    /// top-level keys other than density, strain scale and coeffs (e.g. "strain shift", "meta"), in file order
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// Largest admissible |z_k| / σ_k of [`Material::eval_checked`] (II₀₁ against σ₃ and σ₄): a thousand times
/// the fitted range (the originals' knots span |z/σ| ≤ 0.95). Beyond the knots ψ continues linearly (the
/// original's extrapolation), which means nothing physically a thousand ranges out; from about |z| = 1e150 the
/// spectral terms' squares overflow and ψ becomes NaN. With the coefficient limits of [`json`] every ψ, ∇ψ, ∇²ψ
/// inside this range is finite.
pub const MAX_NORMALISED_STRAIN: f64 = 1e3;

/// A strain outside a material's admissible range ([`Material::eval_checked`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MaterialStrainError {
    #[error("{component} = {} is not finite", compact(*value))]
    /// A strain component that is NaN or infinite.
    NotFinite {
        /// the component's name
        component: &'static str,
        /// its value
        value: f64,
    },
    #[error(
        "{component} = {} is outside the material's admissible range |{component}| ≤ {limit:e} \
         ({MAX_NORMALISED_STRAIN:e} strain scales σ = {scale})",
        compact(*value)
    )]
    /// A strain component beyond [`MAX_NORMALISED_STRAIN`] strain scales.
    OutOfRange {
        /// the component's name
        component: &'static str,
        /// its value
        value: f64,
        /// the largest admissible |z_k| (MAX_NORMALISED_STRAIN · σ_k)
        limit: f64,
        /// the strain scale σ_k
        scale: f64,
    },
}

/// ψ, ∇ψ and ∇²ψ at one strain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PsiVgh {
    /// ψ(z) (J/m²)
    pub value: f64,
    /// ∇ψ = ∂ψ/∂z (J/m² per unit strain; J/m per 1/m for the II components)
    pub grad: [f64; 6],
    /// ∇²ψ = ∂²ψ/∂z² (symmetric)
    pub hess: [[f64; 6]; 6],
}

impl Material {
    /// Fast ψ, ∇ψ, ∇²ψ at z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁).
    ///
    /// The in-plane terms add directly. The bending terms of each bending index kb (the 1D term and the 2D terms
    /// (k, kb)) share L/σ_kb, so their eigen-geometry is computed once and their derivatives are summed in the
    /// spectral variables ([`spectral::SpectralSum`]) before one chain rule to z per bending index.
    /// The Hessian is accumulated in its upper triangle and mirrored at the end.
    ///
    /// # Example
    ///
    /// ψ, ∇ψ and ∇²ψ of the default material at a stretched, sheared and bent strain: the gradient matches
    /// central differences of the value and the Hessian is symmetric.
    ///
    /// ```
    /// use hylc::material::synthetic::default_material;
    ///
    /// let m = default_material();
    /// // z = (s_x, s_a, s_y, II₀₀ [1/m], II₀₁ [1/m], II₁₁ [1/m])
    /// let z = [0.1, 0.2, -0.05, 20.0, 5.0, -10.0];
    /// let e = m.eval(&z);
    /// assert!(e.value.is_finite());
    /// for k in 0..6 {
    ///     let h = 1e-6 * z[k].abs().max(1.0);
    ///     let (mut zp, mut zm) = (z, z);
    ///     zp[k] += h;
    ///     zm[k] -= h;
    ///     let fd = (m.eval(&zp).value - m.eval(&zm).value) / (2.0 * h);
    ///     assert!((e.grad[k] - fd).abs() <= 1e-6 * (e.grad[k].abs() + 1.0), "∂ψ/∂z_{k}");
    ///     for l in 0..6 {
    ///         assert!((e.hess[k][l] - e.hess[l][k]).abs() <= 1e-12 * (e.hess[k][l].abs() + 1.0));
    ///     }
    /// }
    /// ```
    pub fn eval(&self, z: &[f64; 6]) -> PsiVgh {
        let inv = self.strain_scale.map(|s| 1.0 / s);
        let mut out = PsiVgh {
            value: self.constant,
            grad: [0.0; 6],
            hess: [[0.0; 6]; 6],
        };
        // (m, δ, b) of L/σ_kb; δ → −δ for the 11 component ([f(L)]₁₁ is [f(L)]₀₀ with δ → −δ)
        let eig = [3, 4].map(|kb| {
            let (iv, sgn) = (inv[kb], if kb == 3 { 1.0 } else { -1.0 });
            spectral::Eigen2::new(
                0.5 * iv * (z[3] + z[5]),
                0.5 * sgn * iv * (z[3] - z[5]),
                iv * z[4],
            )
        });
        let mut bend = [spectral::SpectralSum::default(); 2];
        let mut used = [false; 2];
        for t in &self.terms1d {
            let k = t.strain.index();
            if k <= 2 {
                let [f, f1, f2] = t.spline.eval2(z[k] * inv[k]);
                out.value += f;
                out.grad[k] += f1 * inv[k];
                out.hess[k][k] += f2 * inv[k] * inv[k];
            } else {
                bend[k - 3].add(&t.spline, &eig[k - 3], None);
                used[k - 3] = true;
            }
        }
        for t in &self.terms2d {
            // k0 is in-plane and k1 > k0 (the format's rule, checked on load)
            let (k0, k1) = (t.strains[0].index(), t.strains[1].index());
            let iu = inv[k0];
            let u = z[k0] * iu;
            if k1 <= 2 {
                let iv = inv[k1];
                let [f, fu, fv, fuu, fuv, fvv] = t.spline.eval2(u, z[k1] * iv);
                out.value += f;
                out.grad[k0] += fu * iu;
                out.grad[k1] += fv * iv;
                out.hess[k0][k0] += fuu * iu * iu;
                out.hess[k1][k1] += fvv * iv * iv;
                out.hess[k0][k1] += fuv * iu * iv;
            } else {
                bend[k1 - 3].add(&t.spline.at_u(u), &eig[k1 - 3], Some(k0));
                used[k1 - 3] = true;
            }
        }
        for g in 0..2 {
            if used[g] {
                self.add_bending(&mut out, &inv, g + 3, &bend[g].finish(&eig[g]));
            }
        }
        let h = &out.hess;
        PsiVgh {
            value: out.value,
            grad: out.grad,
            hess: std::array::from_fn(|i| std::array::from_fn(|j| h[i.min(j)][i.max(j)])),
        }
    }

    /// Add the summed bending terms of index `kb`, with derivatives in w = (m, δ, b) and u_k = z_k/σ_k, to ψ's
    /// z-derivatives (upper triangle). m = c (II₀₀ + II₁₁), δ = ±c (II₀₀ − II₁₁) with c = 1/2σ (minus for kb = 4),
    /// b = II₀₁/σ: a linear map R, so ∇_z = Rᵀ∇_w and ∇²_z = Rᵀ∇²_w R.
    #[inline(always)]
    fn add_bending(&self, out: &mut PsiVgh, inv: &[f64; 5], kb: usize, w: &spectral::SpectralW) {
        let ib = inv[kb];
        let c = 0.5 * ib;
        let sc = if kb == 3 { c } else { -c };
        let [gm, gd, gb] = w.g;
        let [hmm, hmd, hmb, hdd, hdb, hbb] = w.h;
        out.value += w.value;
        out.grad[3] += c * gm + sc * gd;
        out.grad[5] += c * gm - sc * gd;
        out.grad[4] += ib * gb;
        // II₀₀ and II₁₁ directions: R₃ = (c, sc, 0), R₅ = (c, −sc, 0); II₀₁: R₄ = (0, 0, 1/σ)
        let (cc, cs, ss) = (c * c * hmm, c * sc * hmd, sc * sc * hdd);
        out.hess[3][3] += cc + 2.0 * cs + ss;
        out.hess[3][5] += cc - ss;
        out.hess[5][5] += cc - 2.0 * cs + ss;
        out.hess[3][4] += ib * (c * hmb + sc * hdb);
        out.hess[4][5] += ib * (c * hmb - sc * hdb);
        out.hess[4][4] += ib * ib * hbb;
        for k in 0..3 {
            let iu = inv[k];
            let hu = &w.hu[k];
            out.grad[k] += iu * w.gu[k];
            out.hess[k][k] += iu * iu * w.huu[k];
            out.hess[k][3] += iu * (c * hu[0] + sc * hu[1]);
            out.hess[k][5] += iu * (c * hu[0] - sc * hu[1]);
            out.hess[k][4] += iu * ib * hu[2];
        }
    }

    /// The admissible range of the material: |z_k| ≤ [`MAX_NORMALISED_STRAIN`] σ_k for z = (s_x, s_a, s_y, II₀₀,
    /// II₀₁, II₁₁), II₀₁ with the smaller of σ₃, σ₄ (it enters both bending terms).
    pub fn admissible_limits(&self) -> [f64; 6] {
        let sc = &self.strain_scale;
        [sc[0], sc[1], sc[2], sc[3], sc[3].min(sc[4]), sc[4]].map(|s| s * MAX_NORMALISED_STRAIN)
    }

    /// [`Material::eval`] after checking that z is finite and within [`Material::admissible_limits`]; the
    /// values are bitwise those of `eval`. The checked entry point for user-given strains (`hylc material`).
    pub fn eval_checked(&self, z: &[f64; 6]) -> Result<PsiVgh, MaterialStrainError> {
        let limits = self.admissible_limits();
        for (k, (&value, &limit)) in z.iter().zip(&limits).enumerate() {
            let component = Strain6::NAMES[k];
            if !value.is_finite() {
                return Err(MaterialStrainError::NotFinite { component, value });
            }
            if value.abs() > limit {
                return Err(MaterialStrainError::OutOfRange {
                    component,
                    value,
                    limit,
                    scale: limit / MAX_NORMALISED_STRAIN,
                });
            }
        }
        Ok(self.eval(z))
    }

    /// ψ alone (same arithmetic as [`Material::eval`]).
    pub fn value(&self, z: &[f64; 6]) -> f64 {
        self.eval(z).value
    }

    /// Generic reference twin of ψ(z), written from the formula with the Hermite basis evaluated directly.
    pub fn reference<D: Real>(&self, z: &[D]) -> D {
        let sc = &self.strain_scale;
        let mut psi = D::from(self.constant);
        // spectral variables of bending index kb: (m, δ, b), δ sign-flipped for the 11 component
        let mdb = |kb: usize| {
            let s = sc[kb];
            let sgn = if kb == 3 { 1.0 } else { -1.0 };
            (
                (z[3].clone() + z[5].clone()) / (2.0 * s),
                (z[3].clone() - z[5].clone()) * (sgn / (2.0 * s)),
                z[4].clone() / s,
            )
        };
        for t in &self.terms1d {
            let k = t.strain.index();
            if k <= 2 {
                psi += t.spline.reference(&(z[k].clone() / sc[k]));
            } else {
                let (m, delta, b) = mdb(k);
                let sp = &t.spline;
                let n = sp.t.len();
                psi += spectral_00_reference(
                    |x| sp.piece(x),
                    |x: &D| sp.reference(x),
                    |index| {
                        let bp = basis_piece(&sp.t, piece_from_index(n, index));
                        let i = bp_cell(n, index);
                        let data = [sp.p[i], sp.p[i + 1], sp.m[i], sp.m[i + 1]];
                        let cf = std::array::from_fn(|j| {
                            D::from((0..4).map(|k| bp.w[k][j] * data[k]).sum::<f64>())
                        });
                        (cf, bp.origin, bp.h)
                    },
                    &m,
                    &delta,
                    &b,
                );
            }
        }
        for t in &self.terms2d {
            let (k0, k1) = (t.strains[0].index(), t.strains[1].index());
            let u = z[k0].clone() / sc[k0];
            let sp = &t.spline;
            if k1 <= 2 {
                psi += sp.reference(&u, &(z[k1].clone() / sc[k1]));
            } else {
                let (m, delta, b) = mdb(k1);
                let (nu, nv) = (sp.tu.len(), sp.tv.len());
                let (iu, wu) = basis_weights(&sp.tu, &u);
                psi += spectral_00_reference(
                    |x| sp.v_piece(x),
                    |x: &D| sp.reference(&u, x),
                    |index| {
                        // f(u, ·) on v piece `index`: Σ_a wu_a(u) Σ_b data[a][b] · (basis b of v in t)
                        let bp = basis_piece(&sp.tv, piece_from_index(nv, index));
                        let j = bp_cell(nv, index);
                        let cf = std::array::from_fn(|jj| {
                            let mut acc = D::from(0.0);
                            for (a, wa) in wu.iter().enumerate() {
                                let (ia, du) =
                                    [(iu, false), (iu + 1, false), (iu, true), (iu + 1, true)][a];
                                let mut coef = 0.0;
                                for bb in 0..4 {
                                    let (ib, dv) =
                                        [(j, false), (j + 1, false), (j, true), (j + 1, true)][bb];
                                    let arr = match (du, dv) {
                                        (false, false) => &sp.p,
                                        (true, false) => &sp.mu,
                                        (false, true) => &sp.mv,
                                        (true, true) => &sp.muv,
                                    };
                                    coef += arr[ib * nu + ia] * bp.w[bb][jj];
                                }
                                acc += wa.clone() * coef;
                            }
                            acc
                        });
                        (cf, bp.origin, bp.h)
                    },
                    &m,
                    &delta,
                    &b,
                );
            }
        }
        psi
    }

    /// Distance (in z units, any single component) to the nearest point where ψ is not C³: a knot of a 1D or 2D
    /// term along an in-plane axis, or an eigenvalue of L/σ on a bending knot. Eigenvalues move at most as fast as
    /// the entries of L (Weyl), and L₀₁ enters twice, hence the factor ½ for the bending terms.
    pub fn kink_distance(&self, z: &[f64; 6]) -> f64 {
        let sc = &self.strain_scale;
        let near = |t: &[f64], x: f64| {
            t.iter()
                .map(|k| (k - x).abs())
                .fold(f64::INFINITY, f64::min)
        };
        let eig = |kb: usize| {
            let s = sc[kb];
            let m = (z[3] + z[5]) / (2.0 * s);
            let d = (((z[3] - z[5]) / (2.0 * s)).powi(2) + (z[4] / s).powi(2)).sqrt();
            (m + d, m - d, s)
        };
        let mut dist = f64::INFINITY;
        for t in &self.terms1d {
            let k = t.strain.index();
            if k <= 2 {
                dist = dist.min(near(&t.spline.t, z[k] / sc[k]) * sc[k]);
            } else {
                let (l1, l2, s) = eig(k);
                dist = dist.min(0.5 * s * near(&t.spline.t, l1).min(near(&t.spline.t, l2)));
            }
        }
        for t in &self.terms2d {
            let (k0, k1) = (t.strains[0].index(), t.strains[1].index());
            let sp = &t.spline;
            dist = dist.min(near(&sp.tu, z[k0] / sc[k0]) * sc[k0]);
            if k1 <= 2 {
                dist = dist.min(near(&sp.tv, z[k1] / sc[k1]) * sc[k1]);
            } else {
                let (l1, l2, s) = eig(k1);
                dist = dist.min(0.5 * s * near(&sp.tv, l1).min(near(&sp.tv, l2)));
            }
        }
        dist
    }

    /// Knot range [min, max] of strain `k` over all terms that use it (normalised units × σ), for samplers.
    pub fn knot_range(&self, k: usize) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut upd = |t: &[f64], s: f64| {
            lo = lo.min(t[0] * s);
            hi = hi.max(t[t.len() - 1] * s);
        };
        for t in &self.terms1d {
            if t.strain.index() == k {
                upd(&t.spline.t, self.strain_scale[k]);
            }
        }
        for t in &self.terms2d {
            if t.strains[0].index() == k {
                upd(&t.spline.tu, self.strain_scale[k]);
            }
            if t.strains[1].index() == k {
                upd(&t.spline.tv, self.strain_scale[k]);
            }
        }
        (lo, hi)
    }
}

/// The data cell of a piece index on a knot line of `n` knots.
fn bp_cell(n: usize, index: usize) -> usize {
    piece_from_index(n, index).cell
}
