//! Yarn parameters as data (`docs/yarn-parameters.md`, "Yarn parameters as data (`--yarn FILE`)"): `hylc yarn` writes
//! the JSON form that `--yarn FILE` reads on every command that solves; bad files are one-line errors naming file and
//! key; sample sidecars record the yarn used, and sidecars from before the contact radius factor still read.

mod common;

use common::cli_error;
use hylc::rod::YarnMaterial;
use std::path::PathBuf;
use std::process::Command;

fn hylc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .unwrap()
}

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("hylc_yarn_file_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Ψ̄ of `hylc solve plain --json` with extra arguments.
fn psi(extra: &[&str]) -> f64 {
    let mut args = vec!["solve", "plain", "--z", "0.05,0,0", "--json"];
    args.extend_from_slice(extra);
    let out = hylc(&args);
    assert!(out.status.success(), "{:?}", out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["psi"].as_f64().unwrap()
}

#[test]
fn the_printed_default_reads_back_and_solves_like_no_file() {
    let d = dir();
    let out = hylc(&["yarn"]);
    assert!(out.status.success());
    let m =
        YarnMaterial::from_json_str(std::str::from_utf8(&out.stdout).unwrap(), &d.join("stdout"))
            .unwrap();
    assert_eq!(m, YarnMaterial::default());
    let file = d.join("default.json");
    std::fs::write(&file, &out.stdout).unwrap();
    let f = file.to_str().unwrap();
    assert_eq!(psi(&["--yarn", f]).to_bits(), psi(&[]).to_bits());

    // a stiffer yarn: stretching energy scales with Y, so Ψ̄ grows
    let stiff = YarnMaterial {
        young: 2e6,
        shear: 8e5,
        ..Default::default()
    };
    let file2 = d.join("stiff.json");
    stiff.save_json(&file2).unwrap();
    let p2 = psi(&["--yarn", file2.to_str().unwrap()]);
    assert!(p2 > 1.5 * psi(&[]), "{p2}");
}

#[test]
fn bad_yarn_files_are_one_line_errors_naming_file_and_key() {
    let d = dir();
    let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
    v["contact_form"] = serde_json::json!("kaldor");
    let unknown = d.join("unknown.json");
    std::fs::write(&unknown, v.to_string()).unwrap();
    let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
    v.as_object_mut().unwrap().remove("bend_twist_factor");
    let missing = d.join("missing.json");
    std::fs::write(&missing, v.to_string()).unwrap();
    let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
    v["contact_radius_factor"] = serde_json::json!(0.0);
    let range = d.join("range.json");
    std::fs::write(&range, v.to_string()).unwrap();
    for (file, key) in [
        (&unknown, "contact_form"),
        (&missing, "bend_twist_factor"),
        (&range, "contact_radius_factor"),
    ] {
        let f = file.to_str().unwrap();
        let out = d.join("o.pyp");
        let grid = d.join("no-grid");
        for args in [
            vec!["solve", "plain", "--yarn", f],
            vec!["sensitivity", "plain", "--yarn", f],
            vec!["sample", "plain", "--out", "x.jsonl", "--yarn", f],
            vec![
                "reference",
                "plain",
                "--out",
                out.to_str().unwrap(),
                "--yarn",
                f,
            ],
            vec!["micro-grid", "plain", grid.to_str().unwrap(), "--yarn", f],
            vec!["run", "--yarn", f],
            vec!["yarn", f],
        ] {
            let err = cli_error(&args);
            assert!(
                err.contains(f) && err.contains(&format!("`{key}`")),
                "{args:?}: {err}"
            );
        }
    }
}

#[test]
fn sample_sidecars_record_the_yarn_and_old_sidecars_read() {
    let d = dir();
    let yarn = YarnMaterial {
        contact_stiffness: 50.0,
        contact_radius_factor: 0.95,
        ..Default::default()
    };
    let yf = d.join("y.json");
    yarn.save_json(&yf).unwrap();
    let samples = d.join("s.jsonl");
    let out = hylc(&[
        "sample",
        "plain",
        "--plan",
        "reduced",
        "--limit",
        "1",
        "--out",
        samples.to_str().unwrap(),
        "--yarn",
        yf.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{out:?}");
    let meta = hylc::workflow::sidecar::read_meta(&samples)
        .unwrap()
        .unwrap();
    let recorded = hylc::workflow::sidecar::recorded_yarn(&samples, &meta)
        .unwrap()
        .unwrap();
    let plain_radius = hylc::generate::default_pattern("plain").unwrap().radius;
    assert_eq!(
        recorded,
        YarnMaterial {
            radius: plain_radius,
            ..yarn.clone()
        }
    );

    // a sidecar written before the contact radius factor existed
    let mut old = meta.clone();
    old["yarn"]
        .as_object_mut()
        .unwrap()
        .remove("contact_radius_factor");
    let r = hylc::workflow::sidecar::recorded_yarn(&samples, &old)
        .unwrap()
        .unwrap();
    assert_eq!(r.contact_radius_factor, 1.0);
    assert_eq!(r.contact_stiffness, 50.0);
    // any other missing key is named
    old["yarn"].as_object_mut().unwrap().remove("young");
    let e = hylc::workflow::sidecar::recorded_yarn(&samples, &old)
        .unwrap_err()
        .to_string();
    assert!(e.contains("`young`") && e.contains("s.meta.json"), "{e}");
}

/// A yarn file whose radius differs from the pattern's: one warning naming both, the pattern's used; a file with
/// the pattern's radius is silent.
#[test]
fn a_yarn_radius_the_pattern_overrides_warns_once() {
    let d = dir();
    let warnings = |yarn: &YarnMaterial, name: &str| -> Vec<String> {
        let f = d.join(name);
        yarn.save_json(&f).unwrap();
        let out = hylc(&[
            "solve",
            "plain",
            "--z",
            "0,0,0",
            "--yarn",
            f.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{out:?}");
        String::from_utf8_lossy(&out.stderr)
            .lines()
            .filter(|l| l.contains("radius"))
            .map(str::to_string)
            .collect()
    };
    let thick = YarnMaterial {
        radius: 2e-3,
        ..Default::default()
    };
    let w = warnings(&thick, "thick.json");
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("warning: ")
            && w[0].contains("thick.json: radius 0.002 m is not used: the pattern plain carries its own radius, 0.001 m"),
        "{}",
        w[0]
    );
    // the generated pattern's radius (1 mm) within 1e-6 relative: silent
    let same = YarnMaterial {
        radius: 1e-3 * (1.0 + 1e-9),
        ..Default::default()
    };
    assert!(warnings(&same, "same.json").is_empty());
}
