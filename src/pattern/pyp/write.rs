//! Writing `.pyp` text in the originals' layout (see the [module documentation](super)).

use super::Block;
use crate::pattern::Pattern;

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

impl Pattern {
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
}
