//! The chain to the yarn parameters (`hylc gradient … --samples S --yarn Y`, docs/sensitivities.md, "The chain to
//! the yarn"): on the generated plain weave with the quick plan (474 samples; a smaller plan, 7 per 1D range and 4
//! per 2D axis, put a switching decision within ±1 % of the bending factor, and the difference was 65 % off), dJ/dθ of a quasi-static hanging cloth's elastic
//! energy through the samples' ∂Ψ̄/∂θ, the fit's tangent and the adjoint agrees with central differences of the
//! pipeline at θ(1 ± h) (samples re-solved on the same reference state, refitted, the scene re-solved) for
//! Young's modulus, the bending factor and the contact stiffness. Bad input: other yarn parameters than the
//! samples', samples without sensitivities, a material fitted to other samples, a material without recorded fit
//! options: one line each, exit 2.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn hylc(cwd: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run hylc");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

fn ok(cwd: &Path, args: &[&str]) -> String {
    let (code, out, err) = hylc(cwd, args);
    // `sample` exits 3 when a sample did not converge; the fit leaves it out
    assert!(
        code == 0 || (args[0] == "sample" && code == 3),
        "hylc {args:?}: exit {code}\n{err}"
    );
    out
}

/// Samples of `plan` on `reference` with the yarn `yarn` into `dir/samples.jsonl`, fitted into
/// `dir/material.json`.
fn sample_and_fit(
    cwd: &Path,
    dir: &str,
    reference: &str,
    plan: &str,
    yarn: &str,
    sensitivities: bool,
) {
    std::fs::create_dir_all(cwd.join(dir)).unwrap();
    let samples = format!("{dir}/samples.jsonl");
    let mut args = vec![
        "sample",
        reference,
        "--plan",
        plan,
        "--out",
        &samples,
        "--crossings",
        "reject",
        "--yarn",
        yarn,
    ];
    if sensitivities {
        args.push("--sensitivities");
    }
    ok(cwd, &args);
    let material = format!("{dir}/material.json");
    ok(cwd, &["fit", &samples, "--out", &material, "--no-plots"]);
}

fn energy(cwd: &Path, material: &str, out: &str, extra: &[&str]) -> Value {
    let mut args = vec![
        "gradient",
        "scene.json",
        "--observable",
        "energy",
        "--material",
        material,
        "--out",
        out,
        "--quiet",
    ];
    args.extend_from_slice(extra);
    ok(cwd, &args);
    serde_json::from_str(&std::fs::read_to_string(cwd.join(out).join("gradient.json")).unwrap())
        .unwrap()
}

#[test]
fn yarn_gradient_agrees_with_differences_of_the_pipeline() {
    let d: PathBuf = std::env::temp_dir().join(format!("hylc-yarn-chain-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    // a quasi-static hanging cloth on a 3 cm mesh, one step, tight tolerance
    let mut s: Value = serde_json::from_str(&ok(&d, &["simulate", "hanging", "--print"])).unwrap();
    s["mesh"]["rectangle"]["edge"] = 0.03.into();
    s["quasi_static"] = true.into();
    s["duration"] = 0.1.into();
    s["dt"] = 0.1.into();
    s["drag"] = 0.0.into();
    s["solver"]["force_tol"] = 1e-11.into();
    s["solver"]["max_newton"] = 200.into();
    std::fs::write(d.join("scene.json"), s.to_string()).unwrap();
    let yarn0: Value = serde_json::from_str(&ok(&d, &["yarn"])).unwrap();
    std::fs::write(d.join("yarn.json"), yarn0.to_string()).unwrap();
    ok(
        &d,
        &[
            "reference",
            "plain",
            "--yarn",
            "yarn.json",
            "--out",
            "reference.pyp",
        ],
    );
    sample_and_fit(&d, "base", "reference.pyp", "quick", "yarn.json", true);
    let g = energy(
        &d,
        "base/material.json",
        "base/gradient",
        &["--samples", "base/samples.jsonl", "--yarn", "yarn.json"],
    );
    let chain = &g["yarn"];
    assert_eq!(g["yarn_chain"]["reference_state"], "held fixed");
    let h = 1e-2;
    for name in ["young", "bend_twist_factor", "contact_stiffness"] {
        let mut js = vec![];
        for (sign, tag) in [(1.0, "p"), (-1.0, "m")] {
            let mut y = yarn0.clone();
            y[name] = (yarn0[name].as_f64().unwrap() * (1.0 + sign * h)).into();
            let yf = format!("yarn_{name}_{tag}.json");
            std::fs::write(d.join(&yf), y.to_string()).unwrap();
            let dir = format!("{name}_{tag}");
            sample_and_fit(&d, &dir, "reference.pyp", "quick", &yf, false);
            let gj = energy(
                &d,
                &format!("{dir}/material.json"),
                &format!("{dir}/gradient"),
                &[],
            );
            js.push(gj["value"].as_f64().unwrap());
        }
        let theta = yarn0[name].as_f64().unwrap();
        let diff = (js[0] - js[1]) / (2.0 * h * theta);
        let adj = chain[name].as_f64().unwrap();
        let rel = (adj - diff).abs() / diff.abs();
        println!("{name}: chain {adj:.6e}, difference {diff:.6e}, relative {rel:.2e}");
        assert!(
            rel < 0.02,
            "{name}: chain {adj:e} against difference {diff:e} ({rel:.2e})"
        );
    }

    // bad input, one line each, exit 2
    let bad = |extra: &[&str], material: &str, want: &str| {
        let mut args = vec![
            "gradient",
            "scene.json",
            "--observable",
            "energy",
            "--material",
            material,
            "--out",
            "bad",
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let (code, _, err) = hylc(&d, &args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains(want) && err.trim().lines().count() == 1,
            "{args:?}: {err}"
        );
    };
    let base = ["--samples", "base/samples.jsonl"];
    bad(
        &[&base[..], &["--yarn", "yarn_young_p.json"]].concat(),
        "base/material.json",
        "young",
    );
    bad(
        &[
            "--samples",
            "young_p/samples.jsonl",
            "--yarn",
            "yarn_young_p.json",
        ],
        "young_p/material.json",
        "has no dpsi_dtheta",
    );
    bad(
        &[&base[..], &["--yarn", "yarn.json"]].concat(),
        "young_m/material.json",
        "do not belong together",
    );
    let mut m: Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("base/material.json")).unwrap())
            .unwrap();
    m["meta"].as_object_mut().unwrap().remove("fit options");
    std::fs::write(d.join("old.material.json"), m.to_string()).unwrap();
    bad(
        &[&base[..], &["--yarn", "yarn.json"]].concat(),
        "old.material.json",
        "fit options",
    );
    // the pattern's radius is the one the samples were solved with: a yarn file's other radius stands for it
    let mut y = yarn0.clone();
    y["radius"] = (2.0 * yarn0["radius"].as_f64().unwrap()).into();
    std::fs::write(d.join("yarn_radius.json"), y.to_string()).unwrap();
    let g2 = energy(
        &d,
        "base/material.json",
        "base/gradient2",
        &[
            "--samples",
            "base/samples.jsonl",
            "--yarn",
            "yarn_radius.json",
        ],
    );
    assert_eq!(g2["yarn"], g["yarn"]);
    let _ = std::fs::remove_dir_all(&d);
}
