//! Helpers shared by the sampling tests (`tests/sample.rs`, `tests/sample_starts.rs`): a tiny plan on the
//! generated plain weave, run into a file and read back by id.

use hylc::generate::default_pattern;
use hylc::micro::{MicroProblem, SolverOptions};
use hylc::rod::YarnMaterial;
use hylc::sample::{merge, read_samples, run_plan, Plan, Record, RunOptions};
use hylc::strain::StrainComponent::{Sa, Sx, Sy, II00};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The generated plain weave with the default yarn and solver.
pub fn problem() -> MicroProblem {
    let p = default_pattern("plain").expect("plain pattern");
    MicroProblem::new(p, &YarnMaterial::default(), SolverOptions::default())
}

/// A tiny plan: 1D counts 4, 3×3 grids on two pairs (38 samples).
pub fn tiny_plan() -> Plan {
    let mut p = Plan::reduced();
    p.count_1d = 4;
    p.count_2d = 3;
    p.pairs = vec![[Sx, Sa], [Sy, II00]];
    p
}

/// An empty temporary folder `hylc-<suite>-<name>-<pid>`.
pub fn dir(suite: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hylc-{suite}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// The records by id with the wall time zeroed (the only field that may differ between runs).
pub fn by_id(records: Vec<Record>) -> BTreeMap<String, Record> {
    records
        .into_iter()
        .map(|mut r| {
            r.time = 0.0;
            (r.id.clone(), r)
        })
        .collect()
}

/// Run `plan` into `out` and read the records back by id.
pub fn run(
    problem: &MicroProblem,
    plan: &Plan,
    out: &Path,
    opts: RunOptions,
) -> BTreeMap<String, Record> {
    run_plan(problem, plan, out, &opts).expect("run");
    by_id(read_samples(out, false).expect("read"))
}

/// The records of `full` (a finished run of `plan` with `opts`) are what a run resumed after a cut in the middle
/// of a line of that file writes, and what two shards merged write (files in `d`).
pub fn assert_resumed_and_sharded_equal(
    problem: &MicroProblem,
    plan: &Plan,
    d: &Path,
    full: &Path,
    opts: &RunOptions,
) {
    let expected = by_id(read_samples(full, false).expect("read"));
    let text = std::fs::read(full).unwrap();
    let cut = d.join("cut.jsonl");
    std::fs::write(&cut, &text[..text.len() / 2 + 7]).unwrap();
    let before = read_samples(&cut, false).unwrap().len();
    assert!(before > 0 && before < plan.len());
    assert_eq!(run(problem, plan, &cut, opts.clone()), expected);
    assert_eq!(read_samples(&cut, false).unwrap().len(), plan.len());
    let files: Vec<PathBuf> = (0..2).map(|k| d.join(format!("s{k}.jsonl"))).collect();
    for (k, f) in files.iter().enumerate() {
        let shard = RunOptions {
            shard: Some((k, 2)),
            ..opts.clone()
        };
        run(problem, plan, f, shard);
    }
    let m = d.join("merged.jsonl");
    merge(&m, &[files[0].as_path(), files[1].as_path()]).unwrap();
    assert_eq!(by_id(read_samples(&m, false).unwrap()), expected);
}
