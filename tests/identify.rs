//! `hylc identify` (`docs/yarn-parameters.md`) on small generated patterns with synthetic targets (no external data):
//! the Jacobians of the residual sets a, b, c (from the equilibrium sensitivities and the envelope theorem)
//! against central differences of complete re-evaluations, the identification recovering the parameters that
//! made the target, and the one-line errors of bad input. The original patterns are in the `validation/identify/`
//! scripts (minutes), not here.

mod common;

use common::cli_error;
use hylc::generate::default_pattern;
use hylc::micro::{MacroStrain, MicroProblem, SolverOptions};
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use hylc::validation::grid::{counterpart, GridData, AXIS_LEN, GRID_LEN};
use hylc::validation::identify::residuals::{CurveTarget, GridTarget, WarmStates};
use hylc::validation::identify::{
    evaluate, identify, material_of, unknowns_of, IdentifyOptions, Residuals, StoredTarget,
};
use std::path::Path;

fn solver() -> SolverOptions {
    SolverOptions {
        tolerance: 1e-11,
        decrement_tolerance: 0.0,
        ..Default::default()
    }
}

/// Small axes around z = 0 (the grid points one step away are the compared ones).
fn axes() -> [[f64; AXIS_LEN]; 3] {
    let a = |h: f64| std::array::from_fn(|i| (i as f64 - 4.0) * h);
    [a(0.02), a(0.03), a(0.02)]
}

/// Grid data holding our own displacement rows for `material` at the start point and its six neighbours (zero
/// elsewhere), i.e. data our model reproduces exactly with that material.
fn synthetic_grid(pattern: &Pattern, material: &YarnMaterial, points: &[usize]) -> GridData {
    let n = pattern.len();
    let mut values = vec![0.0f32; 4 * GRID_LEN * n];
    let blank = GridData::from_values(axes(), values.clone(), Path::new("synthetic")).unwrap();
    let problem = MicroProblem::new(pattern.clone(), material, solver());
    let g0 = blank.zero_point();
    let s0 = problem.solve(&blank.strain(g0), None).unwrap();
    for &g in points.iter().chain([g0].iter()) {
        let s = problem.solve(&blank.strain(g), Some(&s0.state)).unwrap();
        let rows = counterpart(pattern, &s.state).unwrap();
        for v in 0..n {
            for c in 0..4 {
                values[4 * (g + GRID_LEN * v) + c] = rows[v][c] as f32;
            }
        }
    }
    GridData::from_values(axes(), values, Path::new("synthetic")).unwrap()
}

fn neighbours_of_zero() -> Vec<usize> {
    let blank = GridData::from_values(axes(), vec![0.0; 4 * GRID_LEN], Path::new("x")).unwrap();
    hylc::validation::grid::neighbours(blank.zero_point())
}

fn psi_at(pattern: &Pattern, material: &YarnMaterial, strains: &[MacroStrain]) -> Vec<f64> {
    let problem = MicroProblem::new(pattern.clone(), material, solver());
    strains
        .iter()
        .map(|z| problem.solve(z, None).unwrap().psi().unwrap())
        .collect()
}

#[test]
fn residual_jacobians_match_central_differences() {
    let pattern = default_pattern("plain").unwrap();
    let truth = YarnMaterial {
        contact_radius_factor: 1.02,
        ..Default::default()
    };
    let points = neighbours_of_zero();
    let data = synthetic_grid(&pattern, &YarnMaterial::default(), &points);
    let strains = vec![
        MacroStrain::in_plane(-0.04, 0.0, 0.0),
        MacroStrain::in_plane(0.05, 0.0, 0.0),
        MacroStrain::in_plane(0.1, 0.0, 0.0),
    ];
    let values = psi_at(&pattern, &YarnMaterial::default(), &strains);
    // the generated pattern's stored state is stress-free; a perturbed copy is not an equilibrium
    let mut stored = pattern.clone();
    for (v, x) in stored.positions.iter_mut().enumerate() {
        let t = v as f64;
        *x += nalgebra::Vector3::new((1.3 * t).sin(), (2.1 * t).cos(), (0.7 * t).sin())
            * (0.05 * pattern.radius);
    }
    let sets = Residuals {
        stored: Some(StoredTarget {
            pattern: stored,
            weight: 1.0,
        }),
        grid: Some(GridTarget {
            data,
            points,
            weight: 1.0,
        }),
        curve: Some(CurveTarget::new(
            &strains
                .iter()
                .copied()
                .zip(values.iter().copied())
                .collect::<Vec<_>>(),
            1.0,
        )),
    };
    let q0 = unknowns_of(&truth);
    let mut warm = WarmStates::default();
    let ev = evaluate(&pattern, &truth, &sets, &solver(), &mut warm).unwrap();
    let m = ev.residual.len();
    let mut worst: f64 = 0.0;
    for k in 0..5 {
        // a step of 1e-3 in ln θ: truncation error O(h²) ~ 1e-6 relative and the re-solve noise (1e-11 k_s)
        // well below; for ln f 1e-5: the contact gradient is only C⁰ in the contact radius where a quadrature
        // distance equals 2ρ, and a larger step crosses such points
        let h = if k == 4 { 1e-5 } else { 1e-3 };
        let at = |d: f64| {
            let mut q = q0;
            q[k] += d;
            let mut w = warm.clone();
            evaluate(&pattern, &material_of(&q, &truth), &sets, &solver(), &mut w)
                .unwrap()
                .residual
        };
        let (rp, rm) = (at(h), at(-h));
        let fd: Vec<f64> = (0..m).map(|i| (rp[i] - rm[i]) / (2.0 * h)).collect();
        let an: Vec<f64> = ev.jacobian.iter().map(|row| row[k]).collect();
        let num: f64 = an
            .iter()
            .zip(&fd)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        let den: f64 = fd.iter().map(|b| b * b).sum::<f64>().sqrt();
        let e = num / den;
        let an_norm = an.iter().map(|v| v * v).sum::<f64>().sqrt();
        eprintln!(
            "column {k}: ‖J‖ = {an_norm:.3e} (differences {den:.3e}), relative error {e:.2e}"
        );
        assert!(den > 0.0 && e <= 1e-4, "column {k}: relative error {e:.2e}");
        worst = worst.max(e);
    }
    eprintln!("Jacobian of a, b, c against central differences: worst relative error {worst:.2e}");
}

#[test]
fn identification_recovers_the_parameters_of_synthetic_data() {
    // data made with known parameters; start from the defaults; (b) and (c) together fix every unknown
    let pattern = default_pattern("plain").unwrap();
    let truth = YarnMaterial {
        young: 1.6e6,
        bend_twist_factor: 0.14,
        contact_stiffness: 50.0,
        ..Default::default()
    };
    let points = neighbours_of_zero();
    let data = synthetic_grid(&pattern, &truth, &points);
    let strains = vec![
        MacroStrain::in_plane(-0.04, 0.0, 0.0),
        MacroStrain::in_plane(0.05, 0.0, 0.0),
        MacroStrain::in_plane(0.1, 0.0, 0.0),
    ];
    let values = psi_at(&pattern, &truth, &strains);
    let sets = Residuals {
        stored: None,
        grid: Some(GridTarget {
            data,
            points,
            weight: 1.0,
        }),
        curve: Some(CurveTarget::new(
            &strains
                .iter()
                .copied()
                .zip(values.iter().copied())
                .collect::<Vec<_>>(),
            1.0,
        )),
    };
    let options = IdentifyOptions {
        // G/Y and f held at the truth: the plain weave's small tile barely twists
        free: [true, true, false, true, false],
        solver: solver(),
        cost_tolerance: 1e-12,
        step_tolerance: 1e-9,
        ..Default::default()
    };
    let start = YarnMaterial::default();
    let r = identify(&pattern, &start, &sets, &options, &mut |_| {}).unwrap();
    let got = &r.identified;
    for (name, a, b) in [
        ("young", got.young, truth.young),
        ("gamma", got.bend_twist_factor, truth.bend_twist_factor),
        ("contact", got.contact_stiffness, truth.contact_stiffness),
    ] {
        assert!(
            (a / b - 1.0).abs() < 1e-3,
            "{name}: identified {a} vs truth {b} ({})",
            r.stopped
        );
    }
    assert!(
        r.after.cost < 1e-8 * r.before.cost,
        "{:?} → {:?}",
        r.before,
        r.after
    );
    eprintln!(
        "recovered Y, γ, k_c within {:.1e} in {} iterations, {:.1} s",
        [
            got.young / truth.young,
            got.bend_twist_factor / truth.bend_twist_factor,
            got.contact_stiffness / truth.contact_stiffness
        ]
        .iter()
        .map(|v| (v - 1.0).abs())
        .fold(0.0, f64::max),
        r.iterations.len() - 1,
        r.time
    );
}

#[test]
fn bad_input_is_one_line_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("hylc_identify_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pyp = dir.join("plain.pyp");
    default_pattern("plain").unwrap().save_pyp(&pyp).unwrap();
    let p = pyp.to_str().unwrap();
    // displacement folder with the wrong vertex count, and with a NaN
    let data = dir.join("data");
    std::fs::create_dir_all(&data).unwrap();
    let axes_text: String = axes()
        .iter()
        .map(|a| {
            a.iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(" ")
                + "\n"
        })
        .collect();
    std::fs::write(data.join("axes.txt"), axes_text).unwrap();
    let write_npy = |rows: usize, nan: bool| {
        let mut v = vec![0.0f32; 4 * rows];
        if nan {
            v[5] = f32::NAN;
        }
        let mut out = Vec::new();
        {
            use npyz::WriterBuilder;
            let mut w = npyz::WriteOptions::<f32>::new()
                .default_dtype()
                .shape(&[rows as u64, 4])
                .writer(&mut out)
                .begin_nd()
                .unwrap();
            w.extend(v).unwrap();
            w.finish().unwrap();
        }
        std::fs::write(data.join("data.npy"), out).unwrap();
    };
    let d = data.to_str().unwrap();
    write_npy(GRID_LEN * 3, false);
    let e = cli_error(&["identify", p, "--data", d, "--residuals", "b"]);
    assert!(e.contains("vertices") && e.contains("plain.pyp"), "{e}");
    write_npy(GRID_LEN * default_pattern("plain").unwrap().len(), true);
    let e = cli_error(&["identify", p, "--data", d, "--residuals", "b"]);
    assert!(e.contains("data.npy") && e.contains("non-finite"), "{e}");
    // unknown residual set, unknown unknown, missing inputs
    let e = cli_error(&["identify", p, "--residuals", "a,x"]);
    assert!(e.contains("--residuals") && e.contains("\"x\""), "{e}");
    let e = cli_error(&["identify", p, "--residuals", "a", "--fix", "poisson"]);
    assert!(e.contains("--fix") && e.contains("poisson"), "{e}");
    let e = cli_error(&["identify", p, "--residuals", "c"]);
    assert!(e.contains("--material"), "{e}");
    // a yarn file with a missing key
    let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
    v.as_object_mut().unwrap().remove("young");
    let y = dir.join("y.json");
    std::fs::write(&y, v.to_string()).unwrap();
    let e = cli_error(&[
        "identify",
        p,
        "--residuals",
        "a",
        "--yarn",
        y.to_str().unwrap(),
    ]);
    assert!(e.contains("y.json") && e.contains("`young`"), "{e}");
}
