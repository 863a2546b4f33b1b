//! One step of the cloth solver: its substeps chosen by convergence and, with `time_tol`, by their estimated
//! error (module documentation of [`super`], "Adaptive substeps" and "Accuracy"), and the step's report.

use super::{check_finite, integrator, Minimum, Settings, Simulation, StepReport, Substep, Target};
use crate::shell::ShellError;
use std::time::Instant;

/// How the substeps of a step are chosen: the longest substep dt (the step over `substeps`), the smallest
/// (dt / 2^`max_halvings`) and the accuracy tolerance (none in quasi-static mode).
struct SubstepPlan {
    dt: f64,
    h_min: f64,
    tol: Option<f64>,
}

impl SubstepPlan {
    fn new(s: &Settings) -> SubstepPlan {
        let dt = s.dt / f64::from(s.substeps);
        SubstepPlan {
            dt,
            h_min: dt / f64::from(1u32 << s.max_halvings),
            tol: s.time_tol.filter(|_| !s.quasi_static),
        }
    }

    /// The next substep's length for the `wanted` one and the time `remaining` in the step: under `time_tol`,
    /// the last two substeps of a step share what is left instead of ending with a sliver (a very short substep
    /// after a long one makes the held vertices' inertia jump).
    fn length(&self, wanted: f64, remaining: f64) -> f64 {
        if self.tol.is_some() && remaining > wanted && remaining < 2.0 * wanted {
            0.5 * remaining
        } else {
            wanted.min(remaining)
        }
    }
}

/// What a step's substeps did, for its report.
#[derive(Default)]
struct Tally {
    newton: usize,
    substeps: usize,
    rejected: usize,
    dt_min: f64,
    max_shift: f64,
    error_max: f64,
}

impl Simulation {
    /// Advance one step of length dt, in as many substeps as convergence (and `time_tol`) needs (module
    /// documentation).
    ///
    /// # Example
    ///
    /// The built-in `hanging` scene (a square hanging from its two top corners) on a coarse mesh, three steps of
    /// 1/60 s: every step converges to the force tolerance and the cloth falls (the gravitational energy drops
    /// below its initial value).
    ///
    /// ```
    /// use hylc::shell::scene::{builtin, MeshSpec};
    ///
    /// let mut scene = builtin("hanging").unwrap();
    /// scene.mesh = MeshSpec::Rectangle {
    ///     width: 0.3,
    ///     height: 0.3,
    ///     edge: 0.05, // m: 6 × 6 cells, 72 triangles
    ///     perturb: 0.0,
    ///     seed: 1,
    /// };
    /// let (mut sim, _triangles) = scene.build("hanging", std::path::Path::new("."))?;
    /// for _ in 0..3 {
    ///     let report = sim.step()?;
    ///     assert!(report.residual <= sim.settings.force_tol); // N
    ///     assert!(report.energy_gravity < 0.0); // J, relative to the initial state
    /// }
    /// assert!((sim.time - 3.0 / 60.0).abs() < 1e-12);
    /// # Ok::<(), hylc::shell::ShellError>(())
    /// ```
    pub fn step(&mut self) -> Result<StepReport, ShellError> {
        let start = Instant::now();
        let t_end = self.time + self.settings.dt;
        let plan = SubstepPlan::new(&self.settings);
        let step = self.steps + 1;
        let mut tally = Tally {
            dt_min: self.settings.dt,
            ..Tally::default()
        };
        let mut last: Option<(Minimum, Target)> = None;
        // the step ends when the remaining time is a round-off fraction of dt
        while t_end - self.time > 1e-9 * plan.dt {
            let wanted = match plan.tol {
                None => plan.dt / f64::from(1u32 << self.level),
                Some(_) => self.h_next,
            };
            let h = plan.length(wanted, t_end - self.time);
            match self.substep(h, step)? {
                Substep::Done(done) => {
                    let (m, tg) = *done;
                    if let Some(done) = self.conclude(m, tg, h, wanted, &plan, &mut tally) {
                        last = Some(done);
                    }
                }
                Substep::Retry {
                    error,
                    residual,
                    newton,
                } => {
                    tally.newton += newton;
                    self.streak = 0;
                    let exhausted = match plan.tol {
                        None => self.level >= self.settings.max_halvings,
                        Some(_) => h <= plan.h_min * (1.0 + 1e-9),
                    };
                    if exhausted {
                        return Err(error.unwrap_or(ShellError::StepFailed {
                            step,
                            time: self.time,
                            halvings: match plan.tol {
                                None => self.level,
                                Some(_) => (plan.dt / h).log2().round() as u32,
                            },
                            dt: h,
                            residual,
                            newton,
                        }));
                    }
                    self.level += 1;
                    self.h_next = (h / 2.0).max(plan.h_min);
                }
            }
        }
        self.time = t_end;
        self.steps += 1;
        let (m, _) = last.expect("a step of positive length takes a substep");
        self.report(m, &tally, start)
    }

    /// A converged substep of length h (the controller asked for `wanted`): under `time_tol` rejected when its
    /// estimated error is too large (`None`, the next length set), else accepted, with the next length set and
    /// the tally updated. Returns the accepted minimum and its constants.
    fn conclude(
        &mut self,
        mut m: Minimum,
        tg: Target,
        h: f64,
        wanted: f64,
        plan: &SubstepPlan,
        tally: &mut Tally,
    ) -> Option<(Minimum, Target)> {
        let err = self.substep_error(&m.x, &tg);
        if let Some(tol) = plan.tol {
            let factor = 0.9 * (tol / err).powf(1.0 / f64::from(tg.order + 1));
            if err > tol && h > plan.h_min * (1.0 + 1e-9) {
                // too inaccurate: retry shorter (the Newton work counts)
                tally.newton += m.newton;
                tally.rejected += 1;
                self.h_next = (h * factor.max(0.2)).max(plan.h_min);
                return None;
            }
            let grown = h * factor.min(2.0);
            // a substep shortened only to end the step does not shrink the next one
            self.h_next = if h < wanted {
                grown.max(self.h_next)
            } else {
                grown
            }
            .clamp(plan.h_min, plan.dt);
        }
        tally.error_max = tally.error_max.max(err);
        let local = std::mem::take(&mut m.asm.local);
        self.damping_cache = (!local.is_empty()).then(|| (m.x.clone(), std::sync::Arc::new(local)));
        tally.newton += m.newton;
        tally.substeps += 1;
        tally.dt_min = tally.dt_min.min(h);
        tally.max_shift = tally.max_shift.max(m.max_shift);
        self.accept(&m, &tg);
        self.streak += 1;
        if self.level > 0 && self.streak >= 2 {
            self.level -= 1;
            self.streak = 0;
        }
        Some((m, tg))
    }

    /// The report of a finished step whose last substep ended at `m` (errors when an energy is not finite).
    fn report(&self, m: Minimum, tally: &Tally, start: Instant) -> Result<StepReport, ShellError> {
        let (ek, eg, eo) = self.energies();
        for (what, v) in [
            ("kinetic energy", ek),
            ("gravitational energy", eg),
            ("obstacle energy", eo),
        ] {
            check_finite(self.steps, self.time, what, v)?;
        }
        let handle_forces = self.handle_forces(&m.g_full);
        let asm = m.asm;
        Ok(StepReport {
            step: self.steps,
            time: self.time,
            newton: tally.newton,
            substeps: tally.substeps,
            dt_min: tally.dt_min,
            rejected: tally.rejected,
            error_estimate: tally.error_max,
            residual: m.residual,
            converged: m.converged,
            energy_elastic: asm.energy,
            energy_kinetic: ek,
            energy_gravity: eg,
            energy_obstacles: eo,
            handle_forces,
            shift: tally.max_shift,
            wall: start.elapsed().as_secs_f64(),
            strain_min: asm.zmin,
            strain_max: asm.zmax,
            strain_p01: strain_quantile(&asm.z, 0.01),
            strain_p99: strain_quantile(&asm.z, 0.99),
        })
    }

    /// The estimated local error of a substep that ended at `x` over the free vertices (m; module
    /// documentation, "Accuracy", and [`integrator`]), 0 in quasi-static mode.
    fn substep_error(&self, x: &[f64], tg: &Target) -> f64 {
        if self.settings.quasi_static {
            return 0.0;
        }
        integrator::local_error(x, &tg.xt, tg.xp.as_deref(), |v| {
            self.pattern.free[v].is_some()
        })
    }
}

/// Componentwise quantile q ∈ [0, 1] of per-triangle strains (nearest rank; 0 for an empty mesh).
pub fn strain_quantile(z: &[[f64; 6]], q: f64) -> [f64; 6] {
    let mut out = [0.0; 6];
    if z.is_empty() {
        return out;
    }
    let mut col: Vec<f64> = Vec::with_capacity(z.len());
    for (k, o) in out.iter_mut().enumerate() {
        col.clear();
        col.extend(z.iter().map(|v| v[k]));
        let i = ((q.clamp(0.0, 1.0) * (col.len() - 1) as f64).round()) as usize;
        let (_, v, _) = col.select_nth_unstable_by(i, |a, b| a.total_cmp(b));
        *o = *v;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::strain_quantile;

    /// Nearest-rank quantiles per component, independent of the order of the triangles.
    #[test]
    fn strain_quantiles_are_per_component_nearest_rank() {
        let mut z: Vec<[f64; 6]> = (0..101)
            .map(|i| {
                let v = i as f64;
                [v, -v, 2.0 * v, 0.0, 1e3 - v, v * v]
            })
            .collect();
        z.reverse();
        z.swap(3, 70);
        assert_eq!(
            strain_quantile(&z, 0.01),
            [1.0, -99.0, 2.0, 0.0, 901.0, 1.0]
        );
        assert_eq!(
            strain_quantile(&z, 0.99),
            [99.0, -1.0, 198.0, 0.0, 999.0, 9801.0]
        );
        assert_eq!(strain_quantile(&z, 0.0)[0], 0.0);
        assert_eq!(strain_quantile(&z, 1.0)[0], 100.0);
        assert_eq!(strain_quantile(&[], 0.5), [0.0; 6]);
    }
}
