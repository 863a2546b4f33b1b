//! Unit tests of sampling plans: enumeration, ids, chains, JSON errors, limits.

use super::*;
use std::path::Path;

#[test]
fn plan_stretch_limits_agree_with_the_solver() {
    // up to the plan's own upper limit, a plan accepts exactly the stretches the micro solver accepts
    for v in [
        -1.0,
        -0.95,
        -0.9,
        MIN_PLAN_STRETCH,
        -0.899_999_999,
        -0.85,
        0.0,
        2.5,
        3.0,
    ] {
        let plan = inadmissible(0, v).is_none();
        let solver = crate::micro::MacroStrain::in_plane(v, 0.0, 0.0)
            .validate()
            .is_ok();
        assert_eq!(plan, solver, "s_x = {v}");
    }
    assert!(inadmissible(2, 3.01).is_some());
}

#[test]
fn holdout_grid_samples_and_chains() {
    let p = Plan::holdout();
    assert_eq!(p.len(), 729);
    let s = p.samples();
    assert_eq!(s[0].z, [-0.2, -0.7, -0.2, 0.0, 0.0]);
    assert_eq!(s[728].z, [1.0, 0.7, 1.0, 0.0, 0.0]);
    let chains = p.chains();
    assert_eq!(chains.len(), 9);
    let mut seen = vec![0; 729];
    for c in &chains {
        assert!(c.steps[0].from.is_none());
        assert_eq!(s[c.steps[0].sample].z[1], 0.0);
        for (k, st) in c.steps.iter().enumerate() {
            seen[st.sample] += 1;
            if k > 0 {
                assert!(st.from.unwrap() < k);
            }
        }
    }
    assert!(seen.iter().all(|&n| n == 1));
    // round trip, and plans without a grid keep their JSON (and hash)
    assert_eq!(Plan::from_json(&p.canonical_json(), None).unwrap(), p);
    assert!(!Plan::default().canonical_json().contains("grid"));
    let mut bad = p.clone();
    bad.grid.as_mut().unwrap().s_a[0] = 1.0;
    assert!(bad.validate().unwrap_err().field == "grid.s_a");
}

#[test]
fn per_pair_2d_ranges() {
    let mut p = Plan::reduced();
    let base_hash = p.hash();
    let mut r: Vec<[[f64; 2]; 2]> = p
        .pairs
        .iter()
        .map(|[a, b]| {
            let (ka, kb) = (a.index(), b.index());
            [p.ranges.get(ka), p.ranges.get(kb)]
        })
        .collect();
    r[0] = [[-0.1, 0.84], [-0.6, 0.6]];
    p.ranges_2d = Some(r);
    p.validate().unwrap();
    assert_ne!(p.hash(), base_hash);
    let s = p.samples();
    let g0: Vec<&Sample> = s[150..250].iter().collect();
    let min_sx = g0.iter().map(|s| s.z[0]).fold(f64::INFINITY, f64::min);
    let max_sa = g0.iter().map(|s| s.z[1]).fold(f64::NEG_INFINITY, f64::max);
    assert!((min_sx + 0.1).abs() < 1e-12 && (max_sa - 0.6).abs() < 1e-12);
    // the other grids keep the strain ranges
    assert_eq!(s[250].z[0], -0.6000000000000001);
    assert_eq!(Plan::from_json(&p.canonical_json(), None).unwrap(), p);
    // one entry per pair, each containing 0
    let mut bad = p.clone();
    bad.ranges_2d.as_mut().unwrap().pop();
    assert_eq!(bad.validate().unwrap_err().field, "ranges_2d");
    let mut bad = p.clone();
    bad.ranges_2d.as_mut().unwrap()[3][1] = [10.0, 20.0];
    assert_eq!(bad.validate().unwrap_err().field, "ranges_2d[3][1]");
}

#[test]
fn counts() {
    let p = Plan::default();
    assert_eq!(p.len(), 5 * 150 + 9 * 2500);
    assert_eq!(p.len(), 23_250);
    assert_eq!(p.samples().len(), 23_250);
    assert_eq!(Plan::reduced().samples().len(), 5 * 30 + 9 * 100);
    assert_eq!(p.pairs.len(), 9);
}

#[test]
fn sample_range_endpoints_and_densification() {
    let s = sample_range(0, -0.6, 0.96, 150);
    assert_eq!(s.len(), 150);
    assert!((s[0] + 0.6).abs() < 1e-12 && (s[149] - 0.96).abs() < 1e-12);
    // denser towards compression: steps grow
    let d: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(d.iter().all(|v| *v > 0.0));
    assert!(d.windows(2).all(|w| w[1] > w[0]));
    let a = sample_range(1, -0.7, 0.7, 51);
    assert!((a[0] + 0.7).abs() < 1e-12 && (a[50] - 0.7).abs() < 1e-12);
    assert_eq!(a[25], 0.0);
    // denser near 0: steps shrink towards the middle
    let d: Vec<f64> = a.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(d[0] > d[20] && d[49] > d[30]);
    let b = sample_range(3, -160.0, 160.0, 50);
    assert!((b[0] + 160.0).abs() < 1e-9 && (b[49] - 160.0).abs() < 1e-9);
    assert!(b.windows(2).all(|w| w[1] > w[0]));
    // exact formula at one interior point
    let lo = 0.4f64.powf(0.1);
    let hi = 1.96f64.powf(0.1);
    let v = lo + (hi - lo) * 7.0 / 149.0;
    assert_eq!(s[7], v.powi(10) - 1.0);
}

#[test]
fn ids_are_stable() {
    // the hash of the default plan is fixed across runs and builds (canonical JSON, FNV-1a 64)
    let p = Plan::default();
    assert_eq!(p.hash(), fnv1a64(p.canonical_json().as_bytes()));
    assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
    let s = p.samples();
    assert_eq!(s[17].id, format!("{:016x}-17", p.hash()));
    assert_eq!(Plan::default().samples()[17].id, s[17].id);
    assert_ne!(Plan::reduced().hash(), p.hash());
    assert_eq!(
        p.hash(),
        PINNED_DEFAULT_HASH,
        "the default plan's hash changed"
    );
}

const PINNED_DEFAULT_HASH: u64 = 3_641_870_492_531_437_183;

#[test]
fn json_round_trip() {
    for p in [Plan::default(), Plan::reduced()] {
        let text = serde_json::to_string_pretty(&p).unwrap();
        let q = Plan::from_json(&text, Some("x.json")).unwrap();
        assert_eq!(p, q);
        assert_eq!(p.hash(), q.hash());
    }
}

#[test]
fn bad_json_errors_name_file_and_field() {
    let good = serde_json::to_value(Plan::reduced()).unwrap();
    let cases: Vec<(serde_json::Value, &str)> = vec![
        (
            {
                let mut v = good.clone();
                v["count_1d"] = "ten".into();
                v
            },
            "count_1d",
        ),
        (
            {
                let mut v = good.clone();
                v["extra"] = 1.into();
                v
            },
            "extra",
        ),
        (
            {
                let mut v = good.clone();
                v.as_object_mut().unwrap().remove("count_2d");
                v
            },
            "count_2d",
        ),
        (
            {
                let mut v = good.clone();
                v["ranges"]["s_a"] = serde_json::json!([0.5, 0.7]);
                v
            },
            "ranges.s_a",
        ),
        (
            {
                let mut v = good.clone();
                v["ranges"]["s_x"] = serde_json::json!([-1.5, 0.7]);
                v
            },
            "ranges.s_x",
        ),
        (
            {
                let mut v = good.clone();
                v["ranges"]["s_q"] = serde_json::json!([0, 1]);
                v
            },
            "ranges.s_q",
        ),
        (
            {
                let mut v = good.clone();
                v["pairs"][1] = serde_json::json!(["s_x", "s_z"]);
                v
            },
            "pairs[1]",
        ),
        (
            {
                let mut v = good.clone();
                v["pairs"][1] = serde_json::json!(["s_a", "s_x"]);
                v
            },
            "pairs[1]",
        ),
        (
            {
                let mut v = good.clone();
                v["pairs"][1] = serde_json::json!(["II00", "II11"]);
                v
            },
            "pairs[1]",
        ),
    ];
    for (v, field) in cases {
        let e = Plan::from_json(&v.to_string(), Some("plan.json")).unwrap_err();
        assert_eq!(e.field, field, "{e}");
        let msg = e.to_string();
        assert!(msg.contains("plan.json") && msg.contains(field), "{msg}");
    }
    let e = Plan::from_json("{", Some("p.json")).unwrap_err();
    assert!(e.to_string().starts_with("p.json: "));
}

#[test]
fn chains_cover_every_sample_once_and_start_near_zero() {
    let uniform = Plan {
        count_1d: 7,
        count_2d: 5,
        ..Plan::reduced()
    };
    // per-range counts: different on every range and both axes of every grid
    let per_range = Plan {
        counts_1d: Some([7, 4, 9, 5, 6]),
        counts_2d: Some((0..9).map(|p| [3 + p % 4, 5 + p % 3]).collect()),
        ..uniform.clone()
    };
    assert_eq!(
        per_range.len(),
        31 + (0..9).map(|p| (3 + p % 4) * (5 + p % 3)).sum::<usize>()
    );
    let text = serde_json::to_string(&per_range).unwrap();
    assert_eq!(Plan::from_json(&text, None).unwrap(), per_range);
    assert!(!serde_json::to_string(&uniform).unwrap().contains("counts_"));
    for p in [uniform, per_range] {
        check_chains(&p);
    }
}

#[test]
fn huge_counts_are_rejected_before_any_allocation() {
    let good = serde_json::to_value(Plan::reduced()).unwrap();
    let big = serde_json::json!(u64::MAX);
    let cases: Vec<(&str, serde_json::Value, &str)> = vec![
        ("count_1d", big.clone(), "count_1d"),
        ("count_1d", 1_000_000_000u64.into(), "count_1d"),
        ("count_1d", (1u64 << 32).into(), "count_1d"),
        // 5 × 200 001 > 10⁶: each count is within the limit, the total is not
        ("count_1d", 200_001u64.into(), "count_1d"),
        ("count_2d", 100_000u64.into(), "count_2d"),
        ("count_2d", 1_000_000_000u64.into(), "count_2d"),
        // 9 × 400² = 1 440 000
        ("count_2d", 400u64.into(), "count_2d"),
        (
            "counts_1d",
            serde_json::json!([3, 3, u64::MAX, 3, 3]),
            "counts_1d[2]",
        ),
        (
            "counts_2d",
            {
                let mut c = vec![serde_json::json!([3, 3]); 9];
                c[4] = serde_json::json!([1u64 << 32, 1u64 << 32]);
                c.into()
            },
            "counts_2d[4][0]",
        ),
        (
            "counts_2d",
            {
                let mut c = vec![serde_json::json!([3, 3]); 9];
                c[7] = serde_json::json!([1000, 1001]);
                c.into()
            },
            "counts_2d[7]",
        ),
        (
            "grid",
            serde_json::json!({"s_x": vec![0.0; 101], "s_a": vec![0.0; 100], "s_y": vec![0.0; 100]}),
            "grid",
        ),
    ];
    for (key, value, field) in cases {
        let mut v = good.clone();
        v[key] = value;
        let e = Plan::from_json(&v.to_string(), Some("big.json")).unwrap_err();
        assert_eq!(e.field, field, "{e}");
        assert!(e.to_string().contains("1000000 samples per plan"), "{e}");
    }
    // checked arithmetic: a plan built in code with overflowing counts has no length, and len() saturates
    let p = Plan {
        count_2d: usize::MAX,
        ..Plan::reduced()
    };
    assert_eq!(p.checked_len(), None);
    assert_eq!(p.len(), usize::MAX);
    assert_eq!(p.validate().unwrap_err().field, "count_2d");
    // the limit itself is admissible
    let p = Plan {
        count_1d: 200_000,
        count_2d: 0,
        pairs: vec![],
        ..Plan::reduced()
    };
    assert_eq!(p.checked_len(), Some(MAX_PLAN_SAMPLES));
    p.validate().unwrap();
}

#[test]
fn ranges_beyond_the_admissible_strains_are_rejected() {
    let good = serde_json::to_value(Plan::reduced()).unwrap();
    let cases: Vec<(&str, serde_json::Value, &str)> = vec![
        ("/ranges/s_x", serde_json::json!([-0.5, 1e23]), "ranges.s_x"),
        (
            "/ranges/s_y",
            serde_json::json!([-0.5, 1e300]),
            "ranges.s_y",
        ),
        ("/ranges/s_y", serde_json::json!([-0.5, 3.5]), "ranges.s_y"),
        (
            "/ranges/II00",
            serde_json::json!([-1e12, 1e12]),
            "ranges.II00",
        ),
        (
            "/ranges/II11",
            serde_json::json!([-0.0, 1000.5]),
            "ranges.II11",
        ),
        ("/ranges/s_a", serde_json::json!([-1e6, 1e6]), "ranges.s_a"),
        ("/ranges/s_a", serde_json::json!([-1.0, 0.5]), "ranges.s_a"),
        (
            "/grid",
            serde_json::json!({"s_x": [0.0, 5.0], "s_a": [0.0], "s_y": [0.0]}),
            "grid.s_x",
        ),
    ];
    for (pointer, value, field) in cases {
        let mut v = good.clone();
        if pointer == "/grid" {
            v["grid"] = value;
        } else {
            *v.pointer_mut(pointer).unwrap() = value;
        }
        let e = Plan::from_json(&v.to_string(), Some("r.json")).unwrap_err();
        assert_eq!(e.field, field, "{e}");
        assert!(e.to_string().starts_with("r.json: plan field "), "{e}");
    }
    let mut p = Plan::reduced();
    p.ranges_2d = Some(vec![[[-0.5, 0.5], [-0.5, 0.5]]; 9]);
    p.validate().unwrap();
    p.ranges_2d.as_mut().unwrap()[5][1] = [-2000.0, 0.0];
    assert_eq!(p.validate().unwrap_err().field, "ranges_2d[5][1]");
    // the limits themselves are admissible; every built-in plan is valid
    p.ranges_2d = None;
    p.ranges.s_x = [-0.85, MAX_PLAN_STRETCH];
    p.ranges.ii00 = [-MAX_PLAN_CURVATURE, MAX_PLAN_CURVATURE];
    p.ranges.s_a = [-0.999, 0.999];
    p.validate().unwrap();
    for p in [
        Plan::default(),
        Plan::reduced(),
        Plan::quick(),
        Plan::holdout(),
    ] {
        p.validate().unwrap();
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/plans");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "json") {
            Plan::load(&path).unwrap();
            n += 1;
        }
    }
    assert!(n >= 10);
}

#[test]
fn a_byte_order_mark_is_accepted() {
    let text = format!("\u{feff}{}", Plan::reduced().canonical_json());
    assert_eq!(Plan::from_json(&text, None).unwrap(), Plan::reduced());
}

fn check_chains(p: &Plan) {
    for k in 0..5 {
        let r = p.range_1d(k);
        for (i, v) in p.axis_1d(k).into_iter().enumerate() {
            assert_eq!(p.samples()[r.start + i].z[k], v);
        }
    }
    let samples = p.samples();
    assert_eq!(samples.len(), p.len());
    let chains = p.chains();
    assert_eq!(chains.len(), 5 + 9);
    let mut seen = vec![0; p.len()];
    for c in &chains {
        assert_eq!(c.steps[0].from, None);
        let z0 = samples[c.steps[0].sample].z;
        for (i, s) in c.steps.iter().enumerate() {
            seen[s.sample] += 1;
            if i > 0 {
                let f = s.from.unwrap();
                assert!(f < i);
                // each step moves one grid index along one strain, away from the origin
                let a = samples[c.steps[f].sample].z;
                let b = samples[s.sample].z;
                let changed: Vec<usize> = (0..5).filter(|&k| a[k] != b[k]).collect();
                assert_eq!(changed.len(), 1);
                let k = changed[0];
                assert!((b[k] - z0[k]).abs() > (a[k] - z0[k]).abs());
            }
        }
    }
    assert!(seen.iter().all(|&n| n == 1));
}
