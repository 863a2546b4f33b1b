//! What made an output: hylc's version, the commit it was built from and the command line, written beside
//! every run's outputs (`provenance.json`) and into the JSON reports.

use serde::Serialize;

/// The version of hylc.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The commit hylc was built from (`git rev-parse --short=12 HEAD` at build time; `unknown` outside a git
/// checkout). Uncommitted changes are not marked.
pub const COMMIT: &str = env!("HYLC_COMMIT");

/// The provenance record of an output.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Provenance {
    /// hylc's version ([`VERSION`])
    pub hylc: &'static str,
    /// the commit hylc was built from ([`COMMIT`])
    pub commit: &'static str,
    /// the process's command line (for the Python module: the interpreter's)
    pub command: Vec<String>,
    /// seconds since the Unix epoch when the record was made
    pub unix_time: u64,
}

impl Provenance {
    /// The record for this process now.
    pub fn now() -> Provenance {
        Provenance {
            hylc: VERSION,
            commit: COMMIT,
            command: std::env::args().collect(),
            unix_time: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
        }
    }

    /// As a JSON value.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("a provenance record serialises")
    }
}
