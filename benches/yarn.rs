//! Rod kernels and the whole-tile energy (timings in `docs/results.md`, "Yarn model kernels").
//!
//! Kernels: stretching value + gradient + Hessian; bending+twisting value alone and value + gradient + exact
//! Hessian at a generic stencil evaluated away from its stored state (transport active), with num-dual AD of the
//! reference implementation as the baseline. Tile: energy alone and energy + gradient + sparse Hessian (triplets)
//! of each original pattern at its stored state with the default material, contact pairs from the BVH broad phase
//! (skipped with a message when ../shared is absent), and the generated plain weave and stockinette.

use criterion::{criterion_group, criterion_main, Criterion};
use hylc::diff::{reference_ad, Differentiable};
use hylc::generate::{stockinette, weave, KnitParams, WeaveParams};
use hylc::pattern::Pattern;
use hylc::rod::bend_twist::{bend_twist_value, bend_twist_vgh, BendTwistParams, StencilFrames};
use hylc::rod::frame::reference_twist_raw;
use hylc::rod::stretch::stretch_vgh;
use hylc::rod::{BendingForm, YarnMaterial};
use hylc::tile::{Terms, Tile, Want};
use nalgebra::Vector3;
use std::hint::black_box;

const R: f64 = 1e-3;

struct BendTwistRef {
    frames: StencilFrames,
    params: BendTwistParams,
}

impl Differentiable for BendTwistRef {
    fn name(&self) -> String {
        "bend-twist".into()
    }
    fn dim(&self) -> usize {
        11
    }
    fn reference<D: hylc::diff::Real>(&self, x: &[D]) -> D {
        hylc::rod::bend_twist::bend_twist_reference(x, &self.frames, &self.params)
    }
    fn fast(&self, _x: &[f64]) -> hylc::diff::Vgh {
        unreachable!("only the reference is benchmarked")
    }
    fn sample(&self, _rng: &mut rand_chacha::ChaCha8Rng, _i: usize) -> Vec<f64> {
        Vec::new()
    }
}

fn bench_kernels(c: &mut Criterion) {
    let m = YarnMaterial::default();
    let t0 = Vector3::new(1.0, 0.2, 0.1).normalize();
    let t1 = Vector3::new(0.8, -0.4, 0.3).normalize();
    let u0 = t0.cross(&Vector3::z()).normalize();
    let u1 = t1.cross(&Vector3::z()).normalize();
    let frames = StencilFrames::new(t0, u0, t1, u1, reference_twist_raw(&t0, &u0, &t1, &u1));
    let params = BendTwistParams {
        rest_curvature: [0.1, -0.2],
        rest_twist: 0.05,
        voronoi_length: 1.2 * R,
        bend: m.bend_stiffness(),
        twist: m.twist_stiffness(),
        form: BendingForm::Tan,
    };
    let x1 = Vector3::zeros();
    let x = [
        x1 - t0 * 1.1 * R + Vector3::new(1e-5, 0.0, 2e-5),
        x1,
        x1 + t1 * 1.3 * R + Vector3::new(0.0, -3e-5, 1e-5),
    ];
    let th = [0.3, -0.2];
    let mut g = c.benchmark_group("rod stencil");
    g.bench_function("stretch value+grad+hess", |b| {
        b.iter(|| {
            black_box(stretch_vgh(
                black_box(&x[0]),
                &x[1],
                1.05 * R,
                m.stretch_stiffness(),
            ))
        })
    });
    g.bench_function("bend-twist value", |b| {
        b.iter(|| black_box(bend_twist_value(black_box(&x), th, &frames, &params)))
    });
    g.bench_function("bend-twist value+grad+hess", |b| {
        b.iter(|| black_box(bend_twist_vgh(black_box(&x), th, &frames, &params)))
    });
    let r = BendTwistRef { frames, params };
    let mut flat: Vec<f64> = x.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    flat.extend_from_slice(&th);
    g.bench_function("bend-twist num-dual AD of the reference (baseline)", |b| {
        b.iter(|| black_box(reference_ad(&r, black_box(&flat))))
    });
    g.finish();
}

fn patterns() -> Vec<(String, Pattern)> {
    let mut v = vec![
        (
            "plain (generated)".to_string(),
            weave(&WeaveParams::plain()).unwrap(),
        ),
        (
            "stockinette (generated)".to_string(),
            stockinette(&KnitParams::stockinette()).unwrap(),
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
                let (mut p, _) = Pattern::load_pyp(&path).unwrap();
                if name == "basket" {
                    p.periods = p.implied_periods().unwrap();
                }
                v.push((name.to_string(), p));
            }
        }
        None => eprintln!("../shared not found: benchmarking the generated patterns only"),
    }
    v
}

fn bench_tiles(c: &mut Criterion) {
    let mut g = c.benchmark_group("tile");
    for (name, p) in patterns() {
        let (state, tile, y) = Tile::at_rest_state(&p, &YarnMaterial::default()).unwrap();
        let active = tile.active_contact_pairs(&y).unwrap();
        let label = format!(
            "{name} [{} vertices, {} candidate pairs, {} active]",
            p.len(),
            tile.contacts.len(),
            active
        );
        g.bench_function(format!("{label} energy"), |b| {
            b.iter(|| black_box(tile.evaluate(&state, black_box(&y), Want::Value, &Terms::ALL)))
        });
        g.bench_function(format!("{label} energy+grad+hess"), |b| {
            b.iter(|| black_box(tile.evaluate(&state, black_box(&y), Want::Hessian, &Terms::ALL)))
        });
        g.bench_function(format!("{label} broad phase"), |b| {
            b.iter(|| {
                let mut t = Tile::new(&p, &YarnMaterial::default());
                t.update_contacts(black_box(&state.positions), 0.5 * p.radius)
                    .unwrap();
                black_box(t.contacts.len())
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = bench_kernels, bench_tiles
}
criterion_main!(benches);
