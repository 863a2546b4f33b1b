//! The fuzz suite in CI (`docs/robustness.md`, "The fuzz suite"; `hylc::validation::fuzz`): mutated `.pyp` patterns,
//! material JSON, sampling plans, scene JSON and sample files through the library's parsers and evaluators. Every case
//! must end in an accepted input with finite outputs or a typed error: no panic, no non-finite number, no case over its
//! time budget. `HYLC_FUZZ_CASES` sets the cases per format (default 600); `validation/fuzz.sh` runs 10⁶.

use hylc::validation::fuzz::{run, Format, FuzzReport};

fn cases() -> usize {
    std::env::var("HYLC_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(600)
}

fn check(format: Format) {
    let dir = std::env::temp_dir().join(format!(
        "hylc-fuzz-{}-{}",
        format.name(),
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let r: FuzzReport = run(format, cases(), 1, &dir, &mut |_| {});
    std::fs::remove_dir_all(&dir).ok();
    eprintln!("{}: {}", format.name(), r.counts());
    assert_eq!(r.failed(), 0, "{}: {:#?}", format.name(), r.failures);
    // the mutators must leave some inputs valid, or the evaluators are never reached
    assert!(r.accepted > 0, "{}: no case was accepted", format.name());
}

#[test]
fn fuzz_pyp() {
    check(Format::Pyp);
}

#[test]
fn fuzz_material() {
    check(Format::Material);
}

#[test]
fn fuzz_plan() {
    check(Format::Plan);
}

#[test]
fn fuzz_scene() {
    check(Format::Scene);
}

#[test]
fn fuzz_samples() {
    check(Format::Samples);
}
