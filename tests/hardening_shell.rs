//! Hardening (`docs/robustness.md`) of the cloth scenes: sizes against documented limits before any allocation,
//! physical parameters in range with the field named, vertex selections checked, a byte-order mark accepted, a
//! diverging run stopped with an error, and `hylc simulate`'s exit codes (0 complete, 2 bad input, 3 did not converge).

mod common;

use hylc::material::synthetic::default_material;
use hylc::shell::element::{ElementModel, ModelFlags, Psd};
use hylc::shell::mesh::{Mesh, MAX_TRIANGLES, MAX_VERTICES};
use hylc::shell::scene::{self, MeshSpec, Scene, Selection};
use hylc::shell::solver::{Boundary, Settings, Simulation};
use hylc::shell::ShellError;
use std::path::Path;

/// A scratch file in a folder of this test process.
fn temp_file(name: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hylc-hardening-shell-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The built-in `name` on a coarse 10 × 10 mesh (fast).
fn coarse(name: &str) -> Scene {
    let mut s = scene::builtin(name).unwrap();
    s.mesh = MeshSpec::Rectangle {
        width: 0.3,
        height: 0.3,
        edge: 0.02,
        perturb: 0.0,
        seed: 1,
    };
    s.duration = 0.05;
    s
}

/// The error message of building `s`.
fn build_error(s: &Scene) -> String {
    match s.build("scene.json", Path::new(".")) {
        Ok(_) => panic!("the scene was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn rectangle_sizes_are_checked_in_floating_point_before_any_allocation() {
    for (w, h, e) in [
        (1e308, 0.3, 0.01),
        (0.3, 0.3, 1e-300),
        (0.3, 1e300, 1e-300),
        (1e18, 1e18, 1.0),
        (3.0, 3.0, 1e-3),
    ] {
        let err = Mesh::rectangle(w, h, e, 0.0, 1).unwrap_err().to_string();
        assert!(
            err.contains("too many") && err.contains(&MAX_VERTICES.to_string()),
            "{err}"
        );
    }
    for (w, h, e) in [
        (f64::INFINITY, 0.3, 0.01),
        (0.3, 0.3, f64::INFINITY),
        (0.3, -0.3, 0.01),
        (0.3, 0.3, f64::NAN),
    ] {
        let err = Mesh::rectangle(w, h, e, 0.0, 1).unwrap_err().to_string();
        assert!(err.contains("positive finite"), "{err}");
    }
    // the limit itself is reachable: 2 000 × 2 000 cells
    assert!((2001.0f64 * 2001.0) <= MAX_VERTICES as f64);
    // through the command line: one line, exit 2, naming the file and the field
    let scene = temp_file(
        "huge.json",
        r#"{"material": "default", "mesh": {"rectangle": {"width": 1e308, "height": 0.3, "edge": 0.01}}, "duration": 0.1}"#,
    );
    let err = common::cli_error(&["simulate", scene.to_str().unwrap(), "--quiet"]);
    assert!(
        err.contains("huge.json: field `mesh`") && err.contains("too many"),
        "{err}"
    );
    let err = common::cli_error(&["simulate", "drape-x", "--edge", "1e-300", "--quiet"]);
    assert!(err.contains("too many"), "{err}");
}

#[test]
fn obj_vertex_and_triangle_counts_are_limited() {
    let mut text = String::with_capacity(8 * (MAX_VERTICES + 1));
    for _ in 0..=MAX_VERTICES {
        text.push_str("v 0 0 0\n");
    }
    let err = Mesh::parse_obj(&text, "big.obj").unwrap_err().to_string();
    assert!(
        err.starts_with(&format!("big.obj:{}", MAX_VERTICES + 1))
            && err.contains("vertices (the limit"),
        "{err}"
    );
    // one polygon fanning into more triangles than the limit
    let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    for _ in 0..MAX_TRIANGLES + 3 {
        text.push_str(" 1");
    }
    let err = Mesh::parse_obj(&text, "fan.obj").unwrap_err().to_string();
    assert!(
        err.starts_with("fan.obj:4") && err.contains("triangles (the limit"),
        "{err}"
    );
}

/// A change to a scene.
type Change = Box<dyn Fn(&mut Scene)>;

#[test]
fn physical_parameters_out_of_range_are_errors_naming_the_field() {
    let cases: Vec<(&str, Change)> = vec![
        ("field `drag`", Box::new(|s| s.drag = -1.0)),
        (
            "field `model.bending_scale`",
            Box::new(|s| s.model.bending_scale = -1.0),
        ),
        (
            "field `gravity`",
            Box::new(|s| s.gravity = [0.0, 0.0, -1e300]),
        ),
        (
            "field `gravity`",
            Box::new(|s| s.gravity = [0.0, 0.0, -1.0001 * scene::MAX_GRAVITY]),
        ),
        ("field `dt`", Box::new(|s| s.dt = 2.0 * s.duration)),
        (
            "field `dt`",
            Box::new(|s| {
                s.duration = 1e5;
                s.dt = 1e-3
            }),
        ),
        (
            "field `solver.max_newton`",
            Box::new(|s| s.solver.max_newton = scene::MAX_NEWTON + 1),
        ),
        (
            "field `contact.stiffness`",
            Box::new(|s| s.contact.stiffness = -1.0),
        ),
        (
            "field `contact.thickness`",
            Box::new(|s| s.contact.thickness = f64::INFINITY),
        ),
        ("field `dt`", Box::new(|s| s.dt = 1e-12)),
        (
            "field `placement.origin`",
            Box::new(|s| s.placement.origin = [1e300, 0.0, 0.0]),
        ),
        (
            "field `placement`",
            Box::new(|s| s.placement.u = [1e200, 0.0, 0.0]),
        ),
        (
            "field `handles[0].keyframes`",
            Box::new(|s| {
                s.handles = scene::builtin("stretch-x").unwrap().handles;
                s.pins.clear();
                s.handles[0].keyframes[1].offset = [1e300, 0.0, 0.0];
            }),
        ),
        (
            "field `handles[0].keyframes`: keyframe 1: the velocity",
            Box::new(|s| {
                s.handles = scene::builtin("stretch-x").unwrap().handles;
                s.pins.clear();
                s.handles[0].keyframes[1].velocity = Some([f64::NAN, 0.0, 0.0]);
            }),
        ),
        (
            "field `handles[1].keyframes`: keyframe 0 gives a velocity, which only a Hermite motion uses",
            Box::new(|s| {
                s.handles = scene::builtin("stretch-x").unwrap().handles;
                s.pins.clear();
                s.handles[1].interpolation = hylc::shell::scene::Interpolation::Linear;
                s.handles[1].keyframes[0].velocity = Some([0.0; 3]);
            }),
        ),
        (
            "field `obstacles[0].motion`: keyframe 1: times must increase, got 0.5 after 0.5",
            Box::new(|s| {
                let mut m = hylc::shell::motion::Motion::hermite(&[(0.5, [0.0; 3]), (0.5, [0.0; 3])]);
                m.keyframes[0].velocity = None;
                s.obstacles = vec![hylc::shell::scene::ObstacleSpec::Sphere {
                    center: [0.0, 0.0, -1.0],
                    radius: 0.5,
                    motion: Some(m),
                }]
            }),
        ),
        (
            "field `obstacles[0]`",
            Box::new(|s| {
                s.obstacles = vec![hylc::shell::scene::ObstacleSpec::Sphere {
                    center: [0.0, 0.0, -1e300],
                    radius: 1.0,
                    motion: None,
                }]
            }),
        ),
        (
            "field `solver.time_tol`: must be a positive length (m) or null, got 0",
            Box::new(|s| s.solver.time_tol = Some(0.0)),
        ),
        (
            "field `solver.time_tol`: must be a positive length (m) or null, got NaN",
            Box::new(|s| s.solver.time_tol = Some(f64::NAN)),
        ),
        (
            "field `fabric_angle_deg`",
            Box::new(|s| s.fabric_angle_deg = f64::NAN),
        ),
        (
            "field `model.fold_barrier.angle`",
            Box::new(|s| {
                s.model.fold_barrier = Some(hylc::shell::fold::FoldBarrier {
                    angle: 3.2,
                    stiffness: 1.0,
                })
            }),
        ),
        (
            "field `model.collapse_barrier.area`",
            Box::new(|s| {
                s.model.collapse_barrier = Some(hylc::shell::fold::CollapseBarrier {
                    area: 1.0,
                    stiffness: 1.0,
                })
            }),
        ),
        (
            "field `model.fold_barrier.stiffness`",
            Box::new(|s| {
                s.model.fold_barrier = Some(hylc::shell::fold::FoldBarrier {
                    angle: 2.0,
                    stiffness: -1.0,
                })
            }),
        ),
        (
            "field `obstacles[0]`",
            Box::new(|s| {
                s.obstacles = vec![hylc::shell::scene::ObstacleSpec::Plane {
                    point: [0.0; 3],
                    normal: [0.0, 0.0, 1e-200],
                    motion: None,
                }]
            }),
        ),
    ];
    for (want, change) in cases {
        let mut s = coarse("drape-x");
        change(&mut s);
        let err = build_error(&s);
        assert!(
            err.starts_with("scene.json: ") && err.contains(want),
            "{want}: {err}"
        );
    }
    // the boundaries themselves are admissible
    let mut s = coarse("drape-x");
    s.drag = 0.0;
    s.model.bending_scale = 0.0;
    s.gravity = [0.0, 0.0, -scene::MAX_GRAVITY];
    s.dt = s.duration;
    assert!(s.build("scene.json", Path::new(".")).is_ok());
    // a duration of zero takes no step whatever dt
    let mut s = coarse("drape-x");
    s.duration = 0.0;
    assert!(s.build("scene.json", Path::new(".")).is_ok());
    assert_eq!(s.steps(), 0);
}

#[test]
fn vertex_indices_out_of_range_name_the_index() {
    let mut s = coarse("drape-x");
    s.pins.push(Selection::Vertices(vec![0, 5, 1_000_000_000]));
    let err = build_error(&s);
    assert!(
        err.contains("field `pins[2]`") && err.contains("vertex index 1000000000 out of range"),
        "{err}"
    );
    let mut s = coarse("stretch-x");
    s.handles[1].select = Selection::Vertices(vec![3, 256]);
    let err = build_error(&s);
    assert!(
        err.contains("field `handles[1].select`")
            && err.contains("vertex index 256 out of range (the mesh has 256"),
        "{err}"
    );
    // the last vertex is fine
    s.handles[1].select = Selection::Vertices(vec![255]);
    assert!(s.build("scene.json", Path::new(".")).is_ok());
}

#[test]
fn scene_json_accepts_a_byte_order_mark() {
    let text = r#"{"material": "default", "mesh": {"rectangle": {"width": 0.1, "height": 0.1, "edge": 0.01}}, "duration": 0.1}"#;
    let plain = Scene::from_json_str(text, "a.json").unwrap();
    let bom = Scene::from_json_str(&format!("\u{feff}{text}"), "b.json").unwrap();
    assert_eq!(plain, bom);
    let p = temp_file("bom.json", &format!("\u{feff}{text}"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["simulate", p.to_str().unwrap(), "--print"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_material_with_a_non_finite_energy_is_reported_as_such() {
    let mut material = default_material();
    material.constant = f64::NAN;
    let flags = ModelFlags {
        bending: true,
        only_1d: false,
        in_plane_only: false,
        stiffness: 1.0,
        bending_scale: 1.0,
        fold: None,
        collapse: None,
    };
    let model = ElementModel::new(&material, &flags, Psd::Psi);
    let mesh = Mesh::rectangle(0.1, 0.1, 0.02, 0.0, 1).unwrap();
    let x0 = mesh.place([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let err = Simulation::new(
        model,
        mesh.stencils(0.0).unwrap(),
        x0,
        Boundary::default(),
        Settings::default(),
        1.0,
    )
    .err()
    .expect("a NaN material is an error");
    assert!(
        matches!(
            err,
            ShellError::NonFiniteMaterial {
                triangle: 0,
                step: None,
                ..
            }
        ),
        "{err}"
    );
    assert!(
        err.to_string().contains("material's energy is not finite"),
        "{err}"
    );
}

#[test]
fn a_diverging_run_stops_with_an_error() {
    let s = coarse("hanging");
    let (mut sim, tris) = s.build("hanging", Path::new(".")).unwrap();
    // the library takes the settings as given: an absurd gravity makes the step's forces overflow
    sim.settings.gravity = [0.0, 0.0, -1e300];
    let err = scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap_err();
    assert!(
        matches!(err, ShellError::NonFiniteState { step: 1, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("diverged"), "{err}");
}

#[test]
fn simulate_exits_3_when_a_step_fails_even_halved_and_0_when_complete() {
    let base = r#""material": "default", "mesh": {"rectangle": {"width": 0.1, "height": 0.1, "edge": 0.02}},
        "duration": 0.05, "pins": [{"near": {"point": [0, 0], "radius": 0.001}}]"#;
    let capped = temp_file(
        "capped.json",
        &format!(r#"{{{base}, "solver": {{"max_newton": 1, "force_tol": 1e-12}}}}"#),
    );
    let ok = temp_file("ok.json", &format!("{{{base}}}"));
    let run = |scene: &Path, out: &str| {
        let dir =
            std::env::temp_dir().join(format!("hylc-hardening-shell-{}-{out}", std::process::id()));
        std::process::Command::new(env!("CARGO_BIN_EXE_hylc"))
            .args([
                "simulate",
                scene.to_str().unwrap(),
                "--quiet",
                "--out",
                dir.to_str().unwrap(),
            ])
            .output()
            .unwrap()
    };
    let out = run(&capped, "capped");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("Newton did not converge even with the time step halved 6 times"),
        "{err}"
    );
    let out = run(&ok, "ok");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A scene with duration 0 runs (frame 0 only) and says so in one warning line.
#[test]
fn duration_zero_warns_once() {
    let out = std::env::temp_dir().join(format!("hylc-duration0-{}", std::process::id()));
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args([
            "simulate",
            "stretch-x",
            "--duration",
            "0",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("duration 0")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].starts_with("warning: duration 0 s: no step is simulated"),
        "{err}"
    );
    assert!(out.join("frame_0000.obj").exists());
    let _ = std::fs::remove_dir_all(&out);
}

/// `hylc simulate SCENE --quiet --out (scratch folder)` with extra arguments: its stderr lines that start with
/// `warning:` and contain `needle`.
fn simulate_warnings(name: &str, args: &[&str], needle: &str) -> Vec<String> {
    let out = std::env::temp_dir().join(format!("hylc-warn-{name}-{}", std::process::id()));
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_hylc"))
        .arg("simulate")
        .args(args)
        .args(["--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    let _ = std::fs::remove_dir_all(&out);
    err.lines()
        .filter(|l| l.starts_with("warning:") && l.contains(needle))
        .map(str::to_string)
        .collect()
}

/// Strains outside the material's knots: one warning after the run naming the component, its visited range
/// against the knots and the steps outside, with `hylc scene-plan` on the run's log; silent when the run stays
/// inside, and silent on the bending components when bending is off.
#[test]
fn strains_outside_the_knots_warn_once() {
    // the default material with s_x's knots squeezed to about ±1e-3: any stretch leaves them
    let mut m = default_material();
    m.strain_scale[0] = 1e-3;
    let narrow = temp_file("narrow.material.json", &m.to_json_string());
    let base = [
        "stretch-x",
        "--duration",
        "0.05",
        "--edge",
        "0.02",
        "--no-bending",
    ];
    let mut args = base.to_vec();
    args.extend(["--material", narrow.to_str().unwrap()]);
    let w = simulate_warnings("narrow", &args, "knots");
    assert_eq!(w.len(), 1, "{w:?}");
    let w = &w[0];
    assert!(
        w.starts_with("warning: strains outside the material's fitted knots, where ψ extrapolates: s_x visited [")
            && w.contains("knots [-6.000e-4, 9.000e-4]")
            && w.contains("in 3 of 3 steps")
            && w.contains("hylc scene-plan ")
            && w.contains("log.jsonl"),
        "{w}"
    );
    assert!(!w.contains("II00") && !w.contains("II11"), "{w}");
    // the default material's knots hold this short stretch
    assert!(simulate_warnings("inside", &base, "knots").is_empty());
}

/// A mesh edge longer than a quarter of the cloth's bounding-box diagonal: one warning before the run; a finer
/// mesh is silent.
#[test]
fn a_mesh_too_coarse_to_bend_warns_once() {
    let w = simulate_warnings(
        "coarse",
        &["drape-x", "--duration", "0", "--edge", "0.1"],
        "too coarse",
    );
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("warning: the longest mesh edge, ")
            && w[0]
                .contains("quarter of the cloth's bounding-box diagonal (0.4243 m / 4 = 0.1061 m)"),
        "{}",
        w[0]
    );
    let fine = ["drape-x", "--duration", "0", "--edge", "0.05"];
    assert!(simulate_warnings("fine", &fine, "too coarse").is_empty());
}
