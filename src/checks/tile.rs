//! Harness row for the whole-tile energy (`docs/derivative-harness.md`, section 1): every dof of a small generated pattern
//! at once, stretching + bending + twisting + contact, with the frames stored at the pattern's state.
//!
//! Reference: the plain sum of the stencils' generic reference twins over the same stencils and contact pairs.
//! Samples: the stored state itself; small perturbations (0.05 r, 0.1 rad); larger ones (0.2 r, θ shifted by up to
//! 2π). Scales: with n vertices, mean rest length l and K = k_s l + (B + GJ)/l + k_c l² (one stencil's energy of
//! a unit strain, curvature or contact overlap), value n K, gradient √n K/l, Hessian √n K/l² (norms over all
//! stencils). Inputs are scaled by r (positions) and 1 (angles). Contact is C¹ at ρ = 1: finite differences stay
//! below the smallest distance from a quadrature pair to the cut-off.

use crate::contact::pair_energy_reference;
use crate::contact::GaussLegendre;
use crate::diff::{Check, Differentiable, Scales, Vgh};
use crate::pattern::Pattern;
use crate::real::Real;
use crate::rod::bend_twist::bend_twist_reference;
use crate::rod::stretch::stretch_reference;
use crate::rod::{RodState, YarnMaterial};
use crate::tile::{Terms, Tile, Want};
use nalgebra::DMatrix;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// The whole-tile energy of one pattern as a function of all its dofs.
pub struct TileCheck {
    name: String,
    pattern: Pattern,
    material: YarnMaterial,
    frames: RodState,
    contacts: Vec<crate::tile::ContactPair>,
    rule: GaussLegendre,
}

impl TileCheck {
    /// A check on `pattern` with its contact pairs found at the pattern's state.
    pub fn new(name: &str, pattern: Pattern, material: &YarnMaterial) -> Self {
        let (frames, contacts, material) = {
            let (frames, tile, _) = Tile::at_rest_state(&pattern, material)
                .expect("the embedded harness patterns have finite positions");
            (frames, tile.contacts.clone(), tile.material.clone())
        };
        let rule = GaussLegendre::new(material.contact_quadrature);
        TileCheck {
            name: name.to_string(),
            pattern,
            material,
            frames,
            contacts,
            rule,
        }
    }

    fn tile(&self) -> Tile<'_> {
        let mut t = Tile::new(&self.pattern, &self.material);
        t.contacts = self.contacts.clone();
        t
    }
}

impl Differentiable for TileCheck {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn dim(&self) -> usize {
        4 * self.pattern.len()
    }
    fn cases(&self, requested: usize) -> usize {
        requested.min(24)
    }
    fn scales(&self) -> Scales {
        let n = self.pattern.len() as f64;
        let l = self
            .pattern
            .edges
            .iter()
            .map(|e| e.rest_length)
            .sum::<f64>()
            / n;
        let m = &self.material;
        let k = m.stretch_stiffness() * l
            + (m.bend_stiffness() + m.twist_stiffness()) / l
            + m.contact_stiffness * l * l;
        Scales {
            value: n * k,
            gradient: n.sqrt() * k / l,
            hessian: n.sqrt() * k / (l * l),
        }
    }
    fn input_scale(&self, i: usize) -> f64 {
        if i < 3 * self.pattern.len() {
            self.pattern.radius
        } else {
            1.0
        }
    }
    fn kink_distance_of(&self, x: &[f64], i: usize) -> f64 {
        if i >= 3 * self.pattern.len() {
            return f64::INFINITY;
        }
        contact_kink_distance(&self.tile(), x, &self.contacts, &self.rule)
    }
    fn reference<D: Real>(&self, y: &[D]) -> D {
        let tile = self.tile();
        let n = self.pattern.len();
        let pos = |v: usize, o: [i32; 2]| -> [D; 3] {
            let s = self.pattern.shift(o);
            [0, 1, 2].map(|c| y[3 * v + c].clone() + s[c])
        };
        reference_energy(&tile, &self.frames, &self.rule, &y[3 * n..], &pos)
    }
    fn fast(&self, y: &[f64]) -> Vgh {
        let n = self.dim();
        match self
            .tile()
            .evaluate(&self.frames, y, Want::Hessian, &Terms::ALL)
        {
            Ok(r) => Vgh {
                value: r.value(),
                hessian: r.dense_hessian(n).unwrap_or_else(|| DMatrix::zeros(n, n)),
                gradient: r.gradient.unwrap_or_else(|| nalgebra::DVector::zeros(n)),
            },
            Err(_) => Vgh {
                value: f64::NAN,
                gradient: nalgebra::DVector::from_element(n, f64::NAN),
                hessian: DMatrix::from_element(n, n, f64::NAN),
            },
        }
    }
    fn fast_value(&self, y: &[f64]) -> f64 {
        self.tile()
            .evaluate(&self.frames, y, Want::Value, &Terms::ALL)
            .map(|r| r.value())
            .unwrap_or(f64::NAN)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let mut y = Tile::dofs_of(&self.frames);
        let n = self.pattern.len();
        let r = self.pattern.radius;
        let (dx, dth, wind) = match i % 3 {
            0 => (0.0, 0.0, false),
            1 => (0.05 * r, 0.1, false),
            _ => (0.2 * r, 0.3, true),
        };
        for v in y.iter_mut().take(3 * n) {
            *v += rng.random_range(-dx..=dx);
        }
        for v in y.iter_mut().skip(3 * n) {
            *v += rng.random_range(-dth..=dth);
            if wind {
                *v += 2.0 * std::f64::consts::PI * rng.random_range(-1..=1) as f64;
            }
        }
        y
    }
}

/// Distance of the tile's positions `x` from the contact kinks: min over the contact pairs' quadrature node pairs
/// of |‖d_pq‖ − 2r| (the pair energy is only C¹ where a node distance crosses the contact diameter).
pub(super) fn contact_kink_distance(
    tile: &Tile,
    x: &[f64],
    contacts: &[crate::tile::ContactPair],
    rule: &GaussLegendre,
) -> f64 {
    let two_r = 2.0 * tile.pattern.radius;
    let mut gap = f64::INFINITY;
    for pair in contacts {
        let p = pair.points(tile).map(|(v, o)| tile.position(x, v, o));
        for &s in rule.nodes() {
            for &t in rule.nodes() {
                let d = (p[0] * (1.0 - s) + p[1] * s) - (p[2] * (1.0 - t) + p[3] * t);
                gap = gap.min((d.norm() - two_r).abs());
            }
        }
    }
    gap
}

/// The plain sum of the stencils' reference twins over a tile's stencils and contact pairs, with the world
/// position of every copy given by `pos(vertex, offset)` and the angles `theta` (shared with the micro rows).
pub(crate) fn reference_energy<D: Real>(
    tile: &Tile,
    frames: &RodState,
    rule: &GaussLegendre,
    theta: &[D],
    pos: &dyn Fn(usize, [i32; 2]) -> [D; 3],
) -> D {
    let p = tile.pattern;
    let m = &tile.material;
    let mut e = D::from(0.0);
    for (i, edge) in p.edges.iter().enumerate() {
        let mut x: Vec<D> = pos(i, [0, 0]).to_vec();
        x.extend(pos(edge.end, edge.offset));
        e += stretch_reference(&x, edge.rest_length, m.stretch_stiffness());
    }
    for (i, s) in tile.topology.stencils.iter().enumerate() {
        let mut x: Vec<D> = Vec::with_capacity(11);
        for k in 0..3 {
            x.extend(pos(s.vertices[k], s.offsets[k]));
        }
        x.push(theta[s.edges[0]].clone());
        x.push(theta[s.edges[1]].clone());
        let (_, _, fr) = frames.stencil(s, &tile.placement);
        e += bend_twist_reference(&x, &fr, &tile.bend_params(i, &Terms::ALL));
    }
    for pair in &tile.contacts {
        let mut x: Vec<D> = Vec::with_capacity(12);
        for (v, o) in pair.points(tile) {
            x.extend(pos(v, o));
        }
        e += pair_energy_reference(
            &x,
            p.edges[pair.a].rest_length,
            p.edges[pair.b].rest_length,
            m.contact_stiffness,
            D::from(tile.contact_radius),
            rule,
        );
    }
    e
}

/// The whole-tile rows: built from the embedded generated patterns (no external data needed).
pub fn diff_checks() -> Vec<Box<dyn Check>> {
    let m = YarnMaterial::default();
    let patterns = crate::generate::harness_patterns();
    // the bending-discretisation variant (docs/yarn-parameters.md) on the first pattern: the rest-curvature conversion and
    // the form's kernels assembled into a tile
    let sin = YarnMaterial {
        bending: crate::rod::BendingForm::Sin,
        ..m.clone()
    };
    let variant = patterns.first().map(|(name, p)| {
        Box::new(TileCheck::new(
            &format!("tile[{name}; sin bending]"),
            p.clone(),
            &sin,
        )) as Box<dyn Check>
    });
    patterns
        .into_iter()
        .map(|(name, p)| {
            Box::new(TileCheck::new(&format!("tile[{name}]"), p, &m)) as Box<dyn Check>
        })
        .chain(variant)
        .collect()
}
