//! Parallel assembly of the shell energy, gradient and Hessian into a fixed sparsity pattern
//! (`docs/cloth-simulator.md`, "The cloth solver").
//!
//! The pattern is built once per mesh and set of constrained vertices: the Hessian of the free dofs, lower
//! triangle, compressed sparse columns, with a 3×3 block for every pair of free vertices that share a stencil.
//! Every stencil stores where each of its 3×3 blocks lands ([`Pattern`]), so assembly is a plain scatter. The
//! stencils are split into one contiguous range per rayon thread; each thread accumulates into its own value and
//! gradient arrays, which are then summed (deterministic for a given thread count).

use super::element::ElementModel;
use super::mesh::Stencil;
use super::strain::NDOF;
use crate::sparse::LowerPattern;
use rayon::prelude::*;

const NONE: u32 = u32::MAX;

/// The sparsity pattern of the free-dof Hessian (lower triangle, CSC) and each stencil's scatter map.
#[derive(Clone, Debug)]
pub struct Pattern {
    /// number of mesh vertices
    pub n: usize,
    /// free index of each vertex (`None`: constrained)
    pub free: Vec<Option<usize>>,
    /// number of free vertices (the system has 3 × this many unknowns)
    pub nfree: usize,
    /// the lower triangle of the 3 nfree × 3 nfree Hessian (free dof 3k + c of free vertex k)
    pub lower: LowerPattern,
    /// per stencil, per (local vertex a, local vertex b, column c): value index of the first row stored
    offs: Vec<[u32; 108]>,
}

impl Pattern {
    /// The pattern for `stencils` on `n` vertices with the vertices flagged in `constrained` eliminated.
    pub fn new(stencils: &[Stencil], n: usize, constrained: &[bool]) -> Pattern {
        let mut free = vec![None; n];
        let mut nfree = 0;
        for v in 0..n {
            if !constrained[v] {
                free[v] = Some(nfree);
                nfree += 1;
            }
        }
        let lower =
            LowerPattern::from_columns(dof_columns(&block_neighbours(stencils, &free, nfree)));
        let offs = stencils
            .iter()
            .map(|s| {
                let mut o = [NONE; 108];
                for a in 0..6 {
                    for b in 0..6 {
                        if (a >= 3 && !s.flaps[a - 3]) || (b >= 3 && !s.flaps[b - 3]) {
                            continue;
                        }
                        let (Some(ka), Some(kb)) = (free[s.v[a]], free[s.v[b]]) else {
                            continue;
                        };
                        if ka < kb {
                            continue;
                        }
                        // the first stored row of block (ka, kb) in column 3 kb + c: 3 ka + c on the diagonal
                        // block (its lower triangle), else 3 ka
                        for c in 0..3 {
                            let r0 = if ka == kb { c } else { 0 };
                            o[18 * a + 3 * b + c] = lower
                                .find(3 * ka + r0, 3 * kb + c)
                                .expect("pattern holds every stencil pair")
                                as u32;
                        }
                    }
                }
                o
            })
            .collect();
        Pattern {
            n,
            free,
            nfree,
            lower,
            offs,
        }
    }

    /// Number of stored (lower-triangle) entries.
    pub fn nnz(&self) -> usize {
        self.lower.nnz()
    }

    /// Add the symmetric 18×18 matrix `h` of stencil number `si` (stencil `s`) to the free-dof values.
    pub fn add_stencil_hessian(
        &self,
        values: &mut [f64],
        si: usize,
        s: &Stencil,
        h: &[[f64; NDOF]; NDOF],
    ) {
        let offs = &self.offs[si];
        for a in 0..6 {
            for b in 0..6 {
                let base = 18 * a + 3 * b;
                if offs[base] == NONE {
                    continue;
                }
                let diag = self.free[s.v[a]] == self.free[s.v[b]];
                for c in 0..3 {
                    let start = offs[base + c] as usize;
                    let r0 = if diag { c } else { 0 };
                    for r in r0..3 {
                        values[start + r - r0] += h[3 * a + r][3 * b + c];
                    }
                }
            }
        }
    }

    /// Add a symmetric 3×3 block to the diagonal block of free vertex `k`.
    pub fn add_diag_block(&self, values: &mut [f64], k: usize, m: &[[f64; 3]; 3]) {
        for c in 0..3 {
            let start = self.lower.diag[3 * k + c];
            for r in c..3 {
                values[start + r - c] += m[r][c];
            }
        }
    }
}

/// The free vertices ≥ k that share a stencil with free vertex k (k itself included), sorted, for every k.
fn block_neighbours(stencils: &[Stencil], free: &[Option<usize>], nfree: usize) -> Vec<Vec<usize>> {
    let mut nb: Vec<Vec<usize>> = (0..nfree).map(|k| vec![k]).collect();
    for s in stencils {
        let live = live_vertices(s);
        for &a in &live {
            for &b in &live {
                if let (Some(ka), Some(kb)) = (free[s.v[a]], free[s.v[b]]) {
                    if ka > kb {
                        nb[kb].push(ka);
                    }
                }
            }
        }
    }
    for l in nb.iter_mut() {
        l.sort_unstable();
        l.dedup();
    }
    nb
}

/// The dof rows of every dof column from the block neighbours: column 3 kb + c holds the lower triangle of the
/// diagonal block (rows 3 kb + c … 3 kb + 2) and the three rows of every block (ka, kb) below it.
fn dof_columns(nb: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let mut cols = Vec::with_capacity(3 * nb.len());
    for (kb, l) in nb.iter().enumerate() {
        for c in 0..3 {
            let mut rows = Vec::with_capacity(3 * l.len());
            for &ka in l {
                let r0 = if ka == kb { c } else { 0 };
                rows.extend((r0..3).map(|r| 3 * ka + r));
            }
            cols.push(rows);
        }
    }
    cols
}

/// Local vertices of a stencil that carry dofs (the triangle and its existing flaps).
fn live_vertices(s: &Stencil) -> Vec<usize> {
    (0..6).filter(|&a| a < 3 || s.flaps[a - 3]).collect()
}

/// Gather a stencil's 18 coordinates from the flat position vector.
#[inline]
pub fn gather(s: &Stencil, x: &[f64]) -> [f64; NDOF] {
    let mut q = [0.0; NDOF];
    for a in 0..6 {
        for k in 0..3 {
            q[3 * a + k] = x[3 * s.v[a] + k];
        }
    }
    q
}

/// Zero the rows and columns of a local Hessian that belong to flaps the stencil lacks (or every flap, without
/// bending).
pub fn zero_absent_flaps(h: &mut [[f64; NDOF]; NDOF], s: &Stencil, bending: bool) {
    for a in 3..6 {
        if !s.flaps[a - 3] || !bending {
            for r in 0..NDOF {
                for k in 0..3 {
                    h[3 * a + k][r] = 0.0;
                    h[r][3 * a + k] = 0.0;
                }
            }
        }
    }
}

/// Result of one assembly.
#[derive(Clone, Debug)]
pub struct Assembled {
    /// elastic energy E = Σ k A ψ(S z) (barriers included) (J)
    pub energy: f64,
    /// gradient over all 3n dofs (constrained ones included, for reaction forces)
    pub grad: Vec<f64>,
    /// Hessian values in the pattern's order, with the model's PSD option (empty when not requested)
    pub values: Vec<f64>,
    /// exact Hessian values (only when requested with `exact_too`)
    pub values_exact: Vec<f64>,
    /// componentwise min and max of z over the mesh
    pub zmin: [f64; 6],
    /// componentwise max of z over the mesh
    pub zmax: [f64; 6],
    /// z of every triangle, in stencil order
    pub z: Vec<[f64; 6]>,
    /// every stencil's local Hessian with the PSD option, in stencil order (only from [`assemble_keeping`];
    /// rows and columns of absent flaps are zero)
    pub local: Vec<[[f64; NDOF]; NDOF]>,
}

/// Elastic energy only; `None` if any triangle is degenerate.
pub fn energy(model: &ElementModel, stencils: &[Stencil], x: &[f64]) -> Option<f64> {
    stencils
        .par_iter()
        .with_min_len(256)
        .map(|s| model.energy(&gather(s, x), &s.rest, s.flaps))
        .try_reduce(|| 0.0, |a, b| Some(a + b))
}

/// Energy, gradient and (if `hessian`) the free-dof Hessian of the elastic energy with the model's PSD option,
/// and with `exact_too` also the exact Hessian (same evaluation); `None` if any triangle is degenerate.
pub fn assemble(
    model: &ElementModel,
    stencils: &[Stencil],
    pattern: &Pattern,
    x: &[f64],
    hessian: bool,
    exact_too: bool,
) -> Option<Assembled> {
    assemble_with(model, stencils, pattern, x, hessian, exact_too, false)
}

/// [`assemble`] with the Hessian, also keeping every stencil's local PSD-option Hessian in
/// [`Assembled::local`] (the damping of the next step reuses those at the converged state).
pub fn assemble_keeping(
    model: &ElementModel,
    stencils: &[Stencil],
    pattern: &Pattern,
    x: &[f64],
    exact_too: bool,
) -> Option<Assembled> {
    assemble_with(model, stencils, pattern, x, true, exact_too, true)
}

/// What an assembly computes besides the energy, the gradient and z.
#[derive(Clone, Copy)]
struct Wanted {
    /// the Hessian with the model's PSD option
    hessian: bool,
    /// the exact Hessian too (only with `hessian`)
    exact_too: bool,
    /// every stencil's local PSD-option Hessian ([`Assembled::local`])
    keep_local: bool,
}

fn assemble_with(
    model: &ElementModel,
    stencils: &[Stencil],
    pattern: &Pattern,
    x: &[f64],
    hessian: bool,
    exact_too: bool,
    keep_local: bool,
) -> Option<Assembled> {
    let exact_too = hessian && exact_too;
    if stencils.is_empty() {
        return Some(Assembled {
            energy: 0.0,
            grad: vec![0.0; x.len()],
            values: vec![0.0; if hessian { pattern.nnz() } else { 0 }],
            values_exact: vec![0.0; if exact_too { pattern.nnz() } else { 0 }],
            zmin: [0.0; 6],
            zmax: [0.0; 6],
            z: vec![],
            local: vec![],
        });
    }
    let want = Wanted {
        hessian,
        exact_too,
        keep_local,
    };
    let nthreads = rayon::current_num_threads().max(1);
    let chunk = stencils.len().div_ceil(nthreads).max(1);
    let parts: Vec<Option<Assembled>> = stencils
        .par_chunks(chunk)
        .enumerate()
        .map(|(ci, ss)| assemble_chunk(model, pattern, x, ss, ci * chunk, want))
        .collect();
    let parts: Vec<Assembled> = parts.into_iter().collect::<Option<Vec<_>>>()?;
    Some(sum_parts(parts, keep_local, stencils.len()))
}

/// One thread's share: the stencils `ss` (the first is stencil number `first`) accumulated into arrays of their
/// own; `None` if a triangle is degenerate.
fn assemble_chunk(
    model: &ElementModel,
    pattern: &Pattern,
    x: &[f64],
    ss: &[Stencil],
    first: usize,
    want: Wanted,
) -> Option<Assembled> {
    let Wanted {
        hessian,
        exact_too,
        keep_local,
    } = want;
    let nnz = if hessian { pattern.nnz() } else { 0 };
    let mut out = Assembled {
        energy: 0.0,
        grad: vec![0.0; x.len()],
        values: vec![0.0; nnz],
        values_exact: vec![0.0; if exact_too { nnz } else { 0 }],
        zmin: [f64::INFINITY; 6],
        zmax: [f64::NEG_INFINITY; 6],
        z: Vec::with_capacity(ss.len()),
        local: Vec::with_capacity(if keep_local { ss.len() } else { 0 }),
    };
    let mut g = [0.0; NDOF];
    let mut h = [[0.0; NDOF]; NDOF];
    let mut hx = [[0.0; NDOF]; NDOF];
    for (si, s) in ss.iter().enumerate() {
        let q = gather(s, x);
        let (e, z) = if exact_too {
            model.energy_gradient_hessians(&q, &s.rest, s.flaps, &mut g, &mut hx, &mut h)?
        } else if hessian {
            model.energy_gradient_hessian(&q, &s.rest, s.flaps, &mut g, &mut h)?
        } else {
            model.energy_gradient(&q, &s.rest, s.flaps, &mut g)?
        };
        out.energy += e;
        out.z.push(z);
        if keep_local {
            let mut hl = h;
            zero_absent_flaps(&mut hl, s, model.bending);
            out.local.push(hl);
        }
        for k in 0..6 {
            out.zmin[k] = out.zmin[k].min(z[k]);
            out.zmax[k] = out.zmax[k].max(z[k]);
        }
        for a in 0..6 {
            if a >= 3 && !s.flaps[a - 3] {
                continue;
            }
            for k in 0..3 {
                out.grad[3 * s.v[a] + k] += g[3 * a + k];
            }
        }
        if hessian {
            let k = first + si;
            pattern.add_stencil_hessian(&mut out.values, k, s, &h);
            if exact_too {
                pattern.add_stencil_hessian(&mut out.values_exact, k, s, &hx);
            }
        }
    }
    Some(out)
}

/// The threads' shares summed into one (in a fixed order: deterministic for a given thread count); z and the
/// local Hessians concatenated in stencil order.
fn sum_parts(mut parts: Vec<Assembled>, keep_local: bool, nstencils: usize) -> Assembled {
    let z: Vec<[f64; 6]> = parts.iter().flat_map(|p| p.z.iter().copied()).collect();
    // the first part's local Hessians grow by the others' (moved once, not element by element into a vector
    // that reallocates as it grows)
    let local: Vec<[[f64; NDOF]; NDOF]> = if keep_local {
        let mut all = std::mem::take(&mut parts[0].local);
        all.reserve_exact(nstencils - all.len());
        for p in parts.iter_mut().skip(1) {
            all.append(&mut p.local);
        }
        all
    } else {
        vec![]
    };
    let mut total = parts.swap_remove(0);
    total.z = z;
    total.local = local;
    for p in &parts {
        total.energy += p.energy;
        total
            .grad
            .par_iter_mut()
            .zip(p.grad.par_iter())
            .for_each(|(a, b)| *a += b);
        total
            .values
            .par_iter_mut()
            .zip(p.values.par_iter())
            .for_each(|(a, b)| *a += b);
        total
            .values_exact
            .par_iter_mut()
            .zip(p.values_exact.par_iter())
            .for_each(|(a, b)| *a += b);
        for k in 0..6 {
            total.zmin[k] = total.zmin[k].min(p.zmin[k]);
            total.zmax[k] = total.zmax[k].max(p.zmax[k]);
        }
    }
    total
}
