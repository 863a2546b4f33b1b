//! The commit the crate is built from, for `hylc --version` and the provenance of outputs
//! (`hylc::provenance::COMMIT`): `git rev-parse --short=12 HEAD`, or `unknown` when git or the repository is
//! not there (a crate built from a package). Rerun when HEAD moves (a checkout or a commit).

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
}

fn main() {
    let commit = git(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=HYLC_COMMIT={commit}");
    println!("cargo:rerun-if-changed=build.rs");
    // HEAD names the branch; the branch's ref file (or packed-refs) moves with every commit
    if let Some(git_dir) = git(&["rev-parse", "--git-dir"]) {
        let dir = std::path::Path::new(&git_dir);
        println!("cargo:rerun-if-changed={}", dir.join("HEAD").display());
        if let Some(r) = git(&["symbolic-ref", "-q", "HEAD"]) {
            println!("cargo:rerun-if-changed={}", dir.join(r).display());
        }
        println!(
            "cargo:rerun-if-changed={}",
            dir.join("packed-refs").display()
        );
    }
}
