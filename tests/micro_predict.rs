//! Predictors along a chain of strains (issue 20, item 1) and the solver options of issue 20, item 2, on the
//! generated plain weave (no external data needed).

use hylc::generate::default_pattern;
use hylc::micro::envelope::strain_stiffness;
use hylc::micro::{MacroStrain, MicroProblem, MicroState, SolverOptions, Status};
use hylc::rod::YarnMaterial;
use hylc::tile::{Terms, Want};

fn problem(options: SolverOptions) -> MicroProblem {
    MicroProblem::new(
        default_pattern("plain").unwrap(),
        &YarnMaterial::default(),
        options,
    )
}

fn tight() -> SolverOptions {
    SolverOptions {
        tolerance: 1e-11,
        decrement_tolerance: 0.0,
        ..Default::default()
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// The tangent predictor is y* + (dy*/dz)·Δz to first order: its distance to the new equilibrium is second order
/// in Δz (halving Δz divides it by about four), far below the plain warm start's (first order), and it agrees
/// with the envelope module's dy*/dz; a solve from it reaches the same Ψ̄ as one from the warm start.
#[test]
fn tangent_predictor_is_first_order_accurate() {
    let p = problem(tight());
    let z0 = MacroStrain::in_plane(0.03, 0.1, -0.02);
    let s0 = p.solve(&z0, None).unwrap();
    assert_eq!(s0.status, Status::Converged);
    let dy = strain_stiffness(&p, &s0.state).unwrap();
    let mut errors = vec![];
    for h in [0.004, 0.002] {
        let z1 = MacroStrain::in_plane(0.03 + h, 0.1, -0.02);
        let exact = p.solve(&z1, Some(&s0.state)).unwrap();
        assert_eq!(exact.status, Status::Converged);
        let pred = p.predict_tangent(&s0.state, &z1).unwrap().unwrap();
        assert_eq!(pred.strain, z1);
        let e_pred = distance(&pred.y, &exact.state.y);
        let e_warm = distance(&s0.state.y, &exact.state.y);
        eprintln!("h {h}: tangent {e_pred:e}, warm {e_warm:e}");
        assert!(
            e_pred < 0.1 * e_warm,
            "h {h}: tangent {e_pred:e} vs warm {e_warm:e}"
        );
        // dy*/dz_sx · h from the envelope module (components: s_x first)
        let lin: Vec<f64> = s0
            .state
            .y
            .iter()
            .zip(&dy.dy[0])
            .map(|(y, d)| y + d * h)
            .collect();
        let e_lin = distance(&pred.y, &lin);
        eprintln!("h {h}: against dy*/dz {e_lin:e}");
        assert!(e_lin < 0.1 * e_warm, "h {h}: against dy*/dz {e_lin:e}");
        let from_pred = p.solve(&z1, Some(&pred)).unwrap();
        assert_eq!(from_pred.status, Status::Converged);
        let (a, b) = (from_pred.psi().unwrap(), exact.psi().unwrap());
        assert!((a - b).abs() <= 1e-8 * b.abs(), "{a} vs {b}");
        assert!(
            from_pred.steps <= exact.steps,
            "{} vs {}",
            from_pred.steps,
            exact.steps
        );
        errors.push(e_pred);
    }
    let ratio = errors[0] / errors[1];
    assert!(
        (2.5..6.0).contains(&ratio),
        "second order: error ratio {ratio} for half the step"
    );
}

/// The tangent predictor refuses a change of family and a zero step.
#[test]
fn tangent_predictor_declines_other_families_and_zero_steps() {
    let p = problem(SolverOptions::default());
    let z0 = MacroStrain::new(0.0, 0.0, 0.0, 0.0, 10.0);
    let s0 = p.solve(&z0, None).unwrap();
    let bend_x = MacroStrain::new(0.0, 0.0, 0.0, 10.0, 0.0);
    assert!(p.predict_tangent(&s0.state, &bend_x).unwrap().is_none());
    assert!(p.predict_tangent(&s0.state, &z0).unwrap().is_none());
    // an inadmissible strain is an error, not a prediction
    assert!(p
        .predict_tangent(&s0.state, &MacroStrain::in_plane(0.0, 1.5, 0.0))
        .is_err());
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

/// With exact steps on the constraint space switched on, solves still end at equilibria (the force test).
#[test]
fn projected_steps_option_converges() {
    let projected = problem(SolverOptions {
        projected_steps: true,
        ..Default::default()
    });
    let ks = projected.material.stretch_stiffness();
    for z in [
        MacroStrain::in_plane(0.1, 0.3, -0.2),
        MacroStrain::new(-0.2, 0.0, 0.0, 60.0, 0.0),
    ] {
        let b = projected.solve(&z, None).unwrap();
        assert_eq!(b.status, Status::Converged, "{z}");
        assert!(b.gradient_norm <= 1e-8 * ks || b.steps > 0, "{z}");
    }
}

/// Keeping the shift after a step that had to grow it reaches the same equilibria (Ψ̄ to 1e-8) in at most as
/// many factorisations' worth of steps on compressed and bent samples, where H is indefinite.
#[test]
fn keep_shift_option_reaches_the_same_equilibria() {
    let plain = problem(SolverOptions::default());
    let keep = problem(SolverOptions {
        keep_shift: true,
        ..Default::default()
    });
    for z in [
        MacroStrain::in_plane(0.1, 0.3, -0.2),
        MacroStrain::new(-0.2, 0.0, 0.0, 60.0, 0.0),
        MacroStrain::new(0.0, 0.2, -0.3, 0.0, -80.0),
    ] {
        let a = plain.solve(&z, None).unwrap();
        let b = keep.solve(&z, None).unwrap();
        assert_eq!(a.status, Status::Converged, "{z}");
        assert_eq!(b.status, Status::Converged, "{z}");
        let (pa, pb) = (a.psi().unwrap(), b.psi().unwrap());
        assert!((pa - pb).abs() <= 1e-8 * pa.abs(), "{z}: {pa} vs {pb}");
    }
}
