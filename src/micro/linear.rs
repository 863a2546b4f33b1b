//! The constrained Newton system (`docs/micro-solver.md`, section 3):
//!
//! [ H + μ I   Aᵀ ] [ δy ]   [ −g ]
//! [ A          0 ] [ λ  ] = [  0 ]
//!
//! solved by one sparse Cholesky factorisation of H + μ I (faer, sequential so that results do not depend on
//! the thread count; the lower-triangle pattern is a [`LowerPattern`] and its symbolic analysis is kept and reused
//! while the sparsity structure is unchanged) and the Schur complement S = A (H + μI)⁻¹ Aᵀ of the few dense
//! constraint rows.

use crate::sparse::LowerPattern;
pub use factor::Factorization;
use factor::{factorize_shifted, workspace, Factor};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymbolicCholesky};
use faer::{Mat, Side};
use nalgebra::{DMatrix, DVector};

mod factor;

/// Why a factorisation could not be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FactorError {
    /// H + μI is not numerically positive definite.
    #[error("the shifted Newton matrix H + μI is not positive definite")]
    NotPositiveDefinite,
    /// The Schur complement of the constraints is singular (dependent constraint rows).
    #[error("the constraint rows are dependent (singular Schur complement)")]
    SingularConstraints,
    /// Anything else faer reports (out of memory, index overflow), or a misuse (an entry outside the lower
    /// triangle, a solve before the matrix is set).
    #[error("{0}")]
    Other(String),
}

/// Patterns up to this order keep a dense n×n slot table (4 bytes per entry); larger ones search each column.
const DENSE_SLOTS_MAX: usize = 3000;

/// The lower-triangle pattern the solver factorises ([`LowerPattern`]) with a fast lookup of each entry's value
/// slot. It only grows within one solver's life, so a matrix whose entries it covers reuses the symbolic
/// analysis.
struct SlotPattern {
    lower: LowerPattern,
    /// slot + 1 of entry (i, j) at i + n j (0: not in the pattern), for n ≤ [`DENSE_SLOTS_MAX`]
    slots: Vec<u32>,
}

impl SlotPattern {
    /// The pattern with the columns `cols` (row lists, unsorted, duplicates allowed) plus the diagonal; the slot
    /// table of `old` (a pattern this one replaces) is reused, only its entries cleared.
    fn new(cols: Vec<Vec<usize>>, old: Option<SlotPattern>) -> Self {
        let lower = LowerPattern::from_columns(cols);
        let n = lower.n;
        let mut slots = Vec::new();
        if n <= DENSE_SLOTS_MAX {
            match old {
                Some(o) if o.lower.n == n && o.slots.len() == n * n => {
                    slots = o.slots;
                    for j in 0..n {
                        for &i in o.lower.rows(j) {
                            slots[i + n * j] = 0;
                        }
                    }
                }
                _ => slots = vec![0u32; n * n],
            }
            for j in 0..n {
                for s in lower.col_ptr[j]..lower.col_ptr[j + 1] {
                    slots[lower.row_idx[s] + n * j] = s as u32 + 1;
                }
            }
        }
        Self { lower, slots }
    }

    /// The value slot of entry (i, j), if the pattern has it.
    fn slot(&self, i: usize, j: usize) -> Option<usize> {
        if self.slots.is_empty() {
            self.lower.find(i, j)
        } else {
            (self.slots[i + self.lower.n * j] as usize).checked_sub(1)
        }
    }
}

/// A sparse Cholesky solver that keeps its matrix pattern and symbolic analysis across factorisations. The
/// pattern is the union of every matrix set since the solver was created (entries missing from a new matrix are
/// explicit zeros), so contact pairs that come and go cost a symbolic analysis only the first time their blocks
/// appear.
#[derive(Default)]
pub struct KktSolver {
    pattern: Option<(SlotPattern, SymbolicCholesky<usize>)>,
    /// H in the pattern's value order (duplicates summed), without the shift
    matrix: Vec<f64>,
    values: Vec<f64>,
    /// factorisation and solve workspace for up to this many right-hand sides (reset with the pattern)
    scratch: Option<(usize, MemBuffer)>,
    /// Number of symbolic analyses performed (for the performance report).
    pub analyses: usize,
    /// Which factorisation of H + μI is used (and so which shifted matrices are accepted).
    pub factorization: Factorization,
}

impl KktSolver {
    /// A solver that factorises with `factorization`.
    pub fn with(factorization: Factorization) -> Self {
        KktSolver {
            factorization,
            ..Default::default()
        }
    }

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

    /// [`set_matrix`](Self::set_matrix) and [`solve_shifted`](Self::solve_shifted) in one call.
    pub fn solve_refined(
        &mut self,
        n: usize,
        lower: &[(usize, usize, f64)],
        mu: f64,
        rhs_list: &[Vec<f64>],
        a: &[Vec<f64>],
        refine: usize,
    ) -> Result<Vec<Vec<f64>>, FactorError> {
        self.set_matrix(n, lower)?;
        self.solve_shifted(mu, rhs_list, a, refine)
    }

    /// Store H from its lower-triangle triplets (duplicates summed). The pattern grows (and the symbolic analysis
    /// is redone) only when `lower` has an entry it lacks, or when n changes.
    pub fn set_matrix(
        &mut self,
        n: usize,
        lower: &[(usize, usize, f64)],
    ) -> Result<(), FactorError> {
        if let Some(&(i, j, _)) = lower.iter().find(|t| t.0 >= n || t.1 > t.0) {
            return Err(FactorError::Other(format!(
                "entry ({i}, {j}) is not in the lower triangle of a {n}×{n} matrix"
            )));
        }
        // entries the current pattern lacks (all of them when there is none)
        let mut missing: Vec<(usize, usize)> = Vec::new();
        let mut cols = match &self.pattern {
            Some((p, _)) if p.lower.n == n => {
                self.matrix.clear();
                self.matrix.resize(p.lower.nnz(), 0.0);
                for &(i, j, v) in lower {
                    match p.slot(i, j) {
                        Some(s) => self.matrix[s] += v,
                        None => missing.push((i, j)),
                    }
                }
                if missing.is_empty() {
                    return Ok(());
                }
                p.lower.columns()
            }
            _ => {
                missing.extend(lower.iter().map(|&(i, j, _)| (i, j)));
                vec![Vec::new(); n]
            }
        };
        for (i, j) in missing {
            cols[j].push(i);
        }
        let pattern = SlotPattern::new(cols, self.pattern.take().map(|(p, _)| p));
        let symbolic = factorize_symbolic_cholesky(
            pattern.lower.symbolic(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .map_err(|e| FactorError::Other(format!("{e:?}")))?;
        self.analyses += 1;
        self.scratch = None;
        self.matrix.clear();
        self.matrix.resize(pattern.lower.nnz(), 0.0);
        for &(i, j, v) in lower {
            self.matrix[pattern
                .slot(i, j)
                .expect("pattern built from these entries")] += v;
        }
        self.pattern = Some((pattern, symbolic));
        Ok(())
    }

    /// Solve with the stored H (see [`set_matrix`](Self::set_matrix)) shifted by `mu`, followed by `refine` steps
    /// of iterative refinement against the unshifted H: δ ← δ + solve(b + H δ). Each step shrinks the error of
    /// the shift μ by about μ/λ on the constraint space (λ the smallest eigenvalue there), so the result tends to
    /// the exact constrained solve while the factorisation stays regularised (the exact rigid modes are removed
    /// by the constraints).
    pub fn solve_shifted(
        &mut self,
        mu: f64,
        rhs_list: &[Vec<f64>],
        a: &[Vec<f64>],
        refine: usize,
    ) -> Result<Vec<Vec<f64>>, FactorError> {
        let Some((pattern, symbolic)) = self.pattern.as_ref() else {
            return Err(FactorError::Other("solve before set_matrix".into()));
        };
        let lower = &pattern.lower;
        let cols = rhs_list.len().max(a.len()).max(1);
        let buf = workspace(&mut self.scratch, symbolic, cols);
        let llt = factorize_shifted(
            self.factorization,
            symbolic,
            lower,
            &self.matrix,
            mu,
            &mut self.values,
            buf,
        )?;
        let mut solver = ConstrainedSolve::new(llt, buf, lower.n, a)?;
        let mut out = solver.apply(&as_slices(rhs_list));
        for _ in 0..refine {
            // residual b + H δ with the unshifted symmetric H (lower triangle stored)
            let res: Vec<Vec<f64>> = out
                .iter()
                .zip(rhs_list)
                .map(|(d, b)| {
                    let mut r = b.clone();
                    lower.add_symmetric_product(&self.matrix, d, &mut r);
                    r
                })
                .collect();
            let corr = solver.apply(&as_slices(&res));
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

    /// δ with H δ + Aᵀλ = −b, A δ = 0 for each b in `rhs_list` when H is positive definite only on the null space
    /// of A (a constrained equilibrium whose constraints hold back a mode of negative curvature, e.g. a yarn that
    /// would slide): projected preconditioned conjugate gradients on the null space, preconditioned with the
    /// constrained solve of H + μI (μ from `mu`, grown ×10 until it factorises), until √(rᵀz) ≤ `tol` times its
    /// start value. An error when a search direction has pᵀHp ≤ 0 (H is not positive definite on the null space)
    /// or after `max_iter` iterations.
    pub fn solve_projected(
        &mut self,
        mu: f64,
        rhs_list: &[Vec<f64>],
        a: &[Vec<f64>],
        tol: f64,
        max_iter: usize,
    ) -> Result<Vec<Vec<f64>>, FactorError> {
        let Some((pattern, symbolic)) = self.pattern.as_ref() else {
            return Err(FactorError::Other("solve before set_matrix".into()));
        };
        let lower = &pattern.lower;
        let n = lower.n;
        let cols = a.len().max(1);
        let buf = workspace(&mut self.scratch, symbolic, cols);
        let mut mu = mu.max(f64::MIN_POSITIVE);
        let mut tries = 0;
        while factorize_shifted(
            self.factorization,
            symbolic,
            lower,
            &self.matrix,
            mu,
            &mut self.values,
            buf,
        )
        .is_err()
        {
            mu *= 10.0;
            tries += 1;
            if tries > 40 {
                return Err(FactorError::NotPositiveDefinite);
            }
        }
        let llt = factorize_shifted(
            self.factorization,
            symbolic,
            lower,
            &self.matrix,
            mu,
            &mut self.values,
            buf,
        )?;
        let mut solver = ConstrainedSolve::new(llt, buf, n, a)?;
        rhs_list
            .iter()
            .map(|b| projected_cg(&mut solver, lower, &self.matrix, b, tol, max_iter))
            .collect()
    }
}

/// Projected preconditioned conjugate gradients for H x + Aᵀλ = −b, A x = 0 (`lower`, `matrix`: H), the
/// preconditioner the constrained solve `solver` of H + μI, until √(rᵀz) ≤ `tol` times its start value; an error
/// when a search direction has pᵀHp ≤ 0 or after `max_iter` iterations.
fn projected_cg(
    solver: &mut ConstrainedSolve,
    lower: &LowerPattern,
    matrix: &[f64],
    b: &[f64],
    tol: f64,
    max_iter: usize,
) -> Result<Vec<f64>, FactorError> {
    let n = lower.n;
    let mut x = vec![0.0; n];
    let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
    let mut z = solver.precondition(&r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let rz0 = rz;
    let mut converged = rz0 <= 0.0;
    for _ in 0..max_iter {
        if rz <= tol * tol * rz0 {
            converged = true;
            break;
        }
        let mut hp = vec![0.0; n];
        lower.add_symmetric_product(matrix, &p, &mut hp);
        let php = dot(&p, &hp);
        if php.is_nan() || php <= 0.0 {
            return Err(FactorError::NotPositiveDefinite);
        }
        let alpha = rz / php;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * hp[i];
        }
        z = solver.precondition(&r);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
        rz = rz_new;
    }
    if !converged && rz > tol * tol * rz0 {
        return Err(FactorError::Other(format!(
            "projected conjugate gradients did not reach {tol:.0e} in {max_iter} iterations"
        )));
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(FactorError::NotPositiveDefinite);
    }
    Ok(x)
}

/// The rows of a list of vectors as slices.
fn as_slices(rows: &[Vec<f64>]) -> Vec<&[f64]> {
    rows.iter().map(|r| r.as_slice()).collect()
}

/// Solves with the factorised K = H + μI on the constraint space A δ = 0 by the Schur complement of the
/// constraint rows: X_A = K⁻¹ Aᵀ, S = A X_A, and for each right-hand side b, δ = −(x + X_A λ) with x = K⁻¹ b and
/// λ = −S⁻¹ A x.
struct ConstrainedSolve<'a> {
    llt: Factor<'a>,
    buf: &'a mut MemBuffer,
    n: usize,
    a: &'a [Vec<f64>],
    /// X_A = K⁻¹ Aᵀ (n × m)
    xa: Mat<f64>,
    /// S⁻¹ (none without constraint rows)
    sinv: Option<DMatrix<f64>>,
}

impl<'a> ConstrainedSolve<'a> {
    /// z = M_A⁻¹ r of the projected conjugate gradients: M z + Aᵀλ = r, A z = 0 ([`ConstrainedSolve::apply`]
    /// returns the negative).
    fn precondition(&mut self, r: &[f64]) -> Vec<f64> {
        self.apply(&[r])
            .pop()
            .expect("one column")
            .into_iter()
            .map(|v| -v)
            .collect()
    }

    /// X_A and S⁻¹ for the constraint rows `a`; an error when S is singular.
    fn new(
        llt: Factor<'a>,
        buf: &'a mut MemBuffer,
        n: usize,
        a: &'a [Vec<f64>],
    ) -> Result<Self, FactorError> {
        let m = a.len();
        let xa = solve_columns(&llt, buf, n, &as_slices(a));
        let sinv = if m > 0 {
            let s = DMatrix::from_fn(m, m, |i, j| {
                (0..n).map(|q| a[i][q] * xa[(q, j)]).sum::<f64>()
            });
            if !llt.kkt_inertia_ok(&s) {
                return Err(FactorError::NotPositiveDefinite);
            }
            Some(
                s.clone()
                    .cholesky()
                    .map(|c| c.inverse())
                    .or_else(|| s.try_inverse())
                    .ok_or(FactorError::SingularConstraints)?,
            )
        } else {
            if !llt.kkt_inertia_ok(&DMatrix::zeros(0, 0)) {
                return Err(FactorError::NotPositiveDefinite);
            }
            None
        };
        Ok(ConstrainedSolve {
            llt,
            buf,
            n,
            a,
            xa,
            sinv,
        })
    }

    /// δ = −(x + X_A λ), x = K⁻¹ b, λ = −S⁻¹ A x for each column b of `cols`.
    fn apply(&mut self, cols: &[&[f64]]) -> Vec<Vec<f64>> {
        let (n, m, a) = (self.n, self.a.len(), self.a);
        let x = solve_columns(&self.llt, self.buf, n, cols);
        (0..cols.len())
            .map(|c| {
                let mut delta: Vec<f64> = (0..n).map(|i| -x[(i, c)]).collect();
                if let Some(sinv) = &self.sinv {
                    let ax = DVector::from_fn(m, |i, _| {
                        (0..n).map(|q| a[i][q] * x[(q, c)]).sum::<f64>()
                    });
                    let lambda = -(sinv * ax);
                    for (i, d) in delta.iter_mut().enumerate() {
                        let mut t = 0.0;
                        for q in 0..m {
                            t += self.xa[(i, q)] * lambda[q];
                        }
                        *d -= t;
                    }
                }
                delta
            })
            .collect()
    }
}

/// uᵀv.
fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(x, y)| x * y).sum()
}

/// K⁻¹ applied to the columns `cols` (each of length n), as an n × cols matrix.
fn solve_columns(llt: &Factor<'_>, buf: &mut MemBuffer, n: usize, cols: &[&[f64]]) -> Mat<f64> {
    let mut rhs = Mat::<f64>::from_fn(n, cols.len(), |i, j| cols[j][i]);
    llt.solve_in_place(rhs.as_mut(), MemStack::new(buf));
    rhs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower-triangle triplets (row ≥ column) of the non-zero entries of a dense symmetric matrix.
    fn lower_triplets(h: &DMatrix<f64>) -> Vec<(usize, usize, f64)> {
        let n = h.nrows();
        (0..n)
            .flat_map(|j| (j..n).map(move |i| (i, j)))
            .filter(|&(i, j)| h[(i, j)] != 0.0)
            .map(|(i, j)| (i, j, h[(i, j)]))
            .collect()
    }

    /// diag(−3, 2, 3, 4, 5) with two couplings (indefinite; e₀ carries the negative curvature) and a right-hand
    /// side.
    fn indefinite_example() -> (DMatrix<f64>, Vec<f64>) {
        let mut h = DMatrix::from_diagonal(&DVector::from_vec(vec![-3.0, 2.0, 3.0, 4.0, 5.0]));
        h[(1, 2)] = 0.5;
        h[(2, 1)] = 0.5;
        h[(0, 3)] = 1.0;
        h[(3, 0)] = 1.0;
        let b = (0..5).map(|i| (i as f64 * 0.9).cos()).collect();
        (h, b)
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
        k.lu().solve(&rhs).unwrap()
    }

    /// H indefinite in the full space but positive definite on the null space of A: the shifted factorisation
    /// fails at μ = 0, and the projected conjugate gradients agree with a dense solve of the KKT matrix.
    #[test]
    fn projected_solve_matches_dense_for_an_indefinite_h() {
        let n = 5;
        // A = e₀ᵀ removes the negative direction
        let (h, b) = indefinite_example();
        let lower = lower_triplets(&h);
        let a = vec![vec![1.0, 0.0, 0.0, 0.0, 0.0]];
        let mut solver = KktSolver::default();
        solver.set_matrix(n, &lower).unwrap();
        assert_eq!(
            solver.solve_shifted(0.0, std::slice::from_ref(&b), &a, 0),
            Err(FactorError::NotPositiveDefinite)
        );
        let d = solver
            .solve_projected(1e-10, std::slice::from_ref(&b), &a, 1e-14, 100)
            .unwrap()
            .pop()
            .unwrap();
        let x = dense_kkt(&h, &a, &b);
        for i in 0..n {
            assert!((x[i] - d[i]).abs() < 1e-12, "{i}: {} vs {}", x[i], d[i]);
        }
        // negative curvature on the null space is refused
        let a_wrong = vec![vec![0.0, 0.0, 0.0, 0.0, 1.0]];
        assert!(solver
            .solve_projected(1e-10, std::slice::from_ref(&b), &a_wrong, 1e-14, 100)
            .is_err());
    }

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
        let lower = lower_triplets(&h);
        let g: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let a = vec![vec![1.0; n], (0..n).map(|i| i as f64).collect::<Vec<_>>()];
        let mut solver = KktSolver::default();
        let d = solver.solve(n, &lower, 0.0, &g, &a).unwrap();
        let x = dense_kkt(&h, &a, &g);
        for i in 0..n {
            assert!((x[i] - d[i]).abs() < 1e-13, "{i}: {} vs {}", x[i], d[i]);
        }
        // the symbolic analysis is reused for the same structure
        solver.solve(n, &lower, 1.0, &g, &a).unwrap();
        assert_eq!(solver.analyses, 1);
        // and for a matrix with fewer entries (the missing ones are explicit zeros of the kept pattern)
        let tridiag_less: Vec<_> = lower
            .iter()
            .copied()
            .filter(|&(i, j, _)| !(i == 3 && j == 2))
            .collect();
        let d_less = solver.solve(n, &tridiag_less, 0.0, &g, &a).unwrap();
        assert_eq!(solver.analyses, 1);
        // a new entry grows the pattern once; the solve agrees with a fresh solver's
        let mut more = tridiag_less.clone();
        more.push((5, 0, 0.5));
        let d_more = solver.solve(n, &more, 0.0, &g, &a).unwrap();
        assert_eq!(solver.analyses, 2);
        solver.solve(n, &more, 0.0, &g, &a).unwrap();
        assert_eq!(solver.analyses, 2);
        for (m, want) in [(&tridiag_less, &d_less), (&more, &d_more)] {
            let fresh = KktSolver::default().solve(n, m, 0.0, &g, &a).unwrap();
            for i in 0..n {
                assert!(
                    (fresh[i] - want[i]).abs() < 1e-13,
                    "{i}: {} vs {}",
                    fresh[i],
                    want[i]
                );
            }
        }
        // upper-triangle entries are refused with the entry named
        let err = KktSolver::default()
            .solve(n, &[(0, 1, 1.0)], 0.0, &g, &a)
            .unwrap_err();
        assert!(
            matches!(&err, FactorError::Other(m) if m.contains("(0, 1)")),
            "{err:?}"
        );
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
