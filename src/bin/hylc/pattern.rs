//! `hylc pattern FILE`: load and check a `.pyp` yarn pattern (`hylc::pattern`; `docs/yarn-model.md`).

use hylc::pattern::Pattern;
use std::path::PathBuf;
use std::process::ExitCode;

/// Load and check a `.pyp` yarn pattern file and print a summary (vertices, yarns, periods, radius, lengths,
/// warnings); optionally write it back out.
#[derive(clap::Args)]
pub struct Args {
    /// pattern file (`.pyp`, the original HYLC format)
    file: PathBuf,
    /// write the pattern to this file (exact round trip)
    #[arg(long)]
    write: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let file = a.file.as_path();
    let (p, warnings) = Pattern::load_pyp(file)?;
    let n = p.len();
    let periodic = |k: usize| p.edges.iter().filter(|e| e.offset[k] != 0).count();
    println!("pattern: {}", file.display());
    println!(
        "vertices: {n} (= edges; {} cross the tile's x side, {} its y side)",
        periodic(0),
        periodic(1)
    );
    println!(
        "periods: {} x {} m, yarn radius {} m",
        p.periods[0], p.periods[1], p.radius
    );
    let yarns = p.yarns();
    println!("yarns: {}", yarns.len());
    let (mut rest_total, mut cur_total) = (0.0, 0.0);
    for (k, y) in yarns.iter().enumerate() {
        let rest: f64 = y.iter().map(|&v| p.edges[v].rest_length).sum();
        let cur: f64 = y.iter().map(|&v| p.edge_vector(v).norm()).sum();
        let mut d = [0, 0];
        for &v in y {
            d[0] += p.edges[v].offset[0];
            d[1] += p.edges[v].offset[1];
        }
        rest_total += rest;
        cur_total += cur;
        println!(
            "  yarn {k}: {} vertices (from {}), rest length {rest:.6e} m, repeats with offset ({}, {})",
            y.len(),
            y[0],
            d[0],
            d[1]
        );
    }
    println!("total yarn length: {rest_total:.6e} m at rest, {cur_total:.6e} m current");
    println!("warnings: {}", warnings.len());
    for w in &warnings {
        println!("warning: {w}");
    }
    if let Some(out) = &a.write {
        p.save_pyp(out)?;
        let (back, _) = Pattern::load_pyp(out)?;
        if back != p {
            anyhow::bail!("{}: the written file reads back differently", out.display());
        }
        println!("wrote {}", out.display());
    }
    Ok(ExitCode::SUCCESS)
}
