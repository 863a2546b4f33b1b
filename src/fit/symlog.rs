//! The symmetric logarithm used by FIT1D step 1 (`docs/fitting.md`, "Fitting (C5, C6, C7)"):
//! symlog(v) = sgn(v) ln(1 + |v|/ε) and its inverse symexp(w) = sgn(w) ε (e^|w| − 1). It compresses the range of
//! energies that grow by orders of magnitude over a strain range while staying linear (slope 1/ε) near 0.

use super::scalar::{FitScalar, KinkRule, Kinks};

/// symlog(v) = sgn(v) ln(1 + |v|/ε), ε > 0. symlog(±0) = ±0; NaN stays NaN.
#[inline]
pub fn symlog(v: f64, eps: f64) -> f64 {
    (v.abs() / eps).ln_1p().copysign(v)
}

/// symexp(w) = sgn(w) ε (e^|w| − 1), the inverse of [`symlog`] with the same ε.
#[inline]
pub fn symexp(w: f64, eps: f64) -> f64 {
    (eps * w.abs().exp_m1()).copysign(w)
}

/// Step 1's transform of the sample values: ε = `eps_rel` · max|Ψ| (1 when all Ψ are 0) and symlog(Ψ, ε) of
/// each. Returns (ε, the transformed values).
pub fn symlog_samples(psi: &[f64], eps_rel: f64) -> (f64, Vec<f64>) {
    symlog_samples_t(psi, eps_rel, &mut Kinks::off(), |_| String::new())
}

/// [`symlog`] over a [`FitScalar`]: sgn(v) ln(1 + |v|/ε), the sign taken from the real part (the function is C¹
/// at v = 0, slope 1/ε from both sides).
pub fn symlog_t<T: FitScalar>(v: T, eps: T) -> T {
    v.copysign_of(1.0).quot(eps).ln_1p().copysign_of(v.value())
}

/// [`symexp`] over a [`FitScalar`]: sgn(w) ε (e^|w| − 1).
pub fn symexp_t<T: FitScalar>(w: T, eps: T) -> T {
    (eps * w.copysign_of(1.0).exp_m1()).copysign_of(w.value())
}

/// [`symlog_samples`] over a [`FitScalar`]: ε = `eps_rel` · |Ψ_a| with a = argmax |Ψᵢ| (on the real parts), so ε
/// carries the tangent of that sample; another sample within a relative 1e-9 of the largest |Ψ| is a kink
/// ([`KinkRule::SymlogScale`], the site named by `site(i)`).
pub(crate) fn symlog_samples_t<T: FitScalar>(
    psi: &[T],
    eps_rel: f64,
    kinks: &mut Kinks,
    site: impl Fn(usize) -> String,
) -> (T, Vec<T>) {
    let zero = T::from(0.0);
    let (mut psi_max, mut at) = (zero, None);
    for (i, &v) in psi.iter().enumerate() {
        let a = v.copysign_of(1.0);
        let m = psi_max.max_of(a);
        if m.value() != psi_max.value() {
            at = Some(i);
        }
        psi_max = m;
    }
    if let Some(a) = at {
        for (i, &v) in psi.iter().enumerate().filter(|&(i, _)| i != a) {
            kinks.tie(v.copysign_of(1.0), psi_max, KinkRule::SymlogScale, || {
                format!("{} and {}", site(a), site(i))
            });
        }
    }
    let eps = if psi_max.value() > 0.0 {
        psi_max * eps_rel
    } else {
        T::from(1.0)
    };
    (eps, psi.iter().map(|&v| symlog_t(v, eps)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symlog_is_odd_and_linear_near_zero() {
        let eps = 1e-3;
        assert_eq!(symlog(0.0, eps), 0.0);
        for v in [1e-9, 1e-4, 0.3, 7.0, 1e8] {
            assert_eq!(symlog(-v, eps), -symlog(v, eps));
        }
        // slope 1/ε at 0
        let v = 1e-12;
        assert!((symlog(v, eps) / v - 1.0 / eps).abs() < 1e-6 / eps);
        assert!((symlog(1.0, 1.0) - 2f64.ln()).abs() < 1e-15);
    }

    #[test]
    fn symexp_inverts_symlog() {
        for eps in [1e-6, 1e-3, 1.0, 50.0] {
            for v in [-1e9, -3.5, -1e-7, 0.0, 2e-5, 0.1, 42.0, 1e12] {
                let back = symexp(symlog(v, eps), eps);
                assert!(
                    (back - v).abs() <= 1e-13 * v.abs(),
                    "eps {eps}, v {v}: {back}"
                );
                let w = v.signum() * v.abs().min(30.0);
                let again = symlog(symexp(w, eps), eps);
                assert!(
                    (again - w).abs() <= 1e-13 * w.abs().max(1.0),
                    "eps {eps}, w {w}: {again}"
                );
            }
        }
        assert!(symlog(f64::NAN, 1.0).is_nan() && symexp(f64::NAN, 1.0).is_nan());
    }
}
