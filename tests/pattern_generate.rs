//! Procedural pattern generators (`docs/yarn-model.md`): structure,
//! frames, rest state, sampling, distances between centre lines, smoothness across the tile boundary,
//! determinism, parameter errors, OBJ export and the `hylc generate` command.

use hylc::generate::{
    default_pattern, min_centerline_distance, segment_distance, stockinette, to_obj, weave,
    GenerateError, KnitParams, SameYarn, WeaveParams, DEFAULT_KINDS,
};
use hylc::pattern::{Edge, Pattern};
use hylc::rod::state::{raw_reference_twists, set_rest_to_current};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::process::Command;

/// Every default and a few more weave matrices, with their expected yarn counts (along ξ₁, along ξ₂).
fn cases() -> Vec<(String, Pattern, [usize; 2])> {
    let mut v: Vec<(String, Pattern, [usize; 2])> = vec![
        ("plain".into(), default_pattern("plain").unwrap(), [2, 2]),
        ("twill".into(), default_pattern("twill").unwrap(), [4, 4]),
        ("satin".into(), default_pattern("satin").unwrap(), [5, 5]),
        ("basket".into(), default_pattern("basket").unwrap(), [4, 4]),
        (
            "stockinette".into(),
            default_pattern("stockinette").unwrap(),
            [2, 0],
        ),
        (
            "twill(3)".into(),
            weave(&WeaveParams::twill(3)).unwrap(),
            [3, 3],
        ),
        (
            "satin(8,3)".into(),
            weave(&WeaveParams::satin(8, 3)).unwrap(),
            [8, 8],
        ),
        (
            "basket(3)".into(),
            weave(&WeaveParams::basket(3)).unwrap(),
            [6, 6],
        ),
    ];
    // a non-square matrix: 3 wefts, 5 warps
    let m: Vec<Vec<bool>> = (0..3)
        .map(|i| (0..5).map(|j| (i + j) % 3 == 0).collect())
        .collect();
    v.push((
        "3x5 matrix".into(),
        weave(&WeaveParams::with_matrix(m)).unwrap(),
        [3, 5],
    ));
    let single = KnitParams {
        wales: 1,
        courses: 1,
        ..KnitParams::stockinette()
    };
    v.push((
        "stockinette 1x1".into(),
        stockinette(&single).unwrap(),
        [1, 0],
    ));
    let wide = KnitParams {
        wales: 3,
        courses: 4,
        ..KnitParams::stockinette()
    };
    v.push((
        "stockinette 3x4".into(),
        stockinette(&wide).unwrap(),
        [4, 0],
    ));
    v
}

fn net_offset(p: &Pattern, yarn: &[usize]) -> [i32; 2] {
    yarn.iter().fold([0, 0], |a, &v| {
        [a[0] + p.edges[v].offset[0], a[1] + p.edges[v].offset[1]]
    })
}

#[test]
fn structure_is_consistent() {
    for (name, p, [along1, along2]) in cases() {
        let n = p.len();
        assert!(n > 0, "{name}");
        assert_eq!(p.theta.len(), n, "{name}");
        assert_eq!(p.edges.len(), n, "{name}");
        assert_eq!(p.rest_curvature.len(), n, "{name}");
        assert_eq!(p.rest_twist.len(), n, "{name}");
        assert_eq!(p.ref_twist.len(), n, "{name}");
        assert_eq!(p.edge_file_order, (0..n).collect::<Vec<_>>(), "{name}");
        assert!(p.theta.iter().all(|&t| t == 0.0), "{name}");
        // one outgoing edge per vertex (by construction) and exactly one incoming
        let mut incoming = vec![0; n];
        for e in &p.edges {
            assert!(e.end < n, "{name}");
            assert!(
                e.offset.iter().all(|o| (-1..=1).contains(o)),
                "{name}: {:?}",
                e.offset
            );
            incoming[e.end] += 1;
        }
        assert!(incoming.iter().all(|&c| c == 1), "{name}");
        // closed yarns: each crosses the tile once, along ξ₁ or along ξ₂
        let yarns = p.yarns();
        assert_eq!(yarns.len(), along1 + along2, "{name}");
        assert_eq!(yarns.iter().map(|y| y.len()).sum::<usize>(), n, "{name}");
        let nets: Vec<[i32; 2]> = yarns.iter().map(|y| net_offset(&p, y)).collect();
        assert_eq!(
            nets.iter().filter(|&&d| d == [1, 0]).count(),
            along1,
            "{name}"
        );
        assert_eq!(
            nets.iter().filter(|&&d| d == [0, 1]).count(),
            along2,
            "{name}"
        );
        for y in &yarns {
            assert!(y.len() >= 4, "{name}");
            // each yarn's vertices are contiguous and in edge order
            for w in y.windows(2) {
                assert_eq!(w[1], w[0] + 1, "{name}");
            }
        }
    }
}

#[test]
fn knit_loops_cross_the_tile_in_xi2() {
    let p = default_pattern("stockinette").unwrap();
    for y in p.yarns() {
        let up = y.iter().filter(|&&v| p.edges[v].offset[1] == 1).count();
        let down = y.iter().filter(|&&v| p.edges[v].offset[1] == -1).count();
        assert!(up > 0 && up == down, "{up} {down}");
    }
    // legs in front of the heads: the height spans about ±depth
    let r = p.radius;
    let (lo, hi) = p
        .positions
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x.z), b.max(x.z))
        });
    assert!(hi - lo > 2.5 * r && hi - lo < 3.5 * r, "{lo} {hi}");
}

#[test]
fn directors_are_unit_and_perpendicular() {
    for (name, p, _) in cases() {
        for i in 0..p.len() {
            let u = p.edges[i].ref_director;
            let t = p.edge_vector(i).normalize();
            assert!((u.norm() - 1.0).abs() < 1e-12, "{name} {i}");
            assert!(u.dot(&t).abs() < 1e-12, "{name} {i}");
        }
    }
}

#[test]
fn directors_are_transported_along_each_yarn() {
    // consecutive edges inside a yarn have zero reference twist (parallel transport); only the yarn's first
    // vertex absorbs the closing mismatch
    for (name, p, _) in cases() {
        let raw = raw_reference_twists(&p);
        for y in p.yarns() {
            for &v in &y[1..] {
                assert!(raw[v].abs() < 1e-10, "{name} {v}: {}", raw[v]);
            }
        }
    }
    // planar weave yarns close without mismatch
    let p = default_pattern("satin").unwrap();
    assert!(raw_reference_twists(&p).iter().all(|t| t.abs() < 1e-10));
}

#[test]
fn rest_values_equal_the_shape() {
    for (name, p, _) in cases() {
        assert_eq!(p.ref_twist, raw_reference_twists(&p), "{name}");
        for i in 0..p.len() {
            let l = p.edge_vector(i).norm();
            assert!(
                (p.edges[i].rest_length - l).abs() <= 1e-12 * l,
                "{name} {i}"
            );
        }
        let mut q = p.clone();
        q.rest_curvature.iter_mut().for_each(|k| *k = [0.0; 2]);
        q.rest_twist.iter_mut().for_each(|t| *t = 0.0);
        q.edges.iter_mut().for_each(|e| e.rest_length = 0.0);
        set_rest_to_current(&mut q);
        assert_eq!(p, q, "{name}");
        assert!(
            p.rest_curvature.iter().any(|k| k[0] != 0.0 || k[1] != 0.0),
            "{name}"
        );
    }
}

#[test]
fn vertex_spacing_is_about_one_radius() {
    for (name, p, _) in cases() {
        let r = p.radius;
        for i in 0..p.len() {
            let l = p.edge_vector(i).norm();
            assert!(l >= 0.7 * r && l <= 1.5 * r, "{name} edge {i}: {} r", l / r);
        }
    }
    // denser sampling scales the vertex count
    let p1 = weave(&WeaveParams::plain()).unwrap();
    let p2 = weave(&WeaveParams {
        vertices_per_radius: 2.0,
        ..WeaveParams::plain()
    })
    .unwrap();
    let ratio = p2.len() as f64 / p1.len() as f64;
    assert!((ratio - 2.0).abs() < 0.25, "{ratio}");
}

#[test]
fn positions_are_centred_in_the_tile() {
    for (name, p, _) in cases() {
        let lengths: Vec<f64> = p.edges.iter().map(|e| e.rest_length).collect();
        let prev = p.prev();
        let mut sum = Vector3::zeros();
        let mut w = 0.0;
        for i in 0..p.len() {
            let wi = 0.5 * (lengths[prev[i]] + lengths[i]);
            sum += p.positions[i] * wi;
            w += wi;
        }
        let mean = sum / w;
        assert!(mean.norm() < 1e-15, "{name}: {mean:?}");
        for x in &p.positions {
            for k in 0..2 {
                assert!(
                    x[k].abs() <= 0.5 * p.periods[k] + 0.5 * p.radius,
                    "{name}: {x:?}"
                );
            }
        }
    }
}

#[test]
fn smooth_across_the_periodic_boundary() {
    // the turning angle at every vertex, including the stencils that use the periodic copy, stays below 60°
    for (name, p, _) in cases() {
        let prev = p.prev();
        let mut worst: f64 = 0.0;
        for i in 0..p.len() {
            let a = p.edge_vector(prev[i]);
            let b = p.edge_vector(i);
            let angle = (a.dot(&b) / (a.norm() * b.norm())).clamp(-1.0, 1.0).acos();
            worst = worst.max(angle.to_degrees());
        }
        assert!(worst < 60.0, "{name}: {worst}°");
        // and the closing edges are as long as the others (no jump at the boundary)
        let r = p.radius;
        for (i, e) in p.edges.iter().enumerate() {
            if e.offset != [0, 0] {
                let l = p.edge_vector(i).norm();
                assert!(l > 0.7 * r && l < 1.5 * r, "{name}");
            }
        }
    }
}

#[test]
fn weave_yarns_do_not_intersect() {
    for kind in ["plain", "twill", "satin", "basket"] {
        let p = default_pattern(kind).unwrap();
        let r = p.radius;
        let d = min_centerline_distance(&p, SameYarn::Skip);
        assert!(d.distance >= 0.95 * 2.0 * r, "{kind}: {d:?}");
        assert!(d.distance <= 2.0 * r, "{kind}: {d:?}");
        // no same-yarn pair closer either (weave yarns are nearly straight)
        let all = min_centerline_distance(&p, SameYarn::ExcludeNeighbours(3));
        assert_eq!(all.distance, d.distance, "{kind}");
    }
    // finer sampling approaches the smooth curves, which touch (2r) at the crossings
    for m in [WeaveParams::plain(), WeaveParams::satin(5, 2)] {
        let p = weave(&WeaveParams {
            vertices_per_radius: 4.0,
            ..m
        })
        .unwrap();
        let d = min_centerline_distance(&p, SameYarn::Skip).distance / p.radius;
        assert!((1.98..=2.0 + 1e-12).contains(&d), "{d}");
    }
}

#[test]
fn knit_segments_keep_apart() {
    for (name, p, _) in cases()
        .into_iter()
        .filter(|c| c.0.starts_with("stockinette"))
    {
        let r = p.radius;
        let other = min_centerline_distance(&p, SameYarn::Skip);
        let any = min_centerline_distance(&p, SameYarn::ExcludeNeighbours(3));
        eprintln!(
            "{name}: min distance other yarns {:.4} r, non-neighbouring segments {:.4} r",
            other.distance / r,
            any.distance / r
        );
        assert!(any.distance >= 1.8 * r, "{name}: {any:?}");
        assert!(other.distance >= any.distance, "{name}");
    }
    // the smooth curves (finely sampled) keep different courses about 2r apart
    let p = stockinette(&KnitParams {
        vertices_per_radius: 3.0,
        wales: 1,
        courses: 1,
        ..KnitParams::stockinette()
    })
    .unwrap();
    let d = min_centerline_distance(&p, SameYarn::Skip).distance / p.radius;
    assert!(d >= 1.9, "{d}");
    // same-yarn pairs more than ~3r apart along the yarn, too
    let d = min_centerline_distance(&p, SameYarn::ExcludeNeighbours(9)).distance / p.radius;
    assert!(d >= 1.9, "{d}");
}

#[test]
fn generation_is_deterministic() {
    for kind in DEFAULT_KINDS {
        let a = default_pattern(kind).unwrap();
        let b = default_pattern(kind).unwrap();
        assert_eq!(a, b, "{kind}");
        assert_eq!(to_obj(&a), to_obj(&b), "{kind}");
    }
}

fn err_weave(p: WeaveParams) -> GenerateError {
    weave(&p).expect_err("bad parameters accepted")
}

fn err_knit(p: KnitParams) -> GenerateError {
    stockinette(&p).expect_err("bad parameters accepted")
}

#[test]
fn bad_parameters_are_reported() {
    let plain = WeaveParams::plain;
    let cases: Vec<(GenerateError, &str, &str)> = vec![
        (
            err_weave(WeaveParams {
                radius: 0.0,
                ..plain()
            }),
            "radius",
            "positive",
        ),
        (
            err_weave(WeaveParams {
                radius: f64::NAN,
                ..plain()
            }),
            "radius",
            "positive",
        ),
        (
            err_weave(WeaveParams {
                radius: -1e-3,
                ..plain()
            }),
            "radius",
            "positive",
        ),
        (
            err_weave(WeaveParams {
                radius: 1e11,
                ..plain()
            }),
            "radius",
            "plausible yarn radii",
        ),
        (
            err_knit(KnitParams {
                radius: 1e-9,
                ..KnitParams::stockinette()
            }),
            "radius",
            "plausible yarn radii",
        ),
        (
            err_weave(WeaveParams {
                spacing: 1.5e-3,
                crimp: 1e-3,
                ..plain()
            }),
            "spacing",
            "diameter",
        ),
        (
            err_weave(WeaveParams {
                spacing: 4e-3,
                ..plain()
            }),
            "spacing",
            "π√2",
        ),
        (
            err_weave(WeaveParams {
                crimp: 0.5e-3,
                ..plain()
            }),
            "crimp",
            "interpenetrate",
        ),
        (
            err_weave(WeaveParams {
                vertices_per_radius: 0.0,
                ..plain()
            }),
            "vertices_per_radius",
            "positive",
        ),
        (
            err_weave(WeaveParams::with_matrix(vec![])),
            "matrix",
            "empty",
        ),
        (
            err_weave(WeaveParams::with_matrix(vec![vec![]])),
            "matrix",
            "empty",
        ),
        (
            err_weave(WeaveParams::with_matrix(vec![
                vec![true, true],
                vec![false, true],
            ])),
            "matrix",
            "row 0 is all true",
        ),
        (
            err_weave(WeaveParams::with_matrix(vec![
                vec![true, false],
                vec![false, false],
            ])),
            "matrix",
            "row 1 is all false",
        ),
        (
            err_weave(WeaveParams::with_matrix(vec![
                vec![true, false],
                vec![true, false],
            ])),
            "matrix",
            "column 0 is all true",
        ),
        (
            err_weave(WeaveParams::with_matrix(vec![
                vec![true, false, true],
                vec![false, true],
            ])),
            "matrix",
            "rectangular",
        ),
        (err_weave(WeaveParams::twill(1)), "matrix", "row 0"),
        (err_weave(WeaveParams::twill(0)), "matrix", "empty"),
        (err_weave(WeaveParams::satin(4, 2)), "matrix", "column 1"),
        (err_weave(WeaveParams::basket(0)), "matrix", "empty"),
        (
            err_knit(KnitParams {
                radius: 0.0,
                ..KnitParams::stockinette()
            }),
            "radius",
            "positive",
        ),
        (
            err_knit(KnitParams {
                wales: 0,
                ..KnitParams::stockinette()
            }),
            "wales",
            "at least one",
        ),
        (
            err_knit(KnitParams {
                courses: 0,
                ..KnitParams::stockinette()
            }),
            "courses",
            "at least one",
        ),
        (
            err_knit(KnitParams {
                loop_height: 2e-3,
                ..KnitParams::stockinette()
            }),
            "loop_height",
            "interlock",
        ),
        (
            err_knit(KnitParams {
                depth: 0.5e-3,
                ..KnitParams::stockinette()
            }),
            "depth",
            "interpenetrate",
        ),
        (
            err_knit(KnitParams {
                wale_spacing: 3e-3,
                ..KnitParams::stockinette()
            }),
            "wale_spacing",
            "4r",
        ),
        (
            err_knit(KnitParams {
                course_spacing: 1.5e-3,
                ..KnitParams::stockinette()
            }),
            "course_spacing",
            "diameter",
        ),
        (
            err_knit(KnitParams {
                loop_bulge: -1.0,
                ..KnitParams::stockinette()
            }),
            "loop_bulge",
            "non-negative",
        ),
        (
            default_pattern("jersey").unwrap_err(),
            "kind",
            "stockinette",
        ),
    ];
    for (e, parameter, phrase) in cases {
        assert_eq!(e.parameter, parameter, "{e}");
        assert!(e.message.contains(phrase), "{e}");
        assert!(e.to_string().starts_with(parameter), "{e}");
    }
    // a very coarse sampling still gives at least 4 vertices per yarn
    let p = weave(&WeaveParams {
        vertices_per_radius: 0.01,
        ..plain()
    })
    .unwrap();
    assert!(p.yarns().iter().all(|y| y.len() == 4));
}

#[test]
fn weave_matrices_of_the_constructors() {
    let t = |m: Vec<Vec<bool>>| -> Vec<String> {
        m.iter()
            .map(|r| r.iter().map(|&b| if b { 'X' } else { '.' }).collect())
            .collect()
    };
    assert_eq!(t(WeaveParams::plain().matrix), ["X.", ".X"]);
    assert_eq!(t(WeaveParams::twill(3).matrix), ["XX.", ".XX", "X.X"]);
    assert_eq!(
        t(WeaveParams::twill(4).matrix),
        ["XX..", ".XX.", "..XX", "X..X"]
    );
    assert_eq!(
        t(WeaveParams::satin(5, 2).matrix),
        ["X....", "..X..", "....X", ".X...", "...X."]
    );
    assert_eq!(
        t(WeaveParams::basket(2).matrix),
        ["XX..", "XX..", "..XX", "..XX"]
    );
    // crossing heights follow the matrix: warp over weft ⇒ warp above
    let p = default_pattern("twill").unwrap();
    let m = WeaveParams::twill(4).matrix;
    let yarns = p.yarns();
    let (wefts, warps) = yarns.split_at(4);
    for (i, weft) in wefts.iter().enumerate() {
        for (j, warp) in warps.iter().enumerate() {
            // the warp's and the weft's heights at the vertices nearest to the crossing point
            let x = p.positions[warp[0]].x;
            let y = p.positions[weft[0]].y;
            let near = |yarn: &Vec<usize>| {
                *yarn
                    .iter()
                    .min_by(|&&a, &&b| {
                        let da = (p.positions[a].x - x).hypot(p.positions[a].y - y);
                        let db = (p.positions[b].x - x).hypot(p.positions[b].y - y);
                        da.total_cmp(&db)
                    })
                    .unwrap()
            };
            let (hw, hf) = (p.positions[near(warp)].z, p.positions[near(weft)].z);
            assert_eq!(hw > hf, m[i][j], "weft {i} warp {j}: {hw} {hf}");
            assert!(((hw - hf).abs() - 2.0 * p.radius).abs() < 1e-12);
        }
    }
}

#[test]
fn segment_distance_matches_sampling() {
    let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
    // skew perpendicular lines one apart
    let d = segment_distance(
        &v(-1.0, 0.0, 0.0),
        &v(1.0, 0.0, 0.0),
        &v(0.0, -1.0, 1.0),
        &v(0.0, 1.0, 1.0),
    );
    assert!((d - 1.0).abs() < 1e-15);
    // parallel, overlapping and not overlapping
    let d = segment_distance(
        &v(0.0, 0.0, 0.0),
        &v(2.0, 0.0, 0.0),
        &v(1.0, 0.5, 0.0),
        &v(3.0, 0.5, 0.0),
    );
    assert!((d - 0.5).abs() < 1e-15);
    let d = segment_distance(
        &v(0.0, 0.0, 0.0),
        &v(1.0, 0.0, 0.0),
        &v(3.0, 0.0, 0.0),
        &v(4.0, 0.0, 0.0),
    );
    assert!((d - 2.0).abs() < 1e-15);
    // degenerate segments
    let d = segment_distance(
        &v(0.0, 0.0, 0.0),
        &v(0.0, 0.0, 0.0),
        &v(1.0, 1.0, 0.0),
        &v(1.0, 1.0, 0.0),
    );
    assert!((d - 2f64.sqrt()).abs() < 1e-15);
    let d = segment_distance(
        &v(0.0, 1.0, 0.0),
        &v(0.0, 1.0, 0.0),
        &v(-1.0, 0.0, 0.0),
        &v(1.0, 0.0, 0.0),
    );
    assert!((d - 1.0).abs() < 1e-15);
    // random segments against dense sampling (sampling only ever overestimates)
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..300 {
        let mut p = || v(rng.random(), rng.random(), rng.random());
        let (a0, a1, b0, b1) = (p(), p(), p(), p());
        let d = segment_distance(&a0, &a1, &b0, &b1);
        assert!(
            (d - segment_distance(&b0, &b1, &a0, &a1)).abs() < 1e-12,
            "symmetry"
        );
        let k = 200;
        let mut sampled = f64::INFINITY;
        for i in 0..=k {
            let x = a0 + (a1 - a0) * (i as f64 / k as f64);
            for j in 0..=k {
                let y = b0 + (b1 - b0) * (j as f64 / k as f64);
                sampled = sampled.min((x - y).norm());
            }
        }
        assert!(d <= sampled + 1e-12, "{d} {sampled}");
        assert!(sampled - d < 2e-2, "{d} {sampled}");
    }
}

/// A hand-built pattern: straight yarns along ξ₁ at the given heights y, `m` vertices each, tile p₁ × p₂.
fn straight_wefts(ys: &[f64], m: usize, periods: [f64; 2]) -> Pattern {
    let mut positions = Vec::new();
    let mut edges = Vec::new();
    for &y in ys {
        let base = positions.len();
        for k in 0..m {
            positions.push(Vector3::new(
                -0.5 * periods[0] + (k as f64 + 0.5) * periods[0] / m as f64,
                y,
                0.0,
            ));
            edges.push(Edge {
                end: base + (k + 1) % m,
                offset: if k + 1 == m { [1, 0] } else { [0, 0] },
                rest_length: periods[0] / m as f64,
                ref_director: Vector3::z(),
            });
        }
    }
    Pattern::from_geometry(periods, 1.0, positions, edges)
}

#[test]
fn min_distance_knows_yarns_and_copies() {
    // one straight yarn of 10 unit edges, tile 10 × 7: its copy at (0, ±1) is another yarn 7 away
    let p = straight_wefts(&[0.0], 10, [10.0, 7.0]);
    let d = min_centerline_distance(&p, SameYarn::Skip);
    assert!((d.distance - 7.0).abs() < 1e-12, "{d:?}");
    assert_eq!(d.offset[1].abs(), 1);
    // along the yarn (through the periodic continuation): k excluded neighbours leave a gap of k edges
    for k in [1, 3, 5] {
        let d = min_centerline_distance(&p, SameYarn::ExcludeNeighbours(k));
        assert!((d.distance - k as f64).abs() < 1e-12, "{k}: {d:?}");
    }
    // the gap across the tile boundary counts as well: 9 excluded → the closest is the other yarn copy
    let d = min_centerline_distance(&p, SameYarn::ExcludeNeighbours(9));
    assert!((d.distance - 7.0).abs() < 1e-12, "{d:?}");
    // two yarns 2 apart in a tile of height 7: 2 (not 5, the distance to the next copy)
    let p = straight_wefts(&[-1.0, 1.0], 10, [10.0, 7.0]);
    let d = min_centerline_distance(&p, SameYarn::Skip);
    assert!((d.distance - 2.0).abs() < 1e-12, "{d:?}");
    // a yarn that winds through the boundary in ξ₂ (a knit): its wrapped pieces are the same yarn, the
    // copies of the other course are not — Skip never reports a distance below the true inter-course distance
    let p = default_pattern("stockinette").unwrap();
    let skip = min_centerline_distance(&p, SameYarn::Skip);
    let all = min_centerline_distance(&p, SameYarn::ExcludeNeighbours(usize::MAX - 1));
    assert_eq!(skip.distance, all.distance);
}

#[test]
fn obj_export() {
    let p = default_pattern("stockinette").unwrap();
    let text = to_obj(&p);
    let verts: Vec<Vector3<f64>> = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f64> = l[2..].split(' ').map(|x| x.parse().unwrap()).collect();
            Vector3::new(c[0], c[1], c[2])
        })
        .collect();
    let lines: Vec<(usize, usize)> = text
        .lines()
        .filter(|l| l.starts_with("l "))
        .map(|l| {
            let c: Vec<usize> = l[2..].split(' ').map(|x| x.parse().unwrap()).collect();
            (c[0], c[1])
        })
        .collect();
    let crossing = p.edges.iter().filter(|e| e.offset != [0, 0]).count();
    assert!(crossing > 0);
    assert_eq!(verts.len(), p.len() + crossing);
    assert_eq!(lines.len(), p.len());
    for (i, &(a, b)) in lines.iter().enumerate() {
        assert_eq!(a, i + 1);
        let l = (verts[b - 1] - verts[a - 1]).norm();
        assert!((l - p.edges[i].rest_length).abs() < 1e-12);
    }
}

#[test]
fn cli_generate() {
    let dir = std::env::temp_dir().join(format!("hylc-generate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("satin.obj");
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["generate", "satin", "--obj", obj.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("250 in 10 yarns"), "{text}");
    assert!(
        text.contains("min distance between different yarns"),
        "{text}"
    );
    let written = std::fs::read_to_string(&obj).unwrap();
    assert_eq!(written, to_obj(&default_pattern("satin").unwrap()));
    let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
        .args(["generate", "twill", "--n", "3"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    assert!(String::from_utf8(out.stdout)
        .unwrap()
        .contains("in 6 yarns"));
    for args in [
        vec!["generate", "jersey"],
        vec!["generate", "satin", "--n", "4", "--step", "2"],
        vec!["generate", "plain", "--step", "2"],
        vec!["generate", "plain", "--vertices-per-radius", "0"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_hylc"))
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(
            err.starts_with("error: ") && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
