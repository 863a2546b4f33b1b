//! FIT2D (`docs/fitting.md`, "Fitting (C5, C6, C7)", FIT2D steps 1–7, and a step 8 of ours): one 2D term f_kl of the material
//! from samples (X, Y, Ψ) of its 2D grid (X, Y already normalised by the strain scales).
//!
//! 1. g(u, v) = symexp(MLS(u, v | X, Y, symlog Ψ)) with a 2D local-quadratic MLS ([`Mls2D`]), symmetrised in the
//!    axis that is s_a.
//! 2. Knots per axis: linspace on [e·min, 0] and on [0, e·max] sharing 0 (e = `extent`, 0.9; 0.3 for
//!    stockinette-like patterns). The axis's `n_knots − 1` intervals are split between the two sides in proportion
//!    to their lengths, at least one per non-empty side (this reproduces the knot layout of the original
//!    materials, e.g. 1 + 6 intervals for s_x on [−0.1, 0.84]). p = g at the knots; pˣ, pʸ, pˣʸ by central
//!    differences of g (step `fd_step` × the smallest knot spacing of the axis).
//! 3. Quasi-convexification (not for (s_x, s_y)): i_min = the knot u = 0; j_min = the knot v = 0 for an in-plane
//!    second strain, else argmin_j p(0, v_j). Rows are processed outward from j_min and each row outward from
//!    i_min, raising every value to p ≥ (its inner neighbour along the row) + Δu pˣ_min and ≥ (its inner
//!    neighbour along the column) + Δv pˣ_min; both inner neighbours are final when a value is visited, so both
//!    conditions hold at the end. Slopes: pˣ ≥ pˣ_min right of i_min (≤ −pˣ_min left of it), pʸ likewise about
//!    j_min.
//! 4. Increasing extrapolation: boundary pˣ (first/last column) clamped to ≤ −pˣ_min / ≥ pˣ_min, boundary pʸ
//!    likewise, pˣʸ = 0 on the boundary.
//! 5. Monotone bicubic correction: Fritsch–Carlson along every row (pˣ) and column (pʸ): a slope is capped at
//!    3 |secant| of each adjacent cell it agrees with, and set to 0 where it disagrees in sign (the minimum knot
//!    exempt, as in FIT1D); along grid lines the bicubic is exactly these 1D Hermite cubics, so it is monotone
//!    along every grid line outward from the minimum. Inside the patches monotonicity also depends on the twists
//!    pˣʸ and on how the cross slopes vary. Carlson & Fritsch (1985) give sufficient conditions; not having them,
//!    we check the sign of ∂f/∂u (∂f/∂v) on the whole of every patch not touching the minimum's column (row),
//!    certified on the Bernstein–Bézier coefficients of the derivative with adaptive subdivision (a sample of
//!    the patch is not enough: where a grid line's slope is ≈ 0 at one end of a cell and 3 × its secant at the
//!    other, as Fritsch–Carlson allows, ∂f/∂u vanishes quadratically towards that edge along the rows while the
//!    interior's cross terms vanish only linearly, so f can fall in a thin strip along the edge; a 7 × 7 sample
//!    missed one with s > 0.84), and halve the four corner twists of each failing patch, up to 40 rounds. A twist-free patch can still be non-monotone in u when pʸ
//!    varies strongly along u, so then (up to 60 rounds) the corners of each failing patch get pˣʸ = 0 and |pʸ|
//!    (for a failure along u; |pˣ| along v) halved, never below pˣ_min and never changing sign, which keeps the
//!    grid lines monotone; in the limit (all cross slopes ±pˣ_min) the offending term vanishes. Patches that
//!    still fail are counted in the report, not hidden.
//! 6. Residual: r(u, v) = f(u, v) − f(u, 0) − f(0, v) + f(0, 0), i.e. on the knots p − p(·, 0) − p(0, ·) + p(0, 0),
//!    pˣ − pˣ(·, 0), pʸ − pʸ(0, ·) and pˣʸ unchanged. This is exact as a function (f(u, 0) and f(0, v) are
//!    bicubics themselves), so r vanishes identically on both axes, extrapolation included.
//! 7. Zero-compression residual (not for (s_x, s_y)): on a stretch axis (s_x or s_y), every knot with that
//!    coordinate ≤ 0 gets p = pˣ = pʸ = pˣʸ = 0. Including the knot at 0 (where p and the along-axis slope are
//!    already 0) makes r vanish on the whole compressed half-plane, not only at its knots; the original keeps a
//!    non-zero twist there.
//! 8. Bounded extrapolation (our addition): the residual's slope across the boundary of the knot box is set to 0
//!    (pˣ on the first and last knot column, pʸ on the first and last row), so r continues as a constant beyond
//!    the sampled box and only the 1D terms, which rise outward, extrapolate. Without it the linear continuation
//!    of r, the difference of two fits' boundary slopes, can fall faster than the 1D terms rise, and ψ gets a well
//!    of negative energy beyond the sampled box that a simulation can fall into. The changed slopes only reshape
//!    the boundary patches, which the report's errors include.
//!
//! The unconverted spline f of step 5 is returned too ([`Fit2D::full`]): its errors against the samples are the
//! fit's own quality; the material uses the residual.

use super::fit1d::MinimumAt;
use super::mls::{Mls2D, DEFAULT_BANDWIDTH_FACTOR};
use super::scalar::{FitScalar, KinkRule, Kinks};
use super::symlog::{symexp_t, symlog_samples_t};
use super::FitError;
use crate::material::Hermite2D;
use certify::nonnegative;

/// FIT2D parameters; [`Default`] gives the defaults for a pair of in-plane strains other than s_a.
#[derive(Clone, Debug)]
pub struct Fit2DOptions {
    /// knots per axis (u, v) including 0 (default 9 each; the original uses 8–10)
    pub n_knots: [usize; 2],
    /// e: knots span [e·min, e·max] of the data (default 0.9; 0.3 for stockinette-like patterns)
    pub extent: f64,
    /// MLS bandwidth in median sample spacings (default 2)
    pub bandwidth_factor: f64,
    /// ε = eps_rel · max|Ψ| in symlog (default 1e-3)
    pub eps_rel: f64,
    /// pˣ_min (default 0.001; 0.01 for stockinette-like patterns), > 0
    pub min_slope: f64,
    /// symmetrise the MLS in u and/or v (the axis that is s_a)
    pub symmetric: [bool; 2],
    /// steps 3 and 7 (false for (s_x, s_y))
    pub quasi_convex: bool,
    /// j_min rule: the knot v = 0 (in-plane second strain) or argmin along u = 0 (bending)
    pub minimum_v: MinimumAt,
    /// axes that are stretches (s_x, s_y): their compressed side is zeroed in step 7
    pub stretch: [bool; 2],
    /// central-difference step as a fraction of the smallest knot spacing (default 1e-3)
    pub fd_step: f64,
    /// after the twists, also shrink the cross slopes of failing patches until every patch is monotone (default
    /// true); false stops after the twists and only counts the failing patches
    pub strict_patches: bool,
    /// step 7′ instead of step 7 ([`compression`]): the residual on the compressed half-plane of a stretch axis
    /// kept as a non-negative excess, monotone outward from the axes (default false: zeroed)
    pub compression_residual: bool,
}

impl Default for Fit2DOptions {
    fn default() -> Self {
        Fit2DOptions {
            n_knots: [9, 9],
            extent: 0.9,
            bandwidth_factor: DEFAULT_BANDWIDTH_FACTOR,
            eps_rel: 1e-3,
            min_slope: 1e-3,
            symmetric: [false, false],
            quasi_convex: true,
            minimum_v: MinimumAt::Zero,
            stretch: [false, false],
            fd_step: 1e-3,
            strict_patches: true,
            compression_residual: false,
        }
    }
}

/// Fit quality of the unconverted spline f at the samples it was fitted to.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit2DReport {
    /// samples used
    pub n_samples: usize,
    /// samples excluded because a coordinate or Ψ is not finite (failed solves)
    pub n_excluded: usize,
    /// √(Σ e²) / √(Σ Ψ²), e = f − Ψ
    pub rms_rel: f64,
    /// max |e| / max |Ψ|
    pub max_rel: f64,
    /// minimum knot (i_min along u, j_min along v)
    pub i_min: usize,
    /// (j_min along v)
    pub j_min: usize,
    /// rounds of twist halving that step 5 needed
    pub twist_rounds: usize,
    /// rounds of cross-slope shrinking that step 5 needed after the twists
    pub slope_rounds: usize,
    /// patches still failing the monotonicity check of step 5
    pub nonmonotone_patches: usize,
    /// patches of the compressed block still failing step 7′'s check (0 without it)
    pub compression_nonmonotone: usize,
}

/// A fitted 2D term: the residual spline the material uses, the unconverted spline f, and the report.
#[derive(Clone, Debug)]
pub struct Fit2D {
    /// the residual r(u, v) = f(u, v) − f(u, 0) − f(0, v) + f(0, 0) after steps 6–8, which the material uses
    pub residual: Hermite2D,
    /// the unconverted spline f of step 5
    pub full: Hermite2D,
    /// the fit's report
    pub report: Fit2DReport,
}

/// Knots of one axis (step 2) for data spanning [lo, hi].
pub fn axis_knots(lo: f64, hi: f64, n: usize, extent: f64) -> Result<Vec<f64>, FitError> {
    let (a, b) = (extent * lo.min(0.0), extent * hi.max(0.0));
    let sides = usize::from(a < 0.0) + usize::from(b > 0.0);
    if sides == 0 || n < sides + 1 {
        return Err(FitError::Knots(format!(
            "{n} knots cannot cover [{a}, 0] and [0, {b}] (data [{lo}, {hi}])"
        )));
    }
    let intervals = n - 1;
    let mut left = if a < 0.0 {
        ((intervals as f64 * -a / (b - a)).round() as usize).max(1)
    } else {
        0
    };
    if b > 0.0 {
        left = left.min(intervals - 1);
    } else {
        left = intervals;
    }
    let right = intervals - left;
    let mut t: Vec<f64> = (0..left)
        .map(|i| a * (left - i) as f64 / left as f64)
        .collect();
    t.push(0.0);
    t.extend((1..=right).map(|i| b * i as f64 / right as f64));
    Ok(t)
}

fn check_options(o: &Fit2DOptions) -> Result<(), FitError> {
    let bad = |s: String| Err(FitError::BadOption(s));
    if o.n_knots.iter().any(|&n| n < 3) {
        return bad(format!("n_knots = {:?} (need ≥ 3 per axis)", o.n_knots));
    }
    if !(o.extent.is_finite() && o.extent > 0.0 && o.extent <= 1.0) {
        return bad(format!("extent = {} (need in (0, 1])", o.extent));
    }
    super::check_common(o.eps_rel, o.min_slope, o.fd_step)
}

/// Fritsch–Carlson limits along one grid line (step 5): `p`, `m` are the values and slopes at `t`; `min` is the
/// minimum knot whose slope keeps its sign. The decisions are taken on the real parts; `site(i)` names knot `i`
/// of the line for the kink report.
fn limit_line<T: FitScalar>(
    t: &[f64],
    p: &[T],
    m: &mut [T],
    min: Option<usize>,
    kinks: &mut Kinks,
    site: &dyn Fn(usize) -> String,
) {
    let zero = T::from(0.0);
    for c in 0..t.len() - 1 {
        let secant = (p[c + 1] - p[c]) / (t[c + 1] - t[c]);
        let cap = secant.copysign_of(1.0) * 3.0;
        for i in [c, c + 1] {
            let (mi, s) = (m[i].value(), secant.value());
            let agrees = mi * s > 0.0;
            // where the secant is 0 the sign test switches between keeping the slope (or its cap) and 0
            if min != Some(i) || mi.abs() > cap.value() {
                kinks.tie(p[c + 1], p[c], KinkRule::FritschCarlsonSign, || site(i));
            }
            if min != Some(i) {
                kinks.tie(m[i], zero, KinkRule::FritschCarlsonSign, || site(i));
            }
            if agrees {
                kinks.tie(
                    m[i].copysign_of(1.0),
                    cap,
                    KinkRule::FritschCarlsonCap,
                    || site(i),
                );
            }
            if min == Some(i) {
                if agrees && mi.abs() > (3.0 * s.abs()) {
                    m[i] = cap.copysign_of(mi);
                }
            } else if mi * s <= 0.0 {
                m[i] = zero;
            } else if mi.abs() > (3.0 * s.abs()) {
                m[i] = cap.copysign_of(mi);
            }
        }
    }
}

/// A patch failing the interior monotonicity check, and in which direction.
struct Failing {
    cell: (usize, usize),
    along_u: bool,
    along_v: bool,
}

/// Grid data of a bicubic Hermite spline with u inner: index j·nu + i.
#[derive(Clone)]
pub(crate) struct Grid<T = f64> {
    tu: Vec<f64>,
    tv: Vec<f64>,
    pub(crate) p: Vec<T>,
    pub(crate) mu: Vec<T>,
    pub(crate) mv: Vec<T>,
    pub(crate) muv: Vec<T>,
}

impl<T: FitScalar> Grid<T> {
    fn at(&self, i: usize, j: usize) -> usize {
        j * self.tu.len() + i
    }

    /// The spline of the real parts.
    fn spline(&self) -> Hermite2D {
        let re = |a: &[T]| a.iter().map(|v| v.value()).collect::<Vec<f64>>();
        Hermite2D::new(
            self.tu.clone(),
            self.tv.clone(),
            re(&self.p),
            re(&self.mu),
            re(&self.mv),
            re(&self.muv),
        )
    }

    /// The Bézier control net `b[a][b]` of patch `(ci, cj)` (a along u, b along v): on the patch the bicubic is
    /// Σ b[a][b] B³_a(s) B³_b(t) with s, t ∈ [0, 1] the local coordinates and B³ the cubic Bernstein polynomials.
    /// Per axis the Hermite data (p₀, p₁, h m₀, h m₁) of a cubic have the net (p₀, p₀ + h m₀/3, p₁ − h m₁/3, p₁);
    /// the patch's net is the tensor product of that map applied to its 16 Hermite data.
    fn bezier_net(&self, (ci, cj): (usize, usize)) -> [[f64; 4]; 4] {
        const THIRD: f64 = 1.0 / 3.0;
        // rows: net points; columns: weights of (p₀, p₁, h m₀, h m₁)
        const M: [[f64; 4]; 4] = [
            [1.0, 0.0, 0.0, 0.0],
            [1.0, 0.0, THIRD, 0.0],
            [0.0, 1.0, 0.0, -THIRD],
            [0.0, 1.0, 0.0, 0.0],
        ];
        let (hu, hv) = (self.tu[ci + 1] - self.tu[ci], self.tv[cj + 1] - self.tv[cj]);
        // g[k][l]: k over (p at ci, p at ci + 1, hu pˣ at ci, hu pˣ at ci + 1), l likewise along v
        let mut g = [[0.0; 4]; 4];
        for (k, row) in g.iter_mut().enumerate() {
            for (l, gkl) in row.iter_mut().enumerate() {
                let idx = self.at(ci + k % 2, cj + l % 2);
                *gkl = match (k >= 2, l >= 2) {
                    (false, false) => self.p[idx].value(),
                    (true, false) => hu * self.mu[idx].value(),
                    (false, true) => hv * self.mv[idx].value(),
                    (true, true) => hu * hv * self.muv[idx].value(),
                };
            }
        }
        let mut net = [[0.0; 4]; 4];
        for (a, row) in net.iter_mut().enumerate() {
            for (b, nab) in row.iter_mut().enumerate() {
                for k in 0..4 {
                    for l in 0..4 {
                        *nab += M[a][k] * g[k][l] * M[b][l];
                    }
                }
            }
        }
        net
    }

    /// Patches failing the interior monotonicity check of step 5: the sign of ∂f/∂u (∂f/∂v) on the whole of every
    /// patch not touching the minimum's column (row), certified by [`nonnegative`] on the Bernstein coefficients
    /// of the derivative (not sampled: a sign change can hide between any finite set of samples, e.g. within
    /// 1/20 of a patch from an edge where the grid line's slope is ≈ 0).
    fn failing_patches(&self, i_min: usize, j_min: usize) -> Vec<Failing> {
        let scale = self
            .p
            .iter()
            .fold(0.0f64, |m, v| m.max(v.value().abs()))
            .max(1e-300);
        // on ∂f/∂s = h_u ∂f/∂u (∂f/∂t = h_v ∂f/∂v): a drop of at most 1e-10 of the largest value across a patch
        let tol = 1e-10 * scale;
        let (nu, nv) = (self.tu.len(), self.tv.len());
        let mut out = Vec::new();
        for cj in 0..nv - 1 {
            for ci in 0..nu - 1 {
                let sx = if ci < i_min { -1.0 } else { 1.0 };
                let sy = if cj < j_min { -1.0 } else { 1.0 };
                let check_x = ci != i_min && ci + 1 != i_min;
                let check_y = cj != j_min && cj + 1 != j_min;
                if !(check_x || check_y) {
                    continue;
                }
                let (fx, fy) =
                    self.patch_fails((ci, cj), check_x.then_some(sx), check_y.then_some(sy), tol);
                if fx || fy {
                    out.push(Failing {
                        cell: (ci, cj),
                        along_u: fx,
                        along_v: fy,
                    });
                }
            }
        }
        out
    }

    /// Whether patch `(ci, cj)` fails the outward monotonicity certificate along u (sign `su`) and along v (sign
    /// `sv`), `None` for a direction not checked; the Bernstein coefficients of
    /// the outward derivative have their first index along the derivative (degree 2), the second across (degree 3).
    fn patch_fails(
        &self,
        cell: (usize, usize),
        su: Option<f64>,
        sv: Option<f64>,
        tol: f64,
    ) -> (bool, bool) {
        let net = self.bezier_net(cell);
        let mut du = [[0.0; 4]; 3];
        let mut dv = [[0.0; 4]; 3];
        for a in 0..3 {
            for b in 0..4 {
                du[a][b] = su.unwrap_or(0.0) * 3.0 * (net[a + 1][b] - net[a][b]);
                dv[a][b] = sv.unwrap_or(0.0) * 3.0 * (net[b][a + 1] - net[b][a]);
            }
        }
        (
            su.is_some() && !nonnegative(&du, tol),
            sv.is_some() && !nonnegative(&dv, tol),
        )
    }
}

/// The minimum knot of step 3 (i_min along u, j_min along v) and the knot v = 0 (j0), about which step 6 takes
/// the residual (i_min is the knot u = 0).
struct Minimum {
    i: usize,
    j: usize,
    j0: usize,
}

/// What the patch fixes of step 5 needed: rounds of twist halving, rounds of cross-slope shrinking, and the
/// patches still failing the check.
#[derive(Default)]
struct PatchRounds {
    twist: usize,
    slope: usize,
    nonmonotone: usize,
}

/// Step 1: g(u, v) = symexp(MLS(u, v | X, Y, symlog Ψ)), symmetrised in the axes that are s_a. The MLS is linear
/// in the transformed values, so it is applied to each part of them (one QR per point).
struct Smoothed<T> {
    mls: Mls2D,
    logs: Vec<Vec<f64>>,
    eps: T,
    symmetric: [bool; 2],
}

impl<T: FitScalar> Smoothed<T> {
    fn new(
        (xs, ys, fs): (&[f64], &[f64], &[T]),
        opts: &Fit2DOptions,
        kinks: &mut Kinks,
    ) -> Result<Self, FitError> {
        let (eps, logs) = symlog_samples_t(fs, opts.eps_rel, kinks, |i| {
            format!("sample at ({}, {})", xs[i], ys[i])
        });
        let re: Vec<f64> = logs.iter().map(|v| v.value()).collect();
        let mls = Mls2D::new(xs, ys, &re, opts.bandwidth_factor)?;
        Ok(Smoothed {
            mls,
            logs: T::parts(&logs),
            eps,
            symmetric: opts.symmetric,
        })
    }

    fn g(&self, u: f64, v: f64) -> T {
        let [su, sv] = self.symmetric;
        let fs: Vec<&[f64]> = self.logs.iter().map(|y| y.as_slice()).collect();
        let w = T::from_parts(&self.mls.eval_symmetric_with(u, v, su, sv, &fs));
        symexp_t(w, self.eps)
    }
}

/// The samples where x, y and Ψ are all finite, in their order.
fn usable_samples<T: FitScalar>(x: &[f64], y: &[f64], psi: &[T]) -> (Vec<f64>, Vec<f64>, Vec<T>) {
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    let mut fs = Vec::new();
    for i in 0..psi.len() {
        if x[i].is_finite() && y[i].is_finite() && psi[i].value().is_finite() {
            xs.push(x[i]);
            ys.push(y[i]);
            fs.push(psi[i]);
        }
    }
    (xs, ys, fs)
}

/// The knot indices of a line of `n` knots in the order step 3 visits them: `c`, then outward to the right, then
/// outward to the left.
fn outward(n: usize, c: usize) -> Vec<usize> {
    let mut o = vec![c];
    o.extend(c + 1..n);
    o.extend((0..c).rev());
    o
}

impl<T: FitScalar> Grid<T> {
    /// Step 2: the knots of both axes over the samples' ranges, p = g at the knots and pˣ, pʸ, pˣʸ by central
    /// differences of g (step `fd_step` × the smallest knot spacing of the axis). An error when g is not finite
    /// at a knot.
    fn sample(
        g: &Smoothed<T>,
        xs: &[f64],
        ys: &[f64],
        opts: &Fit2DOptions,
    ) -> Result<Grid<T>, FitError> {
        let range = |d: &[f64]| {
            d.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                    (l.min(v), h.max(v))
                })
        };
        let (xl, xh) = range(xs);
        let (yl, yh) = range(ys);
        let tu = axis_knots(xl, xh, opts.n_knots[0], opts.extent)?;
        let tv = axis_knots(yl, yh, opts.n_knots[1], opts.extent)?;
        let (nu, nv) = (tu.len(), tv.len());
        let min_gap = |t: &[f64]| {
            t.windows(2)
                .map(|w| w[1] - w[0])
                .fold(f64::INFINITY, f64::min)
        };
        let du = opts.fd_step * min_gap(&tu);
        let dv = opts.fd_step * min_gap(&tv);
        let zero = T::from(0.0);
        let mut grid = Grid {
            p: vec![zero; nu * nv],
            mu: vec![zero; nu * nv],
            mv: vec![zero; nu * nv],
            muv: vec![zero; nu * nv],
            tu,
            tv,
        };
        let g = |u: f64, v: f64| g.g(u, v);
        for j in 0..nv {
            for i in 0..nu {
                let (u, v) = (grid.tu[i], grid.tv[j]);
                let k = grid.at(i, j);
                grid.p[k] = g(u, v);
                grid.mu[k] = (g(u + du, v) - g(u - du, v)) / (2.0 * du);
                grid.mv[k] = (g(u, v + dv) - g(u, v - dv)) / (2.0 * dv);
                grid.muv[k] = (g(u + du, v + dv) - g(u + du, v - dv) - g(u - du, v + dv)
                    + g(u - du, v - dv))
                    / (4.0 * du * dv);
            }
        }
        if [&grid.p, &grid.mu, &grid.mv, &grid.muv]
            .iter()
            .any(|a| a.iter().any(|v| !v.value().is_finite()))
        {
            return Err(FitError::BadOption(
                "the MLS surface is not finite at the knots (Ψ too large for symexp, or too few samples near a knot)"
                    .into(),
            ));
        }
        Ok(grid)
    }

    /// Step 3's minimum knot: i_min = the knot u = 0; j_min = the knot v = 0 ([`MinimumAt::Zero`]) or argmin_j
    /// p(0, v_j) ([`MinimumAt::Argmin`]).
    fn minimum(&self, rule: MinimumAt, kinks: &mut Kinks) -> Minimum {
        let nv = self.tv.len();
        let i_min = self.tu.iter().position(|&t| t == 0.0).unwrap_or(0);
        let j0 = self.tv.iter().position(|&t| t == 0.0).unwrap_or(0);
        let j_min = match rule {
            MinimumAt::Zero => j0,
            MinimumAt::Argmin => {
                let pj = |j: usize| self.p[self.at(i_min, j)];
                let b = (0..nv).fold(0, |b, j| if pj(j).value() < pj(b).value() { j } else { b });
                for j in (0..nv).filter(|&j| j != b) {
                    kinks.tie(pj(j), pj(b), KinkRule::MinimumKnot, || {
                        format!("knots ({i_min}, {b}) and ({i_min}, {j})")
                    });
                }
                b
            }
        };
        Minimum {
            i: i_min,
            j: j_min,
            j0,
        }
    }

    /// Step 3: rows outward from j_min, each row outward from i_min, every value raised to ≥ its inner neighbours
    /// along the row and the column plus their distance × pˣ_min; slopes pointing away from the minimum are at
    /// least pˣ_min.
    fn quasi_convexify(&mut self, min: &Minimum, pmin: f64, kinks: &mut Kinks) {
        let (i_min, j_min) = (min.i, min.j);
        let (nu, nv) = (self.tu.len(), self.tv.len());
        let bound = T::from(pmin);
        let (qv, qs) = (KinkRule::QuasiConvexValue, KinkRule::QuasiConvexSlope);
        for &j in &outward(nv, j_min) {
            for &i in &outward(nu, i_min) {
                let k = self.at(i, j);
                let site = || format!("knot ({i}, {j})");
                let mut v = self.p[k];
                if i != i_min {
                    let ii = if i > i_min { i - 1 } else { i + 1 };
                    let w = self.p[self.at(ii, j)] + (self.tu[i] - self.tu[ii]).abs() * pmin;
                    v = kinks.max(v, w, qv, site);
                    self.mu[k] = if i > i_min {
                        kinks.max(self.mu[k], bound, qs, site)
                    } else {
                        kinks.min(self.mu[k], -bound, qs, site)
                    };
                }
                if j != j_min {
                    let jj = if j > j_min { j - 1 } else { j + 1 };
                    let w = self.p[self.at(i, jj)] + (self.tv[j] - self.tv[jj]).abs() * pmin;
                    v = kinks.max(v, w, qv, site);
                    self.mv[k] = if j > j_min {
                        kinks.max(self.mv[k], bound, qs, site)
                    } else {
                        kinks.min(self.mv[k], -bound, qs, site)
                    };
                }
                self.p[k] = v;
            }
        }
    }

    /// Step 4: boundary pˣ (first/last column) clamped to ≤ −pˣ_min / ≥ pˣ_min, boundary pʸ likewise, pˣʸ = 0 on
    /// the boundary.
    fn clamp_boundary(&mut self, pmin: f64, kinks: &mut Kinks) {
        let (nu, nv) = (self.tu.len(), self.tv.len());
        let (bound, e) = (T::from(pmin), KinkRule::EndSlope);
        for j in 0..nv {
            let (a, b) = (self.at(0, j), self.at(nu - 1, j));
            self.mu[a] = kinks.min(self.mu[a], -bound, e, || format!("knot (0, {j})"));
            self.mu[b] = kinks.max(self.mu[b], bound, e, || format!("knot ({}, {j})", nu - 1));
        }
        for i in 0..nu {
            let (a, b) = (self.at(i, 0), self.at(i, nv - 1));
            self.mv[a] = kinks.min(self.mv[a], -bound, e, || format!("knot ({i}, 0)"));
            self.mv[b] = kinks.max(self.mv[b], bound, e, || format!("knot ({i}, {})", nv - 1));
        }
        for j in 0..nv {
            for i in 0..nu {
                if i == 0 || j == 0 || i == nu - 1 || j == nv - 1 {
                    let k = self.at(i, j);
                    self.muv[k] = T::from(0.0);
                }
            }
        }
    }

    /// Step 5, grid lines: Fritsch–Carlson limits ([`limit_line`]) on pˣ along every row and on pʸ along every
    /// column; `mi`, `mj` are the minimum knots whose slopes keep their sign.
    fn limit_lines(&mut self, mi: Option<usize>, mj: Option<usize>, kinks: &mut Kinks) {
        let (nu, nv) = (self.tu.len(), self.tv.len());
        for j in 0..nv {
            let ks: Vec<usize> = (0..nu).map(|i| self.at(i, j)).collect();
            let p: Vec<T> = ks.iter().map(|&k| self.p[k]).collect();
            let mut m: Vec<T> = ks.iter().map(|&k| self.mu[k]).collect();
            limit_line(&self.tu, &p, &mut m, mi, kinks, &|i| {
                format!("knot ({i}, {j}), pˣ")
            });
            for (&k, v) in ks.iter().zip(m) {
                self.mu[k] = v;
            }
        }
        for i in 0..nu {
            let ks: Vec<usize> = (0..nv).map(|j| self.at(i, j)).collect();
            let p: Vec<T> = ks.iter().map(|&k| self.p[k]).collect();
            let mut m: Vec<T> = ks.iter().map(|&k| self.mv[k]).collect();
            limit_line(&self.tv, &p, &mut m, mj, kinks, &|j| {
                format!("knot ({i}, {j}), pʸ")
            });
            for (&k, v) in ks.iter().zip(m) {
                self.mv[k] = v;
            }
        }
    }

    /// The four corners (i, j, index) of patch `(ci, cj)`.
    fn corners(&self, (ci, cj): (usize, usize)) -> [(usize, usize, usize); 4] {
        [
            (ci, cj, self.at(ci, cj)),
            (ci + 1, cj, self.at(ci + 1, cj)),
            (ci, cj + 1, self.at(ci, cj + 1)),
            (ci + 1, cj + 1, self.at(ci + 1, cj + 1)),
        ]
    }

    /// Step 5, patch interiors: halve the twists at the corners of failing patches (up to 40 rounds), then, when
    /// `strict`, shrink their cross slopes (up to 60 rounds).
    fn monotone_patches(
        &mut self,
        min: &Minimum,
        pmin: f64,
        strict: bool,
        kinks: &mut Kinks,
    ) -> PatchRounds {
        let mut rounds = PatchRounds::default();
        let mut failing = self.failing_patches(min.i, min.j);
        while !failing.is_empty() && rounds.twist < 40 {
            rounds.twist += 1;
            let mut seen = std::collections::HashSet::new();
            for f in &failing {
                for (_, _, k) in self.corners(f.cell) {
                    if seen.insert(k) {
                        self.muv[k] *= 0.5;
                    }
                }
            }
            failing = self.failing_patches(min.i, min.j);
        }
        while strict && !failing.is_empty() && rounds.slope < 60 {
            rounds.slope += 1;
            self.shrink_cross_slopes(&failing, min, pmin, kinks);
            failing = self.failing_patches(min.i, min.j);
        }
        rounds.nonmonotone = failing.len();
        rounds
    }

    /// One round of cross-slope shrinking. A twist-free patch can still change monotonicity in u when pʸ differs
    /// strongly between its corners (the ∂f/∂u of the patch contains hv k_j(t) ∂_u H[pʸ]); shrinking |pʸ| towards
    /// pˣ_min (keeping its sign, so the columns stay monotone and Fritsch–Carlson's box still holds) removes that
    /// term in the limit, and likewise |pˣ| for a failure along v. The corners' twists are set to 0.
    fn shrink_cross_slopes(
        &mut self,
        failing: &[Failing],
        min: &Minimum,
        pmin: f64,
        kinks: &mut Kinks,
    ) {
        let mut seen = std::collections::HashSet::new();
        let bound = T::from(pmin);
        for f in failing {
            for (i, j, k) in self.corners(f.cell) {
                if !seen.insert(k) {
                    continue;
                }
                self.muv[k] = T::from(0.0);
                let mut shrink = |m: T, free: bool| {
                    if free {
                        m * 0.5
                    } else {
                        let half = m.copysign_of(1.0) * 0.5;
                        kinks
                            .max(half, bound, KinkRule::CrossSlopeFloor, || {
                                format!("knot ({i}, {j})")
                            })
                            .copysign_of(m.value())
                    }
                };
                if f.along_u {
                    self.mv[k] = shrink(self.mv[k], j == min.j);
                }
                if f.along_v {
                    self.mu[k] = shrink(self.mu[k], i == min.i);
                }
            }
        }
    }

    /// Step 6: the residual r = f(u, v) − f(u, 0) − f(0, v) + f(0, 0) about the knots u = 0 (`i0`) and v = 0
    /// (`j0`), with exact zeros on both axes.
    fn residual(&self, i0: usize, j0: usize) -> Grid<T> {
        let (nu, nv) = (self.tu.len(), self.tv.len());
        let zero = T::from(0.0);
        let mut r = Grid {
            tu: self.tu.clone(),
            tv: self.tv.clone(),
            p: vec![zero; nu * nv],
            mu: vec![zero; nu * nv],
            mv: vec![zero; nu * nv],
            muv: self.muv.clone(),
        };
        for j in 0..nv {
            for i in 0..nu {
                let k = self.at(i, j);
                let (kx, ky, k00) = (self.at(i, j0), self.at(i0, j), self.at(i0, j0));
                r.p[k] = self.p[k] - self.p[kx] - self.p[ky] + self.p[k00];
                r.mu[k] = self.mu[k] - self.mu[kx];
                r.mv[k] = self.mv[k] - self.mv[ky];
            }
        }
        // exact zeros on the axes (the formulas above give them up to rounding only when p(0,0) ≠ 0)
        for i in 0..nu {
            let k = r.at(i, j0);
            r.p[k] = zero;
            r.mu[k] = zero;
        }
        for j in 0..nv {
            let k = r.at(i0, j);
            r.p[k] = zero;
            r.mv[k] = zero;
        }
        r
    }

    /// Step 7: every knot with a stretch coordinate ≤ 0 gets p = pˣ = pʸ = pˣʸ = 0.
    fn zero_compression(&mut self, stretch: [bool; 2]) {
        let (nu, nv) = (self.tu.len(), self.tv.len());
        for j in 0..nv {
            for i in 0..nu {
                if (stretch[0] && self.tu[i] <= 0.0) || (stretch[1] && self.tv[j] <= 0.0) {
                    let k = self.at(i, j);
                    let zero = T::from(0.0);
                    self.p[k] = zero;
                    self.mu[k] = zero;
                    self.mv[k] = zero;
                    self.muv[k] = zero;
                }
            }
        }
    }

    /// Step 8: zero slope across the boundary of the knot box (pˣ on the first and last column, pʸ on the first and
    /// last row, pˣʸ on all four sides), so the residual stays constant beyond it.
    fn bound_extrapolation(&mut self) {
        let (nu, nv) = (self.tu.len(), self.tv.len());
        let zero = T::from(0.0);
        for j in 0..nv {
            for i in [0, nu - 1] {
                let k = self.at(i, j);
                self.mu[k] = zero;
                self.muv[k] = zero;
            }
        }
        for i in 0..nu {
            for j in [0, nv - 1] {
                let k = self.at(i, j);
                self.mv[k] = zero;
                self.muv[k] = zero;
            }
        }
    }
}

/// FIT2D on samples `x`, `y` (normalised strains) and `psi`. Samples where any of the three is not finite are
/// excluded and counted. Errors: length mismatch, too few usable samples, invalid options, or data that do not
/// reach 0 on an axis.
pub fn fit2d(x: &[f64], y: &[f64], psi: &[f64], opts: &Fit2DOptions) -> Result<Fit2D, FitError> {
    if x.len() != psi.len() || y.len() != psi.len() {
        return Err(FitError::LengthMismatch {
            x: x.len().min(y.len()),
            psi: psi.len(),
        });
    }
    check_options(opts)?;
    let core = fit2d_core(x, y, psi, opts, &mut Kinks::off())?;
    let full = core.full.spline();

    // report on the unconverted spline
    let mut err = super::RelError::default();
    for ((&u, &v), &f) in core.xs.iter().zip(&core.ys).zip(&core.fs) {
        err.add(full.eval2(u, v)[0], f);
    }
    let report = Fit2DReport {
        n_samples: core.fs.len(),
        n_excluded: core.n_excluded,
        rms_rel: err.rms_rel(),
        max_rel: err.max_rel(),
        i_min: core.min.i,
        j_min: core.min.j,
        twist_rounds: core.rounds.twist,
        slope_rounds: core.rounds.slope,
        nonmonotone_patches: core.rounds.nonmonotone,
        compression_nonmonotone: core.compression.nonmonotone,
    };
    Ok(Fit2D {
        residual: core.residual.spline(),
        full,
        report,
    })
}

/// FIT2D steps 1–8 over a [`FitScalar`]: the unconverted grid f, the residual grid r, and what the report
/// needs. Knots, minimum knots, patch certificates and every branch are decided on the real parts; `kinks`
/// records the decisions at their switching points.
pub(crate) struct Core2D<T> {
    full: Grid<T>,
    pub(crate) residual: Grid<T>,
    min: Minimum,
    rounds: PatchRounds,
    compression: PatchRounds,
    /// the usable samples (real Ψ) and how many were excluded
    xs: Vec<f64>,
    ys: Vec<f64>,
    fs: Vec<f64>,
    n_excluded: usize,
}

/// The core of [`fit2d`] on scalars `psi` (lengths and options checked by the caller).
pub(crate) fn fit2d_core<T: FitScalar>(
    x: &[f64],
    y: &[f64],
    psi: &[T],
    opts: &Fit2DOptions,
    kinks: &mut Kinks,
) -> Result<Core2D<T>, FitError> {
    let (xs, ys, fs) = usable_samples(x, y, psi);
    let n_excluded = psi.len() - fs.len();

    // step 1
    let g = Smoothed::new((&xs, &ys, &fs), opts, kinks)?;
    // step 2
    let mut grid = Grid::sample(&g, &xs, &ys, opts)?;
    // step 3
    let min = grid.minimum(opts.minimum_v, kinks);
    let pmin = opts.min_slope;
    if opts.quasi_convex {
        grid.quasi_convexify(&min, pmin, kinks);
    }
    // step 4 (applied again after step 5 so the Fritsch–Carlson zeroing of (s_x, s_y) cannot undo it)
    grid.clamp_boundary(pmin, kinks);
    // step 5: Fritsch–Carlson along rows and columns, then the patches
    let (mi, mj) = if opts.quasi_convex {
        (Some(min.i), Some(min.j))
    } else {
        (None, None)
    };
    grid.limit_lines(mi, mj, kinks);
    grid.clamp_boundary(pmin, kinks);
    let rounds = if opts.quasi_convex {
        grid.monotone_patches(&min, pmin, opts.strict_patches, kinks)
    } else {
        PatchRounds::default()
    };

    // step 6
    let mut r = grid.residual(min.i, min.j0);
    // step 7 (or 7′)
    let mut compression = PatchRounds::default();
    if opts.quasi_convex {
        if opts.compression_residual {
            compression = r.compression_excess(opts.stretch, min.i, min.j0, kinks);
        } else {
            r.zero_compression(opts.stretch);
        }
    }
    // step 8
    r.bound_extrapolation();
    Ok(Core2D {
        full: grid,
        residual: r,
        min,
        rounds,
        compression,
        xs,
        ys,
        fs: fs.iter().map(|v| v.value()).collect(),
        n_excluded,
    })
}

mod certify;
mod compression;
#[cfg(test)]
mod tests;
