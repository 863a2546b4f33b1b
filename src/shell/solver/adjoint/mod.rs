//! Sensitivities of a quasi-static equilibrium by one adjoint solve.
//!
//! At a converged quasi-static equilibrium the gradient of Φ = E(x; c, s, β) − Σ_v m_v g·x_v + E_obst(x; m)
//! (+ handle springs) vanishes on the free dofs: g(x*, p) = ∂Φ/∂x_f = 0. For a parameter p the implicit function
//! theorem gives H dx*/dp = −∂g/∂p with H = ∂²Φ/∂x_f² the **exact** Hessian on the free dofs (exact elastic
//! Hessian, exact obstacle Hessian m k (2 p n nᵀ − p² ∇²d), springs k I). For a scalar observable J(x*, p) one
//! solve
//!
//!   H λ = (∂J/∂x_f)ᵀ,   dJ/dp = ∂J/∂p − λᵀ ∂g/∂p
//!
//! gives every dJ/dp at once. When H does not factorise as positive definite (faer's sparse Cholesky fails) the
//! equilibrium is not a strict minimum and dx*/dp is undefined: [`ShellError::NotStrictMinimum`], never a
//! projected or shifted Hessian.
//!
//! Parameters ([`Sensitivity`]):
//! - the stiffness multiplier s: E_Δ = A s ψ̃(S z) + fold barrier (ψ̃ = ψ plus the collapse barrier's density,
//!   the fold barrier does not scale with s), so ∂g/∂s = Σ_Δ A Jᵀ S ∇ψ̃;
//! - the bending scale β (S = diag(1, 1, 1, β, β, β)): ∂(S∇ψ̃(Sz))/∂β = P ∇ψ̃ + S ∇²ψ̃ P z with
//!   P = diag(0, 0, 0, 1, 1, 1), so ∂g/∂β = Σ_Δ A s Jᵀ (P ∇ψ̃ + S ∇²ψ̃ P z);
//! - a uniform scale μ of the vertex masses at μ = 1 (the scene's `model.mass` multiplies every mass, so
//!   dJ/d(model.mass) = dJ/dμ / model.mass, [`Sensitivity::mass_multiplier`]): gravity −m g and the obstacle
//!   penalty m k p³/3 are linear in m, so ∂g/∂μ is their gradient;
//! - gravity: ∂g_v/∂g_c = −m_v e_c;
//! - the positions of the boundary: every held set's translation and keyframe offsets, every obstacle's
//!   translation (`boundary`);
//! - every coefficient c_j of the model's material (`material::coefficients`): ∂g/∂c_j = Σ_Δ A s Jᵀ S ∇φ_j(S z).
//!   Reverse mode: per triangle w = A s S J λ_Δ (the adjoint pulled back to ψ's strain space), then
//!   dJ/dc_j = ∂J/∂c_j − Σ_Δ wᵀ ∇φ_j(S z_Δ), over the coefficients of each triangle's local support.
//!
//! Observables ([`Observable`]), with their explicit parts:
//! - the mass-weighted centre Σ m_v x_v / Σ m_v (component c): ∂J/∂x_v = m_v/M e_c, no explicit p dependence
//!   (a uniform mass scale leaves it unchanged);
//! - the elastic energy E: ∂J/∂x = ∇E; ∂E/∂s = Σ A ψ̃, ∂E/∂β = Σ A s ∇ψ̃·P z, ∂E/∂c_j = Σ A s φ_j(S z);
//! - the reaction of a held set (component c, as `handle_forces` reports it): with hard constraints
//!   R = uᵀ ∇Φ_full with u the indicator of the set's dofs of component c, so ∂R/∂x_f = (H_full u)_f (the
//!   free–held block) and ∂R/∂p = uᵀ ∂∇Φ/∂p: both fold into dJ/dp = −(λ − u)ᵀ ∂∇Φ/∂p; with springs
//!   R = Σ k (p_v − x_v), ∂R/∂x_v = −k e_c, no explicit p dependence;
//! - `target` ½ Σ_v |x_v − x̂_v|² over all vertices: ∂J/∂x = x − x̂;
//! - `linear` Σ_v w_v · x_v for a cotangent w: ∂J/∂x = w, so dJ/dp = wᵀ dx*/dp (a vector–Jacobian product).
//!
//! Quasi-static simulations without friction only (friction and the dynamic terms lag data of the previous
//! step): [`ShellError::AdjointUnsupported`] otherwise.

mod boundary;
mod lag;
mod trajectory;

use super::{obstacle, Simulation};
use crate::material::coefficients::{BasisEvaluator, Coefficient, MaterialGradient};
use crate::shell::assemble::{assemble, gather};
use crate::shell::strain::{StrainChain, NDOF};
use crate::shell::{Psd, ShellError};
pub use boundary::HeldGradient;
pub use trajectory::{Tape, TapeStep};

/// A scalar function of the equilibrium.
#[derive(Clone, Debug, PartialEq)]
pub enum Observable {
    /// component `axis` (0, 1, 2) of the mass-weighted centre of all vertices
    CenterOfMass {
        /// the component (0, 1, 2)
        axis: usize,
    },
    /// the elastic energy E (the triangles' energies with their barriers)
    ElasticEnergy,
    /// component `axis` of the force the held set `set` exerts on the cloth (a handle's name or `pinned`;
    /// `handle_forces` of the step report)
    Reaction {
        /// the held set (a handle's name or `pinned`)
        set: String,
        /// the component (0, 1, 2)
        axis: usize,
    },
    /// ½ Σ_v |x_v − x̂_v|² over every vertex
    Target {
        /// the target positions x̂_v, one per vertex (m)
        positions: Vec<[f64; 3]>,
    },
    /// Σ_v w_v · x_v: with w a cotangent on the positions, the gradient is the vector–Jacobian product
    /// wᵀ dx*/dp
    Linear {
        /// the weights w_v, one per vertex
        weights: Vec<[f64; 3]>,
    },
}

/// dJ/dp of one observable at an equilibrium.
#[derive(Clone, Debug)]
pub struct Sensitivity {
    /// J at the equilibrium
    pub value: f64,
    /// the largest residual force on a free vertex at the state (N): the formulas hold at residual 0
    pub residual: f64,
    /// dJ/ds, s the stiffness multiplier (`model.stiffness`)
    pub stiffness: f64,
    /// dJ/dβ, β the bending scale (`model.bending_scale`)
    pub bending_scale: f64,
    /// dJ/dμ at μ = 1 for the masses scaled by μ ([`Sensitivity::mass_multiplier`] for `model.mass`)
    pub mass_scale: f64,
    /// dJ/dg
    pub gravity: [f64; 3],
    /// dJ/dc_j for every coefficient of the model's material (in its layout; `None` unless asked for)
    pub material: Option<MaterialGradient>,
    /// dJ/dT and dJ/d(keyframe offsets) of every held set: the handles in order, then `pinned`
    pub held: Vec<HeldGradient>,
    /// dJ/dTᵢ for a translation of each obstacle, in order
    pub obstacles: Vec<[f64; 3]>,
}

impl Sensitivity {
    /// dJ/d(model.mass) for the scene's mass multiplier `model_mass` (the masses are proportional to it).
    pub fn mass_multiplier(&self, model_mass: f64) -> f64 {
        self.mass_scale / model_mass
    }
}

/// The exact system at the current state.
struct Exact {
    /// exact Hessian of Φ over the free dofs (the pattern's lower triangle)
    values: Vec<f64>,
    /// ∇Φ over all dofs
    g_full: Vec<f64>,
    /// ∇E alone
    g_elastic: Vec<f64>,
    /// the gradient of the terms proportional to the masses (gravity, obstacle penalty), all dofs
    g_mass: Vec<f64>,
    energy: f64,
}

impl Simulation {
    fn adjoint_supported(&self) -> Result<(), ShellError> {
        let s = &self.settings;
        let reason = if !s.quasi_static {
            "the simulation is not quasi-static"
        } else if s.friction > 0.0 {
            "friction lags the previous step's contacts"
        } else {
            return Ok(());
        };
        Err(ShellError::AdjointUnsupported { reason })
    }

    /// The vertices of held set `set` and their translation at the current time.
    fn held_set(&self, set: &str) -> Result<(&[usize], [f64; 3]), ShellError> {
        if let Some(h) = self.handles.iter().find(|h| h.name == set) {
            return Ok((&h.vertices, h.offset(self.time)));
        }
        if set == "pinned" && !self.pinned.is_empty() {
            return Ok((&self.pinned, [0.0; 3]));
        }
        Err(ShellError::UnknownHeldSet {
            set: set.to_string(),
        })
    }

    /// The exact Hessian, gradients and energy of Φ at the current state (quasi-static terms).
    fn exact_system(&self) -> Result<Exact, ShellError> {
        let mut model = self.model.clone();
        model.psd = Psd::None;
        let asm = assemble(&model, &self.stencils, &self.pattern, &self.x, true, false)
            .ok_or(ShellError::Degenerate { step: self.steps })?;
        let s = &self.settings;
        let n = self.pattern.n;
        let mut values = asm.values;
        let mut g_mass = vec![0.0; 3 * n];
        for v in 0..n {
            let m = self.mass[v];
            let p = [self.x[3 * v], self.x[3 * v + 1], self.x[3 * v + 2]];
            let mut blk = [[0.0; 3]; 3];
            for i in 0..self.obstacles.len() {
                let pr = self.obstacle_proximity(i, p, self.time);
                let (_, go, _) = obstacle::penalty(&pr, m, s.contact_stiffness, s.thickness);
                let ho = obstacle::penalty_hessian_exact(&pr, m, s.contact_stiffness, s.thickness);
                for a in 0..3 {
                    g_mass[3 * v + a] += go[a];
                    for b in 0..3 {
                        blk[a][b] += ho[a][b];
                    }
                }
            }
            for c in 0..3 {
                g_mass[3 * v + c] -= m * s.gravity[c];
            }
            if let Some(k) = self.pattern.free[v] {
                self.pattern.add_diag_block(&mut values, k, &blk);
            }
        }
        let mut g_full: Vec<f64> = asm.grad.iter().zip(&g_mass).map(|(a, b)| a + b).collect();
        if let Some(k) = s.handle_stiffness {
            let kb = std::array::from_fn(|a| std::array::from_fn(|b| k * f64::from(a == b)));
            for (v, p) in self.held_targets(self.time) {
                for c in 0..3 {
                    g_full[3 * v + c] += k * (self.x[3 * v + c] - p[c]);
                }
                if let Some(kf) = self.pattern.free[v] {
                    self.pattern.add_diag_block(&mut values, kf, &kb);
                }
            }
        }
        Ok(Exact {
            values,
            g_full,
            g_elastic: asm.grad,
            g_mass,
            energy: asm.energy,
        })
    }

    /// The value of an observable at the current state.
    pub fn observable(&self, obs: &Observable) -> Result<f64, ShellError> {
        let ex = self.exact_system()?;
        Ok(self.observable_parts(obs, &ex)?.0)
    }

    /// J, ∂J/∂x over all dofs, and the reaction indicator u (hard constraints only; zero otherwise).
    fn observable_parts(
        &self,
        obs: &Observable,
        ex: &Exact,
    ) -> Result<(f64, Vec<f64>, Vec<f64>), ShellError> {
        let n = self.pattern.n;
        let x = &self.x;
        let mut djdx = vec![0.0; 3 * n];
        let mut u = vec![0.0; 3 * n];
        let value = match obs {
            Observable::CenterOfMass { axis } => {
                let axis = check_axis(*axis)?;
                let total: f64 = self.mass.iter().sum();
                let mut j = 0.0;
                for v in 0..n {
                    j += self.mass[v] * x[3 * v + axis] / total;
                    djdx[3 * v + axis] = self.mass[v] / total;
                }
                j
            }
            Observable::ElasticEnergy => {
                djdx.copy_from_slice(&ex.g_elastic);
                ex.energy
            }
            Observable::Target { positions } => {
                if positions.len() != n {
                    return Err(ShellError::AdjointUnsupported {
                        reason: "the target has not one position per vertex",
                    });
                }
                let mut j = 0.0;
                for v in 0..n {
                    for c in 0..3 {
                        let d = x[3 * v + c] - positions[v][c];
                        j += 0.5 * d * d;
                        djdx[3 * v + c] = d;
                    }
                }
                j
            }
            Observable::Linear { weights } => {
                if weights.len() != n {
                    return Err(ShellError::AdjointUnsupported {
                        reason: "the cotangent has not one vector per vertex",
                    });
                }
                let mut j = 0.0;
                for v in 0..n {
                    for c in 0..3 {
                        j += weights[v][c] * x[3 * v + c];
                        djdx[3 * v + c] = weights[v][c];
                    }
                }
                j
            }
            Observable::Reaction { set, axis } => {
                let axis = check_axis(*axis)?;
                let (vertices, o) = self.held_set(set)?;
                match self.settings.handle_stiffness {
                    Some(k) => {
                        let mut j = 0.0;
                        for &v in vertices {
                            let i = 3 * v + axis;
                            j += k * (self.x0[i] + o[axis] - x[i]);
                            djdx[i] -= k;
                        }
                        j
                    }
                    None => {
                        let mut j = 0.0;
                        for &v in vertices {
                            u[3 * v + axis] = 1.0;
                            j += ex.g_full[3 * v + axis];
                        }
                        let free = |v: usize| self.pattern.free[v].is_some();
                        self.hessian_times(&u, &free, &mut djdx)?;
                        j
                    }
                }
            }
        };
        Ok((value, djdx, u))
    }

    /// dJ/dp of `obs` at the current state, which must be a converged quasi-static equilibrium (module
    /// documentation): one exact-Hessian factorisation and solve, then one pass over the triangles and vertices;
    /// with `material` also dJ/dc_j for every coefficient of the model's material.
    pub fn sensitivity(&self, obs: &Observable, material: bool) -> Result<Sensitivity, ShellError> {
        self.adjoint_supported()?;
        let ex = self.exact_system()?;
        let (value, djdx, u) = self.observable_parts(obs, &ex)?;
        let n = self.pattern.n;
        let nf = 3 * self.pattern.nfree;
        let mut rhs = vec![0.0; nf];
        let mut residual = 0.0f64;
        for v in 0..n {
            if let Some(k) = self.pattern.free[v] {
                let f2: f64 = (0..3).map(|c| ex.g_full[3 * v + c].powi(2)).sum();
                residual = residual.max(f2.sqrt());
                for c in 0..3 {
                    rhs[3 * k + c] = djdx[3 * v + c];
                }
            }
        }
        // factor_solve returns −λ = −H⁻¹ rhs
        let neg_lambda = if nf == 0 {
            vec![]
        } else {
            self.factor_solve(&ex.values, &rhs)
                .ok_or(ShellError::NotStrictMinimum { residual })?
        };
        // μ = λ − u over all dofs: dJ/dp = ∂J/∂p|other − μᵀ ∂∇Φ/∂p
        let mut mu: Vec<f64> = u.iter().map(|a| -a).collect();
        for v in 0..n {
            if let Some(k) = self.pattern.free[v] {
                for c in 0..3 {
                    mu[3 * v + c] -= neg_lambda[3 * k + c];
                }
            }
        }
        let mut out = Sensitivity {
            value,
            residual,
            stiffness: 0.0,
            bending_scale: 0.0,
            mass_scale: 0.0,
            gravity: [0.0; 3],
            material: material.then(|| MaterialGradient::zeros(&self.model.material)),
            held: self.held_gradients(Some(obs), &mu, &djdx, 0.0, None)?,
            obstacles: self.obstacle_gradients(&mu),
        };
        let energy = matches!(obs, Observable::ElasticEnergy);
        self.add_parameter_terms(&mu, &ex.g_mass, energy, &mut out)?;
        Ok(out)
    }

    /// Add −μᵀ ∂∇Φ/∂p at the current state to `out` for gravity, the mass scale (`g_mass` the gradient of the
    /// terms proportional to the masses), the stiffness, the bending scale and (when `out.material` is `Some`)
    /// every material coefficient; with `energy` also the elastic energy's explicit ∂E/∂p (module
    /// documentation).
    fn add_parameter_terms(
        &self,
        mu: &[f64],
        g_mass: &[f64],
        energy: bool,
        out: &mut Sensitivity,
    ) -> Result<(), ShellError> {
        // per vertex: gravity and the mass scale
        for v in 0..self.pattern.n {
            for c in 0..3 {
                let i = 3 * v + c;
                out.gravity[c] += self.mass[v] * mu[i];
                out.mass_scale -= mu[i] * g_mass[i];
            }
        }
        // per triangle: stiffness, bending scale, material coefficients
        let model = &self.model;
        let mat = &model.material;
        let mut basis = BasisEvaluator::new(mat);
        let b = model.bending_scale;
        let sv = [1.0, 1.0, 1.0, b, b, b];
        for st in &self.stencils {
            let flaps = if model.bending { st.flaps } else { [false; 3] };
            let q = gather(st, &self.x);
            let ch = StrainChain::new(&q, &st.rest, flaps)
                .ok_or(ShellError::Degenerate { step: self.steps })?;
            let ml = gather(st, mu);
            let w6: [f64; 6] =
                std::array::from_fn(|k| (0..NDOF).map(|j| ch.jac[k][j] * ml[j]).sum());
            let z = ch.z;
            let sz: [f64; 6] = std::array::from_fn(|k| sv[k] * z[k]);
            let mut p = mat.eval(&sz);
            if let Some(cb) = &model.collapse {
                // the collapse barrier acts on the in-plane strains only, where S is the identity
                cb.add_to(&z, &mut p.value, &mut p.grad, &mut p.hess)
                    .ok_or(ShellError::Degenerate { step: self.steps })?;
            }
            let a = st.rest.area;
            let ak = a * model.stiffness;
            // ∂g/∂s = A Jᵀ S ∇ψ̃
            out.stiffness -= a * (0..6).map(|k| sv[k] * p.grad[k] * w6[k]).sum::<f64>();
            // ∂g/∂β = A s Jᵀ (P ∇ψ̃ + S ∇²ψ̃ P z)
            out.bending_scale -= ak
                * (0..6)
                    .map(|k| {
                        let pk = if k >= 3 { p.grad[k] } else { 0.0 };
                        let hz: f64 = (3..6).map(|l| p.hess[k][l] * z[l]).sum();
                        w6[k] * (pk + sv[k] * hz)
                    })
                    .sum::<f64>();
            if energy {
                out.stiffness += a * p.value;
                out.bending_scale += ak * (3..6).map(|l| p.grad[l] * z[l]).sum::<f64>();
            }
            if let Some(gc) = out.material.as_mut() {
                let wm: [f64; 6] = std::array::from_fn(|k| ak * sv[k] * w6[k]);
                for c in mat.support(&sz) {
                    let (phi, gphi) = basis.basis(c, &sz);
                    let d = gc.get_mut(c);
                    *d -= (0..6).map(|k| wm[k] * gphi[k]).sum::<f64>();
                    if energy {
                        *d += ak * phi;
                    }
                }
                if energy {
                    *gc.get_mut(Coefficient::Constant) += ak;
                }
            }
        }
        Ok(())
    }
}

fn check_axis(axis: usize) -> Result<usize, ShellError> {
    if axis < 3 {
        Ok(axis)
    } else {
        Err(ShellError::AdjointUnsupported {
            reason: "an axis is 0, 1 or 2",
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::shell::scene::{self, MeshSpec};
    use std::path::Path;

    /// The adjoint's exact Hessian is the solver's exact Hessian (no obstacles: the same terms).
    #[test]
    fn exact_hessian_is_the_solvers() {
        let mut s = scene::builtin("stretch-x").unwrap();
        s.mesh = MeshSpec::Rectangle {
            width: 0.3,
            height: 0.3,
            edge: 0.3 / 20.0,
            perturb: 0.0,
            seed: 1,
        };
        s.quasi_static = true;
        s.duration = 0.25;
        s.dt = 0.05;
        s.gravity = [0.0; 3];
        let (mut sim, _) = s.build("scene.json", Path::new(".")).unwrap();
        sim.step().unwrap();
        let h = sim.settings.dt;
        let (tg, _) = sim.start_of_step(sim.time, h).unwrap();
        let (asm, g) = sim.gradient_hessian(&sim.x, &tg).unwrap();
        let ex = sim.exact_system().unwrap();
        let scale = ex.values.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for (a, b) in asm.values_exact.iter().zip(&ex.values) {
            assert!((a - b).abs() <= 1e-12 * scale, "{a} vs {b}");
        }
        let gs = g.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for (a, b) in g.iter().zip(&ex.g_full) {
            assert!((a - b).abs() <= 1e-12 * gs.max(1.0), "{a} vs {b}");
        }
    }
}
