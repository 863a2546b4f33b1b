//! The micro-scale Newton solver (Algorithms C2, C3; `docs/micro-solver.md`, sections 2–4).
//!
//! A [`MicroProblem`] holds one pattern (its reference state), the yarn material and the solver options; its
//! [`solve`](MicroProblem::solve) finds the yarn equilibrium at a macro strain, cold from the reference state or
//! warm from a neighbouring solution. Each Newton step:
//! 1. evaluates E, the reduced gradient and Hessian at y with the frames stored at y (exact Hessian);
//! 2. tests convergence on ‖g‖_∞ ≤ tol·k_s and on the Newton decrement;
//! 3. solves the KKT system of the null-space constraints with the unit scaling (r θ as the angular unknown),
//!    growing μ ×10 while H + μI is not positive definite and shrinking it after successful steps; with
//!    [`StepRule::Inertia`] (the default) the exact step at μ's floor comes first wherever H is positive
//!    definite on the constraint space, kept when the energy follows its quadratic model;
//! 4. limits the largest vertex displacement to r · λ_min(Ī);
//! 5. backtracks y₀ + 0.1ⁱ δy, i = 0 … 10, transporting the stored frames to each trial (the stored frames are
//!    only replaced when a trial is accepted), refreshing the contact candidates when vertices have moved by more
//!    than half the broad-phase margin, and accepts the first lower energy.
//!
//! Step rules that were measured and not adopted (projected exact steps, a kept shift, per-stencil PSD projection,
//! an exact-attempt backoff, an interpolating line search, a trust region, other displacement limits and
//! backtracking factors, the tangent predictor) are described with their measurements in
//! `docs/notes/retired-micro-solver-rules.md`.
//!
//! Every result carries its [`Status`]; [`Solution::psi`] refuses a non-converged one.

use super::elimination::Elimination;
use super::linear::{FactorError, Factorization, KktSolver};
pub use super::options::{CrossingGuard, SolverOptions, StepRule};
use super::strain::{Family, MacroStrain, StrainError};
use crate::contact::ccd::{net_crossings, Crossing};
use crate::contact::ContactError;
use crate::pattern::Pattern;
use crate::rod::{RodState, RodTopology, YarnMaterial};
use crate::tile::{EnergyParts, Terms, Tile, TileEval, Want};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::time::Instant;

mod direction;
mod steps;

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Status {
    /// The force or Newton-decrement test passed.
    Converged,
    /// No trial step lowered the energy while the gradient was above round-off.
    Stalled,
    /// The step limit was reached.
    MaxSteps,
    /// The time limit was reached.
    TimeLimit,
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{self:?}")
    }
}

/// Errors that stop a solve before it runs or in the middle (bad input, overlapping yarns at the start).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MicroError {
    /// An inadmissible macro strain.
    #[error(transparent)]
    Strain(#[from] StrainError),
    /// The contact pairs could not be built (e.g. overlapping yarns at the start).
    #[error("contact: {0}")]
    Contact(#[from] ContactError),
    /// The KKT system could not be factorised.
    #[error("linear solve: {0}")]
    Linear(#[from] FactorError),
    /// A quantity defined at an equilibrium asked of a solve that did not converge.
    #[error("{what} need an equilibrium: {source}")]
    NeedsEquilibrium {
        /// What needs the equilibrium (e.g. "equilibrium sensitivities").
        what: &'static str,
        /// How the solve ended instead.
        source: NotConverged,
    },
    /// A constraint row of [`MicroProblem::with_constraints`] with the wrong number of entries.
    #[error("constraint row {row} has {len} entries, expected {expected}")]
    ConstraintLength {
        /// The row's index.
        row: usize,
        /// Its number of entries.
        len: usize,
        /// The number required (4n).
        expected: usize,
    },
    /// The tile energy (or Ψ̄ = E / (p₁ p₂)) is infinite or NaN at an iterate: the pattern or the start state is
    /// not physical (e.g. a rest length so small that the stretch energy overflows). Never reported as converged.
    #[error(
        "strain {strain}: the tile energy is {energy} J after {steps} Newton steps (not finite: the pattern or \
         its start state is not physical)"
    )]
    NonFiniteEnergy {
        /// The macro strain of the solve.
        strain: MacroStrain,
        /// Newton steps taken.
        steps: usize,
        /// The tile energy (J).
        energy: f64,
    },
    /// A constraint row of [`MicroProblem::with_constraints`] that cannot be normalised.
    #[error("constraint row {row} is zero or not finite")]
    ConstraintRow {
        /// The row's index.
        row: usize,
    },
}

/// A yarn state at a macro strain: the unknowns y = (ũ, θ) in the tile's dof layout and the stored frames
/// (world coordinates) at that state.
#[derive(Clone, Debug, PartialEq)]
pub struct MicroState {
    /// The macro strain z = (s_x, s_a, s_y, Π₀₀, Π₁₁) of the state.
    pub strain: MacroStrain,
    /// The surface map family that embeds the tile at this strain.
    pub family: Family,
    /// The unknowns y = (ũ, θ): the displacement of each vertex in its local frame (m), then the edge angles (rad).
    pub y: Vec<f64>,
    /// The stored rod frames (world coordinates) at this state.
    pub frames: RodState,
}

/// Where the wall time of a solve went (seconds).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Energy, gradient and Hessian assembly at the iterates.
    pub assembly: f64,
    /// Broad-phase contact updates.
    pub contact: f64,
    /// Factorisation and KKT solves.
    pub factorization: f64,
    /// Trial evaluations of the line search.
    pub line_search: f64,
    /// Moving the start state to the requested strain.
    pub start: f64,
}

/// The outcome of one solve.
#[derive(Clone, Debug)]
pub struct Solution {
    /// The final state.
    pub state: MicroState,
    /// How the solve ended.
    pub status: Status,
    /// Newton steps taken.
    pub steps: usize,
    /// Energy parts at the final state (J, one tile).
    pub energy: EnergyParts,
    /// Final ‖g‖_∞ of the scaled reduced gradient projected on the constraint space (N).
    pub gradient_norm: f64,
    /// Wall time (s).
    pub time: f64,
    /// Where the wall time went.
    pub timings: Timings,
    /// The reference area p₁ p₂ (m²).
    pub area: f64,
    /// The largest regularisation μ used (N/m).
    pub max_mu: f64,
    /// Of the steps, the exact constrained Newton steps of [`StepRule::Inertia`] taken where the shift rule
    /// would have shifted μ above its floor.
    pub exact_steps: usize,
    /// Yarn crossings of the accepted steps ([`SolverOptions::crossings`] `count`; empty otherwise).
    pub crossings: Vec<Crossing>,
    /// Line-search trials rejected because they crossed yarns ([`SolverOptions::crossings`] `reject`).
    pub rejected_crossings: usize,
}

/// Asking for Ψ̄ of a non-converged solve.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "the micro solve did not converge ({status} after {steps} steps, ‖g‖∞ = {gradient_norm:.3e} N)"
)]
pub struct NotConverged {
    /// How the solve ended.
    pub status: Status,
    /// Newton steps taken.
    pub steps: usize,
    /// Final ‖g‖_∞ of the projected reduced gradient (N).
    pub gradient_norm: f64,
}

impl Solution {
    /// The pairs whose crossings along the path do not cancel ([`net_crossings`]): 0 for a solve that stayed in
    /// the fabric it started in (or that did not count).
    pub fn net_crossings(&self) -> usize {
        net_crossings(&self.crossings).len()
    }

    /// Ψ̄ = E / (p₁ p₂) (J/m²) of a converged solve; an error for any other status.
    pub fn psi(&self) -> Result<f64, NotConverged> {
        if self.status == Status::Converged {
            Ok(self.energy.total() / self.area)
        } else {
            Err(NotConverged {
                status: self.status,
                steps: self.steps,
                gradient_norm: self.gradient_norm,
            })
        }
    }
}

/// One pattern with its material and options, ready to solve at any strain.
pub struct MicroProblem {
    /// The pattern (its reference state).
    pub pattern: Pattern,
    /// The yarn material (radius the pattern's).
    pub material: YarnMaterial,
    /// The solver options.
    pub options: SolverOptions,
    pub(super) topology: RodTopology,
    /// Constraint rows A (length 4n each; zero on the angles), normalised.
    constraints: Vec<Vec<f64>>,
}

impl MicroProblem {
    /// The problem for `pattern` with `material` (its radius replaced by the pattern's).
    pub fn new(pattern: Pattern, material: &YarnMaterial, options: SolverOptions) -> Self {
        let mut material = material.clone();
        material.radius = pattern.radius;
        let topology = RodTopology::new(&pattern);
        let constraints = null_space_rows(&pattern, options.slide_constraints);
        MicroProblem {
            pattern,
            material,
            options,
            topology,
            constraints,
        }
    }

    /// The null-space constraint rows A (`docs/micro-solver.md`, section 3).
    pub fn constraints(&self) -> &[Vec<f64>] {
        &self.constraints
    }

    /// Replace the constraint rows (each of length 4n over the unknowns y = (ũ, θ); normalised here), e.g. to pin
    /// one vertex per yarn along its axis as the original solver did. The rows must be independent and, together
    /// with H, leave no free rigid mode.
    pub fn with_constraints(mut self, rows: Vec<Vec<f64>>) -> Result<Self, MicroError> {
        let nd = 4 * self.pattern.len();
        let mut rows = rows;
        for (k, row) in rows.iter_mut().enumerate() {
            if row.len() != nd {
                return Err(MicroError::ConstraintLength {
                    row: k,
                    len: row.len(),
                    expected: nd,
                });
            }
            let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return Err(MicroError::ConstraintRow { row: k });
            }
            row.iter_mut().for_each(|v| *v /= norm);
        }
        self.constraints = rows;
        Ok(self)
    }

    /// Euclidean projection of a (scaled) gradient on the null space of A: g − Aᵀ (A Aᵀ)⁻¹ A g.
    pub fn project(&self, g: &[f64]) -> Vec<f64> {
        let a = &self.constraints;
        let m = a.len();
        let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
        let gram = nalgebra::DMatrix::from_fn(m, m, |i, j| dot(&a[i], &a[j]));
        let ag = nalgebra::DVector::from_fn(m, |i, _| dot(&a[i], g));
        let Some(c) = gram.cholesky() else {
            return g.to_vec();
        };
        let lambda = c.solve(&ag);
        let mut out = g.to_vec();
        for (k, row) in a.iter().enumerate() {
            for (o, r) in out.iter_mut().zip(row) {
                *o -= lambda[k] * r;
            }
        }
        out
    }

    /// The reference state: zero strain, ũ = 0, the pattern's angles and frames.
    pub fn reference_state(&self) -> MicroState {
        let n = self.pattern.len();
        let mut y = vec![0.0; 3 * n];
        y.extend_from_slice(&self.pattern.theta);
        MicroState {
            strain: MacroStrain::ZERO,
            family: Family::BendY,
            y,
            frames: RodState::from_pattern(&self.pattern),
        }
    }

    /// A tile for `elim` (contacts not yet found).
    pub fn tile(&self, elim: &Elimination) -> Tile<'_> {
        let mut t = Tile::new(&self.pattern, &self.material);
        elim.apply_to(&mut t);
        t
    }

    /// Move a state to another strain at fixed ũ and θ: in steps small enough for the frame transport and the
    /// reference-twist continuation, switching between the `BendY` and `BendX` families at zero curvature.
    /// The strain must pass [`MacroStrain::validate_for_radius`] with the pattern's radius.
    pub fn move_to(&self, state: &mut MicroState, target: &MacroStrain) -> Result<(), StrainError> {
        self.move_until(state, target, None).map(|_| ())
    }

    /// [`MicroProblem::move_to`], stopping between two moving steps once `deadline` (a start and a limit in
    /// seconds) has passed; returns whether `state` reached `target` (if not, it stays at the last step's strain).
    fn move_until(
        &self,
        state: &mut MicroState,
        target: &MacroStrain,
        deadline: Option<(Instant, f64)>,
    ) -> Result<bool, StrainError> {
        let family = target.validate_for_radius(self.pattern.radius)?;
        if family != state.family {
            // leave the current family at zero curvature, switch, continue
            let mut flat = state.strain;
            flat.0[3] = 0.0;
            flat.0[4] = 0.0;
            if !self.move_within(state, &flat, deadline) {
                return Ok(false);
            }
            self.switch_family(state, family);
        }
        Ok(self.move_within(state, target, deadline))
    }

    /// Move within the state's family (see [`MicroProblem::move_until`]); the number of steps is bounded by the
    /// admissible strain set (`MAX_STRETCH`, `MAX_CURVATURE_RADIUS` in [`crate::micro::strain`]).
    fn move_within(
        &self,
        state: &mut MicroState,
        target: &MacroStrain,
        deadline: Option<(Instant, f64)>,
    ) -> bool {
        let from = state.strain;
        let steps = self.move_steps(&from, target);
        if from == *target {
            return true;
        }
        let n = self.pattern.len();
        let mut old = Elimination::in_family(&self.pattern, &from, state.family);
        for s in 1..=steps {
            if deadline.is_some_and(|(t0, limit)| t0.elapsed().as_secs_f64() > limit) {
                return false;
            }
            let z = move_strain(&from, target, s, steps);
            let new = Elimination::in_family(&self.pattern, &z, state.family);
            let positions: Vec<Vector3<f64>> = (0..n)
                .map(|v| new.position(v, [0, 0], &local(&state.y, v)))
                .collect();
            let theta = state.y[3 * n..].to_vec();
            state.frames.advance_between(
                &self.pattern,
                &self.topology,
                positions,
                theta,
                &old.transforms,
                &new.transforms,
            );
            old = new;
            state.strain = z;
        }
        true
    }

    /// The number of equal strain steps of a move from `from` to `target` at fixed ũ and θ: in-plane components
    /// change by at most 0.05 per step, curvatures by at most 0.25 / (2 max(p₁, p₂)).
    pub(super) fn move_steps(&self, from: &MacroStrain, target: &MacroStrain) -> usize {
        let pmax = self.pattern.periods[0].max(self.pattern.periods[1]);
        let dz = (0..3)
            .map(|k| (target.0[k] - from.0[k]).abs())
            .fold(0.0, f64::max);
        let dk = (target.0[3] - from.0[3])
            .abs()
            .max((target.0[4] - from.0[4]).abs());
        ((dz / 0.05).max(dk * 2.0 * pmax / 0.25).ceil() as usize).max(1)
    }

    /// Switch between `BendY` and `BendX` at zero curvature: a rotation Q about e₃ with Q F₂ = G₂ maps the plane
    /// of one family onto the other; positions, frames and local displacements turn with it.
    pub fn switch_family(&self, state: &mut MicroState, family: Family) {
        if family == state.family {
            return;
        }
        let c = state.strain.0[1];
        let s = (1.0 - c * c).sqrt();
        // BendY → BendX: Q e₁ = (√(1−c²), c, 0)
        let mut q = Matrix3::new(s, -c, 0.0, c, s, 0.0, 0.0, 0.0, 1.0);
        if family == Family::BendY {
            q = q.transpose();
        }
        let f = &mut state.frames;
        for x in f.positions.iter_mut() {
            *x = q * *x;
        }
        for t in f.tangents.iter_mut() {
            *t = q * *t;
        }
        for d in f.directors.iter_mut() {
            *d = q * *d;
        }
        let n = self.pattern.len();
        for v in 0..n {
            let u = q * local(&state.y, v);
            state.y[3 * v..3 * v + 3].copy_from_slice(u.as_slice());
        }
        state.family = family;
    }

    /// Solve at `strain`, starting from `start` (the reference state when `None`).
    ///
    /// # Example
    ///
    /// A cold solve of the generated plain weave (used as generated; `hylc run` first brings a pattern to its
    /// reference state, [`super::reference`]) at 5 % stretch along ξ₁, then a warm one next to it: the
    /// envelope-theorem stress σ_x = ∂Ψ̄/∂s_x matches the central difference of Ψ̄.
    ///
    /// ```
    /// use hylc::generate::default_pattern;
    /// use hylc::micro::envelope::energy_strain_gradient;
    /// use hylc::micro::{MacroStrain, MicroProblem, SolverOptions, Status};
    /// use hylc::rod::YarnMaterial;
    ///
    /// let pattern = default_pattern("plain")?;
    /// let problem = MicroProblem::new(pattern, &YarnMaterial::default(), SolverOptions::default());
    /// let at = |s_x: f64| MacroStrain::new(s_x, 0.0, 0.0, 0.0, 0.0);
    /// let mid = problem.solve(&at(0.05), None)?;
    /// assert_eq!(mid.status, Status::Converged);
    /// let psi = mid.psi()?; // Ψ̄ = E / (p₁ p₂), J/m²
    /// assert!(psi > 0.0);
    ///
    /// let h = 1e-4;
    /// let plus = problem.solve(&at(0.05 + h), Some(&mid.state))?.psi()?;
    /// let minus = problem.solve(&at(0.05 - h), Some(&mid.state))?.psi()?;
    /// let sigma_x = energy_strain_gradient(&problem, &mid.state)?[0].unwrap() / mid.area;
    /// let fd = (plus - minus) / (2.0 * h);
    /// assert!((sigma_x - fd).abs() <= 1e-3 * sigma_x.abs(), "{sigma_x} vs {fd}");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn solve(
        &self,
        strain: &MacroStrain,
        start: Option<&MicroState>,
    ) -> Result<Solution, MicroError> {
        let t0 = Instant::now();
        strain.validate_for_radius(self.pattern.radius)?;
        let mut state = match start {
            Some(s) => s.clone(),
            None => self.reference_state(),
        };
        let deadline = self.options.time_limit.map(|limit| (t0, limit));
        if !self.move_until(&mut state, strain, deadline)? {
            return Ok(self.stopped_in_start_phase(state, t0));
        }
        let start_time = t0.elapsed().as_secs_f64();
        let mut sol = self.newton(state, t0)?;
        sol.timings.start = start_time;
        Ok(sol)
    }

    /// The outcome of a solve whose time limit passed while moving the start state to its strain: status
    /// `TimeLimit`, no Newton step, the state at the strain it reached, no energy evaluated (zero parts) and an
    /// infinite gradient norm (nothing is known about equilibrium).
    fn stopped_in_start_phase(&self, state: MicroState, t0: Instant) -> Solution {
        let time = t0.elapsed().as_secs_f64();
        Solution {
            state,
            status: Status::TimeLimit,
            steps: 0,
            energy: EnergyParts::default(),
            gradient_norm: f64::INFINITY,
            time,
            timings: Timings {
                start: time,
                ..Timings::default()
            },
            area: self.pattern.periods[0] * self.pattern.periods[1],
            max_mu: 0.0,
            exact_steps: 0,
            crossings: Vec::new(),
            rejected_crossings: 0,
        }
    }

    /// Newton iterations from a state already at its strain (the steps of the module documentation).
    fn newton(&self, mut state: MicroState, t0: Instant) -> Result<Solution, MicroError> {
        let mut run = NewtonRun::start(self, &state, t0)?;
        let inertia = self.options.inertia_steps();
        let mut roundoff = false;
        loop {
            // 1. energy, scaled gradient and Hessian at the iterate
            let (ev, energy) = run.evaluate(&state)?;
            let g = run.scaled_gradient(&ev);
            // 2. the force test uses the gradient projected on the constraint space (the constrained equilibrium
            // keeps a residual g = −Aᵀλ along the rows that are not exact symmetries, e.g. the yarn slides)
            let gnorm = self.project(&g).iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if let Some(status) = run.stop_before_step(gnorm) {
                return Ok(run.finish(state, status, &ev, gnorm));
            }
            if roundoff {
                return Ok(run.finish(state, Status::Converged, &ev, gnorm));
            }
            // 3. KKT step; with the inertia rule the exact step first, kept when the energy follows its model
            if inertia {
                if let Some(delta) = run.exact_direction(&ev, &g)? {
                    let decrement = dot(&g, &delta);
                    if run.decrement_converged(decrement, energy) {
                        return Ok(run.finish(state, Status::Converged, &ev, gnorm));
                    }
                    if let Some(dmax_now) = run.exact_step(&mut state, delta, decrement, energy) {
                        run.trace_exact(energy, gnorm, decrement, dmax_now);
                        run.steps += 1;
                        run.mu = (run.mu / 10.0).max(run.mu_floor);
                        continue;
                    }
                }
            }
            let direction = if inertia {
                run.shifted_direction(&g)?
            } else {
                run.direction(&ev, &g)?
            };
            let Some(mut delta) = direction else {
                return Ok(run.finish(state, Status::Stalled, &ev, gnorm));
            };
            let decrement = dot(&g, &delta);
            if run.decrement_converged(decrement, energy) {
                return Ok(run.finish(state, Status::Converged, &ev, gnorm));
            }
            // 4. back to tile dofs, displacement limit; 5. line search
            let dmax_now = run.limit_step(&mut delta);
            let accepted = run.line_search(&mut state, &delta, energy);
            run.trace_step(energy, gnorm, decrement, dmax_now, accepted);
            run.steps += 1;
            let at_roundoff = decrement.abs() <= 1e-11 * (energy.abs() + run.ks * run.r);
            let Some(step) = accepted else {
                // no lower energy: converged only at round-off level
                let status = if at_roundoff {
                    Status::Converged
                } else {
                    Status::Stalled
                };
                return Ok(run.finish(state, status, &ev, gnorm));
            };
            // with the inertia rule, a step that had to backtrack although its predicted decrease is at round-off
            // level ends the solve at the next state: the energy no longer resolves the steps (else such solves
            // can creep on by decreases of a few ulps until the step limit)
            roundoff = inertia && step < 1.0 && at_roundoff;
            run.mu = (run.mu / 10.0).max(run.mu_floor);
        }
    }
}

/// gᵀδ.
fn dot(g: &[f64], delta: &[f64]) -> f64 {
    g.iter().zip(delta).map(|(a, b)| a * b).sum()
}

/// The working state of one Newton solve ([`MicroProblem::newton`]): the tile with its contact candidates, the
/// KKT solver with its kept symbolic analysis, the regularisation μ and the bookkeeping.
struct NewtonRun<'p> {
    problem: &'p MicroProblem,
    tile: Tile<'p>,
    /// Home positions at the last contact update.
    contact_at: Vec<Vector3<f64>>,
    /// The rod stencils' part of the KKT pattern, added to the first matrix.
    rod_structure: Vec<(usize, usize, f64)>,
    kkt: KktSolver,
    timings: Timings,
    /// Regularisation μ, its floor at the current step and the largest μ used.
    mu: f64,
    mu_floor: f64,
    max_mu: f64,
    /// Newton steps taken.
    steps: usize,
    /// Exact steps of the inertia rule ([`StepRule::Inertia`]) that were accepted.
    exact: usize,
    /// Crossings of the accepted steps and trials rejected for crossing ([`SolverOptions::crossings`]).
    crossings: Vec<Crossing>,
    rejected_crossings: usize,
    n: usize,
    /// Yarn radius r, stretch stiffness k_s, broad-phase margin, displacement limit d_max, tile area p₁ p₂.
    r: f64,
    ks: f64,
    margin: f64,
    d_max: f64,
    area: f64,
    t0: Instant,
}

impl<'p> NewtonRun<'p> {
    /// The tile of `state`'s strain with its contact candidates found, and the fixed part of the KKT pattern.
    fn start(
        problem: &'p MicroProblem,
        state: &MicroState,
        t0: Instant,
    ) -> Result<Self, MicroError> {
        let opts = &problem.options;
        let r = problem.pattern.radius;
        let elim = Elimination::in_family(&problem.pattern, &state.strain, state.family);
        let mut tile = problem.tile(&elim);
        let margin = opts.contact_margin * r;
        let mut timings = Timings::default();

        let tc = Instant::now();
        let contact_at = tile.home_positions(&state.y);
        tile.update_contacts(&contact_at, margin)?;
        // the KKT solver's pattern is the union of every matrix of this solve: the rod blocks from the start,
        // each contact pair's blocks from the first step it is active, so the symbolic analysis is reused
        let rod_structure = rod_structure(&tile);
        timings.contact += tc.elapsed().as_secs_f64();

        let d_max = r * state.strain.min_stretch_eigenvalue();
        Ok(NewtonRun {
            problem,
            tile,
            contact_at,
            rod_structure,
            kkt: KktSolver::with(if opts.inertia_steps() {
                Factorization::Inertia
            } else {
                Factorization::Cholesky
            }),
            timings,
            mu: 0.0,
            mu_floor: 0.0,
            max_mu: 0.0,
            steps: 0,
            exact: 0,
            crossings: Vec::new(),
            rejected_crossings: 0,
            n: problem.pattern.len(),
            r,
            ks: problem.material.stretch_stiffness(),
            margin,
            d_max,
            area: problem.pattern.periods[0] * problem.pattern.periods[1],
            t0,
        })
    }

    /// The unit scaling M of dof i: the angular unknown is r θ.
    fn scale(&self, i: usize) -> f64 {
        if i < 3 * self.n {
            1.0
        } else {
            1.0 / self.r
        }
    }

    /// M⁻¹ ∇E: the gradient in the scaled unknowns.
    fn scaled_gradient(&self, ev: &TileEval) -> Vec<f64> {
        ev.gradient
            .as_ref()
            .expect("asked for")
            .iter()
            .enumerate()
            .map(|(i, v)| v * self.scale(i))
            .collect()
    }

    /// The status that ends the solve before another step: the force test, the step limit, the time limit.
    fn stop_before_step(&self, gnorm: f64) -> Option<Status> {
        let opts = &self.problem.options;
        if gnorm <= opts.tolerance * self.ks {
            return Some(Status::Converged);
        }
        if self.steps >= opts.max_steps {
            return Some(Status::MaxSteps);
        }
        if let Some(limit) = opts.time_limit {
            if self.t0.elapsed().as_secs_f64() > limit {
                return Some(Status::TimeLimit);
            }
        }
        None
    }

    /// Step 1: the energy, gradient and Hessian at `state` (exact Hessian, the stored frames) and the energy; an
    /// error when Ψ̄ is not finite.
    fn evaluate(&mut self, state: &MicroState) -> Result<(TileEval, f64), MicroError> {
        let ta = Instant::now();
        let ev = self
            .tile
            .evaluate(&state.frames, &state.y, Want::Hessian, &Terms::ALL)?;
        self.timings.assembly += ta.elapsed().as_secs_f64();
        let energy = ev.value();
        if !(energy / self.area).is_finite() {
            return Err(MicroError::NonFiniteEnergy {
                strain: state.strain,
                steps: self.steps,
                energy,
            });
        }
        Ok((ev, energy))
    }

    /// The Newton-decrement test on gᵀδ = `decrement` at the energy `energy`.
    fn decrement_converged(&self, decrement: f64, energy: f64) -> bool {
        let tol = self.problem.options.decrement_tolerance;
        decrement.abs() <= tol * (energy.abs() + self.ks * self.r)
    }

    /// [`SolverOptions::trace`]: the line of an accepted exact step.
    fn trace_exact(&self, energy: f64, gnorm: f64, decrement: f64, dmax_now: f64) {
        if self.problem.options.trace {
            tracing::info!(
                "step {}: E {energy:.15e} J, |g|inf {gnorm:.3e} N, g.d {decrement:.3e} J, exact (mu {:.2e} \
                 kept), |d|max {:.3e} m, accepted at 1e0, symbolic analyses {}, exact steps {}",
                self.steps,
                self.mu,
                dmax_now.min(self.d_max),
                self.kkt.analyses,
                self.exact
            );
        }
    }

    /// [`SolverOptions::trace`]: the line of a shifted step and its line search.
    fn trace_step(
        &self,
        energy: f64,
        gnorm: f64,
        decrement: f64,
        dmax_now: f64,
        accepted: Option<f64>,
    ) {
        if self.problem.options.trace {
            tracing::info!(
                "step {}: E {energy:.15e} J, |g|inf {gnorm:.3e} N, g.d {decrement:.3e} J, mu {:.2e}, |d|max \
                 {:.3e} m, accepted {}, symbolic analyses {}",
                self.steps,
                self.mu,
                dmax_now.min(self.d_max),
                match accepted {
                    Some(step) => format!("at {step:.0e}"),
                    None => "none".into(),
                },
                self.kkt.analyses,
            );
        }
    }

    /// Back to tile dofs (θ = y_θ / r), then the displacement limit: scale the step so that no vertex moves by
    /// more than d_max. Returns the largest vertex displacement before the limit.
    fn limit_step(&self, delta: &mut [f64]) -> f64 {
        for (i, d) in delta.iter_mut().enumerate() {
            *d *= self.scale(i);
        }
        let dmax_now = (0..self.n)
            .map(|v| Vector3::new(delta[3 * v], delta[3 * v + 1], delta[3 * v + 2]).norm())
            .fold(0.0, f64::max);
        if dmax_now > self.d_max {
            let f = self.d_max / dmax_now;
            delta.iter_mut().for_each(|d| *d *= f);
        }
        dmax_now
    }

    /// The solution at `state` with the evaluation `ev` of it.
    fn finish(&self, state: MicroState, status: Status, ev: &TileEval, gnorm: f64) -> Solution {
        Solution {
            state,
            status,
            steps: self.steps,
            energy: ev.parts,
            gradient_norm: gnorm,
            time: self.t0.elapsed().as_secs_f64(),
            timings: self.timings,
            area: self.area,
            max_mu: self.max_mu,
            exact_steps: self.exact,
            crossings: self.crossings.clone(),
            rejected_crossings: self.rejected_crossings,
        }
    }
}

/// Explicit zeros on every (lower) dof pair of the rod stencils: the part of the matrix structure that never
/// changes.
fn rod_structure(tile: &Tile) -> Vec<(usize, usize, f64)> {
    let n = tile.pattern.len();
    let mut out = Vec::new();
    let mut push_all = |dofs: &[usize]| {
        for &a in dofs {
            for &b in dofs {
                if a >= b {
                    out.push((a, b, 0.0));
                }
            }
        }
    };
    for s in &tile.topology.stencils {
        let mut dofs: Vec<usize> = s.vertices.iter().flat_map(|&v| 3 * v..3 * v + 3).collect();
        dofs.push(3 * n + s.edges[0]);
        dofs.push(3 * n + s.edges[1]);
        push_all(&dofs);
    }
    out
}

/// ũ_v from the dof vector.
pub fn local(y: &[f64], v: usize) -> Vector3<f64> {
    Vector3::new(y[3 * v], y[3 * v + 1], y[3 * v + 2])
}

/// The null-space constraint rows (`docs/micro-solver.md`, section 3), each normalised to unit length: the
/// The strain after step `s` of `steps` equal steps from `from` to `target` (exactly `target` at the last).
pub(super) fn move_strain(
    from: &MacroStrain,
    target: &MacroStrain,
    s: usize,
    steps: usize,
) -> MacroStrain {
    let t = s as f64 / steps as f64;
    MacroStrain(std::array::from_fn(|k| {
        if s == steps {
            target.0[k]
        } else {
            from.0[k] + t * (target.0[k] - from.0[k])
        }
    }))
}

/// Voronoi-weighted mean displacement (3 rows) and, optionally, one no-slide row per yarn Σ wᵢ t̄ᵢ·ũᵢ with t̄ᵢ
/// the reference unit tangent at vertex i (mean of its two edges' directions).
pub fn null_space_rows(p: &Pattern, slide: bool) -> Vec<Vec<f64>> {
    let n = p.len();
    let w = p.voronoi_lengths();
    let mut rows = Vec::new();
    for c in 0..3 {
        let mut row = vec![0.0; 4 * n];
        for v in 0..n {
            row[3 * v + c] = w[v];
        }
        rows.push(row);
    }
    if slide {
        let prev = p.prev();
        for yarn in p.yarns() {
            let mut row = vec![0.0; 4 * n];
            for &v in &yarn {
                let t =
                    (p.edge_vector(prev[v]).normalize() + p.edge_vector(v).normalize()).normalize();
                for c in 0..3 {
                    row[3 * v + c] = w[v] * t[c];
                }
            }
            rows.push(row);
        }
    }
    for row in rows.iter_mut() {
        let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt();
        row.iter_mut().for_each(|v| *v /= norm);
    }
    rows
}

/// The world positions of a state's home vertices at its strain.
pub fn world_positions(p: &Pattern, state: &MicroState) -> Vec<Vector3<f64>> {
    let e = Elimination::in_family(p, &state.strain, state.family);
    (0..p.len())
        .map(|v| e.position(v, [0, 0], &local(&state.y, v)))
        .collect()
}
