//! Contact kernels and broad phase (timings in `docs/results.md`, "Yarn model kernels").
//!
//! Pair kernel: a touching crossing pair (perpendicular segments of 2r, normalised gap ρ = 0.9, so the central
//! quadrature pairs are inside the cut-off and the outer ones beyond), value alone and value + gradient + Hessian
//! at Q = 2, 4, 8; num-dual AD of the reference at Q = 4 as a baseline. Broad phase: the synthetic weave of
//! `hylc::generate::synthetic_weave` with 6 + 6 yarns of 24 segments (288 segments, periods 24 r), build +
//! query and refit + query with the 3 × 3 flat images, and the brute-force reference.

use criterion::{criterion_group, criterion_main, Criterion};
use hylc::checks::contact::PairCheck;
use hylc::contact::{
    brute_force_candidates, tile_segments, BroadPhase, PairKernel, SegmentTopology,
};
use hylc::diff::reference_ad;
use hylc::generate::synthetic_weave;
use hylc::periodic::TileImages;
use nalgebra::Vector3;
use std::hint::black_box;

const R: f64 = 1e-3;

fn touching_pair() -> [Vector3<f64>; 4] {
    let g = 2.0 * R * 0.9;
    [
        Vector3::new(-R, 0.1 * R, 0.0),
        Vector3::new(R, -0.1 * R, 0.0),
        Vector3::new(0.05 * R, -R, g),
        Vector3::new(-0.05 * R, R, g),
    ]
}

fn bench_pair(c: &mut Criterion) {
    let x = touching_pair();
    let mut g = c.benchmark_group("contact pair (touching crossing)");
    for q in [2usize, 4, 8] {
        let k = PairKernel::new(60.0, R, q).unwrap();
        g.bench_function(format!("value Q={q}"), |b| {
            b.iter(|| black_box(k.value(black_box(&x), 2.0 * R, 2.0 * R)))
        });
        g.bench_function(format!("value+grad+hess Q={q}"), |b| {
            b.iter(|| black_box(k.value_gradient_hessian(black_box(&x), 2.0 * R, 2.0 * R)))
        });
    }
    let check = PairCheck {
        name: "bench".into(),
        kernel: PairKernel::new(60.0, R, 4).unwrap(),
        rest: [2.0 * R, 2.0 * R],
    };
    let flat: Vec<f64> = x.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
    g.bench_function("num-dual AD of reference Q=4", |b| {
        b.iter(|| black_box(reference_ad(&check, black_box(&flat))))
    });
    g.finish();
}

fn bench_broad(c: &mut Criterion) {
    let p = synthetic_weave(6, 24, R);
    let images = TileImages::flat(p.periods);
    let topo = SegmentTopology::from_pattern(&p);
    let s0 = tile_segments(&p, &p.positions, &images).unwrap();
    // a second state: every vertex moved by 0.2 r in a smooth pattern
    let x1: Vec<Vector3<f64>> = p
        .positions
        .iter()
        .map(|x| x + Vector3::new((x.y / R).sin(), (x.x / R).cos(), (x.x / R).sin()) * (0.2 * R))
        .collect();
    let s1 = tile_segments(&p, &x1, &images).unwrap();
    let margin = 0.5 * R;
    let n_pairs = BroadPhase::new(&s0, topo.clone(), images.clone(), R, margin, 3)
        .unwrap()
        .candidates()
        .len();
    eprintln!(
        "broad phase: {} segments, {} images, {} candidate pairs at the reference state",
        s0.len(),
        images.len(),
        n_pairs
    );
    let mut g = c.benchmark_group(format!("contact broad phase ({} segments)", s0.len()));
    g.bench_function("build + query", |b| {
        b.iter(|| {
            let bp = BroadPhase::new(black_box(&s0), topo.clone(), images.clone(), R, margin, 3)
                .unwrap();
            black_box(bp.candidates())
        })
    });
    let mut bp = BroadPhase::new(&s0, topo.clone(), images.clone(), R, margin, 3).unwrap();
    let mut flip = false;
    g.bench_function("refit + query", |b| {
        b.iter(|| {
            flip = !flip;
            bp.refit(black_box(if flip { &s1 } else { &s0 })).unwrap();
            black_box(bp.candidates())
        })
    });
    g.bench_function("brute force O(n^2)", |b| {
        b.iter(|| {
            black_box(brute_force_candidates(
                black_box(&s0),
                &topo,
                &images,
                2.0 * R + margin,
                3,
            ))
        })
    });
    g.finish();
}

criterion_group! {
    name = contact;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(2));
    targets = bench_pair, bench_broad
}
criterion_main!(contact);
