//! Time steps chosen by accuracy: the per-substep error estimate ½ maxᵥ |xᵥ − x̃ᵥ| is implicit Euler's local
//! error (exactly h² |g|/2 in free fall), `solver.time_tol` keeps every accepted substep within it, and a tighter
//! tolerance follows a reference run with tiny steps more closely.

mod common;

use hylc::shell::scene::Scene;
use std::path::Path;

use common::coarse_builtin as coarse;

fn reports(s: &Scene) -> Vec<hylc::shell::solver::StepReport> {
    let (mut sim, _) = s.build("scene.json", Path::new(".")).unwrap();
    (0..s.steps()).map(|_| sim.step().unwrap()).collect()
}

/// A free fall (no pins, no drag): the estimate of one step of h = 1/60 s is h² g/2, and with a tolerance τ
/// every accepted substep has h² g/2 ≤ τ, so a frame takes at least ⌈dt / √(2τ/g)⌉ substeps.
#[test]
fn free_fall_error_is_half_h_squared_g() {
    let mut s = coarse("hanging", 0.1, 2.0 / 60.0);
    s.pins.clear();
    s.drag = 0.0;
    let g = 9.81;
    let h = 1.0 / 60.0;
    for r in reports(&s) {
        let want = 0.5 * h * h * g;
        assert!(
            (r.error_estimate - want).abs() < 1e-9 * want,
            "{} vs {want}",
            r.error_estimate
        );
        assert_eq!((r.substeps, r.rejected), (1, 0));
    }
    let tol = 1e-5;
    s.solver.time_tol = Some(tol);
    let hmax = (2.0 * tol / g).sqrt();
    let log = reports(&s);
    for r in &log {
        assert!(r.error_estimate <= tol, "{} > {tol}", r.error_estimate);
        assert!(
            r.substeps as f64 >= (h / hmax).ceil(),
            "{} substeps",
            r.substeps
        );
        assert!((r.time - r.step as f64 * h).abs() < 1e-12);
    }
    // the first step starts from dt and must reject its way down
    assert!(log[0].rejected > 0);
}

/// The right handle's x force per frame of a coarse stretch-x.
fn forces(s: &Scene) -> Vec<f64> {
    reports(s).iter().map(|r| r.handle_forces[1].1[0]).collect()
}

/// Self-convergence on the coarse stretch-x over 0.2 s: against a reference with dt/64 fixed substeps (the
/// smallest substep `max_halvings` 6 allows), the handle force with `time_tol` 1e-5 m is closer than with one
/// step per frame, and closer again at 1e-6 m (measured: relative RMS 0.197, 8.9e-3, 4.5e-4; fixed dt/16, 192
/// substeps: 1.8e-2; 1e-5 takes 316).
#[test]
fn tighter_tolerances_follow_the_reference_more_closely() {
    let mut s = coarse("stretch-x", 0.02, 0.2);
    s.damping = 1e-3;
    let mut fine = s.clone();
    fine.dt = s.dt / 64.0;
    let reference: Vec<f64> = forces(&fine).into_iter().skip(63).step_by(64).collect();
    let rms = |f: &[f64]| {
        let e2: f64 = f.iter().zip(&reference).map(|(a, b)| (a - b).powi(2)).sum();
        let r2: f64 = reference.iter().map(|b| b * b).sum();
        (e2 / r2).sqrt()
    };
    assert_eq!(reference.len(), s.steps());
    let plain = rms(&forces(&s));
    s.solver.time_tol = Some(1e-5);
    let loose = rms(&forces(&s));
    s.solver.time_tol = Some(1e-6);
    let tight = rms(&forces(&s));
    assert!(
        tight < 0.2 * loose && loose < 0.2 * plain,
        "relative RMS: none {plain:.3e}, 1e-5 {loose:.3e}, 1e-6 {tight:.3e}"
    );
}

/// ARCSim's linearised implicit Euler (`"integrator": "linearized"`): one Newton step per substep, `substeps`
/// equal substeps per step; a consistent scheme, so with 16 substeps per frame its handle force on the coarse
/// stretch-x follows the implicit-Euler reference with dt/64 as implicit Euler with 16 fixed substeps does
/// (measured relative RMS 1.8e-2 for both). With air drag (ARCSim's wind, density 7) the step must linearise
/// the drag about the current velocity: linearised about zero velocity (a step from xₙ), the quadratic drag
/// drops out of the step and the elastic energy converges to another solution (on the original's
/// basket_stretchX 34 % above the limit at 0.083 s); here the largest relative energy error over the frames from
/// 0.05 s stays below 3 %.
#[test]
fn the_linearized_scheme_takes_one_newton_step_per_substep() {
    let mut s = coarse("stretch-x", 0.02, 0.2);
    s.damping = 1e-3;
    s.wind.density = 7.0;
    let mut fine = s.clone();
    fine.dt = s.dt / 64.0;
    let fine_log = reports(&fine);
    let reference: Vec<f64> = fine_log
        .iter()
        .skip(63)
        .step_by(64)
        .map(|r| r.handle_forces[1].1[0])
        .collect();
    let energies: Vec<f64> = fine_log
        .iter()
        .skip(63)
        .step_by(64)
        .map(|r| r.energy_elastic)
        .collect();
    s.solver.integrator = hylc::shell::solver::Integrator::Linearized;
    s.solver.substeps = 16;
    let log = reports(&s);
    for r in &log {
        assert_eq!((r.substeps, r.newton), (16, 16), "step {}", r.step);
    }
    let f: Vec<f64> = log.iter().map(|r| r.handle_forces[1].1[0]).collect();
    let e2: f64 = f.iter().zip(&reference).map(|(a, b)| (a - b).powi(2)).sum();
    let r2: f64 = reference.iter().map(|b| b * b).sum();
    let rms = (e2 / r2).sqrt();
    let energy = log
        .iter()
        .zip(&energies)
        .filter(|(r, _)| r.time >= 0.05 - 1e-9)
        .map(|(r, e)| (r.energy_elastic - e).abs() / e)
        .fold(0.0, f64::max);
    eprintln!("linearized, 16 substeps: force relative RMS {rms:.3e}, energy max {energy:.3e}");
    assert!(rms < 0.05, "force relative RMS {rms:.3e}");
    assert!(energy < 0.03, "energy relative error {energy:.3e}");
}

/// BDF2 is second order: on the coarse stretch-x over 0.2 s, against a BDF2 reference with dt/64, halving the
/// substep from dt/8 to dt/16 divides its handle-force error by about 4 (measured 4.1e-3 → 1.1e-3), implicit
/// Euler's by about 2 (4.6e-2 → 2.5e-2 against the same reference); and its tolerance-chosen substeps meet a
/// tighter tolerance with fewer substeps than implicit Euler (1e-5 m: 110 substeps, 3.4e-3).
#[test]
fn bdf2_converges_at_second_order() {
    use hylc::shell::solver::Integrator;
    let mut s = coarse("stretch-x", 0.02, 0.2);
    s.damping = 1e-3;
    let mut fine = s.clone();
    fine.dt = s.dt / 64.0;
    fine.solver.integrator = Integrator::Bdf2;
    let reference: Vec<f64> = forces(&fine).into_iter().skip(63).step_by(64).collect();
    let rms = |f: &[f64]| {
        let e2: f64 = f.iter().zip(&reference).map(|(a, b)| (a - b).powi(2)).sum();
        let r2: f64 = reference.iter().map(|b| b * b).sum();
        (e2 / r2).sqrt()
    };
    let error = |integrator: Integrator, k: usize| {
        let mut c = s.clone();
        c.dt = s.dt / k as f64;
        c.solver.integrator = integrator;
        let f: Vec<f64> = forces(&c).into_iter().skip(k - 1).step_by(k).collect();
        rms(&f)
    };
    let (b8, b16) = (error(Integrator::Bdf2, 8), error(Integrator::Bdf2, 16));
    let (e8, e16) = (
        error(Integrator::ImplicitEuler, 8),
        error(Integrator::ImplicitEuler, 16),
    );
    assert!(b8 / b16 > 3.0, "BDF2: {b8:.3e} → {b16:.3e}");
    assert!(
        e8 / e16 < 2.5 && e8 / e16 > 1.5,
        "implicit Euler: {e8:.3e} → {e16:.3e}"
    );
    assert!(b16 < 0.1 * e16, "BDF2 {b16:.3e}, implicit Euler {e16:.3e}");
    s.solver.integrator = Integrator::Bdf2;
    s.solver.time_tol = Some(1e-5);
    let log = reports(&s);
    let f: Vec<f64> = log.iter().map(|r| r.handle_forces[1].1[0]).collect();
    let substeps: usize = log.iter().map(|r| r.substeps).sum();
    assert!(
        rms(&f) < 0.01 && substeps < 200,
        "{:.3e} in {substeps} substeps",
        rms(&f)
    );
    assert!(log.iter().all(|r| r.error_estimate <= 1e-5));
}
