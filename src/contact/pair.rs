//! The Kaldor contact energy of one segment pair (`docs/yarn-model.md`, "Yarn-yarn contact"):
//! fast value, fast value + gradient + exact Hessian, and the generic reference twin for the derivative harness.
//!
//! Inputs are the 12 coordinates (x_a0, x_a1, x_b0, x_b1) in this order; the kernel carries k_c, r and the
//! quadrature rule, the caller passes the rest lengths l̄_a, l̄_b.
//!
//! Derivation of the fast path. Per quadrature pair (p, q) let d = x_a(s_p) − x_b(s_q) = Σ_k c_k X_k with
//! c = (1 − s_p, s_p, −(1 − s_q), −s_q) and u = ρ² = ‖d‖²/(4r²). In u the penalty is g(u) = 1/u + u − 2 = (1 − u)²/u
//! (the second form has no cancellation near the cut-off), g'(u) = 1 − 1/u², g''(u) = 2/u³. With the term weight
//! W = k_c l̄_a l̄_b w_p w_q,
//!
//! ∇_d = β d,  ∇²_d = α d dᵀ + β I,  β = W g'(u)/(2r²),  α = W g''(u)/(4r⁴),
//!
//! and the term adds c_k β d to the gradient of point k and c_k c_l (α d dᵀ + β I) to the Hessian block (k, l).
//! The accumulation factors the weights: for each node p the sums Σ_q M and Σ_q s_q M (M = α d dᵀ + β I) give
//! the blocks that involve segment a, while the blocks of segment b are accumulated per term (35 multiply-adds
//! per active term instead of 70 for the ten blocks separately).
//! Terms with u ≥ 1 are exactly zero and skipped; when the segment–segment distance is at least 2r every term is
//! zero and the kernels return zeros without visiting the quadrature pairs.

use super::{segment_distance_squared, ContactError, GaussLegendre, RHO_MIN};
use crate::real::Real;
use crate::rod::YarnMaterial;
use nalgebra::{SMatrix, SVector, Vector3};

/// Index into the block accumulators of block (k, l) of the symmetric 4×4 block Hessian: the ten blocks k ≤ l
/// in the order (0,0), (0,1), (0,2), (0,3), (1,1), (1,2), (1,3), (2,2), (2,3), (3,3).
const BLOCK_OF: [[usize; 4]; 4] = [[0, 1, 2, 3], [1, 4, 5, 6], [2, 5, 7, 8], [3, 6, 8, 9]];

/// Index of entry (i, j) of a symmetric 3×3 block stored as (xx, xy, xz, yy, yz, zz).
const SYM_OF: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];

/// Relative safety factor on (2r)² in the early reject: the computed segment distance may exceed the true one by
/// round-off (most for nearly parallel segments), so the reject only fires when the squared distance is at least
/// (2r)²(1 + 1e-8). Below that the quadrature pairs are visited and each term is tested on its own.
const REJECT_SAFETY: f64 = 1e-8;

/// Value, gradient (12) and Hessian (12×12) of one pair energy; coordinate order (x_a0, x_a1, x_b0, x_b1).
#[derive(Clone, Debug, PartialEq)]
pub struct PairVgh {
    /// the energy (J)
    pub value: f64,
    /// its gradient (N)
    pub gradient: SVector<f64, 12>,
    /// its Hessian (N/m)
    pub hessian: SMatrix<f64, 12, 12>,
}

impl PairVgh {
    /// All zeros (a pair beyond the cut-off).
    pub fn zero() -> Self {
        PairVgh {
            value: 0.0,
            gradient: SVector::zeros(),
            hessian: SMatrix::zeros(),
        }
    }
}

/// u = ρ² = ‖d‖²/(4r²) of quadrature pair (p, q) when its term is active (u < 1), `None` beyond the cut-off;
/// errors for a NaN distance and for an overlap below [`RHO_MIN`].
#[inline]
fn active_term(
    d: &Vector3<f64>,
    inv4r2: f64,
    p: usize,
    q: usize,
) -> Result<Option<f64>, ContactError> {
    let u = d.norm_squared() * inv4r2;
    if u >= 1.0 {
        return Ok(None);
    }
    if u.is_nan() {
        return Err(ContactError::NonFinite);
    }
    if u < RHO_MIN * RHO_MIN {
        return Err(ContactError::Overlap {
            rho: u.sqrt(),
            p,
            q,
        });
    }
    Ok(Some(u))
}

/// The pair kernel: contact stiffness k_c (J/m²), yarn radius r (m) and the Gauss–Legendre rule of order Q.
#[derive(Clone, Debug, PartialEq)]
pub struct PairKernel {
    stiffness: f64,
    radius: f64,
    rule: GaussLegendre,
}

/// Rest lengths enter E_ab as the factor l̄_a l̄_b: both must be finite and ≥ 0.
#[inline]
fn check_rest(rest_a: f64, rest_b: f64) -> Result<(), ContactError> {
    if rest_a.is_finite() && rest_b.is_finite() && rest_a >= 0.0 && rest_b >= 0.0 {
        Ok(())
    } else {
        Err(ContactError::InvalidParameter(format!(
            "rest lengths {rest_a}, {rest_b} must be finite and ≥ 0"
        )))
    }
}

impl PairKernel {
    /// A kernel with stiffness k_c > 0, radius r > 0 (both finite) and quadrature order Q ≥ 1.
    pub fn new(stiffness: f64, radius: f64, order: usize) -> Result<Self, ContactError> {
        if !(stiffness.is_finite() && stiffness >= 0.0) {
            return Err(ContactError::InvalidParameter(format!(
                "contact stiffness {stiffness} must be finite and non-negative"
            )));
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(ContactError::InvalidParameter(format!(
                "radius {radius} must be finite and positive"
            )));
        }
        if order == 0 {
            return Err(ContactError::InvalidParameter(
                "contact quadrature order must be at least 1".into(),
            ));
        }
        Ok(PairKernel {
            stiffness,
            radius,
            rule: GaussLegendre::new(order),
        })
    }

    /// The kernel of a yarn material: k_c = `contact_stiffness`, r = `radius`, Q = `contact_quadrature`.
    pub fn from_material(m: &YarnMaterial) -> Result<Self, ContactError> {
        Self::new(m.contact_stiffness, m.radius, m.contact_quadrature)
    }

    /// The contact stiffness k_c (J/m²).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// The yarn radius r (m).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The Gauss–Legendre rule (Q points).
    pub fn rule(&self) -> &GaussLegendre {
        &self.rule
    }

    /// True when the segments are at least 2r apart (with the safety factor of the module), so every quadrature
    /// term is exactly zero. NaN coordinates give false (the quadrature loop reports them).
    #[inline]
    pub fn beyond_cutoff(&self, x: &[Vector3<f64>; 4]) -> bool {
        let (d2, _, _) = segment_distance_squared(&x[0], &x[1], &x[2], &x[3]);
        let c = 2.0 * self.radius;
        d2 >= c * c * (1.0 + REJECT_SAFETY)
    }

    /// E_ab for the points x = (x_a0, x_a1, x_b0, x_b1) and rest lengths l̄_a, l̄_b.
    pub fn value(
        &self,
        x: &[Vector3<f64>; 4],
        rest_a: f64,
        rest_b: f64,
    ) -> Result<f64, ContactError> {
        check_rest(rest_a, rest_b)?;
        if self.beyond_cutoff(x) {
            return Ok(0.0);
        }
        let inv4r2 = 0.25 / (self.radius * self.radius);
        let (s, w) = (self.rule.nodes(), self.rule.weights());
        let ea = x[1] - x[0];
        let eb = x[3] - x[2];
        let mut acc = 0.0;
        for p in 0..s.len() {
            let xa = x[0] + ea * s[p];
            let mut row = 0.0;
            for q in 0..s.len() {
                let d = xa - (x[2] + eb * s[q]);
                let Some(u) = active_term(&d, inv4r2, p, q)? else {
                    continue;
                };
                let om = 1.0 - u;
                row += w[q] * (om * om / u);
            }
            acc += w[p] * row;
        }
        Ok(self.stiffness * rest_a * rest_b * acc)
    }

    /// ∂E_ab/∂r at fixed points: with u = d²/(4r²) each term (1 − u)²/u changes by 2(1 − u²)/(u r) per unit
    /// radius (the yarn-radius sensitivity of `docs/micro-solver.md`, section 5).
    pub fn radius_derivative(
        &self,
        x: &[Vector3<f64>; 4],
        rest_a: f64,
        rest_b: f64,
    ) -> Result<f64, ContactError> {
        check_rest(rest_a, rest_b)?;
        if self.beyond_cutoff(x) {
            return Ok(0.0);
        }
        let inv4r2 = 0.25 / (self.radius * self.radius);
        let (s, w) = (self.rule.nodes(), self.rule.weights());
        let ea = x[1] - x[0];
        let eb = x[3] - x[2];
        let mut acc = 0.0;
        for p in 0..s.len() {
            let xa = x[0] + ea * s[p];
            for q in 0..s.len() {
                let d = xa - (x[2] + eb * s[q]);
                let Some(u) = active_term(&d, inv4r2, p, q)? else {
                    continue;
                };
                acc += w[p] * w[q] * 2.0 * (1.0 - u * u) / (u * self.radius);
            }
        }
        Ok(self.stiffness * rest_a * rest_b * acc)
    }

    /// The radius derivatives of E_ab at fixed points (docs/yarn-parameters.md: equilibrium sensitivities to the contact radius):
    /// ∂E/∂r, the mixed derivative ∂(∇ₓE)/∂r (12 entries, points in the order of `x`) and ∂²E/∂r².
    ///
    /// Per term, with u = d²/(4r²), g(u) = (1 − u)²/u and the gradient β d, β = W g'(u)/(2r²) (module docs):
    /// ∂u/∂r = −2u/r, so ∂g/∂r = 2(1 − u²)/(u r), ∂²g/∂r² = (6u + 2/u)/r² and ∂β/∂r = −W (1 + 1/u²)/r³; the
    /// mixed derivative of point k is c_k (∂β/∂r) d. Terms beyond the cut-off are zero (∂β/∂r jumps there from
    /// −2W/r³ to 0: the gradient is only C⁰ in r where a quadrature distance equals 2r).
    pub fn radius_derivatives(
        &self,
        x: &[Vector3<f64>; 4],
        rest_a: f64,
        rest_b: f64,
    ) -> Result<PairRadiusDerivatives, ContactError> {
        check_rest(rest_a, rest_b)?;
        let mut out = PairRadiusDerivatives {
            value: 0.0,
            gradient: SVector::zeros(),
            second: 0.0,
        };
        if self.beyond_cutoff(x) {
            return Ok(out);
        }
        let r = self.radius;
        let inv4r2 = 0.25 / (r * r);
        let (s, w) = (self.rule.nodes(), self.rule.weights());
        let ea = x[1] - x[0];
        let eb = x[3] - x[2];
        let mut grad = [Vector3::<f64>::zeros(); 4];
        for p in 0..s.len() {
            let xa = x[0] + ea * s[p];
            for q in 0..s.len() {
                let d = xa - (x[2] + eb * s[q]);
                let Some(u) = active_term(&d, inv4r2, p, q)? else {
                    continue;
                };
                let wt = w[p] * w[q];
                let iu = 1.0 / u;
                out.value += wt * 2.0 * (1.0 - u * u) * iu / r;
                out.second += wt * (6.0 * u + 2.0 * iu) / (r * r);
                let gd = d * (-wt * (1.0 + iu * iu) / (r * r * r));
                let t = s[q];
                grad[0] += gd * (1.0 - s[p]);
                grad[1] += gd * s[p];
                grad[2] -= gd * (1.0 - t);
                grad[3] -= gd * t;
            }
        }
        let scale = self.stiffness * rest_a * rest_b;
        out.value *= scale;
        out.second *= scale;
        for k in 0..4 {
            for i in 0..3 {
                out.gradient[3 * k + i] = scale * grad[k][i];
            }
        }
        Ok(out)
    }

    /// E_ab with its gradient and exact Hessian with respect to (x_a0, x_a1, x_b0, x_b1).
    pub fn value_gradient_hessian(
        &self,
        x: &[Vector3<f64>; 4],
        rest_a: f64,
        rest_b: f64,
    ) -> Result<PairVgh, ContactError> {
        check_rest(rest_a, rest_b)?;
        if self.beyond_cutoff(x) {
            return Ok(PairVgh::zero());
        }
        let r2 = self.radius * self.radius;
        let inv4r2 = 0.25 / r2;
        let (s, w) = (self.rule.nodes(), self.rule.weights());
        let ea = x[1] - x[0];
        let eb = x[3] - x[2];
        let mut value = 0.0;
        // gradients of the four points
        let mut grad = [Vector3::<f64>::zeros(); 4];
        // Hessian blocks (k ≤ l, order of BLOCK_OF), each α d dᵀ + β I summed with weights c_k c_l, stored as
        // (xx, xy, xz, yy, yz, zz, β)
        let mut blk = [[0.0f64; 7]; 10];
        for p in 0..s.len() {
            let xa = x[0] + ea * s[p];
            // over q: Σ M and Σ s_q M for the blocks that involve segment a, Σ β d for its gradient
            let mut m_sum = [0.0f64; 7];
            let mut m_sum_t = [0.0f64; 7];
            let mut g_sum = Vector3::<f64>::zeros();
            let mut active = false;
            for q in 0..s.len() {
                let d = xa - (x[2] + eb * s[q]);
                let Some(u) = active_term(&d, inv4r2, p, q)? else {
                    continue;
                };
                active = true;
                let wt = w[p] * w[q];
                let iu = 1.0 / u;
                let om = 1.0 - u;
                value += wt * om * om * iu;
                // β and α per unit k_c l̄_a l̄_b
                let beta = wt * (1.0 - iu * iu) / (2.0 * r2);
                let alpha = wt * iu * iu * iu / (2.0 * r2 * r2);
                let m = [
                    alpha * d.x * d.x,
                    alpha * d.x * d.y,
                    alpha * d.x * d.z,
                    alpha * d.y * d.y,
                    alpha * d.y * d.z,
                    alpha * d.z * d.z,
                    beta,
                ];
                // segment b: c = (−(1 − t), −t)
                let t = s[q];
                let omt = 1.0 - t;
                let (w22, w23, w33) = (omt * omt, omt * t, t * t);
                for e in 0..7 {
                    m_sum[e] += m[e];
                    m_sum_t[e] += t * m[e];
                    blk[7][e] += w22 * m[e];
                    blk[8][e] += w23 * m[e];
                    blk[9][e] += w33 * m[e];
                }
                let gd = d * beta;
                g_sum += gd;
                grad[2] -= gd * omt;
                grad[3] -= gd * t;
            }
            if !active {
                continue;
            }
            // segment a: c = (1 − s, s); mixed blocks use Σ_q c_2 M = Σ_q s_q M − Σ_q M and Σ_q c_3 M = −Σ_q s_q M
            let (ca0, ca1) = (1.0 - s[p], s[p]);
            grad[0] += g_sum * ca0;
            grad[1] += g_sum * ca1;
            let (w00, w01, w11) = (ca0 * ca0, ca0 * ca1, ca1 * ca1);
            for e in 0..7 {
                let (ms, mt) = (m_sum[e], m_sum_t[e]);
                let (m2, m3) = (mt - ms, -mt);
                blk[0][e] += w00 * ms;
                blk[1][e] += w01 * ms;
                blk[4][e] += w11 * ms;
                blk[2][e] += ca0 * m2;
                blk[3][e] += ca0 * m3;
                blk[5][e] += ca1 * m2;
                blk[6][e] += ca1 * m3;
            }
        }
        let scale = self.stiffness * rest_a * rest_b;
        let mut gradient = [0.0f64; 12];
        for k in 0..4 {
            for i in 0..3 {
                gradient[3 * k + i] = scale * grad[k][i];
            }
        }
        // each block with its diagonal folded in, scaled: (xx, xy, xz, yy, yz, zz)
        let full: [[f64; 6]; 10] = std::array::from_fn(|b| {
            let m = &blk[b];
            [
                scale * (m[0] + m[6]),
                scale * m[1],
                scale * m[2],
                scale * (m[3] + m[6]),
                scale * m[4],
                scale * (m[5] + m[6]),
            ]
        });
        // every entry written once, straight into the output
        let out = PairVgh {
            value: scale * value,
            gradient: SVector::from(gradient),
            hessian: SMatrix::from_fn(|i, j| full[BLOCK_OF[i / 3][j / 3]][SYM_OF[i % 3][j % 3]]),
        };
        Ok(out)
    }
}

/// The radius derivatives of one pair energy ([`PairKernel::radius_derivatives`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PairRadiusDerivatives {
    /// ∂E/∂r (J/m).
    pub value: f64,
    /// ∂(∇ₓE)/∂r (N/m per coordinate of (x_a0, x_a1, x_b0, x_b1)).
    pub gradient: SVector<f64, 12>,
    /// ∂²E/∂r² (J/m²).
    pub second: f64,
}

/// The reference twin of [`PairKernel::value`], generic over the scalar, written plainly as the formula:
/// E = k_c l̄_a l̄_b Σ_p Σ_q w_p w_q f(‖x_a(s_p) − x_b(s_q)‖/(2r)), f(ρ) = 1/ρ² + ρ² − 2 for ρ < 1 (decided on the
/// real part), with `x` the 12 coordinates (x_a0, x_a1, x_b0, x_b1) and the radius r a scalar of the same kind
/// (the harness differentiates in r too). No early reject, no overlap guard.
pub fn pair_energy_reference<D: Real>(
    x: &[D],
    rest_a: f64,
    rest_b: f64,
    stiffness: f64,
    radius: D,
    rule: &GaussLegendre,
) -> D {
    let point = |start: usize, s: f64| -> [D; 3] {
        std::array::from_fn(|i| x[start + i].clone() * (1.0 - s) + x[start + 3 + i].clone() * s)
    };
    let mut sum = D::from(0.0);
    for (&sp, &wp) in rule.nodes().iter().zip(rule.weights()) {
        let xa = point(0, sp);
        for (&sq, &wq) in rule.nodes().iter().zip(rule.weights()) {
            let xb = point(6, sq);
            let mut dist2 = D::from(0.0);
            for i in 0..3 {
                let di = xa[i].clone() - xb[i].clone();
                dist2 += di.clone() * di;
            }
            let rho = dist2.sqrt() / (radius.clone() * 2.0);
            if rho.re() < 1.0 {
                let rho2 = rho.clone() * rho;
                let f = rho2.recip() + rho2 - 2.0;
                sum += f * (wp * wq);
            }
        }
    }
    sum * (stiffness * rest_a * rest_b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_derivative_matches_differences() {
        let x = [
            Vector3::new(-2e-3, 0.0, 0.0),
            Vector3::new(2e-3, 0.0, 0.0),
            Vector3::new(0.0, -2e-3, 1.4e-3),
            Vector3::new(0.0, 2e-3, 1.4e-3),
        ];
        let k = |r: f64| PairKernel::new(76.0, r, 4).unwrap();
        let r = 1e-3;
        let h = 1e-9;
        let fd = (k(r + h).value(&x, 2e-3, 3e-3).unwrap()
            - k(r - h).value(&x, 2e-3, 3e-3).unwrap())
            / (2.0 * h);
        let an = k(r).radius_derivative(&x, 2e-3, 3e-3).unwrap();
        assert!(
            an > 0.0 && (an - fd).abs() <= 1e-6 * an.abs(),
            "{an} vs {fd}"
        );
    }

    fn crossing(gap: f64) -> [Vector3<f64>; 4] {
        [
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, -1.0, gap),
            Vector3::new(0.0, 1.0, gap),
        ]
    }

    fn flat(x: &[Vector3<f64>; 4]) -> Vec<f64> {
        x.iter().flat_map(|v| [v.x, v.y, v.z]).collect()
    }

    #[test]
    fn single_node_pair_matches_closed_form() {
        // Q = 1: one node at the midpoints, weight 1, so E = k_c l̄_a l̄_b f(gap/2r)
        let k = PairKernel::new(3.0, 0.5, 1).unwrap();
        let rho: f64 = 0.6;
        let e = k.value(&crossing(rho), 2.0, 5.0).unwrap();
        let f = 1.0 / (rho * rho) + rho * rho - 2.0;
        assert!((e - 30.0 * f).abs() < 1e-13 * e);
        let v = k.value_gradient_hessian(&crossing(rho), 2.0, 5.0).unwrap();
        assert!((v.value - e).abs() < 1e-13 * e);
        // dE/dz of the b points: each carries half of d f/d gap, f'(ρ)/(2r) · (−1)·(−½)… sign: d = x_a − x_b
        let df = (-2.0 / rho.powi(3) + 2.0 * rho) / (2.0 * 0.5);
        assert!((v.gradient[8] - 30.0 * 0.5 * df).abs() < 1e-12 * df.abs() * 30.0);
        assert!((v.gradient[2] + 30.0 * 0.5 * df).abs() < 1e-12 * df.abs() * 30.0);
    }

    #[test]
    fn zero_beyond_the_cutoff_and_overlap_error() {
        let k = PairKernel::new(60.0, 1e-3, 4).unwrap();
        let far = crossing(2.0 * 1e-3 * 1.0001);
        assert_eq!(k.value(&far, 1e-3, 1e-3).unwrap(), 0.0);
        assert_eq!(
            k.value_gradient_hessian(&far, 1e-3, 1e-3).unwrap(),
            PairVgh::zero()
        );
        // nodes of an even rule never sit at the midpoint, so put two node points on top of each other
        let g = GaussLegendre::new(4);
        let s = g.nodes()[1];
        let a0 = Vector3::new(-s, 0.0, 0.0);
        let x = [
            a0,
            a0 + Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, -s, 0.0),
            Vector3::new(0.0, 1.0 - s, 0.0),
        ];
        let k = PairKernel::new(60.0, 1.0, 4).unwrap();
        assert!(matches!(
            k.value(&x, 1.0, 1.0),
            Err(ContactError::Overlap { p: 1, q: 1, .. })
        ));
        assert!(matches!(
            k.value_gradient_hessian(&x, 1.0, 1.0),
            Err(ContactError::Overlap { .. })
        ));
        let mut nan = crossing(0.5);
        nan[2].x = f64::NAN;
        assert_eq!(k.value(&nan, 1.0, 1.0), Err(ContactError::NonFinite));
        assert!(PairKernel::new(1.0, 0.0, 4).is_err());
        assert!(PairKernel::new(1.0, 1.0, 0).is_err());
    }

    #[test]
    fn fast_matches_reference_value() {
        let k = PairKernel::new(60.0, 1e-3, 4).unwrap();
        let x = [
            Vector3::new(-1e-3, 0.2e-3, 0.1e-3),
            Vector3::new(1.2e-3, -0.1e-3, 0.0),
            Vector3::new(0.1e-3, -1e-3, 1.1e-3),
            Vector3::new(-0.2e-3, 1.3e-3, 1.4e-3),
        ];
        let e = k.value(&x, 2e-3, 2.5e-3).unwrap();
        let r = pair_energy_reference::<f64>(&flat(&x), 2e-3, 2.5e-3, 60.0, 1e-3, k.rule());
        assert!(e > 0.0);
        assert!((e - r).abs() <= 1e-13 * e, "{e} vs {r}");
    }

    /// One-sided consistency at the kink ρ = 1 (`docs/derivative-harness.md`: C¹ functions are checked at their kinks):
    /// with a single node pair (Q = 1) moved across the cut-off, value and gradient tend to 0 from inside and are 0
    /// outside; the one-sided Hessian from inside tends to W f''(1)/(2r)² along the normal.
    #[test]
    fn one_sided_consistency_at_the_cutoff() {
        let r = 0.5;
        let k = PairKernel::new(1.0, r, 1).unwrap();
        let inside = k
            .value_gradient_hessian(&crossing(2.0 * r * (1.0 - 1e-9)), 1.0, 1.0)
            .unwrap();
        let outside = k
            .value_gradient_hessian(&crossing(2.0 * r * (1.0 + 1e-9)), 1.0, 1.0)
            .unwrap();
        assert!(inside.value.abs() < 1e-16 && outside.value == 0.0);
        assert!(inside.gradient.norm() < 1e-7 && outside.gradient.norm() == 0.0);
        // ∂²E/∂z_a1² = ¼ f''(1)/(2r)² with f''(1) = 8 (each endpoint carries interpolation weight ½)
        let expect = 0.25 * 8.0 / (4.0 * r * r);
        assert!((inside.hessian[(5, 5)] - expect).abs() < 1e-6 * expect);
        assert_eq!(outside.hessian[(5, 5)], 0.0);
        // the gradient from finite differences on the inside matches the kernel there
        let h = 1e-6;
        let z = 2.0 * r * (1.0 - 1e-3);
        let (ep, em) = (
            k.value(&crossing(z + h), 1.0, 1.0).unwrap(),
            k.value(&crossing(z - h), 1.0, 1.0).unwrap(),
        );
        let g = k.value_gradient_hessian(&crossing(z), 1.0, 1.0).unwrap();
        let fd = (ep - em) / (2.0 * h);
        let dz = g.gradient[8] + g.gradient[11];
        assert!((fd - dz).abs() < 1e-6 * dz.abs(), "{fd} vs {dz}");
    }
}
