//! ARCSim-HYLC scene files: the conversion of every honoured key on a synthetic scene
//! (handlebar strips as exact vertex sets per side, handlespheres, motions, defaults), one warning per ignored or
//! unknown key, one-line errors naming file and key (exit code 2 from the CLI), `--print` giving a scene that runs
//! bitwise like the original file, and the original's 42 scenes converting and building (skipped without
//! `../shared/data/arcsim-hylc`).

mod common;

use hylc::material::synthetic::default_material;
use hylc::shell::arcsim::{self, Converted};
use hylc::shell::motion::Motion;
use hylc::shell::scene::{Interpolation, Keyframe, ObstacleSpec, Scene, Selection, Transform};
use hylc::shell::{Mesh, Psd, ShellError};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Grid vertices per side of the synthetic cloth (OBJ on [0, 1]², step 0.1; scaled by 2 in the scenes).
const N: usize = 11;

/// A folder laid out like ARCSim-HYLC's: `meshes/grid.obj` (the cloth), `meshes/tet.obj` (a closed obstacle), `mats/m.json`, `tests/conf/<scene>.json` (the scene
/// names `meshes/...` and `mats/...` relative to the root, two folders above it).
struct Fixture {
    root: PathBuf,
}

impl Fixture {
    fn new(name: &str) -> Fixture {
        let root = std::env::temp_dir().join(format!("hylc-arcsim-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        for d in ["meshes", "mats", "tests/conf"] {
            std::fs::create_dir_all(root.join(d)).unwrap();
        }
        let mut obj = String::new();
        for j in 0..N {
            for i in 0..N {
                obj += &format!("v {} {} 0\n", i as f64 / 10.0, j as f64 / 10.0);
            }
        }
        for j in 0..N - 1 {
            for i in 0..N - 1 {
                let v = |a: usize, b: usize| b * N + a + 1;
                obj += &format!("f {} {} {}\n", v(i, j), v(i + 1, j), v(i + 1, j + 1));
                obj += &format!("f {} {} {}\n", v(i, j), v(i + 1, j + 1), v(i, j + 1));
            }
        }
        std::fs::write(root.join("meshes/grid.obj"), obj).unwrap();
        // a closed obstacle (a tetrahedron below the cloth)
        std::fs::write(
            root.join("meshes/tet.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n",
        )
        .unwrap();
        default_material().save(&root.join("mats/m.json")).unwrap();
        Fixture { root }
    }

    /// Write `text` as `tests/conf/<name>.json` and return its path.
    fn scene(&self, name: &str, text: &str) -> PathBuf {
        let p = self.root.join(format!("tests/conf/{name}.json"));
        std::fs::write(&p, text).unwrap();
        p
    }

    fn convert(&self, name: &str, text: &str) -> Result<Converted, ShellError> {
        arcsim::load(&self.scene(name, text))
    }
}

impl Drop for Fixture {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

/// A scene using every honoured key, with comments; `{BARS}` is replaced by the handlebars.
const FULL: &str = r#"{
    // the HYLC material
    "hylc": {"material": "mats/m.json", "only1D": true},
    "frame_time": 0.01, /* s */
    "end_time": 0.02,
    "cloths": [{
        "mesh": "meshes/grid.obj",
        "transform": {"scale": 2, "translate": [-1, -1, 0.5], "rotate": [90, 1, 0, 0]},
        "materials": [{"damping": 2e-3}]
    }],
    "wind": {"density": 3, "drag": 0.5, "velocity": [1, 0, 0]},
    "motions": [[
        {"time": 0, "transform": {"translate": [0, 0, 0]}},
        {"time": 0.5, "transform": {"translate": [-0.1, 0, 0]}, "velocity": {"translate": [0, 0, 0.2]}}
    ], [
        {"time": 0, "transform": {"translate": [0, 0, 0]}},
        {"time": 0.25, "transform": {"translate": [0.05, 0, 0.01], "rotate": [0, 0, 0, 1], "scale": 1}},
        {"time": 0.5, "transform": {"translate": [0.1, 0, 0]}}
    ]],
    "handlebars": [{BARS}],
    "handlespheres": [{"center": [-1, -1, 0.5], "radius": 0.25}],
    "handles": [{"nodes": [120], "motion": 0}],
    "obstacles": [{"mesh": "meshes/tet.obj", "transform": {"scale": 0.5, "translate": [0, 0, -1]}, "motion": 0}],
    "gravity": [0, 0, -9.8],
    "obs_friction": 0.2,
    "magic": {"handle_stiffness": 5e4, "repulsion_thickness": 4e-3}
}"#;

/// A strip with `lengthp` 0.6, `widthp` 0.2, `insetp` 0.3 on `side` following motion `motion`: on the 2 × 2 rest
/// square (vertices every 0.2) across the side it covers [0.4, 0.8] from the side (three vertex columns, two on
/// the box's edges, held because the box is grown by 1e-5), along it [0.4, 1.6] (seven vertices).
fn bar(side: usize, motion: usize) -> String {
    format!(
        r#"{{"side": {side}, "lengthp": 0.6, "widthp": 0.2, "insetp": 0.3, "motion": {motion}}}"#
    )
}

fn full(bars: &[String]) -> String {
    FULL.replace("{BARS}", &bars.join(", "))
}

/// The rest layout and initial positions of a converted scene's cloth, as the scene builds them.
fn cloth(scene: &Scene, dir: &Path) -> (Mesh, Vec<[f64; 3]>) {
    let hylc::shell::scene::MeshSpec::Obj { path, transform } = &scene.mesh else {
        panic!("an OBJ mesh")
    };
    let (mut m, x) = Mesh::load_obj(&dir.join(path)).unwrap();
    for r in m.rest.iter_mut() {
        *r = r.map(|c| c * transform.scale);
    }
    (m, x.into_iter().map(|p| transform.apply(p)).collect())
}

/// Grid vertex (i, j) (x index i, y index j).
fn v(i: usize, j: usize) -> usize {
    j * N + i
}

#[test]
fn handlebars_hold_the_exact_strip_on_each_side() {
    let f = Fixture::new("bars");
    let bars: Vec<String> = (0..4).map(|s| bar(s, s % 2)).collect();
    let c = f.convert("bars", &full(&bars)).unwrap();
    let dir = f.root.join("tests/conf");
    let (mesh, x0) = cloth(&c.scene, &dir);
    let across = [2, 3, 4];
    let far = [6, 7, 8];
    let along: Vec<usize> = (2..=8).collect();
    let set = |cols: &[usize], rows: &[usize], swap: bool| -> Vec<usize> {
        let mut s: Vec<usize> = cols
            .iter()
            .flat_map(|&a| {
                rows.iter()
                    .map(move |&b| if swap { v(b, a) } else { v(a, b) })
            })
            .collect();
        s.sort();
        s
    };
    let expected = [
        set(&across, &along, false), // left: x columns 2–4
        set(&across, &along, true),  // bottom: y rows 2–4
        set(&far, &along, false),    // right: x columns 6–8
        set(&far, &along, true),     // top: y rows 6–8
    ];
    let names = ["left", "bottom", "right", "top"];
    // the four bars, then the handle sphere and the node handle
    assert_eq!(c.scene.handles.len(), 6);
    assert_eq!(c.scene.handles[4].name, "sphere0");
    assert_eq!(c.scene.handles[5].name, "nodes0");
    for (s, h) in c.scene.handles.iter().take(4).enumerate() {
        assert_eq!(h.name, names[s]);
        assert!(matches!(h.select, Selection::Box { .. }), "{:?}", h.select);
        assert_eq!(h.select.select(&mesh, &x0), expected[s], "side {s}");
    }
    // the box is the strip grown by 1e-5 in the rest layout (left: x in [0.4, 0.8], y in [0.4, 1.6])
    let Selection::Box { min, max } = &c.scene.handles[0].select else {
        unreachable!()
    };
    for (got, want) in [
        (min[0], 0.4 - 1e-5),
        (max[0], 0.8 + 1e-5),
        (min[1], 0.4 - 1e-5),
        (max[1], 1.6 + 1e-5),
    ] {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    // the simulation builds with these handles (and the handlesphere pin)
    c.scene.build("bars", &dir).unwrap();
}

#[test]
fn motions_handlespheres_and_every_honoured_key() {
    let f = Fixture::new("keys");
    let c = f.convert("keys", &full(&[bar(0, 1)])).unwrap();
    let s = &c.scene;
    assert_eq!(s.name, "keys");
    assert_eq!(s.material, "../../mats/m.json");
    let hylc::shell::scene::MeshSpec::Obj { path, transform } = &s.mesh else {
        panic!("an OBJ mesh")
    };
    assert_eq!(path, "../../meshes/grid.obj");
    assert_eq!(
        *transform,
        Transform {
            scale: 2.0,
            translate: [-1.0, -1.0, 0.5],
            rotate: [90.0, 1.0, 0.0, 0.0]
        }
    );
    assert!(s.model.only_1d);
    assert_eq!((s.dt, s.duration), (0.01, 0.02));
    assert_eq!(s.damping, 2e-3);
    assert_eq!(
        (s.wind.density, s.wind.drag, s.wind.velocity),
        (3.0, 0.5, [1.0, 0.0, 0.0])
    );
    assert_eq!(s.gravity, [0.0, 0.0, -9.8]);
    assert_eq!(s.contact.friction, 0.2);
    assert_eq!(s.contact.thickness, 4e-3);
    assert_eq!(s.handle_stiffness, Some(5e4));
    assert_eq!(s.psd, Psd::Psi);
    assert_eq!(s.output.obj_every, 1);
    // motion 1: three translation keyframes (the identity rotate and scale are accepted), interpolated as
    // ARCSim does
    assert_eq!(
        s.handles[0].keyframes,
        vec![
            Keyframe::at(0.0, [0.0; 3]),
            Keyframe::at(0.25, [0.05, 0.0, 0.01]),
            Keyframe::at(0.5, [0.1, 0.0, 0.0])
        ]
    );
    assert_eq!(s.handles[0].interpolation, Interpolation::Hermite);
    let mut motion0 = Motion::hermite(&[(0.0, [0.0; 3]), (0.5, [-0.1, 0.0, 0.0])]);
    motion0.keyframes[1].velocity = Some([0.0, 0.0, 0.2]);
    assert_eq!(
        s.obstacles,
        vec![ObstacleSpec::Mesh {
            path: "../../meshes/tet.obj".into(),
            transform: Transform {
                scale: 0.5,
                translate: [0.0, 0.0, -1.0],
                rotate: [0.0, 0.0, 0.0, 1.0]
            },
            motion: Some(motion0.clone()),
        }]
    );
    // the node handle: vertex 120 (the far corner) following motion 0, whose last keyframe gives a velocity
    let nodes = &s.handles[2];
    assert_eq!(nodes.name, "nodes0");
    assert_eq!(nodes.select, Selection::Vertices(vec![120]));
    assert_eq!(nodes.motion(), motion0);
    // the handlesphere: a ball of the initial (transformed) positions: vertex (0, 0) sits at its centre,
    // (1, 0) and (0, 1) 0.2 away are inside, (1, 1) 0.28 away is not
    let dir = f.root.join("tests/conf");
    let (mesh, x0) = cloth(s, &dir);
    assert!(s.pins.is_empty());
    let sphere = &s.handles[1];
    assert_eq!(sphere.name, "sphere0");
    assert!(
        sphere.keyframes.is_empty(),
        "a handle sphere without a motion stays put"
    );
    assert_eq!(
        sphere.select,
        Selection::Ball {
            center: [-1.0, -1.0, 0.5],
            radius: 0.25
        }
    );
    assert_eq!(
        sphere.select.select(&mesh, &x0),
        vec![v(0, 0), v(1, 0), v(0, 1)]
    );
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
}

#[test]
fn defaults_are_arcsims() {
    let f = Fixture::new("defaults");
    let text = r#"{"hylc": {"material": "mats/m.json"}, "frame_time": 0.02, "end_time": 1,
        "cloths": [{"mesh": "meshes/grid.obj", "materials": [{}]}]}"#;
    let c = f.convert("defaults", text).unwrap();
    let s = &c.scene;
    assert_eq!(s.wind.density, 1.0);
    assert_eq!((s.wind.drag, s.wind.velocity), (0.0, [0.0; 3]));
    assert_eq!(s.handle_stiffness, Some(1e3));
    assert_eq!(s.contact.thickness, 1e-3);
    assert_eq!(s.contact.friction, 0.3);
    assert_eq!(s.gravity, [0.0; 3]);
    assert_eq!(s.damping, 0.0);
    // implicit Euler with substeps chosen by accuracy (docs/time-study.md)
    assert_eq!(s.solver.time_tol, Some(1e-4));
    assert_eq!(
        s.solver.integrator,
        hylc::shell::solver::Integrator::ImplicitEuler
    );
    assert!(!s.model.only_1d);
    assert!(s.handles.is_empty() && s.pins.is_empty() && s.obstacles.is_empty());
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    // a wind without a density has ARCSim's density 1
    let c = f
        .convert(
            "wind",
            &text.replace(
                "\"end_time\": 1,",
                "\"end_time\": 1, \"wind\": {\"drag\": 2},",
            ),
        )
        .unwrap();
    assert_eq!((c.scene.wind.density, c.scene.wind.drag), (1.0, 2.0));
}

/// `--time-tol off` (`TimeTol::Off`) takes the conversion's `time_tol` away, a length replaces it, and anything else
/// is an error naming the value.
#[test]
fn time_tol_override_turns_the_conversions_off_or_replaces_it() {
    use hylc::workflow::simulate::{prepare, Overrides, TimeTol};
    let f = Fixture::new("timetol");
    let text = r#"{"hylc": {"material": "mats/m.json"}, "frame_time": 0.02, "end_time": 1,
        "cloths": [{"mesh": "meshes/grid.obj", "materials": [{}]}]}"#;
    let path = f.scene("timetol", text);
    let arg = path.to_str().unwrap();
    let with = |t: Option<TimeTol>| {
        let ov = Overrides {
            time_tol: t,
            ..Default::default()
        };
        prepare(arg, &ov).unwrap().0.solver.time_tol
    };
    assert_eq!(with(None), Some(1e-4));
    assert_eq!(with(Some(TimeTol::Off)), None);
    assert_eq!(with(Some(TimeTol::Metres(2e-5))), Some(2e-5));
    assert_eq!("off".parse::<TimeTol>(), Ok(TimeTol::Off));
    assert_eq!("3e-5".parse::<TimeTol>(), Ok(TimeTol::Metres(3e-5)));
    for bad in ["0", "-1e-4", "NaN", "inf", "of"] {
        let e = bad.parse::<TimeTol>().unwrap_err();
        assert!(e.contains(&format!("`{bad}`")), "{e}");
    }
    // the command line names the flag and the value, exit code 2
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["simulate", arg, "--time-tol", "0", "--quiet"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--time-tol") && err.contains("`0`"), "{err}");
}

#[test]
fn ignored_and_unknown_keys_warn_once_each() {
    let f = Fixture::new("warn");
    let text = r#"{
    "hylc": {"enabled": true, "material": "mats/m.json"},
    "disable": ["remeshing"],
    "implicit": true,
    "frame_time": 0.01, "frame_steps": 50, "end_time": 0.02,
    "remeshing": {"size": 1},
    "mystery": 3,
    "cloths": [{
        "mesh": "meshes/grid.obj",
        "materials": [{"data": "materials/gray-interlock.json", "thicken": 1, "damping": 1e-3, "strange": 1}],
        "remeshing": {"refine_angle": 0.3}
    }],
    "magic": {"collision_stiffness": 1e6, "relax_initial_state": false, "handle_stiffness": 1e5, "odd": 2}
}"#;
    let c = f.convert("warn", text).unwrap();
    let keys = [
        "hylc.enabled",
        "disable",
        "implicit",
        "frame_steps",
        "remeshing",
        "mystery",
        "cloths[0].materials[0].data",
        "cloths[0].materials[0].thicken",
        "cloths[0].materials[0].strange",
        "cloths[0].remeshing",
        "magic.collision_stiffness",
        "magic.relax_initial_state",
        "magic.odd",
    ];
    assert_eq!(c.warnings.len(), keys.len(), "{:#?}", c.warnings);
    for k in keys {
        let hits: Vec<&String> = c
            .warnings
            .iter()
            .filter(|w| w.contains(&format!("key `{k}` ")))
            .collect();
        assert_eq!(hits.len(), 1, "{k}: {:#?}", c.warnings);
        assert!(hits[0].contains("warn.json:") && !hits[0].contains('\n'));
    }
    let col = c
        .warnings
        .iter()
        .find(|w| w.contains("collision_stiffness"))
        .unwrap();
    assert!(col.contains("contact.stiffness"), "{col}");
    let steps = c
        .warnings
        .iter()
        .find(|w| w.contains("frame_steps"))
        .unwrap();
    assert!(
        steps.contains("chosen by their estimated error (solver.time_tol 1e-4 m"),
        "{steps}"
    );
    // the honoured keys still apply
    assert_eq!(c.scene.damping, 1e-3);
    assert_eq!(c.scene.handle_stiffness, Some(1e5));
}

/// Bad inputs: (what is replaced in [`FULL`] with one handlebar, by what, the key the error must name).
const BAD: [(&str, &str, &str); 22] = [
    (
        "\"frame_time\": 0.01",
        "\"frame_time\": NaN",
        "`frame_time`",
    ),
    (
        "\"frame_time\": 0.01",
        "\"frame_time\": -0.01",
        "`frame_time`",
    ),
    (
        "\"frame_time\": 0.01",
        "\"frame_time\": \"fast\"",
        "`frame_time`",
    ),
    ("\"end_time\": 0.02,", "", "`end_time`"),
    (
        "{\"damping\": 2e-3}",
        "{\"damping\": -1}",
        "`cloths[0].materials[0].damping`",
    ),
    ("\"side\": 0", "\"side\": 4", "`handlebars[0].side`"),
    ("\"side\": 0", "\"side\": 1.5", "`handlebars[0].side`"),
    (
        "\"lengthp\": 0.6",
        "\"lengthp\": 1.5",
        "`handlebars[0].lengthp`",
    ),
    (
        "\"widthp\": 0.2",
        "\"widthp\": -0.2",
        "`handlebars[0].widthp`",
    ),
    ("\"motion\": 0", "\"motion\": 2", "`handlebars[0].motion`"),
    // a strip between two vertex columns: across x it covers 0.1 ± 1e-5
    (
        "\"widthp\": 0.2, \"insetp\": 0.3",
        "\"widthp\": 0, \"insetp\": 0.05",
        "`handlebars[0]`",
    ),
    (
        "\"rotate\": [0, 0, 0, 1]",
        "\"rotate\": [30, 0, 0, 1]",
        "`motions[1][1].transform.rotate`",
    ),
    (
        "\"scale\": 1}",
        "\"scale\": 2}",
        "`motions[1][1].transform.scale`",
    ),
    (
        "\"center\": [-1, -1, 0.5], \"radius\": 0.25",
        "\"center\": [5, 5, 5], \"radius\": 0.01",
        "`handlespheres[0]`",
    ),
    (
        "{\"time\": 0.5, \"transform\": {\"translate\": [-0.1",
        "{\"time\": 0, \"transform\": {\"translate\": [-0.1",
        "`motions[0][1].time`",
    ),
    (
        "\"velocity\": {\"translate\": [0, 0, 0.2]}",
        "\"velocity\": [0, 0, 0.2]",
        "`motions[0][1].velocity`",
    ),
    (
        "\"velocity\": {\"translate\": [0, 0, 0.2]}",
        "\"velocity\": {\"translate\": [0, 0.2]}",
        "`motions[0][1].velocity.translate`",
    ),
    (
        "\"velocity\": {\"translate\": [0, 0, 0.2]}",
        "\"velocity\": {\"translate\": [0, 0, 0.2], \"rotate\": [10, 0, 0, 1]}",
        "`motions[0][1].velocity.rotate`",
    ),
    ("\"nodes\": [120]", "\"nodes\": [121]", "`handles[0].nodes`"),
    ("\"nodes\": [120]", "\"nodes\": []", "`handles[0].nodes`"),
    (
        "\"nodes\": [120], \"motion\": 0",
        "\"nodes\": [120], \"motion\": 3",
        "`handles[0].motion`",
    ),
    (
        "[0, 0, -1]}, \"motion\": 0",
        "[0, 0, -1]}, \"motion\": -1",
        "`obstacles[0].motion`",
    ),
];

#[test]
fn bad_inputs_are_one_line_errors_naming_file_and_key() {
    let f = Fixture::new("bad");
    let good = full(&[bar(0, 0)]);
    assert!(f.convert("good", &good).is_ok());
    for (i, (from, to, key)) in BAD.iter().enumerate() {
        assert!(good.contains(from), "{from}");
        let text = good.replacen(from, to, 1);
        let name = format!("bad{i}");
        let e = f.convert(&name, &text).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, ShellError::Arcsim { .. }), "{msg}");
        assert!(msg.contains(&format!("{name}.json:")), "{msg}");
        assert!(msg.contains(key), "{key}: {msg}");
        // the CLI: exit code 2, one line on stderr
        let p = f.scene(&name, &text);
        let err = common::cli_error(&["simulate", p.to_str().unwrap(), "--print"]);
        assert!(err.contains(key), "{key}: {err}");
    }
    // a syntax error names the line and column
    let e = f
        .convert(
            "syntax",
            &good.replacen("\"end_time\": 0.02,", "\"end_time\": 0.02", 1),
        )
        .unwrap_err();
    assert!(matches!(e, ShellError::ArcsimSyntax { line: 6, .. }), "{e}");
    let p = f.scene("syntax", "{\"frame_time\": 0.01,\n \"cloths\": [}");
    let err = common::cli_error(&["simulate", p.to_str().unwrap()]);
    assert!(err.contains("syntax.json:2:"), "{err}");
    // a missing mesh names the key
    let e = f
        .convert(
            "nomesh",
            &good.replacen("meshes/grid.obj", "meshes/none.obj", 1),
        )
        .unwrap_err();
    assert!(e.to_string().contains("`cloths[0].mesh`"), "{e}");
}

/// A small stretch: a 0.3 m square of 10 × 10 cells pulled by two strips, with damping, air, gravity and a
/// fixed corner.
const RUN: &str = r#"{
    "hylc": {"material": "mats/m.json"},
    "frame_time": 0.01, "end_time": 0.02,
    "cloths": [{"mesh": "meshes/grid.obj", "transform": {"scale": 0.3, "translate": [-0.15, -0.15, 0]},
                "materials": [{"damping": 1e-3}]}],
    "wind": {"density": 2},
    "motions": [[{"time": 0, "transform": {"translate": [0, 0, 0]}},
                 {"time": 0.5, "transform": {"translate": [-0.02, 0, 0]}}],
                [{"time": 0, "transform": {"translate": [0, 0, 0]}},
                 {"time": 0.5, "transform": {"translate": [0.02, 0, 0]}}]],
    "handlebars": [{"side": 0, "lengthp": 0.6, "widthp": 0.2, "insetp": 0.3, "motion": 0},
                   {"side": 2, "lengthp": 0.6, "widthp": 0.2, "insetp": 0.3, "motion": 1}],
    "handlespheres": [{"center": [-0.15, -0.15, 0], "radius": 0.01}],
    "gravity": [0, 0, -9.81],
    "magic": {"handle_stiffness": 1e4}
}"#;

/// The log lines without their wall-clock times.
fn log_without_wall(dir: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(dir.join("log.jsonl"))
        .unwrap()
        .lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            v.as_object_mut().unwrap().remove("wall");
            v
        })
        .collect()
}

#[test]
fn printed_scene_runs_like_the_arcsim_file() {
    let f = Fixture::new("print");
    let arc = f.scene("arc", RUN);
    let exe = env!("CARGO_BIN_EXE_hylc");
    let out = Command::new(exe)
        .args(["simulate", arc.to_str().unwrap(), "--print"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let printed = String::from_utf8(out.stdout).unwrap();
    let ours = f.root.join("tests/conf/ours.json");
    std::fs::write(&ours, &printed).unwrap();
    let converted = arcsim::load(&arc).unwrap().scene;
    assert_eq!(
        Scene::from_json_str(&printed, "ours.json").unwrap(),
        converted
    );
    let mut logs = Vec::new();
    for (scene, name) in [(&arc, "a"), (&ours, "b")] {
        let dir = f.root.join(format!("out-{name}"));
        let o = Command::new(exe)
            .args(["simulate", scene.to_str().unwrap(), "--quiet", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        // the frame without its header (the header names the command line, which differs)
        let frame: String = std::fs::read_to_string(dir.join("frame_0002.obj"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| format!("{l}\n"))
            .collect();
        logs.push((log_without_wall(&dir), frame));
    }
    assert_eq!(logs[0].0.len(), 2);
    assert_eq!(logs[0], logs[1]);
}

#[test]
fn the_originals_scenes_convert_and_build() {
    let Some(shared) = common::shared_or_skip("the_originals_scenes_convert_and_build") else {
        return;
    };
    let root = shared.join("data/arcsim-hylc");
    if !root.is_dir() {
        eprintln!(
            "SKIPPED the_originals_scenes_convert_and_build: {} not found",
            root.display()
        );
        return;
    }
    let mut files = Vec::new();
    for set in ["1D", "2D", "small"] {
        for e in std::fs::read_dir(root.join("tests").join(set).join("conf")).unwrap() {
            files.push(e.unwrap().path());
        }
    }
    files.sort();
    assert_eq!(files.len(), 42);
    let builtin = |n: &str| hylc::shell::scene::builtin(n).unwrap();
    for p in &files {
        let c = arcsim::load(p).unwrap_or_else(|e| panic!("{e}"));
        let name = p.display().to_string();
        let dir = p.parent().unwrap();
        let (sim, tris) = c.scene.build(&name, dir).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(tris.len(), 5168, "{name}");
        assert_eq!(sim.pattern.n, 2625, "{name}");
        let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
        assert_eq!(c.scene.model.only_1d, name.contains("/1D/"), "{name}");
        if stem.contains("stretch") {
            // the strips match the built-ins' (the original's handlebar geometry), grown by 1e-5
            let b = builtin(if stem.ends_with('X') {
                "stretch-x"
            } else {
                "stretch-y"
            });
            assert_eq!(c.scene.handles.len(), 2, "{name}");
            for (h, hb) in c.scene.handles.iter().zip(&b.handles) {
                let (
                    Selection::Box { min, max },
                    Selection::Box {
                        min: bmin,
                        max: bmax,
                    },
                ) = (&h.select, &hb.select)
                else {
                    panic!("{name}: box selections")
                };
                assert_eq!(h.name, hb.name, "{name}");
                for k in 0..2 {
                    assert!((min[k] - (bmin[k] - 1e-5)).abs() < 1e-12, "{name}");
                    assert!((max[k] - (bmax[k] + 1e-5)).abs() < 1e-12, "{name}");
                }
            }
        } else {
            // the handle spheres are fixed handles, each reporting its reaction by name
            let names: Vec<&str> = c.scene.handles.iter().map(|h| h.name.as_str()).collect();
            assert_eq!(names, ["sphere0", "sphere1"], "{name}");
            assert!(
                c.scene.handles.iter().all(|h| h.keyframes.is_empty()),
                "{name}"
            );
            assert!(c.scene.pins.is_empty(), "{name}");
            assert_eq!(c.scene.obstacles.len(), 1, "{name}");
        }
    }
}

#[test]
fn damaged_scenes_are_errors_never_panics() {
    let f = Fixture::new("damaged");
    let good = full(&[bar(0, 0)]);
    let chars: Vec<char> = good.chars().collect();
    let dir = f.root.join("tests/conf");
    let mut errors = 0;
    for i in 0..chars.len() {
        // the scene cut after i characters, and the scene without its i-th character
        let cut: String = chars[..i].iter().collect();
        let gap: String = chars[..i].iter().chain(&chars[i + 1..]).collect();
        for text in [cut, gap] {
            match arcsim::convert_str(&text, "damaged.json", &dir) {
                Ok(_) => {}
                Err(e) => {
                    let msg = e.to_string();
                    assert!(
                        msg.starts_with("damaged.json:") && !msg.contains('\n'),
                        "{msg}"
                    );
                    errors += 1;
                }
            }
        }
    }
    assert!(errors > chars.len(), "{errors} errors");
}

#[test]
fn our_scenes_and_builtins_are_not_taken_for_arcsim() {
    for name in hylc::shell::scene::BUILTINS {
        let s = hylc::shell::scene::builtin(name).unwrap();
        let text = serde_json::to_string_pretty(&s).unwrap();
        assert!(!arcsim::is_arcsim(&text), "{name}");
        let (loaded, _, notes) = arcsim::load_scene(name).unwrap();
        assert_eq!(loaded, s);
        assert!(notes.is_empty());
    }
    assert!(arcsim::is_arcsim("{\"frame_time\": 0.01 // a comment\n}"));
    assert!(arcsim::is_arcsim("{\"cloths\": [}"));
    assert!(!arcsim::is_arcsim("{\"mesh\": 1, \"cloths\": []}"));
}
