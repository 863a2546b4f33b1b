//! The reference state of a pattern (Algorithm C1; `docs/micro-solver.md`, section 6):
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
use super::solver::{
    world_positions, MicroError, MicroProblem, MicroState, NotConverged, SolverOptions,
};
use super::strain::MacroStrain;
use crate::pattern::Pattern;
use crate::rod::{set_rest_to_current, YarnMaterial};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Knitted or woven: selects the tension factors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Construction {
    /// Knitted: rest lengths × 0.9 and rest curvatures × 0.8.
    Knitted,
    /// Woven: rest curvatures × 0.9.
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
    /// The relaxed energy after the last stress-free round (J).
    pub stress_free_energy: f64,
    /// Strains (s_x, s_y) of the in-plane minimum relative to the tensioned pattern's periods.
    pub period_strain: [f64; 2],
    /// Newton iterations of the in-plane minimum and the final tile forces |∂E/∂s_k|/p_k (N).
    pub period_steps: usize,
    /// The final tile forces |∂E/∂s_k|/p_k (N).
    pub residual_force: [f64; 2],
    /// Periods before and after.
    pub periods_in: [f64; 2],
    /// The periods after (m).
    pub periods_out: [f64; 2],
    /// Ψ̄ of the final reference state (J/m²).
    pub psi: f64,
    /// Wall time (s).
    pub time: f64,
}

/// Why the reference computation failed.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// A micro solve stopped with an error.
    #[error(transparent)]
    Solve(#[from] MicroError),
    /// A micro solve of the computation did not converge; `stage` says which ("stress-free round 3", "in-plane
    /// minimum at (…)", "final reference state").
    #[error("{stage}: {source}")]
    Unconverged {
        /// which solve
        stage: String,
        /// how it ended
        source: NotConverged,
    },
    /// Step 1 did not reach a stress-free state within the allowed rounds.
    #[error(
        "no stress-free state after {rounds} rounds: relaxed energy {energy:.3e} J (target {target:.3e} J)"
    )]
    NoStressFreeState {
        /// stress-free rounds made
        rounds: usize,
        /// the relaxed energy after the last (J)
        energy: f64,
        /// the target 1e-10 · k_s · (mean rest length) (J)
        target: f64,
    },
    /// Step 3 did not reach zero tile forces within the allowed Newton steps.
    #[error(
        "no zero-stress periods after {steps} Newton steps: tile forces {:.3e}, {:.3e} N (target {tolerance:.1e} N)",
        .force[0],
        .force[1]
    )]
    NoZeroStressPeriods {
        /// Newton steps made
        steps: usize,
        /// the final tile forces |∂E/∂s_k|/p_k (N)
        force: [f64; 2],
        /// the target force (N)
        tolerance: f64,
    },
    /// Step 3 found no strain step that lowers the tile forces.
    #[error(
        "the zero-stress search stalled at s = ({:.3e}, {:.3e}) with tile forces {:.3e}, {:.3e} N",
        .s[0],
        .s[1],
        .force[0],
        .force[1]
    )]
    PeriodSearchStalled {
        /// the strains (s_x, s_y) reached
        s: [f64; 2],
        /// the tile forces there (N)
        force: [f64; 2],
    },
}

/// The error of a micro solve at `stage` that did not converge.
fn unconverged(stage: String) -> impl FnOnce(NotConverged) -> ReferenceError {
    move |source| ReferenceError::Unconverged { stage, source }
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

    // 1. stress-free state
    let (rounds, energy) = stress_free(&mut p, material, solver, options, ks)?;

    // 2. tension
    if options.stress_free_and_tension {
        tension(&mut p, construction, options);
    }
    let periods_in = p.periods;

    // 3. in-plane minimum by Newton on the envelope stress
    let search = PeriodSearch {
        problem: MicroProblem::new(p.clone(), material, solver.clone()),
        periods_in,
    };
    let (minimum, period_steps) =
        search.run(options.stress_tolerance * ks, options.max_period_steps)?;
    let mut out = pattern_from_state(&p, &minimum.state);

    // 4. centring
    centre(&mut out);

    // the final state's Ψ̄ at its own zero strain
    let check = MicroProblem::new(out.clone(), material, solver.clone());
    let sol = check.solve(&MacroStrain::ZERO, None)?;
    let psi = sol
        .psi()
        .map_err(unconverged("final reference state".into()))?;
    let report = ReferenceReport {
        rounds,
        stress_free_energy: energy,
        period_strain: minimum.s,
        period_steps,
        residual_force: minimum.force,
        periods_in,
        periods_out: out.periods,
        psi,
        time: t0.elapsed().as_secs_f64(),
    };
    Ok((out, report))
}

/// Step 1, the stress-free state: rounds of { rest values ← current values; relax at zero strain with the
/// softened material } until the relaxed energy is below 1e-10 · k_s · (mean rest length); the rest values are
/// then set to the relaxed shape. Returns the rounds and the last relaxed energy (0 and no change when
/// `options.stress_free_and_tension` is off).
fn stress_free(
    p: &mut Pattern,
    material: &YarnMaterial,
    solver: &SolverOptions,
    options: &ReferenceOptions,
    ks: f64,
) -> Result<(usize, f64), ReferenceError> {
    let mean_rest = p.edges.iter().map(|e| e.rest_length).sum::<f64>() / p.len() as f64;
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
        set_rest_to_current(p);
        let problem = MicroProblem::new(p.clone(), &soft, solver.clone());
        let sol = problem.solve(&MacroStrain::ZERO, None)?;
        sol.psi()
            .map_err(unconverged(format!("stress-free round {rounds}")))?;
        energy = sol.energy.total();
        *p = pattern_from_state(p, &sol.state);
        if energy < 1e-10 * ks * mean_rest {
            break;
        }
    }
    if energy >= 1e-10 * ks * mean_rest {
        return Err(ReferenceError::NoStressFreeState {
            rounds,
            energy,
            target: 1e-10 * ks * mean_rest,
        });
    }
    if options.stress_free_and_tension {
        set_rest_to_current(p);
    }
    Ok((rounds, energy))
}

/// Step 2, tension: knitted patterns get rest lengths × `knit_length` and rest curvatures × `knit_curvature`,
/// woven ones rest curvatures × `woven_curvature`.
fn tension(p: &mut Pattern, construction: Construction, options: &ReferenceOptions) {
    match construction {
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
}

/// Step 4, centring: the Voronoi-length-weighted mean of the positions moves to the origin.
fn centre(out: &mut Pattern) {
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
}

/// Step 3, the in-plane minimum: strains (s_x, s_y) at s_a = 0 where the tile forces ∂E/∂s_k / p_k (envelope
/// theorem, p the tensioned pattern's periods) vanish.
struct PeriodSearch {
    problem: MicroProblem,
    periods_in: [f64; 2],
}

/// An equilibrium of the zero-stress search: its strains (s_x, s_y), state and tile forces (N).
struct Equilibrium {
    s: [f64; 2],
    state: MicroState,
    force: [f64; 2],
}

impl PeriodSearch {
    /// The tile forces ∂E/∂s_x / p₁, ∂E/∂s_y / p₂ (N) at an in-plane equilibrium.
    fn force(&self, state: &MicroState) -> Result<[f64; 2], MicroError> {
        let d = energy_strain_gradient(&self.problem, state)?;
        Ok([
            d[0].expect("in-plane family") / self.periods_in[0],
            d[2].expect("in-plane family") / self.periods_in[1],
        ])
    }

    /// The converged equilibrium at (s_x, 0, s_y), warm-started from `warm` when given.
    fn solve(&self, s: [f64; 2], warm: Option<&MicroState>) -> Result<MicroState, ReferenceError> {
        let z = MacroStrain::in_plane(s[0], 0.0, s[1]);
        let sol = self.problem.solve(&z, warm)?;
        sol.psi()
            .map_err(unconverged(format!("in-plane minimum at {z}")))?;
        Ok(sol.state)
    }

    /// Newton's method on the forces from s = 0 until both are within `tol` (N), at most `max_steps` steps:
    /// the equilibrium found and the steps taken.
    fn run(&self, tol: f64, max_steps: usize) -> Result<(Equilibrium, usize), ReferenceError> {
        let s = [0.0, 0.0];
        let state = self.solve(s, None)?;
        let force = self.force(&state)?;
        let mut at = Equilibrium { s, state, force };
        let mut steps = 0;
        while at.force[0].abs().max(at.force[1].abs()) > tol {
            if steps >= max_steps {
                return Err(ReferenceError::NoZeroStressPeriods {
                    steps,
                    force: at.force,
                    tolerance: tol,
                });
            }
            steps += 1;
            let ds = self.newton_step(&at)?;
            let Some(next) = self.backtrack(&at, ds)? else {
                return Err(ReferenceError::PeriodSearchStalled {
                    s: at.s,
                    force: at.force,
                });
            };
            at = next;
        }
        Ok((at, steps))
    }

    /// The Newton step −J⁻¹ f at `at`, its Jacobian J by central differences (h = 1e-4) of solves warm-started
    /// from `at`, the step length limited to 0.05 (a small step along −f when J is singular).
    fn newton_step(&self, at: &Equilibrium) -> Result<nalgebra::Vector2<f64>, ReferenceError> {
        let (s, f) = (at.s, at.force);
        let h = 1e-4;
        let mut jac = nalgebra::Matrix2::zeros();
        for k in 0..2 {
            let (mut sp, mut sm) = (s, s);
            sp[k] += h;
            sm[k] -= h;
            let fp = self.force(&self.solve(sp, Some(&at.state))?)?;
            let fm = self.force(&self.solve(sm, Some(&at.state))?)?;
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
        Ok(ds)
    }

    /// The first of s + ds, s + ds/2, … (20 trials) whose solve converges with a smaller force norm than at
    /// `at`; `None` when none does.
    fn backtrack(
        &self,
        at: &Equilibrium,
        mut ds: nalgebra::Vector2<f64>,
    ) -> Result<Option<Equilibrium>, ReferenceError> {
        let (s, f) = (at.s, at.force);
        let fnorm = (f[0] * f[0] + f[1] * f[1]).sqrt();
        for _ in 0..20 {
            let trial = [s[0] + ds[0], s[1] + ds[1]];
            if let Ok(st) = self.solve(trial, Some(&at.state)) {
                let ft = self.force(&st)?;
                if (ft[0] * ft[0] + ft[1] * ft[1]).sqrt() < fnorm {
                    return Ok(Some(Equilibrium {
                        s: trial,
                        state: st,
                        force: ft,
                    }));
                }
            }
            ds *= 0.5;
        }
        Ok(None)
    }
}
