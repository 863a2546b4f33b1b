//! Kinematics and the elimination map q = C̃ y + d̃ (`docs/micro-solver.md`, section 2).
//!
//! Unknowns y = (ũ₀ … ũ_{n−1}, θ₀ … θ_{n−1}): one local displacement per vertex and one angle per edge. The
//! world position of the copy of vertex v at offset o is
//! x = φ(ξ_v + Δ_o) + h_v n(ξ_v + Δ_o) + R(ξ_v + Δ_o) ũ_v = T_o(b_v + R_v ũ_v),
//! affine in y. Periodicity is built in (a vertex and its copies share ũ and θ). The solver never forms C̃: it
//! hands the [`DofMap`] (b_v, R_v) and the tile transforms T_o to the tile, which pulls each stencil's gradient
//! and Hessian back through its 3×3 rotation blocks. [`Elimination::matrix`] builds C̃ and d̃ explicitly for the
//! tests and the derivative harness.

use super::strain::{Family, MacroStrain, StrainError};
use super::surface::SurfaceMap;
use crate::pattern::Pattern;
use crate::periodic::TileTransforms;
use crate::tile::{DofMap, Tile};
use nalgebra::{Matrix3, Vector3};
use std::collections::BTreeSet;

/// The kinematics of a pattern at one macro strain.
#[derive(Clone, Debug)]
pub struct Elimination {
    /// The macro strain.
    pub strain: MacroStrain,
    /// The surface map family.
    pub family: Family,
    /// The surface map φ of the strain.
    pub map: SurfaceMap<f64>,
    /// The reference periods (p₁, p₂) (m).
    pub periods: [f64; 2],
    /// The vertex dof map x_v = b_v + R_v ũ_v.
    pub dofs: DofMap,
    /// The rigid transforms of the periodic copies.
    pub transforms: TileTransforms,
}

impl Elimination {
    /// The kinematics of `pattern` at `strain`, in the family the strain selects.
    pub fn new(pattern: &Pattern, strain: &MacroStrain) -> Result<Self, StrainError> {
        let family = strain.validate()?;
        Ok(Self::in_family(pattern, strain, family))
    }

    /// The kinematics in a given family (`BendX` at Π₀₀ = 0 is the plane rotated in-plane; used for the stress
    /// component ∂Ψ̄/∂Π₀₀ at Π = 0). The strain must be valid for the family.
    pub fn in_family(pattern: &Pattern, strain: &MacroStrain, family: Family) -> Self {
        let map = SurfaceMap::of(strain, family);
        let (base, rotation) = pattern
            .positions
            .iter()
            .map(|x| {
                let (phi, r) = map.frame_na([x.x, x.y]);
                (phi + r.column(2) * x.z, r)
            })
            .unzip();
        Elimination {
            strain: *strain,
            family,
            transforms: map.transforms(pattern.periods),
            map,
            periods: pattern.periods,
            dofs: DofMap { base, rotation },
        }
    }

    /// Install these kinematics on a tile.
    pub fn apply_to(&self, tile: &mut Tile) {
        tile.placement = self.transforms.clone();
        tile.dof_map = Some(self.dofs.clone());
    }

    /// World position of the copy of vertex `v` at offset `o` for the local displacement `u`.
    pub fn position(&self, v: usize, o: [i32; 2], u: &Vector3<f64>) -> Vector3<f64> {
        let x = self.dofs.base[v] + self.dofs.rotation[v] * u;
        if o == [0, 0] {
            x
        } else {
            let (r, t) = self.transforms.get(o);
            r * x + t
        }
    }

    /// The local displacement ũ_v that puts vertex `v`'s home copy at world position `x`.
    pub fn local_displacement(&self, v: usize, x: &Vector3<f64>) -> Vector3<f64> {
        self.dofs.rotation[v].transpose() * (x - self.dofs.base[v])
    }

    /// The explicit elimination map for the listed copies: C̃ as triplets (row, column, value) with rows
    /// 3k..3k+3 for copy k and rows 3K + j for the angle θ_j (K copies), columns the dofs y of [`Tile`]
    /// (3n displacements, then n angles); and d̃.
    #[allow(clippy::type_complexity)]
    pub fn matrix(
        &self,
        copies: &[(usize, [i32; 2])],
        n: usize,
    ) -> (Vec<(usize, usize, f64)>, Vec<f64>) {
        let mut trip = Vec::with_capacity(9 * copies.len() + n);
        let mut d = vec![0.0; 3 * copies.len() + n];
        for (k, &(v, o)) in copies.iter().enumerate() {
            let (r, t) = if o == [0, 0] {
                (Matrix3::identity(), Vector3::zeros())
            } else {
                *self.transforms.get(o)
            };
            let block = r * self.dofs.rotation[v];
            let off = r * self.dofs.base[v] + t;
            for i in 0..3 {
                for j in 0..3 {
                    trip.push((3 * k + i, 3 * v + j, block[(i, j)]));
                }
                d[3 * k + i] = off[i];
            }
        }
        for j in 0..n {
            trip.push((3 * copies.len() + j, 3 * n + j, 1.0));
        }
        (trip, d)
    }
}

/// Every (vertex, offset) copy the tile's stencils reach (stretching, bending+twisting, contact pairs), sorted.
pub fn stencil_copies(tile: &Tile) -> Vec<(usize, [i32; 2])> {
    let mut set = BTreeSet::new();
    let key = |v: usize, o: [i32; 2]| (v, o);
    for (i, e) in tile.pattern.edges.iter().enumerate() {
        set.insert(key(i, [0, 0]));
        set.insert(key(e.end, e.offset));
    }
    for s in &tile.topology.stencils {
        for k in 0..3 {
            set.insert(key(s.vertices[k], s.offsets[k]));
        }
    }
    for c in &tile.contacts {
        for (v, o) in c.points(tile) {
            set.insert(key(v, o));
        }
    }
    set.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::default_pattern;

    #[test]
    fn zero_strain_and_zero_displacement_reproduce_the_reference() {
        let p = default_pattern("plain").unwrap();
        let e = Elimination::new(&p, &MacroStrain::ZERO).unwrap();
        for (v, x) in p.positions.iter().enumerate() {
            assert!((e.position(v, [0, 0], &Vector3::zeros()) - x).norm() < 1e-18);
            let shifted = e.position(v, [1, -1], &Vector3::zeros());
            assert!((shifted - (x + p.shift([1, -1]))).norm() < 1e-17);
        }
    }
}
