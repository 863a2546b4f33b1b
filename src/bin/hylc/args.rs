//! Flag groups and value types that several subcommands share.

use clap::ValueEnum;
use hylc::micro::reference::Construction;
use hylc::micro::{CrossingGuard, Predictor, SolverOptions, StepRule};
use hylc::rod::YarnMaterial;
use hylc::workflow::warnings::radius_overridden;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The micro solver's stopping rules (`hylc solve`, `sample`, `micro-grid`).
#[derive(clap::Args, Clone, Debug)]
pub struct SolverArgs {
    /// force tolerance relative to the stretching stiffness
    #[arg(long, default_value = "1e-8")]
    pub tolerance: f64,
    /// Newton step limit
    #[arg(long, default_value_t = 2000)]
    pub max_steps: usize,
    /// wall-time limit per solve in seconds
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// yarn crossings along the Newton path and, in a sample chain, on the way to each warm or predicted start:
    /// not checked (off), counted (count), or line-search trials and starts that pass two yarn centre lines
    /// through each other rejected (reject); default off (`sample --starts warm+cold|all`: reject). A measured
    /// trade (docs/sampling.md, "The crossing guard"): reject keeps every sample in its fabric, at 0.34–1.2× the speed
    #[arg(long, value_enum)]
    pub crossings: Option<CrossingGuardArg>,
    /// the plain shift rule alone (μ grown until H + μI is positive definite) instead of the default
    /// inertia-controlled steps (the exact constrained Newton step wherever H is positive definite on the
    /// constraint space and the energy follows its quadratic model); reproduces the solver of sample files made
    /// before the inertia control bit for bit, and such files resume only with it
    #[arg(long)]
    pub no_inertia: bool,
}

impl SolverArgs {
    /// The solver options with these stopping rules, the others at their defaults.
    pub fn options(&self) -> SolverOptions {
        SolverOptions {
            tolerance: self.tolerance,
            max_steps: self.max_steps,
            time_limit: self.time_limit,
            crossings: self.crossings.map(CrossingGuard::from).unwrap_or_default(),
            step_rule: if self.no_inertia {
                StepRule::Shift
            } else {
                StepRule::Inertia
            },
            ..Default::default()
        }
    }
}

/// `--crossings` (`hylc::micro::CrossingGuard`; the help of each value is the library variant's).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CrossingGuardArg {
    /// Not checked.
    Off,
    /// Every accepted step (and a chain's start path) is checked and the crossings are reported; the solve is
    /// unchanged.
    Count,
    /// A line-search trial that crosses yarns is rejected (the search backtracks further); a chain's start whose
    /// path crosses is replaced by the next candidate (predicted, warm, cold).
    Reject,
}

impl From<CrossingGuardArg> for CrossingGuard {
    fn from(c: CrossingGuardArg) -> Self {
        match c {
            CrossingGuardArg::Off => CrossingGuard::Off,
            CrossingGuardArg::Count => CrossingGuard::Count,
            CrossingGuardArg::Reject => CrossingGuard::Reject,
        }
    }
}

/// `--predictor` of `solve` and `sample` (`hylc::micro::Predictor`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PredictorArg {
    /// Linear extrapolation from the two previous equilibria.
    Secant,
    /// The previous equilibrium itself (moved to the new strain at fixed unknowns).
    None,
}

impl From<PredictorArg> for Predictor {
    fn from(p: PredictorArg) -> Self {
        match p {
            PredictorArg::Secant => Predictor::Secant,
            PredictorArg::None => Predictor::None,
        }
    }
}

/// The yarn parameters of every command that solves (`solve`, `reference`, `sample`, `micro-grid`, `run`,
/// `sensitivity`, `identify`): a yarn JSON file (`hylc yarn` prints the default one), or the defaults.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct YarnArgs {
    /// yarn parameters as JSON (every key required; `hylc yarn` prints the defaults)
    #[arg(long, value_name = "FILE")]
    pub yarn: Option<PathBuf>,
}

impl YarnArgs {
    /// A warning on stderr when the yarn file's radius differs from the radius of the pattern `pattern` (the
    /// argument that named it), which every solve takes instead (`hylc::workflow::warnings::radius_overridden`).
    pub fn warn_radius(&self, yarn: &YarnMaterial, pattern: &str, pattern_radius: f64) {
        let Some(file) = &self.yarn else { return };
        if let Some(w) = radius_overridden(file, yarn.radius, pattern, pattern_radius) {
            eprintln!("{w}");
        }
    }

    /// The yarn file's parameters, or the defaults without `--yarn`.
    pub fn material(&self) -> anyhow::Result<YarnMaterial> {
        match &self.yarn {
            None => Ok(YarnMaterial::default()),
            Some(path) => {
                Ok(YarnMaterial::load_json(path).map_err(|e| anyhow::anyhow!("--yarn {e}"))?)
            }
        }
    }
}

/// Where a command writes its report as JSON (`hylc reference`, `hylc calibrate`).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct OutputArgs {
    /// also write the report as JSON to this file
    #[arg(long)]
    pub json: Option<PathBuf>,
}

impl OutputArgs {
    /// Write `report` as pretty JSON (with a final newline) when `--json` was given; the file's path when written.
    pub fn write_report<T: serde::Serialize>(&self, report: &T) -> anyhow::Result<Option<&Path>> {
        let Some(path) = &self.json else {
            return Ok(None);
        };
        let text = serde_json::to_string_pretty(report)?;
        std::fs::write(path, text + "\n")
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        Ok(Some(path))
    }
}

/// Knitted or woven (selects C1's tension factors).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstructionArg {
    #[value(alias = "knit")]
    Knitted,
    #[value(alias = "weave")]
    Woven,
}

impl From<ConstructionArg> for Construction {
    fn from(c: ConstructionArg) -> Self {
        match c {
            ConstructionArg::Knitted => Construction::Knitted,
            ConstructionArg::Woven => Construction::Woven,
        }
    }
}

/// Exit code 0 when `ok`, else `code` (e.g. 3: a solve did not converge).
pub fn exit(ok: bool, code: u8) -> ExitCode {
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(code)
    }
}

/// A comma-separated list of values for `--what`.
pub fn parse_list<T: std::str::FromStr>(text: &str, what: &str) -> anyhow::Result<Vec<T>> {
    text.split(',')
        .map(|s| {
            s.trim()
                .parse()
                .map_err(|_| anyhow::anyhow!("--{what}: cannot parse {s:?} in {text:?}"))
        })
        .collect()
}

/// The fit presets (`hylc::fit::FitPreset`).
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum PresetArg {
    Covering,
    Design,
    DesignStockinette,
}

impl From<PresetArg> for hylc::fit::FitPreset {
    fn from(p: PresetArg) -> Self {
        match p {
            PresetArg::Covering => hylc::fit::FitPreset::Covering,
            PresetArg::Design => hylc::fit::FitPreset::Design,
            PresetArg::DesignStockinette => hylc::fit::FitPreset::DesignStockinette,
        }
    }
}
