//! hylc — homogenized yarn-level cloth.
//!
//! Stages follow the data flow of `../shared/design/01-architecture.md`: the derivative harness ([`diff`]) and the
//! spline material ψ(z) ([`material`]) come first; the yarn model, micro solver, fitting and cloth solver build on
//! them.

pub mod contact;
pub mod diff;
pub mod fit;
pub mod material;
pub mod micro;
pub mod pattern;
pub mod rod;
pub mod sample;
pub mod shell;
pub mod tile;
pub mod validate;

use std::path::PathBuf;

/// The folder with the original data and conformance vectors (`shared/` beside the checkout), if present:
/// `$HYLC_SHARED`, else `../shared` from the working directory, else `../shared` from the crate's source folder.
/// Tests and validation skip with a message when it is absent; the project's defaults never need it.
pub fn shared_dir() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("HYLC_SHARED").map(PathBuf::from),
        Some(PathBuf::from("../shared")),
        Some(PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared"
        ))),
    ];
    candidates.into_iter().flatten().find(|p| {
        p.join("design").is_dir() || p.join("data").is_dir() || p.join("oracles").is_dir()
    })
}
