//! Sensitivities of quasi-static equilibria by one adjoint solve (`shell::solver::adjoint`) against central
//! differences of complete re-solves: for the coarse quasi-static `hanging`, `stretch-x` and `drape-x` built-ins
//! with the default material, dJ/dp of several observables for every scene scalar (stiffness, bending scale,
//! mass multiplier, gravity) and for about twenty material coefficients spread over the terms, relative error
//! ≤ 1e-5. Also the cost of one gradient against one Newton iteration of the forward solve (printed).

use hylc::material::coefficients::Coefficient;
use hylc::shell::scene::{self, MeshSpec, ObstacleSpec, Scene};
use hylc::shell::solver::{Observable, Sensitivity, Simulation};
use hylc::shell::ShellError;
use std::path::Path;
use std::time::Instant;

/// The relative tolerance of every compared derivative.
const TOL: f64 = 1e-5;

/// A coarse quasi-static scene, the start's free vertices moved out of the plane by a smooth pattern of
/// amplitude `bump` (a flat start can converge to the symmetric flat equilibrium, a saddle).
#[derive(Clone)]
struct Case {
    scene: Scene,
    bump: f64,
}

/// A coarse quasi-static version of a built-in: steps of `dt` over `duration`, tight force tolerance.
fn coarse(name: &str, edge: f64, duration: f64, dt: f64, bump: f64) -> Case {
    Case {
        scene: coarse_scene(name, edge, duration, dt),
        bump,
    }
}

fn coarse_scene(name: &str, edge: f64, duration: f64, dt: f64) -> Scene {
    let mut s = scene::builtin(name).unwrap();
    s.mesh = MeshSpec::Rectangle {
        width: 0.3,
        height: 0.3,
        edge,
        perturb: 0.0,
        seed: 1,
    };
    s.quasi_static = true;
    s.duration = duration;
    s.dt = dt;
    s.drag = 0.0;
    s.solver.force_tol = 1e-11;
    s.solver.max_newton = 200;
    s
}

/// A parameter of the comparison.
#[derive(Clone, Copy, Debug)]
enum Param {
    Stiffness,
    BendingScale,
    Mass,
    Gravity(usize),
    Coef(Coefficient),
    /// component `axis` of the offset of keyframe `key` of the scene's handle number `handle`
    Keyframe {
        handle: usize,
        key: usize,
        axis: usize,
    },
    /// component `axis` of the position of the scene's obstacle number `index` (a sphere's centre)
    Obstacle {
        index: usize,
        axis: usize,
    },
}

/// The equilibrium of `case` with parameter `p` shifted by `d`.
fn solve(case: &Case, p: Param, d: f64) -> Simulation {
    let mut s = case.scene.clone();
    match p {
        Param::Stiffness => s.model.stiffness += d,
        Param::BendingScale => s.model.bending_scale += d,
        Param::Mass => s.model.mass += d,
        Param::Gravity(c) => s.gravity[c] += d,
        Param::Coef(_) => {}
        Param::Keyframe { handle, key, axis } => s.handles[handle].keyframes[key].offset[axis] += d,
        Param::Obstacle { index, axis } => match &mut s.obstacles[index] {
            ObstacleSpec::Sphere { center, .. } => center[axis] += d,
            _ => unreachable!("the tests move spheres only"),
        },
    }
    let (mut sim, _) = s.build("scene.json", Path::new(".")).unwrap();
    if let Param::Coef(c) = p {
        let m = &sim.model.material;
        sim.model.material = m.with_coefficient(c, m.coefficient(c) + d);
    }
    // out of the plane: y for the vertical `hanging`, z for the others
    let normal = if s.name == "hanging" { 1 } else { 2 };
    for v in 0..sim.pattern.n {
        if sim.pattern.free[v].is_some() {
            let (a, b) = (sim.x0[3 * v], sim.x0[3 * v + 2 - normal]);
            sim.x[3 * v + normal] += case.bump * (7.0 * a + 3.0).sin() * (5.0 * b + 1.0).cos();
        }
    }
    for _ in 0..s.steps() {
        let r = sim.step().unwrap();
        assert!(r.residual <= 1e-10, "{p:?} {d}: residual {}", r.residual);
    }
    sim
}

/// The parameter's value in the base scene and the adjoint's dJ/dp.
fn base_and_adjoint(s: &Scene, sim: &Simulation, sens: &Sensitivity, p: Param) -> (f64, f64) {
    match p {
        Param::Stiffness => (s.model.stiffness, sens.stiffness),
        Param::BendingScale => (s.model.bending_scale, sens.bending_scale),
        Param::Mass => (s.model.mass, sens.mass_multiplier(s.model.mass)),
        Param::Gravity(c) => (s.gravity[c], sens.gravity[c]),
        Param::Coef(c) => (
            sim.model.material.coefficient(c),
            sens.material.as_ref().unwrap().get(c),
        ),
        Param::Keyframe { handle, key, axis } => {
            let h = &s.handles[handle];
            let g = sens.held.iter().find(|g| g.name == h.name).unwrap();
            (h.keyframes[key].offset[axis], g.keyframes[key][axis])
        }
        Param::Obstacle { index, axis } => match &s.obstacles[index] {
            ObstacleSpec::Sphere { center, .. } => (center[axis], sens.obstacles[index][axis]),
            _ => unreachable!("the tests move spheres only"),
        },
    }
}

/// The mean |c| over the array of coefficient `c` (p or m of a 1D term, p, mu, mv or muv of a 2D term).
fn coefficient_scale(sim: &Simulation, c: Coefficient) -> f64 {
    let m = &sim.model.material;
    let same = |k: &Coefficient| match (c, *k) {
        (
            Coefficient::Term1D { term, slope, .. },
            Coefficient::Term1D {
                term: t, slope: s, ..
            },
        ) => term == t && slope == s,
        (
            Coefficient::Term2D { term, array, .. },
            Coefficient::Term2D {
                term: t, array: a, ..
            },
        ) => term == t && array == a,
        _ => false,
    };
    let v: Vec<f64> = m
        .coefficients()
        .iter()
        .filter(|k| same(k))
        .map(|&k| m.coefficient(k).abs())
        .collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Per term (per 1D array; one array per 2D term) the coefficient with the largest |dJ/dc · c|: about twenty
/// coefficients spread over the terms that the equilibrium's strains touch.
fn sample_coefficients(sim: &Simulation, sens: &Sensitivity) -> Vec<Coefficient> {
    let m = &sim.model.material;
    let g = sens.material.as_ref().unwrap();
    let mut best: std::collections::BTreeMap<(usize, usize, usize), (f64, Coefficient)> =
        Default::default();
    for c in m.coefficients() {
        let key = match c {
            Coefficient::Constant => continue,
            Coefficient::Term1D { term, slope, .. } => (1, term, usize::from(slope)),
            // one array per 2D term, turn about
            Coefficient::Term2D { term, array, .. } if array == term % 4 => (2, term, array),
            Coefficient::Term2D { .. } => continue,
        };
        if g.get(c) == 0.0 {
            continue;
        }
        let size = g.get(c).abs() * m.coefficient(c).abs().max(coefficient_scale(sim, c));
        let e = best.entry(key).or_insert((0.0, c));
        if size > e.0 {
            *e = (size, c);
        }
    }
    let top = best.values().map(|v| v.0).fold(0.0, f64::max);
    best.values()
        .filter(|v| v.0 > 1e-6 * top)
        .map(|v| v.1)
        .collect()
}

/// Compare the adjoint's derivatives of `observables` at the equilibrium of `s` against central differences of
/// re-solves for the scene scalars, `extra` parameters and a sample of coefficients (chosen with the first
/// observable); returns the worst relative error.
fn compare(
    name: &str,
    case: &Case,
    observables: &[Observable],
    coefficients: bool,
    extra: &[Param],
) -> f64 {
    let s = &case.scene;
    let base = solve(case, Param::Stiffness, 0.0);
    let sens: Vec<Sensitivity> = observables
        .iter()
        .map(|o| base.sensitivity(o, true).unwrap())
        .collect();
    let mut params = vec![
        Param::Stiffness,
        Param::BendingScale,
        Param::Mass,
        Param::Gravity(0),
        Param::Gravity(1),
        Param::Gravity(2),
    ];
    params.extend_from_slice(extra);
    if coefficients {
        let coefs = sample_coefficients(&base, &sens[0]);
        println!("{name}: {} coefficients sampled", coefs.len());
        assert!(coefs.len() >= 15, "{name}: {} coefficients", coefs.len());
        params.extend(coefs.iter().map(|&c| Param::Coef(c)));
    }
    // each derivative normalised by its parameter's magnitude (dJ/dp · |p|, gravity by |g|); the scale of an
    // observable's derivatives: the largest over the scene scalars
    let magnitude = |p: Param| {
        let (v, _) = base_and_adjoint(s, &base, &sens[0], p);
        let floor = match p {
            Param::Gravity(_) => 9.81,
            // a coefficient by at least the mean size of its array's (a knot value may be 0)
            Param::Coef(c) => coefficient_scale(&base, c),
            // positions in metres: by at least the pull and the sphere's radius
            Param::Keyframe { .. } => 2e-2,
            Param::Obstacle { .. } => 3e-2,
            _ => 1e-2,
        };
        v.abs().max(floor)
    };
    let scale: Vec<f64> = sens
        .iter()
        .map(|se| {
            params[..6]
                .iter()
                .map(|&p| (base_and_adjoint(s, &base, se, p).1 * magnitude(p)).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    let mut worst = 0.0f64;
    let mut worst_small = 0.0f64;
    let mut compared = 0;
    for &p in &params {
        let pm = magnitude(p);
        // the obstacle penalty's curvature changes over the contact's penetration depth (micrometres, where the
        // penalty's third derivative jumps): a step of 1e-5 × 3 cm = 0.3 µm is not small against it, and the
        // difference carries a truncation error of 1e-5 relative; 3 nm is
        let h = match p {
            Param::Obstacle { .. } => 1e-7 * pm,
            _ => 1e-5 * pm,
        };
        let plus = solve(case, p, h);
        let minus = solve(case, p, -h);
        for (k, o) in observables.iter().enumerate() {
            let fd = (plus.observable(o).unwrap() - minus.observable(o).unwrap()) / (2.0 * h);
            let (_, adj) = base_and_adjoint(s, &base, &sens[k], p);
            // a derivative four orders below the observable's scale (one that vanishes by symmetry, or a
            // coefficient barely touched) is compared against that scale: there the differences of re-solves
            // carry the round-off of J (the reaction sums forces that cancel) divided by h
            let negligible = fd.abs().max(adj.abs()) * pm < 1e-4 * scale[k];
            let err = if negligible {
                (adj - fd).abs() * pm / scale[k]
            } else {
                (adj - fd).abs() / fd.abs()
            };
            let what = label(o);
            println!(
                "{name} {what} {p:?}: adjoint {adj:.10e} fd {fd:.10e} rel {err:.2e}{}",
                if negligible { " (negligible)" } else { "" }
            );
            if negligible {
                worst_small = worst_small.max(err);
            } else {
                compared += 1;
                worst = worst.max(err);
            }
            assert!(
                err <= TOL,
                "{name} {what} {p:?}: adjoint {adj:e} fd {fd:e} rel {err:e}"
            );
        }
    }
    println!(
        "{name}: {compared} derivatives compared, worst relative error {worst:.2e}; the small ones: worst error \
         relative to the observable's scale {worst_small:.2e}"
    );
    assert!(compared >= if coefficients { 3 * 15 } else { 6 } + extra.len());
    worst
}

/// A short name of an observable.
fn label(o: &Observable) -> String {
    match o {
        Observable::Target { .. } => "target".into(),
        Observable::Linear { .. } => "linear".into(),
        o => format!("{o:?}"),
    }
}

fn target(sim: &Simulation) -> Observable {
    Observable::Target {
        positions: sim.x0.chunks(3).map(|p| [p[0], p[1], p[2]]).collect(),
    }
}

#[test]
fn hanging_sensitivities_match_resolves() {
    let s = coarse("hanging", 0.3 / 8.0, 1.0, 1.0, 1e-3);
    let base = solve(&s, Param::Stiffness, 0.0);
    let obs = vec![
        Observable::CenterOfMass { axis: 2 },
        Observable::ElasticEnergy,
        Observable::Reaction {
            set: "pin0".into(),
            axis: 2,
        },
        Observable::Reaction {
            set: "pin0".into(),
            axis: 0,
        },
        target(&base),
    ];
    // the cost of one gradient against one Newton iteration of the forward solve
    let t = Instant::now();
    let reps = 5;
    for _ in 0..reps {
        base.newton_direction().unwrap();
    }
    let newton = t.elapsed().as_secs_f64() / reps as f64;
    let t = Instant::now();
    for _ in 0..reps {
        base.sensitivity(&obs[0], false).unwrap();
    }
    let scalars = t.elapsed().as_secs_f64() / reps as f64;
    let t = Instant::now();
    for _ in 0..reps {
        base.sensitivity(&obs[0], true).unwrap();
    }
    let full = t.elapsed().as_secs_f64() / reps as f64;
    println!(
        "hanging ({} vertices, {} triangles): one Newton iteration {:.3} ms, one gradient (scene scalars) {:.3} ms \
         ({:.2}×), with every material coefficient {:.3} ms ({:.2}×)",
        base.pattern.n,
        base.stencils.len(),
        1e3 * newton,
        1e3 * scalars,
        scalars / newton,
        1e3 * full,
        full / newton
    );
    compare("hanging", &s, &obs, true, &[]);
}

#[test]
fn stretch_sensitivities_match_resolves() {
    let s = coarse("stretch-x", 0.3 / 20.0, 0.25, 0.05, 0.0);
    let base = solve(&s, Param::Stiffness, 0.0);
    let obs = vec![
        Observable::Reaction {
            set: "right".into(),
            axis: 0,
        },
        Observable::CenterOfMass { axis: 2 },
        Observable::ElasticEnergy,
        target(&base),
    ];
    let mut obs = obs;
    // a cotangent on the positions (the vector–Jacobian product)
    let weights = (0..base.pattern.n)
        .map(|v| {
            let a = v as f64;
            [
                (0.7 * a).sin(),
                0.3 * (1.3 * a).cos(),
                1.0 + (0.1 * a).sin(),
            ]
        })
        .collect();
    obs.push(Observable::Linear { weights });
    compare("stretch-x", &s, &obs, true, &[]);
}

#[test]
fn drape_sensitivities_match_resolves() {
    let s = coarse("drape-x", 0.3 / 12.0, 1.0, 0.05, 1e-3);
    let base = solve(&s, Param::Stiffness, 0.0);
    let obs = vec![
        Observable::CenterOfMass { axis: 2 },
        Observable::ElasticEnergy,
        Observable::Reaction {
            set: "pin0".into(),
            axis: 2,
        },
        target(&base),
    ];
    match base.sensitivity(&obs[0], false) {
        Err(ShellError::NotStrictMinimum { residual }) => {
            println!("drape-x: not a strict minimum (residual {residual:e})");
        }
        Err(e) => panic!("{e}"),
        Ok(_) => {
            compare("drape-x", &s, &obs, true, &[]);
        }
    }
}

/// Handle springs instead of hard constraints: the reaction is Σ k (p − x) over the handle, depending on the
/// parameters only through x*.
#[test]
fn spring_handle_sensitivities_match_resolves() {
    let mut s = coarse("stretch-x", 0.3 / 20.0, 0.25, 0.05, 0.0);
    s.scene.handle_stiffness = Some(200.0);
    let base = solve(&s, Param::Stiffness, 0.0);
    let obs = vec![
        Observable::Reaction {
            set: "right".into(),
            axis: 0,
        },
        Observable::Reaction {
            set: "left".into(),
            axis: 2,
        },
        Observable::CenterOfMass { axis: 2 },
        target(&base),
    ];
    compare("stretch-x springs", &s, &obs, false, &keyframes());
}

/// Keyframe offsets of the stretch's two handles (`left`, `right`): both keyframes along the pull, the last one
/// across it.
fn keyframes() -> Vec<Param> {
    let k = |handle, key, axis| Param::Keyframe { handle, key, axis };
    vec![k(1, 1, 0), k(0, 1, 0), k(1, 0, 0), k(1, 1, 2), k(0, 1, 1)]
}

/// Halfway through the pull (both keyframes weigh in) over a sphere that lifts the sheet's middle by 5 mm: the
/// handles' keyframe offsets and the sphere's position, hard constraints.
#[test]
fn boundary_sensitivities_match_resolves() {
    let mut s = coarse("stretch-x", 0.3 / 16.0, 0.15, 0.05, 0.0);
    s.scene.obstacles = vec![ObstacleSpec::Sphere {
        center: [0.16, 0.14, -0.025],
        radius: 0.03,
        motion: None,
    }];
    let base = solve(&s, Param::Stiffness, 0.0);
    let obs = vec![
        Observable::Reaction {
            set: "right".into(),
            axis: 0,
        },
        Observable::CenterOfMass { axis: 2 },
        Observable::ElasticEnergy,
        Observable::Reaction {
            set: "left".into(),
            axis: 2,
        },
        target(&base),
    ];
    let mut extra = keyframes();
    extra.extend((0..3).map(|axis| Param::Obstacle { index: 0, axis }));
    compare("stretch-x over a sphere", &s, &obs, false, &extra);
}

/// The typed errors: the flat hanging equilibrium (reached from a flat start) is a saddle, its top compressed
/// between the corners: not a strict minimum; a dynamic simulation; an unknown held set.
#[test]
fn unsupported_cases_are_refused() {
    let flat = coarse("hanging", 0.3 / 8.0, 1.0, 1.0, 0.0);
    let sim = solve(&flat, Param::Stiffness, 0.0);
    match sim.sensitivity(&Observable::CenterOfMass { axis: 2 }, false) {
        Err(ShellError::NotStrictMinimum { residual }) => assert!(residual <= 1e-10),
        other => panic!("{other:?}"),
    }
    let mut s = coarse_scene("hanging", 0.3 / 6.0, 1.0, 1.0);
    s.quasi_static = false;
    s.dt = 0.01;
    let (sim, _) = s.build("scene.json", Path::new(".")).unwrap();
    assert!(matches!(
        sim.sensitivity(&Observable::ElasticEnergy, false),
        Err(ShellError::AdjointUnsupported { .. })
    ));
    let sim = solve(
        &coarse("hanging", 0.3 / 6.0, 1.0, 1.0, 1e-3),
        Param::Stiffness,
        0.0,
    );
    let r = Observable::Reaction {
        set: "nowhere".into(),
        axis: 0,
    };
    assert!(matches!(
        sim.sensitivity(&r, false),
        Err(ShellError::UnknownHeldSet { .. })
    ));
}
