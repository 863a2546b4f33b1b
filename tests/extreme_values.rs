//! Extreme-value properties (`docs/robustness.md`): 10⁴ random extreme inputs each for ψ, the shell strain chain, the
//! rod stencils (their checked entry points) and the contact pair kernel give finite outputs or an explicit rejection
//! (a typed error, or `None` for a degenerate triangle) — never NaN or inf. Inputs mix magnitudes from 1e-300 to 1e300
//! of either sign with zeros, NaN and ±inf.

use hylc::contact::pair::PairKernel;
use hylc::material::synthetic::default_material;
use hylc::rod::checked::{bend_twist_checked, stretch_checked};
use hylc::rod::{BendTwistParams, BendingForm, StencilFrames};
use hylc::shell::{RestTriangle, StrainChain};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CASES: usize = 10_000;

/// A number of any magnitude: mostly log-uniform in [1e-300, 1e300] with a random sign, sometimes 0, NaN or ±inf,
/// sometimes an ordinary value of `scale`.
fn extreme(rng: &mut ChaCha8Rng, scale: f64) -> f64 {
    match rng.random_range(0..40) {
        0 => 0.0,
        1 => f64::NAN,
        2 => f64::INFINITY,
        3 => f64::NEG_INFINITY,
        4..=29 => scale * rng.random_range(-1.0..1.0),
        _ => {
            let e: f64 = rng.random_range(-300.0..300.0);
            let s = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            s * 10f64.powf(e)
        }
    }
}

fn all_finite(v: impl IntoIterator<Item = f64>) -> bool {
    v.into_iter().all(f64::is_finite)
}

#[test]
fn psi_is_finite_or_refused_at_extreme_strains() {
    let m = default_material();
    let scales = [0.5, 0.5, 0.5, 100.0, 100.0, 100.0];
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let (mut ok, mut refused) = (0, 0);
    for _ in 0..CASES {
        let z: [f64; 6] = std::array::from_fn(|k| extreme(&mut rng, scales[k]));
        match m.eval_checked(&z) {
            Ok(r) => {
                let values = std::iter::once(r.value)
                    .chain(r.grad)
                    .chain(r.hess.iter().flatten().copied());
                assert!(all_finite(values), "non-finite ψ at z = {z:?}");
                ok += 1;
            }
            Err(_) => refused += 1,
        }
    }
    assert!(
        ok > CASES / 20 && refused > CASES / 20,
        "{ok} evaluated, {refused} refused"
    );
}

#[test]
fn strain_chain_is_finite_or_degenerate_at_extreme_positions() {
    let rest = RestTriangle::new([0.0, 0.0], [0.01, 0.0], [0.0, 0.01]).unwrap();
    // an ordinary stencil (a flat triangle with three flaps) that the extremes perturb
    let base: [f64; 18] = [
        0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.01, 0.0, 0.01, 0.01, 0.0, -0.005, 0.005, 0.0, 0.005,
        -0.005, 0.0,
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(18);
    let (mut ok, mut degenerate) = (0, 0);
    for _ in 0..CASES {
        let mut q = base;
        // perturb a few coordinates (all of them in a tenth of the cases)
        let n = if rng.random_bool(0.1) {
            18
        } else {
            rng.random_range(1..4)
        };
        for _ in 0..n {
            let j = rng.random_range(0..18);
            q[j] = base[j] + extreme(&mut rng, 0.003);
        }
        let flaps = [
            rng.random_bool(0.8),
            rng.random_bool(0.8),
            rng.random_bool(0.8),
        ];
        match StrainChain::new(&q, &rest, flaps) {
            Some(c) => {
                assert!(all_finite(c.z), "z = {:?} at q = {q:?}", c.z);
                assert!(
                    all_finite(c.jac.iter().flatten().copied()),
                    "Jacobian at q = {q:?}"
                );
                let h = c.weighted_hessian(&[1.0; 6]);
                assert!(
                    all_finite(h.iter().flatten().copied()),
                    "Hessian at q = {q:?}"
                );
                ok += 1;
            }
            None => degenerate += 1,
        }
    }
    assert!(ok > CASES / 10, "{ok} chains, {degenerate} degenerate");
}

#[test]
fn contact_pair_is_finite_or_an_error_at_extreme_positions() {
    let r = 1e-3;
    let kernel = PairKernel::new(1e4, r, 4).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(19);
    let (mut ok, mut errors) = (0, 0);
    for _ in 0..CASES {
        // two crossing segments 1.8 r apart, perturbed by extremes
        let mut x = [
            Vector3::new(-2.0 * r, 0.0, 0.0),
            Vector3::new(2.0 * r, 0.0, 0.0),
            Vector3::new(0.0, -2.0 * r, 1.8 * r),
            Vector3::new(0.0, 2.0 * r, 1.8 * r),
        ];
        let n = rng.random_range(1..4);
        for _ in 0..n {
            let (i, c) = (rng.random_range(0..4), rng.random_range(0..3));
            x[i][c] += extreme(&mut rng, r);
        }
        let rest = [extreme(&mut rng, 4.0 * r).abs(), 4.0 * r];
        match kernel.value_gradient_hessian(&x, rest[0], rest[1]) {
            Ok(v) => {
                let values = std::iter::once(v.value)
                    .chain(v.gradient.iter().copied())
                    .chain(v.hessian.iter().copied());
                assert!(
                    all_finite(values),
                    "non-finite contact energy at x = {x:?}, rest {rest:?}"
                );
                ok += 1;
            }
            Err(_) => errors += 1,
        }
    }
    assert!(ok > CASES / 10, "{ok} evaluated, {errors} errors");
}

#[test]
fn rod_stencils_are_finite_or_an_error_at_extreme_inputs() {
    let r = 1e-3;
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let (mut ok, mut errors) = (0, 0);
    for _ in 0..CASES {
        // a bent stencil of three vertices 1 mm apart, perturbed by extremes
        let mut x = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(r, 0.0, 0.0),
            Vector3::new(2.0 * r, 0.3 * r, 0.0),
        ];
        let n = rng.random_range(1..4);
        for _ in 0..n {
            let (i, c) = (rng.random_range(0..3), rng.random_range(0..3));
            x[i][c] += extreme(&mut rng, r);
        }
        let rest = extreme(&mut rng, r).abs();
        match stretch_checked(&x[0], &x[1], rest, extreme(&mut rng, 1e3)) {
            Ok((e, g, h)) => {
                let values = std::iter::once(e)
                    .chain(g.iter().copied())
                    .chain(h.iter().copied());
                assert!(all_finite(values), "stretch at x = {x:?}, rest {rest}");
                ok += 1;
            }
            Err(_) => errors += 1,
        }
        let t0 = Vector3::new(1.0, 0.0, 0.0);
        let t1 = Vector3::new(0.96, 0.28, 0.0);
        let fr = StencilFrames::new(t0, Vector3::z(), t1, Vector3::z(), extreme(&mut rng, 0.1));
        let p = BendTwistParams {
            rest_curvature: [extreme(&mut rng, 0.5), extreme(&mut rng, 0.5)],
            rest_twist: extreme(&mut rng, 0.1),
            voronoi_length: extreme(&mut rng, r).abs(),
            bend: extreme(&mut rng, 1e-6).abs(),
            twist: extreme(&mut rng, 1e-6).abs(),
            form: if rng.random_bool(0.5) {
                BendingForm::Sin
            } else {
                BendingForm::Tan
            },
        };
        let theta = [extreme(&mut rng, 1.0), extreme(&mut rng, 1.0)];
        match bend_twist_checked(&x, theta, &fr, &p) {
            Ok((e, g, h)) => {
                let values = std::iter::once(e)
                    .chain(g.iter().copied())
                    .chain(h.iter().copied());
                assert!(
                    all_finite(values),
                    "bend-twist at x = {x:?}, θ {theta:?}, {p:?}"
                );
                ok += 1;
            }
            Err(_) => errors += 1,
        }
    }
    assert!(ok > CASES / 10, "{ok} evaluated, {errors} errors");
}
