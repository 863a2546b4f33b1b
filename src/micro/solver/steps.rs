//! The step of one Newton iteration of the micro solver (`03-homogenization.md`, section 4, steps 4–5): the
//! backtracking line search with its yarn-crossing check ([`SolverOptions::crossings`]), and the trust-region
//! variant ([`SolverOptions::trust_region`]) with its norm.

use super::*;

/// Relative tolerance (√(rᵀz) against its start) of the truncated conjugate gradients of
/// [`SolverOptions::trust_region`].
const TRUST_REGION_TOLERANCE: f64 = 1e-10;
/// Iteration limit of those conjugate gradients (the last iterate is taken).
const TRUST_REGION_MAX_ITERATIONS: usize = 100;
/// Trial steps per Newton step of the trust-region variant (each rejected one shrinks the radius ×0.25).
const TRUST_REGION_MAX_TRIALS: usize = 20;
/// The largest trust radius, in units of the displacement limit d_max.
const TRUST_REGION_MAX_RADIUS: f64 = 1.0;

/// [`SolverOptions::inertia`]: the exact Newton step is kept when the energy falls by at least this fraction of
/// the decrease its quadratic model predicts; otherwise the step is the design's shifted one.
const EXACT_STEP_RATIO: f64 = 0.25;

impl<'p> NewtonRun<'p> {
    /// [`SolverOptions::inertia`]: the exact constrained Newton step `delta` (scaled unknowns, directional
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

    /// Backtracking line search on the energy along `delta` (tile dofs; `slope` = gᵀδ) from `state`: trial steps
    /// factorⁱ, or by safeguarded quadratic interpolation ([`SolverOptions::interpolating_search`]), down to
    /// 1e-10; the contact candidates refreshed when the vertices have moved by more than half the margin, the
    /// stored frames transported to the first trial with a lower energy, which becomes the state. Returns the
    /// accepted step.
    pub(super) fn line_search(
        &mut self,
        state: &mut MicroState,
        delta: &[f64],
        energy: f64,
        slope: f64,
    ) -> Option<f64> {
        let problem = self.problem;
        let tl = Instant::now();
        let mut accepted = None;
        let mut step = 1.0;
        let factor = problem.options.backtracking;
        let interpolate = problem.options.interpolating_search && slope < 0.0;
        let trials = (1e-10f64.ln() / factor.ln()).ceil() as usize;
        // the interpolated steps shrink by 0.5–0.1 per trial: the same floor 1e-10, more trials
        let max_trials = if interpolate { 4 * trials } else { trials };
        for _ in 0..=max_trials {
            if interpolate && step < 1e-10 {
                break;
            }
            let trial: Vec<f64> = state
                .y
                .iter()
                .zip(delta)
                .map(|(a, b)| a + step * b)
                .collect();
            let (e, positions) = self.trial_energy(state, &trial);
            if e < energy {
                if self.crossing_rejected(&state.y, &trial) {
                    step *= if interpolate { 0.1 } else { factor };
                    continue;
                }
                self.accept_trial(state, trial, positions);
                accepted = Some(step);
                break;
            }
            step = if interpolate {
                interpolated_step(step, e - energy, slope)
            } else {
                step * factor
            };
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

    /// [`SolverOptions::trust_region`] (`03-homogenization.md`, section 4, steps 3–4 as a trust region): the
    /// truncated conjugate-gradient step ([`KktSolver::trust_region_kept`]) within the radius Δ, preconditioned
    /// by the factorisation of H + μI that [`NewtonRun::direction`] left; the trial at y + δ is accepted when
    /// its energy is lower, and Δ follows the ratio ρ of actual to predicted decrease (×0.25 of the step for
    /// ρ < 0.25 or a rejected trial, ×2 up to d_max for ρ > 0.75 on the boundary). Returns the accepted step
    /// (1, as the line search's step factor; `None` when no trial lowered the energy) and the step's length in
    /// the trust-region norm.
    pub(super) fn trust_region_step(
        &mut self,
        state: &mut MicroState,
        g: &[f64],
        energy: f64,
    ) -> Result<(Option<f64>, f64), MicroError> {
        let region = VertexNorm { n: self.n };
        let max_radius = TRUST_REGION_MAX_RADIUS * self.d_max;
        let mut length = 0.0;
        self.tr_trials = 0;
        for _ in 0..TRUST_REGION_MAX_TRIALS {
            self.tr_trials += 1;
            let tf = Instant::now();
            let step: TrustRegionStep = self.kkt.trust_region_kept(
                g,
                &self.problem.constraints,
                self.radius,
                &region,
                TRUST_REGION_TOLERANCE,
                TRUST_REGION_MAX_ITERATIONS,
            )?;
            self.timings.factorization += tf.elapsed().as_secs_f64();
            self.tr_iterations = step.iterations;
            self.tr_boundary = step.boundary;
            self.tr_negative = step.negative_curvature;
            length = region.norm(&step.step);
            let tl = Instant::now();
            let trial: Vec<f64> = state
                .y
                .iter()
                .zip(&step.step)
                .enumerate()
                .map(|(i, (a, b))| a + b * self.scale(i))
                .collect();
            let (e, positions) = self.trial_energy(state, &trial);
            self.timings.line_search += tl.elapsed().as_secs_f64();
            self.tr_ratio = (energy - e) / step.predicted;
            if e < energy && !self.crossing_rejected(&state.y, &trial) {
                self.accept_trial(state, trial, positions);
                if self.tr_ratio < 0.25 {
                    self.radius = 0.25 * length;
                } else if self.tr_ratio > 0.75 && step.boundary {
                    self.radius = (2.0 * self.radius).min(max_radius);
                }
                return Ok((Some(1.0), length));
            }
            self.radius = 0.25 * length.min(self.radius);
            if self.radius.is_nan() || self.radius <= 1e-10 * self.d_max {
                break;
            }
        }
        Ok((None, length))
    }
}

/// [`SolverOptions::interpolating_search`]: the next trial step after the refused step `t` whose energy change
/// is `de` (≥ 0 under simple decrease, or not finite), for the slope `slope` < 0 at 0: the minimiser of the parabola
/// p(s) = slope·s + (de − slope·t) s²/t², within [0.1 t, 0.5 t].
pub(crate) fn interpolated_step(t: f64, de: f64, slope: f64) -> f64 {
    if !de.is_finite() {
        return 0.1 * t;
    }
    let curvature = de - slope * t; // > 0 since de ≥ 0 > slope·t
    let s = -slope * t * t / (2.0 * curvature);
    s.clamp(0.1 * t, 0.5 * t)
}

/// The trust-region norm of [`SolverOptions::trust_region`] on a step x in the scaled unknowns (ũ, r θ) of a tile
/// with `n` vertices: the largest vertex displacement (as the displacement limit measures it) or |r δθ|.
struct VertexNorm {
    n: usize,
}

impl TrustNorm for VertexNorm {
    fn norm(&self, x: &[f64]) -> f64 {
        let n = self.n;
        let vertices = (0..n)
            .map(|v| (x[3 * v].powi(2) + x[3 * v + 1].powi(2) + x[3 * v + 2].powi(2)).sqrt())
            .fold(0.0, f64::max);
        x[3 * n..].iter().fold(vertices, |m, t| m.max(t.abs()))
    }

    /// The smallest positive root over the vertex blocks and the angles of ‖x_b + τ p_b‖ = radius; 0 when p is
    /// zero.
    fn to_boundary(&self, x: &[f64], p: &[f64], radius: f64) -> f64 {
        let n = self.n;
        let mut tau = f64::INFINITY;
        let mut root = |xb: &[f64], pb: &[f64]| {
            let a: f64 = pb.iter().map(|v| v * v).sum();
            if a == 0.0 {
                return;
            }
            let b: f64 = xb.iter().zip(pb).map(|(u, v)| u * v).sum();
            let c: f64 = xb.iter().map(|v| v * v).sum::<f64>() - radius * radius;
            let t = if c >= 0.0 {
                0.0
            } else {
                let s = (b * b - a * c).sqrt();
                if b > 0.0 {
                    -c / (b + s)
                } else {
                    (s - b) / a
                }
            };
            tau = tau.min(t);
        };
        for v in 0..n {
            root(&x[3 * v..3 * v + 3], &p[3 * v..3 * v + 3]);
        }
        for i in 3 * n..x.len() {
            root(&x[i..i + 1], &p[i..i + 1]);
        }
        if tau.is_finite() {
            tau
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::interpolated_step;

    /// On an energy that is a parabola along the step, the interpolated trial is its minimiser (when that lies
    /// within [0.1 t, 0.5 t]); outside it is clamped; a non-finite trial energy gives 0.1 t.
    #[test]
    fn interpolated_step_is_the_parabola_minimiser_within_its_bounds() {
        // E(s) − E(0) = slope·s + c s², minimum at −slope / (2c)
        let (slope, t) = (-2.0, 0.8);
        for c in [3.0, 5.0, 6.0] {
            let de = slope * t + c * t * t;
            let s = interpolated_step(t, de, slope);
            assert!((s - (-slope / (2.0 * c))).abs() < 1e-14, "c {c}: {s}");
        }
        // a refused trial with a tiny rise: the parabola's minimiser approaches t/2 from below (the upper bound
        // binds only for a fall, de < 0, that a caller with simple decrease never passes)
        let s = interpolated_step(t, 1e-12, slope);
        assert!(s <= 0.5 * t && 0.5 * t - s < 1e-9, "{s}");
        assert_eq!(interpolated_step(t, -1.0, slope), 0.5 * t);
        // a steep wall (minimum near 0)
        assert_eq!(interpolated_step(t, 1e6, slope), 0.1 * t);
        assert_eq!(interpolated_step(t, f64::INFINITY, slope), 0.1 * t);
        assert_eq!(interpolated_step(t, f64::NAN, slope), 0.1 * t);
    }
}
