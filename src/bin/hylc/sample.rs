//! `hylc sample PATTERN --plan P --out S.jsonl`: a sampling plan on one pattern
//! (`docs/sampling.md`, section "Sampling plan (C4)"; `hylc::sample`).

use crate::args::{exit, PredictorArg, SolverArgs, YarnArgs};
use crate::printer::sample_bar;
use crate::strain::load_pattern_noted;
use clap::ValueEnum;
use hylc::micro::{CrossingGuard, MicroProblem};
use hylc::sample::{parse_shard, run_plan_with, RunOptions, Starts};
use hylc::workflow::inputs::load_plan;
use hylc::workflow::sidecar::write_meta;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::OnceLock;

/// Run a sampling plan on a pattern (warm-started chains in parallel), appending to a JSON-lines sample file;
/// finished samples are skipped, so an interrupted run resumes where it stopped.
#[derive(clap::Args)]
pub struct Args {
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
    /// predictor of warm starts along a chain: secant (from the two previous equilibria) or none (the previous
    /// equilibrium itself)
    #[arg(long, value_enum, default_value_t = PredictorArg::Secant)]
    predictor: PredictorArg,
    /// starts of every sample: warm (along the chain), or warm+cold (also from the reference
    /// state, keeping the lowest converged Ψ̄; the record lists every start), or all (where warm and cold
    /// disagree, also from the steps that continue the sample: the chain in reverse)
    #[arg(long, value_enum, default_value_t = StartsArg::Warm)]
    starts: StartsArg,
    /// --starts all: relative difference of the warm and the cold Ψ̄ above which the reversed chain is tried
    #[arg(long, default_value_t = hylc::sample::starts::DEFAULT_DISAGREEMENT)]
    disagreement: f64,
    /// store ∂Ψ̄/∂θ and dσ/dθ for the six yarn parameters in every converged record (`dpsi_dtheta`,
    /// `dstress_dtheta`); on a finished file, add them to the records that lack them
    #[arg(long)]
    sensitivities: bool,
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    yarn: YarnArgs,
}

/// `--starts` (`hylc::sample::Starts`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum StartsArg {
    /// The warm start along the chain only (today's records, bit for bit).
    Warm,
    /// The warm start and the cold start (reference state); the lowest converged Ψ̄ is kept.
    #[value(name = "warm+cold")]
    WarmCold,
    /// Warm and cold, and where they disagree the reversed chain (starts from the steps that continue a sample).
    All,
}

impl From<StartsArg> for Starts {
    fn from(s: StartsArg) -> Self {
        match s {
            StartsArg::Warm => Starts::Warm,
            StartsArg::WarmCold => Starts::WarmCold,
            StartsArg::All => Starts::All,
        }
    }
}

/// `hylc sample`: exit code 3 when a written sample did not converge.
pub fn run(a: Args) -> anyhow::Result<ExitCode> {
    let (pattern, out, cold, limit) = (a.pattern.as_str(), a.out.as_path(), a.cold, a.limit);
    let plan = load_plan(&a.plan)?;
    let shard = a.shard.as_deref().map(parse_shard).transpose()?;
    let yarn = a.yarn.material()?;
    let p = load_pattern_noted(pattern)?;
    a.yarn.warn_radius(&yarn, pattern, p.radius);
    let mut options = a.solver.options();
    let starts = Starts::from(a.starts);
    if starts != Starts::Warm && a.solver.crossings.is_none() {
        // a start that pulls yarns through each other ends in another fabric (docs/sampling.md)
        options.crossings = CrossingGuard::Reject;
    }
    let problem = MicroProblem::new(p, &yarn, options);
    write_meta(out, pattern, &plan, &problem)?;
    let opts = RunOptions {
        cold,
        shard,
        limit,
        predictor: a.predictor.into(),
        starts,
        disagreement: Some(a.disagreement),
        sensitivities: a.sensitivities,
    };
    let bar = OnceLock::new();
    let progress = |done: usize, todo: usize| {
        bar.get_or_init(|| sample_bar(todo))
            .set_position(done as u64);
    };
    let s = run_plan_with(&problem, &plan, out, &opts, &progress)?;
    if let Some(b) = bar.get() {
        b.finish_and_clear();
    }
    println!(
        "{}: plan {:016x}, {} samples selected{}, {} already done, {} written ({} converged, {} not), \
         {} re-solved for warm starts, {:.1} s",
        out.display(),
        plan.hash(),
        s.selected,
        shard.map_or(String::new(), |(k, n)| format!(" (shard {k}/{n})")),
        s.already_done,
        s.written,
        s.converged,
        s.written - s.converged,
        s.replayed,
        s.time
    );
    if a.sensitivities {
        println!(
            "sensitivities: {} written records, {} of {} finished records that lacked them",
            s.sensitivities, s.sensitivities_added, s.lacking_sensitivities
        );
    }
    Ok(exit(s.written == s.converged, 3))
}
