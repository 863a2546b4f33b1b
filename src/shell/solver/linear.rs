//! The Newton system of a step (`docs/cloth-simulator.md`, "The cloth solver"): the exact Hessian first, the PSD option's
//! Hessian when it is not positive definite, a growing diagonal shift as the last resort; faer's sparse
//! Cholesky with the simulation's symbolic analysis, numeric factorisation and solve run sequentially (on this
//! 2-core machine faer's parallel supernodal factorisation spent more time handing work between threads than it
//! saved: `basket_stretchX` took 1.5× longer with two threads than with one).

use super::Simulation;
use crate::shell::ShellError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::LltRef;
use faer::sparse::SparseColMatRef;
use faer::{Conj, Par, Side};

impl Simulation {
    /// Whether the assembly also produces the exact Hessian (only useful when the PSD option changes it).
    pub(super) fn exact_first(&self) -> bool {
        self.settings.exact_first && self.model.psd != crate::shell::Psd::None
    }

    /// Solve H d = −g with the reused symbolic analysis; returns d and the diagonal shift used. With
    /// `exact` non-empty, the exact Hessian is tried first (Newton's own direction, quadratic convergence near the
    /// solution) and the PSD option's `values` only when the exact one is not positive definite.
    pub(super) fn solve(
        &self,
        values: &[f64],
        exact: &[f64],
        g: &[f64],
    ) -> Result<(Vec<f64>, f64), ShellError> {
        let nf = g.len();
        if !exact.is_empty() {
            if let Some(d) = self.factor_solve(exact, g) {
                return Ok((d, 0.0));
            }
        }
        let mut shift = 0.0;
        let mean_diag = self
            .pattern
            .lower
            .diag
            .iter()
            .map(|&k| values[k].abs())
            .sum::<f64>()
            / nf as f64;
        let mut vals = values.to_vec();
        for attempt in 0..30 {
            if attempt > 0 {
                let new_shift = if shift == 0.0 {
                    1e-8 * mean_diag.max(1e-300)
                } else {
                    10.0 * shift
                };
                for &k in &self.pattern.lower.diag {
                    vals[k] += new_shift - shift;
                }
                shift = new_shift;
            }
            if let Some(d) = self.factor_solve(&vals, g) {
                return Ok((d, shift));
            }
        }
        Err(ShellError::Factorization {
            step: self.steps + 1,
        })
    }

    /// d = −H⁻¹ g for the free-dof matrix H with the lower-triangle `values` (the pattern's order): the numeric
    /// Cholesky factorisation with the simulation's symbolic analysis, then one solve. `None` when H is not
    /// positive definite or d is not finite.
    pub(super) fn factor_solve(&self, values: &[f64], g: &[f64]) -> Option<Vec<f64>> {
        let nf = g.len();
        let sym = &self.symbolic;
        let req = sym
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(sym.solve_in_place_scratch::<f64>(1, Par::Seq));
        let mut guard = self
            .factor_scratch
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let (factor, buf) = &mut *guard;
        if buf.len() < req.size_bytes() {
            *buf = MemBuffer::new(req);
        }
        factor.resize(sym.len_val(), 0.0);
        let mat = SparseColMatRef::new(self.pattern.lower.symbolic(), values);
        sym.factorize_numeric_llt(
            factor,
            mat,
            Side::Lower,
            LltRegularization {
                dynamic_regularization_delta: 0.0,
                dynamic_regularization_epsilon: 0.0,
            },
            Par::Seq,
            MemStack::new(buf),
            Default::default(),
        )
        .ok()?;
        let llt = LltRef::new(sym, factor);
        let mut d: Vec<f64> = g.iter().map(|x| -x).collect();
        llt.solve_in_place_with_conj(
            Conj::No,
            faer::MatMut::from_column_major_slice_mut(&mut d, nf, 1),
            Par::Seq,
            MemStack::new(buf),
        );
        d.iter().all(|x| x.is_finite()).then_some(d)
    }
}
