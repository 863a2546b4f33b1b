//! Property tests of the micro scale, the elimination map and the micro solver (`docs/micro-solver.md`):
//! - every copy produced by the elimination map equals the surface point of the shifted reference coordinates
//!   (i.e. the tile transform of the original vertex), for random admissible strains and displacements;
//! - zero strain and ũ = 0 reproduce the reference positions, and the reference state of Algorithm C1 is an
//!   equilibrium at z = 0;
//! - the result of a solve is independent of the number of threads (bit for bit);
//! - Ψ̄(z) ≥ Ψ̄(0) near 0 for in-plane strains (the reference state is a minimum).
//!
//! The pattern is the embedded plain weave after Algorithm C1 (computed once).

use hylc::generate::default_pattern;
use hylc::micro::elimination::stencil_copies;
use hylc::micro::reference::{reference_state, Construction, ReferenceOptions};
use hylc::micro::surface::SurfaceMap;
use hylc::micro::{Elimination, MacroStrain, MicroProblem, SolverOptions, Status};
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use nalgebra::Vector3;
use proptest::prelude::*;
use std::sync::OnceLock;

fn reference() -> &'static Pattern {
    static P: OnceLock<Pattern> = OnceLock::new();
    P.get_or_init(|| {
        reference_state(
            &default_pattern("plain").unwrap(),
            &YarnMaterial::default(),
            Construction::Woven,
            &SolverOptions::default(),
            &ReferenceOptions::default(),
        )
        .expect("C1 on the plain weave")
        .0
    })
}

fn problem() -> MicroProblem {
    MicroProblem::new(
        reference().clone(),
        &YarnMaterial::default(),
        SolverOptions::default(),
    )
}

/// An admissible strain: in-plane, or bending along one axis.
fn strain() -> impl Strategy<Value = MacroStrain> {
    (
        -0.3..0.5f64,
        -0.9..0.9f64,
        -0.3..0.5f64,
        -200.0..200.0f64,
        0..3usize,
    )
        .prop_map(|(sx, sa, sy, k, kind)| match kind {
            0 => MacroStrain::in_plane(sx, sa, sy),
            1 => MacroStrain::new(sx, sa, sy, k, 0.0),
            _ => MacroStrain::new(sx, sa, sy, 0.0, k),
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn copies_are_surface_points_of_the_shifted_reference(
        z in strain(), u in prop::collection::vec(-1e-3..1e-3f64, 3)
    ) {
        let p = reference();
        let e = Elimination::new(p, &z).unwrap();
        let m = SurfaceMap::of(&z, e.family);
        let q = problem();
        let mut tile = q.tile(&e);
        tile.update_contacts(&p.positions, 0.5 * p.radius).unwrap();
        let n = p.len();
        let uu = Vector3::new(u[0], u[1], u[2]);
        let mut y = vec![0.0; 4 * n];
        for v in 0..n {
            y[3 * v..3 * v + 3].copy_from_slice(uu.as_slice());
        }
        let copies = stencil_copies(&tile);
        let (c, d) = e.matrix(&copies, n);
        let mut qv = d.clone();
        for &(r, col, val) in &c {
            qv[r] += val * y[col];
        }
        for (k, &(v, o)) in copies.iter().enumerate() {
            let xi = p.positions[v];
            let shifted = [xi.x + o[0] as f64 * p.periods[0], xi.y + o[1] as f64 * p.periods[1]];
            let want = Vector3::from(m.point(shifted, xi.z, &[u[0], u[1], u[2]]));
            let got = Vector3::new(qv[3 * k], qv[3 * k + 1], qv[3 * k + 2]);
            let home = e.position(v, [0, 0], &uu);
            let (rt, tt) = e.transforms.get(o);
            let transformed = if o == [0, 0] { home } else { rt * home + tt };
            prop_assert!((got - want).norm() <= 1e-15 + 1e-12 * want.norm(), "{z} copy {v} {o:?}: {got} vs {want}");
            prop_assert!((transformed - want).norm() <= 1e-15 + 1e-12 * want.norm());
        }
    }

    #[test]
    fn psi_is_minimal_at_zero_for_small_in_plane_strains(s in prop::array::uniform3(-1.0..1.0f64), size in 1e-4..1e-2f64) {
        let q = problem();
        let zero = q.solve(&MacroStrain::ZERO, None).unwrap();
        let psi0 = zero.psi().unwrap();
        let z = MacroStrain::in_plane(size * s[0], size * s[1], size * s[2]);
        let sol = q.solve(&z, Some(&zero.state)).unwrap();
        let psi = sol.psi().unwrap();
        // the reference is a minimum up to the zero-stress tolerance of C1 (tile forces ≤ 1e-7 k_s)
        let slack = 1e-7 * q.material.stretch_stiffness() * size * (q.pattern.periods[0] + q.pattern.periods[1])
            / (q.pattern.periods[0] * q.pattern.periods[1]);
        prop_assert!(psi >= psi0 - slack, "{z}: Ψ̄ {psi:e} < Ψ̄(0) {psi0:e} (slack {slack:e})");
    }
}

#[test]
fn zero_strain_reproduces_the_reference() {
    let p = reference();
    let e = Elimination::new(p, &MacroStrain::ZERO).unwrap();
    for (v, x) in p.positions.iter().enumerate() {
        assert!((e.position(v, [0, 0], &Vector3::zeros()) - x).norm() == 0.0);
    }
    // the C1 output is an equilibrium at z = 0: the solve stays put
    let q = problem();
    let sol = q.solve(&MacroStrain::ZERO, None).unwrap();
    assert_eq!(sol.status, Status::Converged);
    assert!(sol.steps <= 1, "{} steps", sol.steps);
    let moved = (0..3 * p.len())
        .map(|i| sol.state.y[i].abs())
        .fold(0.0, f64::max);
    assert!(moved <= 1e-9 * p.radius, "moved by {moved:e} m");
}

#[test]
fn solves_do_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let q = problem();
            let z = MacroStrain::new(0.08, 0.2, -0.03, 0.0, 45.0);
            let s = q.solve(&z, None).unwrap();
            (s.psi().unwrap(), s.steps, s.state.y.clone())
        })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.0.to_bits(), b.0.to_bits());
    assert_eq!(a.1, b.1);
    assert!(a
        .2
        .iter()
        .zip(&b.2)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
}
