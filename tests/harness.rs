//! The derivative harness itself: every registered function passes at the policy's tolerances, and deliberately
//! wrong derivatives (test-only mutants of real bugs) are caught.

use hylc::checks::material::{sample_strain, test_spline1d, PsiCheck};
use hylc::checks::run_all;
use hylc::diff::{check_function, CheckConfig, Differentiable, Real, Vgh};
use hylc::material::synthetic::default_material;
use hylc::material::Hermite1D;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

#[test]
fn every_registered_function_passes() {
    let reports = run_all(&CheckConfig::default(), "");
    assert!(
        reports.len() >= 7,
        "expected the material rows, got {}",
        reports.len()
    );
    for r in &reports {
        assert!(
            r.passed(),
            "{} failed: worst ratio {} at {:?}",
            r.name,
            r.worst_ratio,
            r.worst_input
        );
    }
}

/// Mutant 1: the second derivative of a 1D Hermite spline without the 1/h² of the local coordinate.
struct MissingChainFactor(Hermite1D);

impl Differentiable for MissingChainFactor {
    fn name(&self) -> String {
        "mutant: hermite1d f'' without 1/h^2".into()
    }
    fn dim(&self) -> usize {
        1
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        self.0.reference(&x[0])
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let s = &self.0;
        let piece = s.piece(x[0]);
        let d = s.derivs_on(piece, x[0]);
        let i = piece.clamp(1, s.t.len() - 1) - 1;
        let h = s.t[i + 1] - s.t[i];
        Vgh {
            value: d[0],
            gradient: DVector::from_element(1, d[1]),
            hessian: DMatrix::from_element(1, 1, d[2] * h * h),
        }
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        self.0
            .t
            .iter()
            .map(|k| (k - x[0]).abs())
            .fold(f64::INFINITY, f64::min)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, _i: usize) -> Vec<f64> {
        vec![rng.random_range(-0.9..0.95)]
    }
}

/// ψ with a deliberate edit of its fast gradient or Hessian (mutants 2 and 3).
struct PsiMutant {
    name: &'static str,
    inner: PsiCheck,
    edit: fn(&mut Vgh),
}

impl Differentiable for PsiMutant {
    fn name(&self) -> String {
        self.name.into()
    }
    fn dim(&self) -> usize {
        6
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        self.inner.reference(x)
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let mut r = self.inner.fast(x);
        (self.edit)(&mut r);
        r
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        self.inner.fast_value(x)
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        self.inner.kink_distance(x)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        sample_strain(&self.inner.material, rng, i)
    }
}

fn psi_default() -> PsiCheck {
    PsiCheck {
        name: "psi".into(),
        material: default_material(),
    }
}

#[test]
fn wrong_derivatives_are_caught() {
    let cfg = CheckConfig {
        cases: 60,
        ..CheckConfig::default()
    };
    let r = check_function(&MissingChainFactor(test_spline1d()), &cfg);
    assert!(!r.passed() && r.failures > 30, "mutant 1 not caught: {r:?}");
    assert!(r.max_hessian_ad > 1e-2 && r.max_hessian_fd > 1e-2);
    // mutant 2: dψ/dII01 halved (forgetting that L01 appears twice in a symmetric L)
    let halved = PsiMutant {
        name: "mutant: psi dpsi/dII01 halved",
        inner: psi_default(),
        edit: |r| r.gradient[4] *= 0.5,
    };
    let r = check_function(&halved, &cfg);
    assert!(!r.passed(), "mutant 2 not caught: {r:?}");
    assert!(r.max_gradient_ad > 1e-9 && r.max_gradient_fd > 1e-6);
    // mutant 3: one Hessian entry off by one part in a million (far above the 1e-8 AD tolerance)
    let tiny = PsiMutant {
        name: "mutant: psi d2psi/dsx2 * (1 + 1e-6)",
        inner: psi_default(),
        edit: |r| r.hessian[(0, 0)] *= 1.0 + 1e-6,
    };
    let r = check_function(&tiny, &cfg);
    assert!(
        !r.passed() && r.max_hessian_ad > 1e-8,
        "mutant 3 not caught: {r:?}"
    );
}
