//! Property tests of FIT2D (`docs/fitting.md`, "Tests"): random noisy grid
//! samples of random quasi-convex ground truths give a fitted surface f that is quasi-convex (monotone on each side
//! of its minimum) along every knot row and column, on a dense grid reaching 50 % beyond the knots, and monotone
//! inside the patches away from the minimum's row and column, with knot slopes that respect pˣ_min; the residual
//! term vanishes on both axes and on the compressed half-plane and is constant beyond the knot box; the 2D MLS
//! reproduces quadratics; noise-free samples of a smooth convex function are reproduced at the knots.

use hylc::fit::{fit2d, Fit2DOptions, MinimumAt, Mls2D};
use hylc::material::Hermite2D;
use proptest::prelude::*;

/// c + a₁x² + b₁|x|³ + a₂(y−y₀)² + b₂|y−y₀|³ + e x²(y−y₀)²: quasi-convex along every line parallel to an axis, with
/// its minimum at x = 0 and y = y₀.
#[derive(Clone, Debug)]
struct Truth {
    c: f64,
    a: [f64; 2],
    b: [f64; 2],
    e: f64,
    y0: f64,
}

impl Truth {
    fn f(&self, x: f64, y: f64) -> f64 {
        let d = y - self.y0;
        self.c
            + self.a[0] * x * x
            + self.b[0] * x.abs().powi(3)
            + self.a[1] * d * d
            + self.b[1] * d.abs().powi(3)
            + self.e * x * x * d * d
    }
}

#[derive(Clone, Debug)]
struct Case {
    truth: Truth,
    x: Vec<f64>,
    y: Vec<f64>,
    psi: Vec<f64>,
    opts: Fit2DOptions,
}

/// `kind`: 0 = in-plane × in-plane, 1 = in-plane × bending (minimum off 0), 2 = (s_x, s_y) (no quasi-convexity).
fn case() -> impl Strategy<Value = Case> {
    (
        (
            0usize..3,
            any::<bool>(),
            any::<bool>(),
            0.0..1.0f64,
            -0.3..0.3f64,
        ),
        (
            prop::array::uniform2(0.2..2.0f64),
            prop::array::uniform2(0.0..2.0f64),
            0.0..1.0f64,
        ),
        (
            prop::array::uniform4(0.3..1.5f64),
            12usize..30,
            12usize..30,
            0.0..0.02f64,
            any::<u64>(),
            5usize..11,
        ),
    )
        .prop_map(
            |((kind, stretch_x, sym_v, c, y0), (a, b, e), (ext, nx, ny, noise, seed, nk))| {
                use rand::{Rng, SeedableRng};
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
                let truth = Truth {
                    c,
                    a,
                    b,
                    e,
                    y0: if kind == 1 { y0 } else { 0.0 },
                };
                let (mut x, mut y, mut psi) = (vec![], vec![], vec![]);
                for i in 0..nx {
                    for j in 0..ny {
                        let u = -ext[0] + (ext[0] + ext[1]) * i as f64 / (nx - 1) as f64;
                        let v = -ext[2] + (ext[2] + ext[3]) * j as f64 / (ny - 1) as f64;
                        x.push(u);
                        y.push(v);
                        psi.push(if rng.random_bool(0.03) {
                            f64::NAN
                        } else {
                            truth.f(u, v) * (1.0 + noise * rng.random_range(-1.0..1.0))
                        });
                    }
                }
                let opts = Fit2DOptions {
                    n_knots: [nk, nk + 1],
                    symmetric: [false, kind == 0 && sym_v],
                    quasi_convex: kind != 2,
                    minimum_v: if kind == 1 {
                        MinimumAt::Argmin
                    } else {
                        MinimumAt::Zero
                    },
                    stretch: if kind == 2 {
                        [true, true]
                    } else {
                        [stretch_x, false]
                    },
                    ..Fit2DOptions::default()
                };
                Case {
                    truth,
                    x,
                    y,
                    psi,
                    opts,
                }
            },
        )
}

/// Quasi-convex along a line: non-increasing up to the dense grid's minimum, non-decreasing after it.
fn check_line(v: &[f64], what: &str) -> Result<(), TestCaseError> {
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let tol = 1e-12 * scale.max(1e-300);
    let imin = (0..v.len()).fold(0, |m, i| if v[i] < v[m] { i } else { m });
    for i in 1..=imin {
        prop_assert!(
            v[i] <= v[i - 1] + tol,
            "{what}: rises left of the minimum at {i}/{}",
            v.len()
        );
    }
    for i in imin + 1..v.len() {
        prop_assert!(
            v[i] >= v[i - 1] - tol,
            "{what}: falls right of the minimum at {i}/{}",
            v.len()
        );
    }
    Ok(())
}

/// A dense grid from 50 % beyond the first knot to 50 % beyond the last.
pub(crate) fn dense(t: &[f64], n: usize) -> Vec<f64> {
    let (a, b) = (t[0], t[t.len() - 1]);
    let (lo, hi) = (a - 0.5 * (b - a), b + 0.5 * (b - a));
    (0..=n)
        .map(|i| lo + (hi - lo) * i as f64 / n as f64)
        .collect()
}

/// Inside the patches: along the mid-lines between knot rows (columns), f is monotone in u (v) on each side of
/// the minimum, away from the cells that touch the minimum's column (row), which FIT2D leaves quasi-convex only.
/// One direction of the mid-line check: knots along the line, the minimum knot, knots across, f at (along,
/// across), and a name.
type Direction<'a> = (
    &'a [f64],
    usize,
    &'a [f64],
    &'a dyn Fn(f64, f64) -> f64,
    &'a str,
);

fn check_mid_lines(s: &Hermite2D, i_min: usize, j_min: usize) -> Result<(), TestCaseError> {
    let scale = s.p.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    let tol = 1e-10 * scale;
    let n = 400;
    // (knots along the line, minimum knot, knots across, evaluation at (along, across))
    let rows = |a: f64, b: f64| s.eval2(a, b)[0];
    let cols = |a: f64, b: f64| s.eval2(b, a)[0];
    let dirs: [Direction; 2] = [
        (&s.tu, i_min, &s.tv, &rows, "mid-row"),
        (&s.tv, j_min, &s.tu, &cols, "mid-column"),
    ];
    for (along, min, across, f, what) in dirs {
        for j in 0..across.len() - 1 {
            let c = 0.5 * (across[j] + across[j + 1]);
            for (lo, hi, sign) in [
                (min + 1, along.len() - 1, 1.0),
                (0, min.saturating_sub(1), -1.0),
            ] {
                if hi <= lo {
                    continue;
                }
                let (a, b) = (along[lo], along[hi]);
                let vals: Vec<f64> = (0..=n)
                    .map(|k| f(a + (b - a) * k as f64 / n as f64, c))
                    .collect();
                for k in 1..=n {
                    prop_assert!(
                        sign * (vals[k] - vals[k - 1]) >= -tol,
                        "{what} at {c}: not monotone at step {k}/{n} of [{a}, {b}]"
                    );
                }
            }
        }
    }
    Ok(())
}

fn check_grid_lines(s: &Hermite2D) -> Result<(), TestCaseError> {
    for (j, &v) in s.tv.iter().enumerate() {
        let line: Vec<f64> = dense(&s.tu, 1500)
            .iter()
            .map(|&u| s.eval2(u, v)[0])
            .collect();
        check_line(&line, &format!("row {j} (v = {v})"))?;
    }
    for (i, &u) in s.tu.iter().enumerate() {
        let line: Vec<f64> = dense(&s.tv, 1500)
            .iter()
            .map(|&v| s.eval2(u, v)[0])
            .collect();
        check_line(&line, &format!("column {i} (u = {u})"))?;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn fit2d_is_monotone_along_grid_lines_and_its_residual_vanishes(c in case()) {
        let fit = fit2d(&c.x, &c.y, &c.psi, &c.opts).unwrap();
        let (f, r) = (&fit.full, &fit.residual);
        let (nu, nv) = (f.tu.len(), f.tv.len());
        let (i_min, j_min) = (fit.report.i_min, fit.report.j_min);
        prop_assert_eq!(fit.report.n_excluded, c.psi.iter().filter(|v| v.is_nan()).count());
        prop_assert_eq!(f.tu[i_min], 0.0);
        if c.opts.quasi_convex {
            check_grid_lines(f)?;
            prop_assert_eq!(fit.report.nonmonotone_patches, 0, "{:?}", fit.report);
            check_mid_lines(f, i_min, j_min)?;
            let pmin = c.opts.min_slope;
            for j in 0..nv {
                for i in 0..nu {
                    let k = j * nu + i;
                    if i > i_min { prop_assert!(f.mu[k] >= pmin, "pˣ({i},{j}) = {}", f.mu[k]); }
                    if i < i_min { prop_assert!(f.mu[k] <= -pmin, "pˣ({i},{j}) = {}", f.mu[k]); }
                    if j > j_min { prop_assert!(f.mv[k] >= pmin, "pʸ({i},{j}) = {}", f.mv[k]); }
                    if j < j_min { prop_assert!(f.mv[k] <= -pmin, "pʸ({i},{j}) = {}", f.mv[k]); }
                }
            }
        }
        // the residual: zero on both axes (extrapolation included) and on the compressed half-plane
        let scale = r.p.iter().chain(&f.p).fold(0.0f64, |m, v| m.max(v.abs()));
        let tol = 1e-12 * scale;
        for &s in &dense(&r.tu, 400) {
            prop_assert!(r.eval2(s, 0.0)[0].abs() <= tol, "r({s}, 0) = {}", r.eval2(s, 0.0)[0]);
        }
        for &s in &dense(&r.tv, 400) {
            prop_assert!(r.eval2(0.0, s)[0].abs() <= tol, "r(0, {s}) = {}", r.eval2(0.0, s)[0]);
        }
        if c.opts.quasi_convex && c.opts.stretch[0] {
            for &v in &dense(&r.tv, 60) {
                for &u in dense(&r.tu, 120).iter().filter(|&&u| u <= 0.0) {
                    prop_assert!(r.eval2(u, v)[0].abs() <= tol, "compressed r({u}, {v}) = {}", r.eval2(u, v)[0]);
                }
            }
        }
        // step 8: beyond the knot box the residual is constant along the outward direction
        let (nu, nv) = (r.tu.len(), r.tv.len());
        let (u0, u1, v0, v1) = (r.tu[0], r.tu[nu - 1], r.tv[0], r.tv[nv - 1]);
        for &s in &dense(&r.tv, 40) {
            for (edge, out) in [(u0, u0 - 0.7), (u1, u1 + 0.7)] {
                let (a, b) = (r.eval2(edge, s)[0], r.eval2(out, s)[0]);
                prop_assert!((a - b).abs() <= tol, "r({out}, {s}) = {b} ≠ r({edge}, {s}) = {a}");
            }
        }
        for &s in &dense(&r.tu, 40) {
            for (edge, out) in [(v0, v0 - 0.7), (v1, v1 + 0.7)] {
                let (a, b) = (r.eval2(s, edge)[0], r.eval2(s, out)[0]);
                prop_assert!((a - b).abs() <= tol, "r({s}, {out}) = {b} ≠ r({s}, {edge}) = {a}");
            }
        }
        // residual = f − f(·, 0) − f(0, ·) + f(0, 0) where nothing is zeroed, in the patches off the box's
        // boundary (step 8 reshapes the boundary patches)
        let inner = |u: f64, v: f64| u > r.tu[1] && u < r.tu[nu - 2] && v > r.tv[1] && v < r.tv[nv - 2];
        if !c.opts.quasi_convex {
            for (u, v) in [(0.31, 0.27), (-0.2, 0.4), (0.5, -0.15)].into_iter().filter(|&(u, v)| inner(u, v)) {
                let want = f.eval2(u, v)[0] - f.eval2(u, 0.0)[0] - f.eval2(0.0, v)[0] + f.eval2(0.0, 0.0)[0];
                prop_assert!((r.eval2(u, v)[0] - want).abs() <= 1e-10 * scale, "r({u}, {v})");
            }
        }
        prop_assert!(fit.report.rms_rel.is_finite(), "{:?} {:?}", c.truth, fit.report);
    }

    #[test]
    fn mls2d_reproduces_quadratics(
        q in prop::array::uniform6(-10.0..10.0f64), nx in 3usize..15, ny in 3usize..15, factor in 1.0..4.0f64,
        u in -1.0..1.0f64, v in -1.0..1.0f64
    ) {
        let f = |x: f64, y: f64| q[0] + q[1] * x + q[2] * y + q[3] * x * x + q[4] * x * y + q[5] * y * y;
        let (mut x, mut y, mut z) = (vec![], vec![], vec![]);
        for i in 0..nx {
            for j in 0..ny {
                let (a, b) = (-1.0 + 2.0 * i as f64 / (nx - 1) as f64, -1.0 + 2.0 * j as f64 / (ny - 1) as f64);
                x.push(a);
                y.push(b);
                z.push(f(a, b));
            }
        }
        let m = Mls2D::new(&x, &y, &z, factor).unwrap();
        let scale = q.iter().map(|c| c.abs()).sum::<f64>() * (1.0 + u * u + v * v);
        prop_assert!((m.eval(u, v) - f(u, v)).abs() <= 1e-9 * scale, "{} vs {}", m.eval(u, v), f(u, v));
    }

    #[test]
    fn noise_free_smooth_convex_surface_is_reproduced_at_the_knots(
        c in 0.5..2.0f64, a in prop::array::uniform2(0.5..2.0f64), b in prop::array::uniform2(0.0..1.0f64),
        e in 0.0..1.0f64, ext in prop::array::uniform4(0.5..1.5f64)
    ) {
        let f = |x: f64, y: f64| c + a[0] * x * x + b[0] * x.powi(4) + a[1] * y * y + b[1] * y.powi(4) + e * x * x * y * y;
        // (the MLS bias in symlog space scales as b⁴ ∝ spacing⁴: at 50 × 50 a strongly curved log near a knot at
        // the data's edge reaches 1.6e-3 relative; 80 × 80 keeps every knot within 1e-3)
        let n = 80;
        let (mut x, mut y, mut z) = (vec![], vec![], vec![]);
        for i in 0..n {
            for j in 0..n {
                let u = -ext[0] + (ext[0] + ext[1]) * i as f64 / (n - 1) as f64;
                let v = -ext[2] + (ext[2] + ext[3]) * j as f64 / (n - 1) as f64;
                x.push(u);
                y.push(v);
                z.push(f(u, v));
            }
        }
        let fit = fit2d(&x, &y, &z, &Fit2DOptions::default()).unwrap();
        let s = &fit.full;
        for (j, &v) in s.tv.iter().enumerate() {
            for (i, &u) in s.tu.iter().enumerate() {
                let (got, want) = (s.p[j * s.tu.len() + i], f(u, v));
                prop_assert!((got - want).abs() <= 1e-3 * want.abs(), "knot ({u}, {v}): {got} vs {want}");
            }
        }
    }
}
