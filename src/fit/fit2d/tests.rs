//! Unit tests of FIT2D (the regression cases of its monotonicity certification among them).
use super::*;

fn grid_samples(
    f: impl Fn(f64, f64) -> f64,
    xr: [f64; 2],
    yr: [f64; 2],
    n: usize,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (mut x, mut y, mut z) = (vec![], vec![], vec![]);
    for i in 0..n {
        for j in 0..n {
            let u = xr[0] + (xr[1] - xr[0]) * i as f64 / (n - 1) as f64;
            let v = yr[0] + (yr[1] - yr[0]) * j as f64 / (n - 1) as f64;
            x.push(u);
            y.push(v);
            z.push(f(u, v));
        }
    }
    (x, y, z)
}

#[test]
fn knots_reproduce_the_original_layout() {
    // s_x on [−0.1, 0.84] with 8 knots: −0.09, 0, then 6 steps of 0.126 (basket1's (s_x, s_a) term)
    let t = axis_knots(-0.1, 0.84, 8, 0.9).unwrap();
    let want = [-0.09, 0.0, 0.126, 0.252, 0.378, 0.504, 0.63, 0.756];
    assert_eq!(t.len(), want.len());
    for (a, b) in t.iter().zip(want) {
        assert!((a - b).abs() < 1e-12, "{t:?}");
    }
    // s_x on [−0.44, 1] with 10 knots: 3 + 6 intervals (basket1's (s_x, s_y) term)
    let t = axis_knots(-0.44, 1.0, 10, 0.9).unwrap();
    assert!((t[0] + 0.396).abs() < 1e-12 && (t[3]).abs() == 0.0 && (t[4] - 0.15).abs() < 1e-12);
    assert!(axis_knots(0.0, 0.0, 9, 0.9).is_err());
    assert!(axis_knots(-1.0, 1.0, 2, 0.9).is_err());
}

#[test]
fn residual_vanishes_on_axes_and_in_compression() {
    let f = |u: f64, v: f64| 1.0 + u * u + 0.5 * v * v + 0.8 * u * u * v * v + 0.2 * u.powi(3);
    let (x, y, z) = grid_samples(f, [-0.4, 1.0], [-1.0, 1.0], 30);
    let o = Fit2DOptions {
        stretch: [true, false],
        ..Default::default()
    };
    let fit = fit2d(&x, &y, &z, &o).unwrap();
    let r = &fit.residual;
    for k in 0..=200 {
        let s = -1.5 + 3.0 * k as f64 / 200.0;
        assert_eq!(r.eval2(s, 0.0)[0], 0.0, "on v = 0 at u = {s}");
        assert_eq!(r.eval2(0.0, s)[0], 0.0, "on u = 0 at v = {s}");
        assert_eq!(
            r.eval2(-0.05 * (1.0 + s.abs()), s)[0],
            0.0,
            "compressed at v = {s}"
        );
    }
    // the coupling u²v² shows up where both are non-zero
    assert!(r.eval2(0.8, 0.8)[0] > 0.1);
    // the unconverted spline reproduces the smooth data (the largest errors are in the linear extrapolation
    // between the last knot, at 0.9 of the range, and the data's end)
    assert!(
        fit.report.rms_rel < 5e-3 && fit.report.max_rel < 3e-2,
        "{:?}",
        fit.report
    );
    assert_eq!(fit.report.nonmonotone_patches, 0);
}

/// A grid of `nu` × `nv` knots from row-major (v outer) arrays.
fn grid(tu: &[f64], tv: &[f64], p: &[f64], mu: &[f64], mv: &[f64], muv: &[f64]) -> Grid {
    Grid {
        tu: tu.to_vec(),
        tv: tv.to_vec(),
        p: p.to_vec(),
        mu: mu.to_vec(),
        mv: mv.to_vec(),
        muv: muv.to_vec(),
    }
}

#[test]
fn bezier_net_and_its_derivative_coefficients_reproduce_the_spline() {
    let (tu, tv) = ([-0.3, 0.1, 0.5], [0.0, 0.25, 0.7]);
    let n = 9;
    let w = |k: usize, a: f64, b: f64| {
        (0..n)
            .map(|i| a * ((i * k) as f64 * 0.7).sin() + b)
            .collect::<Vec<_>>()
    };
    let g = grid(
        &tu,
        &tv,
        &w(3, 1.0, 2.0),
        &w(5, 0.8, 0.1),
        &w(7, 0.6, -0.2),
        &w(11, 2.0, 0.0),
    );
    let s = g.spline();
    let bern = |n: usize, k: usize, x: f64| {
        let binom = [
            [1.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0, 0.0],
            [1.0, 2.0, 1.0, 0.0],
            [1.0, 3.0, 3.0, 1.0],
        ];
        binom[n][k] * x.powi(k as i32) * (1.0 - x).powi((n - k) as i32)
    };
    for (ci, cj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let net = g.bezier_net((ci, cj));
        let (hu, hv) = (tu[ci + 1] - tu[ci], tv[cj + 1] - tv[cj]);
        for (a, b) in [(0.0, 0.0), (0.3, 0.8), (0.55, 0.1), (1.0, 0.45), (0.9, 1.0)] {
            let (u, v) = (tu[ci] + a * hu, tv[cj] + b * hv);
            let d = s.eval2(u, v);
            let (mut f, mut fs, mut ft) = (0.0, 0.0, 0.0);
            for i in 0..4 {
                for j in 0..4 {
                    f += net[i][j] * bern(3, i, a) * bern(3, j, b);
                }
            }
            for i in 0..3 {
                for j in 0..4 {
                    fs += 3.0 * (net[i + 1][j] - net[i][j]) * bern(2, i, a) * bern(3, j, b);
                    ft += 3.0 * (net[j][i + 1] - net[j][i]) * bern(3, j, a) * bern(2, i, b);
                }
            }
            assert!((f - d[0]).abs() < 1e-12, "f at ({u}, {v}): {f} vs {}", d[0]);
            assert!(
                (fs - hu * d[1]).abs() < 1e-12,
                "f_u at ({u}, {v}): {} vs {}",
                fs / hu,
                d[1]
            );
            assert!(
                (ft - hv * d[2]).abs() < 1e-12,
                "f_v at ({u}, {v}): {} vs {}",
                ft / hv,
                d[2]
            );
        }
    }
}

/// Regression (proptest-regressions/fit2d.txt, case 20f84643…: "mid-row at 1.2476: not monotone at step
/// 360/400 of [0.135, 0.27]"): the patch of that fit in which f fell along u, with the minimum column moved to
/// u = 0 and the patch's lower row to v = 0 (values rounded to 5 digits). Its right edge has the slope
/// pˣ = pˣ_min, next to the Fritsch–Carlson cap pˣ = 3 × secant at the left, so along both rows ∂f/∂u ≈
/// 3 δ (1 − s)² vanishes quadratically towards the edge while the cross terms of the interior (pʸ rising along
/// u on both rows, the twist 1.98 at the lower left) vanish only linearly: ∂f/∂u < 0 in a strip s > 0.84, which
/// the former 7 × 7 sample check (s = 0, 1/6, …, 5/6, 1) missed. The certified check finds it and step 5
/// repairs it.
#[test]
fn a_sign_change_of_the_derivative_next_to_a_flat_edge_is_found_and_repaired() {
    let mut g = grid(
        &[0.0, 0.135, 0.27],
        &[0.0, 0.19193527110105266],
        &[1.56513, 1.78701, 1.82372, 1.71414, 2.13730, 2.18080],
        &[1.51384, 0.81565, 0.00100, 2.63625, 0.96656, 0.00100],
        &[0.75571, 1.58123, 1.60521, 0.79333, 2.08166, 2.12463],
        &[4.90910, 1.97813, 0.0, 0.0, 0.0, 0.0],
    );
    let min = Minimum { i: 0, j: 0, j0: 0 };
    let (hu, hv) = (0.135, 0.19193527110105266);
    // the least ∂f/∂u on an (n + 1)² sample of the patch [0.135, 0.27] × [0, hv]
    let least_fu = |g: &Grid, n: usize| {
        let s = g.spline();
        let mut m = f64::INFINITY;
        for a in 0..=n {
            for b in 0..=n {
                m = m.min(s.eval2(0.135 + hu * a as f64 / n as f64, hv * b as f64 / n as f64)[1]);
            }
        }
        m
    };
    assert!(least_fu(&g, 6) > 0.0, "the 7 × 7 sample sees no failure");
    let before = least_fu(&g, 400);
    assert!(before < -1e-3, "yet ∂f/∂u reaches {before}");
    let failing = g.failing_patches(min.i, min.j);
    assert_eq!(failing.len(), 1);
    assert_eq!(failing[0].cell, (1, 0));
    assert!(failing[0].along_u && !failing[0].along_v);

    let p = g.p.clone();
    let rounds = g.monotone_patches(&min, 1e-3, true, &mut crate::fit::scalar::Kinks::off());
    assert_eq!(rounds.nonmonotone, 0);
    assert!(g.failing_patches(min.i, min.j).is_empty());
    // two halvings of the corner twists suffice; values and slopes stay (C¹ by construction)
    assert_eq!((rounds.twist, rounds.slope), (2, 0));
    assert_eq!(g.p, p);
    assert_eq!(g.muv[1], 1.97813 / 4.0);
    let after = least_fu(&g, 400);
    assert!(after >= 0.0, "∂f/∂u reaches {after} after the repair");
    // the mid-row of the proptest, densely
    let s = g.spline();
    let row: Vec<f64> = (0..=400)
        .map(|k| s.eval2(0.135 + hu * k as f64 / 400.0, 0.5 * hv)[0])
        .collect();
    assert!(row.windows(2).all(|w| w[1] >= w[0]));
}

#[test]
fn bad_input_is_an_error() {
    let (x, y, z) = grid_samples(|u, v| u * u + v * v, [-1.0, 1.0], [-1.0, 1.0], 10);
    assert!(fit2d(&x[..5], &y, &z, &Fit2DOptions::default()).is_err());
    for bad in [
        Fit2DOptions {
            n_knots: [2, 9],
            ..Default::default()
        },
        Fit2DOptions {
            extent: 0.0,
            ..Default::default()
        },
        Fit2DOptions {
            min_slope: 0.0,
            ..Default::default()
        },
    ] {
        assert!(matches!(
            fit2d(&x, &y, &z, &bad),
            Err(FitError::BadOption(_))
        ));
    }
    let nan = vec![f64::NAN; z.len()];
    assert!(fit2d(&x, &y, &nan, &Fit2DOptions::default()).is_err());
}
