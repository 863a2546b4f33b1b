//! The micro solver's command line on bad input and on non-converged solves (`docs/robustness.md`): strains
//! outside the admissible set give a one-line error naming the component; a solve stopped early is reported with
//! its status and a non-zero exit code, and no Ψ̄.

mod common;

use common::{cli_error, cli_ok};
use std::process::Command;

#[test]
fn inadmissible_strains_are_rejected_with_the_component_named() {
    for (z, needle) in [
        ("0,1,0", "s_a"),
        ("0,-1.2,0", "s_a"),
        ("-1,0,0", "1 + s_x"),
        ("0,0,-2", "1 + s_y"),
        ("0,0,0,10,20", "both"),
        ("0,0,nan", "s_y"),
        ("0,0", "expected 3"),
        ("0,x,0", "cannot parse"),
    ] {
        let err = cli_error(&["solve", "plain", "--z", z]);
        assert!(err.contains(needle), "--z {z}: {err}");
    }
}

#[test]
fn unknown_patterns_and_missing_construction_are_named() {
    let err = cli_error(&["solve", "no-such-pattern"]);
    assert!(err.contains("no-such-pattern"), "{err}");
    let dir = std::env::temp_dir().join("hylc_micro_cli");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("plain.pyp");
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["generate", "plain", "--out", file.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success());
    let out_pyp = dir.join("ref.pyp");
    let err = cli_error(&[
        "reference",
        file.to_str().unwrap(),
        "--out",
        out_pyp.to_str().unwrap(),
    ]);
    assert!(err.contains("--construction"), "{err}");
}

#[test]
fn a_solve_stopped_early_is_reported_and_has_no_psi() {
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args([
            "solve",
            "plain",
            "--z",
            "0.3,0.4,0.1",
            "--max-steps",
            "1",
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3), "{out:?}");
    let line = String::from_utf8(out.stdout).unwrap();
    let v: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    assert_eq!(v["status"], "MaxSteps");
    assert!(v["psi"].is_null());
    assert_eq!(v["steps"], 1);
}

#[test]
fn a_time_limit_is_reported_as_such() {
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args([
            "solve",
            "plain",
            "--z",
            "0.3,0.4,0.1",
            "--time-limit",
            "0",
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3), "{out:?}");
    let v: serde_json::Value =
        serde_json::from_str(String::from_utf8(out.stdout).unwrap().trim()).unwrap();
    assert_eq!(v["status"], "TimeLimit");
    assert!(v["psi"].is_null());
}

#[test]
fn reference_writes_a_pattern_that_loads_and_is_an_equilibrium() {
    let dir = std::env::temp_dir().join("hylc_micro_cli_ref");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("plain_ref.pyp");
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["reference", "plain", "--out", file.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let (p, warnings) = hylc::pattern::Pattern::load_pyp(&file).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    // solving the written reference at zero strain stays put (0–1 Newton steps)
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["solve", file.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    let v: serde_json::Value =
        serde_json::from_str(String::from_utf8(out.stdout).unwrap().trim()).unwrap();
    assert_eq!(v["status"], "Converged");
    assert!(v["steps"].as_u64().unwrap() <= 1, "{v}");
    assert_eq!(p.len(), 40);
}

/// `solve --quadrature` changes the contact integral (and so Ψ̄ of a pattern in contact), and 0 points is a
/// one-line error.
#[test]
fn solve_quadrature_changes_the_contact_integral() {
    let err = cli_error(&["solve", "plain", "--quadrature", "0"]);
    assert!(err.contains("--quadrature"), "{err}");
    let psi = |q: &str| -> f64 {
        let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
            .args([
                "solve",
                "plain",
                "--json",
                "--z",
                "0.05,0,0",
                "--quadrature",
                q,
            ])
            .output()
            .unwrap();
        assert!(out.status.success());
        let line = String::from_utf8_lossy(&out.stdout)
            .lines()
            .next()
            .unwrap()
            .to_string();
        serde_json::from_str::<serde_json::Value>(&line).unwrap()["psi"]
            .as_f64()
            .unwrap()
    };
    let (p1, p8) = (psi("1"), psi("8"));
    assert!(p1.is_finite() && p8.is_finite());
    assert!((p1 - p8).abs() > 1e-9 * p8.abs(), "{p1} vs {p8}");
}

/// The flags of the retired micro-solver rules (`docs/notes/retired-micro-solver-rules.md`) are gone from every
/// command that solves (one line naming the flag), and a sample file's settings say their version and the step
/// rule.
#[test]
fn retired_flags_are_refused_and_settings_carry_their_version() {
    for flag in [
        "--step-factor",
        "--projected-steps",
        "--keep-shift",
        "--psd-stencils",
        "--exact-backoff",
        "--interpolating-search",
        "--trust-region",
    ] {
        for cmd in ["solve", "sample", "micro-grid", "identify"] {
            let err = cli_error(&[cmd, "plain", flag]);
            assert!(err.contains(flag), "{cmd} {flag}: {err}");
        }
    }
    let err = cli_error(&["solve", "plain", "--backtracking", "0.5"]);
    assert!(err.contains("--backtracking"), "{err}");
    let err = cli_error(&["sample", "plain", "--predictor", "tangent"]);
    assert!(err.contains("tangent"), "{err}");
    let dir = std::env::temp_dir().join("hylc_micro_cli_settings_version");
    std::fs::create_dir_all(&dir).unwrap();
    let plan = dir.join("plan.json");
    let mut p = hylc::sample::Plan::reduced();
    p.count_1d = 0;
    p.counts_1d = Some([2, 0, 0, 0, 0]);
    p.count_2d = 0;
    p.pairs = vec![];
    std::fs::write(&plan, p.canonical_json()).unwrap();
    let settings = |extra: &[&str]| -> serde_json::Value {
        let out_file = dir.join(format!("s{}.jsonl", extra.len()));
        std::fs::remove_file(&out_file).ok();
        let mut args = vec![
            "sample",
            "plain",
            "--plan",
            plan.to_str().unwrap(),
            "--out",
            out_file.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        cli_ok(&args);
        let meta = out_file.with_extension("meta.json");
        serde_json::from_str(&std::fs::read_to_string(meta).unwrap()).unwrap()
    };
    let (default, design) = (settings(&[]), settings(&["--no-inertia"]));
    assert_eq!(default["solver"]["version"].as_u64(), Some(2));
    assert_eq!(default["solver"]["step_rule"].as_str(), Some("inertia"));
    assert_eq!(design["solver"]["step_rule"].as_str(), Some("shift"));
    assert!(default["solver"].get("step_factor").is_none());
    assert_ne!(default["problem"], design["problem"]);
    std::fs::remove_dir_all(&dir).ok();
}
