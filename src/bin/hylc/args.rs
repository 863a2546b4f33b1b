//! Flag groups and value types that several subcommands share.

use clap::ValueEnum;
use hylc::micro::reference::Construction;
use hylc::micro::{CrossingGuard, PsdStencils, SolverOptions};
use hylc::rod::YarnMaterial;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The micro solver's stopping rules (`hylc solve`, `sample`, `micro-grid`).
#[derive(clap::Args, Clone, Debug)]
pub struct SolverArgs {
    /// force tolerance relative to the stretching stiffness
    #[arg(long, default_value_t = 1e-8)]
    pub tolerance: f64,
    /// Newton step limit
    #[arg(long, default_value_t = 2000)]
    pub max_steps: usize,
    /// wall-time limit per solve in seconds
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// where H + μI needs a shift above its floor, take the exact Newton step on the constraint space
    /// (projected conjugate gradients) when H is positive definite there, instead of the shifted step
    #[arg(long)]
    pub projected_steps: bool,
    /// after a step whose factorisation needed a larger shift μ, start the next step at that μ (not μ/10)
    #[arg(long)]
    pub keep_shift: bool,
    /// project each rod stencil's and contact pair's local Hessian to positive semi-definite: always, or only
    /// where the exact H + μI does not factorise at μ's floor (fallback); off: the exact Hessian with the μ shift
    #[arg(long, value_enum, default_value = "off")]
    pub psd_stencils: PsdStencilsArg,
    /// yarn crossings along the Newton path and, in a sample chain, on the way to each warm or predicted start:
    /// not checked (off), counted (count), or line-search trials and starts that pass two yarn centre lines
    /// through each other rejected (reject); default off (`sample --starts warm+cold|all`: reject)
    #[arg(long, value_enum)]
    pub crossings: Option<CrossingGuard>,
    /// trust-region Newton steps (truncated conjugate gradients preconditioned by the shifted factorisation,
    /// following negative curvature to the boundary) instead of the displacement limit and the backtracking
    #[arg(long)]
    pub trust_region: bool,
    /// the design's shift rule alone (μ grown until H + μI is positive definite) instead of the default
    /// inertia-controlled steps (the exact constrained Newton step wherever H is positive definite on the
    /// constraint space and the energy follows its quadratic model)
    #[arg(long)]
    pub no_inertia: bool,
    /// with the inertia-controlled steps: after a refused exact step, skip the exact attempt for the next 1, 2,
    /// 4, …, 16 steps (doubled after each consecutive refusal)
    #[arg(long, conflicts_with = "no_inertia")]
    pub exact_backoff: bool,
    /// line search: after a refused trial step, the next from the parabola through E(0), the slope at 0 and the
    /// refused trial's energy (within 0.1–0.5 of the refused step) instead of the fixed factor 0.1
    #[arg(long)]
    pub interpolating_search: bool,
    /// displacement limit factor: no vertex moves more than F · r · λ_min(Ī) per Newton step (the design's 1)
    #[arg(long, default_value_t = 1.0, value_name = "F", value_parser = positive_finite, allow_hyphen_values = true)]
    pub step_factor: f64,
}

/// `--psd-stencils` ([`PsdStencils`]).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PsdStencilsArg {
    Off,
    Always,
    Fallback,
}

impl From<PsdStencilsArg> for PsdStencils {
    fn from(p: PsdStencilsArg) -> Self {
        match p {
            PsdStencilsArg::Off => PsdStencils::Off,
            PsdStencilsArg::Always => PsdStencils::Always,
            PsdStencilsArg::Fallback => PsdStencils::Fallback,
        }
    }
}

impl SolverArgs {
    /// The solver options with these stopping rules, the others at their defaults.
    pub fn options(&self) -> SolverOptions {
        SolverOptions {
            tolerance: self.tolerance,
            max_steps: self.max_steps,
            time_limit: self.time_limit,
            projected_steps: self.projected_steps,
            keep_shift: self.keep_shift,
            psd_stencils: self.psd_stencils.into(),
            crossings: self.crossings.unwrap_or_default(),
            trust_region: self.trust_region,
            inertia: !self.no_inertia,
            exact_backoff: self.exact_backoff,
            interpolating_search: self.interpolating_search,
            step_factor: self.step_factor,
            ..Default::default()
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

/// A clap value parser: a finite number > 0.
fn positive_finite(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!("expected a finite number > 0, got {v}")),
        Err(e) => Err(format!("{e}")),
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
