//! Yarn–yarn contact (`docs/yarn-model.md`, "Yarn-yarn contact").
//!
//! The Kaldor–James–Marschner (2008) penalty between two straight segments a and b,
//!
//! E_ab = k_c l̄_a l̄_b Σ_p Σ_q w_p w_q f(‖x_a(s_p) − x_b(s_q)‖ / (2r)),  f(ρ) = 1/ρ² + ρ² − 2 for ρ < 1, else 0,
//!
//! with x(s) = (1 − s) x_start + s x_end and Gauss–Legendre nodes and weights (s_p, w_p) on [0, 1]
//! ([`GaussLegendre`]). The per-pair kernels (value; value, gradient and exact Hessian) and their generic reference
//! twin live in [`pair`], the harness rows in [`checks`], and the periodic broad phase (a parry3d-f64 BVH over the
//! segments of one tile, queried against the tile's periodic images) in [`broad`].
//!
//! f is C¹ at ρ = 1 (f(1) = f'(1) = 0, f''(1⁻) = 8) and grows like 1/ρ² as ρ → 0. Realistic states never come near
//! ρ = 0; the kernels still guard it and return [`ContactError::Overlap`] below [`RHO_MIN`] instead of a huge or
//! non-finite number.

pub mod broad;
pub mod ccd;
pub mod pair;

pub use broad::{
    brute_force_candidates, tile_segments, BroadPhase, CandidatePair, Segment, SegmentTopology,
};
pub use pair::{pair_energy_reference, PairKernel, PairRadiusDerivatives, PairVgh};

use nalgebra::Vector3;

/// Smallest normalised quadrature distance ρ = ‖x_a(s_p) − x_b(s_q)‖ / (2r) the kernels accept. Below it they
/// return [`ContactError::Overlap`]: f(10⁻⁶) ≈ 10¹² per unit weight and the Hessian entries scale like ρ⁻⁶, so a
/// state this deep inside another yarn is a failed step (a line search should reject it), not a contact state.
pub const RHO_MIN: f64 = 1e-6;

/// Errors of the contact kernels and the broad phase.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// Two quadrature points (node `p` on segment a, node `q` on segment b) are closer than [`RHO_MIN`]·2r.
    #[error(
        "contact overlap: quadrature points {p} and {q} at normalised distance rho = {rho:.3e} (below {min:.0e})",
        min = RHO_MIN
    )]
    Overlap {
        /// the normalised distance ρ = |x_p − x_q|/(2r)
        rho: f64,
        /// node on segment a
        p: usize,
        /// node on segment b
        q: usize,
    },
    /// An input coordinate is NaN.
    #[error("contact: non-finite input coordinate")]
    NonFinite,
    /// A parameter is out of its range (radius or stiffness not positive and finite, quadrature order 0, …).
    #[error("contact: invalid parameter: {0}")]
    InvalidParameter(String),
    /// The broad phase needs the tile image with this periodic offset and was not given it.
    #[error("contact broad phase: no tile image with offset ({}, {})", .offset[0], .offset[1])]
    MissingImage {
        /// the missing image's offset
        offset: [i32; 2],
    },
}

impl From<crate::periodic::PeriodicError> for ContactError {
    fn from(e: crate::periodic::PeriodicError) -> Self {
        match e {
            crate::periodic::PeriodicError::Invalid(m) => ContactError::InvalidParameter(m),
            crate::periodic::PeriodicError::MissingImage { offset } => {
                ContactError::MissingImage { offset }
            }
        }
    }
}

/// Gauss–Legendre quadrature of order Q on [0, 1]: Q nodes in increasing order and their weights (summing to 1).
/// Exact for polynomials of degree ≤ 2Q − 1.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussLegendre {
    /// The rule of order `q` ≥ 1, computed by Newton's method on the Legendre polynomial P_q (three-term
    /// recurrence) from the asymptotic guesses cos(π(i + 3/4)/(q + 1/2)), iterated to round-off; the nodes are
    /// placed symmetrically about 1/2 (the middle node of an odd order is exactly 1/2) and the weights are
    /// 1/((1 − x²) P_q'(x)²) at the roots x ∈ (−1, 1). Accuracy (against 40–50-digit values): nodes within one
    /// ulp (≤ 1.2e-16 absolute) for every order tested (Q ≤ 24); weights within 1e-15 relative up to Q = 8, the
    /// error growing like Q² ε (1.6e-15 at Q = 13, 1.2e-14 at Q = 24: the rounding of a node near ±1 is amplified
    /// by 1/(1 − x²)).
    ///
    /// # Panics
    /// When `q` is 0.
    pub fn new(q: usize) -> Self {
        assert!(q >= 1, "Gauss-Legendre order must be at least 1");
        let mut nodes = vec![0.0; q];
        let mut weights = vec![0.0; q];
        let n = q as f64;
        for i in 0..q.div_ceil(2) {
            // root x in (0, 1) of P_q on [−1, 1], the i-th largest
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n + 0.5)).cos();
            if 2 * i + 1 == q {
                x = 0.0; // the middle root of an odd order, exactly
            }
            if x != 0.0 {
                // Newton until the update reaches round-off, then one more step
                let mut settled = false;
                for _ in 0..100 {
                    let (p, d) = legendre(q, x);
                    let dx = p / d;
                    x -= dx;
                    if settled {
                        break;
                    }
                    settled = dx.abs() <= 1e-15 * x.abs();
                }
            }
            let dp = legendre(q, x).1;
            let w = 1.0 / ((1.0 - x * x) * dp * dp); // = ½ · 2/((1 − x²) P'(x)²)
            nodes[i] = 0.5 * (1.0 - x);
            nodes[q - 1 - i] = 0.5 * (1.0 + x);
            weights[i] = w;
            weights[q - 1 - i] = w;
        }
        GaussLegendre { nodes, weights }
    }

    /// Number of nodes Q.
    pub fn order(&self) -> usize {
        self.nodes.len()
    }

    /// Nodes s_p ∈ (0, 1), increasing.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Weights w_p > 0, summing to 1.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
}

/// P_n(x) and P_n'(x) by the three-term recurrence (n ≥ 1, |x| < 1).
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// Squared distance between the segments [p0, p1] and [q0, q1] and the parameters (s, t) ∈ [0, 1]² of a closest
/// pair of points (degenerate and parallel segments included).
///
/// The minimiser of the convex quadratic ‖p(s) − q(t)‖² over the unit square: the unconstrained s for the infinite
/// lines, clamped, then t optimal for that s, clamped, then s re-optimised for the clamped t (exact for this
/// problem in exact arithmetic). For parallel segments (denominator ≤ 0) any s on the overlap is optimal; s = 0 is
/// taken before the same two clamping steps.
pub fn segment_distance_squared(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    q0: &Vector3<f64>,
    q1: &Vector3<f64>,
) -> (f64, f64, f64) {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.dot(&d1);
    let e = d2.dot(&d2);
    let f = d2.dot(&r);
    let clamp = |v: f64| v.clamp(0.0, 1.0);
    let (s, t) = if a == 0.0 && e == 0.0 {
        (0.0, 0.0)
    } else if a == 0.0 {
        (0.0, clamp(f / e))
    } else {
        let c = d1.dot(&r);
        if e == 0.0 {
            (clamp(-c / a), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s = if denom > 0.0 {
                clamp((b * f - c * e) / denom)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                (clamp(-c / a), 0.0)
            } else if t > 1.0 {
                (clamp((b - c) / a), 1.0)
            } else {
                (s, t)
            }
        }
    };
    let diff = r + d1 * s - d2 * t;
    (diff.dot(&diff), s, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_rule(q: usize, nodes: &[f64], weights: &[f64]) {
        let g = GaussLegendre::new(q);
        assert_eq!(g.order(), q);
        for p in 0..q {
            assert!(
                (g.nodes()[p] - nodes[p]).abs() <= 2e-16,
                "Q={q} node {p}: {} vs {}",
                g.nodes()[p],
                nodes[p]
            );
            assert!(
                (g.weights()[p] - weights[p]).abs() <= 4e-16,
                "Q={q} weight {p}: {} vs {}",
                g.weights()[p],
                weights[p]
            );
        }
    }

    /// Closed forms on [−1, 1] mapped to [0, 1]: s = (1 + x)/2, w/2.
    #[test]
    fn gauss_legendre_matches_closed_forms_for_orders_1_to_5() {
        let map = |xs: &[f64], ws: &[f64]| {
            let mut v: Vec<(f64, f64)> = xs
                .iter()
                .zip(ws)
                .map(|(x, w)| (0.5 * (1.0 + x), 0.5 * w))
                .collect();
            v.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
            v.into_iter().unzip::<f64, f64, Vec<f64>, Vec<f64>>()
        };
        let (n, w) = map(&[0.0], &[2.0]);
        assert_rule(1, &n, &w);
        let x2 = 1.0 / 3f64.sqrt();
        let (n, w) = map(&[-x2, x2], &[1.0, 1.0]);
        assert_rule(2, &n, &w);
        let x3 = (3.0f64 / 5.0).sqrt();
        let (n, w) = map(&[-x3, 0.0, x3], &[5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]);
        assert_rule(3, &n, &w);
        let r65 = (6.0f64 / 5.0).sqrt();
        let xa = (3.0 / 7.0 - 2.0 / 7.0 * r65).sqrt();
        let xb = (3.0 / 7.0 + 2.0 / 7.0 * r65).sqrt();
        let wa = (18.0 + 30f64.sqrt()) / 36.0;
        let wb = (18.0 - 30f64.sqrt()) / 36.0;
        let (n, w) = map(&[-xb, -xa, xa, xb], &[wb, wa, wa, wb]);
        assert_rule(4, &n, &w);
        let r107 = (10.0f64 / 7.0).sqrt();
        let xa = (5.0 - 2.0 * r107).sqrt() / 3.0;
        let xb = (5.0 + 2.0 * r107).sqrt() / 3.0;
        let wa = (322.0 + 13.0 * 70f64.sqrt()) / 900.0;
        let wb = (322.0 - 13.0 * 70f64.sqrt()) / 900.0;
        let (n, w) = map(&[-xb, -xa, 0.0, xa, xb], &[wb, wa, 128.0 / 225.0, wa, wb]);
        assert_rule(5, &n, &w);
    }

    /// Q = 8 against 50-digit values (Newton in multiple precision), rounded to 22 digits.
    #[test]
    #[allow(clippy::excessive_precision)] // the reference digits as computed
    fn gauss_legendre_order_8_against_multiple_precision() {
        let half = [
            (0.01985507175123188415822, 0.05061426814518812957627),
            (0.1016667612931866302042, 0.1111905172266872352722),
            (0.2372337950418355070911, 0.156853322938943643669),
            (0.4082826787521750975303, 0.1813418916891809914826),
        ];
        let g = GaussLegendre::new(8);
        for (p, &(s, w)) in half.iter().enumerate() {
            assert!((g.nodes()[p] - s).abs() <= 1.2e-16, "node {p}");
            assert!(
                (g.nodes()[7 - p] - (1.0 - s)).abs() <= 1.2e-16,
                "node {}",
                7 - p
            );
            assert!((g.weights()[p] - w).abs() <= 1e-15 * w, "weight {p}");
            assert_eq!(g.weights()[p], g.weights()[7 - p]);
        }
    }

    #[test]
    fn gauss_legendre_integrates_degree_2q_minus_1_exactly() {
        for q in 1..=24 {
            let g = GaussLegendre::new(q);
            for k in 0..=(2 * q - 1) {
                let sum: f64 = g
                    .nodes()
                    .iter()
                    .zip(g.weights())
                    .map(|(s, w)| w * s.powi(k as i32))
                    .sum();
                let exact = 1.0 / (k as f64 + 1.0);
                assert!(
                    (sum - exact).abs() <= 4e-16 * q as f64 * exact,
                    "Q={q} degree {k}: {sum} vs {exact}"
                );
            }
            // … and degree 2Q with exactly the Gauss remainder ∫ − Σ = (Q!)⁴ / ((2Q + 1) ((2Q)!)²) on [0, 1]
            if q <= 8 {
                let k = 2 * q;
                let sum: f64 = g
                    .nodes()
                    .iter()
                    .zip(g.weights())
                    .map(|(s, w)| w * s.powi(k as i32))
                    .sum();
                let fact = |n: usize| (1..=n).map(|i| i as f64).product::<f64>();
                let remainder = fact(q).powi(4) / ((2 * q + 1) as f64 * fact(2 * q).powi(2));
                let err = 1.0 / (k as f64 + 1.0) - sum;
                assert!(
                    (err - remainder).abs() <= 1e-4 * remainder,
                    "Q={q}: {err} vs {remainder}"
                );
            }
            // increasing, inside (0, 1), symmetric
            for p in 0..q {
                assert!(g.nodes()[p] > 0.0 && g.nodes()[p] < 1.0);
                if p > 0 {
                    assert!(g.nodes()[p] > g.nodes()[p - 1]);
                }
                assert!((g.nodes()[p] + g.nodes()[q - 1 - p] - 1.0).abs() <= 1e-16);
            }
        }
    }

    #[test]
    fn segment_distance_cases() {
        let v = Vector3::new;
        // crossing at right angles, separated by 2 along z
        let (d2, s, t) = segment_distance_squared(
            &v(-1.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
            &v(0.0, -1.0, 2.0),
            &v(0.0, 1.0, 2.0),
        );
        assert!((d2 - 4.0).abs() < 1e-15 && (s - 0.5).abs() < 1e-15 && (t - 0.5).abs() < 1e-15);
        // parallel, overlapping
        let (d2, _, _) = segment_distance_squared(
            &v(0.0, 0.0, 0.0),
            &v(2.0, 0.0, 0.0),
            &v(1.0, 1.0, 0.0),
            &v(3.0, 1.0, 0.0),
        );
        assert!((d2 - 1.0).abs() < 1e-15);
        // parallel, disjoint along the line: endpoint to endpoint
        let (d2, _, _) = segment_distance_squared(
            &v(0.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
            &v(3.0, 1.0, 0.0),
            &v(4.0, 1.0, 0.0),
        );
        assert!((d2 - 5.0).abs() < 1e-14);
        // degenerate point and segment
        let (d2, _, t) = segment_distance_squared(
            &v(0.5, 1.0, 0.0),
            &v(0.5, 1.0, 0.0),
            &v(0.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
        );
        assert!((d2 - 1.0).abs() < 1e-15 && (t - 0.5).abs() < 1e-15);
        // endpoint region: closest points at the ends
        let (d2, s, t) = segment_distance_squared(
            &v(0.0, 0.0, 0.0),
            &v(1.0, 0.0, 0.0),
            &v(2.0, 1.0, 0.0),
            &v(2.0, 3.0, 0.0),
        );
        assert!((d2 - 2.0).abs() < 1e-15 && s == 1.0 && t == 0.0);
    }

    /// The closed-form distance never exceeds a dense sampling of point pairs and comes within its resolution.
    #[test]
    fn segment_distance_against_sampling() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200 {
            let mut p = || {
                Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
            };
            let (a0, a1, b0, b1) = (p(), p(), p(), p());
            let (d2, _, _) = segment_distance_squared(&a0, &a1, &b0, &b1);
            let n = 200;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                let x = a0.lerp(&a1, i as f64 / n as f64);
                for j in 0..=n {
                    let y = b0.lerp(&b1, j as f64 / n as f64);
                    best = best.min((x - y).norm_squared());
                }
            }
            assert!(d2 <= best + 1e-14, "{d2} > sampled {best}");
            assert!(best.sqrt() - d2.sqrt() < 0.02, "{d2} vs sampled {best}");
        }
    }
}
