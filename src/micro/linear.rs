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
        let mut out = self.solve_many(n, lower, mu, &[g.to_vec()], a)?;
        Ok(out.pop().expect("one right-hand side"))
    }

    /// [`solve`](Self::solve) for several right-hand sides with one factorisation: for each b returns
    /// δ = −(H + μI)⁻¹ (b + Aᵀλ) with A δ = 0, i.e. minus the constrained inverse applied to b.
    pub fn solve_many(
        &mut self,
        n: usize,
        lower: &[(usize, usize, f64)],
        mu: f64,
        rhs_list: &[Vec<f64>],
        a: &[Vec<f64>],
    ) -> Result<Vec<Vec<f64>>, FactorError> {
        self.solve_refined(n, lower, mu, rhs_list, a, 0)
    }

    /// [`solve_many`](Self::solve_many) followed by `refine` steps of iterative refinement against the
    /// unshifted H: δ ← δ + solve(b + H δ). Each step shrinks the error of the shift μ by about μ/λ on the
    /// constraint space (λ the smallest eigenvalue there), so the result tends to the exact constrained solve
    /// while the factorisation stays regularised (the exact rigid modes are removed by the constraints).
    pub fn solve_refined(
        &mut self,
        n: usize,
        lower: &[(usize, usize, f64)],
        mu: f64,
        rhs_list: &[Vec<f64>],
        a: &[Vec<f64>],
        refine: usize,
    ) -> Result<Vec<Vec<f64>>, FactorError> {
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
        let k = rhs_list.len();
        let m = a.len();
        let mut buf = MemBuffer::new(
            symbolic
                .factorize_numeric_llt_scratch::<f64>(par, Default::default())
                .or(symbolic.solve_in_place_scratch::<f64>(k.max(m).max(1), par)),
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
        let mut solve_cols = |cols: &[&[f64]]| -> Mat<f64> {
            let mut rhs = Mat::<f64>::from_fn(n, cols.len(), |i, j| cols[j][i]);
            llt.solve_in_place_with_conj(Conj::No, rhs.as_mut(), par, MemStack::new(&mut buf));
            rhs
        };
        // X_A = (H+μI)⁻¹ Aᵀ and the Schur complement S = A X_A
        let xa = solve_cols(&a.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
        let sinv = if m > 0 {
            let s = DMatrix::from_fn(m, m, |i, j| {
                (0..n).map(|q| a[i][q] * xa[(q, j)]).sum::<f64>()
            });
            Some(
                s.clone()
                    .cholesky()
                    .map(|c| c.inverse())
                    .or_else(|| s.try_inverse())
                    .ok_or(FactorError::SingularConstraints)?,
            )
        } else {
            None
        };
        // δ = −(x + X_A λ), x = (H+μI)⁻¹ b, λ = −S⁻¹ A x
        let mut apply = |cols: &[&[f64]]| -> Vec<Vec<f64>> {
            let x = solve_cols(cols);
            (0..cols.len())
                .map(|c| {
                    let mut delta: Vec<f64> = (0..n).map(|i| -x[(i, c)]).collect();
                    if let Some(sinv) = &sinv {
                        let ax = DVector::from_fn(m, |i, _| {
                            (0..n).map(|q| a[i][q] * x[(q, c)]).sum::<f64>()
                        });
                        let lambda = -(sinv * ax);
                        for (i, d) in delta.iter_mut().enumerate() {
                            let mut t = 0.0;
                            for q in 0..m {
                                t += xa[(i, q)] * lambda[q];
                            }
                            *d -= t;
                        }
                    }
                    delta
                })
                .collect()
        };
        let mut out = apply(&rhs_list.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
        for _ in 0..refine {
            // residual b + H δ with the unshifted symmetric H (lower triangle stored)
            let res: Vec<Vec<f64>> = out
                .iter()
                .zip(rhs_list)
                .map(|(d, b)| {
                    let mut r = b.clone();
                    for &(i, j, v) in lower {
                        r[i] += v * d[j];
                        if i != j {
                            r[j] += v * d[i];
                        }
                    }
                    r
                })
                .collect();
            let corr = apply(&res.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
            for (d, c) in out.iter_mut().zip(corr) {
                for (x, y) in d.iter_mut().zip(c) {
                    *x += y;
                }
            }
        }
        if out.iter().flatten().any(|v| !v.is_finite()) {
            return Err(FactorError::NotPositiveDefinite);
        }
        Ok(out)
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
