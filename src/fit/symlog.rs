//! The symmetric logarithm used by FIT1D step 1 (`docs/fitting.md`, "Fitting (C5, C6, C7)"):
//! symlog(v) = sgn(v) ln(1 + |v|/ε) and its inverse symexp(w) = sgn(w) ε (e^|w| − 1). It compresses the range of
//! energies that grow by orders of magnitude over a strain range while staying linear (slope 1/ε) near 0.

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
    let psi_max = psi.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let eps = if psi_max > 0.0 {
        eps_rel * psi_max
    } else {
        1.0
    };
    (eps, psi.iter().map(|&v| symlog(v, eps)).collect())
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
