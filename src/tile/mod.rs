//! The whole periodic tile at zero macro strain (`02-yarn-model.md`): total rod + contact energy, its gradient and
//! its sparse Hessian, assembled stencil by stencil in parallel (rayon), with periodic copies as translations.
//!
//! Degrees of freedom: `[x₀, y₀, z₀, x₁, …, z_{n−1}, θ₀, …, θ_{n−1}]` — the home-tile vertex positions, then the
//! material angle of each vertex's outgoing edge. A stencil that reaches a periodic copy of a vertex acts on that
//! vertex's dofs through the copy map (a translation here; [`Placement`] carries the rotation for curved maps).
//! Reference frames come from a stored [`RodState`] and are parallel-transported to the evaluated positions, so the
//! value, gradient and Hessian are those of one smooth function of the dofs (what the derivative harness checks).

pub mod calibration;
mod checks;
pub mod contact;

pub use checks::diff_checks;
pub use contact::ContactPair;

use crate::contact::ContactError;
use crate::pattern::Pattern;
use crate::rod::bend_twist::{bend_twist_parts, bend_twist_parts_vgh, BendTwistParams};
use crate::rod::stretch::{stretch_value, stretch_vgh};
use crate::rod::{Placement, RodState, RodTopology, Translation, YarnMaterial};
use nalgebra::{DVector, Matrix3, Vector3};
use rayon::prelude::*;

/// What an evaluation computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Want {
    Value,
    Gradient,
    Hessian,
}

/// The energy of each part of the model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyParts {
    pub stretch: f64,
    pub bend: f64,
    pub twist: f64,
    pub contact: f64,
}

impl EnergyParts {
    pub fn total(&self) -> f64 {
        self.stretch + self.bend + self.twist + self.contact
    }
}

/// Which energy terms an evaluation includes, with a weight on each (1 for the physical energy; the calibration
/// evaluates the terms one at a time to get ∂∇E/∂parameter).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terms {
    pub stretch: f64,
    pub bend: f64,
    pub twist: f64,
    pub contact: f64,
}

impl Terms {
    pub const ALL: Terms = Terms {
        stretch: 1.0,
        bend: 1.0,
        twist: 1.0,
        contact: 1.0,
    };
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
    pub parts: EnergyParts,
    pub gradient: Option<DVector<f64>>,
    pub hessian: Option<Vec<(usize, usize, f64)>>,
}

impl TileEval {
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

/// A periodic tile ready to evaluate: the pattern's rest values, the material, the rod topology and the contact
/// pairs.
pub struct Tile<'a> {
    pub pattern: &'a Pattern,
    pub material: YarnMaterial,
    pub topology: RodTopology,
    pub voronoi: Vec<f64>,
    pub placement: Translation,
    pub contacts: Vec<ContactPair>,
    /// Radius of the contact distance 2r (the yarn radius unless a calibration varies it).
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
        Tile {
            pattern,
            material,
            topology: RodTopology::new(pattern),
            voronoi: pattern.voronoi_lengths(),
            placement: Translation {
                periods: pattern.periods,
            },
            contacts: Vec::new(),
            contact_radius: pattern.radius,
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

    /// World position of the copy at offset `o` of vertex `v` for dofs `y`.
    pub fn position(&self, y: &[f64], v: usize, o: [i32; 2]) -> Vector3<f64> {
        let x = Vector3::new(y[3 * v], y[3 * v + 1], y[3 * v + 2]);
        self.placement.position(&x, o)
    }

    pub(crate) fn bend_params(&self, i: usize, terms: &Terms) -> BendTwistParams {
        BendTwistParams {
            rest_curvature: self.pattern.rest_curvature[i],
            rest_twist: self.pattern.rest_twist[i],
            voronoi_length: self.voronoi[i],
            bend: self.material.bend_stiffness() * terms.bend,
            twist: self.material.twist_stiffness() * terms.twist,
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
        let n = self.pattern.len();
        let ks = self.material.stretch_stiffness() * terms.stretch;
        let mut parts = EnergyParts::default();
        let mut grad = (want != Want::Value).then(|| DVector::zeros(4 * n));
        let mut trip: Option<Vec<(usize, usize, f64)>> = (want == Want::Hessian).then(Vec::new);

        // stretching, one stencil per edge
        if terms.stretch != 0.0 {
            let locals: Vec<Local<6>> = (0..n)
                .into_par_iter()
                .map(|i| {
                    let e = &self.pattern.edges[i];
                    let a = self.position(y, i, [0, 0]);
                    let b = self.position(y, e.end, e.offset);
                    if want == Want::Value {
                        Local {
                            value: stretch_value(&a, &b, e.rest_length, ks),
                            g: Default::default(),
                            h: Default::default(),
                        }
                    } else {
                        let (value, g, h) = stretch_vgh(&a, &b, e.rest_length, ks);
                        Local { value, g, h }
                    }
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
                    if want == Want::Value {
                        let [eb, et] = bend_twist_parts(&x, th, &fr, &p);
                        (
                            eb,
                            et,
                            Local {
                                value: eb + et,
                                g: Default::default(),
                                h: Default::default(),
                            },
                        )
                    } else {
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
                    }
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
        let rot: Vec<Matrix3<f64>> = pos
            .iter()
            .map(|&(_, o)| self.placement.rotation(o))
            .collect();
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
