//! The Newton system of a step (`docs/cloth-simulator.md`, "The cloth solver"): the exact Hessian first, the PSD option's
//! Hessian when it is not positive definite, a growing diagonal shift as the last resort; faer's sparse
//! Cholesky with the simulation's symbolic analysis, numeric factorisation and solve run sequentially (on this
//! 2-core machine faer's parallel supernodal factorisation spent more time handing work between threads than it
//! saved: `basket_stretchX` took 1.5× longer with two threads than with one, the factorisation of the Newton
//! benchmark's systems 1.3–2× longer, `docs/notes/newton-ordering.md`). The fill-reducing ordering of the symbolic
//! analysis is chosen in [`ordering`](super::ordering).

use super::ordering::{dof_permutation, nested_dissection, vertex_adjacency, FillOrdering};
use super::Simulation;
use crate::shell::assemble::Pattern;
use crate::shell::ShellError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::SparseColMatRef;
use faer::{Conj, Par, Side};

/// The symbolic Cholesky analysis of the free-dof matrix of `pattern` under the fill-reducing `ordering`; `x`
/// holds the positions (3 per mesh vertex) that the nested dissection splits.
pub(super) fn symbolic_analysis(
    pattern: &Pattern,
    x: &[f64],
    ordering: FillOrdering,
) -> Result<SymbolicCholesky<usize>, ShellError> {
    let (fwd, inv);
    let ord = match ordering {
        FillOrdering::Auto => {
            let amd = symbolic_analysis(pattern, x, FillOrdering::Amd)?;
            let nd = symbolic_analysis(pattern, x, FillOrdering::NestedDissection)?;
            return Ok(if factor_flops(&nd) <= factor_flops(&amd) {
                nd
            } else {
                amd
            });
        }
        FillOrdering::Amd => SymmetricOrdering::Amd,
        FillOrdering::NestedDissection => {
            let mut pos = vec![[0.0; 3]; pattern.nfree];
            for (v, k) in pattern.free.iter().enumerate() {
                if let Some(k) = *k {
                    pos[k] = [x[3 * v], x[3 * v + 1], x[3 * v + 2]];
                }
            }
            let order = nested_dissection(&vertex_adjacency(&pattern.lower), &pos);
            (fwd, inv) = dof_permutation(&order);
            SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(&fwd, &inv, fwd.len()))
        }
    };
    factorize_symbolic_cholesky(
        pattern.lower.symbolic(),
        Side::Lower,
        ord,
        Default::default(),
    )
    .map_err(|source| ShellError::Symbolic { source })
}

/// The floating-point operations of a numeric Cholesky factorisation with the symbolic analysis `sym`: per
/// simplicial column with c entries c²; per supernode of c columns and r rows below them, the dense Cholesky of
/// its diagonal block (c³/3), the triangular solve of the rows below (r c²) and their update of the later
/// columns (r² c).
fn factor_flops(sym: &SymbolicCholesky<usize>) -> f64 {
    match sym.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => s
            .col_ptr()
            .windows(2)
            .map(|w| ((w[1] - w[0]) as f64).powi(2))
            .sum(),
        SymbolicCholeskyRaw::Supernodal(s) => (0..s.n_supernodes())
            .map(|k| {
                let c = (s.supernode_end()[k] - s.supernode_begin()[k]) as f64;
                let r = s.supernode(k).pattern().len() as f64;
                c * c * c / 3.0 + r * c * c + r * r * c
            })
            .sum(),
    }
}

impl Simulation {
    /// Redo the symbolic analysis of the Newton system with another fill-reducing ordering (the nested
    /// dissection splits the initial positions).
    pub fn set_fill_ordering(&mut self, ordering: FillOrdering) -> Result<(), ShellError> {
        self.symbolic = symbolic_analysis(&self.pattern, &self.x0, ordering)?;
        Ok(())
    }

    /// The number of values the Cholesky factor stores (with the supernodal factorisation: its dense blocks)
    /// and the floating-point operations of its numeric factorisation (multiplications and additions, the
    /// supernodes' stored zeros included).
    pub fn factor_cost(&self) -> (usize, f64) {
        (self.symbolic.len_val(), factor_flops(&self.symbolic))
    }

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

#[cfg(test)]
mod tests {
    use super::super::{Boundary, FillOrdering, Settings, Simulation};
    use crate::material::synthetic::default_material;
    use crate::shell::{ElementModel, Mesh, ModelFlags, Psd};

    /// A rippled 30 cm square (the Newton benchmark's state, `benches/shell.rs`) with `cells` squares a side,
    /// its vertices moved randomly by `perturb` edges, the left side pinned.
    fn rippled(cells: usize, perturb: f64) -> Simulation {
        let mesh = Mesh::rectangle(0.3, 0.3, 0.3 / cells as f64, perturb, 3).unwrap();
        let stencils = mesh.stencils(0.0).unwrap();
        let x0: Vec<[f64; 3]> = mesh
            .rest
            .iter()
            .map(|p| {
                let z = 0.01 * (20.0 * p[0]).sin() * (15.0 * p[1]).cos();
                [1.03 * p[0], 0.99 * p[1], z]
            })
            .collect();
        let pinned = (0..x0.len()).filter(|&v| mesh.rest[v][0] < 1e-9).collect();
        let model = ElementModel::new(&default_material(), &ModelFlags::default(), Psd::Full);
        let boundary = Boundary {
            pinned,
            ..Boundary::default()
        };
        Simulation::new(model, stencils, x0, boundary, Settings::default(), 1.0).unwrap()
    }

    /// ‖H d + g‖∞ / (‖H‖∞ ‖d‖∞ + ‖g‖∞) for the symmetric H with the lower-triangle `values`.
    fn backward_error(sim: &Simulation, values: &[f64], d: &[f64], g: &[f64]) -> f64 {
        let lower = &sim.pattern.lower;
        let mut r = g.to_vec();
        lower.add_symmetric_product(values, d, &mut r);
        let abs: Vec<f64> = values.iter().map(|v| v.abs()).collect();
        let mut rows = vec![0.0; g.len()];
        lower.add_symmetric_product(&abs, &vec![1.0; g.len()], &mut rows);
        let inf = |v: &[f64]| v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        inf(&r) / (inf(&rows) * inf(d) + inf(g))
    }

    /// With every ordering, on a regular and a perturbed mesh, the factorisation solves the Newton system of the
    /// PSD Hessian to round-off (backward error ≤ 1e-14) and the directions agree to 1e-9 relative; the
    /// automatic choice is the ordering with fewer operations.
    #[test]
    fn every_ordering_solves_the_newton_system() {
        for perturb in [0.0, 0.3] {
            let mut sim = rippled(24, perturb);
            let (asm, gf) = sim.newton_system().unwrap();
            let mut dirs = vec![];
            let mut flops = vec![];
            for ordering in [
                FillOrdering::Amd,
                FillOrdering::NestedDissection,
                FillOrdering::Auto,
            ] {
                sim.set_fill_ordering(ordering).unwrap();
                flops.push(sim.factor_cost().1);
                let d = sim
                    .factor_solve(&asm.values, &gf)
                    .expect("PSD Hessian factorises");
                let err = backward_error(&sim, &asm.values, &d, &gf);
                assert!(
                    err <= 1e-14,
                    "{ordering:?}, perturb {perturb}: backward error {err:e}"
                );
                dirs.push(d);
            }
            let scale = dirs[0].iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for d in &dirs[1..] {
                for (a, b) in d.iter().zip(&dirs[0]) {
                    assert!((a - b).abs() <= 1e-9 * scale, "{a} vs {b}");
                }
            }
            assert_eq!(
                flops[2],
                flops[0].min(flops[1]),
                "perturb {perturb}: {flops:?}"
            );
        }
    }

    /// The operation count of a dense matrix's factor is the dense Cholesky's, n³/3 + O(n²): one square of two
    /// triangles with one vertex pinned couples every free dof with every other (n = 9).
    #[test]
    fn operation_count_of_a_dense_factor() {
        let mesh = Mesh::rectangle(0.1, 0.1, 0.1, 0.0, 1).unwrap();
        let stencils = mesh.stencils(0.0).unwrap();
        let model = ElementModel::new(&default_material(), &ModelFlags::default(), Psd::Full);
        let boundary = Boundary {
            pinned: vec![0],
            ..Boundary::default()
        };
        let x0 = mesh.rest.iter().map(|p| [p[0], p[1], 0.0]).collect();
        let mut sim =
            Simulation::new(model, stencils, x0, boundary, Settings::default(), 1.0).unwrap();
        let n = (3 * sim.pattern.nfree) as f64;
        assert_eq!(n, 9.0);
        assert_eq!(
            sim.pattern.nnz() as f64,
            n * (n + 1.0) / 2.0,
            "a dense pattern"
        );
        for ordering in [FillOrdering::Amd, FillOrdering::NestedDissection] {
            sim.set_fill_ordering(ordering).unwrap();
            let (len, flops) = sim.factor_cost();
            assert!(
                len as f64 >= n * (n + 1.0) / 2.0,
                "{ordering:?}: {len} values"
            );
            assert!(
                flops >= n * n * n / 3.0 && flops <= n * n * n / 3.0 + n * n,
                "{ordering:?}: {flops} operations for n = {n}"
            );
        }
    }
}
