//! The consistency checks of a [`Pattern`] (the list in the [module documentation](super)): structure, numbers,
//! edges and reference directors are errors; inconsistent periods are a [`PatternWarning`].

use super::{check_offset, vertex_range, Block, Ctx, Lines, PatternError};
use crate::pattern::Pattern;
use nalgebra::Vector3;
use std::fmt;

/// Largest accepted |‖u‖ − 1| of a reference director (the originals: ≤ 7.6e-7).
pub const DIRECTOR_NORM_TOL: f64 = 1e-5;
/// Largest accepted |u·t| / ‖u‖ of a reference director u and its edge's unit tangent t (the originals: ≤ 5.3e-5,
/// basket's periodic edges ≤ 4.8e-4 at their implied periods).
pub const DIRECTOR_PERP_TOL: f64 = 2e-3;
/// How far (in strain) a periodic edge's (l − l̄)/l̄ may lie outside the interior edges' range before the period
/// check warns (basket: 6.6 %; the other originals: < 0.002 %).
pub const PERIOD_MISMATCH_TOL: f64 = 0.01;

/// Smallest plausible yarn radius r (m): 1 µm, the radius of a fine single filament (the originals: 1 mm).
pub const MIN_RADIUS: f64 = 1e-6;
/// Largest plausible yarn radius r (m): 5 cm, thicker than any rope used as yarn. It also catches a file written
/// in millimetres (r = 1 for a 1 mm yarn) and keeps the micro solver's lengths far from overflow.
pub const MAX_RADIUS: f64 = 0.05;
/// Smallest period p₁, p₂ relative to the radius: a tile narrower than one yarn radius would overlap every yarn
/// with its own periodic images (the originals: 7.9 r and more).
pub const MIN_PERIOD_RATIO: f64 = 1.0;
/// Largest period p₁, p₂ relative to the radius (the originals: at most 17.4 r). The micro solver's start phase
/// moves curvature in steps proportional to r / p, so this bounds its work too.
pub const MAX_PERIOD_RATIO: f64 = 1e4;
/// Smallest rest length l̄ relative to the radius: the stretch energy grows like 1/l̄ and overflows for
/// sub-normal lengths (5e-324 gave Ψ̄ = inf). The originals' edges are 0.53 r and longer and the generator samples
/// at most 100 vertices per radius (l̄ ≥ 0.01 r), so 1e-3 r leaves a margin of 10×.
pub const MIN_REST_LENGTH_RATIO: f64 = 1e-3;
/// Largest rest length l̄ relative to the radius (the originals: at most 1.5 r): an edge may not be longer than
/// the largest admissible period, [`MAX_PERIOD_RATIO`] r.
pub const MAX_REST_LENGTH_RATIO: f64 = MAX_PERIOD_RATIO;

/// A consistency problem that does not stop a pattern from loading.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum PatternWarning {
    /// The periodic edges do not have their rest lengths at the stored periods while the interior edges do (see
    /// the module documentation): the tile is probably compressed or stretched by wrong periods.
    PeriodMismatch(PeriodMismatch),
}

/// The numbers behind [`PatternWarning::PeriodMismatch`].
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodMismatch {
    /// the pattern file
    pub file: String,
    /// The stored periods (m).
    pub stored: [f64; 2],
    /// The periods the rest lengths of the periodic edges imply ([`Pattern::implied_periods`]), if solvable.
    pub implied: Option<[f64; 2]>,
    /// Smallest and largest strain (l − l̄)/l̄ of the periodic edges at the stored periods.
    pub periodic_strain: [f64; 2],
    /// Smallest and largest strain of the interior edges (`None` without interior edges).
    pub interior_strain: Option<[f64; 2]>,
    /// Largest |u·t| of the periodic edges' reference directors at the stored periods.
    pub director_cos_stored: f64,
    /// The same at the implied periods.
    pub director_cos_implied: Option<f64>,
}

impl fmt::Display for PatternWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PatternWarning::PeriodMismatch(m) => m.fmt(f),
        }
    }
}

impl fmt::Display for PeriodMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [lo, hi] = self.periodic_strain;
        let (what, look) = if hi < 0.0 {
            (
                format!("{:.1}–{:.1} % shorter than", -100.0 * hi, -100.0 * lo),
                "compressed",
            )
        } else if lo > 0.0 {
            (
                format!("{:.1}–{:.1} % longer than", 100.0 * lo, 100.0 * hi),
                "stretched",
            )
        } else {
            (
                format!(
                    "between {:.1} % shorter and {:.1} % longer than",
                    -100.0 * lo,
                    100.0 * hi
                ),
                "inconsistent",
            )
        };
        let interior = match self.interior_strain {
            Some([a, b]) => format!(
                "interior edges within {:.2} %",
                100.0 * a.abs().max(b.abs())
            ),
            None => "no interior edges".to_string(),
        };
        write!(
            f,
            "{}: periodic edges are {what} their rest lengths ({interior}): the stored periods {} × {} m look {look}",
            self.file, self.stored[0], self.stored[1]
        )?;
        match self.implied {
            Some(p) => {
                write!(
                    f,
                    "; the rest lengths imply {} × {} m ({:+.2} %, {:+.2} %)",
                    sig(p[0], 6),
                    sig(p[1], 6),
                    100.0 * (p[0] / self.stored[0] - 1.0),
                    100.0 * (p[1] / self.stored[1] - 1.0)
                )?;
                if let Some(c) = self.director_cos_implied {
                    write!(
                        f,
                        " (the periodic edges' reference directors have |u·t| ≤ {} at the stored periods, ≤ {} at \
                         the implied ones)",
                        sig(self.director_cos_stored, 2),
                        sig(c, 2)
                    )?;
                }
                Ok(())
            }
            None => write!(f, "; the implied periods could not be solved for"),
        }
    }
}

/// `x` with `digits` significant digits, trailing zeros removed (like C's `%g`).
fn sig(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let e = x.abs().log10().floor() as i32;
    if (-5..digits as i32).contains(&e) {
        let decimals = (digits as i32 - 1 - e).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.*e}", digits - 1)
    }
}

/// The checks of one pattern; errors name `cx.file` and the lines of `lines`.
struct Checker<'a> {
    p: &'a Pattern,
    cx: Ctx<'a>,
    lines: &'a Lines,
}

impl Checker<'_> {
    /// An error at record `i` of block `b`.
    fn at(&self, b: Block, i: usize, msg: String) -> PatternError {
        self.cx.err(Some(b), self.lines.record(b, i), msg)
    }

    /// An error at the header of block `b`.
    fn head(&self, b: Block, msg: String) -> PatternError {
        self.cx
            .err(Some(b), Some(self.lines.header[b.index()]), msg)
    }

    /// n ≥ 1, every per-vertex array has n entries, `edge_file_order` is a permutation of 0..n.
    fn sizes(&self) -> Result<(), PatternError> {
        let p = self.p;
        let n = p.len();
        if n == 0 {
            return Err(self.at(
                Block::Pattern,
                0,
                "n = 0: the number of vertices must be positive".into(),
            ));
        }
        let sizes: [(Block, &str, usize); 6] = [
            (Block::Q, "theta", p.theta.len()),
            (Block::E, "edges", p.edges.len()),
            (Block::RK, "rest_curvature", p.rest_curvature.len()),
            (Block::RT, "rest_twist", p.rest_twist.len()),
            (Block::RefT, "ref_twist", p.ref_twist.len()),
            (Block::E, "edge_file_order", p.edge_file_order.len()),
        ];
        for (b, field, len) in sizes {
            if len != n {
                return Err(self.head(
                    b,
                    format!("{field} has {len} entries but the pattern has {n} vertices"),
                ));
            }
        }
        if p.file_order().is_none() {
            return Err(self.head(
                Block::E,
                format!("edge_file_order is not a permutation of 0..{n}"),
            ));
        }
        Ok(())
    }

    /// Periods and radius finite and positive.
    fn header_numbers(&self) -> Result<(), PatternError> {
        let p = Block::Pattern;
        for (name, v) in [
            ("px", self.p.periods[0]),
            ("py", self.p.periods[1]),
            ("r", self.p.radius),
        ] {
            if !v.is_finite() {
                return Err(self.at(p, 0, format!("{name} = {v} is not finite")));
            }
            if v <= 0.0 {
                return Err(self.at(p, 0, format!("{name} = {v} must be positive")));
            }
        }
        let r = self.p.radius;
        if !(MIN_RADIUS..=MAX_RADIUS).contains(&r) {
            return Err(self.at(
                p,
                0,
                format!(
                    "r = {r:e} m is not a plausible yarn radius (must lie in [{MIN_RADIUS:e}, {MAX_RADIUS}] m; lengths \
                     are in metres)"
                ),
            ));
        }
        for (name, v) in [("px", self.p.periods[0]), ("py", self.p.periods[1])] {
            let ratio = v / r;
            if !(MIN_PERIOD_RATIO..=MAX_PERIOD_RATIO).contains(&ratio) {
                return Err(self.at(
                    p,
                    0,
                    format!(
                        "{name} = {v:e} m is {ratio:.3e} yarn radii (must lie in [{MIN_PERIOD_RATIO}, \
                         {MAX_PERIOD_RATIO:e}] r)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The numbers `vals` of record `i` of block `b` finite.
    fn finite(&self, b: Block, i: usize, vals: &[f64]) -> Result<(), PatternError> {
        for (k, v) in vals.iter().enumerate() {
            if !v.is_finite() {
                return Err(self.at(
                    b,
                    i,
                    format!("{} = {v} of vertex {i} is not finite", b.fields()[k]),
                ));
            }
        }
        Ok(())
    }

    /// Every per-vertex number finite.
    fn all_finite(&self) -> Result<(), PatternError> {
        let p = self.p;
        for i in 0..p.len() {
            let x = p.positions[i];
            self.finite(Block::Q, i, &[x[0], x[1], x[2], p.theta[i]])?;
            let e = &p.edges[i];
            self.finite(Block::RL, i, &[e.rest_length])?;
            self.finite(Block::RK, i, &p.rest_curvature[i])?;
            self.finite(Block::RT, i, &[p.rest_twist[i]])?;
            let u = e.ref_director;
            self.finite(Block::RefD1, i, &[u[0], u[1], u[2]])?;
            self.finite(Block::RefT, i, &[p.ref_twist[i]])?;
        }
        Ok(())
    }

    /// Edges, in file order so that "the second edge" is the later line: end vertex in 0..n, offsets in
    /// {−1, 0, 1}, exactly one incoming edge per vertex, positive rest length.
    fn edges(&self) -> Result<(), PatternError> {
        let p = self.p;
        let n = p.len();
        let mut incoming = vec![usize::MAX; n];
        for &i in &p.edge_file_order {
            let e = &p.edges[i];
            if e.end >= n {
                return Err(self.at(
                    Block::E,
                    i,
                    format!(
                        "edge {i} ends at vertex {} but the pattern has {}",
                        e.end,
                        vertex_range(n)
                    ),
                ));
            }
            for (d, name) in [(e.offset[0], "dx"), (e.offset[1], "dy")] {
                if !check_offset(d as i64) {
                    return Err(self.at(
                        Block::E,
                        i,
                        format!("edge {i} has offset {name} = {d} (must be -1, 0 or 1)"),
                    ));
                }
            }
            let first = incoming[e.end];
            if first != usize::MAX {
                let orphan = (0..n)
                    .find(|&v| !p.edges.iter().any(|f| f.end == v))
                    .map(|v| format!(", so vertex {v} has none"))
                    .unwrap_or_default();
                return Err(self.at(
                    Block::E,
                    i,
                    format!(
                        "edges {first} (line {}) and {i} both end at vertex {}{orphan}: every vertex has exactly \
                         one incoming edge",
                        self.lines.record(Block::E, first).unwrap_or(0),
                        e.end
                    ),
                ));
            }
            incoming[e.end] = i;
            if e.rest_length <= 0.0 {
                return Err(self.at(
                    Block::RL,
                    i,
                    format!("rest length {} of edge {i} must be positive", e.rest_length),
                ));
            }
            let ratio = e.rest_length / p.radius;
            if !(MIN_REST_LENGTH_RATIO..=MAX_REST_LENGTH_RATIO).contains(&ratio) {
                return Err(self.at(
                    Block::RL,
                    i,
                    format!(
                        "rest length {:e} m of edge {i} is {ratio:.3e} yarn radii (must lie in \
                         [{MIN_REST_LENGTH_RATIO:e}, {MAX_REST_LENGTH_RATIO:e}] r)",
                        e.rest_length
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Every edge of non-zero finite current length, every reference director of unit norm.
    fn lengths_and_norms(&self) -> Result<(), PatternError> {
        let p = self.p;
        for i in 0..p.len() {
            let l = p.edge_vector(i).norm();
            if !(l > 0.0 && l.is_finite()) {
                return Err(self.at(
                    Block::E,
                    i,
                    format!(
                        "edge {i} (vertex {i} to vertex {}) has length {l}",
                        p.edges[i].end
                    ),
                ));
            }
            let norm = p.edges[i].ref_director.norm();
            if (norm - 1.0).abs() > DIRECTOR_NORM_TOL {
                return Err(self.at(
                    Block::RefD1,
                    i,
                    format!(
                        "reference director of edge {i} has norm {} (must be 1 within {DIRECTOR_NORM_TOL:e})",
                        sig(norm, 8)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Reference directors ⟂ their edges; a periodic edge may instead be ⟂ at the `implied` periods (given when
    /// the period check flags the pattern).
    fn directors(&self, implied: Option<[f64; 2]>) -> Result<(), PatternError> {
        let p = self.p;
        for i in 0..p.len() {
            let c = p.director_cos(i, p.periods);
            if c <= DIRECTOR_PERP_TOL {
                continue;
            }
            let alt = match implied {
                Some(q) if p.edges[i].offset != [0, 0] => Some(p.director_cos(i, q)),
                _ => None,
            };
            if alt.is_some_and(|a| a <= DIRECTOR_PERP_TOL) {
                continue;
            }
            let alt_msg = alt
                .map(|a| format!(", {} at the implied periods", sig(a, 3)))
                .unwrap_or_default();
            return Err(self.at(
                Block::RefD1,
                i,
                format!(
                    "reference director of edge {i} is not perpendicular to the edge: |u·t| = {} ({:.3}° off){alt_msg}, \
                     tolerance {DIRECTOR_PERP_TOL}",
                    sig(c, 3),
                    c.clamp(0.0, 1.0).asin().to_degrees()
                ),
            ));
        }
        Ok(())
    }
}

impl Pattern {
    /// [`Pattern::validate_as`] under the name `pattern`.
    pub fn validate(&self) -> Result<Vec<PatternWarning>, PatternError> {
        self.validate_as("pattern")
    }

    /// Check the structure and numbers of the pattern (the list in the module documentation) and the consistency
    /// of its periods. Errors name `name`, the block and the line of the file [`Pattern::to_pyp_string`] would
    /// write. The loader runs the same checks with the lines of the file it read.
    pub fn validate_as(&self, name: &str) -> Result<Vec<PatternWarning>, PatternError> {
        self.validate_impl(name, &Lines::layout(self))
    }

    /// The checks with the lines `lines` (of the file read, or of [`Lines::layout`]); errors name `file`.
    pub(super) fn validate_impl(
        &self,
        file: &str,
        lines: &Lines,
    ) -> Result<Vec<PatternWarning>, PatternError> {
        let c = Checker {
            p: self,
            cx: Ctx { file },
            lines,
        };
        c.sizes()?;
        c.header_numbers()?;
        c.all_finite()?;
        c.edges()?;
        c.lengths_and_norms()?;
        // periods, then directors ⟂ edges (a periodic edge may instead be ⟂ at the implied periods)
        let mut warnings = Vec::new();
        let check = self.period_check(file);
        let implied = match &check {
            Some(m) => {
                let implied = m.implied;
                warnings.push(PatternWarning::PeriodMismatch(m.clone()));
                implied
            }
            None => None,
        };
        c.directors(implied)?;
        Ok(warnings)
    }

    /// |u·t| / ‖u‖ of edge i with the given periods.
    fn director_cos(&self, i: usize, periods: [f64; 2]) -> f64 {
        let e = &self.edges[i];
        let shift = Vector3::new(
            e.offset[0] as f64 * periods[0],
            e.offset[1] as f64 * periods[1],
            0.0,
        );
        let v = self.positions[e.end] + shift - self.positions[i];
        let c = e.ref_director.dot(&v).abs() / (v.norm() * e.ref_director.norm());
        if c.is_finite() {
            c
        } else {
            f64::INFINITY
        }
    }

    /// The strain (l − l̄)/l̄ of every edge: its current length at the stored periods against its rest length.
    pub fn edge_strains(&self) -> Vec<f64> {
        (0..self.len())
            .map(|i| self.edge_vector(i).norm() / self.edges[i].rest_length - 1.0)
            .collect()
    }

    /// The periods (p₁, p₂) at which the periodic edges (offset ≠ 0) have their rest lengths, by Gauss–Newton
    /// least squares on Σ (l(p) − l̄)² over the periodic edges, started at the stored periods (with step halving).
    /// A direction without periodic edges keeps its stored period. `None` without periodic edges, when the
    /// problem is degenerate (a direction's periodic edges do not change length with its period) or when the
    /// iteration does not converge. Periodic edges' directors are sensitive to the periods, which is why the
    /// director check uses the implied periods only as an alternative for a pattern the period check flags.
    pub fn implied_periods(&self) -> Option<[f64; 2]> {
        let n = self.len();
        if self.edges.len() != n {
            return None;
        }
        let periodic: Vec<usize> = (0..n)
            .filter(|&i| self.edges[i].offset != [0, 0] && self.edges[i].end < n)
            .collect();
        if periodic.is_empty() {
            return None;
        }
        let active = [0, 1].map(|k| periodic.iter().any(|&i| self.edges[i].offset[k] != 0));
        let eval = |p: [f64; 2]| -> (f64, [[f64; 2]; 2], [f64; 2]) {
            let mut cost = 0.0;
            let mut jtj = [[0.0; 2]; 2];
            let mut jtr = [0.0; 2];
            for &i in &periodic {
                let e = &self.edges[i];
                let v = self.positions[e.end]
                    + Vector3::new(e.offset[0] as f64 * p[0], e.offset[1] as f64 * p[1], 0.0)
                    - self.positions[i];
                let l = v.norm();
                let r = l - e.rest_length;
                let j = [e.offset[0] as f64 * v[0] / l, e.offset[1] as f64 * v[1] / l];
                cost += r * r;
                for a in 0..2 {
                    jtr[a] += j[a] * r;
                    for b in 0..2 {
                        jtj[a][b] += j[a] * j[b];
                    }
                }
            }
            (cost, jtj, jtr)
        };
        let mut p = self.periods;
        let (mut cost, mut jtj, mut jtr) = eval(p);
        for _ in 0..100 {
            if !cost.is_finite() {
                return None;
            }
            let step = match active {
                [true, true] => {
                    let det = jtj[0][0] * jtj[1][1] - jtj[0][1] * jtj[1][0];
                    if det.is_nan() || det <= 1e-12 * jtj[0][0] * jtj[1][1] {
                        return None;
                    }
                    [
                        (jtj[1][1] * jtr[0] - jtj[0][1] * jtr[1]) / det,
                        (jtj[0][0] * jtr[1] - jtj[1][0] * jtr[0]) / det,
                    ]
                }
                [true, false] if jtj[0][0] > 0.0 => [jtr[0] / jtj[0][0], 0.0],
                [false, true] if jtj[1][1] > 0.0 => [0.0, jtr[1] / jtj[1][1]],
                _ => return None,
            };
            // converged: the cost (Σ r², r ≈ 1e-7 l̄ for the originals) is only known to ~1e-12 relative, so the
            // line search cannot judge smaller steps
            if (0..2).all(|k| step[k].abs() <= 1e-10 * p[k].abs()) {
                return Some([p[0] - step[0], p[1] - step[1]]);
            }
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..40 {
                let q = [p[0] - t * step[0], p[1] - t * step[1]];
                if q[0] > 0.0 && q[1] > 0.0 {
                    let (c, jj, jr) = eval(q);
                    if c <= cost {
                        p = q;
                        (cost, jtj, jtr) = (c, jj, jr);
                        accepted = true;
                        break;
                    }
                }
                t *= 0.5;
            }
            if !accepted {
                return Some(p).filter(|_| cost == 0.0);
            }
        }
        None
    }

    /// The period check of the module documentation: `Some` when the pattern should be warned about.
    fn period_check(&self, file: &str) -> Option<PeriodMismatch> {
        let strains = self.edge_strains();
        let range = |periodic: bool| -> Option<[f64; 2]> {
            let mut it = (0..self.len())
                .filter(|&i| (self.edges[i].offset != [0, 0]) == periodic)
                .map(|i| strains[i]);
            let first = it.next()?;
            Some(it.fold([first, first], |[a, b], s| [a.min(s), b.max(s)]))
        };
        let periodic_strain = range(true)?;
        let interior_strain = range(false);
        let [a, b] = interior_strain.unwrap_or([0.0, 0.0]);
        let [lo, hi] = periodic_strain;
        if lo >= a - PERIOD_MISMATCH_TOL && hi <= b + PERIOD_MISMATCH_TOL {
            return None;
        }
        let implied = self.implied_periods();
        let max_cos = |p: [f64; 2]| {
            (0..self.len())
                .filter(|&i| self.edges[i].offset != [0, 0])
                .map(|i| self.director_cos(i, p))
                .fold(0.0, f64::max)
        };
        Some(PeriodMismatch {
            file: file.to_string(),
            stored: self.periods,
            implied,
            periodic_strain,
            interior_strain,
            director_cos_stored: max_cos(self.periods),
            director_cos_implied: implied.map(max_cos),
        })
    }
}
