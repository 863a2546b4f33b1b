//! The factorisations of K = H + μI behind the KKT solve (`docs/micro-solver.md`, section 3).
//!
//! - [`Factorization::Cholesky`] (the default): sparse LLᵀ; it exists only when K is positive definite.
//! - [`Factorization::Inertia`]: sparse LDLᵀ without pivoting, accepted when the KKT matrix
//!   [K Aᵀ; A 0] has the inertia of a constrained minimum: exactly m negative and no zero eigenvalues (m
//!   constraint rows), i.e. K is positive definite on the null space of A, where the constrained Newton step
//!   is a descent step even where K is indefinite along the constraint rows (a yarn held back from sliding). By
//!   Haynsworth's inertia additivity, In([K Aᵀ; A 0]) = In(K) + In(−S) with S = A K⁻¹ Aᵀ, so the count is
//!   neg(D) + pos(S): D from the factor, S the m × m Schur complement the solve forms anyway.

use super::{FactorError, LowerPattern};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLdltRef;
use faer::sparse::linalg::cholesky::{LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::SparseColMatRef;
use faer::{Conj, MatMut, Par, Side};
use nalgebra::DMatrix;

/// Which factorisation of K = H + μI a [`KktSolver`](super::KktSolver) uses, and so which K it accepts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Factorization {
    /// LLᵀ: K positive definite.
    #[default]
    Cholesky,
    /// LDLᵀ with the inertia test: K positive definite on the null space of the constraint rows.
    Inertia,
}

/// A numeric factor of K.
pub(super) enum Factor<'a> {
    Llt(LltRef<'a, usize, f64>),
    /// With the number of negative pivots of D.
    Ldlt(LdltRef<'a, usize, f64>, usize),
}

impl<'a> Factor<'a> {
    /// K⁻¹ applied in place to the columns of `rhs`.
    pub(super) fn solve_in_place(&self, rhs: MatMut<'_, f64>, stack: &mut MemStack) {
        match self {
            Factor::Llt(f) => f.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack),
            Factor::Ldlt(f, _) => f.solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack),
        }
    }

    /// Whether the KKT matrix with the Schur complement `s` = A K⁻¹ Aᵀ has exactly m = dim s negative
    /// eigenvalues and no zero one (always true for LLᵀ, where K and so S are positive definite).
    pub(super) fn kkt_inertia_ok(&self, s: &DMatrix<f64>) -> bool {
        let Factor::Ldlt(_, negative) = self else {
            return true;
        };
        let m = s.nrows();
        if *negative > m {
            return false;
        }
        if m == 0 {
            return *negative == 0;
        }
        let eig = s.clone().symmetric_eigenvalues();
        let scale = eig.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        // a zero eigenvalue of S (to round-off) is a singular KKT matrix
        if eig.iter().any(|v| v.abs() <= 1e-14 * scale) {
            return false;
        }
        let positive = eig.iter().filter(|&&v| v > 0.0).count();
        negative + positive == m
    }
}

/// The numbers of negative and zero pivots (entries of D) of an LDLᵀ factor.
pub(super) fn pivot_signs(symbolic: &SymbolicCholesky<usize>, values: &[f64]) -> (usize, usize) {
    let mut d = Vec::with_capacity(symbolic.nrows());
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            // each column's first stored entry is its diagonal (D)
            let ptr = s.col_ptr();
            d.extend((0..symbolic.nrows()).map(|j| values[ptr[j]]));
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let f = SupernodalLdltRef::new(s, values);
            for k in 0..s.n_supernodes() {
                let block = f.supernode(k).val();
                d.extend((0..block.ncols()).map(|i| block[(i, i)]));
            }
        }
    }
    let negative = d.iter().filter(|&&v| v < 0.0).count();
    let zero = d.iter().filter(|&&v| v == 0.0 || !v.is_finite()).count();
    (negative, zero)
}

/// The factorisation and solve workspace for `cols` right-hand sides, allocated when the kept one is smaller.
pub(super) fn workspace<'a>(
    scratch: &'a mut Option<(usize, MemBuffer)>,
    symbolic: &SymbolicCholesky<usize>,
    cols: usize,
) -> &'a mut MemBuffer {
    if !matches!(scratch, Some((c, _)) if *c >= cols) {
        let req = symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()))
            .or(symbolic.solve_in_place_scratch::<f64>(cols, Par::Seq));
        *scratch = Some((cols, MemBuffer::new(req)));
    }
    &mut scratch.as_mut().expect("set above").1
}

/// The numeric factorisation of K = H + μI (`matrix` holds H in the pattern's value order; `values` receives
/// the factor), sequential and without dynamic regularisation: LLᵀ (an error unless K is positive definite) or
/// LDLᵀ (an error at a zero pivot; the inertia test follows in the solve).
pub(super) fn factorize_shifted<'a>(
    kind: Factorization,
    symbolic: &'a SymbolicCholesky<usize>,
    lower: &LowerPattern,
    matrix: &[f64],
    mu: f64,
    values: &'a mut Vec<f64>,
    buf: &mut MemBuffer,
) -> Result<Factor<'a>, FactorError> {
    let mut shifted = matrix.to_vec();
    for &s in &lower.diag {
        shifted[s] += mu;
    }
    let mat = SparseColMatRef::new(lower.symbolic(), &shifted);
    values.clear();
    values.resize(symbolic.len_val(), 0.0);
    match kind {
        Factorization::Cholesky => symbolic
            .factorize_numeric_llt(
                values,
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
            .map(Factor::Llt)
            .map_err(|_| FactorError::NotPositiveDefinite),
        Factorization::Inertia => {
            symbolic
                .factorize_numeric_ldlt(
                    values,
                    mat,
                    Side::Lower,
                    LdltRegularization::default(),
                    Par::Seq,
                    MemStack::new(buf),
                    Default::default(),
                )
                .map_err(|_| FactorError::NotPositiveDefinite)?;
            let (negative, zero) = pivot_signs(symbolic, values);
            if zero > 0 {
                return Err(FactorError::NotPositiveDefinite);
            }
            Ok(Factor::Ldlt(LdltRef::new(symbolic, values), negative))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::KktSolver;
    use super::*;
    use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams};
    use faer::sparse::linalg::SupernodalThreshold;
    use nalgebra::DVector;

    /// The lower-triangle triplets (row ≥ column) of the non-zero entries of a dense symmetric matrix.
    fn lower_triplets(h: &DMatrix<f64>) -> Vec<(usize, usize, f64)> {
        let n = h.nrows();
        (0..n)
            .flat_map(|j| (j..n).map(move |i| (i, j)))
            .filter(|&(i, j)| h[(i, j)] != 0.0)
            .map(|(i, j)| (i, j, h[(i, j)]))
            .collect()
    }

    /// The primal part x of the dense KKT solve [H Aᵀ; A 0] (x, λ) = (−b, 0).
    fn dense_kkt(h: &DMatrix<f64>, a: &[Vec<f64>], b: &[f64]) -> DVector<f64> {
        let (n, m) = (h.nrows(), a.len());
        let mut k = DMatrix::zeros(n + m, n + m);
        k.view_mut((0, 0), (n, n)).copy_from(h);
        for (r, row) in a.iter().enumerate() {
            for i in 0..n {
                k[(n + r, i)] = row[i];
                k[(i, n + r)] = row[i];
            }
        }
        let rhs = DVector::from_fn(n + m, |i, _| if i < n { -b[i] } else { 0.0 });
        k.lu().solve(&rhs).unwrap().rows(0, n).into_owned()
    }

    /// A banded symmetric 40 × 40 matrix (bandwidth 3) whose diagonal makes `negative` eigenvalues negative.
    fn banded(n: usize, negative: usize) -> DMatrix<f64> {
        let mut h = DMatrix::zeros(n, n);
        for i in 0..n {
            h[(i, i)] = if i % (n / negative.max(1)) == 1 && negative > 0 {
                -4.0
            } else {
                6.0 + (i as f64 * 0.7).sin()
            };
            for k in 1..=3 {
                if i + k < n {
                    let v = 0.3 * ((i * 7 + k) as f64).cos();
                    h[(i + k, i)] = v;
                    h[(i, i + k)] = v;
                }
            }
        }
        h
    }

    /// The pivot signs of LDLᵀ are the inertia of the matrix (Sylvester), read from simplicial and from supernodal
    /// factors alike.
    #[test]
    fn pivot_signs_count_the_negative_eigenvalues() {
        for negative in [0, 1, 3, 5] {
            let h = banded(40, negative);
            let expect = h
                .clone()
                .symmetric_eigenvalues()
                .iter()
                .filter(|&&v| v < 0.0)
                .count();
            assert_eq!(expect, negative, "the example's inertia");
            let cols: Vec<Vec<usize>> = (0..40)
                .map(|j| (j..40).filter(|&i| h[(i, j)] != 0.0).collect())
                .collect();
            let lower = LowerPattern::from_columns(cols);
            let mut matrix = vec![0.0; lower.nnz()];
            for j in 0..40 {
                for s in lower.col_ptr[j]..lower.col_ptr[j + 1] {
                    matrix[s] = h[(lower.row_idx[s], j)];
                }
            }
            for threshold in [
                SupernodalThreshold::FORCE_SIMPLICIAL,
                SupernodalThreshold::FORCE_SUPERNODAL,
            ] {
                let symbolic = factorize_symbolic_cholesky(
                    lower.symbolic(),
                    Side::Lower,
                    Default::default(),
                    CholeskySymbolicParams {
                        supernodal_flop_ratio_threshold: threshold,
                        ..Default::default()
                    },
                )
                .unwrap();
                let mut scratch = None;
                let buf = workspace(&mut scratch, &symbolic, 1);
                let mut values = Vec::new();
                let f = factorize_shifted(
                    Factorization::Inertia,
                    &symbolic,
                    &lower,
                    &matrix,
                    0.0,
                    &mut values,
                    buf,
                )
                .unwrap();
                let Factor::Ldlt(_, counted) = f else {
                    panic!("LDLᵀ asked for")
                };
                assert_eq!(counted, negative, "threshold {threshold:?}");
                let llt = factorize_shifted(
                    Factorization::Cholesky,
                    &symbolic,
                    &lower,
                    &matrix,
                    0.0,
                    &mut values,
                    buf,
                );
                assert_eq!(llt.is_ok(), negative == 0, "threshold {threshold:?}");
            }
        }
    }

    /// H = diag(−3, 2, 3, 4, 5) with two couplings is indefinite along e₀. With A = e₀ᵀ it is positive definite on
    /// the null space: Cholesky refuses μ = 0, the inertia test accepts it and the step is the dense KKT solve.
    /// With A = e₄ᵀ (negative curvature left in the null space) or without constraints the inertia test refuses
    /// too; on a positive definite H both factorisations give the same step.
    #[test]
    fn inertia_test_accepts_exactly_the_constrained_minima() {
        let mut h = DMatrix::from_diagonal(&DVector::from_vec(vec![-3.0, 2.0, 3.0, 4.0, 5.0]));
        h[(1, 2)] = 0.5;
        h[(2, 1)] = 0.5;
        h[(0, 3)] = 1.0;
        h[(3, 0)] = 1.0;
        let b: Vec<f64> = (0..5).map(|i| (i as f64 * 0.9).cos()).collect();
        let rhs = std::slice::from_ref(&b);
        let e = |k: usize| {
            (0..5)
                .map(|i| f64::from(u8::from(i == k)))
                .collect::<Vec<f64>>()
        };
        let (held, free) = (vec![e(0)], vec![e(4)]);
        let mut chol = KktSolver::with(Factorization::Cholesky);
        let mut inertia = KktSolver::with(Factorization::Inertia);
        chol.set_matrix(5, &lower_triplets(&h)).unwrap();
        inertia.set_matrix(5, &lower_triplets(&h)).unwrap();
        assert_eq!(
            chol.solve_shifted(0.0, rhs, &held, 0),
            Err(FactorError::NotPositiveDefinite)
        );
        let d = inertia
            .solve_shifted(0.0, rhs, &held, 0)
            .unwrap()
            .pop()
            .unwrap();
        let x = dense_kkt(&h, &held, &b);
        for i in 0..5 {
            assert!((x[i] - d[i]).abs() < 1e-12, "{i}: {} vs {}", x[i], d[i]);
        }
        assert!(
            d.iter().zip(&b).map(|(u, v)| u * v).sum::<f64>() < 0.0,
            "descent"
        );
        assert_eq!(
            inertia.solve_shifted(0.0, rhs, &free, 0),
            Err(FactorError::NotPositiveDefinite)
        );
        assert_eq!(
            inertia.solve_shifted(0.0, rhs, &[], 0),
            Err(FactorError::NotPositiveDefinite)
        );
        // shifted into positive definiteness, both agree
        let a = chol
            .solve_shifted(3.5, rhs, &free, 0)
            .unwrap()
            .pop()
            .unwrap();
        let c = inertia
            .solve_shifted(3.5, rhs, &free, 0)
            .unwrap()
            .pop()
            .unwrap();
        for i in 0..5 {
            assert!((a[i] - c[i]).abs() < 1e-13 * a[i].abs().max(1.0), "{i}");
        }
    }
}
