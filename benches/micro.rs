//! The micro solver (`docs/micro-solver.md`): one Newton iteration (tile energy + gradient +
//! Hessian, and the KKT solve) and complete solves, cold from the reference state and warm-started from a
//! neighbouring strain (0.006 away in s_x and s_y, the spacing of a default 150-sample range), for the generated
//! plain weave and stockinette and, when ../shared is present, each original pattern (at its implied periods when
//! the file's disagree).

use criterion::{criterion_group, criterion_main, Criterion};
use hylc::generate::default_pattern;
use hylc::micro::linear::KktSolver;
use hylc::micro::{Elimination, MacroStrain, MicroProblem, SolverOptions};
use hylc::pattern::Pattern;
use hylc::rod::YarnMaterial;
use hylc::tile::{Terms, Want};
use std::hint::black_box;

fn patterns() -> Vec<(String, Pattern)> {
    let mut v = vec![
        ("plain".to_string(), default_pattern("plain").unwrap()),
        (
            "stockinette (gen)".to_string(),
            default_pattern("stockinette").unwrap(),
        ),
    ];
    match hylc::shared_dir() {
        Some(dir) => {
            for name in [
                "basket",
                "satin",
                "slip_stitch_honeycomb",
                "stockinette",
                "cartridge_belt_rib",
            ] {
                let path = dir.join(format!("data/hylc2020/patterns/{name}.pyp"));
                if let Ok((p, _)) = Pattern::load_pyp_at_implied_periods(&path) {
                    v.push((name.to_string(), p));
                }
            }
        }
        None => eprintln!("note: ../shared not found; benchmarking the generated patterns only"),
    }
    v
}

fn bench_micro(c: &mut Criterion) {
    let m = YarnMaterial::default();
    let z = MacroStrain::in_plane(0.1, 0.1, 0.05);
    let near = MacroStrain::in_plane(0.094, 0.1, 0.044);
    let mut g = c.benchmark_group("micro");
    g.sample_size(10);
    for (name, p) in patterns() {
        let q = MicroProblem::new(p, &m, SolverOptions::default());
        let warm = q.solve(&near, None).unwrap();
        let sol = q.solve(&z, Some(&warm.state)).unwrap();
        let cold = q.solve(&z, None).unwrap();
        eprintln!(
            "{name}: {} vertices; cold {} steps ({:?}), warm {} steps ({:?})",
            q.pattern.len(),
            cold.steps,
            cold.status,
            sol.steps,
            sol.status
        );
        // one Newton iteration at the cold start's first iterate: assembly and the KKT solve
        let mut state = q.reference_state();
        q.move_to(&mut state, &z).unwrap();
        let elim = Elimination::in_family(&q.pattern, &state.strain, state.family);
        let mut tile = q.tile(&elim);
        tile.update_contacts(&tile.home_positions(&state.y), 0.5 * q.pattern.radius)
            .unwrap();
        g.bench_function(format!("{name}/assembly"), |b| {
            b.iter(|| {
                black_box(
                    tile.evaluate(&state.frames, &state.y, Want::Hessian, &Terms::ALL)
                        .unwrap(),
                )
            })
        });
        let ev = tile
            .evaluate(&state.frames, &state.y, Want::Hessian, &Terms::ALL)
            .unwrap();
        let n = q.pattern.len();
        let r = q.pattern.radius;
        let s = |i: usize| if i < 3 * n { 1.0 } else { 1.0 / r };
        let lower: Vec<(usize, usize, f64)> = ev
            .hessian
            .unwrap()
            .into_iter()
            .filter(|t| t.0 >= t.1)
            .map(|(i, j, v)| (i, j, v * s(i) * s(j)))
            .collect();
        let grad: Vec<f64> = ev
            .gradient
            .unwrap()
            .iter()
            .enumerate()
            .map(|(i, v)| v * s(i))
            .collect();
        let mu = 1e-3 * m.stretch_stiffness() / r;
        let mut kkt = KktSolver::default();
        g.bench_function(format!("{name}/kkt solve"), |b| {
            b.iter(|| {
                black_box(
                    kkt.solve(4 * n, &lower, mu, &grad, q.constraints())
                        .unwrap(),
                )
            })
        });
        g.bench_function(format!("{name}/solve cold"), |b| {
            b.iter(|| black_box(q.solve(&z, None).unwrap()))
        });
        g.bench_function(format!("{name}/solve warm"), |b| {
            b.iter(|| black_box(q.solve(&z, Some(&warm.state)).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_micro);
criterion_main!(benches);
