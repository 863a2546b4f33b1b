//! Verification and validation against the original method's data (`docs/results.md`,
//! "Validation against the original"), kept out of the numerical core: the stages below know nothing of it.
//!
//! - [`conformance`]: ψ and the strain chain against the original code's oracle vectors (item 3a);
//! - [`calibration`]: the yarn parameters that make the original reference patterns static equilibria (item 3b);
//! - [`grid`]: our micro solver against the original solver's displacements on the 9×9×9 grid (item 3c);
//! - [`identify`]: the yarn parameters from the original data by Levenberg–Marquardt with the solver's derivatives
//!   (docs/yarn-parameters.md);
//! - [`fuzz`]: mutated inputs of the five input formats through the parsers and evaluators (docs/robustness.md).
//!
//! Each reads `../shared` (the caller passes the folder or files) and returns numbers; the callers (`hylc
//! validate`, `hylc calibrate`, `hylc micro-grid`, the conformance tests) decide what passes.

pub mod calibration;
pub mod conformance;
pub mod fuzz;
pub mod grid;
pub mod identify;

use std::path::PathBuf;

/// Reading the original data failed: the file, and what is wrong with it.
#[derive(Debug, thiserror::Error)]
pub enum ValidationError {
    /// A file could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A file is not the JSON it should be.
    #[error("{}: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The parser's error.
        source: serde_json::Error,
    },
    /// The file was read but its content is not what it should be.
    #[error("{}: {message}", path.display())]
    Data {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A material file of the original data could not be used.
    #[error(transparent)]
    Material(#[from] crate::material::MaterialError),
}
