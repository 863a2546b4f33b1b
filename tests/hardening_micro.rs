//! Hardening (`docs/robustness.md`) of the micro solver, patterns and materials: absurd strains, pattern values and
//! material coefficients are rejected up front with the component, block/line or JSON path named; the start phase
//! honours the time limit; a non-finite Ψ̄ is an error, never "converged".

mod common;

use common::cli_error;
use hylc::generate::default_pattern;
use hylc::material::json::{MAX_COEFFICIENT, MIN_KNOT_SPACING};
use hylc::material::synthetic::default_material;
use hylc::material::{Material, MaterialStrainError};
use hylc::micro::{MacroStrain, MicroError, MicroProblem, SolverOptions, Status};
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use std::process::Command;
use std::time::Instant;

fn hylc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn absurd_strains_fail_fast_with_exit_2() {
    for (z, needle) in [
        ("1e6,0,0", "s_x = 1000000"),
        ("1e300,0,0", "s_x = 1e300"),
        ("0,0,20", "s_y = 20"),
        ("0,0,0,1e12,0", "II00 = 1000000000000 1/m"),
        ("0,0,0,0,2000", "yarn radius"),
    ] {
        let t = Instant::now();
        let err = cli_error(&[
            "solve",
            "plain",
            "--z",
            z,
            "--max-steps",
            "20",
            "--time-limit",
            "3",
        ]);
        assert!(err.contains(needle), "--z {z}: {err}");
        assert!(err.len() < 400, "--z {z}: {err}");
        assert!(t.elapsed().as_secs_f64() < 3.0, "--z {z}");
    }
}

#[test]
fn the_start_phase_honours_the_time_limit() {
    let p = default_pattern("plain").unwrap();
    let options = SolverOptions {
        time_limit: Some(0.0),
        ..SolverOptions::default()
    };
    let problem = MicroProblem::new(p, &YarnMaterial::default(), options);
    let target = MacroStrain::new(8.0, 0.0, 0.0, 0.0, 0.0);
    let sol = problem.solve(&target, None).unwrap();
    assert_eq!(sol.status, Status::TimeLimit);
    assert_eq!(sol.steps, 0);
    // stopped while moving the start state: the state stays at the strain it reached
    assert_ne!(sol.state.strain, target);
    assert!(sol.psi().is_err());
}

#[test]
fn a_non_finite_energy_is_an_error_not_converged() {
    // bypasses the loader's rest-length check on purpose
    let mut p = default_pattern("plain").unwrap();
    p.edges[0].rest_length = 5e-324;
    let problem = MicroProblem::new(p, &YarnMaterial::default(), SolverOptions::default());
    match problem.solve(&MacroStrain::ZERO, None) {
        Err(MicroError::NonFiniteEnergy { steps, energy, .. }) => {
            assert_eq!(steps, 0);
            assert!(!energy.is_finite());
        }
        other => panic!(
            "expected NonFiniteEnergy, got {:?}",
            other.map(|s| s.status)
        ),
    }
}

/// The generated plain pattern's `.pyp` text with one number replaced: the first number of block `block`'s first
/// record (the `*pattern` line: `field` 0..2 = px, py, r).
fn plain_pyp_with(block: &str, field: usize, value: &str) -> String {
    let text = default_pattern("plain").unwrap().to_pyp_string();
    let mut out = Vec::new();
    let mut in_block = false;
    let mut done = false;
    for line in text.lines() {
        if line.starts_with('*') {
            in_block = line.split_whitespace().next() == Some(block);
            out.push(line.to_string());
            continue;
        }
        if in_block && !done && !line.trim().is_empty() {
            let mut f: Vec<String> = line.split_whitespace().map(str::to_string).collect();
            f[field] = value.to_string();
            out.push(f.join(" "));
            done = true;
            continue;
        }
        out.push(line.to_string());
    }
    assert!(done);
    out.join("\n") + "\n"
}

#[test]
fn non_physical_pattern_values_are_rejected_at_load() {
    let ok = plain_pyp_with("*RL", 0, "0.001");
    Pattern::from_pyp_str(&ok, "ok.pyp").unwrap();
    for (block, field, value, needle) in [
        ("*RL", 0, "5e-324", "rest length 5e-324"),
        ("*RL", 0, "1e300", "rest length 1e300"),
        ("*pattern", 2, "1e11", "r = 1e11"),
        ("*pattern", 2, "1e-9", "r = 1e-9"),
        ("*pattern", 0, "1e-5", "px = 1e-5"),
        ("*pattern", 1, "1e3", "py = 1e3"),
    ] {
        let text = plain_pyp_with(block, field, value);
        let e = Pattern::from_pyp_str(&text, "bad.pyp")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("bad.pyp: block"), "{e}");
        assert!(e.contains(block) && e.contains("line"), "{e}");
        assert!(e.contains(needle), "{e}");
    }
}

#[test]
fn a_tiny_rest_length_in_a_file_is_exit_2_for_solve() {
    let dir = std::env::temp_dir().join("hylc_hardening_micro");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("tiny.pyp");
    std::fs::write(&file, plain_pyp_with("*RL", 0, "5e-324")).unwrap();
    let err = cli_error(&["solve", file.to_str().unwrap()]);
    assert!(err.contains("rest length"), "{err}");
}

#[test]
fn material_strains_outside_the_admissible_range_are_refused() {
    let m = default_material();
    let z = [0.1, 0.2, -0.1, 30.0, 5.0, -20.0];
    assert_eq!(m.eval_checked(&z).unwrap(), m.eval(&z));
    let e = m
        .eval_checked(&[1e300, 0.0, 0.0, 0.0, 0.0, 0.0])
        .unwrap_err();
    assert!(
        matches!(
            e,
            MaterialStrainError::OutOfRange {
                component: "s_x",
                ..
            }
        ),
        "{e}"
    );
    let e = m
        .eval_checked(&[0.0, 0.0, 0.0, 0.0, f64::NAN, 0.0])
        .unwrap_err();
    assert!(
        matches!(
            e,
            MaterialStrainError::NotFinite {
                component: "II01",
                ..
            }
        ),
        "{e}"
    );
    // every strain inside the range evaluates to finite numbers
    for lim in [m.admissible_limits(), m.admissible_limits().map(|v| -v)] {
        let r = m.eval_checked(&lim).unwrap();
        assert!(r.value.is_finite() && r.grad.iter().all(|v| v.is_finite()));
        assert!(r.hess.iter().flatten().all(|v| v.is_finite()));
    }
    for (z, needle) in [
        ("1e300,0,0,0,0,0", "s_x = 1e300"),
        ("0,0,0,0,0,1e150", "II11 = 1e150"),
        ("0,0,0,nan,0,0", "not finite"),
    ] {
        let err = cli_error(&["material", "default", "--z", z]);
        assert!(err.contains(needle), "{err}");
    }
    let out = hylc(&["material", "default", "--z", "0.1,0,0,0,0,0"]);
    assert!(out.status.success());
}

/// The embedded default material as JSON, edited by `f`.
fn default_json_with(f: impl FnOnce(&mut serde_json::Value)) -> String {
    let mut v = default_material().to_json_value();
    f(&mut v);
    v.to_string()
}

#[test]
fn absurd_material_coefficients_are_rejected_with_their_path() {
    let cases: Vec<(String, &str)> = vec![
        (
            default_json_with(|v| {
                let t = &mut v["coeffs"]["1D"][0]["t"];
                for x in t.as_array_mut().unwrap() {
                    *x = (x.as_f64().unwrap() * 1e-300).into();
                }
            }),
            "coeffs.1D[0].t[",
        ),
        (
            default_json_with(|v| v["coeffs"]["1D"][1]["m"][2] = 1e308.into()),
            "coeffs.1D[1].m[2]",
        ),
        (
            default_json_with(|v| v["coeffs"]["2D"][0]["mu"][3] = (-1e308).into()),
            "coeffs.2D[0].mu[3]",
        ),
        (
            default_json_with(|v| v["coeffs"]["const"] = (2.0 * MAX_COEFFICIENT).into()),
            "coeffs.const",
        ),
        (
            default_json_with(|v| v["strain scale"][2] = 5e-324.into()),
            "strain scale[2]",
        ),
        (
            default_json_with(|v| v["strain scale"][4] = 1e300.into()),
            "strain scale[4]",
        ),
        (
            default_json_with(|v| v["coeffs"]["1D"][0]["t"][0] = (-1e6).into()),
            "coeffs.1D[0].t[0]",
        ),
        (
            default_json_with(|v| v["density"] = 1e300.into()),
            "density",
        ),
    ];
    for (text, field) in cases {
        let e = Material::from_json_str(&text, "m.json").unwrap_err();
        assert!(e.field.starts_with(field), "{field}: {e}");
        assert!(e.to_string().len() < 300, "{e}");
    }
    // spacing just above the minimum is accepted
    let fine = default_json_with(|v| {
        v["coeffs"]["1D"][0]["t"][1] =
            (v["coeffs"]["1D"][0]["t"][0].as_f64().unwrap() + 2.0 * MIN_KNOT_SPACING).into()
    });
    Material::from_json_str(&fine, "m.json").unwrap();
}

#[test]
fn material_json_accepts_a_byte_order_mark() {
    let text = default_material().to_json_string();
    let with_bom = format!("\u{feff}{text}");
    let a = Material::from_json_str(&with_bom, "bom.json").unwrap();
    let b = Material::from_json_str(&text, "plain.json").unwrap();
    assert_eq!(a.to_json_string(), b.to_json_string());
}

#[test]
fn the_originals_satisfy_every_limit() {
    let Some(shared) = common::shared_or_skip("the_originals_satisfy_every_limit") else {
        return;
    };
    let data = shared.join("data/hylc2020");
    for name in ["basket1", "honey1", "rib1", "satin1", "stock1"] {
        Material::load(&data.join(format!("materials/{name}.json"))).unwrap();
    }
    for name in [
        "basket",
        "cartridge_belt_rib",
        "satin",
        "slip_stitch_honeycomb",
        "stockinette",
    ] {
        Pattern::load_pyp(data.join(format!("patterns/{name}.pyp"))).unwrap();
    }
}
