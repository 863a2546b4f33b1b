//! Property tests of the rod stencils (`docs/yarn-model.md`): invariance under rigid motions and under
//! a rotation of the reference frames compensated by θ, gradients that sum to zero over a translation, and a
//! reference twist that stays continuous along a path crossing ±π.

use hylc::rod::bend_twist::{bend_twist_value, bend_twist_vgh, BendTwistParams, StencilFrames};
use hylc::rod::frame::{continuous_twist, reference_twist_raw};
use hylc::rod::stretch::stretch_vgh;
use hylc::rod::{BendingForm, YarnMaterial};
use nalgebra::{Rotation3, Unit, Vector3};
use proptest::prelude::*;
use std::f64::consts::PI;

fn vec3(range: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

fn unit() -> impl Strategy<Value = Vector3<f64>> {
    vec3(1.0).prop_filter_map("non-degenerate", |v| {
        (v.norm() > 0.2).then(|| v.normalize())
    })
}

/// A unit vector perpendicular to `t`, at angle `a` in the plane ⟂ t.
fn perp(t: &Vector3<f64>, a: f64) -> Vector3<f64> {
    let helper = if t.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let p = (helper - t * t.dot(&helper)).normalize();
    let q = t.cross(&p);
    p * a.cos() + q * a.sin()
}

/// A random stencil: positions, angles, stored frames at those positions, parameters.
#[derive(Clone, Debug)]
struct Stencil {
    x: [Vector3<f64>; 3],
    theta: [f64; 2],
    frames: StencilFrames,
    params: BendTwistParams,
}

fn stencil() -> impl Strategy<Value = Stencil> {
    (
        vec3(5e-3),
        unit(),
        unit(),
        0.5e-3..2e-3f64,
        0.5e-3..2e-3f64,
        (-PI..PI, -PI..PI),
        (-PI..PI, -PI..PI),
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        prop::bool::ANY,
    )
        .prop_filter("not folded", |(_, a, b, ..)| a.dot(b) > -0.95)
        .prop_map(
            |(x1, t0, t1, l0, l1, (a0, a1), (th0, th1), (k1, k2, m), sin)| {
                let u0 = perp(&t0, a0);
                let u1 = perp(&t1, a1);
                let twist = reference_twist_raw(&t0, &u0, &t1, &u1);
                let mat = YarnMaterial::default();
                Stencil {
                    x: [x1 - t0 * l0, x1, x1 + t1 * l1],
                    theta: [th0, th1],
                    frames: StencilFrames::new(t0, u0, t1, u1, twist),
                    params: BendTwistParams {
                        rest_curvature: [k1, k2],
                        rest_twist: m,
                        voronoi_length: 0.5 * (l0 + l1),
                        bend: mat.bend_stiffness(),
                        twist: mat.twist_stiffness(),
                        form: if sin {
                            BendingForm::Sin
                        } else {
                            BendingForm::Tan
                        },
                    },
                }
            },
        )
}

/// A perturbation of the positions (the stored frames stay) so that transport is exercised.
fn perturbed(s: &Stencil, d: &[Vector3<f64>; 3]) -> [Vector3<f64>; 3] {
    [s.x[0] + d[0], s.x[1] + d[1], s.x[2] + d[2]]
}

fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / (b.abs() + scale)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn bend_twist_is_invariant_under_rigid_motions(
        s in stencil(),
        d in (vec3(1e-4), vec3(1e-4), vec3(1e-4)),
        axis in unit(),
        angle in -PI..PI,
        shift in vec3(1e-2),
    ) {
        let x = perturbed(&s, &[d.0, d.1, d.2]);
        let e = bend_twist_value(&x, s.theta, &s.frames, &s.params);
        let q = Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle);
        let xr = x.map(|p| q * p + shift);
        let f = &s.frames;
        let fr = StencilFrames::new(q * f.t0, q * f.u0, q * f.t1, q * f.u1, f.twist);
        let er = bend_twist_value(&xr, s.theta, &fr, &s.params);
        let scale = (s.params.bend + s.params.twist) / s.params.voronoi_length;
        // round-off: moving millimetre coordinates by up to 1 cm costs ~1e-14 relative in the edge vectors, which
        // near-folded stencils amplify
        prop_assert!(rel(er, e, scale) < 1e-10, "{} vs {}", er, e);
    }

    #[test]
    fn rotating_the_reference_frames_with_theta_changes_nothing(
        s in stencil(),
        d in (vec3(1e-4), vec3(1e-4), vec3(1e-4)),
        alpha in (-PI..PI, -PI..PI),
    ) {
        // u → cos α u + sin α v and θ → θ − α leaves the material frame unchanged; the reference twist moves by
        // α¹ − α⁰ and the twist m = θ¹ − θ⁰ + τ stays.
        let x = perturbed(&s, &[d.0, d.1, d.2]);
        let e = bend_twist_value(&x, s.theta, &s.frames, &s.params);
        let f = &s.frames;
        let rot = |t: &Vector3<f64>, u: &Vector3<f64>, a: f64| u * a.cos() + t.cross(u) * a.sin();
        let fr = StencilFrames::new(
            f.t0,
            rot(&f.t0, &f.u0, alpha.0),
            f.t1,
            rot(&f.t1, &f.u1, alpha.1),
            f.twist + alpha.1 - alpha.0,
        );
        let th = [s.theta[0] - alpha.0, s.theta[1] - alpha.1];
        let er = bend_twist_value(&x, th, &fr, &s.params);
        let scale = (s.params.bend + s.params.twist) / s.params.voronoi_length;
        prop_assert!(rel(er, e, scale) < 1e-10, "{} vs {}", er, e);
    }

    #[test]
    fn gradients_sum_to_zero_over_a_translation(
        s in stencil(),
        d in (vec3(1e-4), vec3(1e-4), vec3(1e-4)),
        strain in -0.3..0.3f64,
    ) {
        let x = perturbed(&s, &[d.0, d.1, d.2]);
        let (_, g, h) = bend_twist_vgh(&x, s.theta, &s.frames, &s.params);
        let scale = (s.params.bend + s.params.twist) / s.params.voronoi_length / 1e-3;
        for c in 0..3 {
            let sum = g[c] + g[3 + c] + g[6 + c];
            prop_assert!(sum.abs() <= 1e-10 * (g.norm() + scale), "component {}: {}", c, sum);
            // the Hessian maps a translation to zero as well
            for r in 0..11 {
                let hs = h[(r, c)] + h[(r, 3 + c)] + h[(r, 6 + c)];
                prop_assert!(hs.abs() <= 1e-10 * (h.norm() + scale / 1e-3), "row {}: {}", r, hs);
            }
        }
        let ks = YarnMaterial::default().stretch_stiffness();
        let rest = (x[1] - x[0]).norm() / (1.0 + strain);
        let (_, gs, _) = stretch_vgh(&x[0], &x[1], rest, ks);
        for c in 0..3 {
            prop_assert!((gs[c] + gs[3 + c]).abs() <= 1e-12 * (gs.norm() + ks));
        }
    }

    #[test]
    fn reference_twist_is_continuous_through_pi(
        t0 in unit(),
        t1 in unit(),
        a0 in -PI..PI,
        before in 0.05..1.0f64,
        steps in 20usize..60,
    ) {
        prop_assume!(t0.dot(&t1) > -0.9);
        // rotating u¹ by b about t¹ adds b to the raw angle; start `before` below π and rotate by 1 rad, so the raw
        // angle jumps from +π to −π on the way while the continued twist must grow smoothly by 1
        let u0 = perp(&t0, a0);
        let c = PI - before - reference_twist_raw(&t0, &u0, &t1, &perp(&t1, 0.0));
        let raw0 = reference_twist_raw(&t0, &u0, &t1, &perp(&t1, c));
        prop_assert!((raw0 - (PI - before)).abs() < 1e-9);
        let mut twist = raw0;
        let mut raw_prev = raw0;
        let mut crossed = false;
        for k in 1..=steps {
            let b = k as f64 / steps as f64;
            let raw = reference_twist_raw(&t0, &u0, &t1, &perp(&t1, c + b));
            let next = continuous_twist(twist, raw_prev, raw);
            prop_assert!((next - twist - 1.0 / steps as f64).abs() < 1e-9, "jump {}", next - twist);
            crossed |= (raw - raw_prev).abs() > PI;
            twist = next;
            raw_prev = raw;
        }
        prop_assert!(crossed, "the raw angle never wrapped");
        prop_assert!((twist - raw0 - 1.0).abs() < 1e-9);
        prop_assert!(twist > PI);
    }
}
