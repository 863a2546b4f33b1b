//! Property tests of the contact pair energy (`docs/yarn-model.md`): symmetric in the pair, zero beyond 2r,
//! monotone in distance, plus invariance under reversing a segment and under rigid motions.
//!
//! Inputs come from the harness sampler [`sample_pair`] (all its categories: generic, nearly parallel, at the
//! cut-off, deep, short, long, partly beyond, beyond) driven by a proptest seed, and from explicit crossing
//! configurations for the monotonicity test. Comparisons use the harness form ‖a − b‖ ≤ tol (‖b‖ + scale) with
//! the scales of `hylc::contact::checks` (V = k_c l̄_a l̄_b, V/r, V/r²).

use hylc::checks::contact::{random_rotation, sample_pair, PAIR_CATEGORIES};
use hylc::contact::{PairKernel, PairVgh};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const R: f64 = 1e-3;
const KC: f64 = 60.0;
const REST: [f64; 2] = [1.5 * R, 2.0 * R];

fn scale() -> f64 {
    KC * REST[0] * REST[1]
}

fn close_vgh(a: &PairVgh, b: &PairVgh, tol: f64) -> Result<(), String> {
    let v = scale();
    let ev = (a.value - b.value).abs() / (b.value.abs() + v);
    let eg = (a.gradient - b.gradient).norm() / (b.gradient.norm() + v / R);
    let eh = (a.hessian - b.hessian).norm() / (b.hessian.norm() + v / (R * R));
    if ev <= tol && eg <= tol && eh <= tol {
        Ok(())
    } else {
        Err(format!(
            "value {ev:.2e}, gradient {eg:.2e}, Hessian {eh:.2e}"
        ))
    }
}

fn pair(seed: u64, cat: usize, q: usize) -> [Vector3<f64>; 4] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    sample_pair(&mut rng, cat, R, q)
}

/// Permutation of the 12 coordinates that maps point k to point perm[k].
fn permute(v: &PairVgh, perm: [usize; 4]) -> PairVgh {
    let idx = |i: usize| 3 * perm[i / 3] + i % 3;
    PairVgh {
        value: v.value,
        gradient: SVector::<f64, 12>::from_fn(|i, _| v.gradient[idx(i)]),
        hessian: SMatrix::<f64, 12, 12>::from_fn(|i, j| v.hessian[(idx(i), idx(j))]),
    }
}

fn orders() -> impl Strategy<Value = usize> {
    prop_oneof![Just(1usize), Just(2), Just(3), Just(4), Just(6), Just(8)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn symmetric_under_swapping_the_segments(seed in any::<u64>(), cat in 0..PAIR_CATEGORIES, q in orders()) {
        let k = PairKernel::new(KC, R, q).unwrap();
        let x = pair(seed, cat, q);
        let e = k.value_gradient_hessian(&x, REST[0], REST[1]).unwrap();
        let swapped = [x[2], x[3], x[0], x[1]];
        let s = k.value_gradient_hessian(&swapped, REST[1], REST[0]).unwrap();
        // the swapped problem's point k is the original's point perm[k]
        let back = permute(&s, [2, 3, 0, 1]);
        if let Err(m) = close_vgh(&back, &e, 1e-12) {
            prop_assert!(false, "swap: {m}");
        }
        prop_assert_eq!(k.value(&swapped, REST[1], REST[0]).unwrap() == 0.0, e.value == 0.0);
    }

    #[test]
    fn invariant_under_reversing_a_segment(seed in any::<u64>(), cat in 0..PAIR_CATEGORIES, q in orders(), which in 0..2usize) {
        let k = PairKernel::new(KC, R, q).unwrap();
        let x = pair(seed, cat, q);
        let e = k.value_gradient_hessian(&x, REST[0], REST[1]).unwrap();
        let mut y = x;
        y.swap(2 * which, 2 * which + 1);
        let perm = if which == 0 { [1, 0, 2, 3] } else { [0, 1, 3, 2] };
        let r = permute(&k.value_gradient_hessian(&y, REST[0], REST[1]).unwrap(), perm);
        if let Err(m) = close_vgh(&r, &e, 1e-12) {
            prop_assert!(false, "reversal: {m}");
        }
    }

    #[test]
    fn rigid_motion_invariance(seed in any::<u64>(), cat in 0..PAIR_CATEGORIES, q in orders(), rot_seed in any::<u64>(),
                               t in prop::array::uniform3(-20.0 * R..20.0 * R)) {
        let k = PairKernel::new(KC, R, q).unwrap();
        let x = pair(seed, cat, q);
        let rot: Matrix3<f64> = random_rotation(&mut ChaCha8Rng::seed_from_u64(rot_seed));
        let shift = Vector3::from(t);
        let y = x.map(|p| rot * p + shift);
        let e = k.value_gradient_hessian(&x, REST[0], REST[1]).unwrap();
        let f = k.value_gradient_hessian(&y, REST[0], REST[1]).unwrap();
        // gradient rotates with the points, Hessian blocks as R H Rᵀ
        let mut big = SMatrix::<f64, 12, 12>::zeros();
        for b in 0..4 {
            big.fixed_view_mut::<3, 3>(3 * b, 3 * b).copy_from(&rot);
        }
        let expect = PairVgh {
            value: e.value,
            gradient: big * e.gradient,
            hessian: big * e.hessian * big.transpose(),
        };
        // translations of up to 20 r lose a few digits in the coordinate differences
        if let Err(m) = close_vgh(&f, &expect, 1e-11) {
            prop_assert!(false, "rigid motion: {m}");
        }
        // the gradient sums to zero over a translation (each component)
        let mut sum = Vector3::zeros();
        for b in 0..4 {
            sum += e.gradient.fixed_rows::<3>(3 * b);
        }
        prop_assert!(sum.norm() <= 1e-12 * (e.gradient.norm() + scale() / R));
    }

    #[test]
    fn exactly_zero_beyond_the_cutoff(seed in any::<u64>(), q in orders(), extra in 1e-9..3.0f64, lateral in -3.0..3.0f64) {
        let k = PairKernel::new(KC, R, q).unwrap();
        // the harness's "beyond" category: segment distance ≥ 2r(1 + 1e-4)
        let x = pair(seed, 7, q);
        prop_assert_eq!(k.value(&x, REST[0], REST[1]).unwrap(), 0.0);
        prop_assert_eq!(k.value_gradient_hessian(&x, REST[0], REST[1]).unwrap(), PairVgh::zero());
        // parallel segments at a distance just beyond 2r (the early reject may or may not fire; the quadrature
        // terms are zero on their own), shifted along their direction
        let g = 2.0 * R * (1.0 + extra);
        let y = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(2.0 * R, 0.0, 0.0),
            Vector3::new(lateral * R, 0.0, g),
            Vector3::new(lateral * R + 1.5 * R, 0.0, g),
        ];
        prop_assert_eq!(k.value(&y, REST[0], REST[1]).unwrap(), 0.0);
        prop_assert_eq!(k.value_gradient_hessian(&y, REST[0], REST[1]).unwrap(), PairVgh::zero());
    }

    #[test]
    fn zero_when_every_quadrature_pair_is_beyond_even_if_the_segments_are_close(q in 1usize..6, gap in 0.2..1.0f64, angle in 0.3..2.8f64) {
        // crossing long segments whose crossing point is between nodes: the segments are closer than 2r, the
        // quadrature points are all farther than 2r, so every term is exactly zero
        let k = PairKernel::new(KC, R, q).unwrap();
        let len = 80.0 * R;
        let nodes = k.rule().nodes().to_vec();
        // crossing halfway between two nodes (or between node 0 and the start for Q = 1)
        let s_cross = if q == 1 { 0.25 } else { 0.5 * (nodes[0] + nodes[1]) };
        let (ta, tb) = (Vector3::new(1.0, 0.0, 0.0), Vector3::new(angle.cos(), angle.sin(), 0.0));
        let n = Vector3::new(0.0, 0.0, gap * 2.0 * R);
        let x = [-ta * (s_cross * len), ta * ((1.0 - s_cross) * len), n - tb * (s_cross * len), n + tb * ((1.0 - s_cross) * len)];
        let mut min_node = f64::INFINITY;
        for &sp in &nodes {
            for &sq in &nodes {
                min_node = min_node.min((x[0].lerp(&x[1], sp) - x[2].lerp(&x[3], sq)).norm());
            }
        }
        prop_assume!(min_node > 2.0 * R);
        prop_assert!(!k.beyond_cutoff(&x));
        prop_assert_eq!(k.value(&x, REST[0], REST[1]).unwrap(), 0.0);
        prop_assert_eq!(k.value_gradient_hessian(&x, REST[0], REST[1]).unwrap(), PairVgh::zero());
    }

    #[test]
    fn monotone_in_the_separation_along_the_common_normal(
        q in orders(), angle in 0.05..3.09f64, la in 0.5..3.0f64, lb in 0.5..3.0f64,
        sa in 0.0..1.0f64, sb in 0.0..1.0f64, g0 in 0.3..1.2f64, rot_seed in any::<u64>()
    ) {
        // two crossing segments in parallel planes; segment b moves away along the common normal
        let k = PairKernel::new(KC, R, q).unwrap();
        let rot = random_rotation(&mut ChaCha8Rng::seed_from_u64(rot_seed));
        let (ta, tb) = (Vector3::new(1.0, 0.0, 0.0), Vector3::new(angle.cos(), angle.sin(), 0.0));
        let at = |g: f64| {
            let n = Vector3::new(0.0, 0.0, g * 2.0 * R);
            [
                -ta * (sa * la * R),
                ta * ((1.0 - sa) * la * R),
                n - tb * (sb * lb * R),
                n + tb * ((1.0 - sb) * lb * R),
            ]
            .map(|p| rot * p)
        };
        let mut prev = f64::INFINITY;
        for i in 0..40 {
            let g = g0 + 0.025 * i as f64;
            let x = at(g);
            let v = k.value_gradient_hessian(&x, REST[0], REST[1]).unwrap();
            prop_assert!(v.value <= prev, "energy increased at gap {g}: {} > {prev}", v.value);
            // the derivative along the normal (b moves, a fixed) is ≤ 0
            let nrm = rot * Vector3::z();
            let slope = nrm.dot(&(v.gradient.fixed_rows::<3>(6) + v.gradient.fixed_rows::<3>(9)));
            prop_assert!(slope <= 1e-12 * scale() / R, "slope {slope} at gap {g}");
            prev = v.value;
        }
        prop_assert_eq!(prev, 0.0); // at gap ≥ 1.2 + 0.975 > 1 everything is beyond
    }
}
