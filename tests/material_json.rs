//! Material JSON: exact round trips, tolerated unknown keys, and one-line file-and-field errors for bad input
//! (`docs/file-formats.md`, "Material (JSON)"), also through the CLI (exit code 2, no panic).

mod common;

use hylc::material::synthetic::default_material;
use hylc::material::Material;
use serde_json::Value;
use std::process::Command;

/// Bitwise equality of two JSON documents' numbers (and everything else).
fn same_bits(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(p), Some(q)) => p.to_bits() == q.to_bits(),
            _ => x == y,
        },
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(p, q)| same_bits(p, q))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len()
                && x.iter()
                    .all(|(k, v)| y.get(k).is_some_and(|w| same_bits(v, w)))
        }
        _ => a == b,
    }
}

#[test]
fn original_materials_round_trip_to_the_last_bit() {
    let Some(shared) = common::shared_or_skip("original_materials_round_trip_to_the_last_bit")
    else {
        return;
    };
    for name in ["basket1", "honey1", "rib1", "satin1", "stock1"] {
        let path = shared.join(format!("data/hylc2020/materials/{name}.json"));
        let text = std::fs::read_to_string(&path).unwrap();
        let original: Value = serde_json::from_str(&text).unwrap();
        let m = Material::from_json_str(&text, name).unwrap();
        assert!(
            m.extra.contains_key("strain shift"),
            "{name}: unknown key not kept"
        );
        let written = m.to_json_string();
        let again: Value = serde_json::from_str(&written).unwrap();
        assert!(
            same_bits(&original, &again),
            "{name}: written JSON differs from the original"
        );
        let m2 = Material::from_json_str(&written, name).unwrap();
        for z in [
            [0.1, -0.2, 0.3, 40.0, -7.0, 12.0],
            [-0.7, 0.9, 1.4, 500.0, 0.0, 500.0],
        ] {
            assert_eq!(
                m.eval(&z),
                m2.eval(&z),
                "{name}: evaluation changed after a round trip"
            );
        }
    }
}

#[test]
fn default_material_round_trips_and_keeps_meta() {
    let m = default_material();
    let text = m.to_json_string();
    let m2 = Material::from_json_str(&text, "default").unwrap();
    assert_eq!(m2.to_json_string(), text);
    assert!(m2.extra["meta"]["generator"].is_string());
    let dir = std::env::temp_dir().join(format!("hylc-json-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("m.json");
    m.save(&path).unwrap();
    let m3 = Material::load(&path).unwrap();
    let z = [0.2, 0.1, -0.3, 10.0, 20.0, -30.0];
    assert_eq!(m3.eval(&z), m.eval(&z));
}

/// The default material's text with one edit, parsed; returns the error line.
fn broken(edit: impl Fn(&mut Value)) -> String {
    let mut v = default_material().to_json_value();
    edit(&mut v);
    let text = serde_json::to_string_pretty(&v).unwrap();
    Material::from_json_str(&text, "bad.json")
        .unwrap_err()
        .to_string()
}

fn broken_text(from: &str, to: &str) -> String {
    let text = default_material().to_json_string();
    assert!(text.contains(from), "test setup: {from:?} not in the text");
    let text = text.replacen(from, to, 1);
    Material::from_json_str(&text, "bad.json")
        .unwrap_err()
        .to_string()
}

fn assert_names(msg: &str, field: &str, what: &str) {
    assert!(!msg.contains('\n'), "not one line: {msg}");
    assert!(msg.starts_with("bad.json: "), "file not named: {msg}");
    assert!(msg.contains(field), "field {field:?} not named: {msg}");
    assert!(msg.contains(what), "{what:?} not said: {msg}");
}

#[test]
fn missing_key_is_named() {
    let msg = broken(|v| {
        v["coeffs"]["1D"][2].as_object_mut().unwrap().remove("m");
    });
    assert_names(&msg, "coeffs.1D[2]", "missing key \"m\"");
    let msg = broken(|v| {
        v.as_object_mut().unwrap().remove("density");
    });
    assert_names(&msg, "(top level)", "missing key \"density\"");
}

#[test]
fn wrong_array_length_is_named() {
    let msg = broken(|v| {
        v["coeffs"]["2D"][1]["muv"].as_array_mut().unwrap().pop();
    });
    assert_names(&msg, "coeffs.2D[1].muv", "wrong array length");
    let msg = broken(|v| {
        v["coeffs"]["1D"][0]["p"]
            .as_array_mut()
            .unwrap()
            .push(Value::from(1.0));
    });
    assert_names(&msg, "coeffs.1D[0].p", "wrong array length 12");
    let msg = broken(|v| {
        v["strain scale"].as_array_mut().unwrap().pop();
    });
    assert_names(&msg, "strain scale", "wrong array length 4");
}

#[test]
fn non_increasing_knots_are_named() {
    let msg = broken(|v| {
        v["coeffs"]["1D"][1]["t"][4] = Value::from(-0.9);
    });
    assert_names(&msg, "coeffs.1D[1].t", "not strictly increasing at index 4");
    let msg = broken(|v| {
        v["coeffs"]["2D"][3]["tv"][2] = v["coeffs"]["2D"][3]["tv"][1].clone();
    });
    assert_names(
        &msg,
        "coeffs.2D[3].tv",
        "not strictly increasing at index 2",
    );
}

#[test]
fn nan_and_infinity_are_named() {
    let msg = broken_text("\"const\": 0.0", "\"const\": NaN");
    assert_names(&msg, "coeffs.const", "finite number, found NaN");
    let msg = broken_text("\"density\": 0.3", "\"density\": Infinity");
    assert_names(&msg, "density", "found Infinity");
    let msg = broken_text("\"density\": 0.3", "\"density\": -1e999");
    assert_names(&msg, "density", "found -1e999");
    let msg = broken(|v| {
        v["coeffs"]["1D"][3]["p"][5] = Value::String("NaN".into());
    });
    assert_names(&msg, "coeffs.1D[3].p[5]", "NaN");
}

#[test]
fn unknown_strain_index_is_named() {
    let msg = broken(|v| {
        v["coeffs"]["1D"][4]["k"] = Value::from(7);
    });
    assert_names(&msg, "coeffs.1D[4].k", "unknown strain index 7");
    let msg = broken(|v| {
        v["coeffs"]["2D"][0]["k0"] = Value::from(3);
        v["coeffs"]["2D"][0]["k1"] = Value::from(4);
    });
    assert_names(&msg, "coeffs.2D[0].k1", "unsupported pair (3, 4)");
    let msg = broken(|v| {
        v["coeffs"]["1D"][4]["k"] = Value::from(1.5);
    });
    assert_names(&msg, "coeffs.1D[4].k", "unknown strain index 1.5");
}

#[test]
fn syntax_errors_and_wrong_types_are_reported() {
    let e = Material::from_json_str("{\"density\": 0.3,\n \"coeffs\": [1, 2,]}", "bad.json")
        .unwrap_err();
    assert_eq!(e.field, "line 2 column 18");
    assert_names(&e.to_string(), "line 2", "invalid JSON");
    let msg = broken(|v| v["coeffs"]["1D"] = Value::from("none"));
    assert_names(&msg, "coeffs.1D", "expected an array, found a string");
    let msg = broken(|v| v["strain shift"] = serde_json::json!([0, 0, 0, 0, 0]));
    assert_names(&msg, "strain shift", "not supported");
}

#[test]
fn cli_reports_bad_files_in_one_line_without_panicking() {
    let dir = std::env::temp_dir().join(format!("hylc-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.json");
    std::fs::write(
        &bad,
        default_material()
            .to_json_string()
            .replacen("\"k\": 3", "\"k\": 9", 1),
    )
    .unwrap();
    let err = common::cli_error(&["material", bad.to_str().unwrap(), "--z", "0,0,0,0,0,0"]);
    assert!(
        err.contains("bad.json")
            && err.contains("coeffs.1D[3].k")
            && err.contains("unknown strain index 9")
    );
    // a bad strain file names file and line
    let zf = dir.join("z.txt");
    std::fs::write(&zf, "# strains\n0 0 0 0 0 0\n0.1, 0.2, nope, 0, 0, 0\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["material", "default", "--z-file", zf.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("z.txt:3") && err.contains("s_y"), "{err}");
    // good input evaluates
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["material", "default", "--json", "--z", "0.1,0,0,0,0,0"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = default_material();
    assert_eq!(
        v["psi"].as_f64().unwrap(),
        m.eval(&[0.1, 0.0, 0.0, 0.0, 0.0, 0.0]).value
    );
}

/// Output piped into a reader that stops early (`hylc material … --json | head -1`) ends `hylc` quietly (SIGPIPE,
/// as for other Unix tools), not with a panic on the broken pipe.
#[cfg(unix)]
#[test]
fn a_closed_output_pipe_is_no_panic() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let dir = std::env::temp_dir().join(format!("hylc-pipe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // far more output than a pipe buffers (64 KiB): ~0.7 kB per strain
    let zs = dir.join("z.txt");
    let lines: Vec<String> = (0..4000)
        .map(|i| format!("{},0,0,0,0,0", 0.0001 * i as f64))
        .collect();
    std::fs::write(&zs, lines.join("\n")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args([
            "material",
            "default",
            "--z-file",
            zs.to_str().unwrap(),
            "--json",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.starts_with("{\"z\""), "{first}");
    // the reader is gone: the rest of the output meets a closed pipe
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}
