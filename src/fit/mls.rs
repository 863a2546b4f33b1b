//! 1D moving least squares (FIT1D step 1, `docs/fitting.md`, "Fitting (C5, C6, C7)"): at each evaluation
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
        let median = median_spacing(x).map_err(|distinct| FitError::TooFewSamples {
            usable: distinct,
            needed: 3,
        })?;
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
        self.eval_with(u, &self.y)
    }

    /// [`Mls1D::eval`] with the values `y` in place of the samples' (same abscissae, so the same weights and
    /// the same local model): the MLS is linear in the values, Σᵢ ℓᵢ(u) yᵢ.
    pub fn eval_with(&self, u: f64, y: &[f64]) -> f64 {
        let b = self.bandwidth;
        let d2min = self
            .x
            .iter()
            .map(|&x| ((x - u) / b).powi(2))
            .fold(f64::INFINITY, f64::min);
        // normal equations in the scaled coordinate d = (x − u)/b with basis 1, d, d²: moments Σ w dᵏ, Σ w dᵏ y
        let mut s = [0.0f64; 5];
        let mut r = [0.0f64; 3];
        for (&x, &y) in self.x.iter().zip(y) {
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
        self.eval_symmetric_with(u, &self.y)
    }

    /// [`Mls1D::eval_symmetric`] with the values `y` in place of the samples'.
    pub fn eval_symmetric_with(&self, u: f64, y: &[f64]) -> f64 {
        0.5 * (self.eval_with(u, y) + self.eval_with(-u, y))
    }
}

/// Median of the positive gaps between the sorted distinct values of `x`; the number of distinct values when there
/// are fewer than three.
fn median_spacing(x: &[f64]) -> Result<f64, usize> {
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mut gaps: Vec<f64> = sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|&g| g > 0.0)
        .collect();
    if gaps.len() < 2 {
        return Err(gaps.len() + usize::from(!x.is_empty()));
    }
    gaps.sort_by(f64::total_cmp);
    let n = gaps.len();
    Ok(if n % 2 == 1 {
        gaps[n / 2]
    } else {
        0.5 * (gaps[n / 2 - 1] + gaps[n / 2])
    })
}

/// 2D moving least squares (FIT2D step 1): at each point (u, v) a full quadratic in (x − u, y − v) is fitted by
/// weighted least squares with the Gaussian weight exp(−½((x − u)²/b_u² + (y − v)²/b_v²)), one bandwidth per axis
/// (factor × the median spacing of that coordinate's distinct values). Quadratics are reproduced exactly.
#[derive(Clone, Debug)]
pub struct Mls2D {
    x: Vec<f64>,
    y: Vec<f64>,
    f: Vec<f64>,
    bandwidth: [f64; 2],
}

impl Mls2D {
    /// Samples (x, y, f), all finite, with at least three distinct values per coordinate; `factor` finite, > 0.
    pub fn new(x: &[f64], y: &[f64], f: &[f64], factor: f64) -> Result<Mls2D, FitError> {
        if x.len() != f.len() || y.len() != f.len() {
            return Err(FitError::LengthMismatch {
                x: x.len().min(y.len()),
                psi: f.len(),
            });
        }
        if !(factor.is_finite() && factor > 0.0) {
            return Err(FitError::BadOption(format!(
                "MLS bandwidth factor {factor} (must be finite and > 0)"
            )));
        }
        if let Some(i) =
            (0..x.len()).find(|&i| !(x[i].is_finite() && y[i].is_finite() && f[i].is_finite()))
        {
            return Err(FitError::BadOption(format!(
                "MLS sample {i} is not finite ({}, {}, {})",
                x[i], y[i], f[i]
            )));
        }
        let too_few = |distinct: usize| FitError::TooFewSamples {
            usable: distinct,
            needed: 3,
        };
        let bu = median_spacing(x).map_err(too_few)?;
        let bv = median_spacing(y).map_err(too_few)?;
        Ok(Mls2D {
            x: x.to_vec(),
            y: y.to_vec(),
            f: f.to_vec(),
            bandwidth: [factor * bu, factor * bv],
        })
    }

    /// The Gaussian bandwidths (b_u, b_v).
    pub fn bandwidth(&self) -> [f64; 2] {
        self.bandwidth
    }

    /// MLS value at (u, v). As in 1D the weights are scaled so the nearest sample has weight 1, and samples
    /// with weight below 1e-14 are dropped. The weighted least-squares problem is solved by a Householder QR of
    /// the weighted design matrix (not the normal equations, whose squared condition number costs ~8 digits at the
    /// edges of the data); where R is numerically singular the local model drops to a plane, then to a constant.
    pub fn eval(&self, u: f64, v: f64) -> f64 {
        self.eval_with(u, v, &[&self.f])[0]
    }

    /// [`Mls2D::eval`] for several value vectors `fs` at the samples' abscissae (linear in each: Σᵢ ℓᵢ(u, v)
    /// fᵢ). The weights and the QR are formed once; the fallback to a plane or a constant is decided on the first
    /// vector and used for all.
    pub fn eval_with(&self, u: f64, v: f64, fs: &[&[f64]]) -> Vec<f64> {
        let [bu, bv] = self.bandwidth;
        let d2 = |i: usize| ((self.x[i] - u) / bu).powi(2) + ((self.y[i] - v) / bv).powi(2);
        let d2min = (0..self.x.len()).map(d2).fold(f64::INFINITY, f64::min);
        let mut rows: Vec<([f64; 6], usize, f64)> = Vec::new();
        for i in 0..self.x.len() {
            let (du, dv) = ((self.x[i] - u) / bu, (self.y[i] - v) / bv);
            let w = (-0.5 * (du * du + dv * dv - d2min)).exp();
            if w < 1e-14 {
                continue;
            }
            let s = w.sqrt();
            rows.push((
                [s, s * du, s * dv, s * du * du, s * du * dv, s * dv * dv],
                i,
                s,
            ));
        }
        for n in [6usize, 3, 1] {
            if rows.len() < n {
                continue;
            }
            let a = nalgebra::DMatrix::from_fn(rows.len(), n, |i, j| rows[i].0[j]);
            let qr = a.qr();
            let r = qr.r();
            let rmax = (0..n).fold(0.0f64, |m, i| m.max(r[(i, i)].abs()));
            if (0..n).any(|i| r[(i, i)].abs() <= 1e-7 * rmax || !r[(i, i)].is_finite()) {
                continue;
            }
            let solve = |f: &[f64]| {
                let mut rhs =
                    nalgebra::DVector::from_fn(rows.len(), |i, _| rows[i].2 * f[rows[i].1]);
                qr.q_tr_mul(&mut rhs);
                r.solve_upper_triangular(&rhs.rows(0, n).clone_owned())
                    .map_or(f64::NAN, |c| c[0])
            };
            let first = solve(fs[0]);
            if first.is_finite() {
                let mut out = vec![first];
                out.extend(fs[1..].iter().map(|f| solve(f)));
                return out;
            }
        }
        vec![f64::NAN; fs.len()]
    }

    /// ½(MLS(u, v) + MLS(−u, v)) (`sym_u`) and/or the same in v: the symmetrisation for the shear strain s_a.
    pub fn eval_symmetric(&self, u: f64, v: f64, sym_u: bool, sym_v: bool) -> f64 {
        self.eval_symmetric_with(u, v, sym_u, sym_v, &[&self.f])[0]
    }

    /// [`Mls2D::eval_symmetric`] for several value vectors ([`Mls2D::eval_with`]).
    pub fn eval_symmetric_with(
        &self,
        u: f64,
        v: f64,
        sym_u: bool,
        sym_v: bool,
        fs: &[&[f64]],
    ) -> Vec<f64> {
        let e = |u: f64, v: f64| self.eval_with(u, v, fs);
        let combine = |vals: &[Vec<f64>], w: f64| -> Vec<f64> {
            (0..fs.len())
                .map(|k| match vals {
                    [a, b] => w * (a[k] + b[k]),
                    [a, b, c, d] => w * (a[k] + b[k] + c[k] + d[k]),
                    _ => vals[0][k],
                })
                .collect()
        };
        match (sym_u, sym_v) {
            (false, false) => e(u, v),
            (true, false) => combine(&[e(u, v), e(-u, v)], 0.5),
            (false, true) => combine(&[e(u, v), e(u, -v)], 0.5),
            (true, true) => combine(&[e(u, v), e(-u, v), e(u, -v), e(-u, -v)], 0.25),
        }
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
    fn mls2d_reproduces_quadratics_on_a_grid() {
        let mut x = Vec::new();
        let mut y = Vec::new();
        for i in 0..15 {
            for j in 0..12 {
                x.push(-1.0 + 0.13 * i as f64);
                y.push(-0.4 + 0.1 * j as f64 + 0.003 * (i % 3) as f64);
            }
        }
        let q = |x: f64, y: f64| 1.0 - 0.5 * x + 2.0 * y + 0.3 * x * x - 1.1 * x * y + 0.8 * y * y;
        let f: Vec<f64> = x.iter().zip(&y).map(|(&a, &b)| q(a, b)).collect();
        let m = Mls2D::new(&x, &y, &f, 2.0).unwrap();
        for (u, v) in [(0.0, 0.0), (-1.0, -0.4), (0.77, 0.51), (0.8, 0.75)] {
            assert!(
                (m.eval(u, v) - q(u, v)).abs() < 1e-9,
                "({u}, {v}): {} vs {}",
                m.eval(u, v),
                q(u, v)
            );
        }
        let even = |x: f64, y: f64| 0.5 * (q(x, y) + q(-x, y));
        assert!((m.eval_symmetric(0.3, 0.2, true, false) - even(0.3, 0.2)).abs() < 1e-9);
        assert!(Mls2D::new(&x[..2], &y[..2], &f[..2], 2.0).is_err());
        assert!(Mls2D::new(&x, &y, &f, f64::NAN).is_err());
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
