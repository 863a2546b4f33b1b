//! Yarn crossings along a motion (`hylc::contact::ccd`, `Tile::crossings`, `SolverOptions::crossings`): the guard
//! that keeps a start's equilibrium in the fabric it started in (`docs/sampling.md`, "The crossing guard").
//! Generated patterns only.

use hylc::contact::ccd::net_crossings;
use hylc::contact::SegmentTopology;
use hylc::generate::default_pattern;
use hylc::micro::reference::{reference_state, Construction, ReferenceOptions};
use hylc::micro::{CrossingGuard, MacroStrain, MicroProblem, SolverOptions, Status};
use hylc::rod::YarnMaterial;
use hylc::tile::Tile;

/// The generated stockinette's reference state (knitted) and its report.
fn stockinette_reference(
    yarn: &YarnMaterial,
) -> (
    hylc::pattern::Pattern,
    hylc::micro::reference::ReferenceReport,
) {
    let pattern = default_pattern("stockinette").unwrap();
    reference_state(
        &pattern,
        yarn,
        Construction::Knitted,
        &SolverOptions::default(),
        &ReferenceOptions::default(),
    )
    .unwrap()
}

/// Mirroring one weave yarn's undulation moves it through every yarn it crosses: the straight-line motion has
/// crossings, each pairing that yarn with another, and the way back has the opposite directions (net zero over
/// both). Staying put, or moving every vertex by at most 0.2 r, crosses nothing.
#[test]
fn a_weave_yarn_pushed_through_its_crossing_yarns_is_seen() {
    let pattern = default_pattern("plain").unwrap();
    let (_, tile, y) = Tile::at_rest_state(&pattern, &YarnMaterial::default()).unwrap();
    let topology = SegmentTopology::from_pattern(&pattern);
    let yarn0: Vec<usize> = (0..pattern.len())
        .filter(|&v| topology.yarn(v) == 0)
        .collect();
    let zmean = yarn0.iter().map(|&v| y[3 * v + 2]).sum::<f64>() / yarn0.len() as f64;
    let mut mirrored = y.clone();
    for &v in &yarn0 {
        mirrored[3 * v + 2] = 2.0 * zmean - y[3 * v + 2];
    }

    let forth = tile.crossings(&y, &mirrored).unwrap();
    assert!(!forth.is_empty(), "no crossing found");
    for c in &forth {
        let (ya, yb) = (topology.yarn(c.a), topology.yarn(c.b));
        assert!(ya != yb && (ya == 0 || yb == 0), "{c:?}: yarns {ya}, {yb}");
        assert!((0.0..=1.0).contains(&c.time), "{c:?}");
        assert!(c.sign == 1 || c.sign == -1, "{c:?}");
    }
    assert!(!net_crossings(&forth).is_empty());

    let back = tile.crossings(&mirrored, &y).unwrap();
    assert_eq!(back.len(), forth.len());
    let both: Vec<_> = forth.iter().chain(&back).copied().collect();
    assert!(
        net_crossings(&both).is_empty(),
        "{:?}",
        net_crossings(&both)
    );

    assert!(tile.crossings(&y, &y).unwrap().is_empty());
    let r = pattern.radius;
    let mut wiggled = y.clone();
    for (i, v) in wiggled.iter_mut().take(3 * pattern.len()).enumerate() {
        *v += 0.2 * r * (1.7 * i as f64).sin();
    }
    assert!(tile.crossings(&y, &wiggled).unwrap().is_empty());
}

/// The generated stockinette's cold start at the biaxial stretch (s_x, s_y) = (0.45, 0.96) pulls loops through
/// each other (a multi-start run kept 0.067 J/m² there, below the rest state's 0.75): counted, the path
/// has crossings that do not cancel; rejected, the solve converges without any, to the stretched knit's energy
/// (the warm chain's 124 J/m²), far above the rest state's.
#[test]
fn a_cold_knit_start_that_pulls_loops_through_is_caught_and_kept_out() {
    let yarn = YarnMaterial::default();
    let (reference, report) = stockinette_reference(&yarn);
    let f0 = report.psi;
    let z = MacroStrain([0.45, 0.0, 0.96, 0.0, 0.0]);
    let solve = |crossings, max_steps| {
        let options = SolverOptions {
            crossings,
            max_steps,
            ..Default::default()
        };
        MicroProblem::new(reference.clone(), &yarn, options)
            .solve(&z, None)
            .unwrap()
    };
    let counted = solve(CrossingGuard::Count, 300);
    assert!(counted.net_crossings() > 0, "no crossing counted");
    assert_eq!(counted.rejected_crossings, 0);

    let guarded = solve(CrossingGuard::Reject, 2000);
    assert_eq!(guarded.status, Status::Converged);
    assert!(guarded.crossings.is_empty());
    assert!(guarded.rejected_crossings > 0);
    let psi = guarded.psi().unwrap();
    eprintln!("f0 {f0:.4} J/m², guarded cold Ψ̄ {psi:.4} J/m²");
    assert!(psi > 100.0 * f0, "Ψ̄ {psi} against f0 {f0}");

    // off: the same solver path and problem hash as before the option existed (the hash's settings text has
    // no `crossings` key while off)
    let plain = SolverOptions::default().hash_text();
    assert!(!plain.contains("crossings"), "{plain}");
}

/// A warm start moves to its new strain at fixed local displacements ũ before Newton starts
/// (`MicroProblem::start_crossings`, `hylc::micro::path`): the rest fabric deformed by a strain step crosses
/// nothing, but a weft yarn held a large ũ away from its own place (onto its neighbour, 0.1 r beside it) passes
/// through that neighbour when a stretch s_x moves the two apart at fixed ũ, and does not when the stretch moves
/// it the other way.
#[test]
fn a_warm_start_moved_to_its_strain_at_fixed_displacements_is_checked() {
    let pattern = default_pattern("plain").unwrap();
    let problem = MicroProblem::new(
        pattern.clone(),
        &YarnMaterial::default(),
        SolverOptions::default(),
    );
    let rest = problem.reference_state();
    for z in [
        [0.2, 0.0, 0.0, 0.0, 0.0],
        [-0.1, 0.3, 0.2, 40.0, 0.0],
        [0.1, 0.0, -0.1, 0.0, -60.0],
    ] {
        let z = MacroStrain(z);
        let crossed = problem.start_crossings(&rest, &rest, &z).unwrap();
        assert!(
            crossed.is_empty(),
            "rest fabric moved to {z:?}: {crossed:?}"
        );
    }

    // the weft yarns (constant x along each) in order of x; weft j is put 0.1 r beside weft k = j + 1
    let mut wefts: Vec<(f64, Vec<usize>)> = pattern
        .yarns()
        .into_iter()
        .filter(|y| {
            y.iter()
                .all(|&v| (pattern.positions[v].x - pattern.positions[y[0]].x).abs() < 1e-9)
        })
        .map(|y| (pattern.positions[y[0]].x, y))
        .collect();
    wefts.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(wefts.len() >= 2, "{} weft yarns", wefts.len());
    let ((xj, j), (xk, k)) = (&wefts[0], &wefts[1]);
    let mut moved = rest.clone();
    for &v in j {
        moved.y[3 * v] = xk - xj + 0.1 * pattern.radius;
    }
    let stretched = MacroStrain([0.2, 0.0, 0.0, 0.0, 0.0]);
    let crossed = problem.start_crossings(&moved, &moved, &stretched).unwrap();
    let yarn_of = |s: usize| {
        if j.contains(&s) {
            'j'
        } else if k.contains(&s) {
            'k'
        } else {
            '-'
        }
    };
    assert!(
        crossed.iter().any(|c| {
            let pair = (yarn_of(c.a), yarn_of(c.b));
            pair == ('j', 'k') || pair == ('k', 'j')
        }),
        "{crossed:?}"
    );
    assert!(!net_crossings(&crossed).is_empty());
    // the same state compressed: weft j moves further beside weft k, not through it
    let compressed = MacroStrain([-0.1, 0.0, 0.0, 0.0, 0.0]);
    let crossed = problem
        .start_crossings(&moved, &moved, &compressed)
        .unwrap();
    assert!(
        !crossed.iter().any(|c| {
            let pair = (yarn_of(c.a), yarn_of(c.b));
            pair == ('j', 'k') || pair == ('k', 'j')
        }),
        "{crossed:?}"
    );
}

/// The knit case behind it (held-out and `hylc run` samples that landed far below their neighbours):
/// the warm chain of `hylc run`'s (s_x, s_y) grid on the generated stockinette, (0.07, 0.07) → (−0.22, 0.07) →
/// (−0.44, 0.07) → (−0.44, −0.22), predicts its start at (−0.44, −0.44) by the secant; the way there from the
/// last equilibrium pulls yarns through each other before Newton's first step. The plain warm start (no
/// prediction) moved there does not, nor does a small strain step.
#[test]
fn a_compressed_knit_chain_start_crosses_on_its_way_to_the_next_grid_point() {
    let yarn = YarnMaterial::default();
    let (reference, _) = stockinette_reference(&yarn);
    let options = SolverOptions {
        crossings: CrossingGuard::Count,
        ..Default::default()
    };
    let problem = MicroProblem::new(reference, &yarn, options);
    let (a, b, c) = (
        0.06952009047299446,
        -0.22119634070845418,
        -0.43875356526868514,
    );
    let z = |sx: f64, sy: f64| MacroStrain([sx, 0.0, sy, 0.0, 0.0]);
    let solve = |z: MacroStrain, start: Option<&hylc::micro::MicroState>| {
        let sol = problem.solve(&z, start).unwrap();
        assert_eq!(
            (sol.status, sol.net_crossings()),
            (Status::Converged, 0),
            "{z:?}"
        );
        sol.state
    };
    let s0 = solve(z(a, a), None);
    let s1 = solve(z(b, a), Some(&s0));
    let p2 = problem.predict(&s0, &s1, &z(c, a)).unwrap().unwrap();
    let s2 = solve(z(c, a), Some(&p2));
    let s3 = solve(z(c, b), Some(&s2));
    let target = z(c, c);
    let predicted = problem.predict(&s2, &s3, &target).unwrap().unwrap();
    let crossed = problem.start_crossings(&s3, &predicted, &target).unwrap();
    assert!(!net_crossings(&crossed).is_empty(), "{crossed:?}");
    let warm = problem.start_crossings(&s3, &s3, &target).unwrap();
    let small = problem.start_crossings(&s3, &s3, &z(c, b - 0.01)).unwrap();
    eprintln!(
        "predicted start: {} crossings; warm: {}; small step: {}",
        crossed.len(),
        warm.len(),
        small.len()
    );
    assert!(warm.is_empty(), "{warm:?}");
    assert!(small.is_empty(), "{small:?}");
}
