//! Sampling (`docs/sampling.md`, section "Sampling plan (C4)"): plans ([`plan`]) and
//! running them on one pattern ([`run`]): parallel warm-started chains, an append-only sample file of
//! [`record`]s, resume, shards and merging, the starts of a multi-start sample ([`starts`]), per-sample
//! sensitivities to the yarn parameters ([`sensitivities`]); plans derived from the strains a macro run visited
//! ([`scene`]). Sibling modules import one way: `record` ← `starts`, `sensitivities` ← `run`.

pub mod plan;
pub mod record;
pub mod run;
pub mod scene;
pub mod sensitivities;
pub mod starts;

pub use plan::{sample_range, Chain, InPlaneGrid, Plan, PlanError, Sample, Step};
pub use record::{PerParameter, Record, SampleStart, SampleStatus, StartKind, StartResult};
pub use run::{
    merge, parse_shard, read_samples, run_plan, run_plan_until, run_plan_with, RunOptions,
    RunSummary,
};
pub use starts::{compare, Comparison, Disagreement, Starts};

use std::path::PathBuf;

/// Errors of sampling: a bad plan or argument, a sample file or strain log that cannot be read or written.
#[derive(Debug, thiserror::Error)]
pub enum SampleError {
    /// A bad sampling plan.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// A file operation failed.
    #[error("{}: {action}: {source}", path.display())]
    Io {
        /// the file or folder
        path: PathBuf,
        /// what was being done ("cannot read", …)
        action: &'static str,
        /// the I/O error
        source: std::io::Error,
    },
    /// A line of a file is not what it should be.
    #[error("{}:{line}: {message}", path.display())]
    Line {
        /// the file
        path: PathBuf,
        /// the line (1-based)
        line: usize,
        /// what is wrong
        message: String,
    },
    /// A file as a whole is not what it should be.
    #[error("{}: {message}", path.display())]
    File {
        /// the file
        path: PathBuf,
        /// what is wrong
        message: String,
    },
    /// A shard that is not `k/n` with 0 ≤ k < n.
    #[error("--shard: expected k/n with 0 ≤ k < n, got {0:?}")]
    Shard(String),
    /// `--starts` other than `warm` with `--cold` (the cold start is one of the starts).
    #[error("--starts {0} with --cold: --cold solves from the reference state only; drop --cold")]
    Starts(String),
    /// A disagreement tolerance of `--starts all` that is not a finite number ≥ 0.
    #[error("--disagreement: expected a finite relative tolerance ≥ 0, got {0}")]
    Disagreement(f64),
}
