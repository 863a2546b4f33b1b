//! Macro-scale tests (`docs/cloth-simulator.md`): patch tests (uniform deformation, cylinder, rigid motions), the
//! quasi-static uniaxial strip against ∂ψ/∂s_x, and bad input (OBJ and scene files).

mod common;

use hylc::material::synthetic::default_material;
use hylc::shell::assemble::energy;
use hylc::shell::scene::Scene;
use hylc::shell::solver::{Boundary, Handle, Motion, Settings, Simulation};
use hylc::shell::{ElementModel, Mesh, ModelFlags, Psd};
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn model() -> ElementModel {
    ElementModel::new(&default_material(), &ModelFlags::default(), Psd::None)
}

/// Material coordinates of the rest layout with fabric axes at `angle`.
fn material_coords(mesh: &Mesh, angle: f64) -> Vec<[f64; 2]> {
    let (s, c) = angle.sin_cos();
    mesh.rest
        .iter()
        .map(|p| [c * p[0] + s * p[1], -s * p[0] + c * p[1]])
        .collect()
}

#[test]
fn uniform_deformation_gives_psi_per_area() {
    let m = model();
    let mesh = Mesh::rectangle(0.05, 0.04, 0.006, 0.3, 5).unwrap();
    let angle = 0.4;
    let st = mesh.stencils(angle).unwrap();
    let xm = material_coords(&mesh, angle);
    let area: f64 = st.iter().map(|s| s.rest.area).sum();
    assert!((area - 0.05 * 0.04).abs() < 1e-15);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut worst: f64 = 0.0;
    for _ in 0..50 {
        let (lo, hi) = (m.material.knot_range(0), m.material.knot_range(2));
        let z = [
            rng.random_range(0.9 * lo.0..0.9 * lo.1),
            rng.random_range(-0.6..0.6),
            rng.random_range(0.9 * hi.0..0.9 * hi.1),
        ];
        // F e₁ = (1 + s_x)(1, 0), F e₂ = (1 + s_y)(cos φ, sin φ) with cos φ = s_a, then a rigid rotation
        let sin = (1.0 - z[1] * z[1]).sqrt();
        let f2 = nalgebra::Matrix3x2::new(
            1.0 + z[0],
            (1.0 + z[2]) * z[1],
            0.0,
            (1.0 + z[2]) * sin,
            0.0,
            0.0,
        );
        let rot =
            Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(0.3, -1.0, 0.5)), 1.1);
        let f3: nalgebra::Matrix3x2<f64> = rot.matrix() * f2;
        let x: Vec<f64> = xm
            .iter()
            .flat_map(|p| {
                let y = f3 * nalgebra::Vector2::new(p[0], p[1]) + Vector3::new(0.5, -2.0, 1.0);
                [y[0], y[1], y[2]]
            })
            .collect();
        let e = energy(&m, &st, &x).unwrap();
        let psi = m.material.value(&[z[0], z[1], z[2], 0.0, 0.0, 0.0]);
        let err = (e / area - psi).abs() / psi.abs().max(1e-300);
        worst = worst.max(err);
        assert!(
            err <= 1e-10,
            "z = {z:?}: energy/area {} vs psi {psi}: rel err {err:.2e}",
            e / area
        );
    }
    eprintln!("uniform patch: worst relative error of energy/area against psi: {worst:.2e}");
}

/// Mean II over interior triangles (all three flaps) of a mesh wrapped on a cylinder of radius r whose axis is
/// along the mesh y direction; `towards` bends towards the rest normal n₀ = +z.
fn cylinder_curvature(r: f64, towards: bool, angle: f64) -> [f64; 3] {
    let mesh = Mesh::rectangle(0.04, 0.04, 0.001, 0.0, 1).unwrap();
    let st = mesh.stencils(angle).unwrap();
    let sign = if towards { 1.0 } else { -1.0 };
    let x: Vec<f64> = mesh
        .rest
        .iter()
        .flat_map(|p| {
            let t = (p[0] - 0.02) / r;
            [r * t.sin(), p[1], sign * r * (1.0 - t.cos())]
        })
        .collect();
    let m = model();
    let mut acc = [0.0; 3];
    let mut n = 0.0;
    for s in &st {
        if s.flaps.iter().all(|&f| f) {
            let q = hylc::shell::assemble::gather(s, &x);
            let z = m.strain(&q, &s.rest, s.flaps).unwrap();
            for k in 0..3 {
                acc[k] += z[3 + k];
            }
            n += 1.0;
        }
    }
    acc.map(|a| a / n)
}

#[test]
fn cylinder_gives_one_over_r() {
    for r in [0.02, 0.05] {
        for towards in [true, false] {
            let ii = cylinder_curvature(r, towards, 0.0);
            let expect = if towards { 1.0 / r } else { -1.0 / r };
            eprintln!(
                "cylinder R = {r} m, towards n0 = {towards}: II = {ii:?}, expected II00 = {expect}"
            );
            assert!(
                (ii[0] - expect).abs() <= 1e-3 / r,
                "II00 {} vs {expect}",
                ii[0]
            );
            assert!(ii[1].abs() <= 1e-3 / r && ii[2].abs() <= 1e-3 / r, "{ii:?}");
            // fabric axes rotated by 90°: the curvature is along the fabric y axis
            let ii = cylinder_curvature(r, towards, std::f64::consts::FRAC_PI_2);
            assert!(
                (ii[2] - expect).abs() <= 1e-3 / r,
                "rotated: II11 {} vs {expect}",
                ii[2]
            );
            assert!(ii[0].abs() <= 1e-3 / r, "rotated: {ii:?}");
        }
    }
}

#[test]
fn energy_is_invariant_under_rigid_motions() {
    let m = model();
    let mesh = Mesh::rectangle(0.03, 0.03, 0.005, 0.25, 2).unwrap();
    let st = mesh.stencils(0.3).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..10 {
        let x: Vec<f64> = mesh
            .rest
            .iter()
            .flat_map(|p| {
                [
                    1.1 * p[0] + 0.2 * p[1] + rng.random_range(-5e-4..5e-4),
                    0.9 * p[1] + rng.random_range(-5e-4..5e-4),
                    20.0 * p[0] * p[0] - 10.0 * p[1] * p[1] + rng.random_range(-5e-4..5e-4),
                ]
            })
            .collect();
        let e0 = energy(&m, &st, &x).unwrap();
        let axis = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            0.7,
        );
        let rot: Matrix3<f64> =
            *Rotation3::from_axis_angle(&Unit::new_normalize(axis), rng.random_range(-3.0..3.0))
                .matrix();
        let shift = Vector3::new(2.0, -1.5, 0.7);
        let y: Vec<f64> = x
            .chunks(3)
            .flat_map(|p| {
                let q = rot * Vector3::new(p[0], p[1], p[2]) + shift;
                [q[0], q[1], q[2]]
            })
            .collect();
        let e1 = energy(&m, &st, &y).unwrap();
        assert!((e1 - e0).abs() <= 1e-12 * e0.abs(), "{e0} vs {e1}");
    }
}

#[test]
fn uniaxial_strip_reaction_matches_dpsi_dsx() {
    uniaxial_strip(&default_material(), "default");
    if let Some(dir) = common::shared_or_skip("uniaxial strip with basket1") {
        let m = hylc::material::Material::load(&dir.join("data/hylc2020/materials/basket1.json"))
            .unwrap();
        uniaxial_strip(&m, "basket1");
    }
}

fn uniaxial_strip(material: &hylc::material::Material, name: &str) {
    let model = || ElementModel::new(material, &ModelFlags::default(), Psd::None);
    // a 20 cm × 2 cm strip, 4 mm edges, free long edges, clamped ends pulled apart quasi-statically to 8 %
    let (l, w, h) = (0.2, 0.02, 0.004);
    let mesh = Mesh::rectangle(l, w, h, 0.0, 1).unwrap();
    let st = mesh.stencils(0.0).unwrap();
    let x0 = mesh.place([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let ends = |left: bool| -> Vec<usize> {
        (0..mesh.len())
            .filter(|&v| {
                if left {
                    mesh.rest[v][0] < 1e-9
                } else {
                    mesh.rest[v][0] > l - 1e-9
                }
            })
            .collect()
    };
    let stretch = 0.08 * l;
    let handles = vec![
        Handle {
            name: "left".into(),
            vertices: ends(true),
            motion: Motion::linear(&[(0.0, [0.0; 3])]),
        },
        Handle {
            name: "right".into(),
            vertices: ends(false),
            motion: Motion::linear(&[(0.0, [0.0; 3]), (1.0, [stretch, 0.0, 0.0])]),
        },
    ];
    let settings = Settings {
        dt: 0.25,
        quasi_static: true,
        force_tol: 1e-10,
        max_newton: 100,
        gravity: [0.0; 3],
        ..Settings::default()
    };
    let mut sim = Simulation::new(
        model(),
        st.clone(),
        x0,
        Boundary {
            handles,
            ..Boundary::default()
        },
        settings,
        1.0,
    )
    .unwrap();
    let mut last = None;
    for _ in 0..4 {
        let r = sim.step().unwrap();
        assert!(r.converged, "step {} residual {}", r.step, r.residual);
        last = Some(r);
    }
    let r = last.unwrap();
    // mean strain over the triangles of the middle fifth of the strip
    let m = model();
    let mut z = [0.0; 6];
    let mut n = 0.0;
    for s in &st {
        let cx = (0..3).map(|a| mesh.rest[s.v[a]][0]).sum::<f64>() / 3.0;
        if (cx - 0.5 * l).abs() < 0.1 * l {
            let q = hylc::shell::assemble::gather(s, &sim.x);
            let zz = m.strain(&q, &s.rest, s.flaps).unwrap();
            for k in 0..6 {
                z[k] += zz[k];
            }
            n += 1.0;
        }
    }
    let z = z.map(|a| a / n);
    let dpsi = m.material.eval(&z).grad[0];
    let expected = w * dpsi;
    let fx = r.handle_forces[1].1[0];
    eprintln!("uniaxial strip [{name}]: mid strains {z:?}, reaction {fx:.6e} N, width x dpsi/dsx {expected:.6e} N, rel diff {:.2e}", (fx - expected).abs() / expected.abs());
    assert!(z[0] > 0.07, "stretched along x: {z:?}");
    assert!(
        (fx - expected).abs() <= 0.01 * expected.abs(),
        "reaction {fx} vs {expected}"
    );
    assert!(
        (r.handle_forces[0].1[0] + fx).abs() <= 1e-6 * fx.abs(),
        "handles balance"
    );
}

fn temp_file(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hylc-shell-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn bad_obj_files_name_file_and_line() {
    let nonmanifold = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 1 1 0\nf 1 2 3\nf 2 1 4\n# third face on edge 1-2\nf 1 2 5\n";
    let (mesh, _) = Mesh::parse_obj(nonmanifold, "bad.obj").unwrap();
    let e = mesh.stencils(0.0).unwrap_err().to_string();
    assert!(e.starts_with("bad.obj:9: non-manifold edge (1, 2)"), "{e}");
    let degenerate = "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n";
    let (mesh, _) = Mesh::parse_obj(degenerate, "deg.obj").unwrap();
    let e = mesh.stencils(0.0).unwrap_err().to_string();
    assert!(e.starts_with("deg.obj:4: degenerate rest triangle"), "{e}");
    let e = Mesh::parse_obj("v 0 0 0\nv 1 0 x\n", "c.obj")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("c.obj:2: bad vertex coordinate"), "{e}");
    let e = Mesh::parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "i.obj")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("i.obj:4: face index 7 out of range"), "{e}");
    let e = Mesh::parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0.5\nf 1 2 3\n", "f.obj")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("f.obj:3: the rest layout must be flat"),
        "{e}"
    );
    // through a scene and the CLI: one line, exit code 2, naming the file and line
    let obj = temp_file("nonmanifold.obj", nonmanifold);
    let scene = temp_file(
        "obj_scene.json",
        &format!(
            r#"{{"material": "default", "mesh": {{"obj": {{"path": "{}"}}}}, "duration": 0.1}}"#,
            obj.display()
        ),
    );
    let err = common::cli_error(&["simulate", scene.to_str().unwrap(), "--quiet"]);
    assert!(
        err.contains("nonmanifold.obj:9: non-manifold edge"),
        "{err}"
    );
}

#[test]
fn bad_scene_files_name_file_and_field() {
    let unknown = temp_file(
        "unknown.json",
        "{\"material\": \"default\",\n \"mesh\": {\"rectangle\": {\"width\": 0.1, \"height\": 0.1, \"edge\": 0.01}},\n \"duration\": 0.1,\n \"gravty\": [0, 0, -9.81]}",
    );
    let err = common::cli_error(&["simulate", unknown.to_str().unwrap(), "--quiet"]);
    assert!(
        err.contains("unknown.json")
            && err.contains("unknown field `gravty`")
            && err.contains("line 4"),
        "{err}"
    );
    let missing = temp_file(
        "missing.json",
        r#"{"material": "no_such_material.json", "mesh": {"rectangle": {"width": 0.1, "height": 0.1, "edge": 0.01}}, "duration": 0.1}"#,
    );
    let err = common::cli_error(&["simulate", missing.to_str().unwrap(), "--quiet"]);
    assert!(
        err.contains("missing.json: field `material`") && err.contains("no_such_material.json"),
        "{err}"
    );
    let no_mat = temp_file(
        "nomat.json",
        r#"{"mesh": {"rectangle": {"width": 0.1, "height": 0.1, "edge": 0.01}}, "duration": 0.1}"#,
    );
    let err = common::cli_error(&["simulate", no_mat.to_str().unwrap(), "--quiet"]);
    assert!(
        err.contains("nomat.json") && err.contains("missing field `material`"),
        "{err}"
    );
    let dt = temp_file(
        "dt.json",
        r#"{"material": "default", "mesh": {"rectangle": {"width": 0.1, "height": 0.1, "edge": 0.01}}, "duration": 0.1, "dt": -1}"#,
    );
    let err = common::cli_error(&["simulate", dt.to_str().unwrap(), "--quiet"]);
    assert!(err.contains("dt.json: field `dt`"), "{err}");
    let empty = temp_file(
        "empty_pin.json",
        r#"{"material": "default", "mesh": {"rectangle": {"width": 0.1, "height": 0.1, "edge": 0.01}}, "duration": 0.1,
            "pins": [{"near": {"point": [5, 5], "radius": 0.001}}]}"#,
    );
    let err = common::cli_error(&["simulate", empty.to_str().unwrap(), "--quiet"]);
    assert!(err.contains("field `pins[0]` selects no vertex"), "{err}");
    let err = common::cli_error(&["simulate", "no-such-scene", "--quiet"]);
    assert!(err.contains("not a built-in scene"), "{err}");
}

#[test]
fn builtin_scenes_round_trip_and_a_short_run_is_stable() {
    for name in hylc::shell::scene::BUILTINS {
        let s = hylc::shell::scene::builtin(name).unwrap();
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(Scene::from_json_str(&text, name).unwrap(), s);
    }
    // the hanging square on a coarse mesh for 0.2 s: converged steps, falling, finite
    let mut s = hylc::shell::scene::builtin("hanging").unwrap();
    s.mesh = hylc::shell::scene::MeshSpec::Rectangle {
        width: 0.3,
        height: 0.3,
        edge: 0.03,
        perturb: 0.0,
        seed: 1,
    };
    s.duration = 0.2;
    let (mut sim, tris) = s.build("hanging", std::path::Path::new(".")).unwrap();
    let sum = hylc::shell::scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
    assert_eq!(sum.unconverged_steps, 0);
    let r = sum.last.unwrap();
    assert!(r.energy_gravity < 0.0 && r.energy_elastic > 0.0);
    assert!(sim.x.iter().all(|v| v.is_finite()));
}

/// The harness catches the bug this code once had: the dihedral-angle gradient of the triangle's own wing with
/// the wrong sign (here: the Jacobian and Hessian entries of the flap vertices negated), and a 1e-6 relative
/// error in the weighted Hessian.
#[test]
fn harness_catches_strain_chain_mutants() {
    use hylc::checks::shell::StrainCheck;
    use hylc::diff::{check_function, CheckConfig, Differentiable, Real, Vgh};
    struct Mutant(usize);
    impl Differentiable for Mutant {
        fn name(&self) -> String {
            format!("mutant {}", self.0)
        }
        fn dim(&self) -> usize {
            StrainCheck.dim()
        }
        fn n_params(&self) -> usize {
            StrainCheck.n_params()
        }
        fn scales_at(&self, x: &[f64]) -> hylc::diff::Scales {
            StrainCheck.scales_at(x)
        }
        fn input_scale_at(&self, x: &[f64], i: usize) -> f64 {
            StrainCheck.input_scale_at(x, i)
        }
        fn reference<D: Real>(&self, x: &[D]) -> D {
            StrainCheck.reference(x)
        }
        fn fast(&self, x: &[f64]) -> Vgh {
            let mut v = StrainCheck.fast(x);
            if self.0 == 0 {
                for j in 9..18 {
                    v.gradient[j] = -v.gradient[j];
                    for k in 0..18 {
                        v.hessian[(j, k)] = -v.hessian[(j, k)];
                        v.hessian[(k, j)] = -v.hessian[(k, j)];
                    }
                }
            } else {
                v.hessian *= 1.0 + 1e-6;
            }
            v
        }
        fn fast_value(&self, x: &[f64]) -> f64 {
            StrainCheck.fast_value(x)
        }
        fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
            // bending weights only, so the mutated entries matter
            let mut x = StrainCheck.sample(rng, i);
            let n = x.len();
            for k in 0..3 {
                x[n - 6 + k] = 0.0;
                x[n - 3 + k] = rng.random_range(0.5..1.0);
            }
            x
        }
    }
    let cfg = CheckConfig {
        cases: 50,
        ..CheckConfig::default()
    };
    for m in [Mutant(0), Mutant(1)] {
        let r = check_function(&m, &cfg);
        assert!(
            !r.passed(),
            "{} passed: worst ratio {}",
            m.name(),
            r.worst_ratio
        );
    }
    assert!(check_function(&StrainCheck, &cfg).passed());
}

/// Zero strain in the rest configuration (the rest layout in material coordinates, rigidly moved; flaps flat).
#[test]
fn rest_configuration_has_zero_strain() {
    let mesh = Mesh::rectangle(0.04, 0.03, 0.005, 0.3, 9).unwrap();
    let angle = 0.7;
    let st = mesh.stencils(angle).unwrap();
    let xm = material_coords(&mesh, angle);
    let rot = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(1.0, 2.0, -0.5)), 2.0);
    let x: Vec<f64> = xm
        .iter()
        .flat_map(|p| {
            let q = rot * Vector3::new(p[0], p[1], 0.0) + Vector3::new(0.3, 0.1, -0.2);
            [q[0], q[1], q[2]]
        })
        .collect();
    let m = model();
    for s in &st {
        let z = m
            .strain(&hylc::shell::assemble::gather(s, &x), &s.rest, s.flaps)
            .unwrap();
        for k in 0..3 {
            assert!(z[k].abs() <= 1e-13, "{z:?}");
        }
        for k in 3..6 {
            assert!(z[k].abs() <= 1e-9, "{z:?}");
        }
    }
}
