//! The lagged damping Hessian's derivative with respect to the state it is lagged at (`docs/sensitivities.md`,
//! "Damping and air drag").
//!
//! Stiffness-proportional damping freezes, per triangle, the PSD Hessian of option (b) at the substep's start q:
//!
//!   H_d(q) = Jᵀ P(B) J + Σ_{k ∈ {0, 2}} w_k⁺ ∇²z_k,   B = c ∇²_zΨ(z),   w = c ∇_zΨ(z),
//!
//! with z = z(q), J = ∂z/∂q, c = A k, Ψ(z; β) = ψ(S z) + the collapse barrier's density, P the clamp of B's
//! eigenvalues at 0 (the identity where B is PSD) and w_k⁺ = max(w_k, 0). The adjoint of a damped substep needs,
//! for two fixed vectors a and b (its adjoint and its coordinate change), the gradient of φ(q) = aᵀ H_d(q) b:
//!
//!   ∇_q φ = [Σ_k (P(B) J b)_k ∇²z_k] a + [Σ_k (P(B) J a)_k ∇²z_k] b + c Jᵀ ∇_z⟨M, ∇²Ψ⟩
//!           + Σ_{k ∈ {0, 2}, w_k > 0} [(aᵀ∇²z_k b) Jᵀ B_k + w_k ∇_q(aᵀ∇²z_k b)],
//!
//! where B_k is row k of B and M = U (F ∘ Uᵀ sym(J a (J b)ᵀ) U) Uᵀ the Daleckii–Krein contraction of P's
//! derivative (B = U Λ Uᵀ; F_ij = (f(λ_i) − f(λ_j))/(λ_i − λ_j), f′(λ_i) where λ_i = λ_j, f = max(·, 0); F ≡ 1
//! where P is the identity). The third derivatives come from forward-mode AD of the generic twins:
//! ⟨M, ∇²Ψ⟩ = Σ_e m_e v_eᵀ ∇²Ψ v_e (M = Σ_e m_e v_e v_eᵀ) as second directional derivatives with (z, β)
//! carried as a 7-vector dual, and aᵀ∇²z_k b as a hyper-dual of the in-plane strains with the triangle's 9
//! coordinates carried as a 9-vector dual.
//!
//! Parameters: ∂φ/∂k = φ/k (H_d is homogeneous of degree one in c); ∂φ/∂β = c ∂_β⟨M, ∇²Ψ⟩ +
//! Σ_{k ∈ {0, 2}, w_k > 0} (aᵀ∇²z_k b) c Σ_{l ≥ 3} ∂²ψ/∂y_k∂y_l z_l; ∂φ/∂c_j = ⟨N, ∇²φ_j(S z)⟩ + r·∇φ_j(S z)
//! with N = c S M S and r_k = c (aᵀ∇²z_k b) for the stretch strains k ∈ {0, 2} with w_k > 0 (0 otherwise).
//! A hinge beyond the fold barrier's threshold adds barrier terms this does not cover: [`DampingLagError`].

use super::element::{psd6_by_cholesky, ElementModel};
use super::strain::{strain_reference, RestTriangle, StrainChain, NDOF};
use nalgebra::{Const, SMatrix, SymmetricEigen, U1};
use num_dual::{Dual2, DualSVec64, HyperDual};

/// φ = aᵀ H_d(q) b and its derivatives (module documentation).
#[derive(Clone, Debug)]
pub struct DampingLag {
    /// φ = aᵀ H_d(q) b
    pub value: f64,
    /// ∇_q φ (zero on absent flaps)
    pub grad: [f64; NDOF],
    /// ∂φ/∂β
    pub bending_scale: f64,
    /// N = c S M S, so that ∂φ/∂c_j = ⟨N, ∇²φ_j(S z)⟩ + r·∇φ_j(S z)
    pub n: [[f64; 6]; 6],
    /// r of ∂φ/∂c_j
    pub r: [f64; 6],
    /// S z, where the basis functions φ_j are evaluated
    pub y: [f64; 6],
}

/// Why [`ElementModel::damping_lag`] has no answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DampingLagError {
    /// the triangle is degenerate or collapsed
    Degenerate,
    /// a hinge is beyond the fold barrier's threshold
    FoldActive,
}

type D7 = DualSVec64<7>;
type D9 = DualSVec64<9>;

impl ElementModel {
    /// φ(q) = aᵀ H_d(q) b for the option-(b) Hessian H_d at the stencil coordinates `q`, with ∇_q φ and the
    /// parameter derivatives (module documentation).
    pub fn damping_lag(
        &self,
        q: &[f64; NDOF],
        rest: &RestTriangle,
        flaps: [bool; 3],
        a: &[f64; NDOF],
        b: &[f64; NDOF],
    ) -> Result<DampingLag, DampingLagError> {
        let flaps = self.flaps(flaps);
        let ch = StrainChain::new(q, rest, flaps).ok_or(DampingLagError::Degenerate)?;
        if self.fold_active(&ch) {
            return Err(DampingLagError::FoldActive);
        }
        let p = self.psi(&ch.z).ok_or(DampingLagError::Degenerate)?;
        let (c, w) = self.weights(rest, &p.grad);
        let beta = self.bending_scale;
        let s = [1.0, 1.0, 1.0, beta, beta, beta];
        let bm: [[f64; 6]; 6] =
            std::array::from_fn(|i| std::array::from_fn(|j| c * s[i] * s[j] * p.hess[i][j]));
        let jv = |v: &[f64; NDOF]| -> [f64; 6] {
            std::array::from_fn(|k| (0..NDOF).map(|j| ch.jac[k][j] * v[j]).sum())
        };
        let (ja, jb) = (jv(a), jv(b));
        let (pb, m6) = projection_and_contraction(&bm, &ja, &jb);
        let times = |m: &[[f64; 6]; 6], v: &[f64; 6]| -> [f64; 6] {
            std::array::from_fn(|i| (0..6).map(|j| m[i][j] * v[j]).sum())
        };
        let (pja, pjb) = (times(&pb, &ja), times(&pb, &jb));
        let mut value: f64 = (0..6).map(|k| ja[k] * pjb[k]).sum();
        // the derivative of J in J a and J b
        let mut grad = [0.0; NDOF];
        for (y, v) in [(&pjb, a), (&pja, b)] {
            let mut hz = [[0.0; NDOF]; NDOF];
            ch.add_weighted_hessian(y, &mut hz);
            for (g, row) in grad.iter_mut().zip(&hz) {
                *g += row.iter().zip(v).map(|(h, x)| h * x).sum::<f64>();
            }
        }
        // the derivative of B through z and β
        let g7 = if pb == bm {
            // P is the identity: M = sym(J a (J b)ᵀ), and ⟨M, ∇²Ψ⟩ = (J a)ᵀ ∇²Ψ (J b) in one evaluation
            self.contracted_pair(&ch.z, &ja, &jb)
        } else {
            self.contracted_third(&ch.z, &m6)
        };
        let mut wz = g7[..6].iter().map(|g| c * g).collect::<Vec<_>>();
        let mut bending_scale = c * g7[6];
        let mut r = [0.0; 6];
        // the stretch terms act only where their weight is positive (not on a triangle compressed both ways)
        let stretch = if w[0] > 0.0 || w[2] > 0.0 {
            in_plane_second(q, rest, a, b)
        } else {
            [(0.0, [0.0; NDOF]); 2]
        };
        for (k, (t, tg)) in [(0, stretch[0]), (2, stretch[1])] {
            if w[k] <= 0.0 {
                continue;
            }
            value += w[k] * t;
            r[k] = c * t;
            for l in 0..6 {
                wz[l] += t * bm[k][l];
            }
            for (g, d) in grad.iter_mut().zip(&tg) {
                *g += w[k] * d;
            }
            bending_scale += t * c * (3..6).map(|l| p.hess[k][l] * ch.z[l]).sum::<f64>();
        }
        for (j, g) in grad.iter_mut().enumerate() {
            *g += (0..6).map(|k| ch.jac[k][j] * wz[k]).sum::<f64>();
        }
        for (a, &present) in flaps.iter().enumerate() {
            if !present {
                grad[9 + 3 * a..12 + 3 * a].fill(0.0);
            }
        }
        Ok(DampingLag {
            value,
            grad,
            bending_scale,
            n: std::array::from_fn(|i| std::array::from_fn(|j| c * s[i] * s[j] * m6[i][j])),
            r,
            y: self.scaled(&ch.z),
        })
    }

    /// ∇_{(z, β)} αᵀ∇²_zΨ(z; β) β (7 numbers, β last) by one hyper-dual evaluation of the generic twins with
    /// (z, β) carried as a 7-vector dual.
    fn contracted_pair(&self, z: &[f64; 6], alpha: &[f64; 6], beta: &[f64; 6]) -> [f64; 7] {
        let o = D7::from_re(0.0);
        let zz: [HyperDual<D7>; 6] = std::array::from_fn(|i| {
            HyperDual::new(
                D7::from_re(z[i]).derivative(i),
                D7::from_re(alpha[i]),
                D7::from_re(beta[i]),
                o,
            )
        });
        let b = HyperDual::new(D7::from_re(self.bending_scale).derivative(6), o, o, o);
        let y: [HyperDual<D7>; 6] = std::array::from_fn(|i| if i < 3 { zz[i] } else { b * zz[i] });
        let mut psi = self.material.reference(&y);
        if let Some(cb) = &self.collapse {
            psi += cb.reference(&zz);
        }
        let g = psi.eps1eps2.eps.unwrap_generic(Const::<7>, U1);
        std::array::from_fn(|i| g[i])
    }

    /// ∇_{(z, β)} ⟨M, ∇²_zΨ(z; β)⟩ (7 numbers, β last) by forward-mode AD of ψ's and the collapse barrier's
    /// generic twins along M's eigenvectors.
    fn contracted_third(&self, z: &[f64; 6], m: &[[f64; 6]; 6]) -> [f64; 7] {
        let eig = SymmetricEigen::new(SMatrix::<f64, 6, 6>::from_fn(|i, j| m[i][j]));
        let mut out = [0.0; 7];
        // M is often of rank 2 (sym(J a (J b)ᵀ) where P is the identity): its other eigenvalues are rounding
        let floor = 1e-14 * eig.eigenvalues.iter().fold(0.0f64, |m, l| m.max(l.abs()));
        for e in 0..6 {
            let me = eig.eigenvalues[e];
            if me.abs() <= floor {
                continue;
            }
            let v = eig.eigenvectors.column(e);
            let zz: [Dual2<D7>; 6] = std::array::from_fn(|i| {
                Dual2::new(
                    D7::from_re(z[i]).derivative(i),
                    D7::from_re(v[i]),
                    D7::from_re(0.0),
                )
            });
            let b = Dual2::new(
                D7::from_re(self.bending_scale).derivative(6),
                D7::from_re(0.0),
                D7::from_re(0.0),
            );
            let y: [Dual2<D7>; 6] = std::array::from_fn(|i| if i < 3 { zz[i] } else { b * zz[i] });
            let mut psi = self.material.reference(&y);
            if let Some(cb) = &self.collapse {
                psi += cb.reference(&zz);
            }
            let g = psi.v2.eps.unwrap_generic(Const::<7>, U1);
            for (o, gi) in out.iter_mut().zip(g.iter()) {
                *o += me * gi;
            }
        }
        out
    }
}

/// P(B) (the clamp of [`super::element`]'s option (b)) and the Daleckii–Krein contraction M of its derivative
/// with sym(α βᵀ) (module documentation).
fn projection_and_contraction(
    bm: &[[f64; 6]; 6],
    alpha: &[f64; 6],
    beta: &[f64; 6],
) -> ([[f64; 6]; 6], [[f64; 6]; 6]) {
    let s6: [[f64; 6]; 6] = std::array::from_fn(|i| {
        std::array::from_fn(|j| 0.5 * (alpha[i] * beta[j] + beta[i] * alpha[j]))
    });
    let sym = SMatrix::<f64, 6, 6>::from_fn(|i, j| 0.5 * (bm[i][j] + bm[j][i]));
    if psd6_by_cholesky(bm) {
        return (bm.to_owned(), s6);
    }
    let eig = SymmetricEigen::new(sym);
    let lam = eig.eigenvalues;
    if lam.iter().all(|&l| l >= 0.0) {
        return (bm.to_owned(), s6);
    }
    let u = eig.eigenvectors;
    let f = |l: f64| l.max(0.0);
    let scale = lam.iter().fold(0.0f64, |m, l| m.max(l.abs()));
    let fm = SMatrix::<f64, 6, 6>::from_fn(|i, j| {
        let (li, lj) = (lam[i], lam[j]);
        if (li - lj).abs() <= 1e-13 * scale {
            f64::from(li > 0.0)
        } else {
            (f(li) - f(lj)) / (li - lj)
        }
    });
    let pb = u * SMatrix::<f64, 6, 6>::from_diagonal(&lam.map(f)) * u.transpose();
    let t = u.transpose() * SMatrix::<f64, 6, 6>::from_fn(|i, j| s6[i][j]) * u;
    let m = u * t.component_mul(&fm) * u.transpose();
    (
        std::array::from_fn(|i| std::array::from_fn(|j| pb[(i, j)])),
        std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)])),
    )
}

/// (aᵀ∇²z_k b, ∇_q(aᵀ∇²z_k b)) for the stretch strains k = 0 and 2, over the whole stencil (only the triangle's
/// 9 coordinates enter), by a hyper-dual of the generic strain twin.
fn in_plane_second(
    q: &[f64; NDOF],
    rest: &RestTriangle,
    a: &[f64; NDOF],
    b: &[f64; NDOF],
) -> [(f64, [f64; NDOF]); 2] {
    let qq: Vec<HyperDual<D9>> = (0..NDOF)
        .map(|i| {
            if i < 9 {
                HyperDual::new(
                    D9::from_re(q[i]).derivative(i),
                    D9::from_re(a[i]),
                    D9::from_re(b[i]),
                    D9::from_re(0.0),
                )
            } else {
                let k = D9::from_re(q[i]);
                let o = D9::from_re(0.0);
                HyperDual::new(k, o, o, o)
            }
        })
        .collect();
    let z = strain_reference(&qq, rest, [false; 3]);
    [0, 2].map(|k| {
        let d = &z[k].eps1eps2;
        let g = d.eps.unwrap_generic(Const::<9>, U1);
        let mut out = [0.0; NDOF];
        out[..9].copy_from_slice(g.as_slice());
        (d.re, out)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::synthetic::default_material;
    use crate::shell::element::{ModelFlags, Psd};

    /// A stencil: a stretched and sheared triangle with three bent flaps, coordinates of order 1e-2 m.
    fn stencil() -> ([f64; NDOF], RestTriangle) {
        let l = 0.01;
        let rest_pts = [[0.0, 0.0], [l, 0.0], [0.0, l]];
        let rest = RestTriangle::new(rest_pts[0], rest_pts[1], rest_pts[2]).unwrap();
        let q = [
            0.0,
            0.0,
            0.0, //
            1.08 * l,
            0.001,
            0.0002, //
            0.05 * l,
            1.04 * l,
            -0.0003, //
            1.1 * l,
            1.0 * l,
            0.003, // flap opposite vertex 0
            -0.5 * l,
            0.6 * l,
            0.002, // flap opposite vertex 1
            0.5 * l,
            -0.55 * l,
            -0.002, // flap opposite vertex 2
        ];
        (q, rest)
    }

    /// φ(q) = aᵀ H_d(q) b from the element's own option-(b) Hessian.
    fn phi(
        model: &ElementModel,
        q: &[f64; NDOF],
        rest: &RestTriangle,
        a: &[f64],
        b: &[f64],
    ) -> f64 {
        let mut g = [0.0; NDOF];
        let mut h = [[0.0; NDOF]; NDOF];
        model
            .energy_gradient_hessian(q, rest, [true; 3], &mut g, &mut h)
            .unwrap();
        (0..NDOF)
            .map(|i| a[i] * (0..NDOF).map(|j| h[i][j] * b[j]).sum::<f64>())
            .sum()
    }

    /// φ and ∇_q φ, ∂φ/∂β and ∂φ/∂k agree with central differences of the element's option-(b) Hessian, for a
    /// compressed triangle (where the projection clamps) and a stretched one.
    #[test]
    fn lag_gradient_matches_differences_of_the_projected_hessian() {
        let flags = ModelFlags::default();
        let (q0, rest) = stencil();
        let a: [f64; NDOF] = std::array::from_fn(|i| ((i * 7 % 5) as f64 - 2.0) * 0.3);
        let b: [f64; NDOF] = std::array::from_fn(|i| ((i * 3 % 7) as f64 - 3.0) * 1e-4);
        for squeeze in [1.0, 0.9, 0.75, 0.6] {
            let mut q = q0;
            for v in 0..6 {
                q[3 * v] *= squeeze;
            }
            let mut model = ElementModel::new(&default_material(), &flags, Psd::Psi);
            model.bending_scale = 1.3;
            let lag = model.damping_lag(&q, &rest, [true; 3], &a, &b).unwrap();
            let f0 = phi(&model, &q, &rest, &a, &b);
            assert!(
                (lag.value - f0).abs() <= 1e-10 * f0.abs().max(1e-300),
                "{} vs {f0}",
                lag.value
            );
            let gs = lag.grad.iter().fold(0.0f64, |m, g| m.max(g.abs()));
            for i in 0..NDOF {
                let h = 1e-7;
                let (mut qp, mut qm) = (q, q);
                qp[i] += h;
                qm[i] -= h;
                let fd =
                    (phi(&model, &qp, &rest, &a, &b) - phi(&model, &qm, &rest, &a, &b)) / (2.0 * h);
                assert!(
                    (lag.grad[i] - fd).abs() <= 1e-5 * gs,
                    "squeeze {squeeze}, dof {i}: {} vs {fd}",
                    lag.grad[i]
                );
            }
            // φ's rounding (its Hessian sums terms 1e4 apart) needs a wide step; the truncation is then ~1e-9
            let h = 1e-3;
            let at = |beta: f64| {
                let mut m = model.clone();
                m.bending_scale = beta;
                phi(&m, &q, &rest, &a, &b)
            };
            let fd = (at(1.3 + h) - at(1.3 - h)) / (2.0 * h);
            assert!(
                (lag.bending_scale - fd).abs() <= 1e-6 * fd.abs(),
                "squeeze {squeeze}: dφ/dβ {} vs {fd}",
                lag.bending_scale
            );
            let mut m2 = model.clone();
            m2.stiffness *= 1.0 + 1e-6;
            let fd = (phi(&m2, &q, &rest, &a, &b) - f0) / (1e-6 * model.stiffness);
            assert!((f0 / model.stiffness - fd).abs() <= 1e-5 * fd.abs());
        }
    }

    /// ⟨dP[E], sym(α βᵀ)⟩ = ⟨E, M⟩ for a matrix with eigenvalues of both signs (central differences of P).
    #[test]
    fn contraction_is_the_projections_derivative() {
        let sym = |f: &dyn Fn(usize, usize) -> f64| -> [[f64; 6]; 6] {
            std::array::from_fn(|i| std::array::from_fn(|j| f(i.min(j), i.max(j))))
        };
        let bm = sym(&|i, j| {
            ((i + j) * 5 + i * j) as f64 % 7.0 - 3.0 + 0.5 * (i == j) as u8 as f64 * i as f64
        });
        let e = sym(&|i, j| ((i * 3 + j * 2 + 1) % 5) as f64 - 2.0);
        let alpha = [0.3, -1.0, 0.7, 0.2, -0.4, 1.1];
        let beta = [1.0, 0.5, -0.6, 0.9, 0.1, -0.3];
        let (pb, m) = projection_and_contraction(&bm, &alpha, &beta);
        assert_ne!(pb, bm, "the test matrix must be indefinite");
        let inner = |t: f64| {
            let b: [[f64; 6]; 6] =
                std::array::from_fn(|i| std::array::from_fn(|j| bm[i][j] + t * e[i][j]));
            let p = projection_and_contraction(&b, &alpha, &beta).0;
            (0..6)
                .flat_map(|i| (0..6).map(move |j| (i, j)))
                .map(|(i, j)| p[i][j] * 0.5 * (alpha[i] * beta[j] + beta[i] * alpha[j]))
                .sum::<f64>()
        };
        let h = 1e-5;
        let fd = (inner(h) - inner(-h)) / (2.0 * h);
        let dk: f64 = (0..6)
            .flat_map(|i| (0..6).map(move |j| (i, j)))
            .map(|(i, j)| e[i][j] * m[i][j])
            .sum();
        assert!((fd - dk).abs() <= 1e-8 * fd.abs().max(1.0), "{fd} vs {dk}");
    }
}
