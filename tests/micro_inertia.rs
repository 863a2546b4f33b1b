//! Inertia-controlled Newton steps (`SolverOptions::inertia`, the default; issue 20; `03-homogenization.md`,
//! section 3), on the generated plain weave (no external data needed).

use hylc::generate::default_pattern;
use hylc::micro::{MacroStrain, MicroProblem, Solution, SolverOptions, Status};
use hylc::rod::YarnMaterial;

fn solver(options: SolverOptions) -> MicroProblem {
    MicroProblem::new(
        default_pattern("plain").unwrap(),
        &YarnMaterial::default(),
        options,
    )
}

fn problem(inertia: bool) -> MicroProblem {
    solver(SolverOptions {
        inertia,
        ..Default::default()
    })
}

/// An option that is off by default is written to the settings JSON only while on (`on` = the defaults with it
/// set), and the JSON reads back.
fn written_only_while_on(on: SolverOptions, key: &str) {
    let off = serde_json::to_string(&SolverOptions::default()).unwrap();
    assert!(!off.contains(key), "{off}");
    let json = serde_json::to_string(&on).unwrap();
    assert!(json.contains(&format!("\"{key}\":true")), "{json}");
    assert_eq!(serde_json::from_str::<SolverOptions>(&json).unwrap(), on);
}

/// Both rules converge at `z` to the same Ψ̄ (1e-8 relative).
fn same_equilibrium(z: &MacroStrain, design: &Solution, inertia: &Solution) {
    assert_eq!(design.status, Status::Converged, "{z}");
    assert_eq!(inertia.status, Status::Converged, "inertia {z}");
    let (pa, pb) = (design.psi().unwrap(), inertia.psi().unwrap());
    eprintln!(
        "{z}: steps {} (design) vs {} (inertia, {} exact), psi {pa} vs {pb}",
        design.steps, inertia.steps, inertia.exact_steps
    );
    assert!((pa - pb).abs() <= 1e-8 * pa.abs(), "{z}: {pa} vs {pb}");
}

/// The inertia rule reaches the design rule's equilibria, cold and warm along a chain in s_x and one in II₀₀, in
/// no more Newton steps in all (it takes exact steps where the design rule shifts μ); with the rule off no exact
/// step is taken.
#[test]
fn inertia_steps_reach_the_same_equilibria_in_fewer_steps() {
    let (design, inertia) = (problem(false), problem(true));
    let (mut steps_design, mut steps_inertia, mut exact) = (0, 0, 0);
    for chain in [
        (0..5)
            .map(|k| MacroStrain::in_plane(-0.04 * k as f64, 0.1, 0.0))
            .collect::<Vec<_>>(),
        (0..5)
            .map(|k| MacroStrain::new(0.0, 0.0, 0.0, 20.0 * k as f64, 0.0))
            .collect(),
    ] {
        let (mut sa, mut sb) = (None, None);
        for z in &chain {
            let a = design.solve(z, sa.as_ref()).unwrap();
            let b = inertia.solve(z, sb.as_ref()).unwrap();
            same_equilibrium(z, &a, &b);
            assert_eq!(a.exact_steps, 0, "{z}: the design rule takes no exact step");
            steps_design += a.steps;
            steps_inertia += b.steps;
            exact += b.exact_steps;
            sa = Some(a.state);
            sb = Some(b.state);
        }
    }
    eprintln!("steps: design {steps_design}, inertia {steps_inertia} ({exact} exact)");
    assert!(steps_inertia <= steps_design);
}

/// The option is on by default and written to the settings JSON only while on, so that a settings record made
/// before it (no key) reads as off, the rule it was made with, and sample files made before it keep their problem
/// hash with `--no-inertia`.
#[test]
fn inertia_is_the_default_and_an_old_settings_record_reads_as_off() {
    let on = SolverOptions::default();
    assert!(on.inertia && on.inertia_steps());
    let json = serde_json::to_string(&on).unwrap();
    assert!(json.contains("\"inertia\":true"), "{json}");
    let off = SolverOptions {
        inertia: false,
        ..Default::default()
    };
    let json_off = serde_json::to_string(&off).unwrap();
    assert!(!json_off.contains("inertia"), "{json_off}");
    let back: SolverOptions = serde_json::from_str(&json).unwrap();
    assert_eq!(back, on);
    let back_off: SolverOptions = serde_json::from_str(&json_off).unwrap();
    assert_eq!(back_off, off);
}

/// `SolverOptions::exact_backoff`: on a compressed, bent plain weave solved cold (a solve whose exact attempts are
/// refused in runs) the skipped attempts change the path but not the equilibrium (Ψ̄ to 1e-8); the option is
/// off by default and written to the settings JSON only while on.
#[test]
fn exact_backoff_changes_the_path_not_the_equilibrium() {
    let z = MacroStrain::new(-0.4, 0.0, 0.0, 0.0, 150.0);
    let every_step = problem(true).solve(&z, None).unwrap();
    let on = SolverOptions {
        exact_backoff: true,
        ..Default::default()
    };
    let backoff = solver(on.clone()).solve(&z, None).unwrap();
    same_equilibrium(&z, &every_step, &backoff);
    assert_ne!(
        (every_step.steps, every_step.exact_steps),
        (backoff.steps, backoff.exact_steps),
        "the backoff skipped no exact attempt"
    );
    assert!(!SolverOptions::default().exact_backoff);
    written_only_while_on(on, "exact_backoff");
}

/// `SolverOptions::interpolating_search`: on the compressed, bent plain weave solved cold (a solve that
/// backtracks) the interpolated trial steps change the path but not the equilibrium (Ψ̄ to 1e-8); the option is
/// off by default and written to the settings JSON only while on.
#[test]
fn interpolating_search_changes_the_path_not_the_equilibrium() {
    let z = MacroStrain::new(-0.4, 0.0, 0.0, 0.0, 150.0);
    let factor = problem(true).solve(&z, None).unwrap();
    let on = SolverOptions {
        interpolating_search: true,
        ..Default::default()
    };
    let interpolated = solver(on.clone()).solve(&z, None).unwrap();
    same_equilibrium(&z, &factor, &interpolated);
    assert_ne!(
        factor.steps, interpolated.steps,
        "the interpolated trial steps changed nothing"
    );
    assert!(!SolverOptions::default().interpolating_search);
    written_only_while_on(on, "interpolating_search");
}
