//! `hylc fit SAMPLES`: a material from a sample file (Algorithm C5; `docs/sampling.md`, "Fitting (C5, C6,
//! C7)"; `hylc::workflow::fit`), with the JSON fit report and PNG plots.

use crate::printer::Printer;
use clap::ValueEnum;
use hylc::fit::model::FitOptions;
use hylc::fit::SlopeSource;
use hylc::workflow::fit::{fit_samples, FitJob};
use hylc::workflow::WorkflowError;
use std::path::PathBuf;
use std::process::ExitCode;

/// Fit a material (Algorithm C5) to a sample file; writes the material JSON, a JSON fit report and PNG plots.
#[derive(clap::Args)]
pub struct Args {
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
    #[arg(long, value_enum, default_value = "fd")]
    slopes: SlopesArg,
    /// fit the 1D terms to every K-th sample of their ranges only (the others are held out)
    #[arg(long, default_value_t = 1, value_name = "K")]
    thin_1d: usize,
    /// stop FIT2D's monotone correction after the twists (report non-monotone patches instead of shrinking
    /// the cross slopes)
    #[arg(long)]
    twist_only: bool,
    /// keep FIT2D's residual on the compressed half-plane of s_x or s_y as a non-negative excess, monotone
    /// outward from the axes (FIT2D step 7′), instead of zeroing it
    #[arg(long)]
    compression_residual: bool,
    /// fit the two signs of shear s_a separately instead of symmetrising every term in s_a (for patterns whose
    /// Ψ̄ is not even in s_a, e.g. the knits)
    #[arg(long)]
    asymmetric_shear: bool,
    /// knots per axis of the 2D terms with a bending strain (default 9, or 5 with --stockinette-like)
    #[arg(long)]
    knots_2d_bending: Option<usize>,
    /// extent of the knots of the 2D terms with a bending strain as a fraction of the data range (default 0.9,
    /// or 0.3 with --stockinette-like)
    #[arg(long)]
    extent_bending: Option<f64>,
    /// MLS bandwidth of every term (1D and 2D) in median sample spacings
    #[arg(long, default_value_t = 2.0)]
    bandwidth: f64,
    /// extent of the knots of the 1D terms as a fraction of each range (beyond them a term continues linearly)
    #[arg(long, default_value_t = 0.95)]
    extent_1d: f64,
}

/// Where the 1D knot slopes come from (`hylc::fit::SlopeSource`).
#[derive(ValueEnum, Clone, Copy, Debug)]
enum SlopesArg {
    Fd,
    Stress,
}

impl From<SlopesArg> for SlopeSource {
    fn from(s: SlopesArg) -> Self {
        match s {
            SlopesArg::Fd => SlopeSource::FiniteDifference,
            SlopesArg::Stress => SlopeSource::Stress,
        }
    }
}

impl Args {
    /// The fit options these flags select.
    fn options(&self) -> FitOptions {
        let mut options = if self.stockinette_like {
            FitOptions::stockinette_like()
        } else {
            FitOptions::default()
        };
        options.n_knots_1d = self.knots_1d;
        options.n_knots_2d = self.knots_2d;
        if let Some(m) = self.min_slope {
            options.min_slope = m;
        }
        if let Some(e) = self.extent {
            options.extent_2d = e;
        }
        options.slopes = self.slopes.into();
        options.thin_1d = self.thin_1d.max(1);
        options.strict_patches = !self.twist_only;
        options.compression_residual = self.compression_residual;
        options.symmetric_shear = !self.asymmetric_shear;
        if let Some(k) = self.knots_2d_bending {
            options.n_knots_2d_bending = k;
        }
        if let Some(e) = self.extent_bending {
            options.extent_2d_bending = e;
        }
        options.bandwidth_factor = self.bandwidth;
        options.extent_1d = self.extent_1d;
        options
    }
}

/// `hylc fit`: exit code 0 when the material was written, 2 on bad input (including a sample record with a
/// non-finite or absurd value, or an id listed twice with different results), 3 when the fit did not converge:
/// too few samples of a term converged, or the model came out non-finite (nothing is written then).
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let beside = FitJob::beside(&a.samples);
    let job = FitJob {
        out: a.out.clone().unwrap_or(beside.out),
        report: a.report.clone().unwrap_or(beside.report),
        plots: a.plots.clone().unwrap_or(beside.plots),
        plan: a.plan.clone(),
        density: a.density,
        holdout: a.holdout.clone(),
        compare: a.compare.clone(),
        options: a.options(),
        write_plots: !a.no_plots,
        samples: a.samples,
    };
    let mut printer = Printer::default();
    match fit_samples(&job, &mut |e| printer.show(e)) {
        Ok(_) => Ok(ExitCode::SUCCESS),
        // too few samples converged for a term, or the model came out non-finite: nothing written, exit 3
        Err(WorkflowError::Fit { samples, source }) if source.is_not_converged() => {
            eprintln!("error: {}: {source}", samples.display());
            Ok(ExitCode::from(3))
        }
        Err(e) => Err(e.into()),
    }
}
