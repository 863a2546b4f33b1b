//! The constrained Newton system (`03-homogenization.md`, section 3):
//!
//! [ H + μ I   Aᵀ ] [ δy ]   [ −g ]
//! [ A          0 ] [ λ  ] = [  0 ]
//!
//! solved by one sparse Cholesky factorisation of H + μ I (faer, sequential so that results do not depend on
//! the thread count; the symbolic analysis is kept and reused while the sparsity structure is unchanged) and the
//! Schur complement S = A (H + μI)⁻¹ Aᵀ of the few dense constraint rows.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, Mat, Par, Side};
use nalgebra::{DMatrix, DVector};

/// Why a factorisation could not be used.
#[derive(Clone, Debug, PartialEq)]
pub enum FactorError {
    /// H + μI is not numerically positive definite.
    NotPositiveDefinite,
    /// The Schur complement of the constraints is singular (dependent constraint rows).
    SingularConstraints,
    /// Anything else faer reports (out of memory, index overflow).
    Other(String),
}

/// A sparse Cholesky solver that keeps its symbolic analysis across factorisations of matrices with the same
/// structure.
#[derive(Default)]
pub struct KktSolver {
    symbolic: Option<(Vec<usize>, Vec<usize>, SymbolicCholesky<usize>)>,
    values: Vec<f64>,
    /// Number of symbolic analyses performed (for the performance report).
    pub analyses: usize,
}

impl KktSolver {
    /// Solve the KKT system for the lower-triangle triplets `lower` of the n×n matrix H (duplicates summed),
    /// shift `mu`, gradient `g` and constraint rows `a` (each of length n). Returns δy.
    pub fn solve(
        &mut self,
        n: usize,
        lower: &[(usize, usize, f64)],
        mu: f64,
        g: &[f64],
        a: &[Vec<f64>],
    ) -> Result<Vec<f64>, FactorError> {
        let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(lower.len() + n);
        trip.extend(lower.iter().map(|&(i, j, v)| Triplet::new(i, j, v)));
        trip.extend((0..n).map(|i| Triplet::new(i, i, mu)));
        let mat = SparseColMat::try_new_from_triplets(n, n, &trip)
            .map_err(|e| FactorError::Other(format!("{e:?}")))?;
        let sym = mat.symbolic();
        let same = matches!(&self.symbolic, Some((c, r, _)) if c.as_slice() == sym.col_ptr() && r.as_slice() == sym.row_idx());
        if !same {
            let s = factorize_symbolic_cholesky(
                sym,
                Side::Lower,
                Default::default(),
                Default::default(),
            )
            .map_err(|e| FactorError::Other(format!("{e:?}")))?;
            self.symbolic = Some((sym.col_ptr().to_vec(), sym.row_idx().to_vec(), s));
            self.analyses += 1;
        }
        let (_, _, symbolic) = self.symbolic.as_ref().expect("set above");
        self.values.clear();
        self.values.resize(symbolic.len_val(), 0.0);
        let par = Par::Seq;
        let mut buf = MemBuffer::new(
            symbolic
                .factorize_numeric_llt_scratch::<f64>(par, Default::default())
                .or(symbolic.solve_in_place_scratch::<f64>(1 + a.len(), par)),
        );
        let llt: LltRef<'_, usize, f64> = symbolic
            .factorize_numeric_llt(
                &mut self.values,
                mat.as_ref(),
                Side::Lower,
                LltRegularization {
                    dynamic_regularization_delta: 0.0,
                    dynamic_regularization_epsilon: 0.0,
                },
                par,
                MemStack::new(&mut buf),
                Default::default(),
            )
            .map_err(|_| FactorError::NotPositiveDefinite)?;
        let m = a.len();
        let mut rhs = Mat::<f64>::from_fn(n, 1 + m, |i, j| if j == 0 { g[i] } else { a[j - 1][i] });
        llt.solve_in_place_with_conj(Conj::No, rhs.as_mut(), par, MemStack::new(&mut buf));
        // x_g = (H+μI)⁻¹ g, X_A = (H+μI)⁻¹ Aᵀ; λ = −S⁻¹ A x_g; δ = −(x_g + X_A λ)
        let dot = |row: &[f64], col: usize| -> f64 { (0..n).map(|i| row[i] * rhs[(i, col)]).sum() };
        let mut delta: Vec<f64> = (0..n).map(|i| -rhs[(i, 0)]).collect();
        if m > 0 {
            let s = DMatrix::from_fn(m, m, |i, j| dot(&a[i], 1 + j));
            let ax = DVector::from_fn(m, |i, _| dot(&a[i], 0));
            let lambda = s
                .clone()
                .cholesky()
                .map(|c| c.solve(&(-&ax)))
                .or_else(|| s.lu().solve(&(-&ax)))
                .ok_or(FactorError::SingularConstraints)?;
            for (i, d) in delta.iter_mut().enumerate() {
                let mut t = 0.0;
                for k in 0..m {
                    t += rhs[(i, 1 + k)] * lambda[k];
                }
                *d -= t;
            }
        }
        if delta.iter().any(|v| !v.is_finite()) {
            return Err(FactorError::NotPositiveDefinite);
        }
        Ok(delta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small SPD system with one constraint row against a dense solve of the full KKT matrix.
    #[test]
    fn kkt_solution_matches_dense() {
        let n = 6;
        let h = DMatrix::from_fn(n, n, |i, j| {
            if i == j {
                4.0 + i as f64
            } else if (i as i64 - j as i64).abs() == 1 {
                -1.0
            } else {
                0.0
            }
        });
        let lower: Vec<(usize, usize, f64)> = (0..n)
            .flat_map(|j| (j..n).map(move |i| (i, j)))
            .filter(|&(i, j)| h[(i, j)] != 0.0)
            .map(|(i, j)| (i, j, h[(i, j)]))
            .collect();
        let g: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let a = vec![vec![1.0; n], (0..n).map(|i| i as f64).collect::<Vec<_>>()];
        let mut solver = KktSolver::default();
        let d = solver.solve(n, &lower, 0.0, &g, &a).unwrap();
        let m = a.len();
        let mut k = DMatrix::zeros(n + m, n + m);
        k.view_mut((0, 0), (n, n)).copy_from(&h);
        for (r, row) in a.iter().enumerate() {
            for i in 0..n {
                k[(n + r, i)] = row[i];
                k[(i, n + r)] = row[i];
            }
        }
        let mut rhs = DVector::zeros(n + m);
        for i in 0..n {
            rhs[i] = -g[i];
        }
        let x = k.lu().solve(&rhs).unwrap();
        for i in 0..n {
            assert!((x[i] - d[i]).abs() < 1e-13, "{i}: {} vs {}", x[i], d[i]);
        }
        // the symbolic analysis is reused for the same structure
        solver.solve(n, &lower, 1.0, &g, &a).unwrap();
        assert_eq!(solver.analyses, 1);
        // an indefinite matrix is reported
        let bad: Vec<_> = lower
            .iter()
            .map(|&(i, j, v)| (i, j, if i == j { -v } else { v }))
            .collect();
        assert_eq!(
            solver.solve(n, &bad, 0.0, &g, &a),
            Err(FactorError::NotPositiveDefinite)
        );
    }
}
