//! The `hylc` command line (`../shared/design/01-architecture.md`, "Command line").

#[path = "hylc/calibrate.rs"]
mod calibrate;
#[path = "hylc/fit.rs"]
mod fit;
#[path = "hylc/micro.rs"]
mod micro;
#[path = "hylc/micro_grid.rs"]
mod micro_grid;
#[path = "hylc/pipeline.rs"]
mod pipeline;
#[path = "hylc/sample.rs"]
mod sample;
#[path = "hylc/simulate.rs"]
mod simulate;
#[path = "hylc/validate.rs"]
mod validate;

use clap::{Parser, Subcommand};
use hylc::checks::run_all;
use hylc::diff::{format_table, CheckConfig};
use hylc::generate::{
    min_centerline_distance, stockinette, to_obj, weave, KnitParams, SameYarn, WeaveParams,
    DEFAULT_KINDS,
};
use hylc::material::synthetic::default_material;
use hylc::material::{Material, PsiVgh, STRAIN_NAMES};
use hylc::pattern::Pattern;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser)]
#[command(name = "hylc", version, about = "Homogenized yarn-level cloth")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The main job end to end: generate a stockinette (or the given patterns), compute its reference state,
    /// run the quick sampling plan and a 27-point held-out grid, fit the material, drape a cloth with it; prints a
    /// summary and writes everything to the output folder. A rerun resumes (finished samples are kept).
    Run {
        /// output folder
        #[arg(long, default_value = "out/run")]
        out: PathBuf,
        /// patterns: generated kinds (stockinette, plain, twill, satin, basket) or .pyp files, comma-separated
        #[arg(long, default_value = "stockinette", value_delimiter = ',')]
        pattern: Vec<String>,
        /// construction of .pyp files (knitted or woven); generated kinds know theirs
        #[arg(long)]
        construction: Option<String>,
        /// sampling plan: quick (474 samples), reduced (1 050), default (23 250) or a plan file
        #[arg(long, default_value = "quick")]
        plan: String,
        /// the cloth scene (a built-in or a scene file)
        #[arg(long, default_value = "drape-x")]
        scene: String,
        /// edge length (m) of the scene's rectangle mesh (default: 1 cm, 1 800 triangles)
        #[arg(long, default_value_t = 0.01)]
        edge: f64,
        /// simulated time (s) instead of the scene's
        #[arg(long)]
        duration: Option<f64>,
        /// time step of the cloth simulation (s); 1/240 by default: a knit's rest curl makes the cloth crumple at
        /// the mesh scale, and at the scenes' 1/60 Newton no longer converges
        #[arg(long, default_value_t = 1.0 / 240.0)]
        dt: f64,
        /// delete the output folder first instead of resuming
        #[arg(long)]
        fresh: bool,
    },
    /// The validation items of 06-verification.md (section 3) against ../shared: conformance with the original
    /// code, the original patterns as equilibria, the micro solver against the original displacements, the fitted
    /// materials against the original ones; writes the results table (skips when ../shared is absent).
    Validate {
        /// the results table (Markdown)
        #[arg(long, default_value = "validation/results.md")]
        write: PathBuf,
        /// also put the table into this README between `<!-- validate:begin -->` and `<!-- validate:end -->`
        #[arg(long)]
        readme: Option<PathBuf>,
        /// micro-grid points per pattern (the first N of the continuation order)
        #[arg(long, default_value_t = 61)]
        grid_limit: usize,
        /// all 729 micro-grid points per pattern (about 40 min on 2 cores)
        #[arg(long)]
        full: bool,
    },
    /// The material demo on the embedded default material: writes it as JSON, evaluates ψ, ∇ψ, ∇²ψ along
    /// stretch, shear and bending sweeps, times the fast path and checks its derivatives.
    MaterialDemo {
        /// output folder
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Run the derivative harness on every registered function; exits non-zero on any failure.
    CheckDerivatives {
        /// random inputs per function
        #[arg(long, default_value_t = 1000)]
        cases: usize,
        /// seed of the input generator
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// only functions whose name contains this
        #[arg(long, default_value = "")]
        filter: String,
    },
    /// Evaluate ψ, ∇ψ, ∇²ψ of a material file at given strains z = (s_x, s_a, s_y, II00, II01, II11).
    Material {
        /// material JSON (original HYLC format), or `default` for the embedded default material
        file: String,
        /// a strain as six comma-separated numbers (repeatable)
        #[arg(
            long = "z",
            value_name = "SX,SA,SY,II00,II01,II11",
            allow_hyphen_values = true
        )]
        z: Vec<String>,
        /// a file with one strain per line (six numbers separated by commas or spaces; `#` starts a comment)
        #[arg(long)]
        z_file: Option<PathBuf>,
        /// print one JSON object per strain instead of text
        #[arg(long)]
        json: bool,
        /// write the material back out (e.g. `default` to a file)
        #[arg(long)]
        write: Option<PathBuf>,
    },
    /// Load and check a `.pyp` yarn pattern file and print a summary (vertices, yarns, periods, radius, lengths,
    /// warnings); optionally write it back out.
    Pattern {
        /// pattern file (`.pyp`, the original HYLC format)
        file: PathBuf,
        /// write the pattern to this file (exact round trip)
        #[arg(long)]
        write: Option<PathBuf>,
    },
    /// Generate a yarn pattern procedurally and print a summary (vertices, yarns, periods, minimum distances).
    Generate {
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
    },
    /// Solve the micro problem of a pattern at one or more macro strains (warm-started from the previous one
    /// unless --cold): status, Newton steps, Ψ̄, homogenized stress, time and where it went.
    Solve {
        /// `.pyp` file, or a generated kind (plain, twill, satin, basket, stockinette)
        pattern: String,
        /// strain s_x,s_a,s_y[,II00,II11] (repeatable; default zero)
        #[arg(long = "z", allow_hyphen_values = true)]
        z: Vec<String>,
        /// start every strain from the reference state
        #[arg(long)]
        cold: bool,
        /// warm start from the previous solution only (no secant extrapolation along the chain)
        #[arg(long)]
        no_predictor: bool,
        /// force tolerance relative to the stretching stiffness
        #[arg(long, default_value_t = 1e-8)]
        tolerance: f64,
        /// Newton step limit
        #[arg(long, default_value_t = 2000)]
        max_steps: usize,
        /// wall-time limit per solve in seconds
        #[arg(long)]
        time_limit: Option<f64>,
        /// displacement limit factor (times r λ_min(I))
        #[arg(long, default_value_t = 1.0)]
        step_factor: f64,
        /// line-search backtracking factor (trial steps factor^i down to 1e-10)
        #[arg(long, default_value_t = 0.1)]
        backtracking: f64,
        /// no per-yarn slide constraints
        #[arg(long)]
        no_slide_constraints: bool,
        /// write the yarn centre lines as OBJ polylines (one file per strain when several)
        #[arg(long)]
        obj: Option<PathBuf>,
        /// one JSON object per strain
        #[arg(long)]
        json: bool,
        /// print one line per Newton step to stderr
        #[arg(long)]
        trace: bool,
        /// Gauss points per segment of the contact quadrature (default: the calibrated yarn's)
        #[arg(long)]
        quadrature: Option<usize>,
    },
    /// Run a sampling plan on a pattern (warm-started chains in parallel), appending to a JSON-lines sample
    /// file; finished samples are skipped, so an interrupted run resumes where it stopped.
    Sample {
        /// `.pyp` file, or a generated kind (plain, twill, satin, basket, stockinette)
        pattern: String,
        /// plan JSON file, or `default` / `reduced`
        #[arg(long, default_value = "default")]
        plan: String,
        /// sample file (JSON lines; appended to)
        #[arg(long)]
        out: PathBuf,
        /// start every sample from the reference state
        #[arg(long)]
        cold: bool,
        /// run shard k of n (chains with index ≡ k mod n)
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
        /// stop after writing this many samples
        #[arg(long)]
        limit: Option<usize>,
        /// force tolerance relative to the stretching stiffness
        #[arg(long, default_value_t = 1e-8)]
        tolerance: f64,
        /// Newton step limit
        #[arg(long, default_value_t = 2000)]
        max_steps: usize,
        /// wall-time limit per solve in seconds
        #[arg(long)]
        time_limit: Option<f64>,
    },
    /// Merge sample files (e.g. shards) into one, dropping duplicate ids.
    Merge {
        /// merged sample file
        out: PathBuf,
        /// input sample files
        inputs: Vec<PathBuf>,
    },
    /// Write a sampling plan covering only the strains one or more macro runs visited (their `log.jsonl`), plus
    /// a margin, at the sample spacing of a base plan ("model only what a scene requires").
    ScenePlan {
        /// `log.jsonl` files of `hylc simulate` runs
        #[arg(required = true)]
        logs: Vec<PathBuf>,
        /// plan file to write
        #[arg(long)]
        write: PathBuf,
        /// base plan whose ranges clip and whose spacing is kept: default, reduced, quick or a plan file
        #[arg(long, default_value = "default")]
        base: String,
        /// margin added on each side, as a fraction of each visited interval
        #[arg(long, default_value_t = 0.1)]
        margin: f64,
        /// cover every triangle's strains (the logs' min/max) instead of the 1st to 99th percentiles
        #[arg(long)]
        all_triangles: bool,
    },
    /// Write the default sampling plan (or the reduced one) as JSON.
    Plan {
        /// plan file to write
        #[arg(long)]
        write: PathBuf,
        /// the reduced plan (30 per 1D range, 10×10 grids)
        #[arg(long)]
        reduced: bool,
        /// the held-out plan: only the 9×9×9 in-plane grid of the original displacement data
        #[arg(long)]
        holdout: bool,
    },
    /// Fit a material (Algorithm C5) to a sample file; writes the material JSON, a JSON fit report and PNG plots.
    Fit {
        /// sample file (JSON lines from `hylc sample`)
        samples: PathBuf,
        /// material file to write (default: SAMPLES with extension .material.json)
        #[arg(long)]
        out: Option<PathBuf>,
        /// JSON fit report (default: SAMPLES with extension .fit.json)
        #[arg(long)]
        report: Option<PathBuf>,
        /// folder for the PNG plots (default: SAMPLES with extension .plots)
        #[arg(long)]
        plots: Option<PathBuf>,
        /// skip the plots
        #[arg(long)]
        no_plots: bool,
        /// the plan of the samples (default: the sidecar's, or the built-in plan the ids name)
        #[arg(long)]
        plan: Option<String>,
        /// areal density ρ_A in kg/m² (default: the sidecar's)
        #[arg(long)]
        density: Option<f64>,
        /// held-out sample file(s) whose Ψ̄ the model must predict (e.g. from `--plan holdout`)
        #[arg(long)]
        holdout: Vec<PathBuf>,
        /// compare the fitted 1D curves f₀ + f_k with another material file (e.g. the original's)
        #[arg(long)]
        compare: Option<PathBuf>,
        /// the stockinette settings of the design: pˣ_min = 0.01, 2D knots on 0.3 of the range
        #[arg(long)]
        stockinette_like: bool,
        /// knots of each 1D term (N_c)
        #[arg(long, default_value_t = 11)]
        knots_1d: usize,
        /// knots per axis of each 2D term
        #[arg(long, default_value_t = 9)]
        knots_2d: usize,
        /// minimum slope pˣ_min (default 0.001, or 0.01 with --stockinette-like)
        #[arg(long)]
        min_slope: Option<f64>,
        /// extent of the 2D knots as a fraction of the data range (default 0.9, or 0.3 with --stockinette-like)
        #[arg(long)]
        extent: Option<f64>,
        /// slopes of the 1D terms: fd (finite differences of the MLS) or stress (MLS of the sampled stresses)
        #[arg(long, default_value = "fd")]
        slopes: String,
        /// fit the 1D terms to every K-th sample of their ranges only (the others are held out)
        #[arg(long, default_value_t = 1, value_name = "K")]
        thin_1d: usize,
        /// stop FIT2D's monotone correction after the twists (report non-monotone patches instead of shrinking
        /// the cross slopes)
        #[arg(long)]
        twist_only: bool,
    },
    /// Compute the reference state of a pattern (Algorithm C1: stress-free state, tension, zero-stress periods,
    /// centring) and write it as `.pyp`.
    Reference {
        /// `.pyp` file or generated kind
        pattern: String,
        /// knitted or woven (selects the tension factors; inferred for generated kinds)
        #[arg(long)]
        construction: Option<String>,
        /// skip the stress-free state and the tension (re-equilibrate a pattern that is already a reference
        /// state, e.g. an original `.pyp` with this project's yarn model): zero-stress periods and centring only
        #[arg(long)]
        equilibrate_only: bool,
        /// output `.pyp` file
        #[arg(long)]
        out: PathBuf,
        /// write the report as JSON
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Ψ̄ at one strain with its derivatives with respect to the strain and to the yarn parameters (envelope
    /// theorem).
    Sensitivity {
        /// `.pyp` file or generated kind
        pattern: String,
        /// strain s_x,s_a,s_y[,II00,II11]
        #[arg(long = "z", allow_hyphen_values = true, default_value = "0,0,0")]
        z: String,
    },
    /// Our micro solver against the original solver's displacements on the 9×9×9 in-plane strain grid
    /// (validation item 3c): warm-started continuation over the grid, position and θ errors relative to each
    /// side's z = 0 state, convergence with every failure, Newton steps warm vs cold.
    MicroGrid {
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
        /// force tolerance relative to the stretching stiffness
        #[arg(long, default_value_t = 1e-8)]
        tolerance: f64,
        /// Newton step limit
        #[arg(long, default_value_t = 2000)]
        max_steps: usize,
        /// no per-yarn slide constraints
        #[arg(long)]
        no_slide_constraints: bool,
        /// keep the `.pyp` file's periods even where they disagree with the rest lengths (by default the
        /// implied periods are used, as in `hylc solve`)
        #[arg(long)]
        file_periods: bool,
    },
    /// Calibrate the yarn parameters so that the original reference patterns are static equilibria: per contact
    /// form, the residual force at the defaults, the best parameters per pattern and the joint fit.
    Calibrate {
        /// folder with the original `.pyp` files (default: ../shared/data/hylc2020/patterns)
        #[arg(long)]
        dir: Option<PathBuf>,
        /// contact quadrature orders to try (comma-separated)
        #[arg(long, default_value = "4")]
        quadrature: String,
        /// contact exclusions (neighbour segments on each side) to try
        #[arg(long, default_value = "3")]
        exclusion: String,
        /// contact radius factors to try (contact distance 2 x factor x r)
        #[arg(long, default_value = "1")]
        radius_factor: String,
        /// write all rows as JSON
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Simulate a cloth scene: a scene JSON file or a built-in (stretch-x, stretch-y, drape-x, drape-y, hanging).
    /// Writes frame_NNNN.obj per frame and log.jsonl (one JSON object per step) to the output folder.
    Simulate {
        /// scene JSON file or built-in name
        scene: String,
        /// output folder
        #[arg(long, default_value = "out/simulate")]
        out: PathBuf,
        /// material JSON (or `default`) instead of the scene's
        #[arg(long)]
        material: Option<String>,
        /// simulated time (s) instead of the scene's
        #[arg(long)]
        duration: Option<f64>,
        /// time step (s) instead of the scene's
        #[arg(long)]
        dt: Option<f64>,
        /// edge length (m) of a rectangle mesh instead of the scene's
        #[arg(long)]
        edge: Option<f64>,
        /// Hessian projection: full (18x18 eigen-projection), psi (6x6 only) or none (diagonal shift)
        #[arg(long)]
        psd: Option<String>,
        /// switch bending off (II = 0; the hinges are not evaluated)
        #[arg(long)]
        no_bending: bool,
        /// use only the 1D terms of the material (the original's only1D)
        #[arg(long)]
        only_1d: bool,
        /// use only the in-plane terms of the material (implies no bending)
        #[arg(long)]
        in_plane_only: bool,
        /// no progress bar
        #[arg(long)]
        quiet: bool,
        /// print the scene (after overrides) as JSON and exit
        #[arg(long)]
        print: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            out,
            pattern,
            construction,
            plan,
            scene,
            edge,
            duration,
            dt,
            fresh,
        } => pipeline::run(&pipeline::RunArgs {
            out,
            patterns: pattern,
            plan,
            scene,
            edge: Some(edge),
            duration,
            dt,
            fresh,
            construction,
        })
        .map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(3)
            }
        }),
        Command::MaterialDemo { out } => run_demo(&out),
        Command::Validate {
            write,
            readme,
            grid_limit,
            full,
        } => validate::run(&validate::ValidateArgs {
            write,
            readme,
            grid_limit: (!full).then_some(grid_limit),
        })
        .map(|ok| {
            if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }),
        Command::CheckDerivatives {
            cases,
            seed,
            filter,
        } => check_derivatives(cases, seed, &filter),
        Command::Material {
            file,
            z,
            z_file,
            json,
            write,
        } => material_cmd(&file, &z, z_file.as_deref(), json, write.as_deref()),
        Command::Pattern { file, write } => pattern_cmd(&file, write.as_deref()),
        Command::Generate {
            kind,
            n,
            step,
            vertices_per_radius,
            obj,
            out,
        } => generate_cmd(
            &kind,
            n,
            step,
            vertices_per_radius,
            obj.as_deref(),
            out.as_deref(),
        ),
        Command::Sample {
            pattern,
            plan,
            out,
            cold,
            shard,
            limit,
            tolerance,
            max_steps,
            time_limit,
        } => {
            let options = hylc::micro::SolverOptions {
                tolerance,
                max_steps,
                time_limit,
                ..Default::default()
            };
            sample::sample(
                &pattern,
                &plan,
                &out,
                cold,
                shard.as_deref(),
                limit,
                options,
            )
            .map(|ok| {
                if ok {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::from(3)
                }
            })
        }
        Command::ScenePlan {
            logs,
            write,
            base,
            margin,
            all_triangles,
        } => sample::scene_plan_cmd(&logs, &write, &base, margin, all_triangles)
            .map(|_| ExitCode::SUCCESS),
        Command::Merge { out, inputs } => {
            sample::merge_cmd(&out, &inputs).map(|_| ExitCode::SUCCESS)
        }
        Command::Plan {
            write,
            reduced,
            holdout,
        } => sample::plan_cmd(&write, reduced, holdout).map(|_| ExitCode::SUCCESS),
        Command::Fit {
            samples,
            out,
            report,
            plots,
            no_plots,
            plan,
            density,
            holdout,
            compare,
            stockinette_like,
            knots_1d,
            knots_2d,
            min_slope,
            extent,
            slopes,
            thin_1d,
            twist_only,
        } => (|| {
            let mut options = if stockinette_like {
                hylc::fit::FitOptions::stockinette_like()
            } else {
                hylc::fit::FitOptions::default()
            };
            options.n_knots_1d = knots_1d;
            options.n_knots_2d = knots_2d;
            if let Some(m) = min_slope {
                options.min_slope = m;
            }
            if let Some(e) = extent {
                options.extent_2d = e;
            }
            options.slopes = fit::parse_slopes(&slopes)?;
            options.thin_1d = thin_1d.max(1);
            options.strict_patches = !twist_only;
            let out = out.unwrap_or_else(|| samples.with_extension("material.json"));
            let report = report.unwrap_or_else(|| samples.with_extension("fit.json"));
            let plots = plots.unwrap_or_else(|| samples.with_extension("plots"));
            fit::fit(
                &samples,
                &out,
                &report,
                &plots,
                fit::FitArgs {
                    plan,
                    density,
                    holdout,
                    compare,
                    options,
                    plots: !no_plots,
                },
            )
        })()
        .map(|_| ExitCode::SUCCESS),
        Command::Solve {
            pattern,
            z,
            cold,
            no_predictor,
            tolerance,
            max_steps,
            time_limit,
            step_factor,
            backtracking,
            no_slide_constraints,
            obj,
            json,
            trace,
            quadrature,
        } => {
            let options = hylc::micro::SolverOptions {
                trace,
                tolerance,
                max_steps,
                time_limit,
                step_factor,
                backtracking,
                slide_constraints: !no_slide_constraints,
                ..Default::default()
            };
            micro::solve(
                &pattern,
                &z,
                cold,
                !no_predictor,
                options,
                obj.as_deref(),
                json,
                quadrature,
            )
            .map(|ok| {
                if ok {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::from(3)
                }
            })
        }
        Command::Reference {
            pattern,
            construction,
            equilibrate_only,
            out,
            json,
        } => micro::reference(
            &pattern,
            construction.as_deref(),
            equilibrate_only,
            &out,
            json.as_deref(),
        )
        .map(|_| ExitCode::SUCCESS),
        Command::Sensitivity { pattern, z } => {
            micro::sensitivity(&pattern, &z, Default::default()).map(|_| ExitCode::SUCCESS)
        }
        Command::MicroGrid {
            pattern,
            data_dir,
            json,
            limit,
            cold_every,
            tolerance,
            max_steps,
            no_slide_constraints,
            file_periods,
        } => {
            let options = hylc::micro::SolverOptions {
                tolerance,
                max_steps,
                slide_constraints: !no_slide_constraints,
                ..Default::default()
            };
            micro_grid::run(
                &pattern,
                &data_dir,
                json.as_deref(),
                limit,
                cold_every,
                file_periods,
                options,
            )
            .map(|ok| {
                if ok {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::from(3)
                }
            })
        }
        Command::Calibrate {
            dir,
            quadrature,
            exclusion,
            radius_factor,
            json,
        } => calibrate::run(
            dir.as_deref(),
            &quadrature,
            &exclusion,
            &radius_factor,
            json.as_deref(),
        ),
        Command::Simulate {
            scene,
            out,
            material,
            duration,
            dt,
            edge,
            psd,
            no_bending,
            only_1d,
            in_plane_only,
            quiet,
            print,
        } => simulate::run_cmd(
            &scene,
            &out,
            &simulate::Overrides {
                material,
                duration,
                dt,
                edge,
                psd,
                no_bending,
                only_1d,
                in_plane_only,
                quiet,
                print,
            },
        ),
    };
    match result {
        Ok(code) => code,
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::from(2)
        }
    }
}

fn check_derivatives(cases: usize, seed: u64, filter: &str) -> Result<ExitCode, String> {
    let cfg = CheckConfig {
        cases,
        seed,
        ..CheckConfig::default()
    };
    let t0 = Instant::now();
    let reports = run_all(&cfg, filter);
    if reports.is_empty() {
        return Err(format!("no registered function matches filter {filter:?}"));
    }
    print!("{}", format_table(&reports));
    let failed: Vec<&str> = reports
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.name.as_str())
        .collect();
    let tol = cfg.tolerances;
    println!(
        "tolerances (relative, normwise): value {:.0e}, gradient/AD {:.0e}, Hessian/AD {:.0e}, gradient/FD {:.0e}, \
         Hessian/FD {:.0e}; 'worst' is the largest error/tolerance ratio",
        tol.value, tol.gradient_ad, tol.hessian_ad, tol.gradient_fd, tol.hessian_fd
    );
    if hylc::shared_dir().is_none() {
        println!("note: ../shared not found: rows for the original materials were skipped");
    }
    println!(
        "{} functions, {} cases each, seed {seed}, {:.1} s",
        reports.len(),
        cases,
        t0.elapsed().as_secs_f64()
    );
    if failed.is_empty() {
        println!("check-derivatives: {} passed, 0 failed", reports.len());
        Ok(ExitCode::SUCCESS)
    } else {
        println!(
            "check-derivatives: {} passed, {} failed ({})",
            reports.len() - failed.len(),
            failed.len(),
            failed.join(", ")
        );
        Ok(ExitCode::FAILURE)
    }
}

fn generate_cmd(
    kind: &str,
    n: Option<usize>,
    step: Option<usize>,
    vertices_per_radius: f64,
    obj: Option<&Path>,
    out: Option<&Path>,
) -> Result<ExitCode, String> {
    let weave_params = match kind {
        "plain" => Some(WeaveParams::plain()),
        "twill" => Some(WeaveParams::twill(n.unwrap_or(4))),
        "satin" => Some(WeaveParams::satin(n.unwrap_or(5), step.unwrap_or(2))),
        "basket" => Some(WeaveParams::basket(n.unwrap_or(2))),
        "stockinette" => None,
        _ => {
            return Err(format!(
                "unknown pattern kind {kind:?} (expected one of {})",
                DEFAULT_KINDS.join(", ")
            ))
        }
    };
    if n.is_some() && !matches!(kind, "twill" | "satin" | "basket") {
        return Err(format!("--n does not apply to {kind}"));
    }
    if step.is_some() && kind != "satin" {
        return Err(format!("--step applies to satin only, not {kind}"));
    }
    let pattern: Pattern = match weave_params {
        Some(params) => weave(&WeaveParams {
            vertices_per_radius,
            ..params
        }),
        None => stockinette(&KnitParams {
            vertices_per_radius,
            ..KnitParams::stockinette()
        }),
    }
    .map_err(|e| format!("generate {kind}: {e}"))?;
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
    if let Some(path) = obj {
        std::fs::write(path, to_obj(&pattern))
            .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = out {
        pattern.save_pyp(path).map_err(|e| e.to_string())?;
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

fn load_material(file: &str) -> Result<Material, String> {
    if file == "default" {
        Ok(default_material())
    } else {
        Material::load(Path::new(file)).map_err(|e| e.to_string())
    }
}

/// Parse six numbers separated by commas and/or whitespace.
fn parse_strain(text: &str) -> Result<[f64; 6], String> {
    let parts: Vec<&str> = text
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .collect();
    if parts.len() != 6 {
        return Err(format!(
            "expected 6 numbers (s_x, s_a, s_y, II00, II01, II11), found {}",
            parts.len()
        ));
    }
    let mut z = [0.0; 6];
    for (i, p) in parts.iter().enumerate() {
        let v: f64 = p
            .parse()
            .map_err(|_| format!("{} = {p:?} is not a number", STRAIN_NAMES[i]))?;
        if !v.is_finite() {
            return Err(format!("{} = {p} is not finite", STRAIN_NAMES[i]));
        }
        z[i] = v;
    }
    Ok(z)
}

fn material_cmd(
    file: &str,
    zs: &[String],
    z_file: Option<&Path>,
    json: bool,
    write: Option<&Path>,
) -> Result<ExitCode, String> {
    let mat = load_material(file)?;
    let mut strains = Vec::new();
    for (i, s) in zs.iter().enumerate() {
        strains.push(parse_strain(s).map_err(|e| format!("--z #{} {s:?}: {e}", i + 1))?);
    }
    if let Some(path) = z_file {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            strains.push(
                parse_strain(line).map_err(|e| format!("{}:{}: {e}", path.display(), n + 1))?,
            );
        }
    }
    if let Some(out) = write {
        mat.save(out)
            .map_err(|e| format!("{}: cannot write: {e}", out.display()))?;
        eprintln!("wrote {}", out.display());
    }
    if strains.is_empty() && write.is_none() {
        return Err("no strains given: use --z SX,SA,SY,II00,II01,II11 or --z-file FILE".into());
    }
    for z in &strains {
        let r = mat.eval(z);
        if json {
            println!("{}", psi_json(z, &r));
        } else {
            print_psi(z, &r);
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn pattern_cmd(file: &Path, write: Option<&Path>) -> Result<ExitCode, String> {
    let (p, warnings) = Pattern::load_pyp(file).map_err(|e| e.to_string())?;
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
    if let Some(out) = write {
        p.save_pyp(out).map_err(|e| e.to_string())?;
        let (back, _) = Pattern::load_pyp(out).map_err(|e| e.to_string())?;
        if back != p {
            return Err(format!(
                "{}: the written file reads back differently",
                out.display()
            ));
        }
        println!("wrote {}", out.display());
    }
    Ok(ExitCode::SUCCESS)
}

fn psi_json(z: &[f64; 6], r: &PsiVgh) -> String {
    serde_json::json!({ "z": z, "psi": r.value, "grad": r.grad, "hess": r.hess }).to_string()
}

fn print_psi(z: &[f64; 6], r: &PsiVgh) {
    println!("z      = [{}]", fmt_row(z));
    println!("psi    = {:.12e} J/m^2", r.value);
    println!("grad   = [{}]", fmt_row(&r.grad));
    for (i, row) in r.hess.iter().enumerate() {
        println!(
            "{} [{}]",
            if i == 0 { "hess   =" } else { "        " },
            fmt_row(row)
        );
    }
    println!();
}

fn fmt_row(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:>13.6e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A strain sweep: name, z(t), t range.
type Sweep = (&'static str, fn(f64) -> [f64; 6], f64, f64);

/// The material demo: what `run` does until the end-to-end pipeline exists.
fn run_demo(out: &Path) -> Result<ExitCode, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    let t0 = Instant::now();
    let mat = default_material();
    let path = out.join("material_default.json");
    mat.save(&path)
        .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    let back = Material::load(&path).map_err(|e| e.to_string())?;
    let z_probe = [0.1, 0.2, -0.05, 30.0, -10.0, 20.0];
    if back.eval(&z_probe) != mat.eval(&z_probe) {
        return Err(format!(
            "{}: re-read material evaluates differently",
            path.display()
        ));
    }
    println!(
        "material: {} (embedded synthetic default, round trip exact)",
        path.display()
    );
    // sweeps: uniaxial stretch, shear, x-bending, an umbilic (equal principal curvature) sweep
    let sweeps: [Sweep; 4] = [
        ("stretch s_x", |t| [t, 0.0, 0.0, 0.0, 0.0, 0.0], -0.5, 1.0),
        ("shear s_a", |t| [0.0, t, 0.0, 0.0, 0.0, 0.0], -0.7, 0.7),
        (
            "bend II00 (1/m)",
            |t| [0.0, 0.0, 0.0, t, 0.0, 0.0],
            -150.0,
            150.0,
        ),
        (
            "umbilic II00=II11 (1/m)",
            |t| [0.0, 0.0, 0.0, t, 0.0, t],
            -150.0,
            150.0,
        ),
    ];
    let mut log = Vec::new();
    for (name, zf, lo, hi) in sweeps {
        println!(
            "\n{name:>24} {:>13} {:>13} {:>13}",
            "psi", "dpsi/dz", "d2psi/dz2"
        );
        let k = (0..6).find(|&k| zf(1.0)[k] != 0.0).unwrap_or(0);
        for i in 0..=6 {
            let t = lo + (hi - lo) * i as f64 / 6.0;
            let z = zf(t);
            let r = mat.eval(&z);
            println!(
                "{t:>24.4} {:>13.5e} {:>13.5e} {:>13.5e}",
                r.value, r.grad[k], r.hess[k][k]
            );
            log.push(psi_json(&z, &r));
        }
    }
    let sweep_path = out.join("material_sweeps.jsonl");
    std::fs::write(&sweep_path, log.join("\n") + "\n")
        .map_err(|e| format!("{}: cannot write: {e}", sweep_path.display()))?;
    // timing of the fast path, as the CLI's own measurement
    let n = 200_000;
    let mut acc = 0.0;
    let tt = Instant::now();
    for i in 0..n {
        let f = i as f64 / n as f64;
        let r = mat.eval(&[f - 0.5, 0.3 * f, 0.2, 100.0 * f - 50.0, 10.0, 30.0 * f]);
        acc += r.value + r.hess[3][5];
    }
    let per = tt.elapsed().as_secs_f64() / n as f64;
    println!(
        "\npsi + grad + Hessian: {:.3} us per evaluation ({n} evaluations, checksum {acc:.6e})",
        per * 1e6
    );
    let cfg = CheckConfig {
        cases: 100,
        ..CheckConfig::default()
    };
    let reports = run_all(&cfg, "default");
    print!("\n{}", format_table(&reports));
    println!(
        "\nwrote {} and {} in {:.1} s",
        path.display(),
        sweep_path.display(),
        t0.elapsed().as_secs_f64()
    );
    Ok(if reports.iter().all(|r| r.passed()) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
