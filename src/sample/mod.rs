//! Sampling (`../shared/design/04-sampling-fitting.md`, section "Sampling plan (C4)"): plans ([`plan`]) and
//! running them on one pattern ([`run`]): parallel warm-started chains, an append-only sample file, resume,
//! shards and merging; plans derived from the strains a macro run visited ([`scene`]).

pub mod plan;
pub mod run;
pub mod scene;

pub use plan::{sample_range, Chain, InPlaneGrid, Plan, PlanError, Sample, Step};
pub use run::{
    merge, parse_shard, read_samples, run_plan, Record, RunOptions, RunSummary, SampleStart,
    SampleStatus,
};
