//! The fill-reducing orderings of the cloth solver's sparse Cholesky compared in one process
//! (`docs/cloth-simulator.md`, "The cloth solver"): on the Newton benchmark's rippled 30 cm squares
//! (`benches/shell.rs`), the factor's size and operation count under each ordering, and the factorisation + solve
//! of one Newton system timed in interleaved rounds (amd, nd, auto, amd, nd, auto, …) so that a load change on a
//! shared machine hits every ordering alike; the minimum and the median over the rounds, and the ratios to
//! `amd` (faer's minimum degree, the ordering before nested dissection existed).
//!
//! `cargo run --release --example fill_ordering -- [ROUNDS] [TRIANGLES…]` (defaults: 15 rounds; 1000 4000 16000
//! 64000 triangles).

use hylc::material::synthetic::default_material;
use hylc::shell::solver::{Boundary, FillOrdering, Settings, Simulation};
use hylc::shell::{ElementModel, Mesh, ModelFlags, Psd};
use std::time::Instant;

/// The benchmark's square with about `nt` triangles, stretched and rippled.
fn simulation(nt: usize) -> Simulation {
    let cells = ((nt as f64 / 2.0).sqrt()).round();
    let mesh = Mesh::rectangle(0.3, 0.3, 0.3 / cells, 0.0, 1).unwrap();
    let stencils = mesh.stencils(0.0).unwrap();
    let x0: Vec<[f64; 3]> = mesh
        .rest
        .iter()
        .map(|p| {
            let z = 0.01 * (20.0 * p[0]).sin() * (15.0 * p[1]).cos();
            [1.03 * p[0], 0.99 * p[1], z]
        })
        .collect();
    let model = ElementModel::new(&default_material(), &ModelFlags::default(), Psd::Full);
    let boundary = Boundary {
        pinned: vec![0],
        ..Boundary::default()
    };
    Simulation::new(model, stencils, x0, boundary, Settings::default(), 1.0).unwrap()
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numbers: ROUNDS then TRIANGLES…"))
        .collect();
    let rounds = args.first().copied().unwrap_or(15);
    let sizes = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec![1000, 4000, 16000, 64000]
    };
    let orderings = [
        ("amd", FillOrdering::Amd),
        ("nd", FillOrdering::NestedDissection),
        ("auto", FillOrdering::Auto),
    ];
    println!("triangles ordering factor_values flops symbolic_s min_s median_s min_ratio_to_amd median_ratio_to_amd");
    for nt in sizes {
        let mut sim = simulation(nt);
        let (asm, gf) = sim.newton_system().unwrap();
        let mut times = vec![vec![]; orderings.len()];
        let mut costs = vec![];
        let mut symbolic = vec![];
        for (_, ordering) in orderings {
            let t = Instant::now();
            sim.set_fill_ordering(ordering).unwrap();
            symbolic.push(t.elapsed().as_secs_f64());
            costs.push(sim.factor_cost());
        }
        for _ in 0..rounds {
            for (i, (_, ordering)) in orderings.iter().enumerate() {
                sim.set_fill_ordering(*ordering).unwrap();
                let t = Instant::now();
                std::hint::black_box(sim.solve_newton_system(&asm, &gf).unwrap());
                times[i].push(t.elapsed().as_secs_f64());
            }
        }
        for t in &mut times {
            t.sort_by(f64::total_cmp);
        }
        let (min0, med0) = (times[0][0], times[0][rounds / 2]);
        for (i, (name, _)) in orderings.iter().enumerate() {
            let (min, med) = (times[i][0], times[i][rounds / 2]);
            println!(
                "{} {name} {} {:.3e} {:.4} {min:.4} {med:.4} {:.3} {:.3}",
                sim.stencils.len(),
                costs[i].0,
                costs[i].1,
                symbolic[i],
                min / min0,
                med / med0
            );
        }
    }
}
