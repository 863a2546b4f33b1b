//! dJ/dp for the boundary's positions: every held set's translation and each of its keyframes' offsets, and
//! each obstacle's translation (`docs/sensitivities.md`).
//!
//! With μ = λ − u over all dofs (the adjoint λ on the free dofs, minus the reaction indicator u; the module
//! documentation of `adjoint`), dJ/dp = ∂J/∂p − μᵀ ∂∇Φ/∂p for every parameter p:
//! - **hard constraints**: the held dofs x_h themselves are the parameters, ∂∇Φ/∂x_h = H_full e_h, so
//!   dJ/dx_h = ∂J/∂x_h − (H_full μ)_h with ∂J/∂x_h the observable's explicit dependence (the centre of mass,
//!   the energy, the target; a reaction's lies in −(H_full μ)_h through u) and H_full the exact Hessian over all
//!   dofs (the triangles and the per-vertex obstacle blocks);
//! - **springs**: the targets p_v = x⁰_v + T are the parameters, ∂g_v/∂p_v = −k I, so dJ/dp_v = ∂J/∂p_v + k μ_v
//!   with ∂R/∂p_v = k e_c for the reaction R of the set's component c;
//! - a held set translated by T: dJ/dT = Σ_{v ∈ set} dJ/dx_v; keyframe i's offset oᵢ enters the translation at
//!   time t with the weight wᵢ(t) ([`crate::shell::motion::Motion::offset_weights`]), so dJ/doᵢ = wᵢ(t) dJ/dT;
//! - obstacle i translated by Tᵢ: its penalty depends on x_v − Tᵢ, so ∂g_v/∂Tᵢ = −H_v^i (the exact penalty
//!   Hessian) and dJ/dTᵢ = Σ_v H_v^i μ_v (no observable depends on Tᵢ explicitly).

use super::super::{obstacle, Simulation};
use super::Observable;
use crate::shell::assemble::{gather, zero_absent_flaps};
use crate::shell::strain::NDOF;
use crate::shell::{Psd, ShellError};

/// dJ/dp for the positions of one held set.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldGradient {
    /// the set's name (a handle's, `pin0`…, `sphere0`…, or `pinned`)
    pub name: String,
    /// dJ/dT for a translation T of the whole set
    pub translation: [f64; 3],
    /// dJ/doᵢ for the offset of each keyframe of the set's motion (empty for a set without keyframes)
    pub keyframes: Vec<[f64; 3]>,
}

impl Simulation {
    /// out_r += Σ_c H_full[r][c] w_c for the rows r of the vertices where `rows` holds: the exact elastic
    /// Hessian of every triangle that touches such a vertex and carries a non-zero w, plus the per-vertex
    /// obstacle blocks.
    pub(super) fn hessian_times(
        &self,
        w: &[f64],
        rows: &dyn Fn(usize) -> bool,
        out: &mut [f64],
    ) -> Result<(), ShellError> {
        let mut model = self.model.clone();
        model.psd = Psd::None;
        let mut g = [0.0; NDOF];
        let mut h = [[0.0; NDOF]; NDOF];
        let present = |st: &crate::shell::mesh::Stencil, a: usize| a < 3 || st.flaps[a - 3];
        for st in &self.stencils {
            let wl = gather(st, w);
            if wl.iter().all(|&a| a == 0.0) || !(0..6).any(|a| present(st, a) && rows(st.v[a])) {
                continue;
            }
            let q = gather(st, &self.x);
            model
                .energy_gradient_hessian(&q, &st.rest, st.flaps, &mut g, &mut h)
                .ok_or(ShellError::Degenerate { step: self.steps })?;
            zero_absent_flaps(&mut h, st, model.bending);
            for a in 0..6 {
                if !present(st, a) || !rows(st.v[a]) {
                    continue;
                }
                for c in 0..3 {
                    let r = 3 * a + c;
                    out[3 * st.v[a] + c] += (0..NDOF).map(|j| h[r][j] * wl[j]).sum::<f64>();
                }
            }
        }
        let s = &self.settings;
        for v in (0..self.pattern.n).filter(|&v| rows(v)) {
            let wv = [w[3 * v], w[3 * v + 1], w[3 * v + 2]];
            if wv == [0.0; 3] {
                continue;
            }
            let p = [self.x[3 * v], self.x[3 * v + 1], self.x[3 * v + 2]];
            for i in 0..self.obstacles.len() {
                let pr = self.obstacle_proximity(i, p, self.time);
                let ho = obstacle::penalty_hessian_exact(
                    &pr,
                    self.mass[v],
                    s.contact_stiffness,
                    s.thickness,
                );
                for a in 0..3 {
                    out[3 * v + a] += (0..3).map(|b| ho[a][b] * wv[b]).sum::<f64>();
                }
            }
        }
        Ok(())
    }

    /// dJ/dT of every held set and dJ/doᵢ of its keyframes (module documentation), from μ = λ − u and the
    /// observable's explicit ∂J/∂x over all dofs; `obs` `None` where J is not observed (a substep of a
    /// trajectory), `inertia` the diagonal m (1/h² + c/h) / m of a dynamic substep's Hessian (0 when static),
    /// `lag_mu` the lagged terms' Hessian times μ over all dofs where a substep has them (`lag`).
    pub(super) fn held_gradients(
        &self,
        obs: Option<&Observable>,
        mu: &[f64],
        djdx: &[f64],
        inertia: f64,
        lag_mu: Option<&[f64]>,
    ) -> Result<Vec<HeldGradient>, ShellError> {
        let n = self.pattern.n;
        // dJ/dx_v for every held vertex (hard) or dJ/dp_v for every spring target
        let mut d = vec![0.0; 3 * n];
        match self.settings.handle_stiffness {
            None => {
                let held = |v: usize| self.pattern.free[v].is_none();
                let mut hmu = vec![0.0; 3 * n];
                self.hessian_times(mu, &held, &mut hmu)?;
                for v in (0..n).filter(|&v| held(v)) {
                    let m = inertia * self.mass[v];
                    for c in 0..3 {
                        let i = 3 * v + c;
                        d[i] = djdx[i] - hmu[i] - m * mu[i] - lag_mu.map_or(0.0, |l| l[i]);
                    }
                }
            }
            Some(k) => {
                for (i, m) in mu.iter().enumerate() {
                    d[i] = k * m;
                }
            }
        }
        let mut sets: Vec<(&str, &[usize], Vec<f64>)> = self
            .handles
            .iter()
            .map(|h| {
                let w = h.motion.offset_weights(self.time);
                (h.name.as_str(), h.vertices.as_slice(), w)
            })
            .collect();
        if !self.pinned.is_empty() {
            sets.push(("pinned", &self.pinned, vec![]));
        }
        let spring_reaction = match (obs, self.settings.handle_stiffness) {
            (Some(Observable::Reaction { set, axis }), Some(k)) => Some((set.as_str(), *axis, k)),
            _ => None,
        };
        Ok(sets
            .into_iter()
            .map(|(name, vertices, w)| {
                let mut t = [0.0; 3];
                for &v in vertices {
                    for (c, tc) in t.iter_mut().enumerate() {
                        *tc += d[3 * v + c];
                    }
                }
                // the spring reaction's explicit ∂R/∂p_v = k e_c
                if let Some((_, axis, k)) = spring_reaction.filter(|r| r.0 == name) {
                    t[axis] += k * vertices.len() as f64;
                }
                HeldGradient {
                    name: name.to_string(),
                    translation: t,
                    keyframes: w.iter().map(|wi| t.map(|tc| wi * tc)).collect(),
                }
            })
            .collect())
    }

    /// dJ/dTᵢ for a translation Tᵢ of each obstacle: Σ_v H_v^i μ_v (module documentation).
    pub(super) fn obstacle_gradients(&self, mu: &[f64]) -> Vec<[f64; 3]> {
        let s = &self.settings;
        (0..self.obstacles.len())
            .map(|i| {
                let mut t = [0.0; 3];
                for v in 0..self.pattern.n {
                    let mv = [mu[3 * v], mu[3 * v + 1], mu[3 * v + 2]];
                    if mv == [0.0; 3] {
                        continue;
                    }
                    let p = [self.x[3 * v], self.x[3 * v + 1], self.x[3 * v + 2]];
                    let pr = self.obstacle_proximity(i, p, self.time);
                    let ho = obstacle::penalty_hessian_exact(
                        &pr,
                        self.mass[v],
                        s.contact_stiffness,
                        s.thickness,
                    );
                    for (a, ta) in t.iter_mut().enumerate() {
                        *ta += (0..3).map(|b| ho[a][b] * mv[b]).sum::<f64>();
                    }
                }
                t
            })
            .collect()
    }
}
