//! Procedural generators of the embedded default patterns (`docs/yarn-model.md`, "Periodic yarn
//! pattern": "the project also generates patterns itself … at least a plain weave (and a weave matrix for
//! twill/satin/basket) and a stockinette knit, as smooth periodic centre-line curves sampled at about one vertex per
//! yarn radius").
//!
//! Every generator builds smooth periodic centre lines, samples each yarn at about equal arclength with about
//! `round(L · vertices_per_radius / r)` vertices, at least 4 (L: the yarn's length per tile; weave yarns are sampled
//! crossing by crossing with a vertex on every crossing, knit yarns loop by loop), wraps the vertices into the
//! tile [−p₁/2, p₁/2) × [−p₂/2, p₂/2) (edges that leave the tile end at the periodic copy, offsets in {−1, 0, 1}),
//! shifts all positions so that their length-weighted (Voronoi) mean is 0, sets θ = 0, chooses reference directors
//! smoothly by parallel transport along each yarn (the closing mismatch of a closed yarn is absorbed by the
//! reference twist of its first vertex), stores the reference twists computed from these directors and finally
//! sets the rest values to the shape ([`set_rest_to_current`]): a stress-free rod state. Contact is not resolved
//! here (the generators only keep the centre lines about 2r apart); Algorithm C1 of the solver brings a generated
//! pattern to its reference state.
//!
//! Vertex order: yarn by yarn, each yarn's vertices contiguous in the order its edges visit them; `edge_file_order`
//! is `0..n`.

use crate::pattern::pyp::{MAX_RADIUS, MIN_RADIUS};
use crate::pattern::{Edge, Pattern};
use crate::rod::frame::transport;
use crate::rod::state::{raw_reference_twists, set_rest_to_current};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// A bad generator parameter: which one and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{parameter}: {message}")]
pub struct GenerateError {
    /// the parameter's name
    pub parameter: String,
    /// what is wrong
    pub message: String,
}

fn bad<T>(parameter: &str, message: impl Into<String>) -> Result<T, GenerateError> {
    Err(GenerateError {
        parameter: parameter.into(),
        message: message.into(),
    })
}

/// The yarn radius within the range a `.pyp` file may have ([`MIN_RADIUS`], [`MAX_RADIUS`] m), so that every
/// generated pattern also loads back.
fn plausible_radius(r: f64) -> Result<(), GenerateError> {
    if (MIN_RADIUS..=MAX_RADIUS).contains(&r) {
        Ok(())
    } else {
        bad(
            "radius",
            format!("{r} m is outside the plausible yarn radii [{MIN_RADIUS}, {MAX_RADIUS}] m"),
        )
    }
}

fn positive(name: &str, v: f64) -> Result<(), GenerateError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        bad(name, format!("must be positive and finite, got {v}"))
    }
}

/// Yarn radius of every default pattern (m), as in the original patterns.
pub const DEFAULT_RADIUS: f64 = 1e-3;

// ---------------------------------------------------------------------------------------------------------------
// Weaves
// ---------------------------------------------------------------------------------------------------------------

/// Parameters of a woven pattern.
///
/// Layout: weft yarns run along ξ₁ (x), one per matrix row, row i at ξ₂ = −p₂/2 + (i + ½)·spacing; warp yarns run
/// along ξ₂ (y), one per matrix column, column j at ξ₁ = −p₁/2 + (j + ½)·spacing. The tile is
/// p₁ = columns · spacing by p₂ = rows · spacing. `matrix[i][j] = true` means warp j passes over weft i: there the
/// warp sits at height +crimp and the weft at −crimp (and the other way round for `false`). Between crossings
/// every yarn's height follows a half cosine with zero slope at the crossings, so a plain weave is an exact
/// cosine, floats are flat. At a crossing the yarn's curvature is crimp·π²/spacing²; the centre lines stay 2·crimp
/// apart there as long as that curvature is below 1/(2·crimp), i.e. spacing ≥ π√2·crimp (checked).
#[derive(Clone, Debug, PartialEq)]
pub struct WeaveParams {
    /// Yarn radius r (m). Default 1 mm.
    pub radius: f64,
    /// Distance between the centre lines of neighbouring parallel yarns (m). Default 5r.
    pub spacing: f64,
    /// Weave matrix: rows = weft yarns (along ξ₁, from low to high ξ₂), columns = warp yarns (along ξ₂, from low to
    /// high ξ₁); `true` = warp over weft at that crossing. Every row and every column needs both values.
    pub matrix: Vec<Vec<bool>>,
    /// Height ±crimp of the yarns' centre lines at the crossings (m). Default r: crossing yarns just touch.
    pub crimp: f64,
    /// Vertices per yarn radius of arclength. Default 1.
    pub vertices_per_radius: f64,
}

impl Default for WeaveParams {
    /// The plain weave.
    fn default() -> Self {
        WeaveParams::plain()
    }
}

impl WeaveParams {
    /// Default radius, spacing, crimp and sampling with a given weave matrix.
    pub fn with_matrix(matrix: Vec<Vec<bool>>) -> Self {
        WeaveParams {
            radius: DEFAULT_RADIUS,
            spacing: 5.0 * DEFAULT_RADIUS,
            matrix,
            crimp: DEFAULT_RADIUS,
            vertices_per_radius: 1.0,
        }
    }

    /// Plain weave: the 2 × 2 matrix [[true, false], [false, true]] (2 weft + 2 warp yarns, 1 cm tile).
    pub fn plain() -> Self {
        Self::with_matrix(vec![vec![true, false], vec![false, true]])
    }

    /// Twill with repeat n: warp j passes over weft i for ⌈n/2⌉ crossings and under ⌊n/2⌋, the pattern shifted by
    /// one crossing per row (`matrix[i][j] = (j − i) mod n < ⌈n/2⌉`): n = 3 is the 2/1 twill, n = 4 the 2/2 twill,
    /// n = 2 the plain weave. n < 2 gives an invalid matrix (reported by [`weave`]).
    pub fn twill(n: usize) -> Self {
        let over = n.div_ceil(2);
        Self::with_matrix(
            (0..n)
                .map(|i| (0..n).map(|j| (j + n - i) % n < over).collect())
                .collect(),
        )
    }

    /// Satin (sateen) with repeat n and move `step`: in row i only warp (i·step) mod n passes over the weft, so the
    /// weft floats over n − 1 warps (`matrix[i][j] = j == (i·step) mod n`). A proper satin has n ≥ 5,
    /// 1 < step < n − 1 and gcd(n, step) = 1; step sharing a factor with n leaves warps that never cross over
    /// (reported by [`weave`]). The classic 5-harness satin is `satin(5, 2)`.
    pub fn satin(n: usize, step: usize) -> Self {
        Self::with_matrix(
            (0..n)
                .map(|i| (0..n).map(|j| j == (i * step) % n.max(1)).collect())
                .collect(),
        )
    }

    /// Basket weave with groups of k yarns: the plain weave with every yarn replaced by k side-by-side yarns
    /// (`matrix[i][j] = (i/k + j/k)` even, size 2k × 2k); k = 1 is the plain weave.
    pub fn basket(k: usize) -> Self {
        let n = 2 * k;
        Self::with_matrix(
            (0..n)
                .map(|i| (0..n).map(|j| (i / k + j / k).is_multiple_of(2)).collect())
                .collect(),
        )
    }

    fn validate(&self) -> Result<(usize, usize), GenerateError> {
        positive("radius", self.radius)?;
        plausible_radius(self.radius)?;
        positive("spacing", self.spacing)?;
        positive("crimp", self.crimp)?;
        positive("vertices_per_radius", self.vertices_per_radius)?;
        let r = self.radius;
        if self.spacing < 2.0 * r {
            return bad(
                "spacing",
                format!(
                    "{} is below the yarn diameter 2r = {}: parallel yarns would interpenetrate",
                    self.spacing,
                    2.0 * r
                ),
            );
        }
        if self.crimp < r {
            return bad(
                "crimp",
                format!(
                    "{} is below the yarn radius {r}: crossing yarns would interpenetrate",
                    self.crimp
                ),
            );
        }
        let min_spacing = PI * 2f64.sqrt() * self.crimp;
        if self.spacing < min_spacing {
            return bad(
                "spacing",
                format!(
                    "{} is too small for crimp {}: the crossing yarns would cut through each other next to the \
                     crossings (need spacing ≥ π√2·crimp = {min_spacing})",
                    self.spacing, self.crimp
                ),
            );
        }
        if self.vertices_per_radius > 100.0 {
            return bad(
                "vertices_per_radius",
                format!(
                    "{} is unreasonably large (at most 100)",
                    self.vertices_per_radius
                ),
            );
        }
        let rows = self.matrix.len();
        if rows == 0 {
            return bad("matrix", "the weave matrix is empty");
        }
        let cols = self.matrix[0].len();
        if cols == 0 {
            return bad("matrix", "the weave matrix has empty rows");
        }
        for (i, row) in self.matrix.iter().enumerate() {
            if row.len() != cols {
                return bad(
                    "matrix",
                    format!(
                        "row {i} has {} entries, row 0 has {cols}: the matrix must be rectangular",
                        row.len()
                    ),
                );
            }
            if row.iter().all(|&b| b) || row.iter().all(|&b| !b) {
                return bad(
                    "matrix",
                    format!(
                        "row {i} is all {}: weft {i} never {} a warp, so it is not interlaced",
                        row[0],
                        if row[0] {
                            "crosses over"
                        } else {
                            "passes under"
                        }
                    ),
                );
            }
        }
        for j in 0..cols {
            let first = self.matrix[0][j];
            if self.matrix.iter().all(|row| row[j] == first) {
                return bad(
                    "matrix",
                    format!(
                        "column {j} is all {first}: warp {j} never {} a weft, so it is not interlaced",
                        if first { "passes under" } else { "crosses over" }
                    ),
                );
            }
        }
        Ok((rows, cols))
    }
}

/// The height of a yarn at crossing coordinate `u` (in units of the spacing from its first crossing), given its
/// heights at the crossings: half cosines between crossings, zero slope at the crossings (C¹, periodic).
fn crimp_height(heights: &[f64], u: f64) -> f64 {
    let m = heights.len() as f64;
    let u = u.rem_euclid(m);
    let j = (u.floor() as usize).min(heights.len() - 1);
    let f = u - j as f64;
    let a = heights[j];
    let b = heights[(j + 1) % heights.len()];
    a + (b - a) * 0.5 * (1.0 - (PI * f).cos())
}

/// Number of vertices of a yarn of length `len`: round(len · vertices_per_radius / r), at least 4.
fn vertex_count(len: f64, radius: f64, vertices_per_radius: f64) -> usize {
    ((len * vertices_per_radius / radius).round() as usize).max(4)
}

/// A woven pattern (see [`WeaveParams`] for the layout). Yarn order: the weft yarns (rows, net offset (1, 0)), then
/// the warp yarns (columns, net offset (0, 1)).
pub fn weave(params: &WeaveParams) -> Result<Pattern, GenerateError> {
    let (rows, cols) = params.validate()?;
    let s = params.spacing;
    let c = params.crimp;
    let periods = [cols as f64 * s, rows as f64 * s];
    let mut yarns = Vec::with_capacity(rows + cols);
    for i in 0..rows {
        // weft i at y_i, crossing warp j at x_j: below it (−crimp) where the warp is over
        let y = -0.5 * periods[1] + (i as f64 + 0.5) * s;
        let heights: Vec<f64> = params.matrix[i]
            .iter()
            .map(|&warp_over| if warp_over { -c } else { c })
            .collect();
        let x0 = -0.5 * periods[0] + 0.5 * s;
        let curve = |x: f64| Vector3::new(x, y, crimp_height(&heights, (x - x0) / s));
        yarns.push(PeriodicYarn {
            points: sample_crossings(&curve, x0, s, cols, params),
            period: [1, 0],
        });
    }
    for j in 0..cols {
        let x = -0.5 * periods[0] + (j as f64 + 0.5) * s;
        let heights: Vec<f64> = params
            .matrix
            .iter()
            .map(|row| if row[j] { c } else { -c })
            .collect();
        let y0 = -0.5 * periods[1] + 0.5 * s;
        let curve = |y: f64| Vector3::new(x, y, crimp_height(&heights, (y - y0) / s));
        yarns.push(PeriodicYarn {
            points: sample_crossings(&curve, y0, s, rows, params),
            period: [0, 1],
        });
    }
    assemble(&yarns, periods, params.radius)
}

/// Sample a weave yarn crossing by crossing: the `m` intervals between consecutive crossings t0 + j·s, each at
/// equal arclength with a vertex on every crossing (so that the polyline does not cut the corner where the yarns
/// touch), max(round(L_j · vertices_per_radius / r), ⌈4/m⌉) vertices per interval of length L_j.
fn sample_crossings<F: Fn(f64) -> Vector3<f64>>(
    curve: &F,
    t0: f64,
    s: f64,
    m: usize,
    params: &WeaveParams,
) -> Vec<Vector3<f64>> {
    let min_per = 4usize.div_ceil(m);
    (0..m)
        .flat_map(|j| {
            let a = t0 + j as f64 * s;
            sample_curve(curve, a, a + s, 0.0, |len| {
                ((len * params.vertices_per_radius / params.radius).round() as usize).max(min_per)
            })
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------------------------
// Knits
// ---------------------------------------------------------------------------------------------------------------

/// Parameters of a stockinette (jersey) knit.
///
/// One yarn per course, running along ξ₁ with one loop per wale. With φ ∈ [0, 2π) per wale (φ = 0 at the
/// sinker between two loops, φ = π at the head of the loop of wale j), the centre line of course k is
///
/// ξ₁ = x_j + w (φ − π)/(2π) + a sin 2φ,  ξ₂ = y_k − H cos φ,  h = −d cos 2φ,
///
/// with x_j = −p₁/2 + (j + ½) w, y_k = −p₂/2 + (k + ½) s. The a-term leans the legs backwards so that the head and
/// the sinker are wider than the neck; the loop (height 2H) reaches over the next course (2H > s) and its head
/// passes behind the legs of the course above (legs at h = +d, heads and sinkers at h = −d), which interlocks the
/// courses. The tile is `wales` · w by `courses` · s; the defaults (r = 1 mm, w = 8r, s = 4.5r, H = 3.85r,
/// a = 1.9r, d = 1.6r, 2 × 2 loops: a 16 mm × 9 mm tile) keep the smooth centre lines of different courses 1.97r
/// apart and the sampled ones (one vertex per radius) 1.90r.
#[derive(Clone, Debug, PartialEq)]
pub struct KnitParams {
    /// Yarn radius r (m). Default 1 mm.
    pub radius: f64,
    /// Wale spacing w: the width of one loop's period along ξ₁ (m). Default 8r.
    pub wale_spacing: f64,
    /// Course spacing s: the distance between courses along ξ₂ (m). Default 4.5r.
    pub course_spacing: f64,
    /// Half height H of a loop along ξ₂ (m); 2H > s makes the loops reach through the course above. Default 3.8r.
    pub loop_height: f64,
    /// Amplitude a of the a·sin 2φ term along ξ₁ (m): how much wider the head and the sinker are than the neck.
    /// Default 1.9r.
    pub loop_bulge: f64,
    /// Out-of-plane amplitude d (m): legs at h = +d, heads and sinkers at h = −d. Default 1.6r.
    pub depth: f64,
    /// Loops per course in the tile. Default 2.
    pub wales: usize,
    /// Courses (yarns) in the tile. Default 2.
    pub courses: usize,
    /// Vertices per yarn radius of arclength. Default 1.
    pub vertices_per_radius: f64,
}

impl Default for KnitParams {
    /// The stockinette.
    fn default() -> Self {
        KnitParams::stockinette()
    }
}

impl KnitParams {
    /// The default stockinette (see [`KnitParams`]).
    pub fn stockinette() -> Self {
        let r = DEFAULT_RADIUS;
        KnitParams {
            radius: r,
            wale_spacing: 8.0 * r,
            course_spacing: 4.5 * r,
            loop_height: 3.8 * r,
            loop_bulge: 1.9 * r,
            depth: 1.6 * r,
            wales: 2,
            courses: 2,
            vertices_per_radius: 1.0,
        }
    }

    fn validate(&self) -> Result<(), GenerateError> {
        positive("radius", self.radius)?;
        plausible_radius(self.radius)?;
        positive("wale_spacing", self.wale_spacing)?;
        positive("course_spacing", self.course_spacing)?;
        positive("loop_height", self.loop_height)?;
        positive("depth", self.depth)?;
        positive("vertices_per_radius", self.vertices_per_radius)?;
        if !self.loop_bulge.is_finite() || self.loop_bulge < 0.0 {
            return bad(
                "loop_bulge",
                format!("must be non-negative and finite, got {}", self.loop_bulge),
            );
        }
        let r = self.radius;
        if self.wale_spacing < 4.0 * r {
            return bad(
                "wale_spacing",
                format!(
                    "{} is below 4r = {}: the two legs of a loop and its neighbours would interpenetrate",
                    self.wale_spacing,
                    4.0 * r
                ),
            );
        }
        if self.course_spacing < 2.0 * r {
            return bad(
                "course_spacing",
                format!(
                    "{} is below the yarn diameter 2r = {}",
                    self.course_spacing,
                    2.0 * r
                ),
            );
        }
        if 2.0 * self.loop_height <= self.course_spacing {
            return bad(
                "loop_height",
                format!(
                    "loops of height 2H = {} do not reach the next course (course_spacing {}): the courses would \
                     not interlock",
                    2.0 * self.loop_height,
                    self.course_spacing
                ),
            );
        }
        if self.depth < r {
            return bad(
                "depth",
                format!(
                    "{} is below the yarn radius {r}: legs and heads would interpenetrate where they cross",
                    self.depth
                ),
            );
        }
        if self.wales == 0 {
            return bad("wales", "at least one wale is needed");
        }
        if self.courses == 0 {
            return bad("courses", "at least one course is needed");
        }
        if self.vertices_per_radius > 100.0 {
            return bad(
                "vertices_per_radius",
                format!(
                    "{} is unreasonably large (at most 100)",
                    self.vertices_per_radius
                ),
            );
        }
        Ok(())
    }
}

/// A stockinette knit (see [`KnitParams`]): one yarn per course (net offset (1, 0)), courses in the order of
/// increasing ξ₂. Loops cross the tile boundary in ξ₂ (edges with offsets (0, ±1) within a yarn).
pub fn stockinette(params: &KnitParams) -> Result<Pattern, GenerateError> {
    params.validate()?;
    let (w, s) = (params.wale_spacing, params.course_spacing);
    let (h, a, d) = (params.loop_height, params.loop_bulge, params.depth);
    let nw = params.wales;
    let periods = [nw as f64 * w, params.courses as f64 * s];
    // per loop: the same number of vertices, so that every loop is sampled alike
    let count = |len: f64| {
        let per_loop = len / nw as f64;
        (nw * vertex_count(per_loop, params.radius, params.vertices_per_radius)).max(4)
    };
    let yarns = (0..params.courses)
        .map(|k| {
            let y = -0.5 * periods[1] + (k as f64 + 0.5) * s;
            // φ runs over [0, 2π·wales): x from −p₁/2 (a sinker) across every loop of the course
            let curve = |phi: f64| {
                Vector3::new(
                    -0.5 * periods[0] + w * phi / (2.0 * PI) + a * (2.0 * phi).sin(),
                    y - h * phi.cos(),
                    -d * (2.0 * phi).cos(),
                )
            };
            PeriodicYarn {
                points: sample_curve(&curve, 0.0, 2.0 * PI * nw as f64, 0.5, count),
                period: [1, 0],
            }
        })
        .collect::<Vec<_>>();
    assemble(&yarns, periods, params.radius)
}

// ---------------------------------------------------------------------------------------------------------------
// Sampling and assembly
// ---------------------------------------------------------------------------------------------------------------

/// Dense samples per curve for the arclength table.
const ARCLENGTH_SAMPLES: usize = 8192;

/// Sample a curve segment t ∈ [t0, t1) at equal arclength: n = count(length) points at arclengths
/// (k + phase)·length/n, evaluated on the curve itself (the arclength is tabulated by dense chords and inverted
/// linearly).
fn sample_curve<F: Fn(f64) -> Vector3<f64>>(
    curve: &F,
    t0: f64,
    t1: f64,
    phase: f64,
    count: impl Fn(f64) -> usize,
) -> Vec<Vector3<f64>> {
    let m = ARCLENGTH_SAMPLES;
    let dt = (t1 - t0) / m as f64;
    let mut arc = Vec::with_capacity(m + 1);
    arc.push(0.0);
    let mut prev = curve(t0);
    for k in 1..=m {
        let x = curve(t0 + k as f64 * dt);
        arc.push(arc[k - 1] + (x - prev).norm());
        prev = x;
    }
    let len = arc[m];
    let n = count(len);
    (0..n)
        .map(|k| {
            let target = (k as f64 + phase) * len / n as f64;
            let j = arc.partition_point(|&a| a <= target).clamp(1, m) - 1;
            let f = (target - arc[j]) / (arc[j + 1] - arc[j]);
            curve(t0 + (j as f64 + f) * dt)
        })
        .collect()
}

/// One yarn as an unwrapped polyline: the last point connects to `points[0]` shifted by `period` tiles.
struct PeriodicYarn {
    points: Vec<Vector3<f64>>,
    period: [i32; 2],
}

/// Build the pattern from unwrapped yarns: wrap into the tile, connect, centre, choose the reference directors,
/// store the reference twists and set the rest values to the shape.
fn assemble(
    yarns: &[PeriodicYarn],
    periods: [f64; 2],
    radius: f64,
) -> Result<Pattern, GenerateError> {
    let cell = |x: &Vector3<f64>| {
        [
            (x.x / periods[0] + 0.5).floor() as i32,
            (x.y / periods[1] + 0.5).floor() as i32,
        ]
    };
    let shift = |o: [i32; 2]| Vector3::new(o[0] as f64 * periods[0], o[1] as f64 * periods[1], 0.0);
    let mut positions = Vec::new();
    let mut edges = Vec::new();
    let mut ranges = Vec::new();
    for (y, yarn) in yarns.iter().enumerate() {
        let base = positions.len();
        let m = yarn.points.len();
        let cells: Vec<[i32; 2]> = yarn.points.iter().map(cell).collect();
        for (x, c) in yarn.points.iter().zip(&cells) {
            positions.push(x - shift(*c));
        }
        for k in 0..m {
            let (next, closing) = if k + 1 < m {
                (k + 1, [0, 0])
            } else {
                (0, yarn.period)
            };
            let offset = [
                cells[next][0] + closing[0] - cells[k][0],
                cells[next][1] + closing[1] - cells[k][1],
            ];
            if offset.iter().any(|o| o.abs() > 1) {
                return bad(
                    "vertices_per_radius",
                    format!(
                        "yarn {y}: an edge spans more than one tile (offset {offset:?}); sample more densely"
                    ),
                );
            }
            edges.push(Edge {
                end: base + next,
                offset,
                rest_length: 0.0,
                ref_director: Vector3::zeros(),
            });
        }
        ranges.push(base..base + m);
    }
    let mut p = Pattern::from_geometry(periods, radius, positions, edges);
    let n = p.len();
    // centre: length-weighted (Voronoi) mean of the positions at the origin
    let lengths: Vec<f64> = (0..n).map(|i| p.edge_vector(i).norm()).collect();
    let prev = p.prev();
    let (mut sum, mut weight) = (Vector3::zeros(), 0.0);
    for i in 0..n {
        let wi = 0.5 * (lengths[prev[i]] + lengths[i]);
        sum += p.positions[i] * wi;
        weight += wi;
    }
    let mean = sum / weight;
    for x in &mut p.positions {
        *x -= mean;
    }
    // reference directors: a first director ⟂ the first edge, parallel-transported along the yarn
    for range in ranges {
        let mut t_prev: Option<Vector3<f64>> = None;
        let mut u = Vector3::zeros();
        for i in range {
            let t = p.edge_vector(i).normalize();
            u = match t_prev {
                None => perpendicular(&t),
                Some(tp) => {
                    let v = transport(&tp, &t, &u);
                    (v - t * t.dot(&v)).normalize()
                }
            };
            p.edges[i].ref_director = u;
            t_prev = Some(t);
        }
    }
    p.ref_twist = raw_reference_twists(&p);
    set_rest_to_current(&mut p);
    Ok(p)
}

/// A unit vector ⟂ unit `t`: the normal direction ẑ projected off t (x̂ when t is nearly vertical).
fn perpendicular(t: &Vector3<f64>) -> Vector3<f64> {
    let a = if t.z.abs() < 0.9 {
        Vector3::z()
    } else {
        Vector3::x()
    };
    (a - t * t.dot(&a)).normalize()
}

// ---------------------------------------------------------------------------------------------------------------
// Distances between centre lines
// ---------------------------------------------------------------------------------------------------------------

/// Distance between the segments [p0, p1] and [q0, q1] (closest points clamped to both segments; degenerate
/// segments are points).
pub fn segment_distance(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    q0: &Vector3<f64>,
    q1: &Vector3<f64>,
) -> f64 {
    crate::contact::segment_distance_squared(p0, p1, q0, q1)
        .0
        .sqrt()
}

/// Which segment pairs on the same (infinite, periodically continued) yarn [`min_centerline_distance`] considers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SameYarn {
    /// Only pairs on different yarns (a yarn's periodic copies that are not on the yarn itself count as
    /// different yarns, e.g. the weft of the next tile in ξ₂).
    Skip,
    /// Also pairs on the same yarn, except those at most this many segments apart along it (1 = skip only
    /// consecutive segments; the contact model excludes 3).
    ExcludeNeighbours(usize),
}

/// The closest pair of segments found by [`min_centerline_distance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MinDistance {
    /// Distance between the centre-line segments (m); infinite if no pair qualifies.
    pub distance: f64,
    /// The two segments (by start vertex): the first in the home tile, the second at `offset`.
    pub segments: [usize; 2],
    /// The periodic offset of the second segment's copy.
    pub offset: [i32; 2],
}

/// The minimum distance between the centre-line segments of a pattern, over all periodic copies (brute force over
/// every pair and every copy that can come closer than two periods). Contact needs at least 2r
/// (`docs/yarn-model.md`, "Yarn-yarn contact").
///
/// Segments on the same physical yarn are recognised through the periodic continuation: a home-tile segment of
/// vertex v lies on the copy of its yarn shifted by −C(v), where C(v) is the sum of the edge offsets from the
/// yarn's first vertex to v; two copies of a yarn with net offset D are the same yarn iff their shifts differ by a
/// multiple of D.
pub fn min_centerline_distance(p: &Pattern, same_yarn: SameYarn) -> MinDistance {
    let n = p.len();
    let mut best = MinDistance {
        distance: f64::INFINITY,
        segments: [0, 0],
        offset: [0, 0],
    };
    if n == 0 {
        return best;
    }
    // per vertex: yarn, index along it, cumulative offset; per yarn: length and net offset
    let yarns = p.yarns();
    let mut yarn_of = vec![0; n];
    let mut index = vec![0i64; n];
    let mut cum = vec![[0i32; 2]; n];
    let mut yarn_len = Vec::new();
    let mut yarn_net = Vec::new();
    for (y, verts) in yarns.iter().enumerate() {
        let mut c = [0, 0];
        for (k, &v) in verts.iter().enumerate() {
            yarn_of[v] = y;
            index[v] = k as i64;
            cum[v] = c;
            let o = p.edges[v].offset;
            c = [c[0] + o[0], c[1] + o[1]];
        }
        yarn_len.push(verts.len() as i64);
        yarn_net.push(c);
    }
    // index separation along the yarn of segment a (home) and segment b at offset o, if on the same yarn
    let separation = |a: usize, b: usize, o: [i32; 2]| -> Option<i64> {
        if yarn_of[a] != yarn_of[b] {
            return None;
        }
        let y = yarn_of[a];
        let q = [o[0] - cum[b][0] + cum[a][0], o[1] - cum[b][1] + cum[a][1]];
        let dnet = yarn_net[y];
        let m = yarn_len[y];
        if dnet == [0, 0] {
            if q != [0, 0] {
                return None;
            }
            let d = (index[b] - index[a]).rem_euclid(m);
            return Some(d.min(m - d));
        }
        // q = k · D for an integer k
        let k = if dnet[0] != 0 {
            if q[0] % dnet[0] != 0 {
                return None;
            }
            q[0] / dnet[0]
        } else {
            if q[1] % dnet[1] != 0 {
                return None;
            }
            q[1] / dnet[1]
        };
        if q != [k * dnet[0], k * dnet[1]] {
            return None;
        }
        Some((index[b] + k as i64 * m - index[a]).abs())
    };
    let seg: Vec<[Vector3<f64>; 2]> = (0..n)
        .map(|i| [p.positions[i], p.positions[i] + p.edge_vector(i)])
        .collect();
    // extent of all segment points: copies farther than this plus two periods cannot come closer than the
    // periods, and the nearest parallel yarn or copy is closer than that
    let (mut lo, mut hi) = (seg[0][0], seg[0][0]);
    for s in &seg {
        for x in s {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
    }
    let reach = [0, 1].map(|k| ((hi[k] - lo[k]) / p.periods[k]).ceil() as i32 + 2);
    for ox in -reach[0]..=reach[0] {
        for oy in -reach[1]..=reach[1] {
            let o = [ox, oy];
            let sh = p.shift(o);
            for a in 0..n {
                let (a0, a1) = (&seg[a][0], &seg[a][1]);
                for b in 0..n {
                    if let Some(sep) = separation(a, b, o) {
                        match same_yarn {
                            SameYarn::Skip => continue,
                            SameYarn::ExcludeNeighbours(k) if sep as u64 <= k as u64 => continue,
                            _ => {}
                        }
                    }
                    let (b0, b1) = (seg[b][0] + sh, seg[b][1] + sh);
                    // cheap bounding-box rejection
                    let gap = (0..3)
                        .map(|k| {
                            let (alo, ahi) = (a0[k].min(a1[k]), a0[k].max(a1[k]));
                            let (blo, bhi) = (b0[k].min(b1[k]), b0[k].max(b1[k]));
                            (blo - ahi).max(alo - bhi).max(0.0)
                        })
                        .fold(0.0, f64::max);
                    if gap >= best.distance {
                        continue;
                    }
                    let dist = segment_distance(a0, a1, &b0, &b1);
                    if dist < best.distance {
                        best = MinDistance {
                            distance: dist,
                            segments: [a, b],
                            offset: o,
                        };
                    }
                }
            }
        }
    }
    best
}

/// The pattern as a Wavefront OBJ polyline file for viewing (Blender, ParaView): one `v` line per vertex, plus one
/// per edge that ends at a periodic copy (the copy's shifted position, so that no line crosses the tile), then one
/// `l i j` line per edge.
pub fn to_obj(p: &Pattern) -> String {
    use std::fmt::Write;
    let n = p.len();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# hylc yarn pattern: {n} vertices, {} yarns, periods {} {} m, yarn radius {} m",
        p.yarns().len(),
        p.periods[0],
        p.periods[1],
        p.radius
    );
    for x in &p.positions {
        let _ = writeln!(out, "v {} {} {}", x.x, x.y, x.z);
    }
    let mut lines = Vec::with_capacity(n);
    let mut extra = n;
    for (i, e) in p.edges.iter().enumerate() {
        if e.offset == [0, 0] {
            lines.push((i + 1, e.end + 1));
        } else {
            let x = p.positions[e.end] + p.shift(e.offset);
            let _ = writeln!(out, "v {} {} {}", x.x, x.y, x.z);
            extra += 1;
            lines.push((i + 1, extra));
        }
    }
    for (a, b) in lines {
        let _ = writeln!(out, "l {a} {b}");
    }
    out
}

/// The small generated patterns the whole-tile derivative harness runs on (`docs/derivative-harness.md`: "the total micro
/// energy … on a small pattern"): the default plain weave (40 vertices, 160 dofs, yarns touching at crossings).
pub fn harness_patterns() -> Vec<(&'static str, Pattern)> {
    vec![(
        "plain",
        weave(&WeaveParams::plain()).expect("the default plain weave is valid"),
    )]
}

mod kinds;
mod synthetic;
pub use kinds::{default_pattern, generate_kind, DEFAULT_KINDS};

pub use synthetic::synthetic_weave;
