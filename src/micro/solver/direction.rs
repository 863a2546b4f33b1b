//! The Newton direction of one micro-solver iteration (`docs/micro-solver.md`, sections 3–4, step 3): the KKT
//! step with the regularisation μ grown ×10 until it exists (the shift rule), and the exact constrained step of
//! [`StepRule::Inertia`] tried first.

use super::*;

impl<'p> NewtonRun<'p> {
    /// The KKT step in the scaled unknowns, growing μ until H + μI factorises and the step is a descent
    /// direction; `None` when 40 attempts fail.
    pub(super) fn direction(
        &mut self,
        ev: &TileEval,
        g: &[f64],
    ) -> Result<Option<Vec<f64>>, MicroError> {
        let tf = Instant::now();
        self.set_newton_matrix(ev)?;
        self.timings.factorization += tf.elapsed().as_secs_f64();
        self.shifted_direction(g)
    }

    /// [`StepRule::Inertia`]: store the Hessian of `ev`; where the shift rule would start above μ's floor,
    /// the exact constrained Newton step at the floor when the KKT matrix there has the inertia of a constrained
    /// minimum; `None` otherwise, and [`NewtonRun::shifted_direction`] goes on from μ (its shifts accepted by the
    /// same inertia test). μ keeps its value, the shifted search's memory.
    pub(super) fn exact_direction(
        &mut self,
        ev: &TileEval,
        g: &[f64],
    ) -> Result<Option<Vec<f64>>, MicroError> {
        let tf = Instant::now();
        self.set_newton_matrix(ev)?;
        let mut delta = None;
        if self.mu > self.mu_floor {
            let saved = self.mu;
            self.mu = self.mu_floor;
            delta = self.try_step(g)?;
            self.mu = saved;
        }
        self.timings.factorization += tf.elapsed().as_secs_f64();
        Ok(delta)
    }

    /// The shifted KKT step for the stored matrix: μ grown ×10 from its current value until the step exists and
    /// is a descent direction; `None` when 40 attempts fail.
    pub(super) fn shifted_direction(&mut self, g: &[f64]) -> Result<Option<Vec<f64>>, MicroError> {
        let tf = Instant::now();
        let mut delta = None;
        for _ in 0..40 {
            if let Some(d) = self.try_step(g)? {
                delta = Some(d);
                break;
            }
            self.mu *= 10.0;
        }
        self.timings.factorization += tf.elapsed().as_secs_f64();
        self.max_mu = self.max_mu.max(self.mu);
        Ok(delta)
    }

    /// Store the scaled Hessian of `ev` in the KKT solver (with the rod structure at the first step) and set μ's
    /// floor from its largest diagonal entry; μ is raised to the floor.
    pub(super) fn set_newton_matrix(&mut self, ev: &TileEval) -> Result<(), MicroError> {
        let mut lower: Vec<(usize, usize, f64)> = ev
            .hessian
            .as_ref()
            .expect("asked for")
            .iter()
            .filter(|&&(i, j, _)| i >= j)
            .map(|&(i, j, v)| (i, j, v * self.scale(i) * self.scale(j)))
            .collect();
        if self.steps == 0 {
            lower.extend_from_slice(&self.rod_structure);
        }
        let diag_max = lower
            .iter()
            .filter(|t| t.0 == t.1)
            .fold(0.0f64, |m, t| m.max(t.2.abs()))
            .max(self.ks / self.r);
        // The tile's rigid motions make H exactly singular: a factorisation at μ = 0 "succeeds" with pivots at
        // round-off level and returns noise. μ therefore never drops below 1e-10 of the largest diagonal
        // entry (the constraints remove those modes from the step), and at that floor two steps of iterative
        // refinement against the unshifted H make the step an exact Newton step also along soft modes. A
        // step that is not a descent direction counts as a failed factorisation.
        self.mu_floor = 1e-10 * diag_max;
        self.mu = self.mu.max(self.mu_floor);
        self.kkt
            .set_matrix(4 * self.n, &lower)
            .map_err(MicroError::Linear)
    }

    /// The KKT step at the current μ for the stored matrix: `None` when H + μI does not factorise or the step is
    /// not a descent direction.
    pub(super) fn try_step(&mut self, g: &[f64]) -> Result<Option<Vec<f64>>, MicroError> {
        // at the floor, two refinement steps remove the shift's effect on soft modes (exact Newton)
        let refine = if self.mu <= self.mu_floor { 2 } else { 0 };
        let rhs = [g.to_vec()];
        let solved = self
            .kkt
            .solve_shifted(self.mu, &rhs, &self.problem.constraints, refine)
            .map(|mut v| v.pop().expect("one right-hand side"));
        match solved {
            Ok(d) if g.iter().zip(&d).map(|(a, b)| a * b).sum::<f64>() < 0.0 => Ok(Some(d)),
            Ok(_) | Err(FactorError::NotPositiveDefinite) => Ok(None),
            Err(e) => Err(MicroError::Linear(e)),
        }
    }
}
