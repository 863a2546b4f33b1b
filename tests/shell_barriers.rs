//! The fold and collapse barriers (`hylc::shell::fold`; `docs/cloth-simulator.md`): a hinge approaching the flat fold
//! (|θ| → π) or a triangle approaching zero area costs unbounded energy and is pushed back; below the thresholds
//! nothing changes; the PSD options treat the fold barrier's Hessian as documented; the derivative harness's barrier
//! rows sample states beyond their thresholds; scenes have both by default and turn them off with `null`.

use hylc::checks::shell::sample_stencil;
use hylc::material::synthetic::default_material;
use hylc::shell::element::{ElementModel, ModelFlags, Psd};
use hylc::shell::fold::{CollapseBarrier, FoldBarrier};
use hylc::shell::scene::Scene;
use hylc::shell::strain::{RestTriangle, StrainChain, NDOF};
use nalgebra::{DMatrix, SymmetricEigen};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// A triangle of 1 cm legs in the plane z = 0 with one flap across its edge (x₀, x₁) folded by φ about that edge
/// (φ = 0: flat, φ = π: the flap lies on the triangle).
fn folded(phi: f64) -> ([f64; NDOF], RestTriangle, [bool; 3]) {
    let rest = RestTriangle::new([0.0, 0.0], [0.01, 0.0], [0.0, 0.01]).unwrap();
    let mut q = [0.0; NDOF];
    let pts = [
        [0.0, 0.0, 0.0],
        [0.01, 0.0, 0.0],
        [0.0, 0.01, 0.0],
        [0.004, -0.008 * phi.cos(), 0.008 * phi.sin()],
    ];
    for (k, p) in pts.iter().enumerate() {
        q[3 * k..3 * k + 3].copy_from_slice(p);
    }
    (q, rest, [true, false, false])
}

fn model(fold: Option<FoldBarrier>, psd: Psd) -> ElementModel {
    let flags = ModelFlags {
        fold,
        ..ModelFlags::default()
    };
    ElementModel::new(&default_material(), &flags, psd)
}

fn collapsing(collapse: Option<CollapseBarrier>, psd: Psd) -> ElementModel {
    let flags = ModelFlags {
        collapse,
        ..ModelFlags::default()
    };
    ElementModel::new(&default_material(), &flags, psd)
}

/// The flat triangle of [`folded`] (flap flat) sheared by moving x₂ along the fabric x axis by `t` legs: the
/// area ratio stays 1 while s_a grows, so use `squash` to move it towards the edge (x₀, x₁) as well: J = 1 − squash.
fn sheared(t: f64, squash: f64) -> ([f64; NDOF], RestTriangle, [bool; 3]) {
    let (mut q, rest, flaps) = folded(0.0);
    q[6] = 0.01 * t;
    q[7] = 0.01 * (1.0 - squash);
    (q, rest, flaps)
}

fn barrier() -> Option<FoldBarrier> {
    Some(FoldBarrier::default())
}

fn min_eigenvalue(h: &[[f64; NDOF]; NDOF]) -> (f64, f64) {
    let m = DMatrix::from_fn(NDOF, NDOF, |i, j| 0.5 * (h[i][j] + h[j][i]));
    let norm = m.norm();
    (SymmetricEigen::new(m).eigenvalues.min(), norm)
}

#[test]
fn the_fold_angle_is_the_hinge_angle() {
    for phi in [0.3, 2.0, 3.0, PI - 1e-3] {
        let (q, rest, flaps) = folded(phi);
        let theta = StrainChain::new(&q, &rest, flaps)
            .unwrap()
            .hinge_angle(0)
            .unwrap();
        assert!((theta.abs() - phi).abs() < 1e-12, "φ = {phi}: θ = {theta}");
    }
}

#[test]
fn a_hinge_cannot_fold_flat() {
    let (with, without) = (model(barrier(), Psd::None), model(None, Psd::None));
    let mut prev = f64::NEG_INFINITY;
    for phi in [2.6, 2.9, 3.1, PI - 1e-4, PI - 1e-8] {
        let (q, rest, flaps) = folded(phi);
        let e = with.energy(&q, &rest, flaps).unwrap();
        let e0 = without.energy(&q, &rest, flaps).unwrap();
        assert!(
            e - e0 > prev,
            "φ = {phi}: the barrier's energy must grow towards the flat fold"
        );
        prev = e - e0;
    }
    // at φ = π − 1e-8 the barrier holds more than the energy of the triangle stretched by 50 %
    let (q, rest, flaps) = folded(0.0);
    let mut stretched = q;
    stretched[3] *= 1.5;
    let big = without.energy(&stretched, &rest, flaps).unwrap();
    assert!(prev > big, "barrier {prev} J against stretch {big} J");
    let (q, rest, flaps) = folded(PI);
    assert!(with.energy(&q, &rest, flaps).is_none());
    assert!(without.energy(&q, &rest, flaps).is_some());
}

#[test]
fn the_barrier_force_opens_the_fold() {
    let (with, without) = (model(barrier(), Psd::None), model(None, Psd::None));
    for phi in [2.7, 3.0, 3.13] {
        let (q, rest, flaps) = folded(phi);
        let (mut g, mut g0) = ([0.0; NDOF], [0.0; NDOF]);
        with.energy_gradient(&q, &rest, flaps, &mut g).unwrap();
        without.energy_gradient(&q, &rest, flaps, &mut g0).unwrap();
        // d(flap)/dφ
        let dflap = [0.0, 0.008 * phi.sin(), 0.008 * phi.cos()];
        let rate: f64 = (0..3).map(|c| (g[9 + c] - g0[9 + c]) * dflap[c]).sum();
        assert!(rate > 0.0, "φ = {phi}: dE_fold/dφ = {rate}");
    }
}

#[test]
fn below_the_threshold_nothing_changes() {
    for psd in [Psd::None, Psd::Psi, Psd::Full] {
        let (with, without) = (model(barrier(), psd), model(None, psd));
        for phi in [0.0, 1.0, 2.4, 2.5] {
            let (q, rest, flaps) = folded(phi);
            let run = |m: &ElementModel| {
                let (mut g, mut h, mut he, mut hp) = (
                    [0.0; NDOF],
                    [[0.0; NDOF]; NDOF],
                    [[0.0; NDOF]; NDOF],
                    [[0.0; NDOF]; NDOF],
                );
                let e = m
                    .energy_gradient_hessian(&q, &rest, flaps, &mut g, &mut h)
                    .unwrap()
                    .0;
                let mut g2 = [0.0; NDOF];
                m.energy_gradient_hessians(&q, &rest, flaps, &mut g2, &mut he, &mut hp)
                    .unwrap();
                (m.energy(&q, &rest, flaps).unwrap(), e, g, h, g2, he, hp)
            };
            assert_eq!(run(&with), run(&without), "{psd:?}, φ = {phi}");
        }
    }
}

#[test]
fn the_psd_options_treat_the_barrier_as_documented() {
    let (q, rest, flaps) = folded(3.0);
    let exact_of = |psd: Psd| {
        let (mut g, mut h) = ([0.0; NDOF], [[0.0; NDOF]; NDOF]);
        model(barrier(), psd)
            .energy_gradient_hessian(&q, &rest, flaps, &mut g, &mut h)
            .unwrap();
        (g, h)
    };
    let (g_none, h_none) = exact_of(Psd::None);
    // the two-Hessian path gives the exact Hessian and the option's projection with the same gradient
    for psd in [Psd::Psi, Psd::Full] {
        let (mut g, mut he, mut hp) = ([0.0; NDOF], [[0.0; NDOF]; NDOF], [[0.0; NDOF]; NDOF]);
        model(barrier(), psd)
            .energy_gradient_hessians(&q, &rest, flaps, &mut g, &mut he, &mut hp)
            .unwrap();
        assert_eq!(g, g_none);
        assert_eq!(he, h_none);
        let (gp, hp1) = exact_of(psd);
        assert_eq!(gp, g_none);
        assert_eq!(hp, hp1, "{psd:?}");
    }
    // (a): the projected sum has no eigenvalue below the floor
    let (l, n) = min_eigenvalue(&exact_of(Psd::Full).1);
    assert!(l > -1e-12 * n, "smallest eigenvalue {l} (norm {n})");
    // (b): the barrier adds c β″ ∇θ ∇θᵀ, positive semi-definite
    let (mut g0, mut h0) = ([0.0; NDOF], [[0.0; NDOF]; NDOF]);
    model(None, Psd::Psi)
        .energy_gradient_hessian(&q, &rest, flaps, &mut g0, &mut h0)
        .unwrap();
    let h_psi = exact_of(Psd::Psi).1;
    let mut diff = [[0.0; NDOF]; NDOF];
    for i in 0..NDOF {
        for j in 0..NDOF {
            diff[i][j] = h_psi[i][j] - h0[i][j];
        }
    }
    let (l, n) = min_eigenvalue(&diff);
    assert!(
        n > 0.0 && l > -1e-12 * n,
        "smallest eigenvalue {l} (norm {n})"
    );
    // (c) differs from (b) by the curvature term c β′ ∇²θ: not zero
    assert_ne!(h_none, h_psi);
}

#[test]
fn the_harness_row_samples_hinges_beyond_its_threshold() {
    // the row `shell triangle energy with fold barrier` uses θ_t = 2.0 on these samples
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let (mut hinges, mut beyond) = (0, 0);
    for i in 0..300 {
        let (q, rest, flaps) = sample_stencil(&mut rng, i);
        let ch = StrainChain::new(&q, &rest, flaps).unwrap();
        for k in 0..3 {
            if let Some(t) = ch.hinge_angle(k) {
                hinges += 1;
                beyond += usize::from(t.abs() > 2.0);
            }
        }
    }
    assert!(
        beyond * 5 > hinges,
        "{beyond} of {hinges} hinges beyond the threshold"
    );
}

#[test]
fn scenes_have_the_barrier_by_default_and_null_turns_it_off() {
    let base = r#"{"material": "default", "duration": 0.1,
        "mesh": {"rectangle": {"width": 0.1, "height": 0.1, "edge": 0.02}}"#;
    let on: Scene = serde_json::from_str(&format!("{base}}}")).unwrap();
    assert_eq!(on.model.fold_barrier, Some(FoldBarrier::default()));
    let off: Scene =
        serde_json::from_str(&format!(r#"{base}, "model": {{"fold_barrier": null}}}}"#)).unwrap();
    assert_eq!(off.model.fold_barrier, None);
    assert_eq!(on.model.collapse_barrier, Some(CollapseBarrier::default()));
    let off: Scene = serde_json::from_str(&format!(
        r#"{base}, "model": {{"collapse_barrier": null}}}}"#
    ))
    .unwrap();
    assert_eq!(off.model.collapse_barrier, None);
    assert_eq!(off.model.fold_barrier, Some(FoldBarrier::default()));
    let custom: Scene = serde_json::from_str(&format!(
        r#"{base}, "model": {{"fold_barrier": {{"angle": 2.0, "stiffness": 3.0}}}}}}"#
    ))
    .unwrap();
    assert_eq!(
        custom.model.fold_barrier,
        Some(FoldBarrier {
            angle: 2.0,
            stiffness: 3.0
        })
    );
    let unknown = serde_json::from_str::<Scene>(&format!(
        r#"{base}, "model": {{"fold_barrier": {{"angle": 2.0, "stifness": 3.0}}}}}}"#
    ));
    assert!(unknown.is_err());
}

#[test]
fn a_triangle_cannot_collapse() {
    let (with, without) = (
        collapsing(Some(CollapseBarrier::default()), Psd::None),
        collapsing(None, Psd::None),
    );
    let mut prev = f64::NEG_INFINITY;
    for squash in [0.85, 0.9, 0.99, 1.0 - 1e-6] {
        let (q, rest, flaps) = sheared(0.5, squash);
        let e = with.energy(&q, &rest, flaps).unwrap();
        let e0 = without.energy(&q, &rest, flaps).unwrap();
        assert!(
            e - e0 > prev,
            "J = {}: the barrier must grow as the area goes",
            1.0 - squash
        );
        prev = e - e0;
        // the barrier's force pushes x₂ away from the edge (x₀, x₁): ∂E/∂y₂ < 0 beyond the material's own
        let (mut g, mut g0) = ([0.0; NDOF], [0.0; NDOF]);
        with.energy_gradient(&q, &rest, flaps, &mut g).unwrap();
        without.energy_gradient(&q, &rest, flaps, &mut g0).unwrap();
        assert!(g[7] - g0[7] < 0.0, "J = {}", 1.0 - squash);
    }
    let (q, rest, flaps) = sheared(0.5, 1.0);
    assert!(with.energy(&q, &rest, flaps).is_none());
}

#[test]
fn above_the_collapse_threshold_nothing_changes() {
    for psd in [Psd::None, Psd::Psi, Psd::Full] {
        let (with, without) = (
            collapsing(Some(CollapseBarrier::default()), psd),
            collapsing(None, psd),
        );
        for (t, squash) in [(0.0, 0.0), (0.9, 0.3), (0.3, 0.75)] {
            let (q, rest, flaps) = sheared(t, squash);
            let run = |m: &ElementModel| {
                let (mut g, mut h) = ([0.0; NDOF], [[0.0; NDOF]; NDOF]);
                let e = m
                    .energy_gradient_hessian(&q, &rest, flaps, &mut g, &mut h)
                    .unwrap()
                    .0;
                (m.energy(&q, &rest, flaps).unwrap(), e, g, h)
            };
            assert_eq!(
                run(&with),
                run(&without),
                "{psd:?}, shear {t}, squash {squash}"
            );
        }
    }
}

#[test]
fn the_harness_row_samples_triangles_beyond_the_collapse_threshold() {
    // the row `shell triangle energy with collapse barrier` uses J_t = 0.6
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut beyond = 0;
    for i in 0..300 {
        let (q, rest, flaps) = sample_stencil(&mut rng, i);
        let z = StrainChain::new(&q, &rest, flaps).unwrap().z;
        let j = (1.0 + z[0]) * (1.0 + z[2]) * (1.0 - z[1] * z[1]).sqrt();
        beyond += usize::from(j < 0.6);
    }
    assert!(
        beyond * 10 > 300,
        "{beyond} of 300 triangles beyond the threshold"
    );
}
