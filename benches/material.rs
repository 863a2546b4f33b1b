//! ψ + ∇ψ + ∇²ψ per evaluation (target: ≤ 0.5 µs for basket1 on an idle machine; the original takes
//! about 3.7 µs on this machine kind), for the original basket1 and stock1 and the embedded default material.
//! Baselines measured in the same run: the value alone, and the same derivatives by num-dual automatic
//! differentiation of the generic reference implementation. Time per iteration covers 64 strains.
//!
//! `HYLC_BENCH_MATERIALS=name=path,name=path` adds material files (e.g. a base fit and its extended variants, the
//! candidates of `validation/fit_candidates.py`, whose cost ratios are taken within one run; `docs/fitting.md`).

use criterion::{criterion_group, criterion_main, Criterion};
use hylc::checks::material::PsiCheck;
use hylc::diff::{reference_ad, Differentiable};
use hylc::material::synthetic::default_material;
use hylc::material::Material;
use std::hint::black_box;

/// A fixed spread of strains inside and beyond the knot ranges, with bending in all directions.
fn strains() -> Vec<[f64; 6]> {
    (0..64)
        .map(|i| {
            let f = i as f64 / 63.0;
            let g = ((i * 37) % 64) as f64 / 63.0;
            [
                1.2 * f - 0.5,
                0.8 * g - 0.4,
                0.9 * (1.0 - f) - 0.3,
                240.0 * g - 120.0,
                60.0 * f - 30.0,
                200.0 * f - 100.0,
            ]
        })
        .collect()
}

fn bench_material(c: &mut Criterion, name: &str, m: Material) {
    let zs = strains();
    let mut g = c.benchmark_group(format!("psi[{name}]"));
    g.throughput(criterion::Throughput::Elements(zs.len() as u64));
    g.bench_function("value+grad+hess", |b| {
        b.iter(|| {
            for z in &zs {
                black_box(m.eval(black_box(z)));
            }
        })
    });
    g.bench_function("reference value (f64)", |b| {
        b.iter(|| {
            for z in &zs {
                black_box(m.reference::<f64>(black_box(z)));
            }
        })
    });
    let check = PsiCheck {
        name: name.into(),
        material: m.clone(),
    };
    g.bench_function("num-dual AD of reference", |b| {
        b.iter(|| {
            for z in zs.iter().take(8) {
                black_box(reference_ad(&check, black_box(z)));
            }
        })
    });
    g.finish();
    let _ = check.dim();
}

fn benches(c: &mut Criterion) {
    if let Some(dir) = hylc::shared_dir() {
        for name in ["basket1", "stock1"] {
            let path = dir.join(format!("data/hylc2020/materials/{name}.json"));
            match Material::load(&path) {
                Ok(m) => bench_material(c, name, m),
                Err(e) => eprintln!("note: {}: {e}; not benchmarked", path.display()),
            }
        }
    } else {
        eprintln!("note: ../shared not found; benchmarking the embedded default material only");
    }
    bench_material(c, "default", default_material());
    for (name, path) in extra_materials() {
        match Material::load(std::path::Path::new(&path)) {
            Ok(m) => bench_material(c, &name, m),
            Err(e) => eprintln!("note: {path}: {e}; not benchmarked"),
        }
    }
}

/// The `name=path` pairs of `HYLC_BENCH_MATERIALS` (a path alone is named by its file name).
fn extra_materials() -> Vec<(String, String)> {
    std::env::var("HYLC_BENCH_MATERIALS")
        .unwrap_or_default()
        .split(',')
        .filter(|s| !s.is_empty())
        .map(|s| match s.split_once('=') {
            Some((n, p)) => (n.to_string(), p.to_string()),
            None => (
                std::path::Path::new(s)
                    .file_name()
                    .map_or(s.to_string(), |f| f.to_string_lossy().into_owned()),
                s.to_string(),
            ),
        })
        .collect()
}

criterion_group! {
    name = material;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = benches
}
criterion_main!(material);
