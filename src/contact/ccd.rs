//! Yarn crossings along a motion: continuous collision detection of yarn centre lines (docs/sampling.md, the
//! guard of a "defined Ψ̄").
//!
//! Two yarns that pass through each other change the tile's topology (e.g. a knit loop pulled through its
//! neighbour), and the equilibrium reached then belongs to another fabric. Along a step from positions X to X'
//! every vertex moves on the straight line x(t) = x + t (x' − x), t ∈ [0, 1]. Segments a = [a₀, a₁] and
//! b = [b₀, b₁] meet at time t only if their four points are coplanar:
//!
//! f(t) = (b₀ − a₀)(t) · ((a₁ − a₀)(t) × (b₁ − b₀)(t)) = c₀ + c₁ t + c₂ t² + c₃ t³ = 0,
//!
//! and the centre lines cross when, at such a root t*, the segments' distance vanishes. The roots are bracketed
//! between the critical points of the cubic (where f' = 0) and refined by bisection; a root is a crossing when the
//! segment distance at t* is below `tol`. The sign of f'(t*) tells the direction (a passes b from one side or the
//! other), so two opposite crossings of one pair cancel in [`net_crossings`].
//!
//! Which pairs can cross: a pair whose segments are farther apart than 2D at X, D the largest displacement of any
//! segment end, cannot meet. [`crossings`] takes the pairs of a [`BroadPhase`] built at X with that margin (and
//! the contact exclusion along each yarn: neighbouring segments share a vertex), so it finds every crossing of the
//! step.

use super::broad::{BroadPhase, Segment, SegmentTopology};
use super::{segment_distance_squared, ContactError};
use crate::periodic::{TileImage, TileImages};
use nalgebra::Vector3;

/// One centre-line crossing along a step: home segment `a`, segment `b` in the image at `offset`, the time
/// t ∈ [0, 1] and the direction (±1, the sign of df/dt).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// the home segment
    pub a: usize,
    /// the other segment
    pub b: usize,
    /// the periodic offset of `b`'s image
    pub offset: [i32; 2],
    /// when along the step, t ∈ [0, 1]
    pub time: f64,
    /// the direction, ±1 (the sign of df/dt)
    pub sign: i8,
}

/// The times t ∈ [0, 1] at which the segments moving linearly from (a, b) to (a', b') cross (distance at the
/// coplanarity root below `tol`), with the direction of each, in increasing t.
pub fn segment_crossings(
    a: &Segment,
    a2: &Segment,
    b: &Segment,
    b2: &Segment,
    tol: f64,
) -> Vec<(f64, i8)> {
    let at = |s: &Segment, s2: &Segment, t: f64| -> Segment {
        [s[0] + (s2[0] - s[0]) * t, s[1] + (s2[1] - s[1]) * t]
    };
    let distance = |t: f64| {
        let (p, q) = (at(a, a2, t), at(b, b2, t));
        segment_distance_squared(&p[0], &p[1], &q[0], &q[1])
            .0
            .sqrt()
    };
    // f(t) = W(t) · (E1(t) × E2(t)), each factor linear in t
    let (w, dw) = (b[0] - a[0], (b2[0] - a2[0]) - (b[0] - a[0]));
    let (e1, d1) = (a[1] - a[0], (a2[1] - a2[0]) - (a[1] - a[0]));
    let (e2, d2) = (b[1] - b[0], (b2[1] - b2[0]) - (b[1] - b[0]));
    let n0 = e1.cross(&e2);
    let n1 = e1.cross(&d2) + d1.cross(&e2);
    let n2 = d1.cross(&d2);
    let c = [
        w.dot(&n0),
        dw.dot(&n0) + w.dot(&n1),
        dw.dot(&n1) + w.dot(&n2),
        dw.dot(&n2),
    ];
    let f = |t: f64| c[0] + t * (c[1] + t * (c[2] + t * c[3]));
    let df = |t: f64| c[1] + t * (2.0 * c[2] + t * 3.0 * c[3]);
    // scale of f: the product of three lengths seen along the step
    let len = |v: &Vector3<f64>, dv: &Vector3<f64>| v.norm() + dv.norm();
    let scale = len(&w, &dw) * len(&e1, &d1) * len(&e2, &d2);
    let mut out = Vec::new();
    if c.iter().all(|v| v.abs() <= 1e-14 * scale) {
        // coplanar throughout (or degenerate): sample the distance
        let hit = (0..=64)
            .map(|k| k as f64 / 64.0)
            .find(|&t| distance(t) < tol);
        if let Some(t) = hit {
            out.push((t, 0));
        }
        return out;
    }
    // monotone pieces of the cubic on [0, 1]: split at the roots of f'
    let mut cuts = vec![0.0, 1.0];
    let (qa, qb, qc) = (3.0 * c[3], 2.0 * c[2], c[1]);
    if qa.abs() > 0.0 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let s = disc.sqrt();
            cuts.push((-qb - s) / (2.0 * qa));
            cuts.push((-qb + s) / (2.0 * qa));
        }
    } else if qb.abs() > 0.0 {
        cuts.push(-qc / qb);
    }
    cuts.retain(|t| (0.0..=1.0).contains(t));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    for piece in cuts.windows(2) {
        let (mut lo, mut hi) = (piece[0], piece[1]);
        let (flo, fhi) = (f(lo), f(hi));
        if flo * fhi > 0.0 {
            continue;
        }
        let rising = fhi > flo;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if (f(mid) > 0.0) == rising {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let t = 0.5 * (lo + hi);
        if distance(t) < tol && out.last().is_none_or(|&(p, _)| t - p > 1e-12) {
            out.push((t, if df(t) >= 0.0 { 1 } else { -1 }));
        }
    }
    out
}

/// Every centre-line crossing of the tile's segments moving linearly from `before` to `after` (the same tile
/// transforms `images` throughout, i.e. one macro strain), pairs excluded along each yarn as the contact is.
/// `tol` is the distance below which the centre lines count as met (e.g. 1e-6 r).
pub fn crossings(
    before: &[Segment],
    after: &[Segment],
    topology: SegmentTopology,
    images: &TileImages,
    exclusion: usize,
    tol: f64,
) -> Result<Vec<Crossing>, ContactError> {
    crossings_between((before, images), (after, images), topology, exclusion, tol)
}

/// [`crossings`] for a motion that also changes the tile transforms (a step of the macro strain): the segments
/// `before` with the copies placed by `images_before`, then `after` with `images_after` (the same offsets in the
/// same order). Every copy of every segment end moves on the straight line between its two world positions,
/// T₀(x) → T₁(x′), so a pair can only meet within the step if it is closer at the start than the two ends' largest
/// motions: a home end by |x′ − x|, a copy by at most |x′ − x| + |T₁(x) − T₀(x)|.
pub fn crossings_between(
    (before, images_before): (&[Segment], &TileImages),
    (after, images_after): (&[Segment], &TileImages),
    topology: SegmentTopology,
    exclusion: usize,
    tol: f64,
) -> Result<Vec<Crossing>, ContactError> {
    if before.len() != after.len() {
        return Err(ContactError::InvalidParameter(format!(
            "crossings between {} and {} segments",
            before.len(),
            after.len()
        )));
    }
    let same_offsets = images_before.len() == images_after.len()
        && images_before
            .iter()
            .zip(images_after.iter())
            .all(|(a, b)| a.offset == b.offset);
    if !same_offsets {
        return Err(ContactError::InvalidParameter(
            "crossings between tiles with different periodic copies".into(),
        ));
    }
    if !(tol.is_finite() && tol > 0.0) {
        return Err(ContactError::InvalidParameter(format!(
            "crossing tolerance {tol}"
        )));
    }
    let moved = before
        .iter()
        .zip(after)
        .map(|(s, s2)| (s2[0] - s[0]).norm().max((s2[1] - s[1]).norm()))
        .fold(0.0f64, f64::max);
    // the largest motion of a copy that the change of the transforms alone causes (0 at one strain)
    let images_moved = if images_before == images_after {
        0.0
    } else {
        images_before
            .iter()
            .zip(images_after.iter())
            .flat_map(|(t0, t1)| {
                before
                    .iter()
                    .flat_map(|s| [s[0], s[1]])
                    .map(move |x| (t1.apply(&x) - t0.apply(&x)).norm())
            })
            .fold(0.0f64, f64::max)
    };
    if !(moved.is_finite() && images_moved.is_finite()) {
        return Err(ContactError::NonFinite);
    }
    // pairs closer than 2·(tol/2) + margin at `before`: every pair that can meet within the step
    let margin = (2.0 * moved + images_moved) * (1.0 + 1e-9) + tol;
    let broad = BroadPhase::new(
        before,
        topology,
        images_before.clone(),
        0.5 * tol,
        margin,
        exclusion,
    )?;
    let mut out = Vec::new();
    for pair in broad.candidates() {
        let (t0, t1) = (images_before.get(pair.image), images_after.get(pair.image));
        let map = |t: &TileImage, s: &Segment| -> Segment { [t.apply(&s[0]), t.apply(&s[1])] };
        for (time, sign) in segment_crossings(
            &before[pair.a],
            &after[pair.a],
            &map(t0, &before[pair.b]),
            &map(t1, &after[pair.b]),
            tol,
        ) {
            out.push(Crossing {
                a: pair.a,
                b: pair.b,
                offset: t0.offset,
                time,
                sign,
            });
        }
    }
    Ok(out)
}

impl Crossing {
    /// The stand-in for a crossing check that failed (non-finite positions): counted as a crossing, so the
    /// motion is not trusted (undirected, never cancelled).
    pub fn untrusted() -> Self {
        Crossing {
            a: 0,
            b: 0,
            offset: [0, 0],
            time: f64::NAN,
            sign: 0,
        }
    }
}

/// A segment pair: home segment a, segment b, the image offset of b.
pub type PairKey = (usize, usize, [i32; 2]);

/// The crossings that do not cancel: per pair (a, b, offset), the sum of the directions; the pairs with a non-zero
/// sum (or an undirected, coplanar crossing), with that sum.
pub fn net_crossings(events: &[Crossing]) -> Vec<(PairKey, i32)> {
    let mut net: std::collections::BTreeMap<PairKey, (i32, bool)> = Default::default();
    for c in events {
        let e = net.entry((c.a, c.b, c.offset)).or_default();
        e.0 += c.sign as i32;
        e.1 |= c.sign == 0;
    }
    net.into_iter()
        .filter(|(_, (s, undirected))| *s != 0 || *undirected)
        .map(|(k, (s, _))| (k, s))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    #[test]
    fn a_segment_pushed_through_another_crosses_once_and_back_cancels() {
        // a along x at z = 0; b along y, moving from z = 1 to z = −1 over it
        let a = [v(-1.0, 0.0, 0.0), v(1.0, 0.0, 0.0)];
        let b = [v(0.0, -1.0, 1.0), v(0.0, 1.0, 1.0)];
        let b2 = [v(0.0, -1.0, -1.0), v(0.0, 1.0, -1.0)];
        let hits = segment_crossings(&a, &a, &b, &b2, 1e-9);
        assert_eq!(hits.len(), 1);
        assert!((hits[0].0 - 0.5).abs() < 1e-12, "{hits:?}");
        let back = segment_crossings(&a, &a, &b2, &b, 1e-9);
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].1, -hits[0].1);
        let events: Vec<Crossing> = [hits[0], back[0]]
            .iter()
            .map(|&(time, sign)| Crossing {
                a: 0,
                b: 1,
                offset: [0, 0],
                time,
                sign,
            })
            .collect();
        assert!(net_crossings(&events).is_empty());
        assert_eq!(net_crossings(&events[..1]).len(), 1);
    }

    #[test]
    fn passing_beside_the_segment_end_or_stopping_short_is_no_crossing() {
        let a = [v(-1.0, 0.0, 0.0), v(1.0, 0.0, 0.0)];
        // b passes through the plane of a, but beyond a's end (x = 1.5)
        let b = [v(1.5, -1.0, 1.0), v(1.5, 1.0, 1.0)];
        let b2 = [v(1.5, -1.0, -1.0), v(1.5, 1.0, -1.0)];
        assert!(segment_crossings(&a, &a, &b, &b2, 1e-9).is_empty());
        // b comes down to z = 0.01 and stops
        let b3 = [v(0.0, -1.0, 0.01), v(0.0, 1.0, 0.01)];
        let b0 = [v(0.0, -1.0, 1.0), v(0.0, 1.0, 1.0)];
        assert!(segment_crossings(&a, &a, &b0, &b3, 1e-9).is_empty());
        // both move and rotate, never meet: parallel translation of the pair
        let shift = v(0.3, 0.2, 0.1);
        let a2 = [a[0] + shift, a[1] + shift];
        let b4 = [b0[0] + shift, b0[1] + shift];
        assert!(segment_crossings(&a, &a2, &b0, &b4, 1e-9).is_empty());
    }

    #[test]
    fn a_rotating_segment_sweeps_through_a_fixed_one() {
        // b tilts and sinks: its point above a (y = 0) goes from z = 0.5 to −0.5, through a at t = 1/2
        let a = [v(-1.0, 0.0, 0.0), v(1.0, 0.0, 0.0)];
        let b = [v(0.2, -0.5, 0.5), v(0.2, 0.5, 0.5)];
        let b2 = [v(0.2, -0.5, -1.5), v(0.2, 0.5, 0.5)];
        let hits = segment_crossings(&a, &a, &b, &b2, 1e-9);
        assert_eq!(hits.len(), 1, "{hits:?}");
        assert!((hits[0].0 - 0.5).abs() < 1e-9, "{hits:?}");
        // at the crossing time the lines meet within both segments
        let t = hits[0].0;
        let bt = [b[0] + (b2[0] - b[0]) * t, b[1] + (b2[1] - b[1]) * t];
        let (d2, _, _) = segment_distance_squared(&a[0], &a[1], &bt[0], &bt[1]);
        assert!(d2.sqrt() < 1e-9);
    }

    #[test]
    fn a_copy_moved_by_the_change_of_the_periods_crosses() {
        use crate::pattern::Edge;
        let edge = |end, offset| Edge {
            end,
            offset,
            rest_length: 1.0,
            ref_director: Vector3::z(),
        };
        // yarn 0: one vertex winding along y at x = 1.9; yarn 1: a segment in the plane x = 0 rising through z = 0
        // at y = 0.5, whose copy at offset (1, 0) sits at x = p₁
        let edges = vec![edge(0, [0, 1]), edge(2, [0, 0]), edge(1, [0, 1])];
        let topology = SegmentTopology::from_edges(&edges);
        let x = [v(1.9, 0.0, 0.0), v(0.0, 0.25, -0.5), v(0.0, 0.75, 0.5)];
        let segments = |images: &TileImages| -> Vec<Segment> {
            edges
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    let k = images.index_of(e.offset).unwrap();
                    [x[i], images.get(k).apply(&x[e.end])]
                })
                .collect()
        };
        let (wide, narrow) = (TileImages::flat([2.0, 1.0]), TileImages::flat([1.8, 1.0]));
        let (s0, s1) = (segments(&wide), segments(&narrow));
        // p₁ from 2 to 1.8 at fixed positions: the copy passes x = 1.9 through yarn 0
        let moved =
            crossings_between((&s0, &wide), (&s1, &narrow), topology.clone(), 1, 1e-9).unwrap();
        assert!(!net_crossings(&moved).is_empty(), "{moved:?}");
        // from 2 to 1.95: it stops short
        let near = TileImages::flat([1.95, 1.0]);
        let short = crossings_between(
            (&s0, &wide),
            (&segments(&near), &near),
            topology.clone(),
            1,
            1e-9,
        );
        assert!(short.unwrap().is_empty());
        // the same motion at one strain sees nothing, and copies that do not match are an error
        assert!(crossings(&s0, &s0, topology.clone(), &wide, 1, 1e-9)
            .unwrap()
            .is_empty());
        let fewer = TileImages::new(vec![TileImage::identity()]).unwrap();
        assert!(crossings_between((&s0, &wide), (&s1, &fewer), topology, 1, 1e-9).is_err());
    }
}
