//! `hylc sensitivity PATTERN --z …`: Ψ̄ and its derivatives with respect to the strain and the yarn parameters
//! at one strain (envelope theorem; `docs/micro-solver.md`, `hylc::micro::envelope`), and the equilibrium's
//! sensitivity to each yarn parameter (`hylc::micro::sensitivity`, docs/yarn-parameters.md).

use crate::args::YarnArgs;
use crate::strain::{load_pattern_noted, parse_strain};
use hylc::micro::envelope::{
    parameter_derivatives, strain_derivatives, strain_stiffness, PARAMETER_NAMES,
};
use hylc::micro::sensitivity::{equilibrium_sensitivities, YarnParameter};
use hylc::micro::{MicroProblem, SolverOptions};
use hylc::strain::StrainComponent;
use std::process::ExitCode;

/// Ψ̄ at one strain with its derivatives with respect to the strain and to the yarn parameters (envelope
/// theorem).
#[derive(clap::Args)]
pub struct Args {
    /// `.pyp` file or generated kind
    pattern: String,
    /// strain s_x,s_a,s_y[,II00,II11]
    #[arg(long = "z", allow_hyphen_values = true, default_value = "0,0,0")]
    z: String,
    #[command(flatten)]
    yarn: YarnArgs,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let yarn = a.yarn.material()?;
    let p = load_pattern_noted(&a.pattern)?;
    a.yarn.warn_radius(&yarn, &a.pattern, p.radius);
    let problem = MicroProblem::new(p, &yarn, SolverOptions::default());
    let strain = parse_strain(&a.z)?;
    let sol = problem.solve(&strain, None)?;
    let psi = sol.psi()?;
    let ds = strain_derivatives(&problem, &sol.state)?;
    let dp = parameter_derivatives(&problem, &sol)?;
    println!("Ψ̄ = {psi:.6e} J/m² ({} steps)", sol.steps);
    for (n, v) in StrainComponent::NAMES.iter().zip(ds) {
        match v {
            Some(v) => println!("  ∂Ψ̄/∂{n} = {v:.6e}"),
            None => println!("  ∂Ψ̄/∂{n}: not available (bending along the other axis)"),
        }
    }
    let dy = equilibrium_sensitivities(&problem, &sol)?;
    let n = problem.pattern.len();
    let r = problem.pattern.radius;
    for ((name, v), (param, d)) in PARAMETER_NAMES
        .iter()
        .zip(dp)
        .zip(YarnParameter::ALL.iter().zip(&dy))
    {
        // the equilibrium's response to a relative change of θ: the largest vertex displacement per unit ln θ
        let theta = param.get(&problem.material);
        let largest = (0..n)
            .map(|v| (d[3 * v].powi(2) + d[3 * v + 1].powi(2) + d[3 * v + 2].powi(2)).sqrt())
            .fold(0.0, f64::max);
        println!(
            "  ∂Ψ̄/∂{name} = {v:.6e}; max |dx*/d ln {name}| = {:.4e} r",
            theta * largest / r
        );
    }
    let st = strain_stiffness(&problem, &sol.state)?;
    let names: Vec<&str> = st
        .components
        .iter()
        .map(|&k| StrainComponent::NAMES[k])
        .collect();
    println!("  d²Ψ̄/dz² over ({}):", names.join(", "));
    for i in 0..names.len() {
        let row: Vec<String> = (0..names.len())
            .map(|j| format!("{:>13.5e}", st.hessian[(i, j)]))
            .collect();
        println!("    {}", row.join(" "));
    }
    Ok(ExitCode::SUCCESS)
}
