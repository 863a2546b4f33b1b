//! The main job end to end (`hylc run`; `docs/pipeline.md`, "`hylc run`") on a small configuration: the
//! plain weave, a 7-per-range / 5×5 plan, a 3 cm mesh and 0.05 s of drape. Every stage writes its outputs, the
//! material loads and is ψ(0)-consistent with the fit report, the summary names the stages, and a rerun resumes
//! (no sample solved twice, the reference state reused). Also `scene-plan` on the run's strain log.

mod common;

use hylc::material::Material;
use hylc::sample::Plan;
use hylc::workflow::pipeline::{self, RunConfig};
use hylc::workflow::Event;
use std::path::PathBuf;
use std::process::Command;

fn hylc(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .expect("run hylc");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

#[test]
fn run_writes_every_stage_and_resumes() {
    let dir = std::env::temp_dir().join(format!("hylc-run-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let plan = dir.join("small.json");
    let mut p = Plan::reduced();
    p.count_1d = 7;
    p.count_2d = 5;
    std::fs::write(&plan, serde_json::to_string(&p).unwrap()).unwrap();
    let out = dir.join("out");
    let args = [
        "run",
        "--pattern",
        "plain",
        "--plan",
        plan.to_str().unwrap(),
        "--edge",
        "0.03",
        "--duration",
        "0.05",
        "--dt",
        "0.0125",
        "--out",
        out.to_str().unwrap(),
    ];
    let (ok, stdout, stderr) = hylc(&args);
    assert!(ok, "{stdout}\n{stderr}");
    let d = out.join("plain");
    for f in [
        "pattern.pyp",
        "reference.pyp",
        "reference.json",
        "samples.jsonl",
        "samples.meta.json",
        "holdout.jsonl",
        "material.json",
        "fit.json",
        "plots/1d_s_x.png",
        "plots/2d_s_x_s_a.png",
        "simulate/log.jsonl",
        "simulate/frame_0000.obj",
        "simulate/frame_0004.obj",
        "snapshot.png",
    ] {
        assert!(d.join(f).exists(), "{f} missing");
    }
    assert!(out.join("run.log").exists() && out.join("summary.json").exists());
    // the material is the fit's: ψ(0) = f₀ of the report
    let m = Material::load(&d.join("material.json")).unwrap();
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("fit.json")).unwrap()).unwrap();
    let f0 = rep["constant"].as_f64().unwrap();
    assert!((m.eval(&[0.0; 6]).value - f0).abs() <= 1e-12 * f0.abs());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let ps = &s["patterns"]["plain"];
    let n = 5 * 7 + 9 * 25;
    assert_eq!(ps["samples"]["selected"], n);
    assert_eq!(ps["samples"]["written"], n);
    assert_eq!(ps["simulate"]["steps"], 4);
    for stage in ["generate", "reference", "sample", "fit", "simulate"] {
        assert!(ps["stages"][stage].as_f64().unwrap() >= 0.0, "{stage}");
    }
    assert!(ps["fit"]["holdout_rms_rel"].as_f64().unwrap().is_finite());
    assert!(
        stdout.contains("summary (wall time per stage, s):"),
        "{stdout}"
    );

    // a rerun resumes: the reference is reused and no sample is solved again
    let (ok, stdout, stderr) = hylc(&args);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("reference: reused"), "{stdout}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let ps = &s["patterns"]["plain"];
    assert_eq!(ps["samples"]["already_done"], n);
    assert_eq!(ps["samples"]["written"], 0);

    // the same job through the library: every log line reaches the callback and run.log, the drape reports each
    // step once, in order, and the summary is the one written to summary.json
    let log_before = std::fs::read_to_string(out.join("run.log")).unwrap();
    let config = RunConfig {
        out: out.clone(),
        patterns: vec!["plain".into()],
        plan: plan.to_str().unwrap().into(),
        edge: Some(0.03),
        duration: Some(0.05),
        dt: 0.0125,
        ..RunConfig::default()
    };
    let (mut lines, mut steps, mut samples) = (Vec::new(), Vec::new(), Vec::new());
    let summary = pipeline::run(&config, &mut |e| match e {
        Event::Log(l) => lines.push(l.to_string()),
        Event::Step { done, total, .. } => steps.push((done, total)),
        Event::Samples { done, todo } => samples.push((done, todo)),
        Event::Print(_) | Event::Note(_) => {}
    })
    .unwrap();
    // nothing left to sample: the plan and the held-out grid each report (0 of 0) once
    assert_eq!(samples, vec![(0, 0), (0, 0)]);
    let log_after = std::fs::read_to_string(out.join("run.log")).unwrap();
    assert_eq!(
        log_after.strip_prefix(log_before.as_str()).unwrap(),
        lines.iter().map(|l| format!("{l}\n")).collect::<String>()
    );
    assert!(lines.iter().any(|l| l.starts_with("reference: reused")));
    assert_eq!(steps, vec![(1, 4), (2, 4), (3, 4), (4, 4)]);
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary, written);
    assert_eq!(summary["patterns"]["plain"]["samples"]["written"], 0);

    // a sample file solved for another problem (an earlier version's settings) is set aside, not resumed: here
    // the held-out grid's records carry another problem hash; the rerun moves the file beside it and solves it
    let holdout = d.join("holdout.jsonl");
    let text = std::fs::read_to_string(&holdout).unwrap();
    let hash = text.split("\"problem\":\"").nth(1).unwrap()[..16].to_string();
    std::fs::write(&holdout, text.replace(&hash, "0123456789abcdef")).unwrap();
    let (ok, stdout, stderr) = hylc(&args);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout.contains("was solved for another problem"),
        "{stdout}"
    );
    assert!(d.join("holdout.0123456789abcdef.jsonl").exists());
    assert!(d.join("holdout.0123456789abcdef.meta.json").exists());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["patterns"]["plain"]["samples"]["written"], 0);
    assert_eq!(s["patterns"]["plain"]["samples"]["holdout"], 27);
    assert_eq!(
        std::fs::read_to_string(&holdout).unwrap().lines().count(),
        27
    );
    assert!(!std::fs::read_to_string(&holdout)
        .unwrap()
        .contains("0123456789abcdef"));

    // another plan (3 × 3 grids): the sample file of the first plan is set aside the same way
    let plan2 = dir.join("smaller.json");
    let mut p2 = p.clone();
    p2.count_2d = 3;
    std::fs::write(&plan2, serde_json::to_string(&p2).unwrap()).unwrap();
    let mut args2 = args;
    args2[4] = plan2.to_str().unwrap();
    let (ok, stdout, stderr) = hylc(&args2);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("was solved for another plan"), "{stdout}");
    let first = format!("samples.{:016x}.jsonl", p.hash());
    assert!(d.join(&first).exists(), "{first} missing");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["patterns"]["plain"]["samples"]["written"], 5 * 7 + 9 * 9);

    // scene-driven sampling from the drape's strain log: a valid plan, smaller than the default one
    let sp = dir.join("scene_plan.json");
    let log = d.join("simulate/log.jsonl");
    let (ok, stdout, stderr) = hylc(&[
        "scene-plan",
        log.to_str().unwrap(),
        "--write",
        sp.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let plan = Plan::load(&sp).unwrap();
    assert!(plan.len() < Plan::default().len());
    assert!(
        stdout.contains("fewer solves than the base plan"),
        "{stdout}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn run_and_scene_plan_reject_bad_input_with_one_line() {
    let e = common::cli_error(&["run", "--pattern", "hexagon", "--out", "/tmp/hylc-run-bad"]);
    assert!(e.contains("hexagon"), "{e}");
    let missing = PathBuf::from("/nonexistent/log.jsonl");
    let e = common::cli_error(&[
        "scene-plan",
        missing.to_str().unwrap(),
        "--write",
        "/tmp/x.json",
    ]);
    assert!(e.contains("/nonexistent/log.jsonl: cannot read"), "{e}");
}

/// A misspelt plan, scene or pattern stops `hylc run` before anything is computed or written (exit 2, the valid
/// names in the message; before these checks a misspelt scene failed after 50 s of sampling).
#[test]
fn run_checks_its_inputs_before_computing() {
    let out = std::env::temp_dir().join(format!("hylc-run-check-{}", std::process::id()));
    for (flag, value, want) in [
        (
            "--plan",
            "fast",
            "fast: not a plan (default, reduced, quick, holdout)",
        ),
        (
            "--scene",
            "drap-x",
            "drap-x: no such scene file and not a built-in scene (stretch-x,",
        ),
        ("--pattern", "stockinete", "stockinete"),
    ] {
        let e = common::cli_error(&["run", flag, value, "--out", out.to_str().unwrap()]);
        assert!(e.contains(want), "{flag} {value}: {e}");
        // nothing written: the output folder is made before the first stage
        assert!(!out.exists(), "{flag} {value}: wrote {}", out.display());
    }
}

/// The README's hand-run recipe (generate → reference → sample with the crossing guard → fit with the default
/// preset) makes the very material `hylc run` makes: the same bytes, when both name their files alike (run in
/// two folders with the same relative paths; `hylc run`'s held-out grid is copied beside the recipe's samples,
/// as `--holdout`).
#[test]
fn the_hand_run_recipe_makes_run_s_material_byte_for_byte() {
    let dir = std::env::temp_dir().join(format!("hylc-run-recipe-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let (a, b) = (dir.join("run"), dir.join("hand"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(b.join("out/plain")).unwrap();
    let mut p = Plan::reduced();
    p.count_1d = 5;
    p.count_2d = 3;
    let plan = dir.join("tiny.json");
    std::fs::write(&plan, serde_json::to_string(&p).unwrap()).unwrap();
    let plan = plan.to_str().unwrap();
    let hylc_in = |cwd: &PathBuf, args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
            .current_dir(cwd)
            .args(args)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stderr).to_string();
        // `sample` exits with 3 when a sample did not converge; the fit leaves it out, as `run` does
        let ok = out.status.success() || (args[0] == "sample" && out.status.code() == Some(3));
        assert!(ok, "hylc {args:?}: {:?} {text}", out.status.code());
    };
    hylc_in(
        &a,
        &[
            "run",
            "--pattern",
            "plain",
            "--plan",
            plan,
            "--edge",
            "0.05",
            "--duration",
            "0.0125",
            "--dt",
            "0.0125",
            "--out",
            "out",
        ],
    );
    for f in ["holdout.jsonl", "holdout.meta.json"] {
        std::fs::copy(a.join("out/plain").join(f), b.join("out/plain").join(f)).unwrap();
    }
    for args in [
        &["generate", "plain", "--out", "out/plain/pattern.pyp"][..],
        &[
            "reference",
            "out/plain/pattern.pyp",
            "--construction",
            "woven",
            "--out",
            "out/plain/reference.pyp",
        ],
        &[
            "sample",
            "out/plain/reference.pyp",
            "--plan",
            plan,
            "--out",
            "out/plain/samples.jsonl",
            "--crossings",
            "reject",
        ],
        &[
            "fit",
            "out/plain/samples.jsonl",
            "--out",
            "out/plain/material.json",
            "--holdout",
            "out/plain/holdout.jsonl",
            "--no-plots",
        ],
    ] {
        hylc_in(&b, args);
    }
    let read = |root: &PathBuf| std::fs::read(root.join("out/plain/material.json")).unwrap();
    let (made_by_run, made_by_hand) = (read(&a), read(&b));
    assert!(
        made_by_run == made_by_hand,
        "the materials differ:\n{}\n---\n{}",
        String::from_utf8_lossy(&made_by_run),
        String::from_utf8_lossy(&made_by_hand)
    );
    // the material records how it was fitted: the default preset's options
    let m: serde_json::Value = serde_json::from_slice(&made_by_run).unwrap();
    let fit: hylc::fit::FitOptions =
        serde_json::from_value(m["meta"]["fit options"].clone()).unwrap();
    assert_eq!(fit, hylc::fit::FitPreset::Covering.options());
    let _ = std::fs::remove_dir_all(&dir);
}
