//! Periodic yarn patterns (`docs/yarn-model.md`, "Periodic yarn pattern").
//!
//! A [`Pattern`] is one rectangular tile of yarn repeating with periods p₁ (along ξ₁ = x) and p₂ (along ξ₂ = y).
//! Every vertex has exactly one outgoing and one incoming edge, so yarns are closed chains once periodicity is
//! taken into account, and edge `i` is the outgoing edge of vertex `i` (the `.pyp` file may list edges in any
//! order; the file order is kept in [`Pattern::edge_file_order`] so that a written file lists them the same way).
//!
//! Conventions (verified against the original data, see `docs/yarn-model.md`): the edge of vertex `i` runs from
//! `X[i]` to the copy of `X[end]` shifted by `(dx·p₁, dy·p₂, 0)`; its reference director and the material angle θ
//! of vertex `i` belong to that outgoing edge; rest curvature, rest twist and reference twist belong to the bending
//! stencil centred at vertex `i` (incoming edge, vertex, outgoing edge).

use nalgebra::Vector3;

pub mod pyp;

pub use pyp::{PatternError, PatternWarning, PeriodMismatch};

/// One periodic tile of yarn (the data of a `.pyp` file).
#[derive(Clone, Debug, PartialEq)]
pub struct Pattern {
    /// Periods (p₁, p₂) of the tile in the material plane (m).
    pub periods: [f64; 2],
    /// Yarn radius r (m).
    pub radius: f64,
    /// Reference position (ξ₁, ξ₂, h) of each vertex (m).
    pub positions: Vec<Vector3<f64>>,
    /// Material-frame angle θ of each vertex's outgoing edge (rad).
    pub theta: Vec<f64>,
    /// The outgoing edge of each vertex, indexed by its start vertex.
    pub edges: Vec<Edge>,
    /// Rest material curvature (κ̄₁, κ̄₂) of the bending stencil centred at each vertex (1/m).
    pub rest_curvature: Vec<[f64; 2]>,
    /// Rest twist m̄ of the stencil centred at each vertex (rad).
    pub rest_twist: Vec<f64>,
    /// Current reference twist τ of the stencil centred at each vertex (rad), kept continuous in time.
    pub ref_twist: Vec<f64>,
    /// Start vertices of the edges in the order a `.pyp` file lists them (a permutation of `0..n`).
    pub edge_file_order: Vec<usize>,
}

/// The outgoing edge of one vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct Edge {
    /// End vertex (its periodic copy shifted by `offset`).
    pub end: usize,
    /// Periodic offset (dx, dy) ∈ {−1, 0, 1}² of the end vertex's copy.
    pub offset: [i32; 2],
    /// Rest length l̄ (m).
    pub rest_length: f64,
    /// Unit reference director u, perpendicular to the edge (the reference frame's first vector).
    pub ref_director: Vector3<f64>,
}

impl Pattern {
    /// A pattern from its geometry: θ = 0, zero rest curvatures, rest twists and reference twists, edges listed in
    /// vertex order (generators then set the rest values from the shape).
    pub fn from_geometry(
        periods: [f64; 2],
        radius: f64,
        positions: Vec<Vector3<f64>>,
        edges: Vec<Edge>,
    ) -> Self {
        let n = positions.len();
        Pattern {
            periods,
            radius,
            positions,
            theta: vec![0.0; n],
            edges,
            rest_curvature: vec![[0.0; 2]; n],
            rest_twist: vec![0.0; n],
            ref_twist: vec![0.0; n],
            edge_file_order: (0..n).collect(),
        }
    }

    /// Number of vertices (= number of edges).
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True for a pattern without vertices.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The in-plane translation (dx·p₁, dy·p₂, 0) of a periodic offset.
    pub fn shift(&self, offset: [i32; 2]) -> Vector3<f64> {
        Vector3::new(
            offset[0] as f64 * self.periods[0],
            offset[1] as f64 * self.periods[1],
            0.0,
        )
    }

    /// The incoming edge's start vertex of every vertex (`prev[edges[i].end] = i`).
    ///
    /// Assumes a consistent pattern (exactly one incoming edge per vertex).
    pub fn prev(&self) -> Vec<usize> {
        let mut prev = vec![usize::MAX; self.len()];
        for (i, e) in self.edges.iter().enumerate() {
            prev[e.end] = i;
        }
        prev
    }

    /// The edge vector of vertex `i`'s outgoing edge: `X[end] + shift(offset) − X[i]`.
    pub fn edge_vector(&self, i: usize) -> Vector3<f64> {
        let e = &self.edges[i];
        self.positions[e.end] + self.shift(e.offset) - self.positions[i]
    }

    /// The closed yarns: each a list of vertices in the order the edges visit them, starting at the yarn's
    /// smallest vertex index; yarns sorted by that index.
    pub fn yarns(&self) -> Vec<Vec<usize>> {
        let n = self.len();
        let mut seen = vec![false; n];
        let mut yarns = Vec::new();
        for start in 0..n {
            if seen[start] {
                continue;
            }
            let mut yarn = Vec::new();
            let mut v = start;
            while !seen[v] {
                seen[v] = true;
                yarn.push(v);
                v = self.edges[v].end;
            }
            yarns.push(yarn);
        }
        yarns
    }

    /// Total rest yarn length Σ l̄ of the tile (m).
    pub fn total_rest_length(&self) -> f64 {
        self.edges.iter().map(|e| e.rest_length).sum()
    }

    /// Areal mass density ρ_A = ρ π r² (total rest yarn length) / (p₁ p₂) (kg/m²) for yarn density `rho` (kg/m³)
    /// (`docs/sampling.md`, "Material JSON").
    pub fn areal_density(&self, rho: f64) -> f64 {
        rho * std::f64::consts::PI * self.radius * self.radius * self.total_rest_length()
            / (self.periods[0] * self.periods[1])
    }

    /// Voronoi rest length l̄ᵢ = (l̄ of the incoming edge + l̄ of the outgoing edge) / 2 of every vertex.
    pub fn voronoi_lengths(&self) -> Vec<f64> {
        let prev = self.prev();
        (0..self.len())
            .map(|i| 0.5 * (self.edges[prev[i]].rest_length + self.edges[i].rest_length))
            .collect()
    }
}
