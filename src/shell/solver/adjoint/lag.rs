//! Stiffness-proportional damping and air drag in the trajectory adjoint: terms whose data are lagged at the
//! substep's start x_k (`docs/sensitivities.md`, "Damping and air drag").
//!
//! Substep k adds to G_k the damping gradient κ Σ_f H_f(x_k) δq_f (κ = c/h, δq_f = q_f(x) − q_f(x_k), H_f the
//! option-(b) PSD Hessian of triangle f, [`crate::shell::dissipation`]) and the drag gradient Σ_f ∇_xΠ_f(x; x_k).
//! Their Hessians κ H_f and ∇²_xΠ_f join H_k (and the full Hessian of the reactions and the held dofs); their
//! dependence on x_k and on the parameters adds, with μ = λ − u,
//!
//!   x̄_k += κ H_f μ_f − κ ∇_q φ_f − ∇_{x_k}(μ_fᵀ ∇_xΠ_f(x; x_k)),   dJ/dp −= κ ∂φ_f/∂p,
//!
//! where φ_f = μ_fᵀ H_f(q_f(x_k)) δq_f with its gradient and parameter derivatives from
//! [`crate::shell::damping_lag`], and the drag's term comes from forward-mode AD of
//! [`dissipation::drag_lagged_reference`] (the wind is no parameter).
//!
//! Lagged friction ([`crate::shell::obstacle`]) freezes, for every free vertex v within an obstacle's layer at
//! x_k, the normal n = ∇d(x_k) and the normal force λ = m k (δ_c − d(x_k))², and charges D_v = μ λ f₀(|T δ_v|)
//! with δ_v = x_v − x_{k,v} − (o(t_{k+1}) − o(t_k)) (o the obstacle's placement). Its gradient is proportional to
//! the masses (it joins the mass scale's ∂G/∂μ), its Hessian ∇²D_v joins H_k, and with a = ∇_n(μ_vᵀ∇D_v) and
//! a_λ = ∂_λ(μ_vᵀ∇D_v) (forward-mode AD of [`crate::shell::obstacle::friction_lagged_reference`]) and
//! ∇λ = −2 m k (δ_c − d) n,
//!
//!   x̄_{k,v} += ∇²D_v μ_v − (∇²d a + a_λ ∇λ),   dJ/dT_i += ∇²d a + a_λ ∇λ
//!
//! (an obstacle translated by T_i moves d(x − T_i), and o(t_{k+1}) − o(t_k) not at all). Which vertices are in
//! contact is held as it ran; λ vanishes with its first derivative at the layer's edge, so a vertex entering
//! the layer changes nothing to first order. Damping with the 18×18 projection (option (a)) and a hinge beyond
//! the fold barrier's threshold at a damped substep's start are not covered: [`ShellError::AdjointUnsupported`].

use super::{Exact, Sensitivity, Simulation};
use crate::material::coefficients::{BasisEvaluator, Coefficient};
use crate::shell::assemble::{gather, zero_absent_flaps};
use crate::shell::damping_lag::{DampingLag, DampingLagError};
use crate::shell::dissipation::{self, DragFace};
use crate::shell::element::ElementModel;
use crate::shell::obstacle::{self, FrictionContact};
use crate::shell::strain::NDOF;
use crate::shell::{Psd, ShellError};
use nalgebra::{Const, U1};
use num_dual::{Dual, DualSVec64};
use rayon::prelude::*;

/// What substep k froze at x_k.
pub(super) struct Lag {
    /// κ = c/h
    kappa: f64,
    /// per stencil H_f(x_k), zero on absent flaps (empty without damping)
    hd: Vec<[[f64; NDOF]; NDOF]>,
    /// per stencil its face lagged at x_k (empty without wind)
    drag: Vec<DragFace>,
    /// the substep's length h (s)
    h: f64,
    /// the vertices in an obstacle's layer at x_k (empty without friction)
    friction: Vec<Contact>,
}

/// A vertex in an obstacle's layer at a substep's start, with what lagged friction froze.
struct Contact {
    /// the frozen normal and normal force
    fc: FrictionContact,
    /// the obstacle
    obstacle: usize,
    /// its translation over the substep, o(t_{k+1}) − o(t_k)
    moved: [f64; 3],
    /// ∇²d at x_k (1/m)
    hess_d: [[f64; 3]; 3],
    /// ∇λ with respect to the vertex's position at x_k (N/m)
    grad_lambda: [f64; 3],
}

impl Simulation {
    /// The damping model: the element model with option (b) where the scene uses (c), as the forward step does.
    fn damping_model(&self) -> Result<ElementModel, ShellError> {
        let mut model = self.model.clone();
        match model.psd {
            Psd::Full => Err(ShellError::AdjointUnsupported {
                reason: "damping with the 18×18 projection (psd \"full\") needs that projection's derivative",
            }),
            Psd::None => {
                model.psd = Psd::Psi;
                Ok(model)
            }
            Psd::Psi => Ok(model),
        }
    }

    /// The data substep k (length `h`, from `tk` to `tk + h`) froze at its start `xk`; `None` without damping,
    /// wind and friction.
    pub(super) fn lag_at(&self, xk: &[f64], h: f64, tk: f64) -> Result<Option<Lag>, ShellError> {
        let s = &self.settings;
        if s.damping == 0.0 && s.wind.is_off() && s.friction == 0.0 {
            return Ok(None);
        }
        let step = self.steps;
        let degenerate = || ShellError::Degenerate { step };
        let mut hd = vec![];
        if s.damping > 0.0 {
            let model = self.damping_model()?;
            hd = self
                .stencils
                .par_iter()
                .map(|st| {
                    let q = gather(st, xk);
                    let (mut g, mut hm) = ([0.0; NDOF], [[0.0; NDOF]; NDOF]);
                    model.energy_gradient_hessian(&q, &st.rest, st.flaps, &mut g, &mut hm)?;
                    zero_absent_flaps(&mut hm, st, model.bending);
                    Some(hm)
                })
                .collect::<Option<Vec<_>>>()
                .ok_or_else(degenerate)?;
        }
        let mut drag = vec![];
        if !s.wind.is_off() {
            for st in &self.stencils {
                let p = |a: usize| std::array::from_fn(|k| xk[3 * st.v[a] + k]);
                drag.push(
                    dissipation::drag_face([p(0), p(1), p(2)], st.rest.area)
                        .ok_or_else(degenerate)?,
                );
            }
        }
        Ok(Some(Lag {
            kappa: s.damping / h,
            hd,
            drag,
            h,
            friction: self.contacts_at(xk, tk, tk + h),
        }))
    }

    /// The free vertices within an obstacle's layer at `xk` (time `tk`), as the forward step froze them for the
    /// substep ending at `t1`.
    fn contacts_at(&self, xk: &[f64], tk: f64, t1: f64) -> Vec<Contact> {
        let s = &self.settings;
        let mut out = vec![];
        if s.friction == 0.0 {
            return out;
        }
        for v in (0..self.pattern.n).filter(|&v| self.pattern.free[v].is_some()) {
            let p = [xk[3 * v], xk[3 * v + 1], xk[3 * v + 2]];
            for (i, motion) in self.obstacle_motions.iter().enumerate() {
                let pr = self.obstacle_proximity(i, p, tk);
                let pen = s.thickness - pr.d;
                if pen <= 0.0 {
                    continue;
                }
                let mk = self.mass[v] * s.contact_stiffness;
                let (o0, o1) = (motion.position(tk), motion.position(t1));
                out.push(Contact {
                    fc: FrictionContact {
                        vertex: v,
                        n: pr.n,
                        lambda: mk * pen * pen,
                    },
                    obstacle: i,
                    moved: std::array::from_fn(|c| o1[c] - o0[c]),
                    hess_d: pr.hess,
                    grad_lambda: pr.n.map(|nc| -2.0 * mk * pen * nc),
                });
            }
        }
        out
    }

    /// One contact's δ, friction gradient and Hessian at the current state.
    fn contact_terms(
        &self,
        c: &Contact,
        xk: &[f64],
        h: f64,
    ) -> ([f64; 3], [f64; 3], [[f64; 3]; 3]) {
        let s = &self.settings;
        let v = c.fc.vertex;
        let delta = std::array::from_fn(|a| self.x[3 * v + a] - xk[3 * v + a] - c.moved[a]);
        let (_, g, hb) = obstacle::friction(&c.fc, s.friction, s.friction_velocity * h, delta);
        (delta, g, hb)
    }

    /// Add the lagged terms' gradients (all dofs) and Hessians (free dofs) at the current state x_{k+1} to `ex`.
    pub(super) fn add_lag_terms(&self, lag: &Lag, xk: &[f64], ex: &mut Exact) {
        let n = 3 * self.pattern.n;
        let mut g = vec![0.0; n];
        for (si, hm) in lag.hd.iter().enumerate() {
            let st = &self.stencils[si];
            let dq: [f64; NDOF] = std::array::from_fn(|i| {
                self.x[3 * st.v[i / 3] + i % 3] - xk[3 * st.v[i / 3] + i % 3]
            });
            let (_, gs) = dissipation::damping(hm, lag.kappa, &dq);
            scatter(st, &gs, &mut g);
            let scaled = hm.map(|row| row.map(|x| lag.kappa * x));
            self.pattern
                .add_stencil_hessian(&mut ex.values, si, st, &scaled);
        }
        let wind = &self.settings.wind;
        for (si, face) in lag.drag.iter().enumerate() {
            let st = &self.stencils[si];
            let q: [f64; 9] = std::array::from_fn(|i| self.x[3 * st.v[i / 3] + i % 3]);
            let (_, g9, h9) = dissipation::drag(face, wind, lag.h, &q);
            let mut gs = [0.0; NDOF];
            gs[..9].copy_from_slice(&g9);
            scatter(st, &gs, &mut g);
            let mut hm = [[0.0; NDOF]; NDOF];
            for r in 0..9 {
                hm[r][..9].copy_from_slice(&h9[r]);
            }
            self.pattern
                .add_stencil_hessian(&mut ex.values, si, st, &hm);
        }
        for (a, b) in ex.g_full.iter_mut().zip(&g) {
            *a += b;
        }
        for c in &lag.friction {
            let v = c.fc.vertex;
            let (_, g, hb) = self.contact_terms(c, xk, lag.h);
            for a in 0..3 {
                ex.g_full[3 * v + a] += g[a];
                ex.g_mass[3 * v + a] += g[a];
            }
            if let Some(f) = self.pattern.free[v] {
                self.pattern.add_diag_block(&mut ex.values, f, &hb);
            }
        }
    }

    /// (κ Σ_f H_f + Σ_f ∇²_xΠ_f + Σ_v ∇²D_v) w over all dofs, at the current state (`xk` the substep's start).
    pub(super) fn lag_times(&self, lag: &Lag, xk: &[f64], w: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; w.len()];
        for (si, hm) in lag.hd.iter().enumerate() {
            let st = &self.stencils[si];
            let wl = gather(st, w);
            let hw: [f64; NDOF] = std::array::from_fn(|r| {
                lag.kappa * (0..NDOF).map(|j| hm[r][j] * wl[j]).sum::<f64>()
            });
            scatter(st, &hw, &mut out);
        }
        let wind = &self.settings.wind;
        for (si, face) in lag.drag.iter().enumerate() {
            let st = &self.stencils[si];
            let q: [f64; 9] = std::array::from_fn(|i| self.x[3 * st.v[i / 3] + i % 3]);
            let (_, _, h9) = dissipation::drag(face, wind, lag.h, &q);
            let wl = gather(st, w);
            let mut hw = [0.0; NDOF];
            for r in 0..9 {
                hw[r] = (0..9).map(|j| h9[r][j] * wl[j]).sum();
            }
            scatter(st, &hw, &mut out);
        }
        for c in &lag.friction {
            let v = c.fc.vertex;
            let (_, _, hb) = self.contact_terms(c, xk, lag.h);
            for a in 0..3 {
                out[3 * v + a] += (0..3).map(|b| hb[a][b] * w[3 * v + b]).sum::<f64>();
            }
        }
        out
    }

    /// The lag's share of x̄_k (added to `xbar`) and of dJ/dp (added to `out`) for the adjoint μ over all dofs,
    /// at the current state x_{k+1} (module documentation).
    pub(super) fn lag_adjoint(
        &self,
        lag: &Lag,
        xk: &[f64],
        mu: &[f64],
        out: &mut Sensitivity,
        xbar: &mut [f64],
    ) -> Result<(), ShellError> {
        if !lag.hd.is_empty() {
            self.damping_adjoint(lag, xk, mu, out, xbar)?;
        }
        let wind = &self.settings.wind;
        type D9 = DualSVec64<9>;
        for (si, face) in lag.drag.iter().enumerate() {
            let st = &self.stencils[si];
            let x: Vec<Dual<D9>> = (0..9)
                .map(|i| {
                    let k = 3 * st.v[i / 3] + i % 3;
                    Dual::new(D9::from_re(self.x[k]), D9::from_re(mu[k]))
                })
                .collect();
            let xn: Vec<Dual<D9>> = (0..9)
                .map(|i| {
                    let k = 3 * st.v[i / 3] + i % 3;
                    Dual::new(D9::from_re(xk[k]).derivative(i), D9::from_re(0.0))
                })
                .collect();
            let pi = dissipation::drag_lagged_reference(face.area, wind, lag.h, &x, &xn);
            let g = pi.eps.eps.unwrap_generic(Const::<9>, U1);
            let mut gs = [0.0; NDOF];
            for (i, gi) in g.iter().enumerate() {
                gs[i] = -gi;
            }
            scatter(st, &gs, xbar);
        }
        for c in &lag.friction {
            self.contact_adjoint(c, lag.h, xk, mu, out, xbar);
        }
        Ok(())
    }

    /// One friction contact's share of x̄_k and of dJ/dT_i (module documentation).
    fn contact_adjoint(
        &self,
        c: &Contact,
        h: f64,
        xk: &[f64],
        mu: &[f64],
        out: &mut Sensitivity,
        xbar: &mut [f64],
    ) {
        type D4 = DualSVec64<4>;
        let s = &self.settings;
        let v = c.fc.vertex;
        let (delta, _, hb) = self.contact_terms(c, xk, h);
        let mv = [mu[3 * v], mu[3 * v + 1], mu[3 * v + 2]];
        let d: Vec<Dual<D4>> = (0..3)
            .map(|a| Dual::new(D4::from_re(delta[a]), D4::from_re(mv[a])))
            .collect();
        let n: Vec<Dual<D4>> = (0..3)
            .map(|a| Dual::new(D4::from_re(c.fc.n[a]).derivative(a), D4::from_re(0.0)))
            .collect();
        let lambda = Dual::new(D4::from_re(c.fc.lambda).derivative(3), D4::from_re(0.0));
        let eps = s.friction_velocity * h;
        let f = obstacle::friction_lagged_reference(&n, lambda, s.friction, eps, &d);
        let g = f.eps.eps.unwrap_generic(Const::<4>, U1);
        // ∇²d a + a_λ ∇λ: μᵀ ∂∇D/∂x_k through the frozen n and λ
        let through: [f64; 3] = std::array::from_fn(|a| {
            (0..3).map(|b| c.hess_d[a][b] * g[b]).sum::<f64>() + g[3] * c.grad_lambda[a]
        });
        for a in 0..3 {
            xbar[3 * v + a] += (0..3).map(|b| hb[a][b] * mv[b]).sum::<f64>() - through[a];
            out.obstacles[c.obstacle][a] += through[a];
        }
    }

    fn damping_adjoint(
        &self,
        lag: &Lag,
        xk: &[f64],
        mu: &[f64],
        out: &mut Sensitivity,
        xbar: &mut [f64],
    ) -> Result<(), ShellError> {
        let model = self.damping_model()?;
        let lags: Vec<DampingLag> = self
            .stencils
            .par_iter()
            .map(|st| {
                let q = gather(st, xk);
                let mut a = gather(st, mu);
                let mut b: [f64; NDOF] = std::array::from_fn(|i| {
                    self.x[3 * st.v[i / 3] + i % 3] - q[i]
                });
                for f in 0..3 {
                    if !st.flaps[f] || !model.bending {
                        a[9 + 3 * f..12 + 3 * f].fill(0.0);
                        b[9 + 3 * f..12 + 3 * f].fill(0.0);
                    }
                }
                model.damping_lag(&q, &st.rest, st.flaps, &a, &b)
            })
            .collect::<Result<_, _>>()
            .map_err(|e| match e {
                DampingLagError::Degenerate => ShellError::Degenerate { step: self.steps },
                DampingLagError::FoldActive => ShellError::AdjointUnsupported {
                    reason: "a hinge is beyond the fold barrier's threshold at a damped substep's start",
                },
            })?;
        let kappa = lag.kappa;
        let mat = &self.model.material;
        let material = out.material.is_some();
        // per triangle: its share of x̄_k and, with the material, of dJ/dc_j (in parallel, summed in order)
        let parts: Vec<TriangleShare> = self
            .stencils
            .par_iter()
            .zip(lag.hd.par_iter())
            .zip(lags.par_iter())
            .map_init(
                || BasisEvaluator::new(mat),
                |basis, ((st, hm), l)| {
                    let a = gather(st, mu);
                    let local: [f64; NDOF] = std::array::from_fn(|r| {
                        kappa * ((0..NDOF).map(|j| hm[r][j] * a[j]).sum::<f64>() - l.grad[r])
                    });
                    let mut coefs = vec![];
                    if material {
                        for c in mat.support(&l.y) {
                            if c == Coefficient::Constant {
                                continue;
                            }
                            let p = basis.basis_hessian(c, &l.y);
                            let mut d: f64 = (0..6).map(|i| l.r[i] * p.grad[i]).sum();
                            for i in 0..6 {
                                d += (0..6).map(|j| l.n[i][j] * p.hess[i][j]).sum::<f64>();
                            }
                            coefs.push((c, kappa * d));
                        }
                    }
                    (local, coefs)
                },
            )
            .collect();
        for ((st, l), (local, coefs)) in self.stencils.iter().zip(&lags).zip(parts) {
            scatter(st, &local, xbar);
            out.stiffness -= kappa * l.value / self.model.stiffness;
            out.bending_scale -= kappa * l.bending_scale;
            if let Some(gc) = out.material.as_mut() {
                for (c, d) in coefs {
                    *gc.get_mut(c) -= d;
                }
            }
        }
        Ok(())
    }
}

/// One triangle's share of x̄_k and its (coefficient, (c/h) ∂φ/∂c_j) pairs.
type TriangleShare = ([f64; NDOF], Vec<(Coefficient, f64)>);

/// out[dofs of the stencil's present vertices] += local.
fn scatter(st: &crate::shell::mesh::Stencil, local: &[f64; NDOF], out: &mut [f64]) {
    for a in 0..6 {
        if a >= 3 && !st.flaps[a - 3] {
            continue;
        }
        for c in 0..3 {
            out[3 * st.v[a] + c] += local[3 * a + c];
        }
    }
}
