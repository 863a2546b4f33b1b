//! The bending-discretisation variant (`"bending": "sin"` in a yarn file; `docs/yarn-parameters.md`, "Bending
//! discretisation"): rest curvatures stored in the `tan` form carry over exactly (a stress-free rest shape stays
//! stress-free), and the form changes the response of a bent state.

use hylc::generate::{stockinette, weave, KnitParams, WeaveParams};
use hylc::pattern::Pattern;
use hylc::rod::{set_rest_to_current, BendingForm, YarnMaterial};
use hylc::tile::{Terms, Tile, Want};

const BEND: Terms = Terms {
    stretch: 0.0,
    bend: 1.0,
    twist: 0.0,
    contact: 0.0,
};

/// Bending energy and the norm of its gradient at the rest state, and the same at the rest state with every
/// coordinate moved by up to 2 % of the radius.
fn bending_at_rest_and_moved(p: &Pattern, form: BendingForm) -> [(f64, f64); 2] {
    let m = YarnMaterial {
        bending: form,
        ..YarnMaterial::with_radius(p.radius)
    };
    let (state, tile, y) = Tile::at_rest_state(p, &m).unwrap();
    let eval = |y: &[f64]| {
        let r = tile.evaluate(&state, y, Want::Gradient, &BEND).unwrap();
        (r.value(), r.gradient.unwrap().norm())
    };
    let moved: Vec<f64> = y
        .iter()
        .enumerate()
        .map(|(i, v)| v + 0.02 * p.radius * ((i as f64) * 0.7).sin())
        .collect();
    [eval(&y), eval(&moved)]
}

#[test]
fn the_sin_form_keeps_stress_free_rest_shapes_stress_free() {
    // material frames turned along the yarn, so that the rest twists are far from zero and the |cos(m̄/2)| of the
    // conversion is exercised
    let mut knit = stockinette(&KnitParams::default()).unwrap();
    for (i, t) in knit.theta.iter_mut().enumerate() {
        *t = 0.8 * (i as f64 * 0.9).sin();
    }
    set_rest_to_current(&mut knit);
    let twist = knit.rest_twist.iter().fold(0.0f64, |a, t| a.max(t.abs()));
    assert!(twist > 0.05, "max rest twist {twist}");
    for (name, p) in [
        ("plain", weave(&WeaveParams::plain()).unwrap()),
        ("stockinette", knit),
    ] {
        for form in [BendingForm::Tan, BendingForm::Sin] {
            let [(e0, g0), (e1, g1)] = bending_at_rest_and_moved(&p, form);
            assert!(e1 > 0.0 && g1 > 0.0, "{name} {form:?}");
            assert!(e0 <= 1e-20 * e1, "{name} {form:?}: {e0} vs {e1}");
            assert!(g0 <= 1e-9 * g1, "{name} {form:?}: |g| {g0} vs {g1}");
        }
    }
}

#[test]
fn the_sin_form_bends_more_softly_at_large_turning_angles() {
    // moved off the rest shape, the sin form's curvature changes by cos(φ/2) / sec²(φ/2) < 1 of the tan form's
    // per unit angle, so its bending energy is smaller for the same displacement of a curved yarn
    let p = stockinette(&KnitParams::default()).unwrap();
    let [_, (tan, _)] = bending_at_rest_and_moved(&p, BendingForm::Tan);
    let [_, (sin, _)] = bending_at_rest_and_moved(&p, BendingForm::Sin);
    assert!(sin < 0.98 * tan && sin > 0.3 * tan, "sin {sin} tan {tan}");
}
