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
//! [`dissipation::drag_lagged_reference`] (the wind is no parameter). Damping with the 18×18 projection (option
//! (a)) and a hinge beyond the fold barrier's threshold at a damped substep's start are not covered:
//! [`ShellError::AdjointUnsupported`].

use super::{Exact, Sensitivity, Simulation};
use crate::material::coefficients::{BasisEvaluator, Coefficient};
use crate::shell::assemble::{gather, zero_absent_flaps};
use crate::shell::damping_lag::{DampingLag, DampingLagError};
use crate::shell::dissipation::{self, DragFace};
use crate::shell::element::ElementModel;
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

    /// The data substep k (length `h`) froze at its start `xk`; `None` without damping and wind.
    pub(super) fn lag_at(&self, xk: &[f64], h: f64) -> Result<Option<Lag>, ShellError> {
        let s = &self.settings;
        if s.damping == 0.0 && s.wind.is_off() {
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
        }))
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
    }

    /// (κ Σ_f H_f + Σ_f ∇²_xΠ_f) w over all dofs, at the current state.
    pub(super) fn lag_times(&self, lag: &Lag, w: &[f64]) -> Vec<f64> {
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
        Ok(())
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
        let mut basis = BasisEvaluator::new(mat);
        for ((st, hm), l) in self.stencils.iter().zip(&lag.hd).zip(&lags) {
            let a = gather(st, mu);
            let local: [f64; NDOF] = std::array::from_fn(|r| {
                kappa * ((0..NDOF).map(|j| hm[r][j] * a[j]).sum::<f64>() - l.grad[r])
            });
            scatter(st, &local, xbar);
            out.stiffness -= kappa * l.value / self.model.stiffness;
            out.bending_scale -= kappa * l.bending_scale;
            if let Some(gc) = out.material.as_mut() {
                for c in mat.support(&l.y) {
                    if c == Coefficient::Constant {
                        continue;
                    }
                    let p = basis.basis_hessian(c, &l.y);
                    let mut d: f64 = (0..6).map(|i| l.r[i] * p.grad[i]).sum();
                    for i in 0..6 {
                        d += (0..6).map(|j| l.n[i][j] * p.hess[i][j]).sum::<f64>();
                    }
                    *gc.get_mut(c) -= kappa * d;
                }
            }
        }
        Ok(())
    }
}

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
