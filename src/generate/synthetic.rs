//! A synthetic periodic weave for tests and benchmarks (not one of the pattern generators: no reference state).

use crate::pattern::{Edge, Pattern};
use nalgebra::Vector3;

/// A synthetic periodic weave for tests and benchmarks (not a reference state): `k` (even) warp yarns along x and
/// `k` weft yarns along y, spacing 4r, each a sine of amplitude 0.9 r in z sampled at `per_yarn` vertices, so the
/// crossings overlap slightly (ρ = 0.9); periods k·4r. Warp yarns wind (1, 0), weft yarns (0, 1).
pub fn synthetic_weave(k: usize, per_yarn: usize, radius: f64) -> Pattern {
    assert!(k >= 2 && k.is_multiple_of(2) && per_yarn >= 3);
    let s = 4.0 * radius;
    let p = k as f64 * s;
    let h = 0.9 * radius;
    let pi = std::f64::consts::PI;
    let mut positions = Vec::new();
    let mut edges = Vec::new();
    for dir in 0..2 {
        for j in 0..k {
            let base = positions.len();
            let c = (j as f64 + 0.5) * s;
            for i in 0..per_yarn {
                let t = (i as f64 + 0.5) * p / per_yarn as f64;
                let phase = pi * t / s + pi * j as f64;
                positions.push(if dir == 0 {
                    Vector3::new(t, c, h * phase.sin())
                } else {
                    Vector3::new(c, t, -h * phase.sin())
                });
            }
            for i in 0..per_yarn {
                let last = i + 1 == per_yarn;
                let wrap = if last { 1 } else { 0 };
                edges.push(Edge {
                    end: base + (i + 1) % per_yarn,
                    offset: if dir == 0 { [wrap, 0] } else { [0, wrap] },
                    rest_length: 0.0,
                    ref_director: Vector3::z(),
                });
            }
        }
    }
    let n = positions.len();
    let mut pat = Pattern::from_geometry([p, p], radius, positions, edges);
    for i in 0..n {
        pat.edges[i].rest_length = pat.edge_vector(i).norm();
    }
    pat
}
