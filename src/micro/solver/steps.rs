//! The step of one Newton iteration of the micro solver (`docs/micro-solver.md`, section 4, steps 4–5): the exact
//! step of [`StepRule::Inertia`] and the backtracking line search, both with their yarn-crossing check
//! ([`SolverOptions::crossings`]).

use super::*;

/// The line search's backtracking factor: trial steps 0.1ⁱ down to 1e-10.
const BACKTRACKING: f64 = 0.1;

/// [`StepRule::Inertia`]: the exact Newton step is kept when the energy falls by at least this fraction of
/// the decrease its quadratic model predicts; otherwise the step is the shifted one of [`StepRule::Shift`].
const EXACT_STEP_RATIO: f64 = 0.25;

impl<'p> NewtonRun<'p> {
    /// [`StepRule::Inertia`]: the exact constrained Newton step `delta` (scaled unknowns, directional
    /// derivative `decrement` = gᵀδ) with the displacement limit, a fraction f ≤ 1 of it. On the constraint
    /// space δᵀHδ = −gᵀδ, so the quadratic model predicts the change gᵀδ (f − f²/2); the trial is accepted (it
    /// becomes the state) when the energy falls by at least [`EXACT_STEP_RATIO`] of that and crosses no yarns
    /// under [`SolverOptions::crossings`]. Returns the largest vertex displacement before the limit, or `None`
    /// (state unchanged) when the trial is refused.
    pub(super) fn exact_step(
        &mut self,
        state: &mut MicroState,
        mut delta: Vec<f64>,
        decrement: f64,
        energy: f64,
    ) -> Option<f64> {
        let tl = Instant::now();
        let dmax_now = self.limit_step(&mut delta);
        let f = (self.d_max / dmax_now).min(1.0);
        let model = decrement * (f - 0.5 * f * f);
        let trial: Vec<f64> = state.y.iter().zip(&delta).map(|(a, b)| a + b).collect();
        let (e, positions) = self.trial_energy(state, &trial);
        let kept = e < energy
            && e - energy <= EXACT_STEP_RATIO * model
            && !self.crossing_rejected(&state.y, &trial);
        if kept {
            self.accept_trial(state, trial, positions);
            self.exact += 1;
        }
        self.timings.line_search += tl.elapsed().as_secs_f64();
        kept.then_some(dmax_now)
    }

    /// Backtracking line search on the energy along `delta` (tile dofs) from `state`: trial steps 0.1ⁱ down to
    /// 1e-10; the contact candidates refreshed when the vertices have moved by more than half the margin, the
    /// stored frames transported to the first trial with a lower energy, which becomes the state. Returns the
    /// accepted step.
    pub(super) fn line_search(
        &mut self,
        state: &mut MicroState,
        delta: &[f64],
        energy: f64,
    ) -> Option<f64> {
        let tl = Instant::now();
        let mut accepted = None;
        let mut step = 1.0;
        let trials = (1e-10f64.ln() / BACKTRACKING.ln()).ceil() as usize;
        for _ in 0..=trials {
            let trial: Vec<f64> = state
                .y
                .iter()
                .zip(delta)
                .map(|(a, b)| a + step * b)
                .collect();
            let (e, positions) = self.trial_energy(state, &trial);
            if e < energy {
                if self.crossing_rejected(&state.y, &trial) {
                    step *= BACKTRACKING;
                    continue;
                }
                self.accept_trial(state, trial, positions);
                accepted = Some(step);
                break;
            }
            step *= BACKTRACKING;
        }
        self.timings.line_search += tl.elapsed().as_secs_f64();
        accepted
    }

    /// [`SolverOptions::crossings`] on a trial with a lower energy: with `count`, its crossings from `y0` are
    /// recorded; with `reject`, a trial that crosses yarns is refused (true) and counted. A failed check
    /// (non-finite positions) counts as a crossing: the trial is not trusted.
    pub(super) fn crossing_rejected(&mut self, y0: &[f64], trial: &[f64]) -> bool {
        let guard = self.problem.options.crossings;
        if guard == CrossingGuard::Off {
            return false;
        }
        let crossed = self
            .tile
            .crossings(y0, trial)
            .unwrap_or_else(|_| vec![Crossing::untrusted()]);
        if crossed.is_empty() {
            return false;
        }
        if guard == CrossingGuard::Reject {
            self.rejected_crossings += 1;
            return true;
        }
        self.crossings.extend(crossed);
        false
    }

    /// The energy at the unknowns `trial` with `state`'s stored frames transported there (infinite where the
    /// evaluation fails), the contact candidates refreshed first when a vertex has moved by more than half the
    /// margin since the last refresh; also the trial's home positions.
    pub(super) fn trial_energy(
        &mut self,
        state: &MicroState,
        trial: &[f64],
    ) -> (f64, Vec<Vector3<f64>>) {
        let positions = self.tile.home_positions(trial);
        let moved = positions
            .iter()
            .zip(&self.contact_at)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        if moved > 0.5 * self.margin {
            let tc = Instant::now();
            if self.tile.update_contacts(&positions, self.margin).is_ok() {
                self.contact_at = positions.clone();
            }
            self.timings.contact += tc.elapsed().as_secs_f64();
        }
        let e = self
            .tile
            .evaluate(&state.frames, trial, Want::Value, &Terms::ALL)
            .map(|r| r.value())
            .unwrap_or(f64::INFINITY);
        (e, positions)
    }

    /// Make the trial (unknowns `trial`, home positions `positions`) the state: its stored frames transported.
    pub(super) fn accept_trial(
        &self,
        state: &mut MicroState,
        trial: Vec<f64>,
        positions: Vec<Vector3<f64>>,
    ) {
        let problem = self.problem;
        let theta = trial[3 * self.n..].to_vec();
        state.frames.advance(
            &problem.pattern,
            &problem.topology,
            positions,
            theta,
            &self.tile.placement,
        );
        state.y = trial;
    }
}
