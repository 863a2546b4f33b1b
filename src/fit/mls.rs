//! 1D moving least squares (FIT1D step 1, `04-sampling-fitting.md`, "Fitting (C5, C6, C7)"): at each evaluation
//! point u a quadratic in (x − u) is fitted to the samples by weighted least squares with Gaussian weights
//! exp(−(x − u)²/(2b²)), and its value at u is the result. The bandwidth b is a factor (default 2) times the median
//! spacing of the sorted sample abscissae. Because the local model is a full quadratic, quadratic data are
//! reproduced exactly (up to rounding). For the shear strain s_a the symmetrised variant
//! ½(MLS(u) + MLS(−u)) is used ([`Mls1D::eval_symmetric`]).

use super::FitError;

/// Default bandwidth factor (× median sample spacing).
pub const DEFAULT_BANDWIDTH_FACTOR: f64 = 2.0;

/// A moving-least-squares smoother over fixed 1D samples.
#[derive(Clone, Debug)]
pub struct Mls1D {
    x: Vec<f64>,
    y: Vec<f64>,
    bandwidth: f64,
}

impl Mls1D {
    /// Samples (x, y), all finite, with at least three distinct abscissae; bandwidth = `factor` × median spacing
    /// (the median over the positive gaps between sorted distinct abscissae). `factor` must be finite and > 0.
    pub fn new(x: &[f64], y: &[f64], factor: f64) -> Result<Mls1D, FitError> {
        if x.len() != y.len() {
            return Err(FitError::LengthMismatch {
                x: x.len(),
                psi: y.len(),
            });
        }
        if !(factor.is_finite() && factor > 0.0) {
            return Err(FitError::BadOption(format!(
                "MLS bandwidth factor {factor} (must be finite and > 0)"
            )));
        }
        if let Some(i) = (0..x.len()).find(|&i| !(x[i].is_finite() && y[i].is_finite())) {
            return Err(FitError::BadOption(format!(
                "MLS sample {i} is not finite ({}, {})",
                x[i], y[i]
            )));
        }
        let mut sorted = x.to_vec();
        sorted.sort_by(f64::total_cmp);
        let mut gaps: Vec<f64> = sorted
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|&g| g > 0.0)
            .collect();
        if gaps.len() < 2 {
            return Err(FitError::TooFewSamples {
                usable: gaps.len() + usize::from(!x.is_empty()),
                needed: 3,
            });
        }
        gaps.sort_by(f64::total_cmp);
        let n = gaps.len();
        let median = if n % 2 == 1 {
            gaps[n / 2]
        } else {
            0.5 * (gaps[n / 2 - 1] + gaps[n / 2])
        };
        Ok(Mls1D {
            x: x.to_vec(),
            y: y.to_vec(),
            bandwidth: factor * median,
        })
    }

    /// The Gaussian bandwidth b (standard deviation of the weight).
    pub fn bandwidth(&self) -> f64 {
        self.bandwidth
    }

    /// MLS value at `u`. The weights are scaled so the nearest sample has weight 1 (no underflow far from the
    /// data); where the weighted quadratic system is numerically singular (far outside the samples) the local
    /// model drops to a line, then to a constant.
    pub fn eval(&self, u: f64) -> f64 {
        let b = self.bandwidth;
        let d2min = self
            .x
            .iter()
            .map(|&x| ((x - u) / b).powi(2))
            .fold(f64::INFINITY, f64::min);
        // normal equations in the scaled coordinate d = (x − u)/b with basis 1, d, d²: moments Σ w dᵏ, Σ w dᵏ y
        let mut s = [0.0f64; 5];
        let mut r = [0.0f64; 3];
        for (&x, &y) in self.x.iter().zip(&self.y) {
            let d = (x - u) / b;
            let w = (-0.5 * (d * d - d2min)).exp();
            let mut dk = w;
            for k in 0..5 {
                s[k] += dk;
                if k < 3 {
                    r[k] += dk * y;
                }
                dk *= d;
            }
        }
        if let Some(c) = solve3(
            [[s[0], s[1], s[2]], [s[1], s[2], s[3]], [s[2], s[3], s[4]]],
            r,
        ) {
            return c;
        }
        let det = s[0] * s[2] - s[1] * s[1];
        if det > 1e-12 * s[0] * s[2] {
            return (r[0] * s[2] - s[1] * r[1]) / det;
        }
        r[0] / s[0]
    }

    /// The symmetrised MLS ½(MLS(u) + MLS(−u)) used for the shear strain s_a.
    pub fn eval_symmetric(&self, u: f64) -> f64 {
        0.5 * (self.eval(u) + self.eval(-u))
    }
}

/// Constant term of the solution of the symmetric positive 3×3 system `a c = r` by Cholesky, or None when a pivot
/// is not clearly positive (relative to the diagonal).
fn solve3(a: [[f64; 3]; 3], r: [f64; 3]) -> Option<f64> {
    let m = nalgebra::Matrix3::from_fn(|i, j| a[i][j]);
    let diag = a[0][0].max(a[1][1]).max(a[2][2]);
    let chol = m.cholesky()?;
    let l = chol.l();
    if (0..3).any(|i| l[(i, i)] * l[(i, i)] <= 1e-13 * diag || l[(i, i)].is_nan()) {
        return None;
    }
    let c = chol.solve(&nalgebra::Vector3::new(r[0], r[1], r[2]));
    c[0].is_finite().then_some(c[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_quadratics_on_irregular_samples() {
        let x: Vec<f64> = (0..40)
            .map(|i| -1.0 + 0.05 * i as f64 + 0.01 * ((i * 7 % 5) as f64))
            .collect();
        let q = |x: f64| 3.0 - 2.0 * x + 0.7 * x * x;
        let y: Vec<f64> = x.iter().map(|&x| q(x)).collect();
        let m = Mls1D::new(&x, &y, 2.0).unwrap();
        for u in [-1.2, -1.0, -0.33, 0.0, 0.5, 0.99, 1.5] {
            assert!(
                (m.eval(u) - q(u)).abs() < 1e-10,
                "{u}: {} vs {}",
                m.eval(u),
                q(u)
            );
        }
        // symmetrised: the even part of q
        let even = |x: f64| 3.0 + 0.7 * x * x;
        assert!((m.eval_symmetric(0.4) - even(0.4)).abs() < 1e-10);
        // far outside the data the result stays finite
        assert!(m.eval(1e3).is_finite());
    }

    #[test]
    fn bandwidth_is_factor_times_median_spacing() {
        let x = [0.0, 0.1, 0.2, 0.2, 0.5, 0.6];
        let y = [0.0; 6];
        // positive gaps 0.1, 0.1, 0.3, 0.1 → median 0.1
        let m = Mls1D::new(&x, &y, 2.0).unwrap();
        assert!((m.bandwidth() - 0.2).abs() < 1e-15);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            Mls1D::new(&[0.0, 1.0], &[0.0, 1.0], 2.0),
            Err(FitError::TooFewSamples { .. })
        ));
        assert!(matches!(
            Mls1D::new(&[0.0, 0.0, 0.0, 0.0], &[0.0; 4], 2.0),
            Err(FitError::TooFewSamples { .. })
        ));
        assert!(Mls1D::new(&[0.0, 1.0, 2.0], &[0.0, 1.0], 2.0).is_err());
        assert!(Mls1D::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, f64::NAN], 2.0).is_err());
        assert!(Mls1D::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, 2.0], 0.0).is_err());
    }
}
