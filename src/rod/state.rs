//! Rods on a periodic pattern: the state the solver carries between accepted steps (positions, angles, the
//! time-parallel reference frames and the continuous reference twists), the stencils it is cut into, and the
//! rest values measured from a state (`docs/yarn-model.md`, "Discrete elastic rods").
//!
//! At zero macro strain a periodic copy of vertex v at offset o sits at X_v + (o₁p₁, o₂p₂, 0) and carries the same
//! reference director; [`Placement`] abstracts this so that later stages can place copies on a curved mid-surface.

use super::bend_twist::{kinematics, StencilFrames, StencilKinematics};
use super::frame::{continuous_twist, reference_twist_raw, transport};
use crate::pattern::Pattern;
use crate::periodic::{neg, Placement, Translation};
use nalgebra::Vector3;

/// The vertices and image offsets of one bending+twisting stencil centred at vertex `i`:
/// (previous vertex, its offset), (i, [0, 0]), (next vertex, its offset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StencilDofs {
    /// previous vertex, centre vertex i, next vertex
    pub vertices: [usize; 3],
    /// the image offset of each of the three vertices
    pub offsets: [[i32; 2]; 3],
    /// The edges (= their start vertices) carrying θ⁰ and θ¹.
    pub edges: [usize; 2],
}

/// Topology of the rod network of a pattern: the bending stencil of every vertex.
#[derive(Clone, Debug)]
pub struct RodTopology {
    /// one stencil per vertex, indexed by its centre vertex
    pub stencils: Vec<StencilDofs>,
}

impl RodTopology {
    /// The stencils of pattern `p`.
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
    /// one and continue every reference twist by its change (`docs/yarn-model.md`: frames are updated in time).
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
