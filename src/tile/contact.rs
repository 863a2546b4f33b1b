//! Contact part of the tile energy: the Kaldor pair kernel (`crate::contact`) summed over the tile's contact pairs
//! (`docs/yarn-model.md`, "Yarn-yarn contact").

use super::{Tile, Want};
use crate::contact::ccd::{crossings_between, Crossing};
use crate::contact::{tile_segments, BroadPhase, ContactError, PairKernel, SegmentTopology};
use crate::pattern::Pattern;
use crate::rod::{RodState, YarnMaterial};
use nalgebra::{DVector, Vector3};
use rayon::prelude::*;

/// Segment `a` (the outgoing edge of vertex `a` in the home tile) against segment `b` in the periodic image at
/// offset `image`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ContactPair {
    /// the home segment (its start vertex)
    pub a: usize,
    /// the other segment (its start vertex)
    pub b: usize,
    /// the periodic offset of `b`'s image
    pub image: [i32; 2],
}

impl ContactPair {
    /// (vertex, offset) of the four points (x_a0, x_a1, x_b0, x_b1).
    pub fn points(&self, tile: &Tile) -> [(usize, [i32; 2]); 4] {
        let ea = &tile.pattern.edges[self.a];
        let eb = &tile.pattern.edges[self.b];
        let o = self.image;
        [
            (self.a, [0, 0]),
            (ea.end, ea.offset),
            (self.b, o),
            (eb.end, [o[0] + eb.offset[0], o[1] + eb.offset[1]]),
        ]
    }
}

/// Sum the pair energies (weight × k_c) into the gradient and Hessian triplets; returns the contact energy.
pub(super) fn assemble(
    tile: &Tile,
    y: &[f64],
    want: Want,
    weight: f64,
    grad: &mut Option<DVector<f64>>,
    trip: &mut Option<Vec<(usize, usize, f64)>>,
) -> Result<f64, ContactError> {
    let m = &tile.material;
    let kernel = PairKernel::new(
        m.contact_stiffness * weight,
        tile.contact_radius,
        m.contact_quadrature,
    )?;
    // pairs beyond the cutoff contribute nothing: only the others carry a (large) local block
    let locals: Vec<Result<Option<super::Local<12>>, ContactError>> = tile
        .contacts
        .par_iter()
        .map(|pair| {
            let pts = pair.points(tile);
            let x: [Vector3<f64>; 4] = pts.map(|(v, o)| tile.position(y, v, o));
            if kernel.beyond_cutoff(&x) {
                return Ok(None);
            }
            let la = tile.pattern.edges[pair.a].rest_length;
            let lb = tile.pattern.edges[pair.b].rest_length;
            if want == Want::Value {
                Ok(Some(super::Local {
                    value: kernel.value(&x, la, lb)?,
                    g: Default::default(),
                    h: Default::default(),
                }))
            } else {
                let r = kernel.value_gradient_hessian(&x, la, lb)?;
                Ok(Some(super::Local {
                    value: r.value,
                    g: r.gradient,
                    h: r.hessian,
                }))
            }
        })
        .collect();
    let mut total = 0.0;
    for (pair, l) in tile.contacts.iter().zip(locals) {
        let Some(l) = l? else {
            continue;
        };
        if l.value == 0.0 && want == Want::Value {
            continue;
        }
        total += l.value;
        if want != Want::Value && l.g.iter().any(|&v| v != 0.0) {
            tile.scatter_positions(&pair.points(tile), &[], &l, grad, trip);
        }
    }
    Ok(total)
}

/// The contact energy alone ([`assemble`] with `Want::Value`): the same pair values summed in the same order.
pub(super) fn assemble_value(tile: &Tile, y: &[f64], weight: f64) -> Result<f64, ContactError> {
    let m = &tile.material;
    let kernel = PairKernel::new(
        m.contact_stiffness * weight,
        tile.contact_radius,
        m.contact_quadrature,
    )?;
    let values: Vec<Result<f64, ContactError>> = tile
        .contacts
        .par_iter()
        .map(|pair| {
            let x: [Vector3<f64>; 4] = pair.points(tile).map(|(v, o)| tile.position(y, v, o));
            if kernel.beyond_cutoff(&x) {
                return Ok(0.0);
            }
            let la = tile.pattern.edges[pair.a].rest_length;
            let lb = tile.pattern.edges[pair.b].rest_length;
            kernel.value(&x, la, lb)
        })
        .collect();
    let mut total = 0.0;
    for v in values {
        let v = v?;
        if v != 0.0 {
            total += v;
        }
    }
    Ok(total)
}

/// Broad-phase margin of [`Tile::at_rest_state`] in units of the yarn radius.
pub const DEFAULT_MARGIN: f64 = 0.5;

impl<'a> Tile<'a> {
    /// The pattern's own rod state, a tile on it with its contact pairs found there (margin
    /// [`DEFAULT_MARGIN`]·r), and the state's dofs: the set-up every evaluation at a pattern's stored state needs.
    pub fn at_rest_state(
        pattern: &'a Pattern,
        material: &YarnMaterial,
    ) -> Result<(RodState, Self, Vec<f64>), ContactError> {
        let state = RodState::from_pattern(pattern);
        let mut tile = Tile::new(pattern, material);
        tile.update_contacts(&state.positions, DEFAULT_MARGIN * pattern.radius)?;
        let y = Tile::dofs_of(&state);
        Ok((state, tile, y))
    }

    /// Find the contact pairs of the tile at `positions` with the BVH broad phase (`crate::contact::broad`): every
    /// pair of segments closer than 2r + `margin` that is not excluded along its yarn, each physical pair once.
    /// The list stays complete while no vertex moves by more than `margin / 2`.
    pub fn update_contacts(
        &mut self,
        positions: &[Vector3<f64>],
        margin: f64,
    ) -> Result<(), ContactError> {
        let images = self.placement.images();
        let segments = tile_segments(self.pattern, positions, &images)?;
        let broad = BroadPhase::new(
            &segments,
            SegmentTopology::from_pattern(self.pattern),
            images.clone(),
            self.contact_radius,
            margin,
            self.material.contact_exclusion,
        )?;
        self.contacts = broad
            .candidates()
            .into_iter()
            .map(|c| ContactPair {
                a: c.a,
                b: c.b,
                image: images.get(c.image).offset,
            })
            .collect();
        Ok(())
    }

    /// The yarn centre-line crossings while the dofs move linearly from `y0` to `y1` at this tile's strain
    /// ([`crate::contact::ccd`]): pairs excluded along each yarn as the contact is, centre lines met when closer
    /// than 1e-6 r.
    pub fn crossings(&self, y0: &[f64], y1: &[f64]) -> Result<Vec<Crossing>, ContactError> {
        self.crossings_to(y0, self, y1)
    }

    /// [`Tile::crossings`] for a motion from dofs `y0` on this tile to dofs `y1` on `other`, a tile of the same
    /// pattern at another strain (its own periodic copies and dof map; [`crossings_between`]): every copy of
    /// every vertex moves on the straight line between its two world positions.
    pub fn crossings_to(
        &self,
        y0: &[f64],
        other: &Tile,
        y1: &[f64],
    ) -> Result<Vec<Crossing>, ContactError> {
        let images = self.placement.images();
        let before = tile_segments(self.pattern, &self.home_positions(y0), &images)?;
        let images_after = other.placement.images();
        let after = tile_segments(other.pattern, &other.home_positions(y1), &images_after)?;
        crossings_between(
            (&before, &images),
            (&after, &images_after),
            SegmentTopology::from_pattern(self.pattern),
            // neighbouring segments share a vertex: they always "meet"
            self.material.contact_exclusion.max(1),
            1e-6 * self.contact_radius,
        )
    }

    /// Number of contact pairs with a non-zero energy at dofs `y`.
    pub fn active_contact_pairs(&self, y: &[f64]) -> Result<usize, ContactError> {
        let m = &self.material;
        let kernel = PairKernel::new(1.0, self.contact_radius, m.contact_quadrature)?;
        let mut count = 0;
        for pair in &self.contacts {
            let x = pair.points(self).map(|(v, o)| self.position(y, v, o));
            if kernel.value(&x, 1.0, 1.0)? > 0.0 {
                count += 1;
            }
        }
        Ok(count)
    }
}

impl Tile<'_> {
    /// ∂E_contact/∂ρ and ∂(∇_y E_contact)/∂ρ (tile dofs) at dofs `y`, with ρ the contact radius
    /// ([`Tile::contact_radius`]) and k_c the material's: the pair kernels' radius derivatives
    /// ([`PairKernel::radius_derivatives`]) summed over the contact pairs, the position blocks turned into the dof
    /// frame as the gradient's are (docs/yarn-parameters.md: equilibrium sensitivities to the contact radius).
    pub fn contact_radius_derivatives(
        &self,
        y: &[f64],
    ) -> Result<(f64, DVector<f64>), ContactError> {
        let m = &self.material;
        let kernel = PairKernel::new(
            m.contact_stiffness,
            self.contact_radius,
            m.contact_quadrature,
        )?;
        let mut grad = Some(DVector::zeros(self.ndof()));
        let mut none = None;
        let mut total = 0.0;
        for pair in &self.contacts {
            let pts = pair.points(self);
            let x: [Vector3<f64>; 4] = pts.map(|(v, o)| self.position(y, v, o));
            let la = self.pattern.edges[pair.a].rest_length;
            let lb = self.pattern.edges[pair.b].rest_length;
            let d = kernel.radius_derivatives(&x, la, lb)?;
            if d.value == 0.0 && d.gradient.iter().all(|&v| v == 0.0) {
                continue;
            }
            total += d.value;
            let local = super::Local::<12> {
                value: d.value,
                g: d.gradient,
                h: Default::default(),
            };
            self.scatter_positions(&pts, &[], &local, &mut grad, &mut none);
        }
        Ok((total, grad.expect("set above")))
    }
}
