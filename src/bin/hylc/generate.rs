//! `hylc generate KIND`: a yarn pattern made procedurally (`hylc::generate`; `docs/yarn-model.md`).

use anyhow::anyhow;
use hylc::generate::{generate_kind, min_centerline_distance, to_obj, SameYarn};
use hylc::pattern::Pattern;
use std::path::PathBuf;
use std::process::ExitCode;

/// Generate a yarn pattern procedurally and print a summary (vertices, yarns, periods, minimum distances).
#[derive(clap::Args)]
pub struct Args {
    /// plain, twill, satin, basket or stockinette
    kind: String,
    /// repeat: twill repeat (default 4), satin repeat (default 5), basket group size (default 2)
    #[arg(long)]
    n: Option<usize>,
    /// satin move (default 2)
    #[arg(long)]
    step: Option<usize>,
    /// vertices per yarn radius of arclength
    #[arg(long, default_value_t = 1.0)]
    vertices_per_radius: f64,
    /// write the centre lines as an OBJ polyline file (for Blender or ParaView)
    #[arg(long)]
    obj: Option<PathBuf>,
    /// write the pattern as a `.pyp` file
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (kind, n, step, vertices_per_radius) =
        (a.kind.as_str(), a.n, a.step, a.vertices_per_radius);
    let pattern: Pattern = generate_kind(kind, n, step, vertices_per_radius)
        .map_err(|e| anyhow!("generate {kind}: {e}"))?;
    let r = pattern.radius;
    let yarns = pattern.yarns();
    let lengths: Vec<f64> = pattern.edges.iter().map(|e| e.rest_length).collect();
    let (lmin, lmax) = lengths
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &l| (a.min(l), b.max(l)));
    let other = min_centerline_distance(&pattern, SameYarn::Skip);
    let any = min_centerline_distance(&pattern, SameYarn::ExcludeNeighbours(3));
    println!("pattern:     {kind}");
    println!(
        "vertices:    {} in {} yarns ({} vertices per yarn)",
        pattern.len(),
        yarns.len(),
        yarns
            .iter()
            .map(|y| y.len().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "periods:     {:.6} x {:.6} m ({:.3} r x {:.3} r), yarn radius r = {r} m",
        pattern.periods[0],
        pattern.periods[1],
        pattern.periods[0] / r,
        pattern.periods[1] / r
    );
    println!("edges:       {:.3} r to {:.3} r", lmin / r, lmax / r);
    println!(
        "min distance between different yarns:              {:.4} r",
        other.distance / r
    );
    println!(
        "min distance between segments > 3 apart (any yarn): {:.4} r",
        any.distance / r
    );
    if let Some(path) = &a.obj {
        std::fs::write(path, to_obj(&pattern))
            .map_err(|e| anyhow!("{}: cannot write: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = &a.out {
        pattern.save_pyp(path)?;
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
