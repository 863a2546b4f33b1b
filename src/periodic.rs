//! Periodic-tile types (`docs/micro-solver.md`, section 1), shared by the rods, the contact broad
//! phase and the tile: an offset o = (o₁, o₂) names the periodic copy of the tile φ(ξ + (o₁p₁, o₂p₂)) = T_o φ(ξ),
//! with T_o: x ↦ R_o x + t_o a rigid motion (a translation by (o₁p₁, o₂p₂, 0) at zero macro strain, a rotation
//! about the cylinder axis for the bending maps).
//!
//! [`Placement`] maps a home-tile point to its copy; [`TileTransforms`] tabulates T_o for |oᵢ| ≤ [`MAX_OFFSET`];
//! [`TileImages`] is the list of copies the contact broad phase searches (closed under o ↦ −o, home first).

use nalgebra::{Matrix3, Vector3};

/// A periodic offset (o₁, o₂) of a tile copy.
pub type Offset = [i32; 2];

/// Errors of the periodic-image list.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PeriodicError {
    /// A list of images is not a valid set of rigid periodic copies (duplicate offset, not rigid, bad home).
    #[error("contact: invalid parameter: {0}")]
    Invalid(String),
    /// The list lacks the image with this periodic offset.
    #[error("contact broad phase: no tile image with offset ({}, {})", offset[0], offset[1])]
    MissingImage {
        /// the offset asked for
        offset: Offset,
    },
}

/// Negated offset.
pub fn neg(o: Offset) -> Offset {
    [-o[0], -o[1]]
}

/// True for the positive half of the offset lattice (dy > 0, or dy = 0 and dx > 0).
pub fn is_positive(o: Offset) -> bool {
    o[1] > 0 || (o[1] == 0 && o[0] > 0)
}

/// Where the periodic copies of a vertex are: `position(x, o)` maps a home-tile point to its copy at offset `o`,
/// and `rotation(o)` is the (constant) rotation part of that map, applied to directors and used to pull
/// gradients back to the home dofs.
pub trait Placement: Sync {
    /// The copy at offset `offset` of the home-tile point `x` (m).
    fn position(&self, x: &Vector3<f64>, offset: [i32; 2]) -> Vector3<f64>;
    /// The rotation part of the map to offset `offset`.
    fn rotation(&self, offset: [i32; 2]) -> Matrix3<f64>;
}

/// Copies as translations by (o₁p₁, o₂p₂, 0): the tile at zero macro strain.
#[derive(Clone, Copy, Debug)]
pub struct Translation {
    /// the periods (p₁, p₂) (m)
    pub periods: [f64; 2],
}

impl Placement for Translation {
    fn position(&self, x: &Vector3<f64>, o: [i32; 2]) -> Vector3<f64> {
        x + Vector3::new(
            o[0] as f64 * self.periods[0],
            o[1] as f64 * self.periods[1],
            0.0,
        )
    }
    fn rotation(&self, _o: [i32; 2]) -> Matrix3<f64> {
        Matrix3::identity()
    }
}

/// Largest periodic offset |oᵢ| a [`TileTransforms`] table holds: edges reach ±1 and contact images a further ±1.
pub const MAX_OFFSET: i32 = 3;

/// Rigid tile transforms T_o(x) = R_o x + t_o of the periodic copies, tabulated for offsets |oᵢ| ≤
/// [`MAX_OFFSET`] (`docs/micro-solver.md`, section 1: φ(ξ + (o₁p₁, o₂p₂)) = T_o φ(ξ)). Translations at zero
/// macro strain; rotations about the cylinder axis for the bending maps.
#[derive(Clone, Debug, PartialEq)]
pub struct TileTransforms {
    table: Vec<(Matrix3<f64>, Vector3<f64>)>,
}

impl TileTransforms {
    const SIDE: i32 = 2 * MAX_OFFSET + 1;

    /// The transforms given by `f(offset) = (R, t)`.
    pub fn from_fn(f: impl Fn([i32; 2]) -> (Matrix3<f64>, Vector3<f64>)) -> Self {
        let mut table = Vec::with_capacity((Self::SIDE * Self::SIDE) as usize);
        for dy in -MAX_OFFSET..=MAX_OFFSET {
            for dx in -MAX_OFFSET..=MAX_OFFSET {
                table.push(f([dx, dy]));
            }
        }
        TileTransforms { table }
    }

    /// Translations by (o₁p₁, o₂p₂, 0): the flat tile at zero macro strain.
    pub fn flat(periods: [f64; 2]) -> Self {
        let t = Translation { periods };
        Self::from_fn(|o| (Matrix3::identity(), t.position(&Vector3::zeros(), o)))
    }

    /// (R, t) of offset `o`. Offsets beyond [`MAX_OFFSET`] do not occur for validated patterns (a bug if they do).
    pub fn get(&self, o: [i32; 2]) -> &(Matrix3<f64>, Vector3<f64>) {
        assert!(
            o[0].abs() <= MAX_OFFSET && o[1].abs() <= MAX_OFFSET,
            "tile offset {o:?} beyond the tabulated range"
        );
        let k = (o[1] + MAX_OFFSET) * Self::SIDE + (o[0] + MAX_OFFSET);
        &self.table[k as usize]
    }

    /// The home tile and its 8 neighbours as broad-phase images.
    pub fn images(&self) -> TileImages {
        let mut v = vec![TileImage::identity()];
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (dx, dy) != (0, 0) {
                    let (r, t) = self.get([dx, dy]);
                    v.push(TileImage {
                        offset: [dx, dy],
                        rotation: *r,
                        translation: *t,
                    });
                }
            }
        }
        TileImages::new(v).expect("tile transforms are rigid and closed under negation")
    }
}

impl Placement for TileTransforms {
    #[inline]
    fn position(&self, x: &Vector3<f64>, o: [i32; 2]) -> Vector3<f64> {
        if o == [0, 0] {
            return *x;
        }
        let (r, t) = self.get(o);
        r * x + t
    }
    #[inline]
    fn rotation(&self, o: [i32; 2]) -> Matrix3<f64> {
        if o == [0, 0] {
            return Matrix3::identity();
        }
        self.get(o).0
    }
}

/// One periodic copy of the tile: the rigid motion x ↦ R x + t that maps the tile onto its copy at offset
/// (dx, dy) (`docs/micro-solver.md`: φ(ξ + (dx p₁, dy p₂)) = T φ(ξ)).
#[derive(Clone, Debug, PartialEq)]
pub struct TileImage {
    /// Periodic offset (dx, dy) of the copy.
    pub offset: [i32; 2],
    /// Rotation R (orthonormal, det +1).
    pub rotation: Matrix3<f64>,
    /// Translation t.
    pub translation: Vector3<f64>,
}

impl TileImage {
    /// The home tile (offset (0, 0), identity).
    pub fn identity() -> Self {
        TileImage {
            offset: [0, 0],
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// The flat copy at `offset`: a translation by (dx p₁, dy p₂, 0).
    pub fn flat(offset: [i32; 2], periods: [f64; 2]) -> Self {
        TileImage {
            offset,
            rotation: Matrix3::identity(),
            translation: Vector3::new(
                offset[0] as f64 * periods[0],
                offset[1] as f64 * periods[1],
                0.0,
            ),
        }
    }

    /// T(x) = R x + t.
    #[inline]
    pub fn apply(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * x + self.translation
    }
}

/// The home tile and its periodic images; index 0 is always the home (offset (0, 0), identity). Closed under
/// o ↦ −o.
#[derive(Clone, Debug, PartialEq)]
pub struct TileImages {
    images: Vec<TileImage>,
}

impl TileImages {
    /// Checks and orders a list of tile images: offsets distinct, the home offset (0, 0) present with the identity
    /// transform, every offset's negative present, rotations orthonormal to 1e-9. The home moves to index 0, the
    /// others keep their order.
    pub fn new(images: Vec<TileImage>) -> Result<Self, PeriodicError> {
        let bad = |m: String| Err(PeriodicError::Invalid(m));
        for (i, a) in images.iter().enumerate() {
            if images[..i].iter().any(|b| b.offset == a.offset) {
                return bad(format!("duplicate tile image offset {:?}", a.offset));
            }
            let opposite = neg(a.offset);
            if !images.iter().any(|b| b.offset == opposite) {
                return Err(PeriodicError::MissingImage { offset: opposite });
            }
            let orth = (a.rotation.transpose() * a.rotation - Matrix3::identity()).norm();
            let rigid = orth <= 1e-9
                && a.rotation.determinant() > 0.0
                && a.translation.iter().all(|v| v.is_finite());
            if !rigid {
                return bad(format!("tile image {:?} is not a rigid motion", a.offset));
            }
        }
        let Some(home) = images.iter().position(|a| a.offset == [0, 0]) else {
            return Err(PeriodicError::MissingImage { offset: [0, 0] });
        };
        if images[home] != TileImage::identity() {
            return bad("the home tile image (0, 0) must be the identity".into());
        }
        let mut ordered = vec![images[home].clone()];
        ordered.extend(
            images
                .into_iter()
                .enumerate()
                .filter(|(i, _)| *i != home)
                .map(|(_, a)| a),
        );
        Ok(TileImages { images: ordered })
    }

    /// The home and its 8 neighbours of a flat tile with periods (p₁, p₂) (zero macro strain): translations by
    /// (dx p₁, dy p₂, 0), dx, dy ∈ {−1, 0, 1}.
    pub fn flat(periods: [f64; 2]) -> Self {
        let mut v = vec![TileImage::identity()];
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (dx, dy) != (0, 0) {
                    v.push(TileImage::flat([dx, dy], periods));
                }
            }
        }
        TileImages { images: v }
    }

    /// Number of images (the home included).
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// Whether there is no image.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }

    /// Image number `k`.
    pub fn get(&self, k: usize) -> &TileImage {
        &self.images[k]
    }

    /// The images in order (the home first).
    pub fn iter(&self) -> std::slice::Iter<'_, TileImage> {
        self.images.iter()
    }

    /// Index of the image with this offset.
    pub fn index_of(&self, offset: [i32; 2]) -> Option<usize> {
        self.images.iter().position(|a| a.offset == offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_are_validated() {
        let per = [1.0, 2.0];
        let mut v: Vec<TileImage> = TileImages::flat(per).iter().cloned().collect();
        assert!(TileImages::new(v.clone()).is_ok());
        v.retain(|im| im.offset != [-1, 0]);
        assert_eq!(
            TileImages::new(v.clone()),
            Err(PeriodicError::MissingImage { offset: [-1, 0] })
        );
        let w = vec![TileImage::flat([1, 0], per), TileImage::flat([-1, 0], per)];
        assert_eq!(
            TileImages::new(w),
            Err(PeriodicError::MissingImage { offset: [0, 0] })
        );
        let mut s = vec![
            TileImage::identity(),
            TileImage::flat([1, 0], per),
            TileImage::flat([-1, 0], per),
        ];
        s[1].rotation *= 2.0;
        assert!(TileImages::new(s).is_err());
        // home moves to the front
        let t = TileImages::new(vec![
            TileImage::flat([1, 0], per),
            TileImage::identity(),
            TileImage::flat([-1, 0], per),
        ])
        .unwrap();
        assert_eq!(t.get(0).offset, [0, 0]);
        assert_eq!(t.index_of([-1, 0]), Some(2));
    }
}
