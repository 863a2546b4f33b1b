//! Motions and reactions of held vertex sets in the cloth solver: built-in pulls follow the original's
//! smoothstep, every pin and handle reports its reaction under its name (in the log and in
//! `handle_forces.csv`), and obstacles move with their motion (penalty and friction relative to the obstacle).

mod common;

use hylc::material::synthetic::default_material;
use hylc::shell::motion::Motion;
use hylc::shell::scene::{self, MeshSpec, ObstacleSpec, Placement, Scene};
use hylc::shell::solver::{Boundary, Settings, Simulation};
use hylc::shell::{ElementModel, Mesh, ModelFlags, Psd};
use std::path::Path;

use common::coarse_builtin as coarse;

fn total_mass(sim: &Simulation) -> f64 {
    sim.mass.iter().sum()
}

/// The built-in pulls are the original's motion: a smoothstep of 2 cm over 0.25 s, so the held strip is at
/// x0 + (3s² − 2s³) d after each step (hard constraints), starts and ends at rest, and stays after 0.25 s.
#[test]
fn builtin_pulls_follow_the_smoothstep() {
    let s = coarse("stretch-x", 0.02, 0.3);
    let (mut sim, _) = s.build("scene.json", Path::new(".")).unwrap();
    let right = sim.handles[1].clone();
    for _ in 0..s.steps() {
        sim.step().unwrap();
        let t = sim.time;
        let u = (t / 0.25).min(1.0);
        let want = 0.02 * (3.0 * u * u - 2.0 * u * u * u);
        for &v in &right.vertices {
            let dx = sim.x[3 * v] - sim.x0[3 * v];
            assert!((dx - want).abs() < 1e-15, "t = {t}: {dx} vs {want}");
        }
    }
    // the velocity of the held vertices at the last step is zero (the pull ended at rest)
    for &v in &right.vertices {
        assert!(sim.v[3 * v].abs() < 1e-12, "{}", sim.v[3 * v]);
    }
}

/// A cloth hanging from two pinned corners at rest: every pin reports its reaction under its name, and the
/// reactions carry the weight, Σ F = −M g, with hard constraints and with handle springs.
#[test]
fn pins_report_their_reactions_and_carry_the_weight() {
    for k in [None, Some(1e4)] {
        let mut s = coarse("hanging", 0.05, 2.0);
        s.quasi_static = true;
        s.dt = 0.5;
        s.handle_stiffness = k;
        s.solver.force_tol = 1e-10;
        let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
        let sum = scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
        let r = sum.last.unwrap();
        let names: Vec<&str> = r.handle_forces.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["pin0", "pin1"], "{k:?}");
        let weight = total_mass(&sim) * 9.81;
        let fz: f64 = r.handle_forces.iter().map(|(_, f)| f[2]).sum();
        let fx: f64 = r.handle_forces.iter().map(|(_, f)| f[0]).sum();
        assert!(
            (fz - weight).abs() < 1e-6 * weight,
            "{k:?}: {fz} vs {weight}"
        );
        assert!(fx.abs() < 1e-6 * weight, "{k:?}: {fx}");
        // the corners share the weight, about equally (the triangulation's diagonals all run one way, so the
        // two corner vertices have different triangles: 0.5 % apart on this mesh)
        let (a, b) = (r.handle_forces[0].1[2], r.handle_forces[1].1[2]);
        assert!((a - b).abs() < 0.01 * weight, "{k:?}: {a} vs {b}");
        assert!(a > 0.0 && b > 0.0, "{k:?}: {a} vs {b}");
    }
}

/// A library simulation's pinned vertices report their reaction as `pinned`.
#[test]
fn library_pins_report_as_pinned() {
    let mesh = Mesh::rectangle(0.1, 0.1, 0.025, 0.0, 1).unwrap();
    let x0 = mesh.place([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let top: Vec<usize> = (0..mesh.len())
        .filter(|&v| mesh.rest[v][1] > 0.1 - 1e-9)
        .collect();
    let model = ElementModel::new(&default_material(), &ModelFlags::default(), Psd::Psi);
    let settings = Settings {
        quasi_static: true,
        force_tol: 1e-10,
        ..Settings::default()
    };
    let mut sim = Simulation::new(
        model,
        mesh.stencils(0.0).unwrap(),
        x0,
        Boundary {
            pinned: top,
            ..Boundary::default()
        },
        settings,
        1.0,
    )
    .unwrap();
    let r = sim.step().unwrap();
    assert_eq!(r.handle_forces.len(), 1);
    assert_eq!(r.handle_forces[0].0, "pinned");
    let weight = total_mass(&sim) * 9.81;
    assert!((r.handle_forces[0].1[2] - weight).abs() < 1e-6 * weight);
    assert_eq!(sim.held_set_names().collect::<Vec<_>>(), ["pinned"]);
}

/// `handle_forces.csv` has a column per held set and component, and one row per step equal to the log's.
#[test]
fn the_runner_writes_the_reactions_as_a_table() {
    let s = coarse("stretch-y", 0.05, 0.05);
    let dir = std::env::temp_dir().join(format!("hylc-motions-csv-{}", std::process::id()));
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    scene::run(&mut sim, &tris, s.steps(), 0, Some(&dir), |_| {}).unwrap();
    let csv = std::fs::read_to_string(dir.join("handle_forces.csv")).unwrap();
    let log = std::fs::read_to_string(dir.join("log.jsonl")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time,bottom_fx,bottom_fy,bottom_fz,bottom_norm,top_fx,top_fy,top_fz,top_norm"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), s.steps());
    for (row, entry) in rows.iter().zip(log.lines()) {
        let e: serde_json::Value = serde_json::from_str(entry).unwrap();
        assert_eq!(row[0], e["time"].as_f64().unwrap());
        for h in 0..2 {
            let f: Vec<f64> = (0..3)
                .map(|c| e["handle_forces"][h][1][c].as_f64().unwrap())
                .collect();
            assert_eq!(&row[1 + 4 * h..4 + 4 * h], &f[..]);
            let norm = f.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert_eq!(row[4 + 4 * h], norm);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A small square resting on the plane z = 0 (in its penalty layer), with a plane motion.
fn on_a_plane(motion: Motion, friction: f64) -> Scene {
    let mut s = scene::builtin("hanging").unwrap();
    s.mesh = MeshSpec::Rectangle {
        width: 0.04,
        height: 0.04,
        edge: 0.01,
        perturb: 0.0,
        seed: 1,
    };
    s.pins.clear();
    s.drag = 0.0;
    s.model.bending = false;
    s.duration = 0.6;
    s.contact.friction = friction;
    s.contact.friction_velocity = 1e-4;
    let pen = (9.81 / s.contact.stiffness).sqrt();
    s.placement = Placement {
        origin: [0.0, 0.0, s.contact.thickness - pen],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
    };
    s.obstacles = vec![ObstacleSpec::Plane {
        point: [0.0; 3],
        normal: [0.0, 0.0, 1.0],
        motion: Some(motion),
    }];
    s
}

fn mean_shift(s: &Scene) -> [f64; 3] {
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    let before = sim.positions();
    scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
    let after = sim.positions();
    let n = before.len() as f64;
    std::array::from_fn(|c| {
        after
            .iter()
            .zip(&before)
            .map(|(a, b)| a[c] - b[c])
            .sum::<f64>()
            / n
    })
}

/// A plane rising 2 cm lifts the cloth resting on it by 2 cm; one sliding sideways by 1 cm drags the cloth
/// along with it under friction (μ = 0.5 against an acceleration of at most 0.6 m/s², well below μ g: it
/// sticks), and leaves it behind without friction.
#[test]
fn moving_obstacles_carry_the_cloth() {
    let up = Motion::hermite(&[(0.0, [0.0; 3]), (0.3, [0.0, 0.0, 0.02])]);
    let d = mean_shift(&on_a_plane(up, 0.0));
    assert!((d[2] - 0.02).abs() < 2e-4, "{d:?}");
    let side = Motion::hermite(&[(0.0, [0.0; 3]), (0.3, [0.01, 0.0, 0.0])]);
    let d = mean_shift(&on_a_plane(side.clone(), 0.5));
    assert!((d[0] - 0.01).abs() < 5e-4, "with friction: {d:?}");
    let d = mean_shift(&on_a_plane(side, 0.0));
    assert!(d[0].abs() < 1e-6, "without friction: {d:?}");
}

/// The snapshot's obstacle surfaces are drawn where the obstacles are at the current time.
#[test]
fn obstacle_surfaces_move_with_their_motion() {
    let mut s = coarse("drape-x", 0.05, 0.1);
    let ObstacleSpec::Sphere { motion, .. } = &mut s.obstacles[0] else {
        panic!("the drape's sphere")
    };
    *motion = Some(Motion::linear(&[(0.0, [0.0; 3]), (0.1, [0.0, 0.0, -0.01])]));
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    let z0 = sim.obstacle_surfaces()[0].0[0][2];
    scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
    let z1 = sim.obstacle_surfaces()[0].0[0][2];
    assert!((z1 - z0 + 0.01).abs() < 1e-12, "{z0} → {z1}");
}
