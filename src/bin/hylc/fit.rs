//! `hylc fit SAMPLES`: a material from a sample file (Algorithm C5; `docs/sampling.md`, "Fitting (C5, C6,
//! C7)"; `hylc::workflow::fit`), with the JSON fit report and PNG plots.

use crate::args::PresetArg;
use crate::printer::Printer;
use clap::ValueEnum;
use hylc::fit::model::FitOptions;
use hylc::fit::{FitPreset, SlopeSource};
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
    /// the fit's settings (docs/fitting.md, "Presets"): covering (knots over the whole sampled range, for
    /// plans with few samples per axis such as the quick plan; `hylc run`'s), design (the method's own, for
    /// dense plans) or design-stockinette (design with the original stockinette material's layout); the flags
    /// below change single settings of it
    #[arg(long, value_enum, default_value = "covering")]
    preset: PresetArg,
    /// knots of each 1D term, N_c [preset: 11]
    #[arg(long)]
    knots_1d: Option<usize>,
    /// knots per axis of each in-plane 2D term [covering: 11, design: 9]
    #[arg(long)]
    knots_2d: Option<usize>,
    /// minimum slope pˣ_min [0.001; design-stockinette: 0.01]
    #[arg(long)]
    min_slope: Option<f64>,
    /// extent of the in-plane 2D knots as a fraction of the data range [covering: 1, design: 0.9]
    #[arg(long)]
    extent: Option<f64>,
    /// slopes of the 1D terms: fd (finite differences of the MLS) or stress (MLS of the sampled stresses)
    /// [preset: fd]
    #[arg(long, value_enum)]
    slopes: Option<SlopesArg>,
    /// fit the 1D terms to every K-th sample of their ranges only (the others are held out) [1]
    #[arg(long, value_name = "K")]
    thin_1d: Option<usize>,
    /// stop FIT2D's monotone correction after the twists (report non-monotone patches instead of shrinking
    /// the cross slopes)
    #[arg(long)]
    twist_only: bool,
    /// keep FIT2D's residual on the compressed half-plane of s_x or s_y as a non-negative excess, monotone
    /// outward from the axes (FIT2D step 7′), instead of zeroing it (`--compression-residual false` zeroes it)
    /// [covering: on, design: off]
    #[arg(long, value_name = "BOOL", num_args = 0..=1, default_missing_value = "true")]
    compression_residual: Option<bool>,
    /// fit the two signs of shear s_a separately instead of symmetrising every term in s_a (for patterns whose
    /// Ψ̄ is not even in s_a, e.g. the knits)
    #[arg(long)]
    asymmetric_shear: bool,
    /// knots per axis of the 2D terms with a bending strain [covering: 11, design: 9, design-stockinette: 5]
    #[arg(long)]
    knots_2d_bending: Option<usize>,
    /// extent of the knots of the 2D terms with a bending strain as a fraction of the data range [covering: 1,
    /// design: 0.9, design-stockinette: 0.3]
    #[arg(long)]
    extent_bending: Option<f64>,
    /// MLS bandwidth of every term (1D and 2D) in median sample spacings [covering: 1, design: 2]
    #[arg(long)]
    bandwidth: Option<f64>,
    /// extent of the knots of the 1D terms as a fraction of each range (beyond them a term continues linearly)
    /// [covering: 1, design: 0.95]
    #[arg(long)]
    extent_1d: Option<f64>,
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
    /// The fit options these flags select: the preset's, with each flag given replacing one setting.
    fn options(&self) -> FitOptions {
        let mut o = FitPreset::from(self.preset).options();
        let set = |slot: &mut usize, v: Option<usize>| *slot = v.unwrap_or(*slot);
        set(&mut o.n_knots_1d, self.knots_1d);
        set(&mut o.n_knots_2d, self.knots_2d);
        set(&mut o.n_knots_2d_bending, self.knots_2d_bending);
        set(&mut o.thin_1d, self.thin_1d.map(|k| k.max(1)));
        let setf = |slot: &mut f64, v: Option<f64>| *slot = v.unwrap_or(*slot);
        setf(&mut o.min_slope, self.min_slope);
        setf(&mut o.extent_2d, self.extent);
        setf(&mut o.extent_2d_bending, self.extent_bending);
        setf(&mut o.bandwidth_factor, self.bandwidth);
        setf(&mut o.extent_1d, self.extent_1d);
        if let Some(s) = self.slopes {
            o.slopes = s.into();
        }
        if let Some(c) = self.compression_residual {
            o.compression_residual = c;
        }
        o.strict_patches &= !self.twist_only;
        o.symmetric_shear &= !self.asymmetric_shear;
        o
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
