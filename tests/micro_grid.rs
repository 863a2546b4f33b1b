//! Validation item c (`docs/micro-vs-original.md`): a quick partial run of the micro solver against the
//! original displacements on satin — a few grid points near z = 0 by warm-started continuation. The full grid is
//! `hylc micro-grid` (`docs/micro-vs-original.md`, "Errors on the 9×9×9 grid"). Skips without `../shared`.

mod common;

use hylc::micro::{MacroStrain, MicroProblem, SolverOptions};
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use hylc::validation::grid::{
    counterpart, run_grid, summarize, GridData, GridError, GridOptions, GRID_LEN,
};
use std::sync::atomic::{AtomicUsize, Ordering};

fn original(shared: &std::path::Path, file: &str) -> Pattern {
    // the same rule as the CLI: periods that disagree with the rest lengths give way to the implied ones
    Pattern::load_pyp_at_implied_periods(shared.join("data/hylc2020/patterns").join(file))
        .unwrap()
        .0
}

#[test]
fn satin_near_zero_converges_with_a_finite_error() {
    let Some(shared) = common::shared_or_skip("satin_near_zero_converges_with_a_finite_error")
    else {
        return;
    };
    let dir = shared.join("data/hylc2020/displacements/satin");
    let data = GridData::load(&dir).unwrap();
    assert_eq!(data.n_vertices, 130);
    let zero = data.zero_point();
    assert_eq!(data.strain(zero), MacroStrain::ZERO);

    let problem = MicroProblem::new(
        original(&shared, "satin.pyp"),
        &YarnMaterial::default(),
        SolverOptions::default(),
    );
    let calls = AtomicUsize::new(0);
    let options = GridOptions {
        limit: Some(4),
        cold_every: 0,
    };
    let run = run_grid(&problem, &data, &options, &|| {
        calls.fetch_add(1, Ordering::Relaxed);
    })
    .unwrap();
    assert_eq!(calls.load(Ordering::Relaxed), 4);
    assert_eq!(run.points.len(), 4);
    assert_eq!(run.points[0].index, zero);
    for p in &run.points {
        assert!(p.state.is_some(), "{}: {:?}", p.strain, p.attempts);
        assert_eq!(p.attempts.len(), 1, "no cold retry needed near zero");
    }

    // our counterpart at z = 0 is small: the reference pattern is close to our model's equilibrium
    let ours0 = counterpart(&problem.pattern, run.points[0].state.as_ref().unwrap()).unwrap();
    let r = problem.pattern.radius;
    let max0 = ours0
        .iter()
        .map(|d| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / r)
        .fold(0.0, f64::max);
    assert!(max0.is_finite() && max0 < 1.0, "{max0}");

    let s = summarize(&problem, &data, &run);
    assert_eq!(s.points, 4);
    assert_eq!(s.converged, 4);
    assert!(s.failures.is_empty(), "{:?}", s.failures);
    assert_eq!(s.position_error.count, 4 * 130);
    for v in [
        s.position_error.rms,
        s.position_error.max,
        s.theta_error.rms,
        s.original_displacement.rms,
    ] {
        assert!(v.is_finite() && v >= 0.0, "{v}");
    }
    assert!(s.position_error.rms <= s.position_error.max);
    // the neighbours of z = 0 move the yarns: the compared quantity is not trivially zero
    assert!(
        s.original_displacement.max > 0.01,
        "{:?}",
        s.original_displacement
    );
    assert_eq!(s.warm.solves, 3);
    assert_eq!(s.cold.solves, 1);
}

#[test]
fn grid_data_must_match_the_pattern() {
    let Some(shared) = common::shared_or_skip("grid_data_must_match_the_pattern") else {
        return;
    };
    let data = GridData::load(&shared.join("data/hylc2020/displacements/basket")).unwrap();
    assert_eq!(data.n_vertices, 80);
    let satin = original(&shared, "satin.pyp");
    let e = data.check_pattern(&satin).unwrap_err();
    assert!(matches!(e, GridError::Mismatch(_)), "{e}");
    assert!(
        e.to_string().contains("80") && e.to_string().contains("130"),
        "{e}"
    );
    let problem = MicroProblem::new(satin, &YarnMaterial::default(), SolverOptions::default());
    assert!(run_grid(&problem, &data, &GridOptions::default(), &|| {}).is_err());
    // a folder without the files names the missing file
    let e = GridData::load(&shared.join("data/hylc2020")).unwrap_err();
    assert!(e.to_string().contains("axes.txt"), "{e}");
    assert_eq!(GRID_LEN, 729);
}
