//! The fill-reducing ordering of the Newton system's sparse Cholesky (`docs/cloth-simulator.md`, "The cloth
//! solver"). The system couples the three dofs of every free vertex with those of every vertex it shares a
//! stencil with (a triangle and its flaps), so the ordering is computed on the free vertices and each vertex k is
//! expanded to the dofs 3k, 3k + 1, 3k + 2.
//!
//! [`FillOrdering::NestedDissection`] is a geometric nested dissection: the vertices are split at the median of
//! their initial positions along the axis of largest extent, the vertices of the lower half with a neighbour in
//! the upper half form the separator, both halves are ordered recursively and the separator last; parts of at
//! most [`LEAF`] vertices keep their order. [`FillOrdering::Amd`] is faer's approximate minimum degree on the dof
//! graph. Neither wins on every mesh: on the benchmark's squares (`benches/shell.rs`) the nested dissection's
//! factorisation needs 10–25 % fewer operations at 4 000–16 000 triangles, 2 % fewer at 64 000 and 18 % more at
//! 1 000, and a geometric split of a folded initial state can be poor. [`FillOrdering::Auto`] (the default)
//! therefore analyses both and keeps the one whose factorisation needs fewer operations; the analysis runs once
//! per simulation and costs a fraction of one factorisation.

use crate::sparse::LowerPattern;

/// Which fill-reducing ordering the symbolic Cholesky analysis uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FillOrdering {
    /// faer's approximate minimum degree on the dof graph
    Amd,
    /// geometric nested dissection on the free vertices (module documentation)
    NestedDissection,
    /// both, keeping the one whose numeric factorisation needs fewer operations
    #[default]
    Auto,
}

/// Parts of at most this many vertices are not split further.
pub const LEAF: usize = 16;

/// The free vertices' adjacency from the dof pattern `lower` (3 dofs per vertex, blocks stored whole): the
/// neighbours of every vertex other than itself, sorted.
pub fn vertex_adjacency(lower: &LowerPattern) -> Vec<Vec<usize>> {
    let nv = lower.n / 3;
    let mut adj = vec![Vec::new(); nv];
    for kb in 0..nv {
        for &r in lower.rows(3 * kb) {
            let ka = r / 3;
            if ka != kb && r % 3 == 0 {
                adj[kb].push(ka);
                adj[ka].push(kb);
            }
        }
    }
    for l in &mut adj {
        l.sort_unstable();
        l.dedup();
    }
    adj
}

/// The nested-dissection order of the vertices of the graph `adj` at the positions `pos`: `order[i]` is the
/// vertex eliminated i-th.
pub fn nested_dissection(adj: &[Vec<usize>], pos: &[[f64; 3]]) -> Vec<usize> {
    assert_eq!(adj.len(), pos.len(), "one position per vertex");
    let mut verts: Vec<usize> = (0..adj.len()).collect();
    let mut side = vec![Side::Out; adj.len()];
    let mut order = Vec::with_capacity(adj.len());
    dissect(&mut verts, adj, pos, &mut side, &mut order);
    order
}

/// Where a vertex lies in the split being made.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    Out,
    Lower,
    Upper,
}

/// Append the nested-dissection order of `verts` (a part of the graph) to `order`; `side` is `Out` for every
/// vertex on entry and on return.
fn dissect(
    verts: &mut [usize],
    adj: &[Vec<usize>],
    pos: &[[f64; 3]],
    side: &mut [Side],
    order: &mut Vec<usize>,
) {
    if verts.len() <= LEAF {
        order.extend_from_slice(verts);
        return;
    }
    let (kept, mid) = split(verts, adj, pos, side);
    let separator: Vec<usize> = verts[kept..mid].to_vec();
    let (lower, rest) = verts.split_at_mut(kept);
    dissect(lower, adj, pos, side, order);
    dissect(&mut rest[mid - kept..], adj, pos, side, order);
    order.extend_from_slice(&separator);
}

/// Split `verts` (at least two) at the median along the axis of largest extent and rearrange them as
/// `[lower half | separator | upper half]`, returning the ends `(kept, mid)` of the first two parts: no vertex of
/// `verts[..kept]` is adjacent to one of `verts[mid..]`. `side` is `Out` for every vertex on entry and on return.
fn split(
    verts: &mut [usize],
    adj: &[Vec<usize>],
    pos: &[[f64; 3]],
    side: &mut [Side],
) -> (usize, usize) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &v in verts.iter() {
        for c in 0..3 {
            lo[c] = lo[c].min(pos[v][c]);
            hi[c] = hi[c].max(pos[v][c]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .expect("three axes");
    let mid = verts.len() / 2;
    // the median along the axis, ties broken by the vertex index so that the split is deterministic
    verts.select_nth_unstable_by(mid, |&a, &b| {
        pos[a][axis].total_cmp(&pos[b][axis]).then(a.cmp(&b))
    });
    for (i, &v) in verts.iter().enumerate() {
        side[v] = if i < mid { Side::Lower } else { Side::Upper };
    }
    // the separator: the lower half's vertices coupled to the upper half, moved to the end of the lower half
    let mut kept = 0;
    for i in 0..mid {
        let v = verts[i];
        if !adj[v].iter().any(|&u| side[u] == Side::Upper) {
            verts.swap(kept, i);
            kept += 1;
        }
    }
    for &v in verts.iter() {
        side[v] = Side::Out;
    }
    (kept, mid)
}

/// The dof permutation of a vertex order (`order[i]` the vertex eliminated i-th): `(fwd, inv)` with `fwd[i]` the
/// dof eliminated i-th and `inv[fwd[i]] = i`, as faer's [`PermRef`](faer::perm::PermRef) takes them.
pub fn dof_permutation(order: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let fwd: Vec<usize> = order
        .iter()
        .flat_map(|&k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect();
    let mut inv = vec![0; fwd.len()];
    for (i, &d) in fwd.iter().enumerate() {
        inv[d] = i;
    }
    (fwd, inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `nx` × `ny` vertices 1 apart, each coupled to its 8 neighbours (the pattern of a triangulated
    /// grid with its flaps is wider; any graph will do for these checks).
    fn grid(nx: usize, ny: usize) -> (Vec<Vec<usize>>, Vec<[f64; 3]>) {
        let id = |i: usize, j: usize| j * nx + i;
        let mut adj = vec![Vec::new(); nx * ny];
        let mut pos = vec![[0.0; 3]; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                pos[id(i, j)] = [i as f64, j as f64, 0.0];
                for (di, dj) in [
                    (-1i64, -1i64),
                    (-1, 0),
                    (-1, 1),
                    (0, -1),
                    (0, 1),
                    (1, -1),
                    (1, 0),
                    (1, 1),
                ] {
                    let (a, b) = (i as i64 + di, j as i64 + dj);
                    if a >= 0 && b >= 0 && (a as usize) < nx && (b as usize) < ny {
                        adj[id(i, j)].push(id(a as usize, b as usize));
                    }
                }
            }
        }
        (adj, pos)
    }

    /// The order holds every vertex exactly once, on a square, a long strip, a graph smaller than a leaf and an
    /// empty one; the dof permutation and its inverse are inverse permutations of 0..3n.
    #[test]
    fn order_is_a_permutation() {
        for (nx, ny) in [(40, 40), (200, 3), (3, 4), (0, 0), (1, 1)] {
            let (adj, pos) = grid(nx, ny);
            let order = nested_dissection(&adj, &pos);
            let mut seen = vec![false; nx * ny];
            for &v in &order {
                assert!(!seen[v], "vertex {v} twice");
                seen[v] = true;
            }
            assert!(seen.iter().all(|&s| s), "{nx}×{ny}: a vertex is missing");
            let (fwd, inv) = dof_permutation(&order);
            assert_eq!(fwd.len(), 3 * nx * ny);
            for (i, &d) in fwd.iter().enumerate() {
                assert_eq!(inv[d], i);
            }
        }
    }

    /// A split leaves no edge between its lower and upper parts, its separator is the lower half's vertices
    /// next to the upper half (on an 8-neighbour grid: one grid line), and it leaves the marks clean.
    #[test]
    fn split_separates() {
        for (nx, ny) in [(40, 40), (37, 11), (5, 60)] {
            let (adj, pos) = grid(nx, ny);
            let mut verts: Vec<usize> = (0..nx * ny).rev().collect();
            let mut side = vec![Side::Out; nx * ny];
            let (kept, mid) = split(&mut verts, &adj, &pos, &mut side);
            assert!(side.iter().all(|&s| s == Side::Out));
            assert_eq!(mid, nx * ny / 2);
            let upper: std::collections::HashSet<usize> = verts[mid..].iter().copied().collect();
            for &v in &verts[..kept] {
                assert!(
                    adj[v].iter().all(|u| !upper.contains(u)),
                    "{nx}×{ny}: {v} is next to the upper half"
                );
            }
            for &v in &verts[kept..mid] {
                assert!(
                    adj[v].iter().any(|u| upper.contains(u)),
                    "{nx}×{ny}: {v} needlessly separates"
                );
            }
            // the split is across the longer side: the separator is about one line of the shorter side
            assert!(
                mid - kept <= nx.min(ny) + 2,
                "{nx}×{ny}: separator of {} vertices",
                mid - kept
            );
        }
    }

    /// The Cholesky factor's nonzeros (faer's simplicial symbolic analysis) of a 3-dof-per-vertex 60 × 60 grid
    /// under nested dissection: less than half of the natural (banded) order's and less than 1.2× faer's minimum
    /// degree's (measured: 873 927, 1 965 060 and 800 109).
    #[test]
    fn fill_is_small() {
        use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymmetricOrdering};
        use faer::sparse::linalg::SupernodalThreshold;
        let (adj, pos) = grid(60, 60);
        let cols: Vec<Vec<usize>> = (0..3 * adj.len())
            .map(|j| {
                let k = j / 3;
                adj[k]
                    .iter()
                    .chain([k].iter())
                    .flat_map(|&u| 3 * u..3 * u + 3)
                    .filter(|&r| r >= j)
                    .collect()
            })
            .collect();
        let lower = LowerPattern::from_columns(cols);
        let order = nested_dissection(&vertex_adjacency(&lower), &pos);
        let (fwd, inv) = dof_permutation(&order);
        let nnz = |ord| {
            let params = faer::sparse::linalg::cholesky::CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                ..Default::default()
            };
            factorize_symbolic_cholesky(lower.symbolic(), faer::Side::Lower, ord, params)
                .unwrap()
                .len_val()
        };
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, fwd.len());
        // the natural order as a custom permutation (faer reads the lower triangle as the upper one under
        // `SymmetricOrdering::Identity`)
        let id: Vec<usize> = (0..fwd.len()).collect();
        let identity = faer::perm::PermRef::new_checked(&id, &id, id.len());
        let (nd, natural, amd) = (
            nnz(SymmetricOrdering::Custom(perm)),
            nnz(SymmetricOrdering::Custom(identity)),
            nnz(SymmetricOrdering::Amd),
        );
        assert!(
            2 * nd < natural,
            "nested dissection {nd}, natural {natural}"
        );
        assert!(
            (nd as f64) < 1.2 * amd as f64,
            "nested dissection {nd}, AMD {amd}"
        );
    }
}
