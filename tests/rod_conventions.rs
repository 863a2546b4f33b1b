//! The rod conventions of `docs/yarn-model.md` against the five original patterns: the stored reference twists are
//! reproduced from the stored reference directors, and the stored rest curvatures and twists agree with the
//! curvatures and twists measured at the stored state (up to the rest-shape scaling of Algorithm C1).
//!
//! The files print every number with 6 significant digits. Rounding the inputs alone moves a recomputed reference
//! twist by ~8e-7 rad RMS and up to ~5e-6 rad (measured by perturbing the inputs within their last digit), so the
//! tolerances below are RMS ≤ 2e-6 rad and max ≤ 2e-5 rad; a wrong convention (sign, transport direction, which
//! edge a director belongs to) gives errors of order 0.1–3 rad.

mod common;

use hylc::pattern::Pattern;
use hylc::periodic::Translation;
use hylc::rod::frame::angle_diff;
use hylc::rod::{raw_reference_twists, RodState, RodTopology};

const NAMES: [&str; 5] = [
    "basket",
    "satin",
    "slip_stitch_honeycomb",
    "stockinette",
    "cartridge_belt_rib",
];

fn load(name: &str) -> Option<Pattern> {
    let dir = common::shared_or_skip("rod_conventions")?.join("data/hylc2020/patterns");
    let (p, _) =
        Pattern::load_pyp(dir.join(format!("{name}.pyp"))).expect("original pattern loads");
    Some(p)
}

/// (max, rms) of the difference between recomputed and stored reference twists, modulo 2π.
fn twist_errors(p: &Pattern) -> (f64, f64) {
    let raw = raw_reference_twists(p);
    let d: Vec<f64> = raw
        .iter()
        .zip(&p.ref_twist)
        .map(|(a, b)| angle_diff(*a, *b))
        .collect();
    let max = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let rms = (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt();
    (max, rms)
}

#[test]
fn stored_reference_twists_are_reproduced() {
    for name in NAMES {
        let Some(mut p) = load(name) else { return };
        if name == "basket" {
            // basket's stored periods are inconsistent with its periodic edges; its directors were computed with
            // the periods its rest lengths imply
            let implied = p.implied_periods().expect("basket has periodic edges");
            let (max, _) = twist_errors(&p);
            assert!(
                max > 1e-4,
                "basket with stored periods should not match: {max:e}"
            );
            p.periods = implied;
        }
        let (max, rms) = twist_errors(&p);
        println!("{name}: reference twist error max {max:.2e} rms {rms:.2e} rad");
        assert!(
            max <= 2e-5 && rms <= 2e-6,
            "{name}: max {max:e}, rms {rms:e}"
        );
    }
}

#[test]
fn a_wrong_convention_is_detected() {
    // transporting the directors the other way round (u¹ to t⁰) flips the sign of the reference twist
    let Some(p) = load("satin") else { return };
    let raw = raw_reference_twists(&p);
    let flipped: f64 = raw
        .iter()
        .zip(&p.ref_twist)
        .map(|(a, b)| angle_diff(-*a, *b).abs())
        .fold(0.0, f64::max);
    assert!(flipped > 1e-2, "sign flip not detected: {flipped:e}");
}

/// Correlation and least-squares ratio of measured against stored values.
fn corr_ratio(measured: &[f64], stored: &[f64]) -> (f64, f64) {
    let sxy: f64 = measured.iter().zip(stored).map(|(a, b)| a * b).sum();
    let sxx: f64 = measured.iter().map(|a| a * a).sum();
    let syy: f64 = stored.iter().map(|b| b * b).sum();
    (sxy / (sxx * syy).sqrt(), sxy / sxx)
}

#[test]
fn stored_rest_curvatures_follow_the_conventions() {
    // Algorithm C1 scales the rest curvatures of woven patterns by 0.9 (knitted: 0.8) after measuring them, and
    // then re-equilibrates, so the stored rest curvatures are ≈ 0.9 × the curvatures at the stored state.
    for name in NAMES {
        let Some(mut p) = load(name) else { return };
        if let Some(implied) = (name == "basket").then(|| p.implied_periods()).flatten() {
            p.periods = implied;
        }
        let state = RodState::from_pattern(&p);
        let topo = RodTopology::new(&p);
        let kin = state.kinematics(&topo, &Translation { periods: p.periods });
        let measured: Vec<f64> = kin.iter().flat_map(|k| k.curvature).collect();
        let stored: Vec<f64> = p.rest_curvature.iter().flatten().copied().collect();
        let (corr, ratio) = corr_ratio(&measured, &stored);
        // swapping the two curvature components (a convention error) destroys the agreement
        let swapped: Vec<f64> = kin
            .iter()
            .flat_map(|k| [k.curvature[1], k.curvature[0]])
            .collect();
        let (corr_swapped, _) = corr_ratio(&swapped, &stored);
        println!(
            "{name}: rest curvature correlation {corr:.4}, ratio {ratio:.3} (components swapped: {corr_swapped:.3})"
        );
        assert!(
            corr_swapped < 0.5,
            "{name}: swapped correlation {corr_swapped}"
        );
        match name {
            "basket" | "satin" => {
                assert!(
                    corr > 0.99 && (0.85..0.95).contains(&ratio),
                    "{name}: {corr} {ratio}"
                )
            }
            "slip_stitch_honeycomb" => {
                assert!(
                    corr > 0.98 && (0.85..0.95).contains(&ratio),
                    "{name}: {corr} {ratio}"
                )
            }
            // the tight knits are not equilibria of the stored rest shape (docs/yarn-model.md); their curvatures
            // still follow the stored ones closely
            _ => assert!(corr > 0.85 && ratio > 0.5, "{name}: {corr} {ratio}"),
        }
    }
}
