//! The value-only tile evaluation of the line search (`docs/micro-solver.md`), on the generated plain weave (no
//! external data needed). (The tangent predictor and the step options this file also tested were retired:
//! `docs/notes/retired-micro-solver-rules.md`.)

use hylc::generate::default_pattern;
use hylc::micro::{MacroStrain, MicroProblem, MicroState, SolverOptions};
use hylc::rod::YarnMaterial;
use hylc::tile::{Terms, Want};

fn problem(options: SolverOptions) -> MicroProblem {
    MicroProblem::new(
        default_pattern("plain").unwrap(),
        &YarnMaterial::default(),
        options,
    )
}

/// The value-only evaluation of the line search gives the same energy parts as the full one (to round-off: the
/// value kernels and the value-gradient-Hessian kernels evaluate the same expressions in other orders).
#[test]
fn value_only_evaluation_matches_the_full_one() {
    let p = problem(SolverOptions::default());
    let z = MacroStrain::new(0.05, 0.2, -0.1, 30.0, 0.0);
    let sol = p.solve(&z, None).unwrap();
    let state: &MicroState = &sol.state;
    let elim = hylc::micro::Elimination::in_family(&p.pattern, &state.strain, state.family);
    let mut tile = p.tile(&elim);
    let x = tile.home_positions(&state.y);
    tile.update_contacts(&x, 0.5 * p.pattern.radius).unwrap();
    assert!(!tile.contacts.is_empty());
    // a perturbed state, so that no part is at a stationary point
    let y: Vec<f64> = state
        .y
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-5 * p.pattern.radius * ((i as f64) * 0.37).sin())
        .collect();
    let v = tile
        .evaluate(&state.frames, &y, Want::Value, &Terms::ALL)
        .unwrap();
    let h = tile
        .evaluate(&state.frames, &y, Want::Hessian, &Terms::ALL)
        .unwrap();
    assert!(v.gradient.is_none() && v.hessian.is_none());
    for (a, b) in [
        (v.parts.stretch, h.parts.stretch),
        (v.parts.bend, h.parts.bend),
        (v.parts.twist, h.parts.twist),
        (v.parts.contact, h.parts.contact),
    ] {
        assert!((a - b).abs() <= 1e-14 * b.abs(), "{a} vs {b}");
    }
    assert!(v.parts.contact > 0.0);
}
