//! The solver settings as files (`hylc::micro::options`): the `version` key, the reading of version-1 settings
//! (written before that key, with the options of the retired micro-solver rules and `inertia` written only while
//! on), the frozen problem hash, and sample files made by hylc before the version key, which still load and
//! resume (`tests/data/v1_sample_files`: the generated plain weave on a 20-sample plan, written by `hylc sample`
//! at commit 37dc6f9 with the defaults and with `--no-inertia`).

use hylc::generate::default_pattern;
use hylc::micro::{CrossingGuard, MicroProblem, SolverOptions, StepRule, SETTINGS_VERSION};
use hylc::sample::run::problem_hash;
use hylc::sample::{read_samples, run_plan, Plan, Record, RunOptions};
use hylc::workflow::sidecar::{read_meta, recorded_yarn};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The version-1 settings text of the design rule (`--no-inertia`) with the defaults, as hylc wrote it before the
/// version key (`hylc sample` sidecars, and the problem hash's text); `EXTRA` before `"trace"`.
fn v1_text(extra: &str) -> String {
    format!(
        "{{\"tolerance\":1e-8,\"decrement_tolerance\":1e-14,\"max_steps\":2000,\"time_limit\":null,\
         \"step_factor\":1.0,\"slide_constraints\":true,\"backtracking\":0.1,\"contact_margin\":{:?},\
         {extra}\"trace\":false}}",
        SolverOptions::default().contact_margin
    )
}

fn shift() -> SolverOptions {
    SolverOptions {
        step_rule: StepRule::Shift,
        ..Default::default()
    }
}

/// The problem hash reads the settings in their version-1 form, unchanged: the text of the defaults, of the shift
/// rule and of the crossing guard is byte for byte what hylc hashed before the version key.
#[test]
fn the_hash_text_is_the_version_1_form() {
    assert_eq!(
        SolverOptions::default().hash_text(),
        v1_text("\"inertia\":true,")
    );
    assert_eq!(shift().hash_text(), v1_text(""));
    let reject = SolverOptions {
        crossings: CrossingGuard::Reject,
        ..Default::default()
    };
    assert_eq!(
        reject.hash_text(),
        v1_text("\"crossings\":\"reject\",\"inertia\":true,")
    );
}

/// Settings are written with the version key and every key, and read back; a key left out of a version-2 object
/// reads as its default (the inertia rule included), and an unknown version or key is refused.
#[test]
fn version_2_settings_round_trip_and_default_missing_keys() {
    for o in [SolverOptions::default(), shift()] {
        let text = serde_json::to_string(&o).unwrap();
        assert!(
            text.starts_with(&format!("{{\"version\":{SETTINGS_VERSION},")),
            "{text}"
        );
        assert_eq!(serde_json::from_str::<SolverOptions>(&text).unwrap(), o);
    }
    let text = serde_json::to_string(&shift()).unwrap();
    assert!(text.contains("\"step_rule\":\"shift\""), "{text}");
    let minimal: SolverOptions = serde_json::from_str("{\"version\":2}").unwrap();
    assert_eq!(minimal, SolverOptions::default());
    let e = serde_json::from_str::<SolverOptions>("{\"version\":3}").unwrap_err();
    assert!(e.to_string().contains("version 3"), "{e}");
    let e =
        serde_json::from_str::<SolverOptions>("{\"version\":2,\"step_factor\":1.0}").unwrap_err();
    assert!(e.to_string().contains("step_factor"), "{e}");
}

/// A version-1 object (no `version`) reads as it was meant: `"inertia":true` is the default rule, a missing
/// `inertia` the design rule (what every file made before the inertia rule meant); the keys of the retired rules
/// load at their default values (as written, or as an old file could carry them) and are refused otherwise,
/// naming the key.
#[test]
fn version_1_settings_load_as_they_were_meant() {
    let read = |text: &str| serde_json::from_str::<SolverOptions>(text);
    assert_eq!(
        read(&v1_text("\"inertia\":true,")).unwrap(),
        SolverOptions::default()
    );
    assert_eq!(read(&v1_text("")).unwrap(), shift());
    assert_eq!(read("{}").unwrap(), shift());
    let all_default = v1_text(
        "\"projected_steps\":false,\"keep_shift\":false,\"psd_stencils\":\"off\",\"crossings\":\"count\",\
         \"trust_region\":false,\"inertia\":true,\"exact_backoff\":false,\"interpolating_search\":false,",
    );
    assert_eq!(
        read(&all_default).unwrap(),
        SolverOptions {
            crossings: CrossingGuard::Count,
            ..Default::default()
        }
    );
    for (key, value) in [
        ("projected_steps", "true"),
        ("keep_shift", "true"),
        ("psd_stencils", "\"fallback\""),
        ("trust_region", "true"),
        ("exact_backoff", "true"),
        ("interpolating_search", "true"),
    ] {
        let e = read(&v1_text(&format!("\"{key}\":{value},"))).unwrap_err();
        assert!(e.to_string().contains(key), "{key}: {e}");
    }
    let e = read(&v1_text("").replace("\"step_factor\":1.0", "\"step_factor\":3.0")).unwrap_err();
    assert!(e.to_string().contains("step_factor"), "{e}");
    let e = read(&v1_text("").replace("\"backtracking\":0.1", "\"backtracking\":0.5")).unwrap_err();
    assert!(e.to_string().contains("backtracking"), "{e}");
}

/// The fixture's files, the first `keep` records of `name`.jsonl (an interrupted run) with its sidecar, copied to
/// a fresh folder; the copy's path.
fn interrupted_copy(name: &str, keep: usize) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/v1_sample_files");
    let d = std::env::temp_dir().join(format!("hylc-settings-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let text = std::fs::read_to_string(src.join(format!("{name}.jsonl"))).unwrap();
    let head: String = text.lines().take(keep).map(|l| format!("{l}\n")).collect();
    std::fs::write(d.join(format!("{name}.jsonl")), head).unwrap();
    std::fs::copy(
        src.join(format!("{name}.meta.json")),
        d.join(format!("{name}.meta.json")),
    )
    .unwrap();
    d.join(format!("{name}.jsonl"))
}

/// The records by id with the wall time zeroed.
fn by_id(records: Vec<Record>) -> BTreeMap<String, Record> {
    records
        .into_iter()
        .map(|mut r| {
            r.time = 0.0;
            (r.id.clone(), r)
        })
        .collect()
}

/// Sample files made before the version key (version-1 sidecars: the defaults with `"inertia":true`, and the
/// design rule without an `inertia` key) load and resume: the settings read from the sidecar are the rule the
/// file was made with, their problem hash is the records' hash, and the resumed run writes the remaining records
/// exactly as the old version wrote them (Ψ̄, stress, steps, starts; the wall time aside).
#[test]
fn sample_files_made_before_the_version_key_load_and_resume() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/v1_sample_files");
    let plan = Plan::from_json(
        &std::fs::read_to_string(fixture.join("plan.json")).unwrap(),
        None,
    )
    .unwrap();
    for (name, rule) in [("default", StepRule::Inertia), ("design", StepRule::Shift)] {
        let out = interrupted_copy(name, 7);
        let meta = read_meta(&out).unwrap().expect("sidecar");
        let options: SolverOptions = serde_json::from_value(meta["solver"].clone()).unwrap();
        assert_eq!(options.step_rule, rule, "{name}");
        let yarn = recorded_yarn(&out, &meta).unwrap().expect("yarn");
        let problem = MicroProblem::new(default_pattern("plain").unwrap(), &yarn, options);
        assert_eq!(
            problem_hash(&problem),
            meta["problem"].as_str().unwrap(),
            "{name}"
        );
        let summary = run_plan(&problem, &plan, &out, &RunOptions::default()).unwrap();
        assert_eq!((summary.already_done, summary.written), (7, 13), "{name}");
        let resumed = by_id(read_samples(&out, false).unwrap());
        let old = by_id(read_samples(&fixture.join(format!("{name}.jsonl")), false).unwrap());
        assert_eq!(resumed, old, "{name}");
        std::fs::remove_dir_all(out.parent().unwrap()).ok();
    }
}
