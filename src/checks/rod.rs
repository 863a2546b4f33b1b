//! Harness rows for the rod stencils (`docs/derivative-harness.md`, section 1): stretching and bending+twisting with frame
//! transport.
//!
//! Samples carry the stencil's stored state as harness parameters (never differentiated): the stored frames come
//! from an "old" configuration, and the evaluation point is either that configuration itself (what the solver
//! differentiates) or a perturbation of it (what the line search and finite differences see). Categories, cycled
//! with the sample index: generic; at the stored state; turning angle up to 179°; nearly straight; edges from
//! 1e-3 r to 1e3 r (r = 1 mm); θ and stored reference twist beyond ±π.
//!
//! Scales: a stiffness K divided by powers of the shortest edge L. For bending+twisting K = (B + GJ)/l̄, the energy
//! of a unit change of the (dimensionless) integrated curvature or twist; gradient K/L, Hessian K/L². For
//! stretching K = k_s l̄ (the energy of unit strain), gradient k_s, Hessian k_s / min(l, l̄). Position inputs are
//! scaled by L, angles by 1.

use crate::diff::{Check, Differentiable, Scales, Vgh};
use crate::real::Real;
use crate::rod::bend_twist::{
    bend_twist_reference, bend_twist_value, bend_twist_vgh, unpack, BendTwistParams, StencilFrames,
};
use crate::rod::frame::reference_twist_raw;
use crate::rod::stretch::{stretch_reference, stretch_value, stretch_vgh};
use crate::rod::{BendingForm, YarnMaterial};
use nalgebra::{DMatrix, DVector, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

const R: f64 = 1e-3;

fn random_unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 0.1 && n < 1.0 {
            return v / n;
        }
    }
}

fn random_perp(rng: &mut ChaCha8Rng, t: &Vector3<f64>) -> Vector3<f64> {
    loop {
        let v = random_unit(rng);
        let p = v - t * t.dot(&v);
        if p.norm() > 0.1 {
            return p.normalize();
        }
    }
}

/// A unit vector at angle `phi` from `t`.
fn at_angle(rng: &mut ChaCha8Rng, t: &Vector3<f64>, phi: f64) -> Vector3<f64> {
    let p = random_perp(rng, t);
    t * phi.cos() + p * phi.sin()
}

/// Stretching of one edge: inputs (x_start, x_end), parameters (l̄, k_s).
pub struct StretchCheck;

impl Differentiable for StretchCheck {
    fn name(&self) -> String {
        "rod-stretch".into()
    }
    fn dim(&self) -> usize {
        6
    }
    fn n_params(&self) -> usize {
        2
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        let (rest, ks) = (x[6], x[7]);
        let l = (Vector3::new(x[3], x[4], x[5]) - Vector3::new(x[0], x[1], x[2])).norm();
        Scales {
            value: ks * rest,
            gradient: ks,
            hessian: ks / l.min(rest),
        }
    }
    fn input_scale_at(&self, x: &[f64], _i: usize) -> f64 {
        let l = (Vector3::new(x[3], x[4], x[5]) - Vector3::new(x[0], x[1], x[2])).norm();
        l.min(x[6])
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        stretch_reference(x, x[6].re(), x[7].re())
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let (a, b) = (
            Vector3::new(x[0], x[1], x[2]),
            Vector3::new(x[3], x[4], x[5]),
        );
        let (v, g, h) = stretch_vgh(&a, &b, x[6], x[7]);
        Vgh {
            value: v,
            gradient: DVector::from_column_slice(g.as_slice()),
            hessian: DMatrix::from_column_slice(6, 6, h.as_slice()),
        }
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        stretch_value(
            &Vector3::new(x[0], x[1], x[2]),
            &Vector3::new(x[3], x[4], x[5]),
            x[6],
            x[7],
        )
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let ks = YarnMaterial::default().stretch_stiffness();
        // lengths: generic near r, or the extremes 1e-3 r … 1e3 r
        let rest = if i % 3 == 2 {
            R * 10f64.powf(rng.random_range(-3.0..3.0))
        } else {
            R * rng.random_range(0.5..2.0)
        };
        let strain: f64 = match i % 4 {
            0 => 0.0,
            1 => rng.random_range(-0.5..1.0),
            _ => rng.random_range(-0.05..0.05),
        };
        let a = random_unit(rng) * rng.random_range(0.0..10.0) * R;
        let b = a + random_unit(rng) * rest * (1.0 + strain);
        vec![a.x, a.y, a.z, b.x, b.y, b.z, rest, ks]
    }
}

/// Bending+twisting stencil: inputs (x⁰, x¹, x², θ⁰, θ¹); parameters (t⁰, u⁰, t¹, u¹ of the stored state, stored
/// reference twist, κ̄₁, κ̄₂, m̄, l̄, B, GJ), with the curvature in the given [`BendingForm`].
pub struct BendTwistCheck(pub BendingForm);

fn parse(x: &[f64], form: BendingForm) -> (StencilFrames, BendTwistParams) {
    let v = |k: usize| Vector3::new(x[k], x[k + 1], x[k + 2]);
    let fr = StencilFrames::new(v(11), v(14), v(17), v(20), x[23]);
    let p = BendTwistParams {
        rest_curvature: [x[24], x[25]],
        rest_twist: x[26],
        voronoi_length: x[27],
        bend: x[28],
        twist: x[29],
        form,
    };
    (fr, p)
}

fn shortest_edge(x: &[f64]) -> f64 {
    let (p, _) = unpack(x);
    (p[1] - p[0]).norm().min((p[2] - p[1]).norm())
}

impl Differentiable for BendTwistCheck {
    fn name(&self) -> String {
        match self.0 {
            BendingForm::Tan => "rod-bend-twist".into(),
            BendingForm::Sin => "rod-bend-twist-sin".into(),
        }
    }
    fn dim(&self) -> usize {
        11
    }
    fn n_params(&self) -> usize {
        19
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        let (_, p) = parse(x, self.0);
        let k = (p.bend + p.twist) / p.voronoi_length;
        let l = shortest_edge(x);
        Scales {
            value: k,
            gradient: k / l,
            hessian: k / (l * l),
        }
    }
    fn input_scale_at(&self, x: &[f64], i: usize) -> f64 {
        if i < 9 {
            shortest_edge(x)
        } else {
            1.0
        }
    }
    /// Near a fold (turning angle φ → π) the energy varies on the length scale (π − φ) L; finite differences stay
    /// well inside it.
    fn kink_distance_of(&self, x: &[f64], i: usize) -> f64 {
        if i >= 9 {
            return f64::INFINITY;
        }
        let (p, _) = unpack(x);
        let (e0, e1) = (p[1] - p[0], p[2] - p[1]);
        let phi = e0.angle(&e1);
        0.01 * shortest_edge(x) * (PI - phi).min(1.0)
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let xf: Vec<f64> = x.iter().map(|v| v.re()).collect();
        let (fr, p) = parse(&xf, self.0);
        bend_twist_reference(&x[..11], &fr, &p)
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let (fr, p) = parse(x, self.0);
        let (pos, th) = unpack(x);
        let (v, g, h) = bend_twist_vgh(&pos, th, &fr, &p);
        Vgh {
            value: v,
            gradient: DVector::from_column_slice(g.as_slice()),
            hessian: DMatrix::from_column_slice(11, 11, h.as_slice()),
        }
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        let (fr, p) = parse(x, self.0);
        let (pos, th) = unpack(x);
        bend_twist_value(&pos, th, &fr, &p)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let cat = i % 6;
        let (l0, l1) = if cat == 4 {
            (
                R * 10f64.powf(rng.random_range(-3.0..3.0)),
                R * 10f64.powf(rng.random_range(-3.0..3.0)),
            )
        } else {
            (
                R * rng.random_range(0.5..2.0),
                R * rng.random_range(0.5..2.0),
            )
        };
        let phi = match cat {
            2 => PI * rng.random_range(0.9..(179.0 / 180.0)),
            3 => 10f64.powf(rng.random_range(-8.0..-3.0)),
            _ => rng.random_range(0.0..2.0),
        };
        // stored ("old") state
        let t0 = random_unit(rng);
        let t1 = at_angle(rng, &t0, phi);
        let x1 = random_unit(rng) * rng.random_range(0.0..5.0) * R;
        let mut pos = [x1 - t0 * l0, x1, x1 + t1 * l1];
        let u0 = random_perp(rng, &t0);
        let u1 = random_perp(rng, &t1);
        let raw = reference_twist_raw(&t0, &u0, &t1, &u1);
        let wind = if cat == 5 {
            rng.random_range(-2..=2) as f64
        } else {
            0.0
        };
        let stored_twist = raw + 2.0 * PI * wind;
        // evaluation point: the stored state itself, or a perturbation of it
        if cat != 1 {
            // small enough that a stencil near a fold stays below 180°
            let size = rng.random_range(0.0..0.1) * l0.min(l1) * (PI - phi).min(1.0);
            for p in pos.iter_mut() {
                *p += random_unit(rng) * size;
            }
        }
        let span = if cat == 5 { 3.0 * PI } else { PI };
        let th = [rng.random_range(-span..span), rng.random_range(-span..span)];
        let m = YarnMaterial::default();
        let rest_k = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
        let rest_m = rng.random_range(-1.0..1.0) + 2.0 * PI * wind;
        let mut x = Vec::with_capacity(30);
        for p in &pos {
            x.extend_from_slice(p.as_slice());
        }
        x.extend_from_slice(&th);
        for v in [t0, u0, t1, u1] {
            x.extend_from_slice(v.as_slice());
        }
        x.push(stored_twist);
        x.extend_from_slice(&rest_k);
        x.push(rest_m);
        x.push(0.5 * (l0 + l1) * rng.random_range(0.8..1.2));
        x.push(m.bend_stiffness());
        x.push(m.twist_stiffness());
        x
    }
}

/// The rod rows of the harness.
pub fn diff_checks() -> Vec<Box<dyn Check>> {
    vec![
        Box::new(StretchCheck),
        Box::new(BendTwistCheck(BendingForm::Tan)),
        Box::new(BendTwistCheck(BendingForm::Sin)),
    ]
}
