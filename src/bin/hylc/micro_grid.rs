//! `hylc micro-grid`: our micro solver against the original solver's displacements on the 9×9×9 in-plane grid
//! (`docs/derivative-harness.md`, item 3c; `hylc::validation::grid`).

use crate::args::{exit, SolverArgs, YarnArgs};
use crate::strain::load_pattern_noted;
use anyhow::anyhow;
use hylc::micro::{MicroProblem, SolverOptions};
use hylc::rod::YarnMaterial;
use hylc::validation::grid::{run_grid, summarize, GridData, GridOptions, GridSummary, GRID_LEN};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Our micro solver against the original solver's displacements on the 9×9×9 in-plane strain grid (validation
/// item 3c): warm-started continuation over the grid, position and θ errors relative to each side's z = 0 state,
/// convergence with every failure, Newton steps warm vs cold.
#[derive(clap::Args)]
pub struct Args {
    /// `.pyp` file of the original pattern
    pattern: String,
    /// folder with `axes.txt` and `data.npy` (e.g. ../shared/data/hylc2020/displacements/satin)
    data_dir: PathBuf,
    /// write the summary as JSON
    #[arg(long)]
    json: Option<PathBuf>,
    /// solve only the first N points of the continuation order (a quick partial run)
    #[arg(long)]
    limit: Option<usize>,
    /// also solve every N-th grid point cold for the warm-vs-cold statistics (0: none)
    #[arg(long, default_value_t = 16)]
    cold_every: usize,
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    yarn: YarnArgs,
    /// no per-yarn slide constraints (an option of the original solver, kept to reproduce it)
    #[arg(long)]
    no_slide_constraints: bool,
    /// keep the `.pyp` file's periods even where they disagree with the rest lengths (by default the
    /// implied periods are used, as in `hylc solve`)
    #[arg(long)]
    file_periods: bool,
}

/// `hylc micro-grid`: exit code 3 when a continuation point did not converge.
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let options = SolverOptions {
        slide_constraints: !a.no_slide_constraints,
        ..a.solver.options()
    };
    let ok = grid(&GridJob {
        pattern: &a.pattern,
        data_dir: &a.data_dir,
        json: a.json.as_deref(),
        limit: a.limit,
        cold_every: a.cold_every,
        file_periods: a.file_periods,
        options,
        yarn: a.yarn.material()?,
    })?;
    Ok(exit(ok, 3))
}

/// One grid run of [`grid`]: the flags of `hylc micro-grid`.
pub struct GridJob<'a> {
    /// The original pattern's `.pyp` file.
    pub pattern: &'a str,
    /// The displacement folder.
    pub data_dir: &'a Path,
    /// Where to write the summary as JSON.
    pub json: Option<&'a Path>,
    /// Solve only the first N points of the continuation order.
    pub limit: Option<usize>,
    /// Also solve every N-th point cold (0: none).
    pub cold_every: usize,
    /// Keep the file's periods.
    pub file_periods: bool,
    pub options: SolverOptions,
    pub yarn: YarnMaterial,
}

/// Run the grid of one pattern, print the summary, optionally write it as JSON. `Ok(true)` when every
/// continuation point converged.
pub fn grid(job: &GridJob) -> anyhow::Result<bool> {
    let GridJob {
        pattern,
        data_dir,
        json,
        limit,
        cold_every,
        file_periods,
        ref options,
        ref yarn,
    } = *job;
    let p = if file_periods {
        // the periods as written, even where they disagree with the rest lengths (a diagnostic for basket)
        hylc::pattern::Pattern::load_pyp(pattern)?.0
    } else {
        load_pattern_noted(pattern)?
    };
    let data = GridData::load(data_dir)?;
    data.check_pattern(&p)
        .map_err(|e| anyhow!("{pattern} with {}: {e}", data_dir.display()))?;
    let problem = MicroProblem::new(p, yarn, options.clone());
    let planned = limit.unwrap_or(GRID_LEN).min(GRID_LEN)
        + if cold_every == 0 {
            0
        } else {
            GRID_LEN.div_ceil(cold_every)
        };
    let bar = ProgressBar::new(planned as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} solves, eta {eta}")?
            .progress_chars("=> "),
    );
    let opts = GridOptions { limit, cold_every };
    let result = run_grid(&problem, &data, &opts, &|| bar.inc(1));
    bar.finish_and_clear();
    let run = result.map_err(|e| anyhow!("{pattern}: {e}"))?;
    let summary = summarize(&problem, &data, &run);
    print_summary(pattern, &summary);
    if let Some(path) = json {
        write_json(
            path,
            pattern,
            data_dir,
            &problem,
            limit,
            file_periods,
            &summary,
        )?;
        println!("wrote {}", path.display());
    }
    Ok(summary.converged == summary.points)
}

/// Add (or replace) this run's entry in the JSON file `path`: an object {"about": …, "runs": {key: …}} keyed by
/// the pattern's file stem, with " (no slide constraints)" appended when they are off, " (yarn HASH)" for yarn
/// parameters other than the defaults and " (first N points)" for a partial run, so that several
/// `micro-grid` runs collect into one file. An existing file that is not such an object is left alone (error).
fn write_json(
    path: &Path,
    pattern: &str,
    data_dir: &Path,
    problem: &MicroProblem,
    limit: Option<usize>,
    file_periods: bool,
    summary: &GridSummary,
) -> anyhow::Result<()> {
    let options = &problem.options;
    let mut root = if path.exists() {
        let text = std::fs::read_to_string(path).map_err(|e| anyhow!("{}: {e}", path.display()))?;
        let v: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| anyhow!("{}: not JSON ({e}); not overwriting it", path.display()))?;
        if !v.get("runs").is_some_and(|r| r.is_object()) {
            return Err(anyhow!(
                "{}: not a micro-grid results file (no \"runs\" object); not overwriting it",
                path.display()
            ));
        }
        v
    } else {
        serde_json::json!({ "runs": {} })
    };
    root["about"] = serde_json::json!(
        "hylc micro-grid: our micro solver against the original solver's displacements on the 9x9x9 in-plane \
         grid (docs/derivative-harness.md, item 3c). Position errors in units of the yarn radius r, θ errors in rad, both \
         relative to each side's z = 0 state; times in s."
    );
    let stem = Path::new(pattern)
        .file_stem()
        .map_or(pattern.to_string(), |s| s.to_string_lossy().into_owned());
    let mut key = stem;
    if !options.slide_constraints {
        key.push_str(" (no slide constraints)");
    }
    if file_periods {
        key.push_str(" (file periods)");
    }
    let default_yarn = YarnMaterial {
        radius: problem.material.radius,
        ..YarnMaterial::default()
    };
    if problem.material != default_yarn {
        // another yarn is another run: keyed by the hash of its parameters
        let hash = hylc::sample::plan::fnv1a64(problem.material.hash_text().as_bytes());
        key.push_str(&format!(" (yarn {hash:016x})"));
    }
    if let Some(n) = limit.filter(|&n| n < GRID_LEN) {
        key.push_str(&format!(" (first {n} points)"));
    }
    root["runs"][key.as_str()] = serde_json::json!({
        "pattern": Path::new(pattern).file_name().map(|s| s.to_string_lossy().into_owned()),
        "data": data_dir.file_name().map(|s| s.to_string_lossy().into_owned()),
        "options": options,
        "yarn": problem.material,
        "summary": summary,
    });
    let text = serde_json::to_string_pretty(&root)?;
    std::fs::write(path, text + "\n").map_err(|e| anyhow!("{}: {e}", path.display()))
}

fn print_summary(pattern: &str, s: &GridSummary) {
    let e = &s.position_error;
    println!(
        "{pattern}: {} vertices, r = {} m, slide constraints {}",
        s.vertices,
        s.radius,
        if s.slide_constraints { "on" } else { "off" }
    );
    println!(
        "  converged {}/{} ({} after a cold retry), {:.1} s",
        s.converged, s.points, s.recovered_cold, s.time
    );
    println!(
        "  position error (r): RMS {:.4}, max {:.4} at {:?} vertex {}; components RMS (ξ1, ξ2, h) {:.4}, {:.4}, {:.4}",
        e.rms,
        e.max,
        e.max_strain,
        e.max_vertex,
        s.position_error_rms_components[0],
        s.position_error_rms_components[1],
        s.position_error_rms_components[2]
    );
    println!(
        "  translation removed: RMS {:.4}, max {:.4}; per-yarn translations removed: RMS {:.4}, max {:.4}",
        s.position_error_translation_removed.rms,
        s.position_error_translation_removed.max,
        s.position_error_yarn_translation_removed.rms,
        s.position_error_yarn_translation_removed.max
    );
    println!(
        "  slid like the original's pins {:?}: RMS {:.4}, max {:.4}",
        s.original_pins,
        s.position_error_pinned_like_original.rms,
        s.position_error_pinned_like_original.max
    );
    println!(
        "  original displacement (r): RMS {:.4}, max {:.4}",
        s.original_displacement.rms, s.original_displacement.max
    );
    println!(
        "  θ error (rad): RMS {:.4}, max {:.4} at {:?} edge {} (original dθ RMS {:.4}, max {:.4})",
        s.theta_error.rms,
        s.theta_error.max,
        s.theta_error.max_strain,
        s.theta_error.max_vertex,
        s.original_theta.rms,
        s.original_theta.max
    );
    println!(
        "  displacement fields: cos ∠(ours, original) {:.3}, ‖ours‖/‖original‖ {:.3}",
        s.cosine, s.magnitude_ratio
    );
    for c in &s.first_neighbours {
        println!(
            "    one step from z = 0 at {:?}: RMS error {:.4} r of {:.4} r, cos {:.3}, ratio {:.3}",
            c.strain, c.rms_error, c.rms_original, c.cosine, c.magnitude_ratio
        );
    }
    for (label, st) in [("warm", &s.warm), ("cold", &s.cold)] {
        println!(
            "  {label}: {} solves ({} converged), steps median {} max {} mean {:.1}, time mean {:.3} s median {:.3} s",
            st.solves,
            st.converged,
            st.median_steps,
            st.max_steps,
            st.mean_steps,
            st.mean_time,
            st.median_time
        );
    }
    let axis: Vec<String> = ["s_x", "s_a", "s_y"]
        .iter()
        .zip(&s.position_error_rms_by_axis)
        .map(|(n, row)| {
            let v: Vec<String> = row.iter().map(|x| format!("{x:.3}")).collect();
            format!("{n} [{}]", v.join(" "))
        })
        .collect();
    println!("  RMS position error by axis value: {}", axis.join("; "));
    let worst: Vec<String> = s
        .worst_points
        .iter()
        .map(|(z, e)| format!("{z:?}: {e:.3}"))
        .collect();
    println!("  worst grid points (RMS r): {}", worst.join("; "));
    let worst: Vec<String> = s
        .worst_vertices
        .iter()
        .map(|(v, e)| format!("{v}: {e:.3}"))
        .collect();
    println!("  worst vertices (RMS r): {}", worst.join("; "));
    if s.failures.is_empty() {
        println!("  failures: none");
    } else {
        println!("  failures ({}):", s.failures.len());
        for f in &s.failures {
            println!(
                "    {:?} {} : {} after {} steps, ‖g‖∞ {:.2e}{}",
                f.strain,
                f.start,
                f.status,
                f.steps,
                f.gradient_norm,
                if f.recovered { " (recovered cold)" } else { "" }
            );
        }
    }
}
