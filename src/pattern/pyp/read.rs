//! Reading `.pyp` text (the format and the reader's rules are in the [module documentation](super)): the text is
//! split into its eight blocks of records, the header line gives n, every block is checked for n records of its
//! field count, the numbers and edges are parsed, and the pattern is checked like [`Pattern::validate_as`] with
//! the lines of the file. Every error names its block and line.

use super::PatternWarning;
use super::{block_list, check_offset, vertex_range, Block, Ctx, Lines, PatternError, BLOCKS};
use crate::pattern::{Edge, Pattern};
use nalgebra::Vector3;

/// One data line: its 1-based line number and its whitespace-separated fields.
struct Record<'a> {
    line: usize,
    tokens: Vec<&'a str>,
}

/// One block: the line of its `*NAME` header and its data lines.
struct RawBlock<'a> {
    header: usize,
    records: Vec<Record<'a>>,
}

/// The block a `*NAME` line (comment removed, trimmed) on line `line` opens; an error for a malformed or unknown
/// name.
fn block_header(cx: &Ctx, content: &str, line: usize) -> Result<Block, PatternError> {
    let name = content.strip_prefix('*').unwrap_or(content).trim();
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
    Block::from_name(name).ok_or_else(|| PatternError {
        file: cx.file.to_string(),
        block: Some(name.to_string()),
        line: Some(line),
        message: format!(
            "unknown block (a .pyp file has {}; unknown data is not ignored)",
            block_list()
        ),
    })
}

/// The blocks of the text in [`BLOCKS`] order, each where it stands: a UTF-8 byte order mark, comments, blank
/// lines, and LF, CRLF or CR line ends are handled here. An error for a bad header, a block that appears twice, or
/// data before the first header.
fn scan<'a>(cx: &Ctx, text: &'a str) -> Result<[Option<RawBlock<'a>>; 8], PatternError> {
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
        if content.starts_with('*') {
            let b = block_header(cx, content, line)?;
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
    Ok(blocks)
}

/// All eight blocks in [`BLOCKS`] order; an error naming the first missing one.
fn require_all<'a>(
    cx: &Ctx,
    blocks: [Option<RawBlock<'a>>; 8],
) -> Result<Vec<RawBlock<'a>>, PatternError> {
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
    Ok(raw)
}

/// The `*pattern` line: periods, radius and the vertex count n (positive), with its line.
struct Header {
    px: f64,
    py: f64,
    r: f64,
    n: i64,
    line: usize,
}

impl Ctx<'_> {
    /// Field `k` of `rec` as a finite number.
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

    /// Field `k` of `rec` as an integer (written as one).
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

    /// An error unless `rec` has exactly the field count of block `b`.
    fn check_fields(&self, b: Block, rec: &Record) -> Result<(), PatternError> {
        let want = b.fields().len();
        if rec.tokens.len() != want {
            let what = if want == 1 {
                format!("1 number ({})", b.fields()[0])
            } else {
                format!("{want} numbers ({})", b.fields().join(" "))
            };
            return Err(self.err(
                Some(b),
                Some(rec.line),
                format!("expected {what}, found {}", rec.tokens.len()),
            ));
        }
        Ok(())
    }

    /// The one line of the `*pattern` block `pb`.
    fn header(&self, pb: &RawBlock) -> Result<Header, PatternError> {
        let prec = match pb.records.as_slice() {
            [] => {
                return Err(self.err(
                    Some(Block::Pattern),
                    Some(pb.header),
                    "empty block: expected one line `px py r n`",
                ))
            }
            [r] => r,
            [_, r, ..] => {
                return Err(self.err(
                    Some(Block::Pattern),
                    Some(r.line),
                    "expected one line `px py r n`, found more",
                ))
            }
        };
        self.check_fields(Block::Pattern, prec)?;
        let px = self.float(Block::Pattern, prec, 0)?;
        let py = self.float(Block::Pattern, prec, 1)?;
        let r = self.float(Block::Pattern, prec, 2)?;
        let n_raw = self.int(Block::Pattern, prec, 3)?;
        if n_raw <= 0 {
            return Err(self.err(
                Some(Block::Pattern),
                Some(prec.line),
                format!("n = {n_raw}: the number of vertices must be positive"),
            ));
        }
        Ok(Header {
            px,
            py,
            r,
            n: n_raw,
            line: prec.line,
        })
    }

    /// Every per-vertex block has exactly n records (checked before anything of size n is allocated), each with
    /// its field count.
    fn check_record_counts(&self, raw: &[RawBlock], h: &Header) -> Result<(), PatternError> {
        let (n_raw, n_line) = (h.n, h.line);
        for b in &BLOCKS[1..] {
            let rb = &raw[b.index()];
            if rb.records.len() > n_raw as usize {
                return Err(self.err(
                    Some(*b),
                    Some(rb.records[n_raw as usize].line),
                    format!(
                        "more than n = {n_raw} data lines (*pattern, line {n_line}); this is line {} of the block",
                        n_raw + 1
                    ),
                ));
            }
            if rb.records.len() < n_raw as usize {
                return Err(self.err(
                    Some(*b),
                    Some(rb.header),
                    format!(
                        "{} data lines, but *pattern (line {n_line}) says n = {n_raw}",
                        rb.records.len()
                    ),
                ));
            }
            for rec in &rb.records {
                self.check_fields(*b, rec)?;
            }
        }
        Ok(())
    }

    /// The numbers of every record of block `b` (a float block).
    fn floats(&self, b: Block, blk: &RawBlock) -> Result<Vec<Vec<f64>>, PatternError> {
        blk.records
            .iter()
            .map(|rec| {
                (0..b.fields().len())
                    .map(|k| self.float(b, rec, k))
                    .collect()
            })
            .collect()
    }

    /// The `*E` block of a pattern with `n_raw` vertices: one outgoing edge per vertex.
    fn edges(&self, blk: &RawBlock, n_raw: i64) -> Result<Edges, PatternError> {
        let n = n_raw as usize;
        let mut e_lines = vec![0usize; n];
        let mut ends = vec![(0usize, [0i32; 2]); n];
        let mut order = Vec::with_capacity(n);
        for rec in &blk.records {
            let v0 = self.int(Block::E, rec, 0)?;
            let v1 = self.int(Block::E, rec, 1)?;
            let dx = self.int(Block::E, rec, 2)?;
            let dy = self.int(Block::E, rec, 3)?;
            let here = |msg: String| self.err(Some(Block::E), Some(rec.line), msg);
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
        Ok(Edges {
            lines: e_lines,
            ends,
            order,
        })
    }
}

/// The `*E` block: per start vertex the line of its edge and (end vertex, offset); the start vertices in file
/// order.
struct Edges {
    lines: Vec<usize>,
    ends: Vec<(usize, [i32; 2])>,
    order: Vec<usize>,
}

/// Where every block and record of the file stands (`*E` records by start vertex).
fn source_lines(raw: &[RawBlock], e_lines: Vec<usize>) -> Lines {
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
    Lines { header, records }
}

impl Pattern {
    /// Parse `.pyp` text (see the module documentation); `file` names the source in messages. Returns the
    /// pattern and the warnings of [`Pattern::validate_as`].
    pub fn from_pyp_str(
        text: &str,
        file: &str,
    ) -> Result<(Pattern, Vec<PatternWarning>), PatternError> {
        let cx = Ctx { file };
        let raw = require_all(&cx, scan(&cx, text)?)?;
        let blk = |b: Block| &raw[b.index()];
        let h = cx.header(blk(Block::Pattern))?;
        cx.check_record_counts(&raw, &h)?;
        let n = h.n as usize;
        let q = cx.floats(Block::Q, blk(Block::Q))?;
        let edges = cx.edges(blk(Block::E), h.n)?;
        let rl = cx.floats(Block::RL, blk(Block::RL))?;
        let rk = cx.floats(Block::RK, blk(Block::RK))?;
        let rt = cx.floats(Block::RT, blk(Block::RT))?;
        let d1 = cx.floats(Block::RefD1, blk(Block::RefD1))?;
        let reft = cx.floats(Block::RefT, blk(Block::RefT))?;

        let pattern = Pattern {
            periods: [h.px, h.py],
            radius: h.r,
            positions: q.iter().map(|v| Vector3::new(v[0], v[1], v[2])).collect(),
            theta: q.iter().map(|v| v[3]).collect(),
            edges: (0..n)
                .map(|i| Edge {
                    end: edges.ends[i].0,
                    offset: edges.ends[i].1,
                    rest_length: rl[i][0],
                    ref_director: Vector3::new(d1[i][0], d1[i][1], d1[i][2]),
                })
                .collect(),
            rest_curvature: rk.iter().map(|v| [v[0], v[1]]).collect(),
            rest_twist: rt.iter().map(|v| v[0]).collect(),
            ref_twist: reft.iter().map(|v| v[0]).collect(),
            edge_file_order: edges.order,
        };
        let warnings = pattern.validate_impl(file, &source_lines(&raw, edges.lines))?;
        Ok((pattern, warnings))
    }
}
