//! `.pyp` pattern files (`docs/file-formats.md`, "Yarn pattern (`.pyp`)"): the five originals load,
//! round-trip to the last bit (and byte for byte up to line ends), basket gets its period warning; every kind of
//! bad input gives one line naming file, block and line, and no input panics. Tests of the originals read them
//! from `../shared` and skip with a message when it is absent; the rest use a small hand-made tile.

mod common;

use hylc::pattern::pyp::{DIRECTOR_NORM_TOL, DIRECTOR_PERP_TOL};
use hylc::pattern::{Pattern, PatternError, PatternWarning};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;
use std::process::Command;

/// The original files: name, vertices, yarns.
const ORIGINALS: [(&str, usize, usize); 5] = [
    ("basket", 80, 8),
    ("cartridge_belt_rib", 356, 4),
    ("satin", 130, 10),
    ("slip_stitch_honeycomb", 182, 4),
    ("stockinette", 100, 2),
];

/// A hand-made tile: two straight yarns crossing a 1 cm × 1 cm tile, yarn A (vertices 0–3) along x below, yarn B
/// (4–7) along y above, 4 vertices each. Line numbers: `*pattern` data on 3, `*Q` vertex i on 6+i, `*E` lines
/// 16–23 in the order 3,0,1,2,7,4,5,6, then vertex i of `*RL` on 26+i, `*RK` 36+i, `*RT` 46+i, `*RefD1` 56+i,
/// `*RefT` 66+i.
const TILE: &str = "\
# two straight yarns crossing a 1 cm tile (hand-made test pattern)
*pattern # px py radius num_vertedges
0.01 0.01 0.0005 8

*Q # dofs: x y z t
0.00125 0.005 -0.0005 0.1
0.00375 0.005 -0.0005 0.1
0.00625 0.005 -0.0005 0.1
0.00875 0.005 -0.0005 0.1
0.005 0.00125 0.0005 -0
0.005 0.00375 0.0005 0
0.005 0.00625 0.0005 2.5e-07
0.005 0.00875 0.0005 -3.14159

*E # edges [v0, v1, dx, dy]
3 0 1 0
0 1 0 0
1 2 0 0
2 3 0 0
7 4 0 1
4 5 0 0
5 6 0 0
6 7 0 0

*RL # rest lengths
0.0025
0.0025
0.0025
0.0025
0.0025
0.0025
0.0025
0.0025

*RK # rest kappas
0 0
1.5 -2.25
0 0
0 0
0 0
0 0
1e-300 0
0 0

*RT # rest twists
0
0
0.01
0
0
0
0
0

*RefD1 # reference directors
0 0 1
0 0 1
0 0 1
0 0 1
-1 0 0
-1 0 0
-1 0 0
-1 0 0

*RefT # reference twists
0
-0.003
0
0
0
0
0
123456789

";

fn tile() -> Pattern {
    let (p, w) = Pattern::from_pyp_str(TILE, "tile.pyp").expect("the hand-made tile is valid");
    assert!(w.is_empty(), "{w:?}");
    p
}

/// Replace 1-based line `line` of `text`.
fn with_line(text: &str, line: usize, new: &str) -> String {
    let mut lines: Vec<&str> = text.split('\n').collect();
    lines[line - 1] = new;
    lines.join("\n")
}

/// Insert `new` before 1-based line `line`.
fn insert_line(text: &str, line: usize, new: &str) -> String {
    let mut lines: Vec<&str> = text.split('\n').collect();
    lines.insert(line - 1, new);
    lines.join("\n")
}

/// Remove 1-based lines `from..=to`.
fn without_lines(text: &str, from: usize, to: usize) -> String {
    let lines: Vec<&str> = text.split('\n').collect();
    let mut kept = lines[..from - 1].to_vec();
    kept.extend_from_slice(&lines[to..]);
    kept.join("\n")
}

/// Every number of a pattern as bits, in a fixed order (so that == means bit-for-bit equal, −0 ≠ 0).
fn bits(p: &Pattern) -> Vec<u64> {
    let mut v: Vec<u64> = vec![
        p.periods[0].to_bits(),
        p.periods[1].to_bits(),
        p.radius.to_bits(),
    ];
    for x in &p.positions {
        v.extend(x.iter().map(|c| c.to_bits()));
    }
    v.extend(p.theta.iter().map(|c| c.to_bits()));
    for e in &p.edges {
        v.extend([e.end as u64, e.offset[0] as u64, e.offset[1] as u64]);
        v.push(e.rest_length.to_bits());
        v.extend(e.ref_director.iter().map(|c| c.to_bits()));
    }
    for k in &p.rest_curvature {
        v.extend(k.iter().map(|c| c.to_bits()));
    }
    v.extend(p.rest_twist.iter().map(|c| c.to_bits()));
    v.extend(p.ref_twist.iter().map(|c| c.to_bits()));
    v.extend(p.edge_file_order.iter().map(|&c| c as u64));
    v
}

/// Parse `text` as `tile.pyp`, expecting an error; check that its one line names the file, the block and the
/// line and contains `what`.
fn bad(text: &str, block: &str, line: Option<usize>, what: &str) -> PatternError {
    let e = match Pattern::from_pyp_str(text, "tile.pyp") {
        Ok(_) => panic!("accepted bad input (expected block *{block}, line {line:?}: {what})"),
        Err(e) => e,
    };
    let msg = e.to_string();
    assert_eq!(msg.lines().count(), 1, "{msg}");
    assert!(msg.starts_with("tile.pyp: "), "{msg}");
    assert_eq!(e.block.as_deref(), Some(block), "{msg}");
    assert_eq!(e.line, line, "{msg}");
    match line {
        Some(l) => assert!(
            msg.contains(&format!("block *{block}, line {l}: ")),
            "{msg}"
        ),
        None => assert!(msg.contains(&format!("block *{block}: ")), "{msg}"),
    }
    assert!(msg.contains(what), "expected {what:?} in: {msg}");
    eprintln!("{msg}");
    e
}

fn original_path(name: &str) -> Option<PathBuf> {
    let shared = common::shared_or_skip(&format!("original pattern {name}"))?;
    let path = shared.join(format!("data/hylc2020/patterns/{name}.pyp"));
    if path.is_file() {
        Some(path)
    } else {
        eprintln!("SKIPPED: {} not found", path.display());
        None
    }
}

// ---------------------------------------------------------------------------------------------------------------
// the hand-made tile

#[test]
fn tile_parses_with_edges_indexed_by_start_vertex() {
    let p = tile();
    assert_eq!(p.len(), 8);
    assert_eq!(p.periods, [0.01, 0.01]);
    assert_eq!(p.radius, 0.0005);
    assert_eq!(p.edge_file_order, vec![3, 0, 1, 2, 7, 4, 5, 6]);
    assert_eq!(p.edges[3].end, 0);
    assert_eq!(p.edges[3].offset, [1, 0]);
    assert_eq!(p.edges[7].offset, [0, 1]);
    assert_eq!(p.rest_curvature[1], [1.5, -2.25]);
    assert_eq!(p.rest_curvature[6][0], 1e-300);
    assert_eq!(p.rest_twist[2], 0.01);
    assert_eq!(p.ref_twist[1], -0.003);
    assert_eq!(p.theta[4].to_bits(), (-0.0f64).to_bits());
    assert_eq!(p.edges[7].ref_director, Vector3::new(-1.0, 0.0, 0.0));
    assert_eq!(p.yarns(), vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]]);
    let implied = p.implied_periods().unwrap();
    assert!(
        (0..2).all(|k| (implied[k] - 0.01).abs() < 1e-15),
        "{implied:?}"
    );
    assert!(p.edge_strains().iter().all(|s| s.abs() < 1e-12));
}

#[test]
fn tile_round_trips_bit_for_bit_and_keeps_the_edge_order() {
    let p = tile();
    let text = p.to_pyp_string();
    let (q, w) = Pattern::from_pyp_str(&text, "written.pyp").unwrap();
    assert!(w.is_empty());
    assert_eq!(bits(&p), bits(&q));
    assert_eq!(q.to_pyp_string(), text);
    // the edges come back in the file's order, with the originals' header comments
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "*pattern # px py radius num_vertedges");
    assert_eq!(lines[13], "*E # edges [v0, v1, dx, dy]");
    assert_eq!(lines[14], "3 0 1 0");
    assert_eq!(lines[18], "7 4 0 1");
    assert!(text.contains("\n2.5e-07 ") || text.contains(" 2.5e-07\n"));
    assert!(text.contains("\n1e-300 0\n"));
    assert!(text.contains("\n1.23456789e+08\n"));
}

#[test]
fn random_values_round_trip_bit_for_bit() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut p = tile();
    let any = |rng: &mut ChaCha8Rng| loop {
        let x = match rng.random_range(0..4) {
            0 => f64::from_bits(rng.random()),
            1 => rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(-320..300)),
            2 => rng.random_range(-1e7..1e7),
            _ => [
                0.0,
                -0.0,
                f64::MIN_POSITIVE,
                5e-324,
                f64::MAX,
                -f64::MAX,
                1e-4,
                1e6,
            ][rng.random_range(0..8)],
        };
        if x.is_finite() {
            return x;
        }
    };
    for _ in 0..200 {
        for i in 0..p.len() {
            p.theta[i] = any(&mut rng);
            p.rest_curvature[i] = [any(&mut rng), any(&mut rng)];
            p.rest_twist[i] = any(&mut rng);
            p.ref_twist[i] = any(&mut rng);
        }
        let (q, _) = Pattern::from_pyp_str(&p.to_pyp_string(), "random.pyp").unwrap();
        assert_eq!(bits(&p), bits(&q));
    }
}

#[test]
fn reader_tolerates_crlf_comments_spacing_and_block_order() {
    let p = tile();
    // CRLF
    let crlf = TILE.replace('\n', "\r\n");
    assert_eq!(
        bits(&Pattern::from_pyp_str(&crlf, "crlf.pyp").unwrap().0),
        bits(&p)
    );
    // CR only
    let cr = TILE.replace('\n', "\r");
    assert_eq!(
        bits(&Pattern::from_pyp_str(&cr, "cr.pyp").unwrap().0),
        bits(&p)
    );
    // byte order mark, tabs, extra spaces, trailing comments, no blank lines, blocks in reverse order
    let text = p.to_pyp_string();
    let mut blocks: Vec<String> = text
        .split("\n\n")
        .filter(|b| !b.trim().is_empty())
        .map(|b| {
            b.lines()
                .map(|l| format!("  {}\t # note", l.replace(' ', " \t  ")))
                .collect::<Vec<_>>()
                .join("\n")
        })
        .collect();
    blocks.reverse();
    let messy = format!(
        "\u{feff}# header comment\n{}\n# end",
        blocks.join("\n# between\n")
    );
    let (q, _) = Pattern::from_pyp_str(&messy, "messy.pyp").unwrap();
    assert_eq!(bits(&q), bits(&p));
}

#[test]
fn save_is_atomic_and_load_reads_it_back() {
    let dir = std::env::temp_dir().join(format!("hylc-pyp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tile.pyp");
    let p = tile();
    p.save_pyp(&path).unwrap();
    let (q, _) = Pattern::load_pyp(&path).unwrap();
    assert_eq!(bits(&p), bits(&q));
    // overwriting leaves no temporary file behind
    p.save_pyp(&path).unwrap();
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["tile.pyp".to_string()]);
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------------------------
// bad input: one test per category

#[test]
fn missing_block() {
    let e = bad(&without_lines(TILE, 45, 54), "RT", None, "missing block");
    assert!(e.to_string().contains("*RK, *RefD1"));
    bad(
        "",
        "pattern",
        None,
        "missing block (the file has no blocks)",
    );
    bad("# only a comment\n\n", "pattern", None, "missing block");
}

#[test]
fn wrong_line_counts() {
    bad(
        &without_lines(TILE, 9, 9),
        "Q",
        Some(5),
        "7 data lines, but *pattern (line 3) says n = 8",
    );
    bad(
        &insert_line(TILE, 34, "0.0025"),
        "RL",
        Some(34),
        "more than n = 8 data lines",
    );
    bad(
        &with_line(TILE, 3, "0.01 0.01 0.0005 9"),
        "Q",
        Some(5),
        "8 data lines, but *pattern (line 3) says n = 9",
    );
    bad(
        &insert_line(TILE, 4, "0.01 0.01 0.0005 8"),
        "pattern",
        Some(4),
        "expected one line",
    );
    bad(
        &without_lines(TILE, 3, 3),
        "pattern",
        Some(2),
        "empty block",
    );
}

#[test]
fn wrong_number_of_fields() {
    bad(
        &with_line(TILE, 8, "0.00625 0.005 -0.0005"),
        "Q",
        Some(8),
        "expected 4 numbers (x y z theta), found 3",
    );
    bad(
        &with_line(TILE, 27, "0.0025 0.0025"),
        "RL",
        Some(27),
        "expected 1 number (rest length), found 2",
    );
    bad(
        &with_line(TILE, 17, "0 1 0 0 0"),
        "E",
        Some(17),
        "expected 4 numbers (v0 v1 dx dy), found 5",
    );
    bad(
        &with_line(TILE, 3, "0.01 0.01 8"),
        "pattern",
        Some(3),
        "found 3",
    );
}

#[test]
fn unparsable_numbers() {
    bad(
        &with_line(TILE, 47, "0.0x1"),
        "RT",
        Some(47),
        "rest twist = \"0.0x1\" is not a number",
    );
    bad(
        &with_line(TILE, 37, "1,5 -2.25"),
        "RK",
        Some(37),
        "k1 = \"1,5\" is not a number",
    );
    bad(
        &with_line(TILE, 18, "1 2.0 0 0"),
        "E",
        Some(18),
        "v1 = \"2.0\" is not an integer",
    );
    bad(
        &with_line(TILE, 3, "0.01 0.01 0.0005 8.0"),
        "pattern",
        Some(3),
        "n = \"8.0\" is not an integer",
    );
}

#[test]
fn nan_and_infinity() {
    bad(
        &with_line(TILE, 68, "nan"),
        "RefT",
        Some(68),
        "is not finite",
    );
    bad(
        &with_line(TILE, 7, "0.00375 0.005 -0.0005 inf"),
        "Q",
        Some(7),
        "theta = inf is not finite",
    );
    bad(
        &with_line(TILE, 58, "0 0 -Infinity"),
        "RefD1",
        Some(58),
        "uz = -Infinity is not finite",
    );
    bad(
        &with_line(TILE, 3, "1e400 0.01 0.0005 8"),
        "pattern",
        Some(3),
        "px = 1e400 is not finite",
    );
}

#[test]
fn edge_to_a_missing_vertex() {
    bad(
        &with_line(TILE, 18, "1 8 0 0"),
        "E",
        Some(18),
        "edge 1 ends at vertex 8 but the pattern has 8 vertices (0..7)",
    );
    bad(
        &with_line(TILE, 18, "1 -1 0 0"),
        "E",
        Some(18),
        "ends at vertex -1",
    );
    bad(
        &with_line(TILE, 18, "9 2 0 0"),
        "E",
        Some(18),
        "an edge starts at vertex 9 but the pattern has 8 vertices",
    );
}

#[test]
fn two_outgoing_edges_at_a_vertex() {
    bad(
        &with_line(TILE, 18, "0 2 0 0"),
        "E",
        Some(18),
        "a second edge starts at vertex 0 (the first is on line 17)",
    );
}

#[test]
fn vertex_without_incoming_edge() {
    // edges 1 and 2 both end at vertex 3; the later line is reported
    bad(
        &with_line(TILE, 18, "1 3 0 0"),
        "E",
        Some(19),
        "edges 1 (line 18) and 2 both end at vertex 3, so vertex 2 has none",
    );
}

#[test]
fn offset_outside_minus_one_to_one() {
    bad(
        &with_line(TILE, 16, "3 0 2 0"),
        "E",
        Some(16),
        "edge 3 has offset dx = 2 (must be -1, 0 or 1)",
    );
    bad(&with_line(TILE, 20, "7 4 0 -5"), "E", Some(20), "dy = -5");
    bad(
        &with_line(TILE, 20, "7 4 0 99999999999999999999"),
        "E",
        Some(20),
        "is too large",
    );
}

#[test]
fn non_positive_sizes() {
    bad(
        &with_line(TILE, 3, "0 0.01 0.0005 8"),
        "pattern",
        Some(3),
        "px = 0 must be positive",
    );
    bad(
        &with_line(TILE, 3, "0.01 -0.01 0.0005 8"),
        "pattern",
        Some(3),
        "py = -0.01 must be positive",
    );
    bad(
        &with_line(TILE, 3, "0.01 0.01 -0 8"),
        "pattern",
        Some(3),
        "r = -0 must be positive",
    );
    bad(
        &with_line(TILE, 3, "0.01 0.01 0.0005 0"),
        "pattern",
        Some(3),
        "n = 0: the number of vertices must be positive",
    );
    bad(
        &with_line(TILE, 3, "0.01 0.01 0.0005 -3"),
        "pattern",
        Some(3),
        "n = -3",
    );
    bad(
        &with_line(TILE, 27, "0"),
        "RL",
        Some(27),
        "rest length 0 of edge 1 must be positive",
    );
    bad(
        &with_line(TILE, 33, "-0.0025"),
        "RL",
        Some(33),
        "rest length -0.0025 of edge 7 must be positive",
    );
}

#[test]
fn director_not_unit_or_not_perpendicular() {
    bad(
        &with_line(TILE, 57, "0 0 1.1"),
        "RefD1",
        Some(57),
        "reference director of edge 1 has norm 1.1",
    );
    bad(
        &with_line(TILE, 57, "0 0 1.0001"),
        "RefD1",
        Some(57),
        "has norm 1.0001 (must be 1 within 1e-5)",
    );
    bad(
        &with_line(TILE, 56, "0.6 0 0.8"),
        "RefD1",
        Some(56),
        "reference director of edge 0 is not perpendicular to the edge: |u·t| = 0.6",
    );
    // the tangent itself
    bad(
        &with_line(TILE, 63, "0 1 0"),
        "RefD1",
        Some(63),
        "|u·t| = 1",
    );
    // just inside the tolerance passes
    let c: f64 = 0.5 * DIRECTOR_PERP_TOL;
    let line = format!("{} 0 {}", c, (1.0 - c * c).sqrt());
    assert!(Pattern::from_pyp_str(&with_line(TILE, 56, &line), "tile.pyp").is_ok());
}

#[test]
fn edge_of_zero_length() {
    bad(
        &with_line(TILE, 7, "0.00125 0.005 -0.0005 0.1"),
        "E",
        Some(17),
        "edge 0 (vertex 0 to vertex 1) has length 0",
    );
}

#[test]
fn unknown_duplicate_and_malformed_blocks() {
    let e = bad(
        &insert_line(TILE, 74, "*Extra # something else\n1 2 3"),
        "Extra",
        Some(74),
        "unknown block",
    );
    assert!(e
        .message
        .contains("*pattern, *Q, *E, *RL, *RK, *RT, *RefD1, *RefT"));
    bad(
        &insert_line(TILE, 74, "*RT\n0"),
        "RT",
        Some(74),
        "the block appears twice (first on line 45)",
    );
    let e = Pattern::from_pyp_str(&with_line(TILE, 45, "*R T"), "tile.pyp").unwrap_err();
    assert_eq!((e.block.as_deref(), e.line), (None, Some(45)), "{e}");
    assert!(
        e.to_string()
            .starts_with("tile.pyp: line 45: malformed block header"),
        "{e}"
    );
    let e = Pattern::from_pyp_str(&insert_line(TILE, 1, "0.01 0.01"), "tile.pyp").unwrap_err();
    assert_eq!(
        e.to_string(),
        "tile.pyp: line 1: data before the first block header (a .pyp file starts with *pattern)"
    );
}

#[test]
fn io_errors_name_the_file() {
    let dir = std::env::temp_dir().join(format!("hylc-pyp-io-{}", std::process::id()));
    let missing = dir.join("nope.pyp");
    let e = Pattern::load_pyp(&missing).unwrap_err();
    assert!(
        e.to_string()
            .starts_with(&format!("{}: cannot read: ", missing.display())),
        "{e}"
    );
    assert_eq!(e.to_string().lines().count(), 1);
    let e = tile()
        .save_pyp(dir.join("no/such/folder/t.pyp"))
        .unwrap_err();
    assert!(e.to_string().contains("t.pyp: cannot write: "), "{e}");
    std::fs::create_dir_all(&dir).unwrap();
    let binary = dir.join("binary.pyp");
    std::fs::write(&binary, b"*pattern\n0.01 0.01 \xff\xfe 8\n").unwrap();
    let e = Pattern::load_pyp(&binary).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("binary.pyp: line 2: not UTF-8 text"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------------------------
// validate() on patterns built in memory: line numbers are those of the file to_pyp_string would write

/// Validate `p`, expecting an error at `block` whose line in `p.to_pyp_string()` contains `written`.
fn bad_in_memory(p: &Pattern, block: &str, written: &str, what: &str) {
    let text = p.to_pyp_string();
    let e = p.validate_as("gen").unwrap_err();
    let msg = e.to_string();
    assert_eq!(msg.lines().count(), 1);
    assert!(
        msg.starts_with(&format!("gen: block *{block}, line ")),
        "{msg}"
    );
    assert!(msg.contains(what), "expected {what:?} in: {msg}");
    let line = e.line.unwrap();
    let at = text.lines().nth(line - 1).unwrap_or("");
    assert!(
        at.contains(written),
        "line {line} of the written file is {at:?}, expected {written:?} ({msg})"
    );
    // the written file is rejected by the reader too, also without panicking
    assert!(Pattern::from_pyp_str(&text, "gen.pyp").is_err(), "{msg}");
}

#[test]
fn validate_checks_patterns_built_in_memory() {
    let good = tile();
    assert_eq!(good.validate(), Ok(vec![]));
    let mut p = good.clone();
    p.positions[2].x = f64::NAN;
    bad_in_memory(&p, "Q", "NaN 0.005", "x = NaN of vertex 2 is not finite");
    let mut p = good.clone();
    p.edges[5].end = 99;
    bad_in_memory(
        &p,
        "E",
        "5 99 0 0",
        "edge 5 ends at vertex 99 but the pattern has 8 vertices (0..7)",
    );
    let mut p = good.clone();
    p.edges[7].offset = [0, 3];
    bad_in_memory(&p, "E", "7 4 0 3", "edge 7 has offset dy = 3");
    let mut p = good.clone();
    p.edges[6].end = 4;
    bad_in_memory(
        &p,
        "E",
        "6 4 0 0",
        "edges 7 (line 19) and 6 both end at vertex 4, so vertex 7 has none",
    );
    let mut p = good.clone();
    p.edges[2].rest_length = -1.0;
    bad_in_memory(&p, "RL", "-1", "rest length -1 of edge 2 must be positive");
    let mut p = good.clone();
    p.edges[4].ref_director *= 2.0;
    bad_in_memory(&p, "RefD1", "-2 0 0", "norm 2");
    let mut p = good.clone();
    p.radius = 0.0;
    bad_in_memory(&p, "pattern", "0.01 0.01 0 8", "r = 0 must be positive");
    let mut p = good.clone();
    p.ref_twist[3] = f64::INFINITY;
    bad_in_memory(
        &p,
        "RefT",
        "inf",
        "reference twist = inf of vertex 3 is not finite",
    );
    // inconsistent sizes and edge orders are errors, not panics
    let mut p = good.clone();
    p.theta.pop();
    let e = p.validate().unwrap_err();
    assert_eq!(
        e.to_string(),
        "pattern: block *Q, line 4: theta has 7 entries but the pattern has 8 vertices"
    );
    let mut p = good.clone();
    p.edge_file_order = vec![0; 8];
    assert!(p
        .validate()
        .unwrap_err()
        .message
        .contains("edge_file_order is not a permutation of 0..8"));
    let (q, _) = Pattern::from_pyp_str(&p.to_pyp_string(), "t").unwrap(); // written in vertex order
    assert_eq!(q.edge_file_order, (0..8).collect::<Vec<_>>());
    let mut p = good.clone();
    p.edges.truncate(3);
    p.validate().unwrap_err();
    let _ = p.to_pyp_string();
    let _ = p.implied_periods();
    let empty = Pattern {
        periods: [1.0, 1.0],
        radius: 1.0,
        positions: vec![],
        theta: vec![],
        edges: vec![],
        rest_curvature: vec![],
        rest_twist: vec![],
        ref_twist: vec![],
        edge_file_order: vec![],
    };
    assert!(empty.validate().unwrap_err().message.contains("n = 0"));
    assert!(Pattern::from_pyp_str(&empty.to_pyp_string(), "empty").is_err());
}

// ---------------------------------------------------------------------------------------------------------------
// no panics

/// Every prefix of whole lines that loses a data line is an error; the rest parse to the same pattern.
fn truncation_sweep(text: &str, name: &str) {
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let last_data = lines
        .iter()
        .rposition(|l| !l.split('#').next().unwrap().trim().is_empty())
        .unwrap();
    let full = bits(&Pattern::from_pyp_str(text, name).unwrap().0);
    let mut prefix = String::new();
    for k in 0..=lines.len() {
        match Pattern::from_pyp_str(&prefix, name) {
            Ok((p, _)) => {
                assert!(k > last_data, "{name}: the first {k} lines were accepted");
                assert_eq!(bits(&p), full);
            }
            Err(e) => {
                assert!(
                    k <= last_data,
                    "{name}: the first {k} lines were rejected: {e}"
                );
                assert_eq!(e.to_string().lines().count(), 1, "{e}");
            }
        }
        if k < lines.len() {
            prefix.push_str(lines[k]);
        }
    }
}

#[test]
fn truncation_at_every_line_is_an_error_not_a_panic() {
    truncation_sweep(TILE, "tile.pyp");
    truncation_sweep(&TILE.replace('\n', "\r\n"), "tile-crlf.pyp");
    // at every byte: never a panic
    for k in 0..=TILE.len() {
        let _ = Pattern::from_pyp_str(&TILE[..k], "tile.pyp");
    }
    for (name, ..) in ORIGINALS {
        let Some(path) = original_path(name) else {
            return;
        };
        truncation_sweep(&std::fs::read_to_string(path).unwrap(), name);
    }
}

#[test]
fn random_mutations_never_panic() {
    let mut rng = ChaCha8Rng::seed_from_u64(2024);
    let junk = [
        "",
        "nan",
        "-1",
        "2",
        "8",
        "1e400",
        "x",
        "0",
        "-0",
        "99999999999999999999",
        "*E",
        "*Q",
        "#",
        "1.5",
        "*",
        "-9223372036854775808",
        "18446744073709551616",
        "0 0 0",
        "\u{2212}1",
        "é",
    ];
    let mut rejected = 0;
    for _ in 0..3000 {
        let mut lines: Vec<String> = TILE.lines().map(String::from).collect();
        for _ in 0..rng.random_range(1..4) {
            let i = rng.random_range(0..lines.len());
            match rng.random_range(0..5) {
                0 => {
                    lines.remove(i);
                }
                1 => {
                    let l = lines[i].clone();
                    lines.insert(rng.random_range(0..lines.len()), l);
                }
                2 => {
                    let j = rng.random_range(0..lines.len());
                    lines.swap(i, j);
                }
                _ => {
                    let mut toks: Vec<String> = lines[i].split(' ').map(String::from).collect();
                    let t = rng.random_range(0..toks.len());
                    toks[t] = junk[rng.random_range(0..junk.len())].to_string();
                    lines[i] = toks.join(" ");
                }
            }
        }
        let text = lines.join("\n");
        match Pattern::from_pyp_str(&text, "m.pyp") {
            Ok((p, _)) => {
                let (q, _) = Pattern::from_pyp_str(&p.to_pyp_string(), "m2.pyp").unwrap();
                assert_eq!(bits(&p), bits(&q));
            }
            Err(e) => {
                rejected += 1;
                let msg = e.to_string();
                assert_eq!(msg.lines().count(), 1, "{msg}");
                assert!(msg.starts_with("m.pyp: "), "{msg}");
            }
        }
    }
    assert!(
        rejected > 1000,
        "only {rejected} of 3000 mutations rejected"
    );
}

// ---------------------------------------------------------------------------------------------------------------
// the five originals

#[test]
fn originals_load_with_their_yarns() {
    for (name, n, yarns) in ORIGINALS {
        let Some(path) = original_path(name) else {
            return;
        };
        let (p, warnings) = Pattern::load_pyp(&path).unwrap();
        let lens: Vec<usize> = p.yarns().iter().map(|y| y.len()).collect();
        eprintln!(
            "{name}: {} vertices, {} yarns {lens:?}",
            p.len(),
            lens.len()
        );
        assert_eq!(p.len(), n, "{name}");
        assert_eq!(lens.len(), yarns, "{name}");
        assert_eq!(lens.iter().sum::<usize>(), n);
        assert_eq!(
            warnings.is_empty(),
            name != "basket",
            "{name}: {warnings:?}"
        );
    }
}

#[test]
fn originals_round_trip_byte_for_byte_and_bit_for_bit() {
    for (name, ..) in ORIGINALS {
        let Some(path) = original_path(name) else {
            return;
        };
        let original = std::fs::read_to_string(&path).unwrap();
        let (p, _) = Pattern::from_pyp_str(&original, name).unwrap();
        let written = p.to_pyp_string();
        assert_eq!(
            written,
            original.replace("\r\n", "\n"),
            "{name}: the written file differs"
        );
        let (q, _) = Pattern::from_pyp_str(&written, name).unwrap();
        assert_eq!(bits(&p), bits(&q), "{name}");
        // and against the file's numbers read independently, block by block in file order
        let mut tokens = Vec::new();
        for line in original.lines() {
            let line = line.split('#').next().unwrap().trim();
            if !line.starts_with('*') {
                tokens.extend(line.split_whitespace().map(|t| t.parse::<f64>().unwrap()));
            }
        }
        let n = p.len();
        let mut ours = vec![p.periods[0], p.periods[1], p.radius, n as f64];
        for i in 0..n {
            ours.extend(p.positions[i].iter());
            ours.push(p.theta[i]);
        }
        for &v in &p.edge_file_order {
            let e = &p.edges[v];
            ours.extend([
                v as f64,
                e.end as f64,
                e.offset[0] as f64,
                e.offset[1] as f64,
            ]);
        }
        ours.extend(p.edges.iter().map(|e| e.rest_length));
        ours.extend(p.rest_curvature.iter().flatten());
        ours.extend(&p.rest_twist);
        ours.extend(p.edges.iter().flat_map(|e| e.ref_director.iter().copied()));
        ours.extend(&p.ref_twist);
        assert_eq!(tokens.len(), ours.len(), "{name}");
        for (k, (a, b)) in tokens.iter().zip(&ours).enumerate() {
            assert_eq!(a.to_bits(), b.to_bits(), "{name}: number {k}");
        }
    }
}

/// The measurements behind the tolerances of `pyp.rs` (printed; run with `--nocapture` to see them).
#[test]
fn originals_directors_and_edge_lengths_are_within_the_tolerances() {
    for (name, ..) in ORIGINALS {
        let Some(path) = original_path(name) else {
            return;
        };
        let (p, warnings) = Pattern::load_pyp(&path).unwrap();
        let mut norm_dev: f64 = 0.0;
        let mut cos = [0.0f64; 2]; // interior, periodic
        let implied = p.implied_periods().unwrap();
        let shifted = Pattern {
            periods: implied,
            ..p.clone()
        };
        let mut cos_implied: f64 = 0.0;
        let mut strain = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
        let strains = p.edge_strains();
        for i in 0..p.len() {
            let e = &p.edges[i];
            let u = e.ref_director;
            norm_dev = norm_dev.max((u.norm() - 1.0).abs());
            let periodic = (e.offset != [0, 0]) as usize;
            cos[periodic] =
                cos[periodic].max((u.dot(&p.edge_vector(i)) / p.edge_vector(i).norm()).abs());
            if periodic == 1 {
                cos_implied = cos_implied
                    .max((u.dot(&shifted.edge_vector(i)) / shifted.edge_vector(i).norm()).abs());
            }
            strain[periodic][0] = strain[periodic][0].min(strains[i]);
            strain[periodic][1] = strain[periodic][1].max(strains[i]);
        }
        eprintln!(
            "{name}: |‖u‖−1| ≤ {norm_dev:.2e}; |u·t| ≤ {:.2e} interior, {:.2e} periodic ({:.2e} at the implied \
             periods); strain interior {:+.4}…{:+.4} %, periodic {:+.4}…{:+.4} %; implied periods {:?} ({:+.3} %, \
             {:+.3} %)",
            cos[0],
            cos[1],
            cos_implied,
            100.0 * strain[0][0],
            100.0 * strain[0][1],
            100.0 * strain[1][0],
            100.0 * strain[1][1],
            implied,
            100.0 * (implied[0] / p.periods[0] - 1.0),
            100.0 * (implied[1] / p.periods[1] - 1.0),
        );
        assert!(norm_dev < DIRECTOR_NORM_TOL / 10.0, "{name}");
        assert!(cos[0] < DIRECTOR_PERP_TOL / 10.0, "{name}");
        if name == "basket" {
            assert!(cos[1] > 0.09, "{name}");
            assert!(strain[1][1] < -0.06 && strain[1][0] > -0.1, "{name}");
            assert!(strain[0][0] > -0.001 && strain[0][1] < 0.001, "{name}");
            assert!(cos_implied < DIRECTOR_PERP_TOL / 4.0, "{name}");
            assert_eq!(warnings.len(), 1);
        } else {
            assert!(cos[1] < DIRECTOR_PERP_TOL / 10.0, "{name}");
            // the periodic edges sit inside the interior edges' range (up to 1e-4)
            assert!(
                strain[1][0] > strain[0][0] - 1e-4 && strain[1][1] < strain[0][1] + 1e-4,
                "{name}"
            );
            // the implied periods agree with the stored ones within 0.1 % (measured: ≤ 0.045 %, stockinette)
            for k in 0..2 {
                assert!(
                    (implied[k] / p.periods[k] - 1.0).abs() < 1e-3,
                    "{name}: {implied:?}"
                );
            }
        }
    }
}

#[test]
fn basket_warns_that_its_periods_are_compressed() {
    let Some(path) = original_path("basket") else {
        return;
    };
    let (p, warnings) = Pattern::load_pyp(&path).unwrap();
    let [PatternWarning::PeriodMismatch(m)] = warnings.as_slice() else {
        panic!("expected one period warning, got {warnings:?}")
    };
    let implied = p.implied_periods().unwrap();
    assert_eq!(m.implied, Some(implied));
    assert_eq!(m.stored, [0.0107037, 0.0103]);
    assert!(
        (implied[0] - 0.0108665).abs() < 1e-7 && (implied[1] - 0.0104499).abs() < 1e-7,
        "{implied:?}"
    );
    assert!(
        (implied[0] / m.stored[0] - 1.0152).abs() < 2e-4,
        "{implied:?}"
    );
    assert!(
        (implied[1] / m.stored[1] - 1.0146).abs() < 2e-4,
        "{implied:?}"
    );
    assert!(
        m.periodic_strain[0] > -0.095 && m.periodic_strain[1] < -0.065,
        "{m:?}"
    );
    // at the implied periods every periodic edge has its rest length within 1e-5
    let fixed = Pattern {
        periods: implied,
        ..p.clone()
    };
    for (i, s) in fixed.edge_strains().iter().enumerate() {
        if p.edges[i].offset != [0, 0] {
            assert!(s.abs() < 2e-5, "edge {i}: {s}");
        }
    }
    assert_eq!(fixed.validate(), Ok(vec![]));
    let msg = warnings[0].to_string();
    eprintln!("{msg}");
    assert_eq!(msg.lines().count(), 1);
    assert!(
        msg.starts_with(&format!(
            "{}: periodic edges are 6.6–9.4 % shorter",
            path.display()
        )),
        "{msg}"
    );
    assert!(
        msg.contains("the stored periods 0.0107037 × 0.0103 m look compressed"),
        "{msg}"
    );
    assert!(
        msg.contains("the rest lengths imply 0.0108665 × 0.0104499 m (+1.52 %, +1.46 %)"),
        "{msg}"
    );
}

// ---------------------------------------------------------------------------------------------------------------
// the command line

#[test]
fn cli_pattern_summarises_writes_and_reports_errors() {
    let dir = std::env::temp_dir().join(format!("hylc-pyp-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("tile.pyp");
    std::fs::write(&input, TILE).unwrap();
    let output = dir.join("out.pyp");
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args([
            "pattern",
            input.to_str().unwrap(),
            "--write",
            output.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for want in [
        "vertices: 8",
        "periods: 0.01 x 0.01 m, yarn radius 0.0005 m",
        "yarns: 2",
        "yarn 0: 4 vertices",
        "yarn 1: 4 vertices",
        "repeats with offset (0, 1)",
        "total yarn length: 2.000000e-2 m at rest",
        "warnings: 0",
    ] {
        assert!(stdout.contains(want), "{want:?} missing from:\n{stdout}");
    }
    assert_eq!(
        std::fs::read_to_string(&output).unwrap(),
        tile().to_pyp_string()
    );
    // bad input: exit code 2, one line naming file, block and line
    let bad_file = dir.join("bad.pyp");
    std::fs::write(&bad_file, with_line(TILE, 16, "3 0 2 0")).unwrap();
    let err = common::cli_error(&["pattern", bad_file.to_str().unwrap()]);
    assert!(
        err.starts_with("error: ")
            && err.contains("bad.pyp: block *E, line 16: edge 3 has offset dx = 2"),
        "{err}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["pattern", dir.join("missing.pyp").to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8(out.stderr)
        .unwrap()
        .contains("missing.pyp: cannot read"));
    std::fs::remove_dir_all(&dir).unwrap();
    // basket: the warning is part of the summary
    let Some(basket) = original_path("basket") else {
        return;
    };
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["pattern", basket.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(
        stdout.contains("yarns: 8") && stdout.contains("warnings: 1"),
        "{stdout}"
    );
    assert!(
        stdout.contains("warning: ") && stdout.contains("imply 0.0108665 × 0.0104499 m"),
        "{stdout}"
    );
}
