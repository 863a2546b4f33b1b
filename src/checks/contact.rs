//! Harness rows for the contact pair energy (`docs/derivative-harness.md`, section 1).
//!
//! Inputs: the 12 coordinates (x_a0, x_a1, x_b0, x_b1); k_c, r, l̄_a, l̄_b and Q are fixed per row.
//!
//! Scales (the `scale` of the tolerance test `‖a − b‖ ≤ tol (‖b‖ + scale)`): value V = k_c l̄_a l̄_b, gradient V/r,
//! Hessian V/r². Every quadrature term is V w_p w_q f(ρ) with f = O(1) over the sampled ρ ∈ [0.3, 1], and each
//! coordinate enters ρ through ‖d‖/(2r), so round-off in the sums is proportional to these magnitudes (not to the
//! value, which is exactly zero beyond the cut-off). Input scales are r: finite-difference steps are 10⁻³ r before
//! the kink rule shrinks them.
//!
//! Kinks: f is only C¹ at ρ = 1, so [`Differentiable::kink_distance`] is min over node pairs of |‖d_pq‖ − 2r|:
//! a change h of one coordinate moves every ‖d_pq‖ by at most |c_k| h ≤ h, so no quadrature distance crosses 2r
//! within that step. The one-sided behaviour at the kink is a unit test in [`crate::contact::pair`].

use crate::contact::{pair_energy_reference, PairKernel};
use crate::diff::{Check, Differentiable, Scales, Vgh};
use crate::real::Real;
use nalgebra::{DMatrix, DVector, Matrix3, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// The pair energy with fixed k_c, r, Q and rest lengths under the harness.
pub struct PairCheck {
    /// the check's name
    pub name: String,
    /// the pair kernel (k_c, r, Q)
    pub kernel: PairKernel,
    /// rest lengths of the two segments (m)
    pub rest: [f64; 2],
}

fn points(x: &[f64]) -> [Vector3<f64>; 4] {
    std::array::from_fn(|k| Vector3::new(x[3 * k], x[3 * k + 1], x[3 * k + 2]))
}

impl Differentiable for PairCheck {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn dim(&self) -> usize {
        12
    }
    fn scales(&self) -> Scales {
        let v = self.kernel.stiffness() * self.rest[0] * self.rest[1];
        let r = self.kernel.radius();
        Scales {
            value: v,
            gradient: v / r,
            hessian: v / (r * r),
        }
    }
    fn input_scale(&self, _i: usize) -> f64 {
        self.kernel.radius()
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        pair_energy_reference(
            x,
            self.rest[0],
            self.rest[1],
            self.kernel.stiffness(),
            D::from(self.kernel.radius()),
            self.kernel.rule(),
        )
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        match self
            .kernel
            .value_gradient_hessian(&points(x), self.rest[0], self.rest[1])
        {
            Ok(v) => Vgh {
                value: v.value,
                gradient: DVector::from_column_slice(v.gradient.as_slice()),
                hessian: DMatrix::from_column_slice(12, 12, v.hessian.as_slice()),
            },
            // an error is a failure of the row (never sampled on purpose): NaN makes the comparison fail
            Err(_) => Vgh {
                value: f64::NAN,
                gradient: DVector::from_element(12, f64::NAN),
                hessian: DMatrix::from_element(12, 12, f64::NAN),
            },
        }
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        self.kernel
            .value(&points(x), self.rest[0], self.rest[1])
            .unwrap_or(f64::NAN)
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        let p = points(x);
        let s = self.kernel.rule().nodes();
        let cut = 2.0 * self.kernel.radius();
        let mut best = f64::INFINITY;
        for &sp in s {
            let xa = p[0].lerp(&p[1], sp);
            for &sq in s {
                let xb = p[2].lerp(&p[3], sq);
                best = best.min(((xa - xb).norm() - cut).abs());
            }
        }
        best
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let p = sample_pair(rng, i, self.kernel.radius(), self.kernel.rule().order());
        p.iter().flat_map(|v| [v.x, v.y, v.z]).collect()
    }
}

/// The pair energy as a function of the 12 coordinates and the contact radius r (13 inputs): the fast side is
/// the kernel's value, gradient and Hessian with the radius derivatives of
/// [`PairKernel::radius_derivatives`] as the 13th gradient entry and the last Hessian row and column (the mixed
/// derivative ∂(∇ₓE)/∂r of the equilibrium sensitivities, docs/yarn-parameters.md); the reference is the plain formula with r
/// as a dual number. Scales as [`PairCheck`] (r is a length like the coordinates, so ∂E/∂r ~ V/r and the mixed
/// and second radius derivatives ~ V/r²); samples are [`sample_pair`]'s at r = 1 mm, the radius input at r.
pub struct PairRadiusCheck {
    /// the check's name
    pub name: String,
    /// contact stiffness k_c (J/m²)
    pub stiffness: f64,
    /// the radius r at which the samples are made (m)
    pub radius: f64,
    /// Gauss–Legendre order Q
    pub order: usize,
    /// rest lengths of the two segments (m)
    pub rest: [f64; 2],
}

impl PairRadiusCheck {
    fn kernel(&self, radius: f64) -> Result<PairKernel, crate::contact::ContactError> {
        PairKernel::new(self.stiffness, radius, self.order)
    }

    /// min over node pairs of |‖d_pq‖ − 2r| at the sample's own radius.
    fn gap_to_cutoff(&self, x: &[f64]) -> f64 {
        let p = points(x);
        let rule = crate::contact::GaussLegendre::new(self.order);
        let cut = 2.0 * x[12];
        let mut best = f64::INFINITY;
        for &sp in rule.nodes() {
            let xa = p[0].lerp(&p[1], sp);
            for &sq in rule.nodes() {
                let xb = p[2].lerp(&p[3], sq);
                best = best.min(((xa - xb).norm() - cut).abs());
            }
        }
        best
    }
}

impl Differentiable for PairRadiusCheck {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn dim(&self) -> usize {
        13
    }
    fn scales(&self) -> Scales {
        let v = self.stiffness * self.rest[0] * self.rest[1];
        let r = self.radius;
        Scales {
            value: v,
            gradient: v / r,
            hessian: v / (r * r),
        }
    }
    fn input_scale(&self, _i: usize) -> f64 {
        self.radius
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        // the pair energy with the radius x[12] as a variable
        pair_energy_reference(
            &x[..12],
            self.rest[0],
            self.rest[1],
            self.stiffness,
            x[12].clone(),
            &crate::contact::GaussLegendre::new(self.order),
        )
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let p = points(x);
        let both = self.kernel(x[12]).and_then(|k| {
            Ok((
                k.value_gradient_hessian(&p, self.rest[0], self.rest[1])?,
                k.radius_derivatives(&p, self.rest[0], self.rest[1])?,
            ))
        });
        match both {
            Ok((v, r)) => {
                let mut gradient = DVector::zeros(13);
                gradient.rows_mut(0, 12).copy_from(&v.gradient);
                gradient[12] = r.value;
                let mut hessian = DMatrix::zeros(13, 13);
                hessian.view_mut((0, 0), (12, 12)).copy_from(&v.hessian);
                for i in 0..12 {
                    hessian[(i, 12)] = r.gradient[i];
                    hessian[(12, i)] = r.gradient[i];
                }
                hessian[(12, 12)] = r.second;
                Vgh {
                    value: v.value,
                    gradient,
                    hessian,
                }
            }
            // an error is a failure of the row (never sampled on purpose): NaN makes the comparison fail
            Err(_) => Vgh {
                value: f64::NAN,
                gradient: DVector::from_element(13, f64::NAN),
                hessian: DMatrix::from_element(13, 13, f64::NAN),
            },
        }
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        self.kernel(x[12])
            .and_then(|k| k.value(&points(x), self.rest[0], self.rest[1]))
            .unwrap_or(f64::NAN)
    }
    fn kink_distance_of(&self, x: &[f64], i: usize) -> f64 {
        // a coordinate step h moves every ‖d_pq‖ by at most h; a radius step h moves the cut-off 2r by 2h
        let d = self.gap_to_cutoff(x);
        if i == 12 {
            0.5 * d
        } else {
            d
        }
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        0.5 * self.gap_to_cutoff(x)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let p = sample_pair(rng, i, self.radius, self.order);
        let mut x: Vec<f64> = p.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
        x.push(self.radius);
        x
    }
}

/// Number of input categories of [`sample_pair`].
pub const PAIR_CATEGORIES: usize = 8;

/// The `i`-th random segment pair for yarn radius r and quadrature order Q, cycling through
/// [`PAIR_CATEGORIES`] categories (lengths in units of r, ρ_min the normalised gap):
///
/// 0. generic crossing: angle in [0.2, π − 0.2], lengths 0.5–3, ρ_min ∈ [0.3, 1);
/// 1. nearly parallel: angle 10⁻⁶…10⁻² rad (log-uniform), lengths 0.5–3, ρ_min ∈ [0.3, 1);
/// 2. at the cut-off: ρ_min ∈ [0.9, 0.999] (most terms just inside or just beyond 2r);
/// 3. deep: ρ_min ∈ [0.3, 0.35];
/// 4. short segments: lengths 10⁻³…10⁻¹ (log-uniform);
/// 5. long segments: lengths 5–30 (most node pairs far apart);
/// 6. partly beyond: the closest node pair is an end node of both segments and the segments run away from each
///    other, so most terms are beyond the cut-off;
/// 7. beyond: ρ_min ∈ [1.0001, 1.5], everything exactly zero.
///
/// Construction: segment a lies in the plane z = +g/2 and b in z = −g/2 (g = 2r ρ_min), so every quadrature
/// distance is at least g; a chosen node pair (p, q) sits near the crossing point of the two lines (jittered along
/// the lines by up to 0.3 r), then the whole pair gets a random rotation and a translation of up to 5 r per axis.
pub fn sample_pair(rng: &mut ChaCha8Rng, i: usize, r: f64, order: usize) -> [Vector3<f64>; 4] {
    let cat = i % PAIR_CATEGORIES;
    let generic_angle = |rng: &mut ChaCha8Rng| rng.random_range(0.2..std::f64::consts::PI - 0.2);
    let usual_len = |rng: &mut ChaCha8Rng| rng.random_range(0.5..3.0) * r;
    let (angle, rho, la, lb) = match cat {
        1 => {
            let a = 10f64.powf(rng.random_range(-6.0..-2.0));
            let a = if rng.random_bool(0.5) { a } else { -a };
            (
                a,
                rng.random_range(0.3..1.0),
                usual_len(rng),
                usual_len(rng),
            )
        }
        2 => (
            generic_angle(rng),
            rng.random_range(0.9..0.999),
            usual_len(rng),
            usual_len(rng),
        ),
        3 => (
            generic_angle(rng),
            rng.random_range(0.3..0.35),
            usual_len(rng),
            usual_len(rng),
        ),
        4 => {
            let mut l = || 10f64.powf(rng.random_range(-3.0..-1.0)) * r;
            let (la, lb) = (l(), l());
            (generic_angle(rng), rng.random_range(0.3..1.0), la, lb)
        }
        5 => (
            generic_angle(rng),
            rng.random_range(0.3..1.0),
            rng.random_range(5.0..30.0) * r,
            rng.random_range(5.0..30.0) * r,
        ),
        6 => (
            generic_angle(rng),
            rng.random_range(0.5..1.0),
            usual_len(rng),
            usual_len(rng),
        ),
        7 => (
            generic_angle(rng),
            rng.random_range(1.0001..1.5),
            usual_len(rng),
            usual_len(rng),
        ),
        _ => (
            generic_angle(rng),
            rng.random_range(0.3..1.0),
            usual_len(rng),
            usual_len(rng),
        ),
    };
    let rule = crate::contact::GaussLegendre::new(order);
    let nodes = rule.nodes();
    let (p, q, jitter) = if cat == 6 {
        // end nodes, segments pointing away from the crossing
        let p = if rng.random_bool(0.5) { 0 } else { order - 1 };
        let q = if rng.random_bool(0.5) { 0 } else { order - 1 };
        (p, q, 0.0)
    } else {
        (
            rng.random_range(0..order),
            rng.random_range(0..order),
            0.3 * r,
        )
    };
    let g = 2.0 * r * rho;
    let ta = Vector3::new(1.0, 0.0, 0.0);
    let tb = Vector3::new(angle.cos(), angle.sin(), 0.0);
    let n = Vector3::new(0.0, 0.0, 1.0);
    let anchor_a = n * (0.5 * g) + ta * rng.random_range(-1.0..=1.0) * jitter;
    let anchor_b = -n * (0.5 * g) + tb * rng.random_range(-1.0..=1.0) * jitter;
    // in category 6, orient the segments so that their chosen end node is the one at the crossing and the rest
    // of each segment runs away from it (p = 0: the segment extends in +t; p = Q − 1: in −t, i.e. still away)
    let (sa, sb) = (nodes[p], nodes[q]);
    let a0 = anchor_a - ta * (sa * la);
    let a1 = anchor_a + ta * ((1.0 - sa) * la);
    let b0 = anchor_b - tb * (sb * lb);
    let b1 = anchor_b + tb * ((1.0 - sb) * lb);
    let rot = random_rotation(rng);
    let shift = Vector3::new(
        rng.random_range(-5.0..5.0),
        rng.random_range(-5.0..5.0),
        rng.random_range(-5.0..5.0),
    ) * r;
    let mut out = [a0, a1, b0, b1].map(|x| rot * x + shift);
    if rng.random_bool(0.5) {
        // swap the roles of a and b now and then
        out.swap(0, 2);
        out.swap(1, 3);
    }
    out
}

/// A uniformly distributed rotation (normalised uniform sample of the unit ball in quaternion space).
pub fn random_rotation(rng: &mut ChaCha8Rng) -> Matrix3<f64> {
    loop {
        let v: [f64; 4] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let n2: f64 = v.iter().map(|x| x * x).sum();
        if n2 > 1e-4 && n2 <= 1.0 {
            let q = nalgebra::Quaternion::new(v[0], v[1], v[2], v[3]);
            return UnitQuaternion::from_quaternion(q)
                .to_rotation_matrix()
                .into_inner();
        }
    }
}

/// The contact rows: the pair energy at the default order Q = 4 and at Q = 2, with the calibrated k_c = 60 J/m²,
/// r = 1 mm and rest lengths 1.5 r and 2 r (typical contact segments); and the same energy with the radius as a
/// 13th input at Q = 4 (the radius derivatives of the equilibrium sensitivities).
pub fn diff_checks() -> Vec<Box<dyn Check>> {
    let r = 1e-3;
    let mut rows: Vec<Box<dyn Check>> = [4usize, 2]
        .into_iter()
        .map(|q| {
            Box::new(PairCheck {
                name: format!("contact pair [Q={q}]"),
                kernel: PairKernel::new(60.0, r, q).expect("valid parameters"),
                rest: [1.5 * r, 2.0 * r],
            }) as Box<dyn Check>
        })
        .collect();
    rows.push(Box::new(PairRadiusCheck {
        name: "contact pair with radius [Q=4]".into(),
        stiffness: 60.0,
        radius: r,
        order: 4,
        rest: [1.5 * r, 2.0 * r],
    }));
    rows
}
