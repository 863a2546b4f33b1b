//! The whole periodic tile at zero macro strain (`docs/yarn-model.md`): total rod + contact energy, its gradient and
//! its sparse Hessian, assembled stencil by stencil in parallel (rayon), with periodic copies as translations.
//!
//! Degrees of freedom: `[x₀, y₀, z₀, x₁, …, z_{n−1}, θ₀, …, θ_{n−1}]` — the home-tile vertex positions, then the
//! material angle of each vertex's outgoing edge. A stencil that reaches a periodic copy of a vertex acts on that
//! vertex's dofs through the copy map (a translation here; [`Placement`] carries the rotation for curved maps).
//! Reference frames come from a stored [`RodState`] and are parallel-transported to the evaluated positions, so the
//! value, gradient and Hessian are those of one smooth function of the dofs (what the derivative harness checks).

pub mod contact;

pub use contact::ContactPair;

use crate::contact::ContactError;
use crate::pattern::Pattern;
use crate::periodic::{Placement, TileTransforms};
use crate::rod::bend_twist::{bend_twist_parts, bend_twist_parts_vgh, BendTwistParams};
use crate::rod::stretch::{stretch_value, stretch_vgh};
use crate::rod::{RodState, RodTopology, YarnMaterial};
use nalgebra::{DVector, Matrix3, Vector3};
use rayon::prelude::*;

/// What an evaluation computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Want {
    /// The energy only.
    Value,
    /// The energy and its gradient.
    Gradient,
    /// The energy, its gradient and its Hessian.
    Hessian,
}

/// The energy of each part of the model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyParts {
    /// Stretching energy (J).
    pub stretch: f64,
    /// Bending energy (J).
    pub bend: f64,
    /// Twisting energy (J).
    pub twist: f64,
    /// Contact energy (J).
    pub contact: f64,
}

impl EnergyParts {
    /// The total energy E (J): the sum of the parts.
    pub fn total(&self) -> f64 {
        self.stretch + self.bend + self.twist + self.contact
    }
}

/// Which energy terms an evaluation includes, with a weight on each (1 for the physical energy; the calibration
/// evaluates the terms one at a time to get ∂∇E/∂parameter).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terms {
    /// Weight of the stretching term.
    pub stretch: f64,
    /// Weight of the bending term.
    pub bend: f64,
    /// Weight of the twisting term.
    pub twist: f64,
    /// Weight of the contact term.
    pub contact: f64,
}

impl Terms {
    /// Every term at weight 1: the physical energy.
    pub const ALL: Terms = Terms {
        stretch: 1.0,
        bend: 1.0,
        twist: 1.0,
        contact: 1.0,
    };
    /// The rod terms only (no contact).
    pub const RODS: Terms = Terms {
        stretch: 1.0,
        bend: 1.0,
        twist: 1.0,
        contact: 0.0,
    };
}

/// Energy, gradient and sparse Hessian (lower and upper triangle, as triplets with duplicates summed by the
/// consumer) of the tile.
#[derive(Clone, Debug)]
pub struct TileEval {
    /// The energy of each part (J).
    pub parts: EnergyParts,
    /// ∇E over the dofs (positions in N, angles in N·m), with [`Want::Gradient`] or [`Want::Hessian`].
    pub gradient: Option<DVector<f64>>,
    /// ∇²E as (row, column, value) triplets, duplicates to be summed, with [`Want::Hessian`].
    pub hessian: Option<Vec<(usize, usize, f64)>>,
}

impl TileEval {
    /// The total energy E (J).
    pub fn value(&self) -> f64 {
        self.parts.total()
    }

    /// The Hessian as a dense matrix (tests and the harness).
    pub fn dense_hessian(&self, n: usize) -> Option<nalgebra::DMatrix<f64>> {
        self.hessian.as_ref().map(|t| {
            let mut m = nalgebra::DMatrix::zeros(n, n);
            for &(i, j, v) in t {
                m[(i, j)] += v;
            }
            m
        })
    }

    /// The Hessian as a faer sparse column matrix (duplicates summed).
    pub fn sparse_hessian(&self, n: usize) -> Option<faer::sparse::SparseColMat<usize, f64>> {
        self.hessian.as_ref().map(|t| {
            let trip: Vec<faer::sparse::Triplet<usize, usize, f64>> = t
                .iter()
                .map(|&(i, j, v)| faer::sparse::Triplet::new(i, j, v))
                .collect();
            faer::sparse::SparseColMat::try_new_from_triplets(n, n, &trip)
                .expect("indices are in range by construction")
        })
    }
}

/// How a vertex's three position dofs place it (`docs/micro-solver.md`, section 2): the home copy of vertex v is
/// at x_v = b_v + R_v ũ_v (b_v = φ(ξ_v) + h_v n(ξ_v), R_v = R(ξ_v)), and its copy at offset o at T_o(x_v).
/// Without a map the dofs are the home positions themselves.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    /// b_v = φ(ξ_v) + h_v n(ξ_v) per vertex (m).
    pub base: Vec<Vector3<f64>>,
    /// R_v = R(ξ_v) per vertex.
    pub rotation: Vec<Matrix3<f64>>,
}

/// Force and moment resultants (F_o, M_o) of the stencil forces on the copies at one offset o
/// ([`Tile::offset_resultants`]).
pub type OffsetResultant = ([i32; 2], Vector3<f64>, Vector3<f64>);

/// A periodic tile ready to evaluate: the pattern's rest values, the material, the rod topology and the contact
/// pairs.
pub struct Tile<'a> {
    /// The pattern (rest values and stored state).
    pub pattern: &'a Pattern,
    /// The yarn material (radius the pattern's).
    pub material: YarnMaterial,
    /// The bending stencil of every vertex.
    pub topology: RodTopology,
    /// The Voronoi length of each vertex along its yarn (m).
    pub voronoi: Vec<f64>,
    /// The rigid transforms of the periodic copies.
    pub placement: TileTransforms,
    /// The per-vertex dof map (none: dofs are world positions).
    pub dof_map: Option<DofMap>,
    /// The contact pairs (segment against segment, with the image offset).
    pub contacts: Vec<ContactPair>,
    /// Radius of the contact distance 2r: the yarn radius times the material's contact radius factor.
    pub contact_radius: f64,
}

/// One local stencil result: dofs as (vertex, offset) for positions and edge indices for angles.
struct Local<const N: usize> {
    value: f64,
    g: nalgebra::SVector<f64, N>,
    h: nalgebra::SMatrix<f64, N, N>,
}

impl<'a> Tile<'a> {
    /// A tile with the given material (its radius is taken from the pattern) and no contact pairs.
    pub fn new(pattern: &'a Pattern, material: &YarnMaterial) -> Self {
        let mut material = material.clone();
        material.radius = pattern.radius;
        let contact_radius = pattern.radius * material.contact_radius_factor;
        Tile {
            pattern,
            material,
            topology: RodTopology::new(pattern),
            voronoi: pattern.voronoi_lengths(),
            placement: TileTransforms::flat(pattern.periods),
            dof_map: None,
            contacts: Vec::new(),
            contact_radius,
        }
    }

    /// Number of dofs (4 per vertex).
    pub fn ndof(&self) -> usize {
        4 * self.pattern.len()
    }

    /// The dof vector of a state.
    pub fn dofs_of(state: &RodState) -> Vec<f64> {
        let mut y: Vec<f64> = state
            .positions
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .collect();
        y.extend_from_slice(&state.theta);
        y
    }

    /// World position of the home copy of vertex `v` for dofs `y`.
    #[inline]
    pub fn home(&self, y: &[f64], v: usize) -> Vector3<f64> {
        let u = Vector3::new(y[3 * v], y[3 * v + 1], y[3 * v + 2]);
        match &self.dof_map {
            None => u,
            Some(m) => m.base[v] + m.rotation[v] * u,
        }
    }

    /// World positions of all home vertices for dofs `y`.
    pub fn home_positions(&self, y: &[f64]) -> Vec<Vector3<f64>> {
        (0..self.pattern.len()).map(|v| self.home(y, v)).collect()
    }

    /// World position of the copy at offset `o` of vertex `v` for dofs `y`.
    #[inline]
    pub fn position(&self, y: &[f64], v: usize, o: [i32; 2]) -> Vector3<f64> {
        self.placement.position(&self.home(y, v), o)
    }

    /// The rotation from vertex `v`'s position dofs to its copy at offset `o`: R_o R_v.
    #[inline]
    pub fn dof_rotation(&self, v: usize, o: [i32; 2]) -> Matrix3<f64> {
        let r = self.placement.rotation(o);
        match &self.dof_map {
            None => r,
            Some(m) => r * m.rotation[v],
        }
    }

    pub(crate) fn bend_params(&self, i: usize, terms: &Terms) -> BendTwistParams {
        let form = self.material.bending;
        let rest_twist = self.pattern.rest_twist[i];
        BendTwistParams {
            rest_curvature: form
                .rest_curvature_from_tan(self.pattern.rest_curvature[i], rest_twist),
            rest_twist,
            voronoi_length: self.voronoi[i],
            bend: self.material.bend_stiffness() * terms.bend,
            twist: self.material.twist_stiffness() * terms.twist,
            form,
        }
    }

    /// Energy (and optionally gradient and Hessian) at dofs `y`, with reference frames transported from `frames`.
    ///
    /// Errors come from the contact kernels only (overlapping yarns, non-finite coordinates).
    pub fn evaluate(
        &self,
        frames: &RodState,
        y: &[f64],
        want: Want,
        terms: &Terms,
    ) -> Result<TileEval, ContactError> {
        if want == Want::Value {
            return self.evaluate_value(frames, y, terms);
        }
        let n = self.pattern.len();
        let ks = self.material.stretch_stiffness() * terms.stretch;
        let mut parts = EnergyParts::default();
        let mut grad = Some(DVector::zeros(4 * n));
        // 6² + 11² lower-and-upper entries per vertex for the rods, 12² per contact pair
        let mut trip: Option<Vec<(usize, usize, f64)>> = (want == Want::Hessian)
            .then(|| Vec::with_capacity(157 * n + 144 * self.contacts.len()));

        // stretching, one stencil per edge
        if terms.stretch != 0.0 {
            let locals: Vec<Local<6>> = (0..n)
                .into_par_iter()
                .map(|i| {
                    let e = &self.pattern.edges[i];
                    let a = self.position(y, i, [0, 0]);
                    let b = self.position(y, e.end, e.offset);
                    let (value, g, h) = stretch_vgh(&a, &b, e.rest_length, ks);
                    Local { value, g, h }
                })
                .collect();
            for (i, l) in locals.iter().enumerate() {
                parts.stretch += l.value;
                let e = &self.pattern.edges[i];
                let dofs = [(i, [0, 0]), (e.end, e.offset)];
                self.scatter_positions(&dofs, &[], l, &mut grad, &mut trip);
            }
        }

        // bending and twisting, one stencil per vertex
        if terms.bend != 0.0 || terms.twist != 0.0 {
            let locals: Vec<(f64, f64, Local<11>)> = (0..n)
                .into_par_iter()
                .map(|i| {
                    let s = &self.topology.stencils[i];
                    let x = [0, 1, 2].map(|k| self.position(y, s.vertices[k], s.offsets[k]));
                    let th = [y[3 * n + s.edges[0]], y[3 * n + s.edges[1]]];
                    let (_, _, fr) = frames.stencil(s, &self.placement);
                    let p = self.bend_params(i, terms);
                    let ([eb, et], g, h) = bend_twist_parts_vgh(&x, th, &fr, &p);
                    (
                        eb,
                        et,
                        Local {
                            value: eb + et,
                            g,
                            h,
                        },
                    )
                })
                .collect();
            for (i, (eb, et, l)) in locals.iter().enumerate() {
                parts.bend += eb;
                parts.twist += et;
                let s = &self.topology.stencils[i];
                let dofs = [0, 1, 2].map(|k| (s.vertices[k], s.offsets[k]));
                self.scatter_positions(&dofs, &s.edges, l, &mut grad, &mut trip);
            }
        }

        if terms.contact != 0.0 && !self.contacts.is_empty() {
            parts.contact = contact::assemble(self, y, want, terms.contact, &mut grad, &mut trip)?;
        }

        Ok(TileEval {
            parts,
            gradient: grad,
            hessian: trip,
        })
    }

    /// [`evaluate`](Self::evaluate) for the value alone (the line search's trials): the same stencil values
    /// summed in the same order, without the local gradient and Hessian storage.
    fn evaluate_value(
        &self,
        frames: &RodState,
        y: &[f64],
        terms: &Terms,
    ) -> Result<TileEval, ContactError> {
        let n = self.pattern.len();
        let ks = self.material.stretch_stiffness() * terms.stretch;
        let mut parts = EnergyParts::default();
        if terms.stretch != 0.0 {
            let values: Vec<f64> = (0..n)
                .into_par_iter()
                .map(|i| {
                    let e = &self.pattern.edges[i];
                    let a = self.position(y, i, [0, 0]);
                    let b = self.position(y, e.end, e.offset);
                    stretch_value(&a, &b, e.rest_length, ks)
                })
                .collect();
            for v in values {
                parts.stretch += v;
            }
        }
        if terms.bend != 0.0 || terms.twist != 0.0 {
            let values: Vec<[f64; 2]> = (0..n)
                .into_par_iter()
                .map(|i| {
                    let s = &self.topology.stencils[i];
                    let x = [0, 1, 2].map(|k| self.position(y, s.vertices[k], s.offsets[k]));
                    let th = [y[3 * n + s.edges[0]], y[3 * n + s.edges[1]]];
                    let (_, _, fr) = frames.stencil(s, &self.placement);
                    bend_twist_parts(&x, th, &fr, &self.bend_params(i, terms))
                })
                .collect();
            for [eb, et] in values {
                parts.bend += eb;
                parts.twist += et;
            }
        }
        if terms.contact != 0.0 && !self.contacts.is_empty() {
            parts.contact = contact::assemble_value(self, y, terms.contact)?;
        }
        Ok(TileEval {
            parts,
            gradient: None,
            hessian: None,
        })
    }

    /// Force and moment resultants of the stencil forces acting on periodic copies, per offset o ≠ 0: F_o = Σ g,
    /// M_o = Σ x × g over the stencil points at offset o (g = ∂E/∂x of the stencil at that point, world
    /// coordinates), plus, for each bending stencil whose incoming edge is a copy, g_θ⁰ t⁰ added to M of that
    /// copy's offset (the copy's stored frame turns with its tile transform: to first order at the stored state
    /// the same as turning θ⁰ by ω·t⁰). With an infinitesimal change of the tile transforms δx = ω_o × x + v_o,
    /// the energy changes by Σ_o ω_o·M_o + v_o·F_o at fixed dofs (`docs/micro-solver.md`, section 5; used for the
    /// envelope-theorem stress).
    pub fn offset_resultants(
        &self,
        frames: &RodState,
        y: &[f64],
        terms: &Terms,
    ) -> Result<Vec<OffsetResultant>, ContactError> {
        use std::collections::BTreeMap;
        let n = self.pattern.len();
        let mut acc = BTreeMap::new();
        type Acc = BTreeMap<[i32; 2], (Vector3<f64>, Vector3<f64>)>;
        fn add(acc: &mut Acc, o: [i32; 2], x: &Vector3<f64>, g: &Vector3<f64>) {
            let e = acc.entry(o).or_insert((Vector3::zeros(), Vector3::zeros()));
            e.0 += g;
            e.1 += x.cross(g);
        }
        if terms.stretch != 0.0 {
            let ks = self.material.stretch_stiffness() * terms.stretch;
            for (i, e) in self.pattern.edges.iter().enumerate() {
                if e.offset == [0, 0] {
                    continue;
                }
                let a = self.position(y, i, [0, 0]);
                let b = self.position(y, e.end, e.offset);
                let (_, g, _) = stretch_vgh(&a, &b, e.rest_length, ks);
                add(&mut acc, e.offset, &b, &g.fixed_rows::<3>(3).into_owned());
            }
        }
        if terms.bend != 0.0 || terms.twist != 0.0 {
            for (i, s) in self.topology.stencils.iter().enumerate() {
                if s.offsets.iter().all(|o| *o == [0, 0]) {
                    continue;
                }
                let x = [0, 1, 2].map(|k| self.position(y, s.vertices[k], s.offsets[k]));
                let th = [y[3 * n + s.edges[0]], y[3 * n + s.edges[1]]];
                let (_, _, fr) = frames.stencil(s, &self.placement);
                let (_, g, _) = bend_twist_parts_vgh(&x, th, &fr, &self.bend_params(i, terms));
                for k in 0..3 {
                    if s.offsets[k] != [0, 0] {
                        add(
                            &mut acc,
                            s.offsets[k],
                            &x[k],
                            &g.fixed_rows::<3>(3 * k).into_owned(),
                        );
                    }
                }
                if s.offsets[0] != [0, 0] {
                    let t0 = (x[1] - x[0]).normalize();
                    let e = acc
                        .entry(s.offsets[0])
                        .or_insert((Vector3::zeros(), Vector3::zeros()));
                    e.1 += t0 * g[9];
                }
            }
        }
        if terms.contact != 0.0 && !self.contacts.is_empty() {
            let m = &self.material;
            let kernel = crate::contact::PairKernel::new(
                m.contact_stiffness * terms.contact,
                self.contact_radius,
                m.contact_quadrature,
            )?;
            for pair in &self.contacts {
                let pts = pair.points(self);
                if pts.iter().all(|(_, o)| *o == [0, 0]) {
                    continue;
                }
                let x: [Vector3<f64>; 4] = pts.map(|(v, o)| self.position(y, v, o));
                if kernel.beyond_cutoff(&x) {
                    continue;
                }
                let la = self.pattern.edges[pair.a].rest_length;
                let lb = self.pattern.edges[pair.b].rest_length;
                let r = kernel.value_gradient_hessian(&x, la, lb)?;
                for k in 0..4 {
                    if pts[k].1 != [0, 0] {
                        add(
                            &mut acc,
                            pts[k].1,
                            &x[k],
                            &r.gradient.fixed_rows::<3>(3 * k).into_owned(),
                        );
                    }
                }
            }
        }
        Ok(acc.into_iter().map(|(o, (f, m))| (o, f, m)).collect())
    }

    /// Add a stencil's local gradient and Hessian: `pos` lists (vertex, offset) for consecutive 3-blocks of the
    /// local dofs, `angles` the edges of the angle dofs that follow them.
    fn scatter_positions<const N: usize>(
        &self,
        pos: &[(usize, [i32; 2])],
        angles: &[usize],
        l: &Local<N>,
        grad: &mut Option<DVector<f64>>,
        trip: &mut Option<Vec<(usize, usize, f64)>>,
    ) {
        let n = self.pattern.len();
        // global index of local dof k and the rotation of its block
        let np = pos.len();
        let rot: Vec<Matrix3<f64>> = pos.iter().map(|&(v, o)| self.dof_rotation(v, o)).collect();
        if let Some(g) = grad.as_mut() {
            for (b, &(v, _)) in pos.iter().enumerate() {
                let gb = rot[b].transpose() * l.g.fixed_rows::<3>(3 * b);
                for c in 0..3 {
                    g[3 * v + c] += gb[c];
                }
            }
            for (k, &e) in angles.iter().enumerate() {
                g[3 * n + e] += l.g[3 * np + k];
            }
        }
        if let Some(t) = trip.as_mut() {
            let index = |k: usize| -> usize {
                if k < 3 * np {
                    3 * pos[k / 3].0 + k % 3
                } else {
                    3 * n + angles[k - 3 * np]
                }
            };
            // rotate the position blocks: H ← Rᵀ H R (identity for translations, skipped then)
            let mut h = l.h;
            if rot.iter().any(|r| *r != Matrix3::identity()) {
                let mut big = nalgebra::SMatrix::<f64, N, N>::identity();
                for (b, r) in rot.iter().enumerate() {
                    big.fixed_view_mut::<3, 3>(3 * b, 3 * b).copy_from(r);
                }
                h = big.transpose() * h * big;
            }
            for a in 0..N {
                let ia = index(a);
                for b in 0..N {
                    let v = h[(a, b)];
                    if v != 0.0 {
                        t.push((ia, index(b), v));
                    }
                }
            }
        }
    }
}
