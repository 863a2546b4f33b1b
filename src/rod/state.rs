//! Rods on a periodic pattern: the state the solver carries between accepted steps (positions, angles, the
//! time-parallel reference frames and the continuous reference twists), the stencils it is cut into, and the
//! rest values measured from a state (`02-yarn-model.md`, "Discrete elastic rods").
//!
//! At zero macro strain a periodic copy of vertex v at offset o sits at X_v + (o₁p₁, o₂p₂, 0) and carries the same
//! reference director; [`Placement`] abstracts this so that later stages can place copies on a curved mid-surface.

use super::bend_twist::{kinematics, StencilFrames, StencilKinematics};
use super::frame::{continuous_twist, reference_twist_raw, transport};
use crate::pattern::Pattern;
use nalgebra::{Matrix3, Vector3};

/// Where the periodic copies of a vertex are: `position(x, o)` maps a home-tile point to its copy at offset `o`,
/// and `rotation(o)` is the (constant) rotation part of that map, applied to directors and used to pull
/// gradients back to the home dofs.
pub trait Placement: Sync {
    fn position(&self, x: &Vector3<f64>, offset: [i32; 2]) -> Vector3<f64>;
    fn rotation(&self, offset: [i32; 2]) -> Matrix3<f64>;
}

/// Copies as translations by (o₁p₁, o₂p₂, 0): the tile at zero macro strain.
#[derive(Clone, Copy, Debug)]
pub struct Translation {
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
/// [`MAX_OFFSET`] (`03-homogenization.md`, section 1: φ(ξ + (o₁p₁, o₂p₂)) = T_o φ(ξ)). Translations at zero
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
    pub fn images(&self) -> crate::contact::TileImages {
        let mut v = vec![crate::contact::TileImage::identity()];
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (dx, dy) != (0, 0) {
                    let (r, t) = self.get([dx, dy]);
                    v.push(crate::contact::TileImage {
                        offset: [dx, dy],
                        rotation: *r,
                        translation: *t,
                    });
                }
            }
        }
        crate::contact::TileImages::new(v)
            .expect("tile transforms are rigid and closed under negation")
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

/// Negated offset.
pub fn neg(o: [i32; 2]) -> [i32; 2] {
    [-o[0], -o[1]]
}

/// The vertices and image offsets of one bending+twisting stencil centred at vertex `i`:
/// (previous vertex, its offset), (i, [0, 0]), (next vertex, its offset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StencilDofs {
    pub vertices: [usize; 3],
    pub offsets: [[i32; 2]; 3],
    /// The edges (= their start vertices) carrying θ⁰ and θ¹.
    pub edges: [usize; 2],
}

/// Topology of the rod network of a pattern: the bending stencil of every vertex.
#[derive(Clone, Debug)]
pub struct RodTopology {
    pub stencils: Vec<StencilDofs>,
}

impl RodTopology {
    pub fn new(p: &Pattern) -> Self {
        let prev = p.prev();
        let stencils = (0..p.len())
            .map(|i| {
                let a = prev[i];
                StencilDofs {
                    vertices: [a, i, p.edges[i].end],
                    offsets: [neg(p.edges[a].offset), [0, 0], p.edges[i].offset],
                    edges: [a, i],
                }
            })
            .collect();
        RodTopology { stencils }
    }
}

/// The state of the rods between accepted steps.
#[derive(Clone, Debug, PartialEq)]
pub struct RodState {
    /// Vertex positions (home tile).
    pub positions: Vec<Vector3<f64>>,
    /// Material angle θ of each edge (indexed by its start vertex).
    pub theta: Vec<f64>,
    /// Unit tangent of each edge at this state.
    pub tangents: Vec<Vector3<f64>>,
    /// Reference director of each edge at this state (time-parallel transported).
    pub directors: Vec<Vector3<f64>>,
    /// Continuous reference twist of each stencil at this state.
    pub ref_twist: Vec<f64>,
}

impl RodState {
    /// The pattern's own state: its positions, angles, reference directors and stored reference twists.
    pub fn from_pattern(p: &Pattern) -> Self {
        let place = Translation { periods: p.periods };
        let tangents = edge_tangents(p, &p.positions, &place);
        RodState {
            positions: p.positions.clone(),
            theta: p.theta.clone(),
            tangents,
            directors: p.edges.iter().map(|e| e.ref_director).collect(),
            ref_twist: p.ref_twist.clone(),
        }
    }

    /// Positions and angles of stencil `s`, with its stored frames.
    pub fn stencil<P: Placement>(
        &self,
        s: &StencilDofs,
        place: &P,
    ) -> ([Vector3<f64>; 3], [f64; 2], StencilFrames) {
        let x = [0, 1, 2].map(|k| place.position(&self.positions[s.vertices[k]], s.offsets[k]));
        let r0 = place.rotation(s.offsets[0]);
        let (a, b) = (s.edges[0], s.edges[1]);
        let fr = StencilFrames::new(
            r0 * self.tangents[a],
            r0 * self.directors[a],
            self.tangents[b],
            self.directors[b],
            self.ref_twist[s.vertices[1]],
        );
        (x, [self.theta[a], self.theta[b]], fr)
    }

    /// Move to new positions and angles: transport every reference director from the current tangent to the new
    /// one and continue every reference twist by its change (`02-yarn-model.md`: frames are updated in time).
    pub fn advance<P: Placement>(
        &mut self,
        p: &Pattern,
        topo: &RodTopology,
        positions: Vec<Vector3<f64>>,
        theta: Vec<f64>,
        place: &P,
    ) {
        self.advance_between(p, topo, positions, theta, place, place)
    }

    /// [`advance`](Self::advance) while the tile transforms also change from `old` to `new` (a change of macro
    /// strain): the copies' stored frames are those of `old`, their new frames those of `new`, and the reference
    /// twists are continued across the change. The change must be small (each copy rotating by well under π);
    /// larger changes are made in steps.
    pub fn advance_between<P: Placement, Q: Placement>(
        &mut self,
        p: &Pattern,
        topo: &RodTopology,
        positions: Vec<Vector3<f64>>,
        theta: Vec<f64>,
        old: &P,
        place: &Q,
    ) {
        let tangents = edge_tangents(p, &positions, place);
        let directors: Vec<Vector3<f64>> = (0..p.len())
            .map(|j| {
                let u = transport(&self.tangents[j], &tangents[j], &self.directors[j]);
                // remove the round-off drift from unit length and orthogonality
                (u - tangents[j] * tangents[j].dot(&u)).normalize()
            })
            .collect();
        let ref_twist = topo
            .stencils
            .iter()
            .map(|s| {
                let (a, b) = (s.edges[0], s.edges[1]);
                let r_old = old.rotation(s.offsets[0]);
                let r0 = place.rotation(s.offsets[0]);
                let old = reference_twist_raw(
                    &(r_old * self.tangents[a]),
                    &(r_old * self.directors[a]),
                    &self.tangents[b],
                    &self.directors[b],
                );
                let new = reference_twist_raw(
                    &(r0 * tangents[a]),
                    &(r0 * directors[a]),
                    &tangents[b],
                    &directors[b],
                );
                continuous_twist(self.ref_twist[s.vertices[1]], old, new)
            })
            .collect();
        self.positions = positions;
        self.theta = theta;
        self.tangents = tangents;
        self.directors = directors;
        self.ref_twist = ref_twist;
    }

    /// Curvature and twist of every stencil at this state.
    pub fn kinematics<P: Placement>(
        &self,
        topo: &RodTopology,
        place: &P,
    ) -> Vec<StencilKinematics> {
        topo.stencils
            .iter()
            .map(|s| {
                let (x, th, fr) = self.stencil(s, place);
                kinematics(&x, th, &fr)
            })
            .collect()
    }
}

/// Unit tangents of every edge for the given vertex positions.
pub fn edge_tangents<P: Placement>(
    p: &Pattern,
    positions: &[Vector3<f64>],
    place: &P,
) -> Vec<Vector3<f64>> {
    p.edges
        .iter()
        .enumerate()
        .map(|(i, e)| (place.position(&positions[e.end], e.offset) - positions[i]).normalize())
        .collect()
}

/// The reference twist of every stencil computed afresh from the pattern's reference directors (raw angles in
/// (−π, π]); compare with the stored `*RefT` modulo 2π.
pub fn raw_reference_twists(p: &Pattern) -> Vec<f64> {
    let place = Translation { periods: p.periods };
    let topo = RodTopology::new(p);
    let tangents = edge_tangents(p, &p.positions, &place);
    topo.stencils
        .iter()
        .map(|s| {
            let (a, b) = (s.edges[0], s.edges[1]);
            reference_twist_raw(
                &tangents[a],
                &p.edges[a].ref_director,
                &tangents[b],
                &p.edges[b].ref_director,
            )
        })
        .collect()
}

/// Set the rest values to the current shape (Algorithm C1 step 1, "the rest shape equals the shape"): rest
/// lengths from the edge lengths, rest curvatures and rest twists from the stencils' current values (with the
/// pattern's reference directors and reference twists).
pub fn set_rest_to_current(p: &mut Pattern) {
    let state = RodState::from_pattern(p);
    let topo = RodTopology::new(p);
    let place = Translation { periods: p.periods };
    let kin = state.kinematics(&topo, &place);
    for i in 0..p.len() {
        p.edges[i].rest_length = p.edge_vector(i).norm();
        p.rest_curvature[i] = kin[i].curvature;
        p.rest_twist[i] = kin[i].twist;
    }
}
