//! Inertia-controlled Newton steps (`StepRule::Inertia`, the default; `docs/micro-solver.md`, "Inertia-controlled
//! Newton steps"), on the generated plain weave (no external data needed).

use hylc::generate::default_pattern;
use hylc::micro::{MacroStrain, MicroProblem, Solution, SolverOptions, Status, StepRule};
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
        step_rule: if inertia {
            StepRule::Inertia
        } else {
            StepRule::Shift
        },
        ..Default::default()
    })
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
