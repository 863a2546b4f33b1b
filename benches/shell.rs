//! Macro-scale kernels (targets: per-triangle force + Hessian ≤ 4.7 µs, ≤ 7 µs with PSD projection; time per
//! Newton iteration growing near-linearly with the mesh size; timings in `docs/results.md`, "Cloth simulation").
//!
//! - `triangle[<material>]/<psd>`: value, gradient and Hessian of one triangle energy (strain chain + ψ + chain
//!   rule + projection), averaged over 64 random stencils of the derivative harness's sampler;
//! - `newton/…/<triangles>`: on a 30 cm square with the default material, for each fill-reducing ordering of
//!   the sparse Cholesky (`[amd]` faer's minimum degree, `[nd]` nested dissection, `[auto]` the one of the two
//!   with fewer operations, the default): `iteration[…]`, one Newton iteration of an implicit Euler step
//!   (parallel assembly, numeric factorisation with the reused symbolic analysis, solve), and
//!   `factor+solve[…]`, the factorisation and solve alone; and `assembly`, the assembly alone. The factor's
//!   size and operation count are printed to stderr.

use criterion::{criterion_group, criterion_main, Criterion};
use hylc::checks::shell::sample_stencil;
use hylc::material::synthetic::default_material;
use hylc::material::Material;
use hylc::shell::solver::{Boundary, FillOrdering, Settings, Simulation};
use hylc::shell::{ElementModel, Mesh, ModelFlags, Psd};
use rand::SeedableRng;
use std::hint::black_box;

fn bench_triangle(c: &mut Criterion, name: &str, m: &Material) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let stencils: Vec<_> = (0..64).map(|i| sample_stencil(&mut rng, 4 * i)).collect();
    let mut g = c.benchmark_group(format!("triangle[{name}]"));
    g.throughput(criterion::Throughput::Elements(stencils.len() as u64));
    for (label, psd) in [
        ("exact", Psd::None),
        ("psd-psi6", Psd::Psi),
        ("psd-full18", Psd::Full),
    ] {
        let model = ElementModel::new(m, &ModelFlags::default(), psd);
        g.bench_function(format!("force+hessian {label}"), |b| {
            let mut gr = [0.0; 18];
            let mut h = [[0.0; 18]; 18];
            b.iter(|| {
                for (q, rest, flaps) in &stencils {
                    black_box(model.energy_gradient_hessian(
                        black_box(q),
                        rest,
                        *flaps,
                        &mut gr,
                        &mut h,
                    ));
                }
            })
        });
    }
    let model = ElementModel::new(m, &ModelFlags::default(), Psd::None);
    g.bench_function("energy only", |b| {
        b.iter(|| {
            for (q, rest, flaps) in &stencils {
                black_box(model.energy(black_box(q), rest, *flaps));
            }
        })
    });
    g.finish();
}

fn triangles(c: &mut Criterion) {
    bench_triangle(c, "default", &default_material());
    if let Some(dir) = hylc::shared_dir() {
        if let Ok(m) = Material::load(&dir.join("data/hylc2020/materials/basket1.json")) {
            bench_triangle(c, "basket1", &m);
        }
    }
}

/// A 30 cm square with about `nt` triangles in a smoothly stretched, bent state.
fn simulation(nt: usize) -> Simulation {
    let cells = ((nt as f64 / 2.0).sqrt()).round();
    let mesh = Mesh::rectangle(0.3, 0.3, 0.3 / cells, 0.0, 1).unwrap();
    let stencils = mesh.stencils(0.0).unwrap();
    let x0: Vec<[f64; 3]> = mesh
        .rest
        .iter()
        .map(|p| {
            [
                1.03 * p[0],
                0.99 * p[1],
                0.01 * (20.0 * p[0]).sin() * (15.0 * p[1]).cos(),
            ]
        })
        .collect();
    let model = ElementModel::new(&default_material(), &ModelFlags::default(), Psd::Full);
    Simulation::new(
        model,
        stencils,
        x0,
        Boundary {
            pinned: vec![0],
            ..Boundary::default()
        },
        Settings::default(),
        1.0,
    )
    .unwrap()
}

fn newton(c: &mut Criterion) {
    let mut g = c.benchmark_group("newton");
    g.sample_size(10);
    for nt in [1000, 4000, 16000, 64000] {
        let mut sim = simulation(nt);
        let label = sim.stencils.len();
        for (name, ordering) in [
            ("amd", FillOrdering::Amd),
            ("nd", FillOrdering::NestedDissection),
            ("auto", FillOrdering::Auto),
        ] {
            sim.set_fill_ordering(ordering).unwrap();
            let (asm, gf) = sim.newton_system().unwrap();
            let (_, shift) = sim.solve_newton_system(&asm, &gf).unwrap();
            let (len, flops) = sim.factor_cost();
            eprintln!(
                "newton/{label} {name}: factor values {len}, {flops:.3e} flops, shift {shift:e}"
            );
            g.bench_function(format!("factor+solve[{name}]/{label}"), |b| {
                b.iter(|| black_box(sim.solve_newton_system(&asm, &gf).unwrap()))
            });
            g.bench_function(format!("iteration[{name}]/{label}"), |b| {
                b.iter(|| black_box(sim.newton_direction().unwrap()))
            });
        }
        g.bench_function(format!("assembly/{label}"), |b| {
            b.iter(|| {
                black_box(hylc::shell::assemble::assemble(
                    &sim.model,
                    &sim.stencils,
                    &sim.pattern,
                    &sim.x,
                    true,
                    false,
                ))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, triangles, newton);
criterion_main!(benches);
