//! Reading and writing `.pyp` pattern files, and the consistency checks of a [`Pattern`]
//! (`../shared/design/02-yarn-model.md`, "Periodic yarn pattern" and its `.pyp` table).
//!
//! # Format
//!
//! Eight blocks, each introduced by a `*NAME` line: `*pattern` (one line `px py r n`), then n lines each of `*Q`
//! (`x y z theta`), `*E` (`v0 v1 dx dy`, in any order of v0), `*RL` (rest length of the edge starting at vertex
//! i), `*RK` (`k1 k2`), `*RT`, `*RefD1` (`ux uy uz`, of the edge starting at vertex i) and `*RefT`. The reader is
//! tolerant of what does not carry data: `#` starts a comment anywhere (also after `*NAME`), blank lines and extra
//! spaces or tabs are ignored (blank lines are not needed between blocks), CRLF, CR-only and LF line ends and a
//! UTF-8 byte order mark are accepted, and the blocks may come in any order. It is strict about data: every block
//! is required exactly once, an unknown block is an error naming it (ignoring it could silently drop data the
//! file's author meant to be used), every data line must have exactly its number of fields, integers (`n`, `v0`,
//! `v1`, `dx`, `dy`) must be written as integers, and NaN or infinite numbers are rejected.
//!
//! The writer reproduces the originals' layout (the same block order and header comments, one blank line after
//! each block, LF line ends) with the edges in [`Pattern::edge_file_order`]. Numbers use Rust's shortest
//! round-trip formatting (plain `{}` for 1e-4 ≤ |x| < 1e6 and zero, else `{:e}` with the exponent written like
//! C's `%g`, `e-05`), and Rust's parser is correctly rounded, so `from_pyp_str(to_pyp_string(p))` gives back `p`
//! bit for bit (including −0). The five originals (printed with `%g`) are written back byte for byte up to their
//! CRLF line ends.
//!
//! # Errors and warnings
//!
//! Every problem is one line `FILE: block *NAME, line L: what is wrong` ([`PatternError`]); nothing panics on any
//! input. For a pattern that was not read from a file ([`Pattern::validate`]), line numbers refer to the file
//! [`Pattern::to_pyp_string`] would write. [`Pattern::validate_as`] checks:
//!
//! - sizes: n ≥ 1 and every per-vertex array has n entries, `edge_file_order` is a permutation of 0..n;
//! - every number finite; periods, radius and rest lengths positive;
//! - edges: end vertex in 0..n, offsets in {−1, 0, 1}, exactly one incoming edge per vertex (one outgoing edge per
//!   vertex is a parse check: a file may list two edges from one vertex), non-zero current length;
//! - reference directors: unit, |‖u‖ − 1| ≤ [`DIRECTOR_NORM_TOL`] = 1e-5, and perpendicular to their edge,
//!   |u·t| / ‖u‖ ≤ [`DIRECTOR_PERP_TOL`] = 2e-3 (t the unit edge tangent). The five original files, printed with
//!   6 significant digits, satisfy |‖u‖ − 1| ≤ 7.6e-7 (13× margin) and |u·t| ≤ 5.3e-5 except basket's periodic
//!   edges (38× margin). Basket's eight periodic edges have |u·t| up to 0.0999 at the stored periods but ≤ 4.8e-4
//!   at the periods their rest lengths imply (4× margin): the directors confirm the period warning below. So a
//!   periodic edge also passes when the period check flags the pattern and its director is perpendicular at the
//!   implied periods;
//! - period consistency (a [`PatternWarning`], not an error; see [`Pattern::implied_periods`]): with the strain
//!   s = (l − l̄)/l̄ of every edge (l its current length), the pattern is flagged when a periodic edge's strain lies
//!   more than [`PERIOD_MISMATCH_TOL`] = 1 % outside the range of the interior edges' strains (or outside ±1 % if
//!   there are no interior edges). Measured on the originals: basket's periodic edges are 6.6–9.4 % short while
//!   its interior edges are within −0.07…−0.04 %; in the other four the periodic edges' strains lie within 0.004 %
//!   of their interior range (rib 0.045–0.074 % vs 0.041–0.070 %, satin −0.059…−0.038 % vs −0.059…−0.035 %,
//!   honeycomb 0.04–0.14 % vs −0.08…0.23 %, stockinette 0.27–0.28 % vs 0.22–0.29 %). Basket's implied periods are
//!   0.0108665 × 0.0104499 m, +1.52 % and +1.46 % over the stored 0.0107037 × 0.0103 m; the other four's differ
//!   from the stored ones by at most 0.045 % (stockinette, whose edges are all about 0.27 % long).

use super::{Edge, Pattern};
use nalgebra::Vector3;
use std::fmt;
use std::path::Path;

/// Largest accepted |‖u‖ − 1| of a reference director (the originals: ≤ 7.6e-7).
pub const DIRECTOR_NORM_TOL: f64 = 1e-5;
/// Largest accepted |u·t| / ‖u‖ of a reference director u and its edge's unit tangent t (the originals: ≤ 5.3e-5,
/// basket's periodic edges ≤ 4.8e-4 at their implied periods).
pub const DIRECTOR_PERP_TOL: f64 = 2e-3;
/// How far (in strain) a periodic edge's (l − l̄)/l̄ may lie outside the interior edges' range before the period
/// check warns (basket: 6.6 %; the other originals: < 0.002 %).
pub const PERIOD_MISMATCH_TOL: f64 = 0.01;

/// The blocks of a `.pyp` file, in the order the writer uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Block {
    Pattern,
    Q,
    E,
    RL,
    RK,
    RT,
    RefD1,
    RefT,
}

const BLOCKS: [Block; 8] = [
    Block::Pattern,
    Block::Q,
    Block::E,
    Block::RL,
    Block::RK,
    Block::RT,
    Block::RefD1,
    Block::RefT,
];

impl Block {
    fn index(self) -> usize {
        self as usize
    }

    fn name(self) -> &'static str {
        match self {
            Block::Pattern => "pattern",
            Block::Q => "Q",
            Block::E => "E",
            Block::RL => "RL",
            Block::RK => "RK",
            Block::RT => "RT",
            Block::RefD1 => "RefD1",
            Block::RefT => "RefT",
        }
    }

    /// The header comment of the original files.
    fn comment(self) -> &'static str {
        match self {
            Block::Pattern => "px py radius num_vertedges",
            Block::Q => "dofs: x y z t",
            Block::E => "edges [v0, v1, dx, dy]",
            Block::RL => "rest lengths",
            Block::RK => "rest kappas",
            Block::RT => "rest twists",
            Block::RefD1 => "reference directors",
            Block::RefT => "reference twists",
        }
    }

    /// The names of the fields of one data line.
    fn fields(self) -> &'static [&'static str] {
        match self {
            Block::Pattern => &["px", "py", "r", "n"],
            Block::Q => &["x", "y", "z", "theta"],
            Block::E => &["v0", "v1", "dx", "dy"],
            Block::RL => &["rest length"],
            Block::RK => &["k1", "k2"],
            Block::RT => &["rest twist"],
            Block::RefD1 => &["ux", "uy", "uz"],
            Block::RefT => &["reference twist"],
        }
    }

    fn from_name(name: &str) -> Option<Block> {
        BLOCKS.into_iter().find(|b| b.name() == name)
    }
}

fn block_list() -> String {
    BLOCKS
        .iter()
        .map(|b| format!("*{}", b.name()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A pattern problem: the file, the block and line where it stands (when there is one) and what is wrong.
/// Displayed as one line `FILE: block *NAME, line L: MESSAGE`.
#[derive(Clone, Debug, PartialEq)]
pub struct PatternError {
    /// The file name as given to the reader (or the name given to [`Pattern::validate_as`]).
    pub file: String,
    /// The block name without the `*` (also for an unknown block).
    pub block: Option<String>,
    /// 1-based line number.
    pub line: Option<usize>,
    pub message: String,
}

impl fmt::Display for PatternError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", self.file)?;
        match (&self.block, self.line) {
            (Some(b), Some(l)) => write!(f, "block *{b}, line {l}: ")?,
            (Some(b), None) => write!(f, "block *{b}: ")?,
            (None, Some(l)) => write!(f, "line {l}: ")?,
            (None, None) => {}
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for PatternError {}

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

/// A float in the writer's format: shortest round-trip digits, exponent notation outside 1e-4 ≤ |x| < 1e6 with
/// a signed exponent of at least two digits as C's `%g` writes it (`-2.45507e-05`, `1e+06`), so that the original
/// files, printed with `%g`, are reproduced byte for byte (up to line ends).
fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-4..1e6).contains(&a) || !a.is_finite() {
        return format!("{x}");
    }
    let s = format!("{x:e}");
    match s.split_once('e') {
        Some((mantissa, exp)) => {
            let (sign, digits) = match exp.strip_prefix('-') {
                Some(d) => ('-', d),
                None => ('+', exp),
            };
            format!("{mantissa}e{sign}{digits:0>2}")
        }
        None => s,
    }
}

/// Where each datum stands: the header line of every block, and the line of every record (for `*E` indexed by
/// the edge's start vertex).
struct Lines {
    header: [usize; 8],
    records: [Vec<usize>; 8],
}

impl Lines {
    fn record(&self, b: Block, i: usize) -> Option<usize> {
        self.records[b.index()]
            .get(i)
            .copied()
            .or(Some(self.header[b.index()]))
    }

    /// The layout [`Pattern::to_pyp_string`] writes.
    fn layout(p: &Pattern) -> Lines {
        let n = p.len();
        let mut header = [0; 8];
        let mut records: [Vec<usize>; 8] = Default::default();
        for b in BLOCKS {
            let h = if b == Block::Pattern {
                1
            } else {
                4 + (b.index() - 1) * (n + 2)
            };
            header[b.index()] = h;
            records[b.index()] = if b == Block::Pattern {
                vec![2]
            } else {
                (0..n).map(|i| h + 1 + i).collect()
            };
        }
        if let Some(order) = p.file_order().filter(|o| o.len() == n) {
            let h = header[Block::E.index()];
            for (k, &v) in order.iter().enumerate() {
                records[Block::E.index()][v] = h + 1 + k;
            }
        }
        Lines { header, records }
    }
}

struct Record<'a> {
    line: usize,
    tokens: Vec<&'a str>,
}

struct RawBlock<'a> {
    header: usize,
    records: Vec<Record<'a>>,
}

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn err(&self, b: Option<Block>, line: Option<usize>, msg: impl Into<String>) -> PatternError {
        PatternError {
            file: self.file.to_string(),
            block: b.map(|b| b.name().to_string()),
            line,
            message: msg.into(),
        }
    }

    fn float(&self, b: Block, rec: &Record, k: usize) -> Result<f64, PatternError> {
        let tok = rec.tokens[k];
        let field = b.fields()[k];
        match tok.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.err(
                Some(b),
                Some(rec.line),
                format!("{field} = {tok} is not finite (NaN and infinity are not allowed)"),
            )),
            Err(_) => Err(self.err(
                Some(b),
                Some(rec.line),
                format!("{field} = {tok:?} is not a number"),
            )),
        }
    }

    fn int(&self, b: Block, rec: &Record, k: usize) -> Result<i64, PatternError> {
        let tok = rec.tokens[k];
        let field = b.fields()[k];
        tok.parse::<i64>().map_err(|_| {
            let digits = tok.strip_prefix(['-', '+']).unwrap_or(tok);
            let hint = if !digits.is_empty() && digits.bytes().all(|c| c.is_ascii_digit()) {
                "too large"
            } else if tok.parse::<f64>().is_ok() {
                "not an integer"
            } else {
                "not a number"
            };
            self.err(
                Some(b),
                Some(rec.line),
                format!("{field} = {tok:?} is {hint}"),
            )
        })
    }
}

fn vertex_range(n: usize) -> String {
    match n {
        1 => "1 vertex (0)".to_string(),
        _ => format!("{n} vertices (0..{})", n - 1),
    }
}

fn check_offset(d: i64) -> bool {
    (-1..=1).contains(&d)
}

impl Pattern {
    /// Parse `.pyp` text (see the module documentation); `file` names the source in messages. Returns the
    /// pattern and the warnings of [`Pattern::validate_as`].
    pub fn from_pyp_str(
        text: &str,
        file: &str,
    ) -> Result<(Pattern, Vec<PatternWarning>), PatternError> {
        let cx = Ctx { file };
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let sep = if text.contains('\n') { '\n' } else { '\r' };
        let mut blocks: [Option<RawBlock>; 8] = Default::default();
        let mut current: Option<Block> = None;
        for (k, raw) in text.split(sep).enumerate() {
            let line = k + 1;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            if let Some(name) = content.strip_prefix('*') {
                let name = name.trim();
                if name.is_empty() || name.contains(char::is_whitespace) {
                    return Err(cx.err(
                        None,
                        Some(line),
                        format!(
                            "malformed block header {content:?} (expected one of {})",
                            block_list()
                        ),
                    ));
                }
                let Some(b) = Block::from_name(name) else {
                    return Err(PatternError {
                        file: file.to_string(),
                        block: Some(name.to_string()),
                        line: Some(line),
                        message: format!(
                            "unknown block (a .pyp file has {}; unknown data is not ignored)",
                            block_list()
                        ),
                    });
                };
                if let Some(first) = &blocks[b.index()] {
                    return Err(cx.err(
                        Some(b),
                        Some(line),
                        format!("the block appears twice (first on line {})", first.header),
                    ));
                }
                blocks[b.index()] = Some(RawBlock {
                    header: line,
                    records: Vec::new(),
                });
                current = Some(b);
                continue;
            }
            let Some(b) = current else {
                return Err(cx.err(
                    None,
                    Some(line),
                    "data before the first block header (a .pyp file starts with *pattern)",
                ));
            };
            if let Some(blk) = blocks[b.index()].as_mut() {
                blk.records.push(Record {
                    line,
                    tokens: content.split_whitespace().collect(),
                });
            }
        }
        let present: Vec<String> = BLOCKS
            .iter()
            .filter(|b| blocks[b.index()].is_some())
            .map(|b| format!("*{}", b.name()))
            .collect();
        let mut raw: Vec<RawBlock> = Vec::with_capacity(8);
        for (b, blk) in BLOCKS.into_iter().zip(blocks) {
            match blk {
                Some(blk) => raw.push(blk),
                None => {
                    return Err(cx.err(
                        Some(b),
                        None,
                        format!(
                            "missing block (the file has {})",
                            if present.is_empty() {
                                "no blocks".to_string()
                            } else {
                                present.join(", ")
                            }
                        ),
                    ))
                }
            }
        }
        let blk = |b: Block| &raw[b.index()];

        // field counts of every record
        let check_fields = |b: Block, rec: &Record| -> Result<(), PatternError> {
            let want = b.fields().len();
            if rec.tokens.len() != want {
                let what = if want == 1 {
                    format!("1 number ({})", b.fields()[0])
                } else {
                    format!("{want} numbers ({})", b.fields().join(" "))
                };
                return Err(cx.err(
                    Some(b),
                    Some(rec.line),
                    format!("expected {what}, found {}", rec.tokens.len()),
                ));
            }
            Ok(())
        };

        // *pattern
        let pb = blk(Block::Pattern);
        let prec = match pb.records.as_slice() {
            [] => {
                return Err(cx.err(
                    Some(Block::Pattern),
                    Some(pb.header),
                    "empty block: expected one line `px py r n`",
                ))
            }
            [r] => r,
            [_, r, ..] => {
                return Err(cx.err(
                    Some(Block::Pattern),
                    Some(r.line),
                    "expected one line `px py r n`, found more",
                ))
            }
        };
        check_fields(Block::Pattern, prec)?;
        let px = cx.float(Block::Pattern, prec, 0)?;
        let py = cx.float(Block::Pattern, prec, 1)?;
        let r = cx.float(Block::Pattern, prec, 2)?;
        let n_raw = cx.int(Block::Pattern, prec, 3)?;
        if n_raw <= 0 {
            return Err(cx.err(
                Some(Block::Pattern),
                Some(prec.line),
                format!("n = {n_raw}: the number of vertices must be positive"),
            ));
        }
        let n_line = prec.line;

        // record counts (before anything of size n is allocated)
        for b in &BLOCKS[1..] {
            let rb = blk(*b);
            if rb.records.len() > n_raw as usize {
                return Err(cx.err(
                    Some(*b),
                    Some(rb.records[n_raw as usize].line),
                    format!(
                        "more than n = {n_raw} data lines (*pattern, line {n_line}); this is line {} of the block",
                        n_raw + 1
                    ),
                ));
            }
            if rb.records.len() < n_raw as usize {
                return Err(cx.err(
                    Some(*b),
                    Some(rb.header),
                    format!(
                        "{} data lines, but *pattern (line {n_line}) says n = {n_raw}",
                        rb.records.len()
                    ),
                ));
            }
            for rec in &rb.records {
                check_fields(*b, rec)?;
            }
        }
        let n = n_raw as usize;

        let floats = |b: Block| -> Result<Vec<Vec<f64>>, PatternError> {
            blk(b)
                .records
                .iter()
                .map(|rec| (0..b.fields().len()).map(|k| cx.float(b, rec, k)).collect())
                .collect()
        };
        let q = floats(Block::Q)?;

        // *E: one outgoing edge per vertex
        let mut e_lines = vec![0usize; n];
        let mut ends = vec![(0usize, [0i32; 2]); n];
        let mut order = Vec::with_capacity(n);
        for rec in &blk(Block::E).records {
            let v0 = cx.int(Block::E, rec, 0)?;
            let v1 = cx.int(Block::E, rec, 1)?;
            let dx = cx.int(Block::E, rec, 2)?;
            let dy = cx.int(Block::E, rec, 3)?;
            let here = |msg: String| cx.err(Some(Block::E), Some(rec.line), msg);
            if v0 < 0 || v0 >= n_raw {
                return Err(here(format!(
                    "an edge starts at vertex {v0} but the pattern has {}",
                    vertex_range(n)
                )));
            }
            let v0 = v0 as usize;
            if v1 < 0 || v1 >= n_raw {
                return Err(here(format!(
                    "edge {v0} ends at vertex {v1} but the pattern has {}",
                    vertex_range(n)
                )));
            }
            for (d, name) in [(dx, "dx"), (dy, "dy")] {
                if !check_offset(d) {
                    return Err(here(format!(
                        "edge {v0} has offset {name} = {d} (must be -1, 0 or 1)"
                    )));
                }
            }
            if e_lines[v0] != 0 {
                return Err(here(format!(
                    "a second edge starts at vertex {v0} (the first is on line {}): every vertex has exactly one \
                     outgoing edge",
                    e_lines[v0]
                )));
            }
            e_lines[v0] = rec.line;
            ends[v0] = (v1 as usize, [dx as i32, dy as i32]);
            order.push(v0);
        }
        let rl = floats(Block::RL)?;
        let rk = floats(Block::RK)?;
        let rt = floats(Block::RT)?;
        let d1 = floats(Block::RefD1)?;
        let reft = floats(Block::RefT)?;

        let pattern = Pattern {
            periods: [px, py],
            radius: r,
            positions: q.iter().map(|v| Vector3::new(v[0], v[1], v[2])).collect(),
            theta: q.iter().map(|v| v[3]).collect(),
            edges: (0..n)
                .map(|i| Edge {
                    end: ends[i].0,
                    offset: ends[i].1,
                    rest_length: rl[i][0],
                    ref_director: Vector3::new(d1[i][0], d1[i][1], d1[i][2]),
                })
                .collect(),
            rest_curvature: rk.iter().map(|v| [v[0], v[1]]).collect(),
            rest_twist: rt.iter().map(|v| v[0]).collect(),
            ref_twist: reft.iter().map(|v| v[0]).collect(),
            edge_file_order: order,
        };
        let mut header = [0; 8];
        let mut records: [Vec<usize>; 8] = Default::default();
        for b in BLOCKS {
            header[b.index()] = raw[b.index()].header;
            records[b.index()] = if b == Block::E {
                e_lines.clone()
            } else {
                raw[b.index()].records.iter().map(|r| r.line).collect()
            };
        }
        let warnings = pattern.validate_impl(file, &Lines { header, records })?;
        Ok((pattern, warnings))
    }

    /// [`load_pyp`](Self::load_pyp), then, when the file's periods disagree with its periodic edges' rest lengths
    /// (a [`PatternWarning`]), the implied periods instead (the original basket needs this). Returns the stored
    /// periods that were replaced, if any.
    pub fn load_pyp_at_implied_periods(
        path: impl AsRef<Path>,
    ) -> Result<(Pattern, Option<[f64; 2]>), PatternError> {
        let (mut p, warnings) = Self::load_pyp(path)?;
        let mut replaced = None;
        if !warnings.is_empty() {
            if let Some(implied) = p.implied_periods() {
                replaced = Some(p.periods);
                p.periods = implied;
            }
        }
        Ok((p, replaced))
    }

    /// Read a `.pyp` file (see [`Pattern::from_pyp_str`]); messages name the path as given.
    pub fn load_pyp(
        path: impl AsRef<Path>,
    ) -> Result<(Pattern, Vec<PatternWarning>), PatternError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| PatternError {
            file: name.clone(),
            block: None,
            line: None,
            message: format!("cannot read: {e}"),
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let line = e.as_bytes()[..at].iter().filter(|&&c| c == b'\n').count() + 1;
            PatternError {
                file: name.clone(),
                block: None,
                line: Some(line),
                message: "not UTF-8 text".to_string(),
            }
        })?;
        Pattern::from_pyp_str(&text, &name)
    }

    /// The pattern as `.pyp` text in the originals' layout (see the module documentation). Edges are listed in
    /// [`Pattern::edge_file_order`] when that is a permutation of 0..n, else by start vertex. Never panics, also
    /// for an inconsistent pattern (which then gives a file the reader rejects).
    pub fn to_pyp_string(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let n = self.len();
        let head = |s: &mut String, b: Block| {
            let _ = writeln!(s, "*{} # {}", b.name(), b.comment());
        };
        head(&mut s, Block::Pattern);
        let _ = writeln!(
            s,
            "{} {} {} {n}\n",
            num(self.periods[0]),
            num(self.periods[1]),
            num(self.radius)
        );
        head(&mut s, Block::Q);
        for (x, t) in self.positions.iter().zip(&self.theta) {
            let _ = writeln!(s, "{} {} {} {}", num(x[0]), num(x[1]), num(x[2]), num(*t));
        }
        s.push('\n');
        head(&mut s, Block::E);
        let order: Vec<usize> = self
            .file_order()
            .map(|o| o.to_vec())
            .unwrap_or_else(|| (0..self.edges.len()).collect());
        for v in order {
            let e = &self.edges[v];
            let _ = writeln!(s, "{v} {} {} {}", e.end, e.offset[0], e.offset[1]);
        }
        s.push('\n');
        head(&mut s, Block::RL);
        for e in &self.edges {
            let _ = writeln!(s, "{}", num(e.rest_length));
        }
        s.push('\n');
        head(&mut s, Block::RK);
        for k in &self.rest_curvature {
            let _ = writeln!(s, "{} {}", num(k[0]), num(k[1]));
        }
        s.push('\n');
        head(&mut s, Block::RT);
        for t in &self.rest_twist {
            let _ = writeln!(s, "{}", num(*t));
        }
        s.push('\n');
        head(&mut s, Block::RefD1);
        for e in &self.edges {
            let u = e.ref_director;
            let _ = writeln!(s, "{} {} {}", num(u[0]), num(u[1]), num(u[2]));
        }
        s.push('\n');
        head(&mut s, Block::RefT);
        for t in &self.ref_twist {
            let _ = writeln!(s, "{}", num(*t));
        }
        s.push('\n');
        s
    }

    /// Write the pattern as a `.pyp` file, atomically: a temporary file in the same folder is renamed into place.
    /// The pattern is written as it is (call [`Pattern::validate`] first for a generated one).
    pub fn save_pyp(&self, path: impl AsRef<Path>) -> Result<(), PatternError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let fail = |message: String| PatternError {
            file: name.clone(),
            block: None,
            line: None,
            message,
        };
        let Some(base) = path.file_name() else {
            return Err(fail("cannot write: not a file name".to_string()));
        };
        let tmp = path.with_file_name(format!(
            ".{}.{}.tmp",
            base.to_string_lossy(),
            std::process::id()
        ));
        if let Err(e) = std::fs::write(&tmp, self.to_pyp_string()) {
            let _ = std::fs::remove_file(&tmp);
            return Err(fail(format!("cannot write: {e}")));
        }
        std::fs::rename(&tmp, path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            fail(format!("cannot write: {e}"))
        })
    }

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

    /// `edge_file_order` if it is a permutation of 0..edges.len().
    fn file_order(&self) -> Option<&[usize]> {
        let m = self.edges.len();
        if self.edge_file_order.len() != m {
            return None;
        }
        let mut seen = vec![false; m];
        for &v in &self.edge_file_order {
            if v >= m || seen[v] {
                return None;
            }
            seen[v] = true;
        }
        Some(&self.edge_file_order)
    }

    fn validate_impl(
        &self,
        file: &str,
        lines: &Lines,
    ) -> Result<Vec<PatternWarning>, PatternError> {
        let cx = Ctx { file };
        let at = |b: Block, i: usize, msg: String| cx.err(Some(b), lines.record(b, i), msg);
        let head = |b: Block, msg: String| cx.err(Some(b), Some(lines.header[b.index()]), msg);
        let n = self.len();
        if n == 0 {
            return Err(at(
                Block::Pattern,
                0,
                "n = 0: the number of vertices must be positive".into(),
            ));
        }
        let sizes: [(Block, &str, usize); 6] = [
            (Block::Q, "theta", self.theta.len()),
            (Block::E, "edges", self.edges.len()),
            (Block::RK, "rest_curvature", self.rest_curvature.len()),
            (Block::RT, "rest_twist", self.rest_twist.len()),
            (Block::RefT, "ref_twist", self.ref_twist.len()),
            (Block::E, "edge_file_order", self.edge_file_order.len()),
        ];
        for (b, field, len) in sizes {
            if len != n {
                return Err(head(
                    b,
                    format!("{field} has {len} entries but the pattern has {n} vertices"),
                ));
            }
        }
        if self.file_order().is_none() {
            return Err(head(
                Block::E,
                format!("edge_file_order is not a permutation of 0..{n}"),
            ));
        }
        // *pattern
        let p = Block::Pattern;
        for (name, v) in [
            ("px", self.periods[0]),
            ("py", self.periods[1]),
            ("r", self.radius),
        ] {
            if !v.is_finite() {
                return Err(at(p, 0, format!("{name} = {v} is not finite")));
            }
            if v <= 0.0 {
                return Err(at(p, 0, format!("{name} = {v} must be positive")));
            }
        }
        // finite numbers
        let finite = |b: Block, i: usize, vals: &[f64]| -> Result<(), PatternError> {
            for (k, v) in vals.iter().enumerate() {
                if !v.is_finite() {
                    return Err(at(
                        b,
                        i,
                        format!("{} = {v} of vertex {i} is not finite", b.fields()[k]),
                    ));
                }
            }
            Ok(())
        };
        for i in 0..n {
            let x = self.positions[i];
            finite(Block::Q, i, &[x[0], x[1], x[2], self.theta[i]])?;
            let e = &self.edges[i];
            finite(Block::RL, i, &[e.rest_length])?;
            finite(Block::RK, i, &self.rest_curvature[i])?;
            finite(Block::RT, i, &[self.rest_twist[i]])?;
            let u = e.ref_director;
            finite(Block::RefD1, i, &[u[0], u[1], u[2]])?;
            finite(Block::RefT, i, &[self.ref_twist[i]])?;
        }
        // edges, in file order so that "the second edge" is the later line
        let mut incoming = vec![usize::MAX; n];
        for &i in &self.edge_file_order {
            let e = &self.edges[i];
            if e.end >= n {
                return Err(at(
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
                    return Err(at(
                        Block::E,
                        i,
                        format!("edge {i} has offset {name} = {d} (must be -1, 0 or 1)"),
                    ));
                }
            }
            let first = incoming[e.end];
            if first != usize::MAX {
                let orphan = (0..n)
                    .find(|&v| !self.edges.iter().any(|f| f.end == v))
                    .map(|v| format!(", so vertex {v} has none"))
                    .unwrap_or_default();
                return Err(at(
                    Block::E,
                    i,
                    format!(
                        "edges {first} (line {}) and {i} both end at vertex {}{orphan}: every vertex has exactly \
                         one incoming edge",
                        lines.record(Block::E, first).unwrap_or(0),
                        e.end
                    ),
                ));
            }
            incoming[e.end] = i;
            if e.rest_length <= 0.0 {
                return Err(at(
                    Block::RL,
                    i,
                    format!("rest length {} of edge {i} must be positive", e.rest_length),
                ));
            }
        }
        for i in 0..n {
            let l = self.edge_vector(i).norm();
            if !(l > 0.0 && l.is_finite()) {
                return Err(at(
                    Block::E,
                    i,
                    format!(
                        "edge {i} (vertex {i} to vertex {}) has length {l}",
                        self.edges[i].end
                    ),
                ));
            }
            let norm = self.edges[i].ref_director.norm();
            if (norm - 1.0).abs() > DIRECTOR_NORM_TOL {
                return Err(at(
                    Block::RefD1,
                    i,
                    format!(
                        "reference director of edge {i} has norm {} (must be 1 within {DIRECTOR_NORM_TOL:e})",
                        sig(norm, 8)
                    ),
                ));
            }
        }
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
        for i in 0..n {
            let c = self.director_cos(i, self.periods);
            if c <= DIRECTOR_PERP_TOL {
                continue;
            }
            let alt = match implied {
                Some(p) if self.edges[i].offset != [0, 0] => Some(self.director_cos(i, p)),
                _ => None,
            };
            if alt.is_some_and(|a| a <= DIRECTOR_PERP_TOL) {
                continue;
            }
            let alt_msg = alt
                .map(|a| format!(", {} at the implied periods", sig(a, 3)))
                .unwrap_or_default();
            return Err(at(
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
    /// iteration does not converge. Basket: 0.0108665 × 0.0104499 m against the stored 0.0107037 × 0.0103 m,
    /// after which its periodic edges match their rest lengths within 1e-5 (see the module documentation); the
    /// other originals: within 0.045 % of the stored periods. Periodic edges' directors are sensitive to the
    /// periods (stockinette's |u·t| grows from 8e-6 to 2e-3 at its implied periods), which is why the director
    /// check uses the implied periods only as an alternative for a pattern the period check flags.
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
