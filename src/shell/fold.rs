//! The fold barrier (our addition to the HYLC shell model; docs/cloth-simulator.md): a hinge may not fold flat onto itself.
//!
//! The strain chain measures a hinge's dihedral angle θ ∈ (−π, π] with atan2 (`docs/cloth-simulator.md`, "Strain chain"), so
//! when two neighbouring triangles fold through each other (|θ| → π, possible because the cloth has no
//! self-contact) θ jumps by 2π and the bending energy jumps with it: Newton's line search then finds no decrease
//! at any step length and the time step fails at every substep. Knits do this: the original stockinette's
//! bending term has its minimum at II₀₀ = −114 m⁻¹ and is almost flat beyond it (the fitted range ends at
//! −190 m⁻¹ and ψ continues linearly), so a free edge curls without limit.
//!
//! Per hinge i of a triangle stencil with rest area A, with x = |θ_i|, threshold θ_t and d = π − x, d̂ = π − θ_t:
//!
//!   E = k_f (A/3) β(x),   β(x) = −(x − θ_t)² ln(d / d̂)  for θ_t < x < π,  0 for x ≤ θ_t,
//!
//! (the clamped log barrier of incremental potential contact, in the angle's distance to the flat fold), so
//! every hinge collects a third of the rest area of each of its two triangles. β is C² at θ_t (β = β′ = β″ = 0
//! there), convex, and → ∞ as x → π: a fold can approach flat but never pass it. With the derivatives in x,
//!
//!   β′(x) = −2u ln(d/d̂) + u²/d,   β″(x) = −2 ln(d/d̂) + 4u/d + u²/d²,   u = x − θ_t,
//!
//! and dβ/dθ = sgn(θ) β′(x), d²β/dθ² = β″(x). In physical terms the barrier stands in for the self-contact of
//! the two wings of a sharp fold; below θ_t (default 2.5 rad, 143°; on a 6 mm mesh a curvature of about
//! 400 m⁻¹) it does nothing, so scenes whose folds stay below it give the same results with or without it.
//!
//! **The collapse barrier** does the same for a triangle's area: with the area ratio
//! J = (1 + s_x)(1 + s_y)√(1 − s_a²) (deformed over rest area, from the in-plane strains), a triangle whose J
//! falls below J_t gets the energy density k_c β_J(J), β_J(J) = −(J − J_t)² ln(J / J_t), added to ψ (so the model's
//! stiffness multiplier scales it too), infinite at J = 0. The fitted materials continue linearly beyond their
//! sampled range, so a shear s_a → ±1 or a compression s → −1 (both J → 0: the yarns would have jammed long
//! before) costs finite energy and a triangle can collapse: the original rib's soft shear lets a triangle at a
//! drape's corner pin do that. Both barriers are the clamped log barrier b(d; d̂) = −(d − d̂)² ln(d/d̂) of a
//! distance d below d̂ ([`log_barrier`]), with d = π − |θ| and d = J.

use crate::real::Real;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The fold barrier's parameters (scene key `model.fold_barrier`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoldBarrier {
    /// θ_t (rad): the barrier acts on hinges folded beyond it, 0 < θ_t < π
    pub angle: f64,
    /// k_f (J/m²): energy density scale
    pub stiffness: f64,
}

impl Default for FoldBarrier {
    fn default() -> Self {
        FoldBarrier {
            angle: 2.5,
            stiffness: 1.0,
        }
    }
}

impl FoldBarrier {
    /// A description of the first parameter out of range: (key, problem).
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if !(self.angle > 0.0 && self.angle < PI) {
            return Err((
                "angle",
                format!("must lie strictly between 0 and π rad, got {}", self.angle),
            ));
        }
        check_stiffness(self.stiffness)
    }

    /// (β, dβ/dθ, d²β/dθ²) at the hinge angle θ; `None` when |θ| ≥ π (folded flat: infinite energy).
    #[inline]
    pub fn profile(&self, theta: f64) -> Option<[f64; 3]> {
        let [b, b1, b2] = log_barrier(PI - theta.abs(), PI - self.angle)?;
        Some([b, -theta.signum() * b1, b2])
    }

    /// The generic reference twin of β(θ) (for the derivative harness).
    pub fn reference<D: Real>(&self, theta: D) -> D {
        let x = if theta.re() < 0.0 { -theta } else { theta };
        log_barrier_reference(-x + PI, PI - self.angle)
    }

    /// The weight k_f A/3 of each hinge of a triangle of rest area A.
    #[inline]
    pub fn weight(&self, area: f64) -> f64 {
        self.stiffness * area / 3.0
    }
}

/// Both barriers' energy density scale must be a positive number.
fn check_stiffness(stiffness: f64) -> Result<(), (&'static str, String)> {
    if !(stiffness > 0.0 && stiffness.is_finite()) {
        return Err((
            "stiffness",
            format!("must be a positive number (J/m²), got {stiffness}"),
        ));
    }
    Ok(())
}

/// The clamped log barrier b(d; d̂) = −(d − d̂)² ln(d/d̂) for 0 < d < d̂, 0 for d ≥ d̂, and its first two
/// derivatives in d: b′ = −2(d − d̂) ln(d/d̂) − (d − d̂)²/d, b″ = −2 ln(d/d̂) − 4(d − d̂)/d + (d − d̂)²/d²
/// (b = b′ = b″ = 0 at d̂; b′ < 0 and b″ > 0 below it). `None` for d ≤ 0 (infinite).
#[inline]
pub fn log_barrier(d: f64, dhat: f64) -> Option<[f64; 3]> {
    if d >= dhat {
        return Some([0.0; 3]);
    }
    if d.is_nan() || d <= 0.0 {
        return None;
    }
    let u = d - dhat;
    let l = (d / dhat).ln();
    Some([
        -u * u * l,
        -2.0 * u * l - u * u / d,
        -2.0 * l - 4.0 * u / d + u * u / (d * d),
    ])
}

/// The generic reference twin of [`log_barrier`]'s value.
pub fn log_barrier_reference<D: Real>(d: D, dhat: f64) -> D {
    if d.re() >= dhat {
        return D::from(0.0);
    }
    let u = d.clone() - dhat;
    -(u.clone() * u) * (d / dhat).ln()
}

/// The collapse barrier's parameters (scene key `model.collapse_barrier`; module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollapseBarrier {
    /// J_t: the barrier acts on triangles whose area ratio falls below it, 0 < J_t < 1
    pub area: f64,
    /// k_c (J/m²): energy density scale
    pub stiffness: f64,
}

impl Default for CollapseBarrier {
    fn default() -> Self {
        CollapseBarrier {
            area: 0.2,
            stiffness: 1.0,
        }
    }
}

impl CollapseBarrier {
    /// A description of the first parameter out of range: (key, problem).
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if !(self.area > 0.0 && self.area < 1.0) {
            return Err((
                "area",
                format!("must lie strictly between 0 and 1, got {}", self.area),
            ));
        }
        check_stiffness(self.stiffness)
    }

    /// The energy density k_c β_J(J(z)) and its gradient and Hessian in z (only the in-plane block is non-zero)
    /// added to `value`, `grad`, `hess`; `None` when J ≤ 0.
    #[inline]
    pub fn add_to(
        &self,
        z: &[f64; 6],
        value: &mut f64,
        grad: &mut [f64; 6],
        hess: &mut [[f64; 6]; 6],
    ) -> Option<()> {
        let (a, b) = (1.0 + z[0], 1.0 + z[2]);
        let c2 = 1.0 - z[1] * z[1];
        if c2.is_nan() || c2 <= 0.0 {
            return None;
        }
        let c = c2.sqrt();
        let j = a * b * c;
        let [v, d1, d2] = log_barrier(j, self.area)?;
        if d1 == 0.0 && d2 == 0.0 {
            return Some(());
        }
        let k = self.stiffness;
        // ∇J and ∇²J in (s_x, s_a, s_y) = (z₀, z₁, z₂): c′ = −s_a/c, c″ = −1/c³
        let (cp, cpp) = (-z[1] / c, -1.0 / (c2 * c));
        let gj = [b * c, a * b * cp, a * c];
        let hj = [
            [0.0, b * cp, c],
            [b * cp, a * b * cpp, a * cp],
            [c, a * cp, 0.0],
        ];
        *value += k * v;
        for p in 0..3 {
            grad[p] += k * d1 * gj[p];
            for q in 0..3 {
                hess[p][q] += k * (d2 * gj[p] * gj[q] + d1 * hj[p][q]);
            }
        }
        Some(())
    }

    /// The energy density alone; `None` when J ≤ 0.
    #[inline]
    pub fn value(&self, z: &[f64; 6]) -> Option<f64> {
        let c2 = 1.0 - z[1] * z[1];
        if c2.is_nan() || c2 <= 0.0 {
            return None;
        }
        let j = (1.0 + z[0]) * (1.0 + z[2]) * c2.sqrt();
        Some(self.stiffness * log_barrier(j, self.area)?[0])
    }

    /// The generic reference twin of the energy density at the in-plane strains of z.
    pub fn reference<D: Real>(&self, z: &[D; 6]) -> D {
        let c2 = -(z[1].clone() * z[1].clone()) + 1.0;
        let j = (z[0].clone() + 1.0) * (z[2].clone() + 1.0) * c2.sqrt();
        log_barrier_reference(j, self.area) * self.stiffness
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Zero up to θ_t, C² there, convex and increasing beyond, even in θ, infinite at the flat fold; β′ and β″
    /// match central differences of β and β′.
    #[test]
    fn profile_is_a_c2_barrier() {
        let f = FoldBarrier::default();
        let t = f.angle;
        assert_eq!(f.profile(t).unwrap(), [0.0; 3]);
        assert_eq!(f.profile(-1.0).unwrap(), [0.0; 3]);
        let [b, b1, b2] = f.profile(t + 1e-6).unwrap();
        assert!(b.abs() < 1e-11 && b1.abs() < 1e-5 && b2.abs() < 1e-4 && b2 > 0.0);
        let mut prev = 0.0;
        for k in 1..200 {
            let th = t + (PI - t) * k as f64 / 200.0;
            let [b, b1, b2] = f.profile(th).unwrap();
            assert!(b > prev && b1 > 0.0 && b2 > 0.0, "θ = {th}");
            prev = b;
            let [bm, b1m, b2m] = f.profile(-th).unwrap();
            assert_eq!((bm, -b1m, b2m), (b, b1, b2));
            let hs = 1e-6 * (PI - th).min(th - t);
            let p = f.profile(th + hs).unwrap();
            let m = f.profile(th - hs).unwrap();
            assert!((((p[0] - m[0]) / (2.0 * hs)) - b1).abs() <= 1e-6 * b1.abs().max(1e-6));
            assert!((((p[1] - m[1]) / (2.0 * hs)) - b2).abs() <= 1e-6 * b2.abs().max(1e-6));
            assert!((f.reference(th) - b).abs() <= 1e-15 * b);
        }
        assert!(f.profile(PI - 1e-9).unwrap()[0] > 8.0 && f.profile(PI - 1e-9).unwrap()[1] > 4e8);
        assert!(f.profile(PI).is_none() && f.profile(-PI).is_none());
    }

    #[test]
    fn parameters_out_of_range_name_their_key() {
        let bad = |angle, stiffness| FoldBarrier { angle, stiffness }.check().unwrap_err().0;
        assert_eq!(bad(0.0, 1.0), "angle");
        assert_eq!(bad(PI, 1.0), "angle");
        assert_eq!(bad(f64::NAN, 1.0), "angle");
        assert_eq!(bad(2.0, 0.0), "stiffness");
        assert_eq!(bad(2.0, f64::INFINITY), "stiffness");
        assert!(FoldBarrier::default().check().is_ok());
    }
}
