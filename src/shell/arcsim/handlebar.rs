//! ARCSim-HYLC's handlebars (docs/arcsim.md, "Handlebars"): a strip on one side of the
//! cloth's rest bounding box, placed by fractions of the box's extents.

use crate::shell::scene::Selection;
use crate::shell::Mesh;

/// How far (m) the strip's box is grown before the strict inside test.
pub const GROW: f64 = 1e-5;

/// Side names, by ARCSim's side index (0 left, 1 bottom, 2 right, 3 top).
pub const SIDES: [&str; 4] = ["left", "bottom", "right", "top"];

/// A handlebar's geometry: `side` 0–3 and the fractions `lengthp`, `widthp`, `insetp` of the cloth's extents.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Handlebar {
    /// the side: 0 left, 1 bottom, 2 right, 3 top
    pub side: usize,
    /// fraction of the extent along the side the strip covers (its middle part)
    pub lengthp: f64,
    /// width of the strip across the side, as a fraction of the extent
    pub widthp: f64,
    /// distance of the strip's centre line from the side, as a fraction of the extent
    pub insetp: f64,
}

impl Handlebar {
    /// The strip's box in the rest layout (before growing) on the rest bounding box [`umin`, `umax`] with
    /// extents e = umax − umin. Across the side (x for sides 0 and 2, y for 1 and 3) the strip covers
    /// insetp·e ± ½ widthp·e measured inward from that side; along it the middle lengthp fraction, from
    /// ½(1 − lengthp)·e after the start to ½(1 − lengthp)·e before the end.
    pub fn rect(&self, umin: [f64; 2], umax: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let e = [umax[0] - umin[0], umax[1] - umin[1]];
        let across = self.side % 2;
        let along = 1 - across;
        let centre = if self.side < 2 {
            umin[across] + self.insetp * e[across]
        } else {
            umax[across] - self.insetp * e[across]
        };
        let half = 0.5 * self.widthp * e[across];
        let end = 0.5 * (1.0 - self.lengthp) * e[along];
        let mut lo = [0.0; 2];
        let mut hi = [0.0; 2];
        lo[across] = centre - half;
        hi[across] = centre + half;
        lo[along] = umin[along] + end;
        hi[along] = umax[along] - end;
        (lo, hi)
    }

    /// The held vertices: those of the rest layout `rest` strictly inside the strip's box grown by [`GROW`]; and
    /// the grown box.
    pub fn select(&self, rest: &[[f64; 2]]) -> (Vec<usize>, [f64; 2], [f64; 2]) {
        let (umin, umax) = bounds(rest);
        let (lo, hi) = self.rect(umin, umax);
        let lo = lo.map(|c| c - GROW);
        let hi = hi.map(|c| c + GROW);
        let held = (0..rest.len())
            .filter(|&v| (0..2).all(|k| rest[v][k] > lo[k] && rest[v][k] < hi[k]))
            .collect();
        (held, lo, hi)
    }

    /// The scene selection for the held vertices on `mesh` (rest layout as the scene builds it): the grown box
    /// when our box selection (inclusive, 1e-9 tolerance) picks exactly the same vertices, which it does unless
    /// a vertex lies within 1e-9 m of the box; otherwise the vertex list. Also returns the held vertices.
    pub fn selection(&self, mesh: &Mesh, x0: &[[f64; 3]]) -> (Selection, Vec<usize>) {
        let (held, min, max) = self.select(&mesh.rest);
        let boxed = Selection::Box { min, max };
        if boxed.select(mesh, x0) == held {
            (boxed, held)
        } else {
            (Selection::Vertices(held.clone()), held)
        }
    }
}

/// The rest bounding box (umin, umax) of a layout (zeros for an empty one).
pub fn bounds(rest: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    if rest.is_empty() {
        return ([0.0; 2], [0.0; 2]);
    }
    rest.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rects_on_a_rectangle() {
        let bar = |side| Handlebar {
            side,
            lengthp: 0.5,
            widthp: 0.2,
            insetp: 0.25,
        };
        let (u0, u1) = ([0.0, 0.0], [1.0, 2.0]);
        let close = |a: ([f64; 2], [f64; 2]), b: ([f64; 2], [f64; 2])| {
            (0..2).all(|k| (a.0[k] - b.0[k]).abs() < 1e-15 && (a.1[k] - b.1[k]).abs() < 1e-15)
        };
        assert!(close(bar(0).rect(u0, u1), ([0.15, 0.5], [0.35, 1.5])));
        assert!(close(bar(1).rect(u0, u1), ([0.25, 0.3], [0.75, 0.7])));
        assert!(close(bar(2).rect(u0, u1), ([0.65, 0.5], [0.85, 1.5])));
        assert!(close(bar(3).rect(u0, u1), ([0.25, 1.3], [0.75, 1.7])));
    }
}
