//! The reference state of a pattern (Algorithm C1; `03-homogenization.md`, section 6):
//! 1. stress-free state: repeat { rest values ← current values; relax at zero strain } until the relaxed energy is
//!    below 1e-10 · k_s · (mean rest length) — contacts resolved, the rest shape equals the shape;
//! 2. tension: knitted patterns get rest lengths × 0.9 and rest curvatures × 0.8, woven ones rest curvatures × 0.9
//!    (the factors are options);
//! 3. in-plane minimum: periods with zero macro stress ∂Ψ̄/∂s_x = ∂Ψ̄/∂s_y = 0 at s_a = 0, found by Newton's
//!    method on the envelope-theorem stress (its 2×2 Jacobian by central differences of warm-started solves); the
//!    equilibrium at those strains becomes the new reference (positions, angles, frames, periods p (1 + s));
//! 4. centring: the Voronoi-length-weighted mean of (ξ₁, ξ₂, h) moves to the origin.
//!
//! The result is a [`Pattern`] like a loaded `.pyp` file (and writable as one).

use super::envelope::energy_strain_gradient;
use super::solver::{world_positions, MicroError, MicroProblem, MicroState, SolverOptions};
use super::strain::MacroStrain;
use crate::pattern::Pattern;
use crate::rod::{set_rest_to_current, YarnMaterial};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Knitted or woven: selects the tension factors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Construction {
    Knitted,
    Woven,
}

/// Settings of Algorithm C1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReferenceOptions {
    /// Rest-length factor of knitted patterns.
    pub knit_length: f64,
    /// Rest-curvature factor of knitted patterns.
    pub knit_curvature: f64,
    /// Rest-curvature factor of woven patterns.
    pub woven_curvature: f64,
    /// Run steps 1 and 2 (stress-free state, tension). Off to re-equilibrate a pattern that already is a
    /// reference state (e.g. a loaded `.pyp` with another yarn model): steps 3 and 4 only.
    pub stress_free_and_tension: bool,
    /// Stress-free rounds before giving up.
    pub max_rounds: usize,
    /// Factor on Y and G during the stress-free rounds. The rest shape is reset to the relaxed shape after every
    /// round, so the rod stiffness used there only sets how far a round moves; at full stiffness interlocked
    /// loops (knits) lengthen by ~k_c/k_s per round and need thousands of rounds. The final state is
    /// stress-free (rest shape = shape, no contact energy) whatever the factor.
    pub stress_free_softening: f64,
    /// Newton iterations of the in-plane minimum.
    pub max_period_steps: usize,
    /// Zero-stress tolerance: |∂E/∂s_k| / p_k ≤ tolerance · k_s (a tile force relative to the stretching
    /// stiffness).
    pub stress_tolerance: f64,
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        ReferenceOptions {
            knit_length: 0.9,
            knit_curvature: 0.8,
            woven_curvature: 0.9,
            stress_free_and_tension: true,
            max_rounds: 200,
            stress_free_softening: 1e-3,
            max_period_steps: 30,
            stress_tolerance: 1e-7,
        }
    }
}

/// What the reference computation did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceReport {
    /// Stress-free rounds and the relaxed energy after the last one (J).
    pub rounds: usize,
    pub stress_free_energy: f64,
    /// Strains (s_x, s_y) of the in-plane minimum relative to the tensioned pattern's periods.
    pub period_strain: [f64; 2],
    /// Newton iterations of the in-plane minimum and the final tile forces |∂E/∂s_k|/p_k (N).
    pub period_steps: usize,
    pub residual_force: [f64; 2],
    /// Periods before and after.
    pub periods_in: [f64; 2],
    pub periods_out: [f64; 2],
    /// Ψ̄ of the final reference state (J/m²).
    pub psi: f64,
    /// Wall time (s).
    pub time: f64,
}

/// Why the reference computation failed.
#[derive(Debug)]
pub enum ReferenceError {
    Solve(MicroError),
    NotConverged(String),
}

impl std::fmt::Display for ReferenceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReferenceError::Solve(e) => write!(f, "{e}"),
            ReferenceError::NotConverged(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for ReferenceError {}

impl From<MicroError> for ReferenceError {
    fn from(e: MicroError) -> Self {
        ReferenceError::Solve(e)
    }
}

/// Write an in-plane equilibrium (s_a = 0, no bending) back into a pattern: world positions become the reference
/// coordinates, the periods stretch by (1 + s_x, 1 + s_y), angles, reference directors and reference twists come
/// from the state; rest values are kept.
pub fn pattern_from_state(p: &Pattern, state: &MicroState) -> Pattern {
    let z = state.strain.0;
    debug_assert!(z[1] == 0.0 && z[3] == 0.0 && z[4] == 0.0);
    let n = p.len();
    let mut out = p.clone();
    out.positions = world_positions(p, state);
    out.theta = state.y[3 * n..].to_vec();
    for (e, d) in out.edges.iter_mut().zip(&state.frames.directors) {
        e.ref_director = *d;
    }
    out.ref_twist = state.frames.ref_twist.clone();
    out.periods = [p.periods[0] * (1.0 + z[0]), p.periods[1] * (1.0 + z[2])];
    out
}

/// Algorithm C1 on `pattern`.
pub fn reference_state(
    pattern: &Pattern,
    material: &YarnMaterial,
    construction: Construction,
    solver: &SolverOptions,
    options: &ReferenceOptions,
) -> Result<(Pattern, ReferenceReport), ReferenceError> {
    let t0 = std::time::Instant::now();
    let mut p = pattern.clone();
    let ks = {
        let mut m = material.clone();
        m.radius = p.radius;
        m.stretch_stiffness()
    };
    let mean_rest = p.edges.iter().map(|e| e.rest_length).sum::<f64>() / p.len() as f64;

    // 1. stress-free state
    let mut rounds = 0;
    let mut energy = if options.stress_free_and_tension {
        f64::INFINITY
    } else {
        0.0
    };
    let mut soft = material.clone();
    soft.young *= options.stress_free_softening;
    soft.shear *= options.stress_free_softening;
    while options.stress_free_and_tension && rounds < options.max_rounds {
        rounds += 1;
        set_rest_to_current(&mut p);
        let problem = MicroProblem::new(p.clone(), &soft, solver.clone());
        let sol = problem.solve(&MacroStrain::ZERO, None)?;
        sol.psi().map_err(|e| {
            ReferenceError::NotConverged(format!("stress-free round {rounds}: {e}"))
        })?;
        energy = sol.energy.total();
        p = pattern_from_state(&p, &sol.state);
        if energy < 1e-10 * ks * mean_rest {
            break;
        }
    }
    if energy >= 1e-10 * ks * mean_rest {
        return Err(ReferenceError::NotConverged(format!(
            "no stress-free state after {rounds} rounds: relaxed energy {energy:.3e} J (target {:.3e} J)",
            1e-10 * ks * mean_rest
        )));
    }
    if options.stress_free_and_tension {
        set_rest_to_current(&mut p);
    }

    // 2. tension
    match construction {
        _ if !options.stress_free_and_tension => {}
        Construction::Knitted => {
            for e in p.edges.iter_mut() {
                e.rest_length *= options.knit_length;
            }
            for k in p.rest_curvature.iter_mut() {
                k[0] *= options.knit_curvature;
                k[1] *= options.knit_curvature;
            }
        }
        Construction::Woven => {
            for k in p.rest_curvature.iter_mut() {
                k[0] *= options.woven_curvature;
                k[1] *= options.woven_curvature;
            }
        }
    }
    let periods_in = p.periods;

    // 3. in-plane minimum by Newton on the envelope stress
    let problem = MicroProblem::new(p.clone(), material, solver.clone());
    let force = |state: &MicroState| -> Result<[f64; 2], MicroError> {
        let d = energy_strain_gradient(&problem, state)?;
        Ok([
            d[0].expect("in-plane family") / periods_in[0],
            d[2].expect("in-plane family") / periods_in[1],
        ])
    };
    let solve = |s: [f64; 2], warm: Option<&MicroState>| -> Result<MicroState, ReferenceError> {
        let z = MacroStrain::in_plane(s[0], 0.0, s[1]);
        let sol = problem.solve(&z, warm)?;
        sol.psi()
            .map_err(|e| ReferenceError::NotConverged(format!("in-plane minimum at {z}: {e}")))?;
        Ok(sol.state)
    };
    let mut s = [0.0, 0.0];
    let mut state = solve(s, None)?;
    let mut f = force(&state)?;
    let mut steps = 0;
    let tol = options.stress_tolerance * ks;
    while f[0].abs().max(f[1].abs()) > tol {
        if steps >= options.max_period_steps {
            return Err(ReferenceError::NotConverged(format!(
                "no zero-stress periods after {steps} Newton steps: tile forces {:.3e}, {:.3e} N (target {tol:.1e} N)",
                f[0], f[1]
            )));
        }
        steps += 1;
        // Jacobian of the tile forces by central differences of warm-started solves
        let h = 1e-4;
        let mut jac = nalgebra::Matrix2::zeros();
        for k in 0..2 {
            let (mut sp, mut sm) = (s, s);
            sp[k] += h;
            sm[k] -= h;
            let fp = force(&solve(sp, Some(&state))?)?;
            let fm = force(&solve(sm, Some(&state))?)?;
            jac[(0, k)] = (fp[0] - fm[0]) / (2.0 * h);
            jac[(1, k)] = (fp[1] - fm[1]) / (2.0 * h);
        }
        let rhs = nalgebra::Vector2::new(-f[0], -f[1]);
        let mut ds = jac
            .lu()
            .solve(&rhs)
            .unwrap_or_else(|| rhs * (1e-3 / rhs.norm().max(1e-300)));
        let len = ds.norm();
        if len > 0.05 {
            ds *= 0.05 / len;
        }
        // accept the step if it lowers the force norm, else halve it
        let fnorm = (f[0] * f[0] + f[1] * f[1]).sqrt();
        let mut accepted = false;
        for _ in 0..20 {
            let trial = [s[0] + ds[0], s[1] + ds[1]];
            if let Ok(st) = solve(trial, Some(&state)) {
                let ft = force(&st)?;
                if (ft[0] * ft[0] + ft[1] * ft[1]).sqrt() < fnorm {
                    s = trial;
                    state = st;
                    f = ft;
                    accepted = true;
                    break;
                }
            }
            ds *= 0.5;
        }
        if !accepted {
            return Err(ReferenceError::NotConverged(format!(
                "the zero-stress search stalled at s = ({:.3e}, {:.3e}) with tile forces {:.3e}, {:.3e} N",
                s[0], s[1], f[0], f[1]
            )));
        }
    }
    let mut out = pattern_from_state(&p, &state);

    // 4. centring
    let w = out.voronoi_lengths();
    let total: f64 = w.iter().sum();
    let centre: Vector3<f64> = out
        .positions
        .iter()
        .zip(&w)
        .map(|(x, wi)| x * *wi)
        .sum::<Vector3<f64>>()
        / total;
    for x in out.positions.iter_mut() {
        *x -= centre;
    }

    // the final state's Ψ̄ at its own zero strain
    let check = MicroProblem::new(out.clone(), material, solver.clone());
    let sol = check.solve(&MacroStrain::ZERO, None)?;
    let psi = sol
        .psi()
        .map_err(|e| ReferenceError::NotConverged(format!("final reference state: {e}")))?;
    let report = ReferenceReport {
        rounds,
        stress_free_energy: energy,
        period_strain: s,
        period_steps: steps,
        residual_force: f,
        periods_in,
        periods_out: out.periods,
        psi,
        time: t0.elapsed().as_secs_f64(),
    };
    Ok((out, report))
}
