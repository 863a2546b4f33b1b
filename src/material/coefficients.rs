//! The coefficients of ψ one by one: ψ is linear in them,
//!
//! ψ(z) = C₀ + Σ_terms Σ_j c_j φ_j(z),
//!
//! with c_j every value and slope of a 1D term (p_i, m_i) and every value and derivative of a 2D term (p, ∂_u,
//! ∂_v, ∂_uv at a grid point) and φ_j = ∂ψ/∂c_j the basis function: ψ of the material with every coefficient
//! zero except c_j = 1 (the constant C₀ has φ = 1, ∇φ = 0). [`BasisEvaluator`] evaluates φ_j and ∇_z φ_j with
//! local support: at a strain z only the coefficients of the active cell of each term can be non-zero (≤ 4 per
//! in-plane 1D term, ≤ 16 per in-plane 2D term; the spectral bending terms through the cells of both
//! eigenvalues of L/σ and those between them). [`MaterialGradient`] holds one number per coefficient in the
//! material's own layout (the sensitivities of `shell::solver::adjoint`).

use super::hermite::locate;
use super::{Hermite1D, Hermite2D, Material, Term1D, Term2D};
use std::collections::HashMap;

/// One coefficient of a material.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Coefficient {
    /// C₀
    Constant,
    /// 1D term number `term` (in `terms1d`): its value p (`slope` false) or slope m at knot `index`
    Term1D {
        /// the term's index in `terms1d`
        term: usize,
        /// the slope m (true) or the value p (false)
        slope: bool,
        /// the knot
        index: usize,
    },
    /// 2D term number `term` (in `terms2d`): array 0 = p, 1 = ∂_u (mu), 2 = ∂_v (mv), 3 = ∂_uv (muv), at
    /// `index` = i_v n_u + i_u (the file's layout)
    Term2D {
        /// the term's index in `terms2d`
        term: usize,
        /// 0 = p, 1 = mu, 2 = mv, 3 = muv
        array: usize,
        /// the knot, i_v n_u + i_u
        index: usize,
    },
}

/// The coefficient's place in the material file: `coeffs.const`, `coeffs.1D[term].p[index]` (or `.m`),
/// `coeffs.2D[term].mu[index]` (or `.p`, `.mv`, `.muv`).
impl std::fmt::Display for Coefficient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Coefficient::Constant => write!(f, "coeffs.const"),
            Coefficient::Term1D { term, slope, index } => {
                let a = if slope { "m" } else { "p" };
                write!(f, "coeffs.1D[{term}].{a}[{index}]")
            }
            Coefficient::Term2D { term, array, index } => {
                let a = ["p", "mu", "mv", "muv"][array];
                write!(f, "coeffs.2D[{term}].{a}[{index}]")
            }
        }
    }
}

/// One number per coefficient of a material, in its layout (e.g. dJ/dc_j).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialGradient {
    /// the number for C₀
    pub constant: f64,
    /// per 1D term: [per knot for p, per knot for m]
    pub terms1d: Vec<[Vec<f64>; 2]>,
    /// per 2D term: [p, mu, mv, muv], each n_u n_v in the file's layout
    pub terms2d: Vec<[Vec<f64>; 4]>,
}

impl MaterialGradient {
    /// All zero, in the layout of `m`.
    pub fn zeros(m: &Material) -> MaterialGradient {
        MaterialGradient {
            constant: 0.0,
            terms1d: m
                .terms1d
                .iter()
                .map(|t| [vec![0.0; t.spline.t.len()], vec![0.0; t.spline.t.len()]])
                .collect(),
            terms2d: m
                .terms2d
                .iter()
                .map(|t| std::array::from_fn(|_| vec![0.0; t.spline.tu.len() * t.spline.tv.len()]))
                .collect(),
        }
    }

    /// The number of coefficient `c`.
    pub fn get(&self, c: Coefficient) -> f64 {
        match c {
            Coefficient::Constant => self.constant,
            Coefficient::Term1D { term, slope, index } => {
                self.terms1d[term][usize::from(slope)][index]
            }
            Coefficient::Term2D { term, array, index } => self.terms2d[term][array][index],
        }
    }

    /// The number of coefficient `c`, mutable.
    pub fn get_mut(&mut self, c: Coefficient) -> &mut f64 {
        match c {
            Coefficient::Constant => &mut self.constant,
            Coefficient::Term1D { term, slope, index } => {
                &mut self.terms1d[term][usize::from(slope)][index]
            }
            Coefficient::Term2D { term, array, index } => &mut self.terms2d[term][array][index],
        }
    }

    /// A material shaped like `like` (knots, strain scales, density, extra keys) with these numbers in place of
    /// its coefficients: e.g. the material JSON of dJ/dc.
    pub fn to_material(&self, like: &Material) -> Material {
        let mut m = like.clone();
        m.constant = self.constant;
        for (t, [p, s]) in m.terms1d.iter_mut().zip(&self.terms1d) {
            t.spline = Hermite1D::new(t.spline.t.clone(), p.clone(), s.clone());
        }
        for (t, [p, mu, mv, muv]) in m.terms2d.iter_mut().zip(&self.terms2d) {
            let sp = &t.spline;
            t.spline = Hermite2D::new(
                sp.tu.clone(),
                sp.tv.clone(),
                p.clone(),
                mu.clone(),
                mv.clone(),
                muv.clone(),
            );
        }
        m
    }
}

impl Material {
    /// Every coefficient of the material, in layout order (constant, 1D terms p then m, 2D terms p, mu, mv, muv).
    pub fn coefficients(&self) -> Vec<Coefficient> {
        let mut out = vec![Coefficient::Constant];
        for (term, t) in self.terms1d.iter().enumerate() {
            for slope in [false, true] {
                out.extend((0..t.spline.t.len()).map(|index| Coefficient::Term1D {
                    term,
                    slope,
                    index,
                }));
            }
        }
        for (term, t) in self.terms2d.iter().enumerate() {
            let n = t.spline.tu.len() * t.spline.tv.len();
            for array in 0..4 {
                out.extend((0..n).map(|index| Coefficient::Term2D { term, array, index }));
            }
        }
        out
    }

    /// The value of coefficient `c`.
    pub fn coefficient(&self, c: Coefficient) -> f64 {
        match c {
            Coefficient::Constant => self.constant,
            Coefficient::Term1D { term, slope, index } => {
                let sp = &self.terms1d[term].spline;
                if slope {
                    sp.m[index]
                } else {
                    sp.p[index]
                }
            }
            Coefficient::Term2D { term, array, index } => {
                let sp = &self.terms2d[term].spline;
                [&sp.p, &sp.mu, &sp.mv, &sp.muv][array][index]
            }
        }
    }

    /// The material with coefficient `c` set to `value` (its spline rebuilt).
    pub fn with_coefficient(&self, c: Coefficient, value: f64) -> Material {
        let mut g = MaterialGradient::zeros(self);
        for k in self.coefficients() {
            *g.get_mut(k) = self.coefficient(k);
        }
        *g.get_mut(c) = value;
        g.to_material(self)
    }

    /// The material whose only non-zero coefficient is `c` = 1, with only `c`'s term: its ψ is φ_c.
    pub fn unit_material(&self, c: Coefficient) -> Material {
        let mut m = Material {
            density: self.density,
            strain_scale: self.strain_scale,
            constant: 0.0,
            terms1d: vec![],
            terms2d: vec![],
            extra: serde_json::Map::new(),
        };
        match c {
            Coefficient::Constant => m.constant = 1.0,
            Coefficient::Term1D { term, slope, index } => {
                let t = &self.terms1d[term];
                let n = t.spline.t.len();
                let mut arrs = [vec![0.0; n], vec![0.0; n]];
                arrs[usize::from(slope)][index] = 1.0;
                let [p, s] = arrs;
                m.terms1d.push(Term1D {
                    strain: t.strain,
                    spline: Hermite1D::new(t.spline.t.clone(), p, s),
                });
            }
            Coefficient::Term2D { term, array, index } => {
                let t = &self.terms2d[term];
                let n = t.spline.tu.len() * t.spline.tv.len();
                let mut arrs: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; n]);
                arrs[array][index] = 1.0;
                let [p, mu, mv, muv] = arrs;
                m.terms2d.push(Term2D {
                    strains: t.strains,
                    spline: Hermite2D::new(
                        t.spline.tu.clone(),
                        t.spline.tv.clone(),
                        p,
                        mu,
                        mv,
                        muv,
                    ),
                });
            }
        }
        m
    }

    /// The knot indices whose data can enter ψ along strain `k` at z: the cell of z_k/σ_k for an in-plane
    /// strain, for a bending index the cells from that of the smaller to that of the larger eigenvalue of L/σ_k
    /// (the divided differences use the pieces of both eigenvalues, or one of them when they are close).
    fn knot_support(&self, t: &[f64], k: usize, z: &[f64; 6]) -> std::ops::RangeInclusive<usize> {
        let s = self.strain_scale[k];
        let (c0, c1) = if k <= 2 {
            let c = locate(t, z[k] / s).cell;
            (c, c)
        } else {
            let m = (z[3] + z[5]) / (2.0 * s);
            let r = (((z[3] - z[5]) / (2.0 * s)).powi(2) + (z[4] / s).powi(2)).sqrt();
            (locate(t, m - r).cell, locate(t, m + r).cell)
        };
        c0..=c1 + 1
    }

    /// The coefficients whose basis function may be non-zero near z (local support; the constant excluded, its
    /// gradient is zero everywhere).
    pub fn support(&self, z: &[f64; 6]) -> Vec<Coefficient> {
        let mut out = Vec::new();
        for (term, t) in self.terms1d.iter().enumerate() {
            let r = self.knot_support(&t.spline.t, t.strain.index(), z);
            for slope in [false, true] {
                out.extend(
                    r.clone()
                        .map(|index| Coefficient::Term1D { term, slope, index }),
                );
            }
        }
        for (term, t) in self.terms2d.iter().enumerate() {
            let sp = &t.spline;
            let ru = self.knot_support(&sp.tu, t.strains[0].index(), z);
            let rv = self.knot_support(&sp.tv, t.strains[1].index(), z);
            let nu = sp.tu.len();
            for array in 0..4 {
                for iv in rv.clone() {
                    out.extend(ru.clone().map(|iu| Coefficient::Term2D {
                        term,
                        array,
                        index: iv * nu + iu,
                    }));
                }
            }
        }
        out
    }
}

/// φ_j(z) and ∇_z φ_j(z) of a material's coefficients, each unit material built once when first needed.
pub struct BasisEvaluator<'a> {
    material: &'a Material,
    cache: HashMap<Coefficient, Material>,
}

impl<'a> BasisEvaluator<'a> {
    /// An evaluator for the coefficients of `material`.
    pub fn new(material: &'a Material) -> Self {
        BasisEvaluator {
            material,
            cache: HashMap::new(),
        }
    }

    /// φ_c(z) and ∇_z φ_c(z) (ψ's own fast path on the unit material).
    pub fn basis(&mut self, c: Coefficient, z: &[f64; 6]) -> (f64, [f64; 6]) {
        if c == Coefficient::Constant {
            return (1.0, [0.0; 6]);
        }
        let material = self.material;
        let unit = self
            .cache
            .entry(c)
            .or_insert_with(|| material.unit_material(c));
        let p = unit.eval(z);
        (p.value, p.grad)
    }

    /// φ_c, ∇φ_c and ∇²φ_c at z.
    pub fn basis_hessian(&mut self, c: Coefficient, z: &[f64; 6]) -> super::PsiVgh {
        let material = self.material;
        let unit = self
            .cache
            .entry(c)
            .or_insert_with(|| material.unit_material(c));
        unit.eval(z)
    }

    /// The generic reference twin of φ_c (for AD checks).
    pub fn reference<D: crate::real::Real>(&mut self, c: Coefficient, z: &[D]) -> D {
        let material = self.material;
        let unit = self
            .cache
            .entry(c)
            .or_insert_with(|| material.unit_material(c));
        unit.reference(z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::synthetic::default_material;

    fn strains() -> Vec<[f64; 6]> {
        // deterministic pseudo-random strains over the fitted ranges, bending on and off, in and out of the knots
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        (0..40)
            .map(|i| {
                let span = if i % 5 == 4 { 1.3 } else { 0.8 };
                let mut z = [
                    span * r(),
                    0.6 * span * r(),
                    span * r(),
                    120.0 * span * r(),
                    120.0 * span * r(),
                    120.0 * span * r(),
                ];
                if i % 7 == 3 {
                    z[4] = 0.0;
                    z[5] = z[3];
                }
                z
            })
            .collect()
    }

    /// Σ_j c_j φ_j = ψ − C₀ and Σ_j c_j ∇φ_j = ∇ψ over the local support: the support holds every coefficient
    /// that enters ψ at z, and the unit materials are ψ's basis functions.
    #[test]
    fn basis_gradients_sum_to_the_material_gradient() {
        let mut m = default_material();
        m.constant = 0.37;
        let mut ev = BasisEvaluator::new(&m);
        for z in strains() {
            let p = m.eval(&z);
            let mut value = m.constant;
            let mut grad = [0.0; 6];
            for c in m.support(&z) {
                let (phi, g) = ev.basis(c, &z);
                let cj = m.coefficient(c);
                value += cj * phi;
                for k in 0..6 {
                    grad[k] += cj * g[k];
                }
            }
            let scale = p.grad.iter().fold(1e-12f64, |a, b| a.max(b.abs()));
            assert!(
                (value - p.value).abs() <= 1e-10 * p.value.abs().max(1.0),
                "ψ at {z:?}: {value} vs {}",
                p.value
            );
            for k in 0..6 {
                assert!(
                    (grad[k] - p.grad[k]).abs() <= 1e-10 * scale,
                    "∂ψ/∂z{k} at {z:?}: {} vs {}",
                    grad[k],
                    p.grad[k]
                );
            }
        }
    }

    /// Outside its support a basis function vanishes with its gradient (the support is not too small by a cell).
    #[test]
    fn basis_functions_vanish_outside_the_support() {
        let m = default_material();
        let mut ev = BasisEvaluator::new(&m);
        let all = m.coefficients();
        for z in strains().into_iter().take(8) {
            let sup = m.support(&z);
            for &c in all.iter().step_by(7) {
                if c == Coefficient::Constant || sup.contains(&c) {
                    continue;
                }
                let (phi, g) = ev.basis(c, &z);
                assert!(phi == 0.0 && g.iter().all(|&x| x == 0.0), "{c:?} at {z:?}");
            }
        }
    }

    /// ∇φ_j against num-dual on the reference twin and against central differences, for coefficients of every
    /// kind of term.
    #[test]
    fn basis_gradients_match_ad_and_finite_differences() {
        use nalgebra::DVector;
        use num_dual::Dual2DVec64;
        let m = default_material();
        let mut ev = BasisEvaluator::new(&m);
        let z = [0.12, -0.2, 0.07, 40.0, -25.0, 60.0];
        let sup = m.support(&z);
        let mut checked = 0;
        for &c in sup.iter().step_by(5) {
            let (_, g) = ev.basis(c, &z);
            let unit = m.unit_material(c);
            let (_, gad, _) = num_dual::hessian(
                |x: DVector<Dual2DVec64>| {
                    let v: Vec<Dual2DVec64> = x.iter().cloned().collect();
                    unit.reference(&v)
                },
                &DVector::from_column_slice(&z),
            );
            let scale = g.iter().fold(1e-12f64, |a, b| a.max(b.abs()));
            for k in 0..6 {
                assert!(
                    (g[k] - gad[k]).abs() <= 1e-9 * scale,
                    "{c:?} ∂/∂z{k}: {} vs AD {}",
                    g[k],
                    gad[k]
                );
                let h = 1e-6 * m.strain_scale[k.min(4)];
                let (mut zp, mut zm) = (z, z);
                zp[k] += h;
                zm[k] -= h;
                let fd = (ev.basis(c, &zp).0 - ev.basis(c, &zm).0) / (2.0 * h);
                assert!(
                    (g[k] - fd).abs() <= 1e-6 * scale,
                    "{c:?} ∂/∂z{k}: {} vs FD {fd}",
                    g[k]
                );
            }
            checked += 1;
        }
        assert!(checked >= 20, "{checked} coefficients checked");
    }
}
