//! The discrete adjoint of a dynamic run: dJ/dp through the implicit Euler substeps exactly as they ran
//! (`docs/sensitivities.md`, "Trajectories").
//!
//! Substep k (length h, from the state (x_k, v_k) to t_{k+1}) makes x_{k+1} the minimiser of Φ_k over the free
//! dofs, so G_k = ∂Φ_k/∂x_f = 0 there, with
//!
//!   G_k = M (x − x_k − h v_k)/h² + c M (x − x_k)/h + ∇E(x) − M g + ∇E_obst(x, t_{k+1}) (+ springs),
//!
//! the held dofs prescribed at t_{k+1}, and v_{k+1} = (x_{k+1} − x_k)/h on every dof. For J = Σ_{k ∈ at}
//! J(x_{k+1}) the reverse pass carries x̄ = dJ/dx_{k+1} and v̄ = dJ/dv_{k+1} back: with the cotangent
//! a = x̄ + v̄/h of x_{k+1} (the observation's ∂J/∂x added first when J is observed there),
//!
//!   H_k λ = a_f   (H_k = ∂G_k/∂x_f: the exact Hessian of Φ_k at x_{k+1}, inertia and drag included),
//!   dJ/dp += −λᵀ ∂G_k/∂p   (the static pass of every parameter at x_{k+1}, t_{k+1}; the mass scale's
//!                           ∂G/∂μ adds the inertia and drag gradients),
//!   x̄_k = λ m (1/h² + c/h) − v̄/h on the free dofs, −v̄/h on the held ones,   v̄_k = λ m / h (free), 0 (held),
//!
//! and the held dofs' total derivative a_h − (H_full λ)_h at t_{k+1} goes to their motion's keyframes (the
//! initial state is the scene's and depends on no parameter). The forward run records every accepted substep's
//! length, end time and state ([`Tape`]); its memory is 8 · 3n bytes per substep (reported by [`Tape::bytes`]).
//!
//! A reaction observed at t_{k+1} (hard constraints) is uᵀ ∂Φ_k/∂x over the set's dofs, inertia and drag of the
//! held vertices included: as in the static case μ = λ − u replaces λ in the parameter terms, and the held
//! dofs' −μ = u carries its ∂/∂x_k and ∂/∂v_k into x̄_k = μ m (1/h² + c/h) − v̄/h and v̄_k = μ m/h.
//!
//! Supported: implicit Euler (fixed or adaptive substeps: the recorded ones), elastic energy, gravity, linear
//! drag, obstacle penalties, hard constraints, handle springs, and stiffness-proportional damping and air drag,
//! and lagged friction, whose data lagged at x_k add their own terms (`lag`). Not: BDF2 and the linearised
//! scheme, damping with the 18×18 projection: [`ShellError::AdjointUnsupported`].

use super::{Exact, HeldGradient, Observable, Sensitivity, Simulation};
use crate::material::coefficients::MaterialGradient;
use crate::shell::solver::Integrator;
use crate::shell::ShellError;

/// The states a dynamic run passed through: its start and every accepted substep.
#[derive(Clone, Debug, Default)]
pub struct Tape {
    /// positions at the start, 3 per vertex (m)
    pub x0: Vec<f64>,
    /// velocities at the start, 3 per vertex (m/s)
    pub v0: Vec<f64>,
    /// time at the start (s)
    pub t0: f64,
    /// the accepted substeps in order
    pub steps: Vec<TapeStep>,
}

/// One accepted substep.
#[derive(Clone, Debug)]
pub struct TapeStep {
    /// its length (s)
    pub h: f64,
    /// its end time (s)
    pub time: f64,
    /// the positions at its end
    pub x: Vec<f64>,
}

impl Tape {
    /// The memory the states take (bytes).
    pub fn bytes(&self) -> usize {
        8 * (self.x0.len()
            + self.v0.len()
            + self.steps.iter().map(|s| s.x.len() + 2).sum::<usize>())
    }

    /// The index of the substep that ends nearest `t`, if one ends within `tol` of it.
    pub fn index_at(&self, t: f64, tol: f64) -> Option<usize> {
        self.steps
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1.time - t).abs().total_cmp(&(b.1.time - t).abs()))
            .filter(|(_, s)| (s.time - t).abs() <= tol)
            .map(|(k, _)| k)
    }
}

impl Simulation {
    /// Record every accepted substep from now on (for [`Simulation::trajectory_sensitivity`]).
    pub fn start_tape(&mut self) {
        self.tape = Some(Tape {
            x0: self.x.clone(),
            v0: self.v.clone(),
            t0: self.time,
            steps: vec![],
        });
    }

    /// The recorded states, if [`Simulation::start_tape`] was called.
    pub fn tape(&self) -> Option<&Tape> {
        self.tape.as_ref()
    }

    fn trajectory_supported(&self) -> Result<(), ShellError> {
        let s = &self.settings;
        let reason = if s.quasi_static {
            "the simulation is quasi-static (use the static sensitivity)"
        } else if s.integrator != Integrator::ImplicitEuler {
            "the trajectory adjoint follows implicit Euler substeps only"
        } else if self.tape.as_ref().is_none_or(|t| t.steps.is_empty()) {
            "no substep was recorded (start_tape before stepping)"
        } else {
            return Ok(());
        };
        Err(ShellError::AdjointUnsupported { reason })
    }

    /// dJ/dp for J = Σ_{k ∈ at} J(x after recorded substep k) (`at` a set of substep indices) through the recorded substeps (module
    /// documentation), for the same parameters as [`Simulation::sensitivity`]; `value` is J, `residual` the
    /// largest residual force over the substeps' ends. The state is left as it was.
    pub fn trajectory_sensitivity(
        &mut self,
        obs: &Observable,
        at: &[usize],
        material: bool,
    ) -> Result<Sensitivity, ShellError> {
        self.trajectory_supported()?;
        let tape = self.tape.take().expect("checked above");
        let saved = (self.x.clone(), self.time);
        let out = self.reverse_pass(&tape, obs, at, material);
        (self.x, self.time) = saved;
        self.tape = Some(tape);
        out
    }

    /// Add substep k's inertia and linear drag to the exact system at its end state (the current one): their
    /// gradient (a reaction includes them, and they are proportional to the masses) and their Hessian diagonal
    /// m (1/h² + c/h); returns 1/h² + c/h.
    fn add_inertia(&self, tape: &Tape, k: usize, ex: &mut Exact) -> f64 {
        let n = self.pattern.n;
        let c_drag = self.settings.drag;
        let st = &tape.steps[k];
        let h = st.h;
        let xk = if k == 0 {
            &tape.x0
        } else {
            &tape.steps[k - 1].x
        };
        let vk: Vec<f64> = if k == 0 {
            tape.v0.clone()
        } else {
            let prev = if k == 1 {
                &tape.x0
            } else {
                &tape.steps[k - 2].x
            };
            let hp = tape.steps[k - 1].h;
            (0..3 * n).map(|i| (xk[i] - prev[i]) / hp).collect()
        };
        let inertia = 1.0 / (h * h) + c_drag / h;
        for v in 0..n {
            let m = self.mass[v];
            for c in 0..3 {
                let i = 3 * v + c;
                let g = m * (st.x[i] - xk[i] - h * vk[i]) / (h * h)
                    + c_drag * m * (st.x[i] - xk[i]) / h;
                ex.g_mass[i] += g;
                ex.g_full[i] += g;
            }
            if let Some(f) = self.pattern.free[v] {
                let d = m * inertia;
                let blk = std::array::from_fn(|r| std::array::from_fn(|s| d * f64::from(r == s)));
                self.pattern.add_diag_block(&mut ex.values, f, &blk);
            }
        }
        inertia
    }

    fn reverse_pass(
        &mut self,
        tape: &Tape,
        obs: &Observable,
        at: &[usize],
        material: bool,
    ) -> Result<Sensitivity, ShellError> {
        let n = self.pattern.n;
        let mut out = Sensitivity {
            value: 0.0,
            residual: 0.0,
            stiffness: 0.0,
            bending_scale: 0.0,
            mass_scale: 0.0,
            gravity: [0.0; 3],
            material: material.then(|| MaterialGradient::zeros(&self.model.material)),
            held: vec![],
            obstacles: vec![[0.0; 3]; self.obstacles.len()],
        };
        let energy = matches!(obs, Observable::ElasticEnergy);
        let (mut xbar, mut vbar) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
        for k in (0..tape.steps.len()).rev() {
            let st = &tape.steps[k];
            let h = st.h;
            let xk = if k == 0 {
                &tape.x0
            } else {
                &tape.steps[k - 1].x
            };
            self.x.clone_from(&st.x);
            self.time = st.time;
            let mut ex = self.exact_system()?;
            let inertia = self.add_inertia(tape, k, &mut ex);
            let tk = if k == 0 {
                tape.t0
            } else {
                tape.steps[k - 1].time
            };
            let lag = self.lag_at(xk, h, tk)?;
            if let Some(lag) = &lag {
                self.add_lag_terms(lag, xk, &mut ex);
            }
            let observed = at.contains(&k);
            let mut u = vec![0.0; 3 * n];
            if observed {
                let (value, mut djdx, uo) = self.observable_parts(obs, &ex)?;
                if let (Some(lag), true) = (&lag, uo.iter().any(|&a| a != 0.0)) {
                    // a reaction's ∂R/∂x_f gains the lagged terms' free–held coupling
                    let hu = self.lag_times(lag, xk, &uo);
                    for v in (0..n).filter(|&v| self.pattern.free[v].is_some()) {
                        for c in 0..3 {
                            djdx[3 * v + c] += hu[3 * v + c];
                        }
                    }
                }
                out.value += value;
                for (a, b) in xbar.iter_mut().zip(&djdx) {
                    *a += b;
                }
                u = uo;
            }
            let a: Vec<f64> = (0..3 * n).map(|i| xbar[i] + vbar[i] / h).collect();
            let mut rhs = vec![0.0; 3 * self.pattern.nfree];
            for v in 0..n {
                if let Some(f) = self.pattern.free[v] {
                    let r2: f64 = (0..3).map(|c| ex.g_full[3 * v + c].powi(2)).sum();
                    out.residual = out.residual.max(r2.sqrt());
                    for c in 0..3 {
                        rhs[3 * f + c] = a[3 * v + c];
                    }
                }
            }
            let residual = out.residual;
            let neg_lambda = self
                .factor_solve(&ex.values, &rhs)
                .ok_or(ShellError::NotStrictMinimum { residual })?;
            // μ = λ − u over all dofs (u the reaction's indicator where observed)
            let mut mu: Vec<f64> = u.iter().map(|a| -a).collect();
            for v in 0..n {
                if let Some(f) = self.pattern.free[v] {
                    for c in 0..3 {
                        mu[3 * v + c] -= neg_lambda[3 * f + c];
                    }
                }
            }
            self.add_parameter_terms(&mu, &ex.g_mass, energy && observed, &mut out)?;
            let seen = observed.then_some(obs);
            let lag_mu = lag.as_ref().map(|l| self.lag_times(l, xk, &mu));
            accumulate_held(
                &mut out.held,
                self.held_gradients(seen, &mu, &a, inertia, lag_mu.as_deref())?,
            );
            for (t, g) in out.obstacles.iter_mut().zip(self.obstacle_gradients(&mu)) {
                for c in 0..3 {
                    t[c] += g[c];
                }
            }
            // back to the substep's start: −μᵀ ∂G/∂x_k and −μᵀ ∂G/∂v_k on every dof (a held dof's μ is −u)
            for v in 0..n {
                let m = self.mass[v];
                for c in 0..3 {
                    let i = 3 * v + c;
                    xbar[i] = mu[i] * m * inertia - vbar[i] / h;
                    vbar[i] = mu[i] * m / h;
                }
            }
            if let Some(lag) = &lag {
                self.lag_adjoint(lag, xk, &mu, &mut out, &mut xbar)?;
            }
        }
        Ok(out)
    }
}

/// Add one substep's held-set gradients to the running sums (same sets in the same order).
fn accumulate_held(sum: &mut Vec<HeldGradient>, step: Vec<HeldGradient>) {
    if sum.is_empty() {
        *sum = step;
        return;
    }
    for (s, g) in sum.iter_mut().zip(step) {
        for c in 0..3 {
            s.translation[c] += g.translation[c];
        }
        for (a, b) in s.keyframes.iter_mut().zip(&g.keyframes) {
            for c in 0..3 {
                a[c] += b[c];
            }
        }
    }
}
