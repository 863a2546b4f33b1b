//! The physics of the original's scenes in our incremental-potential solver (`docs/cloth-simulator.md`): lagged Coulomb
//! friction (a cloth on a tilted plane sticks below the friction angle and slides above it with Coulomb's
//! acceleration), air drag (terminal velocity ρ_A g = ρ v²), stiffness-proportional damping (dissipates), handle
//! springs (their reaction is the spring force and tends to the hard constraint's as k grows), triangle-mesh obstacles
//! (a cloth comes to rest on a closed mesh without passing through it; a non-manifold mesh is refused) and adaptive
//! substeps.

use hylc::checks::shell_external::icosahedron;
use hylc::shell::scene::{self, MeshSpec, ObstacleSpec, Placement, Scene, Transform};
use hylc::shell::ShellError;
use std::path::{Path, PathBuf};

/// A folder of this test process.
fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hylc-shell-physics-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A free square of side `side` (edge `edge`), in-plane stiffness only, no obstacles.
fn square(side: f64, edge: f64) -> Scene {
    let mut s = scene::builtin("hanging").unwrap();
    s.mesh = MeshSpec::Rectangle {
        width: side,
        height: side,
        edge,
        perturb: 0.0,
        seed: 1,
    };
    s.placement = Placement::default();
    s.pins.clear();
    s.drag = 0.0;
    s.model.bending = false;
    s
}

/// Mean position of the cloth after running `s`.
fn run_mean(s: &Scene) -> ([f64; 3], [f64; 3], hylc::shell::solver::Simulation) {
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    let start = mean(&sim.positions());
    scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
    (start, mean(&sim.positions()), sim)
}

fn mean(x: &[[f64; 3]]) -> [f64; 3] {
    let n = x.len() as f64;
    std::array::from_fn(|k| x.iter().map(|p| p[k]).sum::<f64>() / n)
}

/// Distance travelled down a plane tilted by `deg` with friction μ = 0.5 (friction angle 26.57°) in 0.5 s.
fn slide(deg: f64) -> f64 {
    let th = deg.to_radians();
    let (sn, cs) = th.sin_cos();
    let mut s = square(0.04, 0.01);
    s.duration = 0.5;
    s.contact.friction = 0.5;
    s.contact.friction_velocity = 1e-4;
    let n = [-sn, 0.0, cs];
    // rest at the penalty's equilibrium penetration p = √(g cos θ / k) inside the layer δ
    let pen = (9.81 * cs / s.contact.stiffness).sqrt();
    let d = s.contact.thickness - pen;
    s.placement = Placement {
        origin: n.map(|c| c * d),
        u: [cs, 0.0, sn],
        v: [0.0, 1.0, 0.0],
    };
    s.obstacles = vec![ObstacleSpec::Plane {
        point: [0.0; 3],
        normal: n,
        motion: None,
    }];
    let (a, b, _) = run_mean(&s);
    // downhill is −u
    -((b[0] - a[0]) * cs + (b[2] - a[2]) * sn)
}

#[test]
fn a_cloth_on_a_tilted_plane_sticks_below_the_friction_angle_and_slides_above_it() {
    let stick = slide(15.0);
    assert!(stick.abs() < 1e-4, "moved {stick} m at 15° (μ = 0.5)");
    let th = 40f64.to_radians();
    let expected = 0.5 * 9.81 * (th.sin() - 0.5 * th.cos()) * 0.25;
    let slid = slide(40.0);
    assert!(
        (slid - expected).abs() < 0.05 * expected,
        "slid {slid} m at 40°, Coulomb predicts {expected} m"
    );
}

#[test]
fn air_drag_gives_the_terminal_velocity() {
    let mut s = square(0.06, 0.02);
    s.duration = 1.5;
    s.wind.density = 1.0;
    let (_, _, sim) = run_mean(&s);
    let vz = sim.v.chunks(3).map(|v| v[2]).sum::<f64>() / (sim.v.len() / 3) as f64;
    // ρ_A g = ρ v² with the material's areal density ρ_A
    let vt = (sim.model.material.density * 9.81 / 1.0).sqrt();
    assert!((vz + vt).abs() < 5e-3 * vt, "v_z {vz}, terminal {vt}");
}

/// Total mechanical energy of the hanging built-in after 0.3 s with damping c.
fn hanging_energy(c: f64) -> f64 {
    let mut s = scene::builtin("hanging").unwrap();
    s.mesh = MeshSpec::Rectangle {
        width: 0.3,
        height: 0.3,
        edge: 0.03,
        perturb: 0.0,
        seed: 1,
    };
    s.duration = 0.3;
    s.drag = 0.0;
    s.damping = c;
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    let sum = scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
    let r = sum.last.unwrap();
    r.energy_elastic + r.energy_kinetic + r.energy_gravity
}

#[test]
fn stiffness_proportional_damping_dissipates() {
    let e0 = hanging_energy(0.0);
    let e1 = hanging_energy(0.01);
    // both start at zero energy and lose it as the cloth falls; damping loses more
    assert!(
        e1 < e0 - 0.01 * e0.abs(),
        "E(c = 0.01) {e1} J, E(c = 0) {e0} J"
    );
}

/// The right handle's x force at the end of the coarse stretch-x with the given handle stiffness.
fn stretch_force(k: Option<f64>) -> f64 {
    let mut s = scene::builtin("stretch-x").unwrap();
    s.mesh = MeshSpec::Rectangle {
        width: 0.3,
        height: 0.3,
        edge: 0.02,
        perturb: 0.0,
        seed: 1,
    };
    s.duration = 0.1;
    s.handle_stiffness = k;
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    let sum = scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
    let r = sum.last.unwrap();
    if let Some(k) = k {
        // the logged reaction is the spring force Σ k (target − x) over the handle's vertices
        let hd = &sim.handles[1];
        let o = hd.offset(sim.time);
        let f: f64 = hd
            .vertices
            .iter()
            .map(|&v| k * (sim.x0[3 * v] + o[0] - sim.x[3 * v]))
            .sum();
        assert!((f - r.handle_forces[1].1[0]).abs() <= 1e-12 * f.abs());
    }
    r.handle_forces[1].1[0]
}

#[test]
fn handle_springs_report_their_force_and_tend_to_the_hard_constraint() {
    let hard = stretch_force(None);
    let soft = stretch_force(Some(1e3));
    let stiff = stretch_force(Some(1e6));
    assert!(hard > 0.0);
    assert!(
        (stiff - hard).abs() < 0.01 * hard,
        "k = 1e6: {stiff} N, hard: {hard} N"
    );
    assert!(
        (soft - hard).abs() > (stiff - hard).abs(),
        "k = 1e3: {soft} N"
    );
}

fn write_obj(path: &Path, v: &[[f64; 3]], f: &[[usize; 3]]) {
    let mut t = String::new();
    for p in v {
        t += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for q in f {
        t += &format!("f {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1);
    }
    std::fs::write(path, t).unwrap();
}

#[test]
fn a_cloth_rests_on_a_mesh_obstacle_without_passing_through_it() {
    let dir = temp_dir("mesh");
    let (v, f) = icosahedron([0.0; 3], 1.0);
    write_obj(&dir.join("ico.obj"), &v, &f);
    let mut s = square(0.08, 0.01);
    s.placement.origin = [-0.04, -0.04, 0.031];
    s.duration = 0.4;
    s.drag = 2.0;
    s.contact.friction = 0.3;
    s.obstacles = vec![ObstacleSpec::Mesh {
        path: "ico.obj".into(),
        transform: Transform {
            scale: 0.03,
            ..Transform::default()
        },
        motion: None,
    }];
    let (mut sim, tris) = s.build("scene.json", &dir).unwrap();
    scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap();
    let ob = s.obstacles("scene.json", &dir).unwrap();
    let d: Vec<f64> = sim
        .positions()
        .iter()
        .map(|p| ob[0].proximity(*p).d)
        .collect();
    let dmin = d.iter().copied().fold(f64::INFINITY, f64::min);
    // never through the surface, and resting in its layer (the vertices over the top)
    assert!(dmin > 0.0, "a vertex is {dmin} m inside the obstacle");
    assert!(dmin < s.contact.thickness, "nothing touches: {dmin} m");
    // a non-manifold mesh (three triangles on one edge) is refused with the file named
    write_obj(
        &dir.join("fan.obj"),
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        &[[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    s.obstacles = vec![ObstacleSpec::Mesh {
        path: "fan.obj".into(),
        transform: Transform::default(),
        motion: None,
    }];
    let err = s.build("scene.json", &dir).err().unwrap().to_string();
    assert!(
        err.contains("scene.json: obstacles[0]") && err.contains("fan.obj"),
        "{err}"
    );
}

#[test]
fn steps_that_do_not_converge_are_retried_with_halved_substeps() {
    let mut s = scene::builtin("stretch-x").unwrap();
    s.mesh = MeshSpec::Rectangle {
        width: 0.3,
        height: 0.3,
        edge: 0.02,
        perturb: 0.0,
        seed: 1,
    };
    s.duration = 0.1;
    s.solver.max_newton = 3;
    s.solver.force_tol = 1e-9;
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    let mut substeps = vec![];
    scene::run(&mut sim, &tris, s.steps(), 0, None, |r| {
        assert!(r.converged);
        substeps.push((r.substeps, r.dt_min));
    })
    .unwrap();
    assert!(
        substeps.iter().any(|&(n, _)| n > 1),
        "no step needed substeps: {substeps:?}"
    );
    // the smallest substep of a step is dt / 2^k, k ≤ max_halvings, and smaller than dt when there are several
    for &(n, h) in &substeps {
        let level = (s.dt / h).log2();
        assert!(
            (level - level.round()).abs() < 1e-9 && level.round() <= 6.0,
            "{n} {h}"
        );
        assert!(n == 1 || h < s.dt, "{n} substeps of at least {h} s");
    }
    // with no halving allowed the same scene stops with StepFailed
    s.solver.max_halvings = 0;
    let (mut sim, tris) = s.build("scene.json", Path::new(".")).unwrap();
    let err = scene::run(&mut sim, &tris, s.steps(), 0, None, |_| {}).unwrap_err();
    assert!(matches!(err, ShellError::StepFailed { .. }), "{err}");
}

/// The built-in stretch strips sit where the original's handlebars do (`insetp` 0.16 ± `widthp`/2 = 0.035 of the
/// side in from the edge, the middle `lengthp` 0.67 along it), not on the edge.
#[test]
fn builtin_stretch_strips_follow_the_original_handlebar_geometry() {
    let side = scene::SIDE;
    for (name, across) in [("stretch-x", 0), ("stretch-y", 1)] {
        let s = scene::builtin(name).unwrap();
        let along = 1 - across;
        let (sim, _) = s.build("scene.json", Path::new(".")).unwrap();
        for (i, (h, near_edge)) in s.handles.iter().zip([true, false]).enumerate() {
            // the flat rectangle's initial positions are its rest layout
            let held: Vec<[f64; 3]> = sim.handles[i]
                .vertices
                .iter()
                .map(|&v| std::array::from_fn(|k| sim.x0[3 * v + k]))
                .collect();
            assert!(!held.is_empty(), "{name} {}", h.name);
            for p in &held {
                // distance from the strip's own side, as a fraction of the side
                let d = if near_edge {
                    p[across]
                } else {
                    side - p[across]
                } / side;
                assert!(
                    (0.125 - 1e-9..=0.195 + 1e-9).contains(&d),
                    "{name} {}: {d}",
                    h.name
                );
                let a = p[along] / side;
                assert!(
                    (0.165 - 1e-9..=0.835 + 1e-9).contains(&a),
                    "{name} {}: {a}",
                    h.name
                );
            }
        }
    }
}
