//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

pub mod sampling;

/// `../shared`, or `None` after printing why the calling test skips.
pub fn shared_or_skip(test: &str) -> Option<PathBuf> {
    match hylc::shared_dir() {
        Some(p) => Some(p),
        None => {
            eprintln!("SKIPPED {test}: ../shared (original data and oracles) not found; set HYLC_SHARED to run it");
            None
        }
    }
}

/// Run the `hylc` binary with `args` and assert that it succeeds (stderr in the failure message).
pub fn cli_ok(args: &[&str]) -> std::process::Output {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "hylc {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Run the `hylc` binary with `args`, assert that it fails with exit code 2 and a one-line message, and return
/// that message (stderr).
pub fn cli_error(args: &[&str]) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

/// A built-in scene on a coarse rectangle mesh of edge `edge` (m), simulated for `duration` (s).
pub fn coarse_builtin(name: &str, edge: f64, duration: f64) -> hylc::shell::scene::Scene {
    let mut s = hylc::shell::scene::builtin(name).unwrap();
    s.mesh = hylc::shell::scene::MeshSpec::Rectangle {
        width: hylc::shell::scene::SIDE,
        height: hylc::shell::scene::SIDE,
        edge,
        perturb: 0.0,
        seed: 1,
    };
    s.duration = duration;
    s
}
