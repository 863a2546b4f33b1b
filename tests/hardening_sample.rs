//! Hardening (`docs/robustness.md`) of plans, sample files and the fit: huge counts and inadmissible ranges rejected in
//! one line (exit 2), a UTF-8 byte-order mark accepted, only `Converged` records fitted, duplicated ids with different
//! results and absurd values rejected, and the exit codes (0 complete, 2 bad input, 3 did not converge) of `sample` and
//! `fit`.

mod common;

use common::cli_error;
use hylc::fit::model::strain6;
use hylc::material::synthetic::default_material;
use hylc::material::Material;
use hylc::sample::{Plan, Record, SampleStart, SampleStatus};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hylc-hardening-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn hylc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .expect("run hylc")
}

/// The records of `plan` whose Ψ̄ is `truth`'s ψ (all converged).
fn records(plan: &Plan, truth: &Material) -> Vec<Record> {
    plan.samples()
        .into_iter()
        .map(|s| {
            let e = truth.eval(&strain6(&s.z));
            let g = e.grad;
            Record {
                id: s.id.clone(),
                index: s.index,
                z: s.z,
                psi: Some(e.value),
                stress: Some([Some(g[0]), Some(g[1]), Some(g[2]), Some(g[3]), Some(g[5])]),
                status: SampleStatus::Converged,
                error: None,
                steps: 1,
                gradient_norm: Some(0.0),
                time: 0.0,
                start: SampleStart::Cold,
                problem: "0000000000000000".into(),
                starts: vec![],
                kept: None,
                crossings: None,
                dpsi_dtheta: None,
                dstress_dtheta: None,
            }
        })
        .collect()
}

/// Write `records` as a sample file with a sidecar (the plan and a density), optionally with a byte-order mark
/// at the start of both.
fn write(path: &Path, plan: &Plan, records: &[Record], bom: bool) {
    let mark = if bom { "\u{feff}" } else { "" };
    let text: String = records
        .iter()
        .map(|r| serde_json::to_string(r).unwrap() + "\n")
        .collect();
    std::fs::write(path, format!("{mark}{text}")).unwrap();
    let meta = serde_json::json!({"pattern": "synthetic", "plan": plan, "density": 0.3});
    std::fs::write(path.with_extension("meta.json"), format!("{mark}{meta}")).unwrap();
}

fn fit(path: &Path) -> Output {
    let p = path.display().to_string();
    hylc(&["fit", &p, "--no-plots"])
}

fn report(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path.with_extension("fit.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn fit_counts_only_converged_records() {
    let d = dir("maxsteps");
    let plan = Plan::reduced();
    let truth = default_material();
    let good = records(&plan, &truth);
    // samples 5 and 200 marked MaxSteps: once with their Ψ̄ dropped, once keeping a (wrong) Ψ̄ of the last iterate
    let failed = |keep_psi: bool| -> Vec<Record> {
        let mut r = good.clone();
        for i in [5, 200] {
            r[i].status = SampleStatus::MaxSteps;
            r[i].stress = None;
            r[i].psi = if keep_psi {
                r[i].psi.map(|p| 3.0 * p + 1.0)
            } else {
                None
            };
        }
        r
    };
    let (a, b) = (d.join("a.jsonl"), d.join("b.jsonl"));
    write(&a, &plan, &failed(false), false);
    write(&b, &plan, &failed(true), false);
    for p in [&a, &b] {
        let out = fit(p);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let (ra, rb) = (report(&a), report(&b));
    assert_eq!(ra["converged"], 1050 - 2);
    assert_eq!(rb["converged"], ra["converged"]);
    assert_eq!(rb["all"], ra["all"]);
    assert_eq!(rb["terms1d"], ra["terms1d"]);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn fit_rejects_conflicting_duplicates_and_absurd_values() {
    let d = dir("records");
    let plan = Plan::reduced();
    let good = records(&plan, &default_material());
    let s = d.join("s.jsonl");
    let sp = s.display().to_string();
    // an identical duplicate is fitted once
    let mut dup = good.clone();
    dup.push(good[7].clone());
    write(&s, &plan, &dup, false);
    let out = fit(&s);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(report(&s)["samples"], 1050);
    // a duplicate with a different Ψ̄ is an error naming the file and the id
    dup.last_mut().unwrap().psi = Some(1.5);
    write(&s, &plan, &dup, false);
    let err = cli_error(&["fit", &sp, "--no-plots"]);
    assert!(
        err.contains("s.jsonl") && err.contains(&good[7].id) && err.contains("twice"),
        "{err}"
    );
    // absurd Ψ̄ or stresses: an error naming the file, the id, the field and the value
    for (psi, stress, field, value) in [
        (-1e308, 0.0, "psi", "-1e308"),
        (1e300, 0.0, "psi", "1e300"),
        (0.1, 1e300, "stress[2]", "1e300"),
    ] {
        let mut r = good.clone();
        r[11].psi = Some(psi);
        r[11].stress.as_mut().unwrap()[2] = Some(stress);
        write(&s, &plan, &r, false);
        let err = cli_error(&["fit", &sp, "--no-plots"]);
        assert!(
            err.contains("s.jsonl")
                && err.contains(&good[11].id)
                && err.contains(field)
                && err.contains(value),
            "{err}"
        );
    }
    // the same in a held-out file, which names itself
    write(&s, &plan, &good, false);
    let h = d.join("h.jsonl");
    let mut r = good[..20].to_vec();
    r[3].psi = Some(-1e308);
    write(&h, &plan, &r, false);
    let hp = h.display().to_string();
    let err = cli_error(&["fit", &sp, "--no-plots", "--holdout", &hp]);
    assert!(
        err.contains("h.jsonl") && err.contains(&good[3].id),
        "{err}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn fit_exit_code_3_when_a_term_has_too_few_converged_samples() {
    let d = dir("exit3");
    let plan = Plan::reduced();
    let mut r = records(&plan, &default_material());
    // every sample of the s_a range failed
    for i in plan.range_1d(1) {
        r[i].status = SampleStatus::Stalled;
        r[i].psi = None;
        r[i].stress = None;
    }
    let s = d.join("s.jsonl");
    write(&s, &plan, &r, false);
    let out = fit(&s);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("s_a") && err.contains("too few"), "{err}");
    assert!(!s.with_extension("material.json").exists());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn byte_order_marks_are_accepted() {
    let d = dir("bom");
    let plan = Plan::reduced();
    let s = d.join("s.jsonl");
    write(&s, &plan, &records(&plan, &default_material()), true);
    let out = fit(&s);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // a plan file with a BOM, passed to fit and to sample (which then rejects its huge count, not the BOM)
    let pf = d.join("plan.json");
    std::fs::write(&pf, format!("\u{feff}{}", plan.canonical_json())).unwrap();
    let (pp, sp) = (pf.display().to_string(), s.display().to_string());
    let out = hylc(&["fit", &sp, "--no-plots", "--plan", &pp]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn sample_rejects_huge_plans_and_inadmissible_ranges_in_one_line() {
    let d = dir("plans");
    let o = d.join("x.jsonl").display().to_string();
    let good = serde_json::to_value(Plan::reduced()).unwrap();
    let cases: Vec<(&str, serde_json::Value, &str)> = vec![
        ("/count_1d", serde_json::json!(u64::MAX), "count_1d"),
        ("/count_1d", serde_json::json!(1u64 << 32), "count_1d"),
        ("/count_2d", serde_json::json!(100_000), "count_2d"),
        ("/ranges/s_x", serde_json::json!([-0.5, 1e23]), "ranges.s_x"),
        (
            "/ranges/s_y",
            serde_json::json!([-0.5, 1e300]),
            "ranges.s_y",
        ),
        (
            "/ranges/II00",
            serde_json::json!([-1e12, 1e12]),
            "ranges.II00",
        ),
        ("/ranges/s_a", serde_json::json!([-1e6, 1e6]), "ranges.s_a"),
    ];
    for (pointer, value, field) in cases {
        let mut v = good.clone();
        *v.pointer_mut(pointer).unwrap() = value;
        let f = d.join("p.json");
        std::fs::write(&f, format!("\u{feff}{v}")).unwrap();
        let fp = f.display().to_string();
        let err = cli_error(&["sample", "plain", "--plan", &fp, "--out", &o]);
        assert!(err.contains("p.json") && err.contains(field), "{err}");
    }
    assert!(!Path::new(&o).exists());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn sample_exit_code_3_when_a_sample_stops_at_max_steps() {
    let d = dir("sample3");
    let mut plan = Plan::reduced();
    plan.count_1d = 0;
    plan.counts_1d = Some([3, 0, 0, 0, 0]);
    plan.count_2d = 0;
    plan.pairs = vec![];
    let f = d.join("p.json");
    std::fs::write(&f, plan.canonical_json()).unwrap();
    let out_file = d.join("s.jsonl");
    let (fp, o) = (f.display().to_string(), out_file.display().to_string());
    let out = hylc(&[
        "sample",
        "plain",
        "--plan",
        &fp,
        "--out",
        &o,
        "--max-steps",
        "1",
    ]);
    let text = std::fs::read_to_string(&out_file).unwrap();
    // the solver stops after one step: the records say MaxSteps, without a Ψ̄
    assert!(
        text.contains("\"MaxSteps\"") && text.contains("\"psi\":null"),
        "{text}"
    );
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    std::fs::remove_dir_all(&d).ok();
}
