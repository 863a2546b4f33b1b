//! Property tests of FIT2D step 7′ (`hylc fit --compression-residual`; `docs/fitting.md`, "Options beyond the
//! default fit", FIT2D step 7 and its variant 7′): on random noisy samples (with rare branch outliers up to 10× the
//! truth) of quasi-convex truths that couple compression with the other strain, the kept compressed residual is
//! ≥ 0 and monotone outward from the axes on dense lines reaching 50 % beyond the knots, equals the default
//! residual on the tension side, is C¹ across every knot line, and never lies below the default residual (so
//! ψ with it is ≥ ψ without it, which is ≥ f₀) on 10⁵ random points of a box three times the knot box.

use crate::fit2d::dense;
use hylc::fit::{fit2d, Fit2DOptions, MinimumAt};
use hylc::material::Hermite2D;
use proptest::prelude::*;

#[derive(Clone, Debug)]
struct Case {
    x: Vec<f64>,
    y: Vec<f64>,
    psi: Vec<f64>,
    opts: Fit2DOptions,
}

/// Truth c + a₁x² + b₁|x|³ + a₂(y−y₀)² + b₂|y−y₀|³ + e x²(y−y₀)² + g max(−s, 0)² (y−y₀)² with s the stretch axis
/// (x, or y when `transposed`); 2 % noise, 3 % NaN, 2 % outliers × U(1, 10).
fn case() -> impl Strategy<Value = Case> {
    (
        (any::<bool>(), any::<bool>(), 0.0..1.0f64, -0.3..0.3f64),
        (
            prop::array::uniform2(0.2..2.0f64),
            prop::array::uniform2(0.0..2.0f64),
            0.0..1.0f64,
            0.0..30.0f64,
        ),
        (
            prop::array::uniform4(0.3..1.5f64),
            12usize..30,
            12usize..30,
            any::<u64>(),
            5usize..11,
        ),
    )
        .prop_map(
            |((transposed, bending, c, y0), (a, b, e, g), (ext, nx, ny, seed, nk))| {
                use rand::{Rng, SeedableRng};
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
                // the other axis is in-plane (minimum at 0) or bending (minimum at y₀)
                let y0 = if bending { y0 } else { 0.0 };
                let truth = |s: f64, o: f64| {
                    let d = o - y0;
                    c + a[0] * s * s
                        + b[0] * s.abs().powi(3)
                        + a[1] * d * d
                        + b[1] * d.abs().powi(3)
                        + e * s * s * d * d
                        + g * s.min(0.0).powi(2) * d * d
                };
                let (mut x, mut y, mut psi) = (vec![], vec![], vec![]);
                for i in 0..nx {
                    for j in 0..ny {
                        let s = -ext[0] + (ext[0] + ext[1]) * i as f64 / (nx - 1) as f64;
                        let o = -ext[2] + (ext[2] + ext[3]) * j as f64 / (ny - 1) as f64;
                        let f = truth(s, o) * (1.0 + 0.02 * rng.random_range(-1.0..1.0));
                        let f = if rng.random_bool(0.02) {
                            f * rng.random_range(1.0..10.0)
                        } else {
                            f
                        };
                        let f = if rng.random_bool(0.03) { f64::NAN } else { f };
                        let (u, v) = if transposed { (o, s) } else { (s, o) };
                        x.push(u);
                        y.push(v);
                        psi.push(f);
                    }
                }
                let other_min = if bending {
                    MinimumAt::Argmin
                } else {
                    MinimumAt::Zero
                };
                let opts = Fit2DOptions {
                    n_knots: [nk, nk + 1],
                    stretch: [!transposed, transposed],
                    minimum_v: if transposed {
                        MinimumAt::Zero
                    } else {
                        other_min
                    },
                    compression_residual: true,
                    ..Fit2DOptions::default()
                };
                Case { x, y, psi, opts }
            },
        )
}

/// r as a function of (stretch coordinate, other coordinate).
fn along(r: &Hermite2D, transposed: bool) -> impl Fn(f64, f64) -> [f64; 6] + '_ {
    move |s, o| {
        if transposed {
            let e = r.eval2(o, s);
            [e[0], e[2], e[1], e[5], e[4], e[3]]
        } else {
            r.eval2(s, o)
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn compressed_residual_is_a_monotone_nonnegative_c1_excess(c in case()) {
        let fit = fit2d(&c.x, &c.y, &c.psi, &c.opts).unwrap();
        let base = fit2d(&c.x, &c.y, &c.psi, &Fit2DOptions { compression_residual: false, ..c.opts.clone() }).unwrap();
        prop_assert_eq!(fit.report.compression_nonmonotone, 0, "{:?}", fit.report);
        // the unconverted spline is the same: 7′ only changes the residual
        prop_assert_eq!(&fit.full.p, &base.full.p);
        let transposed = c.opts.stretch[1];
        let r = along(&fit.residual, transposed);
        let r0 = along(&base.residual, transposed);
        let (ts, to) = if transposed {
            (&fit.residual.tv, &fit.residual.tu)
        } else {
            (&fit.residual.tu, &fit.residual.tv)
        };
        let scale = fit.full.p.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        let tol = 1e-10 * scale;
        let ss = dense(ts, 600);
        let os = dense(to, 120);
        // tension side: the default residual, bit for bit
        for &o in &os {
            for &s in ss.iter().filter(|&&s| s > 0.0) {
                prop_assert_eq!(r(s, o)[0], r0(s, o)[0], "tension side at ({}, {})", s, o);
            }
        }
        // compressed side: ≥ 0, non-decreasing as s decreases (outward), and along the other axis outward
        // from 0 on each side
        for &o in &os {
            let mut prev = r(0.0, o)[0];
            prop_assert!(prev.abs() <= tol, "r(0, {o}) = {prev}");
            for &s in ss.iter().rev().filter(|&&s| s < 0.0) {
                let v = r(s, o)[0];
                prop_assert!(v >= -tol, "r({s}, {o}) = {v} < 0");
                prop_assert!(v >= prev - tol, "r falls outward along s at ({s}, {o}): {v} < {prev}");
                prev = v;
            }
        }
        for &s in ss.iter().filter(|&&s| s < 0.0).step_by(5) {
            for side in [1.0, -1.0] {
                let mut prev = r(s, 0.0)[0];
                let mut line: Vec<f64> = os.iter().copied().filter(|&o| side * o > 0.0).collect();
                if side < 0.0 {
                    line.reverse();
                }
                for o in line {
                    let v = r(s, o)[0];
                    prop_assert!(v >= prev - tol, "r falls outward along the other axis at ({s}, {o}): {v} < {prev}");
                    prev = v;
                }
            }
        }
        // C¹ across every knot line of the compressed side and across s = 0
        let d = 1e-9;
        for &t in ts.iter().filter(|&&t| t <= 0.0) {
            for &o in os.iter().step_by(7) {
                let (a, b) = (r(t - d, o), r(t + d, o));
                for q in 0..3 {
                    let gs = if q == 0 { 1.0 } else { scale.max(1.0) };
                    prop_assert!((a[q] - b[q]).abs() <= 1e-5 * gs, "derivative {q} jumps across s = {t} at {o}: {} vs {}", a[q], b[q]);
                }
            }
        }
        for &t in to.iter() {
            for &s in ss.iter().filter(|&&s| s < 0.0).step_by(7) {
                let (a, b) = (r(s, t - d), r(s, t + d));
                for q in 0..3 {
                    let gs = if q == 0 { 1.0 } else { scale.max(1.0) };
                    prop_assert!((a[q] - b[q]).abs() <= 1e-5 * gs, "derivative {q} jumps across o = {t} at {s}: {} vs {}", a[q], b[q]);
                }
            }
        }
        // 10⁵ random points of a box three times the knot box: never below the default residual
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(c.x.len() as u64);
        let box3 = |t: &[f64]| {
            let (a, b) = (t[0], t[t.len() - 1]);
            (a - (b - a), b + (b - a))
        };
        let ((s0, s1), (o0, o1)) = (box3(ts), box3(to));
        for _ in 0..100_000 {
            let (s, o) = (rng.random_range(s0..s1), rng.random_range(o0..o1));
            let (v, v0) = (r(s, o)[0], r0(s, o)[0]);
            prop_assert!(v >= v0 - 1e-9, "r({s}, {o}) = {v} below the default's {v0}");
        }
    }
}
