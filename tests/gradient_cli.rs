//! `hylc gradient` end to end (docs/sensitivities.md): on a coarse quasi-static stretch over a sphere, the adjoint
//! gradient of a handle force agrees with the command's own central differences of re-solves (`--check`) for
//! every scene scalar, keyframe, obstacle coordinate and the five largest material coefficients, relative error
//! ≤ 1e-5; the same stretch run dynamically (three steps), the trajectory gradient of its centre of mass ≤ 1e-4; `gradient.json` holds the material's gradient in the material file's layout; a target observable is
//! zero at its own frame. Bad input exits 2 with a message naming the value at fault; no gradient exits 3.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn hylc(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .expect("run hylc");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hylc-gradient-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A built-in printed as JSON and made quasi-static and coarse: `edge` mesh, steps of `dt` to `duration`.
fn scene(
    dir: &Path,
    builtin: &str,
    edge: f64,
    duration: f64,
    dt: f64,
    edit: impl Fn(&mut Value),
) -> String {
    let (code, text, err) = hylc(&["simulate", builtin, "--print"]);
    assert_eq!(code, 0, "{err}");
    let mut s: Value = serde_json::from_str(&text).unwrap();
    s["quasi_static"] = true.into();
    s["duration"] = duration.into();
    s["dt"] = dt.into();
    s["drag"] = 0.0.into();
    s["mesh"]["rectangle"]["edge"] = edge.into();
    edit(&mut s);
    let f = dir.join(format!("{builtin}.json"));
    std::fs::write(&f, serde_json::to_string_pretty(&s).unwrap()).unwrap();
    f.display().to_string()
}

#[test]
fn gradient_matches_its_check_and_writes_the_material_layout() {
    let dir = folder("check");
    let f = scene(&dir, "stretch-x", 0.3 / 12.0, 0.15, 0.05, |s| {
        s["obstacles"] =
            serde_json::json!([{"sphere": {"center": [0.16, 0.14, -0.025], "radius": 0.03}}]);
    });
    let out = dir.join("out");
    let (code, stdout, stderr) = hylc(&[
        "gradient",
        &f,
        "--observable",
        "handle-force:right:x",
        "--check",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let g: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("gradient.json")).unwrap()).unwrap();
    assert_eq!(g["observable"], "handle-force:right:x");
    assert!(g["value"].as_f64().unwrap() > 0.0);
    let check = g["check"].as_array().unwrap();
    // 3 scalars, 3 gravity, 2 handles × 2 keyframes × 3, 1 obstacle × 3, 5 coefficients
    assert_eq!(check.len(), 6 + 12 + 3 + 5, "{check:?}");
    for r in check {
        let e = r["error"].as_f64().unwrap();
        assert!(e <= 1e-5, "{r}");
    }
    // the keyframes' gradients add up to the translation's (the weights of a two-keyframe motion sum to one)
    let right = &g["held"]["right"];
    for c in 0..3 {
        let t = right["translation"][c].as_f64().unwrap();
        let k: f64 = (0..2)
            .map(|i| right["keyframes"][i][c].as_f64().unwrap())
            .sum();
        assert!((t - k).abs() <= 1e-12 * t.abs().max(1e-9), "{right}");
    }
    // the material's gradient loads as a material of the default material's layout
    let m = &g["material"]["coeffs"];
    assert!(m["1D"].as_array().unwrap().len() >= 3);
    let nonzero = m["1D"][0]["p"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v.as_f64() != Some(0.0))
        .count();
    assert!(nonzero >= 2, "{m}");
    assert!(out.join("log.jsonl").exists());
    assert_eq!(g["provenance"]["hylc"], env!("CARGO_PKG_VERSION"));
    assert!(out.join("provenance.json").exists());
}

#[test]
fn dynamic_gradient_matches_its_check() {
    let dir = folder("dynamic");
    let f = scene(&dir, "stretch-x", 0.3 / 12.0, 0.05, 1.0 / 60.0, |s| {
        s["quasi_static"] = false.into();
    });
    let out = dir.join("out");
    let (code, stdout, stderr) = hylc(&[
        "gradient",
        &f,
        "--observable",
        "com-z",
        "--check",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let g: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("gradient.json")).unwrap()).unwrap();
    assert!((g["time"].as_f64().unwrap() - 0.05).abs() < 1e-12);
    let check = g["check"].as_array().unwrap();
    assert_eq!(check.len(), 6 + 12 + 5, "{check:?}");
    for r in check {
        assert!(r["error"].as_f64().unwrap() <= 1e-4, "{r}");
    }
    // a handle's reaction (with the held vertices' inertia) at the second step
    let (code, stdout, stderr) = hylc(&[
        "gradient",
        &f,
        "--observable",
        "handle-force:right:x",
        "--at",
        "0.0333",
        "--check",
        "--check-coefficients",
        "2",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let g: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("gradient.json")).unwrap()).unwrap();
    assert!((g["time"].as_f64().unwrap() - 2.0 / 60.0).abs() < 1e-12);
    for r in g["check"].as_array().unwrap() {
        assert!(r["error"].as_f64().unwrap() <= 1e-4, "{r}");
    }
}

#[test]
fn target_observable_and_bad_input() {
    let dir = folder("input");
    let f = scene(&dir, "stretch-x", 0.3 / 6.0, 0.1, 0.05, |_| {});
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    let (code, _, stderr) = hylc(&[
        "gradient",
        &f,
        "--observable",
        "energy",
        "--out",
        o,
        "--quiet",
    ]);
    assert_eq!(code, 0, "{stderr}");
    // the last frame as the target: J = 0 and every derivative 0
    let frame = out.join("frame_0002.obj");
    let spec = format!("target:{}", frame.display());
    let (code, _, stderr) = hylc(&["gradient", &f, "--observable", &spec, "--out", o, "--quiet"]);
    assert_eq!(code, 0, "{stderr}");
    let g: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("gradient.json")).unwrap()).unwrap();
    assert!(g["value"].as_f64().unwrap() < 1e-20, "{}", g["value"]);
    assert!(g["scene"]["stiffness"].as_f64().unwrap().abs() < 1e-12);
    // bad input: exit 2, naming the value
    let bad = |args: &[&str], needle: &str| {
        let mut a = vec!["gradient", f.as_str(), "--out", o, "--quiet"];
        a.extend_from_slice(args);
        let (code, _, stderr) = hylc(&a);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    };
    bad(&["--observable", "handle-force:middle:x"], "\"middle\"");
    bad(&["--observable", "handle-force:right:w"], "\"w\"");
    bad(&["--observable", "volume"], "volume");
    bad(&["--observable", "energy", "--at", "0.5"], "--at 0.5");
    let initial = format!("target:{}", out.join("nowhere.obj").display());
    bad(&["--observable", &initial], "nowhere.obj");
    let coarser = scene(&dir, "hanging", 0.3 / 4.0, 1.0, 1.0, |_| {});
    let (_, _, _) = hylc(&[
        "simulate",
        &coarser,
        "--out",
        dir.join("h").to_str().unwrap(),
        "--quiet",
    ]);
    let other = format!("target:{}", dir.join("h").join("frame_0000.obj").display());
    bad(&["--observable", &other], "vertices");
    // a dynamic scene with damping under the 18×18 projection, which the trajectory adjoint does not follow
    let damped = scene(&dir, "stretch-x", 0.3 / 6.0, 0.05, 1.0 / 60.0, |s| {
        s["quasi_static"] = false.into();
        s["damping"] = 0.01.into();
        s["psd"] = "full".into();
    });
    let (code, _, stderr) = hylc(&[
        "gradient",
        &damped,
        "--observable",
        "energy",
        "--out",
        o,
        "--quiet",
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("damping") && stderr.contains("full"),
        "{stderr}"
    );
    // the flat hanging cloth's equilibrium is a saddle: no gradient, exit 3
    let flat = scene(&dir, "hanging", 0.3 / 6.0, 1.0, 1.0, |_| {});
    let (code, _, stderr) = hylc(&[
        "gradient",
        &flat,
        "--observable",
        "com-z",
        "--out",
        o,
        "--quiet",
    ]);
    assert_eq!(code, 3, "{stderr}");
    assert!(stderr.contains("strict minimum"), "{stderr}");
}
