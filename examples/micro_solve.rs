//! One micro solve (`docs/micro-solver.md`): generate the plain weave, solve the yarn equilibrium at one macro
//! strain and print the homogenized energy density Ψ̄ = E / (p₁ p₂) and the envelope-theorem stress
//! σ_k = ∂Ψ̄/∂z_k. The pattern is solved as generated; `hylc run` first brings it to its reference state
//! (Algorithm C1, `hylc::micro::reference`).
//!
//! `cargo run --release --example micro_solve -- [S_X] [S_A] [S_Y]` (defaults: 0.05 0 0; no bending).

use hylc::generate::default_pattern;
use hylc::micro::envelope::energy_strain_gradient;
use hylc::micro::{MacroStrain, MicroProblem, SolverOptions, Status};
use hylc::rod::YarnMaterial;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let arg = |i: usize, default: f64| args.get(i).copied().unwrap_or(default);
    let z = MacroStrain::new(arg(0, 0.05), arg(1, 0.0), arg(2, 0.0), 0.0, 0.0);

    // the generated plain weave (2 + 2 yarns, 1 cm tile), the default yarn (E = 1 MPa, r = 1 mm)
    let pattern = default_pattern("plain")?;
    println!(
        "plain weave: {} vertices, periods {:.4} × {:.4} m",
        pattern.len(),
        pattern.periods[0],
        pattern.periods[1]
    );
    let problem = MicroProblem::new(pattern, &YarnMaterial::default(), SolverOptions::default());

    let t0 = Instant::now();
    let solution = problem.solve(&z, None)?; // cold, from the reference state
    println!(
        "strain {z}: {:?} after {} Newton steps, ‖g‖∞ = {:.2e} N, {:.2} s",
        solution.status,
        solution.steps,
        solution.gradient_norm,
        t0.elapsed().as_secs_f64()
    );
    if solution.status != Status::Converged {
        return Err("the solve did not converge".into());
    }

    let e = solution.energy;
    println!(
        "tile energy (J): stretch {:.4e}, bend {:.4e}, twist {:.4e}, contact {:.4e}",
        e.stretch, e.bend, e.twist, e.contact
    );
    println!("Ψ̄ = {:.6e} J/m²", solution.psi()?);

    // σ_k = (∂E/∂z_k) / (p₁ p₂) at the equilibrium (envelope theorem); `None` for the bending component the
    // surface map's family does not parametrise
    let de_dz = energy_strain_gradient(&problem, &solution.state)?;
    for (name, g) in ["s_x", "s_a", "s_y", "II00", "II11"].iter().zip(de_dz) {
        match g {
            Some(g) => println!(
                "σ_{name} = ∂Ψ̄/∂{name} = {:+.6e} J/m² per unit strain",
                g / solution.area
            ),
            None => println!("σ_{name}: not defined in this family"),
        }
    }
    Ok(())
}
