//! Sampling runs (`docs/sampling.md`: resume, shards): a run resumed after its
//! sample file was cut mid-line, or after the CLI was killed with SIGKILL, writes the same records as an
//! uninterrupted run (Ψ̄ and stresses bitwise); shards merged equal the unsharded run.

mod common;

use common::cli_error;
use common::sampling::{self, by_id, problem, run, tiny_plan};
use hylc::generate::default_pattern;
use hylc::micro::{MicroProblem, SolverOptions};
use hylc::rod::YarnMaterial;
use hylc::sample::{
    merge, read_samples, run_plan, run_plan_with, Plan, Record, RunOptions, SampleStart,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn dir(name: &str) -> PathBuf {
    sampling::dir("sample", name)
}

fn assert_same(a: &BTreeMap<String, Record>, b: &BTreeMap<String, Record>) {
    assert_eq!(a.len(), b.len());
    for (id, r) in a {
        let s = &b[id];
        // Ψ̄ bitwise (PartialEq on f64 is exact; compare bits to be explicit)
        assert_eq!(r.psi.map(f64::to_bits), s.psi.map(f64::to_bits), "{id}");
        assert_eq!(r, s, "{id}");
    }
}

#[test]
fn resume_after_truncation_writes_the_same_records() {
    let d = dir("resume");
    let problem = problem();
    let plan = tiny_plan();
    let full = run(
        &problem,
        &plan,
        &d.join("full.jsonl"),
        RunOptions::default(),
    );
    assert_eq!(full.len(), plan.len());
    assert!(
        full.values().all(|r| r.psi.is_some()),
        "the tiny plan converges everywhere"
    );
    assert!(full.values().any(|r| r.start == SampleStart::Predicted));

    // cut the file in the middle of a line, then resume
    let text = std::fs::read(d.join("full.jsonl")).expect("read");
    let cut = d.join("cut.jsonl");
    std::fs::write(&cut, &text[..text.len() / 2 + 7]).expect("write");
    let before = read_samples(&cut, false).expect("read").len();
    assert!(before > 0 && before < plan.len());
    let s = run_plan(&problem, &plan, &cut, &RunOptions::default()).expect("resume");
    assert_eq!(s.already_done, before);
    assert_eq!(s.written, plan.len() - before);
    let resumed = by_id(read_samples(&cut, false).expect("read"));
    assert_same(&full, &resumed);
    assert_eq!(
        read_samples(&cut, false).unwrap().len(),
        plan.len(),
        "no duplicates"
    );

    // a finished file is left alone
    let s = run_plan(&problem, &plan, &cut, &RunOptions::default()).expect("again");
    assert_eq!((s.written, s.replayed), (0, 0));

    // --limit writes that many, and the rest follows on resume
    let lim = d.join("limit.jsonl");
    let opts = RunOptions {
        limit: Some(5),
        ..Default::default()
    };
    let calls = std::sync::Mutex::new(Vec::new());
    let progress = |done: usize, todo: usize| calls.lock().unwrap().push((done, todo));
    let s = run_plan_with(&problem, &plan, &lim, &opts, &progress).unwrap();
    assert_eq!(s.written, 5);
    // progress: (0, 5) before the first solve, then each written count 1..=5 once
    let mut calls = calls.into_inner().unwrap();
    assert_eq!(calls[0], (0, 5));
    calls.sort();
    assert_eq!(calls, (0..=5).map(|n| (n, 5)).collect::<Vec<_>>());
    assert_same(&full, &run(&problem, &plan, &lim, RunOptions::default()));

    // another problem (solver settings) must not append to this file
    let other = MicroProblem::new(
        default_pattern("plain").unwrap(),
        &YarnMaterial::default(),
        SolverOptions {
            tolerance: 1e-9,
            ..Default::default()
        },
    );
    let e = run_plan(&other, &plan, &cut, &RunOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("another problem"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn merged_shards_equal_the_unsharded_run() {
    let d = dir("shards");
    let problem = problem();
    let plan = tiny_plan();
    let full = run(
        &problem,
        &plan,
        &d.join("full.jsonl"),
        RunOptions::default(),
    );
    let mut files = vec![];
    for k in 0..2 {
        let f = d.join(format!("shard{k}.jsonl"));
        let opts = RunOptions {
            shard: Some((k, 2)),
            ..Default::default()
        };
        let part = run(&problem, &plan, &f, opts);
        assert!(!part.is_empty() && part.len() < plan.len());
        files.push(f);
    }
    // a shard given twice is de-duplicated
    let m = d.join("merged.jsonl");
    let ins: Vec<&Path> = vec![&files[0], &files[1], &files[0]];
    let (n, dup) = merge(&m, &ins).expect("merge");
    assert_eq!(n, plan.len());
    assert!(dup > 0);
    let merged = by_id(read_samples(&m, false).expect("read"));
    assert_same(&full, &merged);
    // merged files are ordered by plan index
    let idx: Vec<usize> = read_samples(&m, false)
        .unwrap()
        .iter()
        .map(|r| r.index)
        .collect();
    assert!(idx.windows(2).all(|w| w[0] < w[1]));
    // a shard whose record has another result for the same id is refused, naming the id
    let text = std::fs::read_to_string(&files[0]).unwrap();
    let mut first: Record = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    first.psi = first.psi.map(|p| p * 2.0 + 1.0);
    let conflict = d.join("conflict.jsonl");
    std::fs::write(&conflict, serde_json::to_string(&first).unwrap() + "\n").unwrap();
    let e = merge(
        &d.join("m2.jsonl"),
        &[files[0].as_path(), conflict.as_path()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("conflict.jsonl") && e.contains(&first.id), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn cold_start_solves_every_sample_from_the_reference_state() {
    let d = dir("cold");
    let problem = problem();
    let plan = tiny_plan();
    let opts = RunOptions {
        cold: true,
        ..Default::default()
    };
    let cold = run(&problem, &plan, &d.join("cold.jsonl"), opts);
    assert_eq!(cold.len(), plan.len());
    assert!(cold.values().all(|r| r.start == SampleStart::Cold));
    std::fs::remove_dir_all(&d).ok();
}

#[cfg(unix)]
#[test]
fn cli_killed_with_sigkill_resumes_to_the_same_records() {
    let d = dir("sigkill");
    // all nine pairs, ranges narrowed so that every solve is quick (compression with bending at the default
    // extremes takes thousands of Newton steps on `plain`)
    let mut plan = Plan::reduced();
    plan.count_1d = 10;
    plan.count_2d = 5;
    plan.ranges.s_x = [-0.3, 0.5];
    plan.ranges.s_y = [-0.3, 0.5];
    plan.ranges.s_a = [-0.4, 0.4];
    plan.ranges.ii00 = [-80.0, 80.0];
    plan.ranges.ii11 = [-80.0, 80.0];
    let plan_file = d.join("plan.json");
    std::fs::write(&plan_file, serde_json::to_string(&plan).unwrap()).unwrap();
    let out = d.join("s.jsonl");
    let exe = env!("CARGO_BIN_EXE_hylc");
    let args = |out: &Path| {
        vec![
            "sample".to_string(),
            "plain".into(),
            "--plan".into(),
            plan_file.display().to_string(),
            "--out".into(),
            out.display().to_string(),
        ]
    };
    let mut child = Command::new(exe)
        .args(args(&out))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("spawn hylc");
    let t0 = Instant::now();
    loop {
        let lines = std::fs::read(&out)
            .map(|t| t.iter().filter(|&&b| b == b'\n').count())
            .unwrap_or(0);
        if lines >= 10 || t0.elapsed() > Duration::from_secs(60) {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().expect("SIGKILL");
    child.wait().expect("wait");
    // every complete line is a record, at most the last one is cut
    let killed = read_samples(&out, false).expect("readable after the kill");
    assert!(!killed.is_empty());
    assert!(
        killed.len() < plan.len(),
        "the run finished before the kill; make the plan larger"
    );
    let status = Command::new(exe).args(args(&out)).output().expect("resume");
    // exit 0, or 3 when some sample did not converge
    assert!(
        matches!(status.status.code(), Some(0 | 3)),
        "{:?}: {}",
        status.status,
        String::from_utf8_lossy(&status.stderr)
    );
    let resumed = by_id(read_samples(&out, false).expect("read"));
    assert_eq!(read_samples(&out, false).unwrap().len(), plan.len());
    let full = run(
        &problem(),
        &plan,
        &d.join("full.jsonl"),
        RunOptions::default(),
    );
    assert_same(&full, &resumed);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn cli_plan_files_and_bad_input() {
    let d = dir("cli");
    let exe = env!("CARGO_BIN_EXE_hylc");
    // `hylc plan --write` writes plans that load back to the same plan (same hash, so the same ids)
    for (flag, plan) in [
        (None, Plan::default()),
        (Some("--reduced"), Plan::reduced()),
    ] {
        let f = d.join("plan.json");
        let mut args = vec![
            "plan".to_string(),
            "--write".into(),
            f.display().to_string(),
        ];
        args.extend(flag.map(String::from));
        let out = Command::new(exe).args(&args).output().expect("run");
        assert!(out.status.success());
        let loaded = Plan::load(&f).expect("load");
        assert_eq!(loaded, plan);
        assert_eq!(loaded.hash(), plan.hash());
    }
    // a bad plan file: one line naming the file and the field
    let bad = d.join("bad.json");
    std::fs::write(&bad, r#"{"ranges":{},"count_1d":3}"#).unwrap();
    let out_file = d.join("x.jsonl");
    let (b, o) = (bad.display().to_string(), out_file.display().to_string());
    let err = cli_error(&["sample", "plain", "--plan", &b, "--out", &o]);
    assert!(
        err.contains("bad.json") && err.contains("ranges.s_x"),
        "{err}"
    );
    let err = cli_error(&[
        "sample", "plain", "--plan", "reduced", "--out", &o, "--shard", "2/2",
    ]);
    assert!(err.contains("--shard"), "{err}");
    let err = cli_error(&[
        "sample",
        "no-such-pattern",
        "--plan",
        "reduced",
        "--out",
        &o,
    ]);
    assert!(err.contains("no-such-pattern"), "{err}");
    // a sample file that is not a sample file is not appended to
    std::fs::write(&out_file, "hello\n").unwrap();
    let err = cli_error(&["sample", "plain", "--plan", "reduced", "--out", &o]);
    assert!(err.contains("x.jsonl:1"), "{err}");
    let err = cli_error(&["merge", &d.join("m.jsonl").display().to_string()]);
    assert!(err.contains("no input"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}
