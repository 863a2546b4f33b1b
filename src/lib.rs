#![warn(missing_docs)]
//! hylc — homogenized yarn-level cloth.
//!
//! Stages follow the data flow of `docs/layout.md`. Layers import downwards only (a test,
//! `tests/layers.rs`, fails on an import against this order); each group below may use the groups above it:
//!
//! 1. foundations: [`sparse`] (lower-triangle sparse patterns of the Newton matrices), [`strain`] (strain
//!    components by name), [`real`] (the scalar type of the reference implementations, generic 3-vector
//!    operations), [`periodic`] (tile offsets, transforms and images), [`diff`] (the derivative harness);
//! 2. data: [`material`] (the spline energy density ψ(z)), [`pattern`] (yarn topology, `.pyp` files);
//! 3. yarn mechanics: [`rod`], [`contact`], [`tile`], [`micro`];
//! 4. homogenization: [`sample`], [`fit`];
//! 5. cloth: [`shell`];
//! 6. on top: [`generate`] (pattern generators), [`workflow`] (the stages put together as the command line runs
//!    them, up to the main job), [`validation`] (verification against the original data: conformance, calibration, the micro grid), [`checks`] (every energy
//!    registered with the harness).

// 1. foundations
pub mod diff;
pub mod periodic;
pub mod provenance;
pub mod real;
pub mod sparse;
pub mod strain;
// 2. data
pub mod material;
pub mod pattern;
// 3. yarn mechanics
pub mod contact;
pub mod micro;
pub mod rod;
pub mod tile;
// 4. homogenization
pub mod fit;
pub mod sample;
// 5. cloth
pub mod shell;
// 6. on top
pub mod checks;
pub mod generate;
pub mod validation;
pub mod workflow;

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
