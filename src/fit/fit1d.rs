//! FIT1D (`docs/fitting.md`, "Fitting (C5, C6, C7)", steps 1–6): one 1D term f_k of the material from
//! samples (X, Ψ) of its 1D strain range (X already normalised by the strain scale).
//!
//! 1. g(u) = symexp(MLS(u | X, symlog Ψ)), ε = `eps_rel` · max|Ψ|; symmetrised MLS for s_a.
//! 2. Knots: all multiples of h = 0.95 (max X − min X)/(N_c − 1) inside [0.95 min X, 0.95 max X]; values p = g(t),
//!    slopes pˣ by central finite differences of g (step `fd_step` · h).
//! 3. Quasi-convexification marching outward from i_min (the knot at 0, or argmin p): p_{i+1} ≥ pᵢ + (t_{i+1} − tᵢ)
//!    pˣ_min and pˣᵢ ≥ pˣ_min on the right, mirrored on the left.
//! 4. Fritsch–Carlson (1980) monotone correction on each side of i_min. We use their sufficient region
//!    0 ≤ α, β ≤ 3 (α, β = slope / secant of a cell), clamping each slope to ≤ 3 |secant| of both adjacent cells;
//!    unlike the radial rescaling this never lowers a slope below 3 pˣ_min, so step 3's slope bound survives.
//! 5. Increasing extrapolation: the end slopes are clamped to ≤ −pˣ_min (left) and ≥ pˣ_min (right), so the
//!    linear continuation keeps rising away from the minimum.
//! 6. Residual: p ← p − f(0); the removed constant is returned as [`Fit1D::offset`] (it belongs to f₀).
//!
//! The slope at i_min: for in-plane strains (i_min the knot at 0) it is set to 0, as in the original materials,
//! so that f_k(0) = 0 is the minimum and the rest state z = 0 is an equilibrium of ψ along every in-plane axis.
//! Finite differences of g across a kink of Ψ̄ at 0 (a knit is far softer in compression than in tension) give a
//! slope there of the tension side's sign, and the cell on the compression side would dip below f₀. For bending
//! (i_min = argmin p) the slope is only limited by step 4 on the side its sign points to; the cell on the other
//! side then has slopes of opposite signs at its ends, and a cubic Hermite cell whose end slopes are (−, +) has a
//! quadratic derivative with exactly one root in the cell, so the spline stays quasi-convex (its minimum may sit
//! slightly off the knot).

use super::mls::{Mls1D, DEFAULT_BANDWIDTH_FACTOR};
use super::scalar::{linear, FitScalar, KinkRule, Kinks};
use super::symlog::{symexp_t, symlog_samples_t};
use super::FitError;
use crate::material::Hermite1D;

/// Where the minimum knot i_min is (step 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MinimumAt {
    /// the knot at 0 (in-plane strains s_x, s_a, s_y)
    Zero,
    /// the knot with the smallest value p (bending)
    Argmin,
}

/// Where the knot slopes pˣ come from (step 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlopeSource {
    /// central differences of g (the original's choice)
    FiniteDifference,
    /// the MLS of the sampled stresses dΨ/dX (envelope theorem), odd-symmetrised for s_a; needs the stresses
    Stress,
}

/// FIT1D parameters; [`Default`] gives the defaults for an in-plane strain (`docs/fitting.md`).
#[derive(Clone, Debug)]
pub struct Fit1DOptions {
    /// N_c, the knot count that sets the spacing h (default 11)
    pub n_knots: usize,
    /// MLS bandwidth in median sample spacings (default 2)
    pub bandwidth_factor: f64,
    /// ε = eps_rel · max|Ψ| in symlog (default 1e-3)
    pub eps_rel: f64,
    /// pˣ_min (default 0.001; 0.01 for stockinette-like patterns); must be > 0 so every cell off i_min has a
    /// non-zero secant
    pub min_slope: f64,
    /// use ½(MLS(u) + MLS(−u)) (the shear strain s_a)
    pub symmetric: bool,
    /// i_min rule (default the knot at 0)
    pub minimum: MinimumAt,
    /// central-difference step for the slopes, as a fraction of h (default 1e-3)
    pub fd_step: f64,
    /// slope source (default finite differences)
    pub slopes: SlopeSource,
    /// the knots' extent as a fraction of the sample range (step 2; default 0.95): beyond the last
    /// knot the term continues linearly
    pub extent: f64,
}

impl Default for Fit1DOptions {
    fn default() -> Self {
        Fit1DOptions {
            n_knots: 11,
            bandwidth_factor: DEFAULT_BANDWIDTH_FACTOR,
            eps_rel: 1e-3,
            min_slope: 1e-3,
            symmetric: false,
            minimum: MinimumAt::Zero,
            fd_step: 1e-3,
            slopes: SlopeSource::FiniteDifference,
            extent: 0.95,
        }
    }
}

/// Fit quality at the samples the term was fitted to (the spline plus [`Fit1D::offset`] against Ψ).
#[derive(Clone, Debug, PartialEq)]
pub struct Fit1DReport {
    /// samples used
    pub n_samples: usize,
    /// samples excluded because X or Ψ is not finite (failed solves)
    pub n_excluded: usize,
    /// √(Σ e²) / √(Σ Ψ²) over the used samples (e = fit − Ψ)
    pub rms_rel: f64,
    /// max |e| / max |Ψ|
    pub max_rel: f64,
    /// index of the minimum knot i_min
    pub i_min: usize,
}

/// A fitted 1D term: the residual spline (value 0 at x = 0), the constant removed in step 6, and the report.
#[derive(Clone, Debug)]
pub struct Fit1D {
    /// the residual spline (value 0 at x = 0)
    pub spline: Hermite1D,
    /// the constant removed in step 6 (J/m²; it belongs to f₀)
    pub offset: f64,
    /// the fit's report
    pub report: Fit1DReport,
    /// the smoothed curve g of step 1 at 201 points over the samples' range (for plots)
    pub curve: Vec<[f64; 2]>,
}

fn check_options(o: &Fit1DOptions) -> Result<(), FitError> {
    let bad = |s: String| Err(FitError::BadOption(s));
    if o.n_knots < 2 {
        return bad(format!("n_knots = {} (need ≥ 2)", o.n_knots));
    }
    if !(o.extent > 0.0 && o.extent <= 1.0) {
        return bad(format!("1D knot extent {} (need 0 < e ≤ 1)", o.extent));
    }
    super::check_common(o.eps_rel, o.min_slope, o.fd_step)
}

/// FIT1D on samples `x` (normalised strain) and `psi` (energy density). Samples where either is not finite are
/// excluded and counted. Errors: length mismatch, fewer than three distinct usable abscissae, invalid options, fewer
/// than two knots, or no knot at 0 when [`MinimumAt::Zero`] (the data must straddle 0).
pub fn fit1d(x: &[f64], psi: &[f64], opts: &Fit1DOptions) -> Result<Fit1D, FitError> {
    fit1d_with_stress(x, psi, None, opts)
}

/// The input checks of [`fit1d_with_stress`]: the stresses' length, stresses present when the slopes come from
/// them, the samples' lengths and the options.
fn check_inputs(
    x: &[f64],
    psi: &[f64],
    stress: Option<&[f64]>,
    opts: &Fit1DOptions,
) -> Result<(), FitError> {
    if let Some(st) = stress {
        if st.len() != x.len() {
            return Err(FitError::LengthMismatch {
                x: x.len(),
                psi: st.len(),
            });
        }
    }
    if opts.slopes == SlopeSource::Stress && stress.is_none() {
        return Err(FitError::BadOption(
            "slopes from stresses asked for, but the samples carry no stresses".into(),
        ));
    }
    if x.len() != psi.len() {
        return Err(FitError::LengthMismatch {
            x: x.len(),
            psi: psi.len(),
        });
    }
    check_options(opts)
}

/// Step 1: g(u) = symexp(MLS(u | X, symlog Ψ)), ε = `eps_rel` · max|Ψ|, symmetrised MLS for s_a. The MLS is
/// linear in the transformed values (the weights depend on X only), so it is applied to each part of them.
struct Smoothed<T> {
    mls: Mls1D,
    logs: Vec<Vec<f64>>,
    eps: T,
    symmetric: bool,
}

impl<T: FitScalar> Smoothed<T> {
    fn new(xs: &[f64], ys: &[T], opts: &Fit1DOptions, kinks: &mut Kinks) -> Result<Self, FitError> {
        let (eps, logs) = symlog_samples_t(ys, opts.eps_rel, kinks, |i| {
            format!("sample at X = {}", xs[i])
        });
        let re: Vec<f64> = logs.iter().map(|v| v.value()).collect();
        let mls = Mls1D::new(xs, &re, opts.bandwidth_factor)?;
        Ok(Smoothed {
            mls,
            logs: T::parts(&logs),
            eps,
            symmetric: opts.symmetric,
        })
    }

    fn g(&self, u: f64) -> T {
        let w: T = if self.symmetric {
            linear(&self.logs, |y| self.mls.eval_symmetric_with(u, y))
        } else {
            linear(&self.logs, |y| self.mls.eval_with(u, y))
        };
        symexp_t(w, self.eps)
    }
}

/// Step 2's knots: the multiples k h, k = k_lo..=k_hi, of h = e (hi − lo)/(N_c − 1) inside [e lo, e hi], e the
/// extent (default 0.95).
struct Knots {
    t: Vec<f64>,
    h: f64,
    k_lo: i64,
    k_hi: i64,
}

impl Knots {
    /// The knots for samples spanning [lo, hi]; an error when fewer than two multiples of h fit.
    fn new(lo: f64, hi: f64, n_knots: usize, extent: f64) -> Result<Knots, FitError> {
        let h = extent * (hi - lo) / (n_knots - 1) as f64;
        // a relative tolerance keeps a multiple that lands on the bound despite rounding
        let k_lo = (extent * lo / h - 1e-9).ceil() as i64;
        let k_hi = (extent * hi / h + 1e-9).floor() as i64;
        if k_hi - k_lo < 1 {
            return Err(FitError::Knots(format!(
                "fewer than two multiples of h = {h} in [{}, {}]",
                extent * lo,
                extent * hi
            )));
        }
        let t: Vec<f64> = (k_lo..=k_hi).map(|k| k as f64 * h).collect();
        Ok(Knots { t, h, k_lo, k_hi })
    }

    /// Step 3's i_min: the knot at 0 ([`MinimumAt::Zero`]; an error when there is none, the samples spanning
    /// [lo, hi]) or the knot with the smallest value `p` ([`MinimumAt::Argmin`]).
    fn minimum<T: FitScalar>(
        &self,
        rule: MinimumAt,
        p: &[T],
        (lo, hi): (f64, f64),
        kinks: &mut Kinks,
    ) -> Result<usize, FitError> {
        Ok(match rule {
            MinimumAt::Zero => {
                if self.k_lo > 0 || self.k_hi < 0 {
                    return Err(FitError::Knots(format!(
                        "no knot at 0: the samples span [{lo}, {hi}]"
                    )));
                }
                (-self.k_lo) as usize
            }
            MinimumAt::Argmin => {
                let b = (0..self.t.len()).fold(
                    0,
                    |b, i| {
                        if p[i].value() < p[b].value() {
                            i
                        } else {
                            b
                        }
                    },
                );
                for i in (0..p.len()).filter(|&i| i != b) {
                    kinks.tie(p[i], p[b], KinkRule::MinimumKnot, || {
                        format!("knots {b} and {i}")
                    });
                }
                b
            }
        })
    }
}

/// Step 2's slopes at the knots `t`: the MLS of the sampled stresses (its odd part for s_a) when
/// [`SlopeSource::Stress`], else central differences of g with step `d`.
fn knot_slopes<T: FitScalar>(
    g: &Smoothed<T>,
    t: &[f64],
    d: f64,
    (x, psi, stress): (&[f64], &[T], Option<&[T]>),
    opts: &Fit1DOptions,
) -> Result<Vec<T>, FitError> {
    Ok(match (opts.slopes, stress) {
        (SlopeSource::Stress, Some(st)) => {
            let (sx, sy): (Vec<f64>, Vec<T>) = (0..x.len())
                .filter(|&i| {
                    x[i].is_finite() && psi[i].value().is_finite() && st[i].value().is_finite()
                })
                .map(|i| (x[i], st[i]))
                .unzip();
            let re: Vec<f64> = sy.iter().map(|v| v.value()).collect();
            let ms = Mls1D::new(&sx, &re, opts.bandwidth_factor)?;
            let parts = T::parts(&sy);
            t.iter()
                .map(|&u| {
                    linear(&parts, |y| {
                        if opts.symmetric {
                            0.5 * (ms.eval_with(u, y) - ms.eval_with(-u, y))
                        } else {
                            ms.eval_with(u, y)
                        }
                    })
                })
                .collect()
        }
        _ => t
            .iter()
            .map(|&u| (g.g(u + d) - g.g(u - d)) / (2.0 * d))
            .collect(),
    })
}

/// Step 3: quasi-convexify outward from i_min, p_{i+1} ≥ pᵢ + (t_{i+1} − tᵢ) pˣ_min and pˣᵢ ≥ pˣ_min on the
/// right, mirrored on the left; the slope at i_min is set to 0 when `flat_minimum` (the in-plane strains).
fn quasi_convexify<T: FitScalar>(
    t: &[f64],
    (p, m): (&mut [T], &mut [T]),
    i_min: usize,
    (pmin, flat_minimum): (f64, bool),
    kinks: &mut Kinks,
) {
    let n = t.len();
    if flat_minimum {
        m[i_min] = T::from(0.0);
    }
    let knot = |i: usize| move || format!("knot {i}");
    let bound = T::from(pmin);
    for i in i_min + 1..n {
        p[i] = kinks.max(
            p[i],
            p[i - 1] + (t[i] - t[i - 1]) * pmin,
            KinkRule::QuasiConvexValue,
            knot(i),
        );
        m[i] = kinks.max(m[i], bound, KinkRule::QuasiConvexSlope, knot(i));
    }
    for i in (0..i_min).rev() {
        p[i] = kinks.max(
            p[i],
            p[i + 1] + (t[i + 1] - t[i]) * pmin,
            KinkRule::QuasiConvexValue,
            knot(i),
        );
        m[i] = kinks.min(m[i], -bound, KinkRule::QuasiConvexSlope, knot(i));
    }
}

/// Steps 5 and 4 (5 first: 4 never changes a slope's sign or lowers |slope| below 3 pˣ_min): the end slopes rise
/// outward, then Fritsch–Carlson, 0 ≤ α, β ≤ 3 on every cell, sides of i_min separately.
fn limit_slopes<T: FitScalar>(t: &[f64], p: &[T], m: &mut [T], pmin: f64, kinks: &mut Kinks) {
    let n = t.len();
    let bound = T::from(pmin);
    m[n - 1] = kinks.max(m[n - 1], bound, KinkRule::EndSlope, || {
        format!("knot {}", n - 1)
    });
    m[0] = kinks.min(m[0], -bound, KinkRule::EndSlope, || "knot 0".into());
    for c in 0..n - 1 {
        let secant = (p[c + 1] - p[c]) / (t[c + 1] - t[c]);
        let cap = secant.copysign_of(1.0) * 3.0;
        for i in [c, c + 1] {
            let site = || format!("knot {i}, cell {c}");
            // limit only slopes pointing the way the cell goes; the (−, +) cell at i_min is left as it is
            let (mi, s) = (m[i].value(), secant.value());
            if mi.abs() > cap.value() {
                kinks.tie(p[c + 1], p[c], KinkRule::FritschCarlsonSign, site);
            }
            if mi * s > 0.0 {
                kinks.tie(
                    m[i].copysign_of(1.0),
                    cap,
                    KinkRule::FritschCarlsonCap,
                    site,
                );
            }
            if mi * s > 0.0 && mi.abs() > cap.value() {
                m[i] = cap.copysign_of(mi);
            }
        }
    }
}

/// Step 6: the spline minus its value f(0), and f(0) (taken exactly at the knot 0, always there for in-plane
/// strains, else evaluated, extrapolating).
fn residual_form<T: FitScalar>(t: &[f64], p: &mut [T], m: &[T]) -> T {
    let offset = match t.iter().position(|&v| v == 0.0) {
        Some(i) => p[i],
        None => {
            let n = t.len();
            let pm: Vec<T> = p.iter().chain(m).copied().collect();
            linear(&T::parts(&pm), |c| {
                Hermite1D::new(t.to_vec(), c[..n].to_vec(), c[n..].to_vec()).eval2(0.0)[0]
            })
        }
    };
    for v in p.iter_mut() {
        *v -= offset;
    }
    offset
}

/// FIT1D steps 1–6 over a [`FitScalar`] (the knots, i_min and every branch decided on the real parts; `kinks`
/// records the decisions at their switching points).
pub(crate) struct Core1D<T> {
    pub(crate) t: Vec<f64>,
    pub(crate) p: Vec<T>,
    pub(crate) m: Vec<T>,
    pub(crate) offset: T,
    i_min: usize,
    /// the usable samples (X, real Ψ) and how many were excluded
    xs: Vec<f64>,
    ys: Vec<f64>,
    n_excluded: usize,
    g: Smoothed<T>,
    range: (f64, f64),
}

/// The core of [`fit1d_with_stress`] on scalars `psi` and `stress` (inputs checked by the caller).
pub(crate) fn fit1d_core<T: FitScalar>(
    x: &[f64],
    psi: &[T],
    stress: Option<&[T]>,
    opts: &Fit1DOptions,
    kinks: &mut Kinks,
) -> Result<Core1D<T>, FitError> {
    let (xs, ys): (Vec<f64>, Vec<T>) = x
        .iter()
        .zip(psi)
        .filter(|(a, b)| a.is_finite() && b.value().is_finite())
        .map(|(&a, &b)| (a, b))
        .unzip();
    let n_excluded = x.len() - xs.len();

    // step 1: g = symexp ∘ MLS ∘ symlog
    let g = Smoothed::new(&xs, &ys, opts, kinks)?;

    // step 2: knots at multiples of h inside [0.95 min X, 0.95 max X], p = g(t), slopes
    let (lo, hi) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let knots = Knots::new(lo, hi, opts.n_knots, opts.extent)?;
    let t = knots.t.clone();
    let mut p: Vec<T> = t.iter().map(|&u| g.g(u)).collect();
    let d = opts.fd_step * knots.h;
    let mut m = knot_slopes(&g, &t, d, (x, psi, stress), opts)?;
    if p.iter().chain(&m).any(|v| !v.value().is_finite()) {
        return Err(FitError::BadOption(
            "the MLS curve overflowed (Ψ too large for symexp)".into(),
        ));
    }

    // step 3: quasi-convexify outward from i_min
    let i_min = knots.minimum(opts.minimum, &p, (lo, hi), kinks)?;
    let pmin = opts.min_slope;
    let flat = opts.minimum == MinimumAt::Zero;
    quasi_convexify(&t, (&mut p, &mut m), i_min, (pmin, flat), kinks);

    // steps 5 and 4: end slopes, Fritsch–Carlson
    limit_slopes(&t, &p, &mut m, pmin, kinks);

    // step 6: residual form
    let offset = residual_form(&t, &mut p, &m);
    Ok(Core1D {
        t,
        p,
        m,
        offset,
        i_min,
        xs,
        ys: ys.iter().map(|v| v.value()).collect(),
        n_excluded,
        g,
        range: (lo, hi),
    })
}

/// [`fit1d`] with the sampled stresses dΨ/dX (same length as `x`; non-finite entries are dropped with their
/// sample), used for the slopes when `opts.slopes` is [`SlopeSource::Stress`]: pˣ = MLS(t | X, dΨ/dX), the odd part
/// ½(MLS(t) − MLS(−t)) for s_a. An error when stresses are asked for but not given.
pub fn fit1d_with_stress(
    x: &[f64],
    psi: &[f64],
    stress: Option<&[f64]>,
    opts: &Fit1DOptions,
) -> Result<Fit1D, FitError> {
    check_inputs(x, psi, stress, opts)?;
    let core = fit1d_core(x, psi, stress, opts, &mut Kinks::off())?;
    let (lo, hi) = core.range;
    let curve: Vec<[f64; 2]> = (0..=200)
        .map(|i| {
            let u = lo + (hi - lo) * i as f64 / 200.0;
            [u, core.g.g(u)]
        })
        .collect();
    let spline = Hermite1D::new(core.t, core.p, core.m);
    let (offset, xs, ys) = (core.offset, core.xs, core.ys);

    // report
    let mut err = super::RelError::default();
    for (&xv, &yv) in xs.iter().zip(&ys) {
        err.add(spline.eval2(xv)[0] + offset, yv);
    }
    let report = Fit1DReport {
        n_samples: xs.len(),
        n_excluded: core.n_excluded,
        rms_rel: err.rms_rel(),
        max_rel: err.max_rel(),
        i_min: core.i_min,
    };
    Ok(Fit1D {
        spline,
        offset,
        report,
        curve,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples(f: impl Fn(f64) -> f64, lo: f64, hi: f64, n: usize) -> (Vec<f64>, Vec<f64>) {
        let x: Vec<f64> = (0..n)
            .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
            .collect();
        let y = x.iter().map(|&v| f(v)).collect();
        (x, y)
    }

    #[test]
    fn knots_are_multiples_of_h_with_zero() {
        let (x, y) = samples(|v| v * v, -0.5, 1.0, 61);
        let fit = fit1d(&x, &y, &Fit1DOptions::default()).unwrap();
        let h = 0.95 * 1.5 / 10.0;
        let t = &fit.spline.t;
        assert!(t
            .iter()
            .all(|&v| (0.95 * -0.5 - 1e-12..=0.95 + 1e-12).contains(&v)));
        for (i, v) in t.iter().enumerate() {
            assert!(((v / h) - (v / h).round()).abs() < 1e-9, "knot {i} = {v}");
        }
        assert_eq!(t[fit.report.i_min], 0.0);
        assert_eq!(fit.spline.p[fit.report.i_min], 0.0);
        // multiples k h with k = −3..=6 (0.95 · −0.5 / h = −3.33, 0.95 / h = 6.67)
        assert_eq!(t.len(), 10);
        assert!((t[0] + 3.0 * h).abs() < 1e-15 && (t[9] - 6.0 * h).abs() < 1e-15);
    }

    #[test]
    fn nan_samples_are_excluded_and_counted() {
        let (mut x, mut y) = samples(|v| v * v + v.powi(4), -1.0, 1.0, 81);
        y[3] = f64::NAN;
        x[10] = f64::INFINITY;
        let fit = fit1d(&x, &y, &Fit1DOptions::default()).unwrap();
        assert_eq!(fit.report.n_excluded, 2);
        assert_eq!(fit.report.n_samples, 79);
        assert!(fit.report.max_rel < 1e-2, "{:?}", fit.report);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let o = Fit1DOptions::default();
        assert!(fit1d(&[0.0, 1.0], &[0.0], &o).is_err());
        assert!(matches!(
            fit1d(&[0.0, 1.0, f64::NAN], &[0.0, 1.0, 2.0], &o),
            Err(FitError::TooFewSamples { .. })
        ));
        // no knot at 0 for an in-plane strain
        let (x, y) = samples(|v| v * v, 0.5, 1.0, 20);
        assert!(matches!(fit1d(&x, &y, &o), Err(FitError::Knots(_))));
        // but fine for bending (argmin)
        let ob = Fit1DOptions {
            minimum: MinimumAt::Argmin,
            ..o.clone()
        };
        let (x, y) = samples(|v| (v - 3.0).powi(2), 2.0, 4.0, 201);
        let fit = fit1d(&x, &y, &ob).unwrap();
        // knots span [1.9, 3.8]; the linear extrapolation to X = 4 costs ≈ 4 % of max Ψ there
        assert!(fit.report.max_rel < 0.05, "{:?}", fit.report);
        let s = &fit.spline;
        // (0.95 min X = 1.9 lies outside the data, so the first knot is an MLS extrapolation: skip it)
        for i in (0..s.t.len()).filter(|&i| s.t[i] >= 2.0) {
            // (3e-3 of max Ψ = 1: near the zero minimum symlog is sharp on the 0.01 sample spacing)
            // p is residual: the offset f(0) (from the linear extrapolation to 0) goes back in
            let want = (s.t[i] - 3.0).powi(2);
            let got = s.p[i] + fit.offset;
            assert!(
                (got - want).abs() < 3e-3,
                "knot {}: {got} vs {want}",
                s.t[i]
            );
        }
        for bad in [
            Fit1DOptions {
                n_knots: 1,
                ..o.clone()
            },
            Fit1DOptions {
                eps_rel: 0.0,
                ..o.clone()
            },
            Fit1DOptions {
                min_slope: f64::NAN,
                ..o.clone()
            },
            Fit1DOptions {
                fd_step: 0.0,
                ..o.clone()
            },
            Fit1DOptions {
                bandwidth_factor: -1.0,
                ..o.clone()
            },
            Fit1DOptions {
                extent: 1.5,
                ..o.clone()
            },
        ] {
            assert!(matches!(fit1d(&x, &y, &bad), Err(FitError::BadOption(_))));
        }
    }

    #[test]
    fn slopes_from_stresses() {
        let f = |v: f64| v * v + 0.5 * v.powi(4);
        let df = |v: f64| 2.0 * v + 2.0 * v.powi(3);
        let (x, y) = samples(f, -1.0, 1.0, 41);
        let st: Vec<f64> = x.iter().map(|&v| df(v)).collect();
        let o = Fit1DOptions {
            slopes: SlopeSource::Stress,
            ..Fit1DOptions::default()
        };
        assert!(fit1d(&x, &y, &o).is_err(), "stress slopes need stresses");
        let fit = fit1d_with_stress(&x, &y, Some(&st), &o).unwrap();
        let s = &fit.spline;
        // interior knots keep the sampled derivative (the Fritsch–Carlson caps are not active on this convex data)
        for i in 1..s.t.len() - 1 {
            assert!(
                (s.m[i] - df(s.t[i])).abs() < 2e-3,
                "knot {}: {} vs {}",
                s.t[i],
                s.m[i],
                df(s.t[i])
            );
        }
    }

    #[test]
    fn shear_fit_is_even() {
        let (x, y) = samples(
            |v| 2.0 * v * v + 0.3 * v.powi(3) + v.powi(4),
            -1.0,
            1.0,
            101,
        );
        let o = Fit1DOptions {
            symmetric: true,
            ..Fit1DOptions::default()
        };
        let s = fit1d(&x, &y, &o).unwrap().spline;
        for u in [0.1, 0.37, 0.8] {
            let (a, b) = (s.eval2(u)[0], s.eval2(-u)[0]);
            assert!((a - b).abs() < 1e-9 * a.abs(), "{u}: {a} vs {b}");
        }
    }
}
