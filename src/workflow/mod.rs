//! Workflows: the stages of `../shared/seed/hylc_pseudocode.txt` put together the way the command line runs them
//! (`docs/layout.md`, "Command line"), as library functions that the `hylc` binary, the
//! tests and the Python module share:
//!
//! - [`inputs`]: a pattern, a construction or a sampling plan from a command-line style argument;
//! - [`sidecar`]: the `SAMPLES.meta.json` file beside a sample file (plan, pattern, yarn, solver, density);
//! - [`fit`]: Algorithm C5 on a sample file, with the material, the JSON report and the plots written;
//! - [`simulate`]: a cloth scene (C8) with overrides, its frames, log and PNG snapshot;
//! - [`gradient`]: dJ/dp of an observable of a quasi-static scene by one adjoint solve, with an optional check;
//! - [`warnings`]: warnings that an input is suspect (strains outside a material's knots, a mesh too coarse to
//!   bend, a yarn radius the pattern replaces);
//! - [`pipeline`]: the main job `hylc run` (C1 → C4 → C5–C7 → C8) end to end.
//!
//! Nothing here prints: what a terminal would show goes to an [`Event`] callback (`Send`, because sampling reports
//! its progress from the worker threads).
//!
//! ```no_run
//! use hylc::workflow::{pipeline::{run, RunConfig}, Event};
//!
//! let config = RunConfig { patterns: vec!["plain".into()], out: "out/plain".into(), ..RunConfig::default() };
//! let summary = run(&config, &mut |e| match e {
//!     Event::Log(line) => println!("{line}"),
//!     Event::Samples { done, todo } => eprint!("\rsample {done}/{todo}"),
//!     Event::Step { done, total, .. } => eprint!("\rdrape step {done}/{total}"),
//!     _ => {}
//! })?;
//! println!("{}", summary["total_time"]);
//! # Ok::<(), hylc::workflow::WorkflowError>(())
//! ```

pub mod fit;
pub mod gradient;
pub mod inputs;
pub mod pipeline;
pub mod sidecar;
pub mod simulate;
pub mod warnings;
pub mod yarn_chain;

use std::path::{Path, PathBuf};

/// What a workflow reports while it runs; the `hylc` binary prints the lines and draws a progress bar.
#[derive(Clone, Copy, Debug)]
pub enum Event<'a> {
    /// A line of the run log (`hylc run` also keeps it in `run.log`).
    Log(&'a str),
    /// A line of terminal output that is not part of the run log (e.g. the fit's error table).
    Print(&'a str),
    /// A note or warning (the binary writes it to stderr).
    Note(&'a str),
    /// A sample was written: `done` of the `todo` samples this sampling run writes.
    Samples {
        /// samples written so far
        done: usize,
        /// samples this run writes
        todo: usize,
    },
    /// A cloth time step finished: `done` of `total` steps, simulated time, Newton iterations, final residual.
    Step {
        /// steps finished
        done: usize,
        /// steps in all
        total: usize,
        /// simulated time (s)
        time: f64,
        /// Newton iterations of the step
        newton: usize,
        /// largest residual force on a free vertex at the end of the step (N)
        residual: f64,
    },
}

/// Errors of the workflows: the stage's own error, or a file that could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum WorkflowError {
    /// A file or folder operation failed.
    #[error("{}: {action}: {source}", path.display())]
    Io {
        /// the file or folder
        path: PathBuf,
        /// what was being done ("cannot read", …)
        action: &'static str,
        /// the I/O error
        source: std::io::Error,
    },
    /// A pattern file could not be read or used.
    #[error(transparent)]
    Pattern(#[from] crate::pattern::PatternError),
    /// A pattern could not be generated.
    #[error(transparent)]
    Generate(#[from] crate::generate::GenerateError),
    /// A sampling plan could not be read or used.
    #[error(transparent)]
    Plan(#[from] crate::sample::plan::PlanError),
    /// A material file could not be read or used.
    #[error(transparent)]
    Material(#[from] crate::material::json::MaterialError),
    /// A cloth scene failed.
    #[error(transparent)]
    Shell(#[from] crate::shell::ShellError),
    /// Sampling failed.
    #[error(transparent)]
    Sample(#[from] crate::sample::SampleError),
    /// The reference state (C1) of a pattern failed.
    #[error("{pattern}: reference state: {source}")]
    Reference {
        /// the pattern's name
        pattern: String,
        /// the reference state's error
        source: crate::micro::reference::ReferenceError,
    },
    /// The fit (C5) of a sample file failed.
    #[error("{}: {source}", samples.display())]
    Fit {
        /// the sample file
        samples: PathBuf,
        /// the fit's error
        source: crate::fit::FitError,
    },
    /// Bad input to a workflow, with the argument or file at fault.
    #[error("{0}")]
    Input(String),
    /// A gradient asked for where none exists (an unconverged state).
    #[error("{0}")]
    NoGradient(String),
}

impl WorkflowError {
    /// An I/O error on `path` while doing `action` ("cannot read", "cannot write", …).
    pub fn io(path: &Path, action: &'static str, source: std::io::Error) -> Self {
        WorkflowError::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    }
}

/// Write `text` to `path`, naming the file on failure.
pub(crate) fn write_file(path: &Path, text: impl AsRef<[u8]>) -> Result<(), WorkflowError> {
    std::fs::write(path, text).map_err(|e| WorkflowError::io(path, "cannot write", e))
}
