//! Periodic broad phase for yarn–yarn contact (`docs/yarn-model.md`, "Yarn-yarn contact";
//! tile transforms in `docs/micro-solver.md`, section 1).
//!
//! Segment i of a tile is the outgoing edge of vertex i of a [`Pattern`], given by its two world endpoints (the end
//! is the periodic copy of the end vertex, see [`tile_segments`]). The tile repeats under rigid tile transforms
//! T_o: x ↦ R x + t, one per periodic offset o = (dx, dy) ([`TileImage`]; at zero macro strain R = I and
//! t = (dx p₁, dy p₂, 0), on a bent surface R is a rotation about the cylinder axis). A candidate
//! [`CandidatePair`] (a, b, image) pairs the home segment a with the image T_o(b) of segment b.
//!
//! **Each physical pair exactly once.** (a, b in T_o) and (b, a in T_o⁻¹ = T_−o) are the same pair. The
//! candidates use the canonical representative: o = 0 with a < b (a segment never pairs with itself at home), or
//! o in the positive half-lattice (dy > 0, or dy = 0 and dx > 0) with any a, b — including a = b, a segment and its
//! own image. So the image list must be closed under o ↦ −o ([`TileImages::new`] checks it) and only the home and
//! the positive images are queried.
//!
//! **Exclusion along the yarn.** A closed yarn of the tile with m segments and winding W (the sum of its edge
//! offsets) unrolls into an infinite chain of segments (W ≠ 0: it runs through the tile copies, segment k of chain
//! copy n sits in tile cell o_k + nW, o_k the summed offsets of the edges before it) or into one closed loop per
//! tile copy (W = 0). Home segment a (position k_a along its yarn) and segment b (position k_b) in image o lie on
//! the same physical yarn iff o − o_{k_b} + o_{k_a} = nW for an integer n; their separation along the yarn is then
//! |k_b − k_a + n m| segments (W ≠ 0), or the shorter way around the loop min(|Δ|, m − |Δ|) (W = 0). Pairs with a
//! separation of at most `exclusion` segments (`YarnMaterial::contact_exclusion`, "3 neighbouring segments on each
//! side") are skipped. Segments of different yarns, or of different copies of one yarn (o − o_{k_b} + o_{k_a} not a
//! multiple of W, e.g. the neighbouring parallel copy of a weft yarn), are never excluded. This is the method's
//! "shorter way along the closed yarn" measured on the physical (unrolled) yarn, so a segment near the tile border
//! and its neighbour's copy across the border count as neighbours. Separation is counted in segments (the unit of
//! `contact_exclusion`), not in metres.
//!
//! **BVH and its contract.** [`BroadPhase`] keeps a parry3d-f64 [`Bvh`] over the home segments' bounding boxes,
//! inflated by r + margin/2 (capsules of radius r + margin/2), and queries it with the equally inflated boxes of the
//! image segments. Every pair whose segments are closer than 2r + margin is returned (two capsules that intersect
//! have intersecting boxes); pairs farther apart may be returned too (boxes are conservative). Hence a candidate
//! list computed at positions X stays complete — it contains every pair closer than 2r, i.e. every pair with a
//! non-zero energy — for all positions within margin/2 of X at every vertex (each segment and each rigid image of
//! it then moves by at most margin/2, so a distance changes by at most the margin), as long as the tile transforms
//! are unchanged. After [`BroadPhase::refit`] with new positions the tree is valid for them, but the candidate list
//! is not updated: call [`BroadPhase::candidates`] again. For new tile transforms (another macro strain) build a
//! new broad phase. Refitting keeps the tree topology; after large rearrangements a fresh [`BroadPhase::new`] gives
//! a tighter tree.
//!
//! Only the images passed in are searched: the home and its 8 neighbours suffice as long as no segment comes
//! within 2r + margin of a copy two or more tiles away (periods larger than the tile's extent across them plus
//! 2r + margin, which holds for every realistic pattern and strain); pass more images otherwise.

use super::{segment_distance_squared, ContactError};
use crate::pattern::{Edge, Pattern};
use crate::periodic::{is_positive, TileImage, TileImages};
use nalgebra::Vector3;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector as PVector;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};

/// A segment given by its two world endpoints (start, end).
pub type Segment = [Vector3<f64>; 2];

/// World segments of a tile: segment i runs from `positions[i]` to the image of `positions[end]` under the tile
/// transform of the edge's offset (at zero strain: `positions[end] + (dx p₁, dy p₂, 0)`).
pub fn tile_segments(
    pattern: &Pattern,
    positions: &[Vector3<f64>],
    images: &TileImages,
) -> Result<Vec<Segment>, ContactError> {
    if positions.len() != pattern.len() {
        return Err(ContactError::InvalidParameter(format!(
            "{} positions for a pattern of {} vertices",
            positions.len(),
            pattern.len()
        )));
    }
    pattern
        .edges
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let k = images
                .index_of(e.offset)
                .ok_or(ContactError::MissingImage { offset: e.offset })?;
            Ok([positions[i], images.get(k).apply(&positions[e.end])])
        })
        .collect()
}

/// Yarn membership of every segment, for the exclusion rule (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentTopology {
    /// yarn index of each segment
    yarn: Vec<usize>,
    /// position k of each segment along its yarn (0 at the yarn's first vertex)
    position: Vec<usize>,
    /// summed offsets o_k of the yarn's edges before segment k (the tile cell of its start in the unrolled chain)
    cumulative: Vec<[i32; 2]>,
    /// number of segments m of each yarn
    yarn_len: Vec<usize>,
    /// winding W of each yarn (sum of its edge offsets)
    winding: Vec<[i32; 2]>,
}

impl SegmentTopology {
    /// The yarns of a pattern ([`Pattern::yarns`]) with positions and summed offsets along each.
    pub fn from_pattern(pattern: &Pattern) -> Self {
        Self::from_edges(&pattern.edges)
    }

    /// The same from the edges alone (edge i is the outgoing edge of vertex i).
    pub fn from_edges(edges: &[Edge]) -> Self {
        let n = edges.len();
        let mut t = SegmentTopology {
            yarn: vec![usize::MAX; n],
            position: vec![0; n],
            cumulative: vec![[0, 0]; n],
            yarn_len: Vec::new(),
            winding: Vec::new(),
        };
        for start in 0..n {
            if t.yarn[start] != usize::MAX {
                continue;
            }
            let y = t.yarn_len.len();
            let (mut v, mut k, mut o) = (start, 0, [0i32, 0]);
            while t.yarn[v] == usize::MAX {
                t.yarn[v] = y;
                t.position[v] = k;
                t.cumulative[v] = o;
                o = [o[0] + edges[v].offset[0], o[1] + edges[v].offset[1]];
                k += 1;
                v = edges[v].end;
            }
            t.yarn_len.push(k);
            t.winding.push(o);
        }
        t
    }

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.yarn.len()
    }

    /// Whether there is no segment.
    pub fn is_empty(&self) -> bool {
        self.yarn.is_empty()
    }

    /// Yarn of segment `s`.
    pub fn yarn(&self, s: usize) -> usize {
        self.yarn[s]
    }

    /// Number of yarns.
    pub fn yarn_count(&self) -> usize {
        self.yarn_len.len()
    }

    /// Winding W of yarn `y` (the sum of its edge offsets; zero for a loop closed inside one tile copy).
    pub fn winding(&self, y: usize) -> [i32; 2] {
        self.winding[y]
    }

    /// Separation in segments along the physical yarn between home segment `a` and segment `b` in the tile copy at
    /// `offset`; `None` when they are not on the same physical yarn (see the module documentation).
    pub fn separation(&self, a: usize, b: usize, offset: [i32; 2]) -> Option<usize> {
        let y = self.yarn[a];
        if self.yarn[b] != y {
            return None;
        }
        let (oa, ob) = (self.cumulative[a], self.cumulative[b]);
        let delta = [offset[0] - ob[0] + oa[0], offset[1] - ob[1] + oa[1]];
        let m = self.yarn_len[y] as i64;
        let dk = self.position[b] as i64 - self.position[a] as i64;
        let w = self.winding[y];
        if w == [0, 0] {
            if delta != [0, 0] {
                return None;
            }
            let d = dk.rem_euclid(m);
            return Some(d.min(m - d) as usize);
        }
        // delta = n W for an integer n?
        if delta[0] as i64 * w[1] as i64 != delta[1] as i64 * w[0] as i64 {
            return None;
        }
        let ww = w[0] as i64 * w[0] as i64 + w[1] as i64 * w[1] as i64;
        let dw = delta[0] as i64 * w[0] as i64 + delta[1] as i64 * w[1] as i64;
        if dw % ww != 0 {
            return None;
        }
        let n = dw / ww;
        Some((dk + n * m).unsigned_abs() as usize)
    }

    /// True when the pair is excluded: same physical yarn and at most `exclusion` segments apart (this includes a
    /// segment with itself at home).
    pub fn excluded(&self, a: usize, b: usize, offset: [i32; 2], exclusion: usize) -> bool {
        matches!(self.separation(a, b, offset), Some(s) if s <= exclusion)
    }
}

/// A candidate contact pair: home segment `a` against segment `b` mapped by tile image `image` (an index into the
/// [`TileImages`]). Canonical: image 0 (home) with a < b, or an image with a positive offset.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CandidatePair {
    /// the home segment (index of its start vertex)
    pub a: usize,
    /// the other segment, before the image's map
    pub b: usize,
    /// the tile image of `b` (index into the [`TileImages`])
    pub image: usize,
}

impl CandidatePair {
    /// The kernel input (x_a0, x_a1, T(x_b0), T(x_b1)).
    pub fn points(&self, segments: &[Segment], images: &TileImages) -> [Vector3<f64>; 4] {
        let t = images.get(self.image);
        let (sa, sb) = (&segments[self.a], &segments[self.b]);
        [sa[0], sa[1], t.apply(&sb[0]), t.apply(&sb[1])]
    }
}

fn to_p(v: &Vector3<f64>) -> PVector {
    PVector::new(v.x, v.y, v.z)
}

/// Axis-aligned box of a capsule: the segment's box grown by `inflate` on every side.
fn capsule_aabb(p0: &Vector3<f64>, p1: &Vector3<f64>, inflate: f64) -> Aabb {
    let lo = p0.inf(p1).add_scalar(-inflate);
    let hi = p0.sup(p1).add_scalar(inflate);
    Aabb::new(to_p(&lo), to_p(&hi))
}

fn check_finite(segments: &[Segment]) -> Result<(), ContactError> {
    if segments
        .iter()
        .all(|s| s.iter().all(|p| p.iter().all(|v| v.is_finite())))
    {
        Ok(())
    } else {
        Err(ContactError::NonFinite)
    }
}

/// The images to query: the home and the positive half (see the module documentation).
fn queried_images(images: &TileImages) -> impl Iterator<Item = (usize, &TileImage)> {
    images
        .iter()
        .enumerate()
        .filter(|(k, im)| *k == 0 || is_positive(im.offset))
}

/// The BVH broad phase of one tile (see the module documentation for the contract).
#[derive(Clone)]
pub struct BroadPhase {
    bvh: Bvh,
    workspace: BvhWorkspace,
    segments: Vec<Segment>,
    topology: SegmentTopology,
    images: TileImages,
    radius: f64,
    margin: f64,
    exclusion: usize,
}

impl BroadPhase {
    /// Builds the BVH over `segments` (boxes inflated by r + margin/2). `exclusion` is the number of excluded
    /// neighbour segments on each side along a yarn.
    pub fn new(
        segments: &[Segment],
        topology: SegmentTopology,
        images: TileImages,
        radius: f64,
        margin: f64,
        exclusion: usize,
    ) -> Result<Self, ContactError> {
        if topology.len() != segments.len() {
            return Err(ContactError::InvalidParameter(format!(
                "{} segments for a topology of {}",
                segments.len(),
                topology.len()
            )));
        }
        if !(radius.is_finite() && radius > 0.0 && margin.is_finite() && margin >= 0.0) {
            return Err(ContactError::InvalidParameter(format!(
                "broad phase radius {radius} / margin {margin}"
            )));
        }
        check_finite(segments)?;
        let inflate = radius + 0.5 * margin;
        let boxes: Vec<Aabb> = segments
            .iter()
            .map(|s| capsule_aabb(&s[0], &s[1], inflate))
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes);
        Ok(BroadPhase {
            bvh,
            workspace: BvhWorkspace::default(),
            segments: segments.to_vec(),
            topology,
            images,
            radius,
            margin,
            exclusion,
        })
    }

    /// Moves the segments to new positions and refits the tree (same topology, exact new boxes). The candidate
    /// list is not recomputed: call [`BroadPhase::candidates`] again.
    pub fn refit(&mut self, segments: &[Segment]) -> Result<(), ContactError> {
        if segments.len() != self.segments.len() {
            return Err(ContactError::InvalidParameter(format!(
                "refit with {} segments, built with {}",
                segments.len(),
                self.segments.len()
            )));
        }
        check_finite(segments)?;
        let inflate = self.inflation();
        for (i, s) in segments.iter().enumerate() {
            self.bvh
                .insert_or_update_partially(capsule_aabb(&s[0], &s[1], inflate), i as u32, 0.0);
        }
        self.bvh.refit(&mut self.workspace);
        self.segments.copy_from_slice(segments);
        Ok(())
    }

    /// The canonical candidate pairs at the current positions, sorted by (a, b, image).
    pub fn candidates(&self) -> Vec<CandidatePair> {
        let inflate = self.inflation();
        let mut out = Vec::new();
        for (k, im) in queried_images(&self.images) {
            for (b, s) in self.segments.iter().enumerate() {
                let (p0, p1) = (im.apply(&s[0]), im.apply(&s[1]));
                let query = capsule_aabb(&p0, &p1, inflate);
                for a in self.bvh.intersect_aabb(&query) {
                    let a = a as usize;
                    if k == 0 && a >= b {
                        continue;
                    }
                    if self.topology.excluded(a, b, im.offset, self.exclusion) {
                        continue;
                    }
                    out.push(CandidatePair { a, b, image: k });
                }
            }
        }
        out.sort_unstable();
        out
    }

    /// Current segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The tile images.
    pub fn images(&self) -> &TileImages {
        &self.images
    }

    /// The segments' topology.
    pub fn topology(&self) -> &SegmentTopology {
        &self.topology
    }

    /// The yarn radius r (m).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The broad-phase margin (m): pairs closer than 2r + margin are candidates.
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// Growth of every segment box: r + margin/2.
    pub fn inflation(&self) -> f64 {
        self.radius + 0.5 * self.margin
    }
}

/// Brute-force O(n² · images) reference: every canonical pair (not excluded) whose segments are closer than
/// `cutoff` (exact segment–segment distance), sorted like [`BroadPhase::candidates`].
pub fn brute_force_candidates(
    segments: &[Segment],
    topology: &SegmentTopology,
    images: &TileImages,
    cutoff: f64,
    exclusion: usize,
) -> Vec<CandidatePair> {
    let mut out = Vec::new();
    for (k, im) in queried_images(images) {
        for (b, sb) in segments.iter().enumerate() {
            let (q0, q1) = (im.apply(&sb[0]), im.apply(&sb[1]));
            for (a, sa) in segments.iter().enumerate() {
                if k == 0 && a >= b {
                    continue;
                }
                let (d2, _, _) = segment_distance_squared(&sa[0], &sa[1], &q0, &q1);
                if d2 < cutoff * cutoff && !topology.excluded(a, b, im.offset, exclusion) {
                    out.push(CandidatePair { a, b, image: k });
                }
            }
        }
    }
    out.sort_unstable();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::synthetic_weave;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::collections::HashSet;

    fn straight_yarn(m: usize, rotate: usize) -> Vec<Edge> {
        // one yarn along x with m segments; vertex index v = (i + rotate) mod m for position i along x
        let mut edges = vec![
            Edge {
                end: 0,
                offset: [0, 0],
                rest_length: 1.0,
                ref_director: Vector3::z(),
            };
            m
        ];
        for i in 0..m {
            let v = (i + rotate) % m;
            let next = (i + 1 + rotate) % m;
            edges[v].end = next;
            edges[v].offset = if i + 1 == m { [1, 0] } else { [0, 0] };
        }
        edges
    }

    #[test]
    fn separation_through_the_periodic_boundary() {
        let m = 10;
        for rotate in [0, 3, 9] {
            let t = SegmentTopology::from_edges(&straight_yarn(m, rotate));
            let v = |i: usize| (i + rotate) % m; // vertex of x-position i
            assert_eq!(t.winding(0), [1, 0]);
            // the last segment and the first, at home: the whole tile apart
            assert_eq!(t.separation(v(m - 1), v(0), [0, 0]), Some(m - 1));
            // the first segment's copy in the next tile follows the last segment directly
            assert_eq!(t.separation(v(m - 1), v(0), [1, 0]), Some(1));
            assert_eq!(t.separation(v(0), v(m - 1), [-1, 0]), Some(1));
            assert_eq!(t.separation(v(2), v(m - 2), [-1, 0]), Some(4));
            // a segment and its own copy one period along the yarn: m apart
            assert_eq!(t.separation(v(4), v(4), [1, 0]), Some(m));
            assert_eq!(t.separation(v(4), v(4), [0, 0]), Some(0));
            // the parallel copy of the yarn in the next row is another physical yarn
            assert_eq!(t.separation(v(4), v(4), [0, 1]), None);
            assert_eq!(t.separation(v(4), v(5), [1, 1]), None);
            assert!(t.excluded(v(m - 1), v(0), [1, 0], 3));
            assert!(!t.excluded(v(m - 1), v(0), [0, 0], 3));
            // symmetry: (a, b, o) and (b, a, −o)
            for a in 0..m {
                for b in 0..m {
                    for o in [[0, 0], [1, 0], [-1, 0], [1, 1], [0, -1]] {
                        assert_eq!(t.separation(a, b, o), t.separation(b, a, [-o[0], -o[1]]));
                    }
                }
            }
        }
    }

    #[test]
    fn separation_on_a_closed_loop_and_across_yarns() {
        // a loop of 8 inside the tile (W = 0) and a second yarn
        let mut edges: Vec<Edge> = (0..8)
            .map(|i| Edge {
                end: (i + 1) % 8,
                offset: [0, 0],
                rest_length: 1.0,
                ref_director: Vector3::z(),
            })
            .collect();
        edges.extend(straight_yarn(5, 0).into_iter().map(|mut e| {
            e.end += 8;
            e
        }));
        let t = SegmentTopology::from_edges(&edges);
        assert_eq!(t.yarn_count(), 2);
        assert_eq!(t.winding(0), [0, 0]);
        assert_eq!(t.separation(0, 7, [0, 0]), Some(1));
        assert_eq!(t.separation(1, 6, [0, 0]), Some(3));
        assert_eq!(t.separation(0, 4, [0, 0]), Some(4));
        assert_eq!(t.separation(0, 0, [1, 0]), None); // the loop of the next tile
        assert_eq!(t.separation(0, 9, [0, 0]), None);
    }

    fn jittered(p: &Pattern, amp: f64, seed: u64) -> Vec<Vector3<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        p.positions
            .iter()
            .map(|x| {
                x + Vector3::new(
                    rng.random_range(-amp..amp),
                    rng.random_range(-amp..amp),
                    rng.random_range(-amp..amp),
                )
            })
            .collect()
    }

    /// Cylinder bending about the y axis through (0, 0, −R_c): a point (x, y, z) of the flat tile maps to angle
    /// x/R_c at distance R_c + z from the axis; the images T_(dx,dy) rotate by dx p₁/R_c and shift by dy p₂.
    fn bent(p: &Pattern, positions: &[Vector3<f64>], rc: f64) -> (Vec<Vector3<f64>>, TileImages) {
        let c = Vector3::new(0.0, 0.0, -rc);
        let map = |x: &Vector3<f64>| {
            let a = x.x / rc;
            c + Vector3::new((rc + x.z) * a.sin(), x.y, (rc + x.z) * a.cos())
        };
        let mut images = Vec::new();
        for dy in -1..=1 {
            for dx in -1..=1 {
                let a = dx as f64 * p.periods[0] / rc;
                let rot = *nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), a).matrix();
                images.push(TileImage {
                    offset: [dx, dy],
                    rotation: rot,
                    translation: c - rot * c + Vector3::new(0.0, dy as f64 * p.periods[1], 0.0),
                });
            }
        }
        (
            positions.iter().map(map).collect(),
            TileImages::new(images).unwrap(),
        )
    }

    fn check_against_brute_force(
        p: &Pattern,
        positions: &[Vector3<f64>],
        images: &TileImages,
        margin: f64,
    ) -> Vec<CandidatePair> {
        let r = p.radius;
        let segs = tile_segments(p, positions, images).unwrap();
        let topo = SegmentTopology::from_pattern(p);
        let bp = BroadPhase::new(&segs, topo.clone(), images.clone(), r, margin, 3).unwrap();
        let cand = bp.candidates();
        let set: HashSet<_> = cand.iter().copied().collect();
        assert_eq!(set.len(), cand.len(), "duplicates");
        let exact = brute_force_candidates(&segs, &topo, images, 2.0 * r, 3);
        assert!(!exact.is_empty());
        for c in &exact {
            assert!(set.contains(c), "BVH misses {c:?}");
        }
        // complete up to 2r + margin too (the contract), and every candidate's boxes overlap
        for c in brute_force_candidates(&segs, &topo, images, 2.0 * r + margin, 3) {
            assert!(set.contains(&c), "BVH misses {c:?} within the margin");
        }
        for c in &cand {
            let x = c.points(&segs, images);
            let inf = bp.inflation();
            let (ba, bb) = (
                capsule_aabb(&x[0], &x[1], inf),
                capsule_aabb(&x[2], &x[3], inf),
            );
            assert!(ba.mins.cmple(bb.maxs).all() && bb.mins.cmple(ba.maxs).all());
            assert!(c.image == 0 && c.a < c.b || is_positive(images.get(c.image).offset));
        }
        // each physical pair exactly once: enumerate every ordered pair in every image, map to the canonical form
        let mut all = HashSet::new();
        let mut count = 0;
        for (k, im) in images.iter().enumerate() {
            for a in 0..segs.len() {
                for b in 0..segs.len() {
                    if k == 0 && a == b || topo.excluded(a, b, im.offset, 3) {
                        continue;
                    }
                    let x = CandidatePair { a, b, image: k }.points(&segs, images);
                    let (d2, _, _) = segment_distance_squared(&x[0], &x[1], &x[2], &x[3]);
                    if d2 < 4.0 * r * r {
                        count += 1;
                        let canon = if k == 0 {
                            CandidatePair {
                                a: a.min(b),
                                b: a.max(b),
                                image: 0,
                            }
                        } else if is_positive(im.offset) {
                            CandidatePair { a, b, image: k }
                        } else {
                            let neg = images.index_of([-im.offset[0], -im.offset[1]]).unwrap();
                            CandidatePair {
                                a: b,
                                b: a,
                                image: neg,
                            }
                        };
                        all.insert(canon);
                    }
                }
            }
        }
        assert_eq!(count, 2 * exact.len());
        assert_eq!(all, exact.iter().copied().collect::<HashSet<_>>());
        cand
    }

    #[test]
    fn bvh_finds_every_brute_force_pair_flat_and_bent() {
        let r = 1e-3;
        let p = synthetic_weave(4, 20, r);
        for seed in 0..4 {
            let x = jittered(&p, 0.4 * r, seed);
            let images = TileImages::flat(p.periods);
            let cand = check_against_brute_force(&p, &x, &images, 0.5 * r);
            // periodic pairs are present
            assert!(cand.iter().any(|c| c.image != 0));
            let (xb, images) = bent(&p, &x, 3.0 * p.periods[0]);
            check_against_brute_force(&p, &xb, &images, 0.5 * r);
        }
    }

    #[test]
    fn refit_keeps_the_contract_and_matches_a_rebuild() {
        let r = 1e-3;
        let margin = 0.4 * r;
        let p = synthetic_weave(4, 16, r);
        let images = TileImages::flat(p.periods);
        let topo = SegmentTopology::from_pattern(&p);
        let x0 = jittered(&p, 0.3 * r, 11);
        let s0 = tile_segments(&p, &x0, &images).unwrap();
        let mut bp = BroadPhase::new(&s0, topo.clone(), images.clone(), r, margin, 3).unwrap();
        let c0: HashSet<_> = bp.candidates().into_iter().collect();
        // every vertex moves by less than margin/2 (norm): the old list still holds every pair within 2r
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let x1: Vec<_> = x0
            .iter()
            .map(|x| {
                let d = Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                x + d.normalize() * (0.499 * margin * rng.random_range(0.0..1.0f64))
            })
            .collect();
        let s1 = tile_segments(&p, &x1, &images).unwrap();
        for c in brute_force_candidates(&s1, &topo, &images, 2.0 * r, 3) {
            assert!(c0.contains(&c), "stale list misses {c:?}");
        }
        // a larger move: refit + re-query equals a fresh build
        let x2 = jittered(&p, 0.8 * r, 12);
        let s2 = tile_segments(&p, &x2, &images).unwrap();
        bp.refit(&s2).unwrap();
        let fresh = BroadPhase::new(&s2, topo.clone(), images.clone(), r, margin, 3).unwrap();
        assert_eq!(bp.candidates(), fresh.candidates());
        for c in brute_force_candidates(&s2, &topo, &images, 2.0 * r + margin, 3) {
            assert!(bp.candidates().contains(&c));
        }
        assert!(bp.refit(&s2[1..]).is_err());
    }

    #[test]
    fn exclusion_and_self_images() {
        let r = 1e-3;
        // a coarse weave: 6 segments per yarn of length 16r/6 ≈ 2.7r; with exclusion 0 a segment meets its
        // neighbours (they share endpoints), with exclusion 3 none of the along-yarn neighbours appear
        let p = synthetic_weave(4, 6, r);
        let images = TileImages::flat(p.periods);
        let topo = SegmentTopology::from_pattern(&p);
        let segs = tile_segments(&p, &p.positions, &images).unwrap();
        let c0 = BroadPhase::new(&segs, topo.clone(), images.clone(), r, 0.0, 0)
            .unwrap()
            .candidates();
        let c3 = BroadPhase::new(&segs, topo.clone(), images.clone(), r, 0.0, 3)
            .unwrap()
            .candidates();
        let neighbour =
            |c: &CandidatePair| topo.separation(c.a, c.b, images.get(c.image).offset) == Some(1);
        // the wrap-around neighbours are found through the images (segment 5 of a warp yarn and segment 0's copy)
        assert!(c0.iter().any(|c| neighbour(c) && c.image != 0));
        assert!(c3
            .iter()
            .all(|c| !topo.excluded(c.a, c.b, images.get(c.image).offset, 3)));
        assert!(c3.iter().all(|c| !neighbour(c)));
        // a segment with its own image in the next row is a valid pair when the rows touch: squeeze p₂
        let mut q = p.clone();
        q.periods[1] = 1.5 * r;
        let images = TileImages::flat(q.periods);
        let segs = tile_segments(&q, &q.positions, &images).unwrap();
        let c = BroadPhase::new(&segs, topo.clone(), images.clone(), r, 0.0, 3)
            .unwrap()
            .candidates();
        assert!(c
            .iter()
            .any(|c| c.a == c.b && images.get(c.image).offset == [0, 1]));
        assert!(!c.iter().any(|c| c.a == c.b && c.image == 0));
    }
}
