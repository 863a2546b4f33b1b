//! Frames, parallel transport, curvature binormal and reference twist (`docs/yarn-model.md`, "Discrete elastic
//! rods"), as plain values and as hand-differentiated primitives (value, Jacobian, Hessian).

use super::jet::{Jet, VJet};
use nalgebra::{Matrix3, Vector3};

/// Parallel transport P(a→b) x of a vector x from unit tangent a to unit tangent b: the rotation about a × b by
/// the angle between a and b (identity when a = b). Rodrigues' formula written without the angle:
/// P x = (a·b) x + (a×b)×x + ((a×b)·x)/(1 + a·b) (a×b). Undefined for b = −a.
pub fn transport(a: &Vector3<f64>, b: &Vector3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
    let c = a.dot(b);
    let k = a.cross(b);
    x * c + k.cross(x) + k * (k.dot(x) / (1.0 + c))
}

/// How the discrete curvature measures the turning angle φ between two edges (`docs/yarn-model.md`, "Discrete
/// elastic rods"): the curvature binormal is κb = k(φ) b with b the unit binormal e⁰ × e¹ / |e⁰ × e¹|.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BendingForm {
    /// k(φ) = 2 tan(φ/2) (Bergou et al.): κb = 2 e⁰ × e¹ / (|e⁰||e¹| + e⁰·e¹); the original's form.
    #[default]
    Tan,
    /// k(φ) = 2 sin(φ/2): κb = 2 e⁰ × e¹ / √(2 |e⁰||e¹| (|e⁰||e¹| + e⁰·e¹)), bounded as φ → π (the bending-discretisation
    /// variant, docs/yarn-parameters.md).
    Sin,
}

impl BendingForm {
    /// The factor k_form(φ) / (2 tan(φ/2)) at the angle φ whose `Tan` measure is k = 2 tan(φ/2): 1 for `Tan`,
    /// cos(φ/2) = 1/√(1 + k²/4) for `Sin`. Rest curvatures, stored in the `Tan` form, carry over to this form by
    /// this factor (the curvature binormal of either form is the other's times a scalar, and so are its
    /// material-frame components).
    pub fn factor_from_tan(self, k: f64) -> f64 {
        match self {
            BendingForm::Tan => 1.0,
            BendingForm::Sin => 1.0 / (1.0 + 0.25 * k * k).sqrt(),
        }
    }

    /// A stencil's rest curvature (κ̄₁, κ̄₂) in this form, from the one stored in the `Tan` form with rest twist m̄:
    /// the same rest angle, so [`factor_from_tan`](Self::factor_from_tan) at |κb̄| = |κ̄| / |cos(m̄/2)| (the
    /// binormal is fixed by the transport between the edges, so its angles to the two material frames differ by
    /// the twist m̄). The stored values unchanged for `Tan`.
    pub fn rest_curvature_from_tan(self, stored: [f64; 2], rest_twist: f64) -> [f64; 2] {
        match self {
            BendingForm::Tan => stored,
            BendingForm::Sin => {
                let [k1, k2] = stored;
                let c = self.factor_from_tan(k1.hypot(k2) / (0.5 * rest_twist).cos().abs());
                [k1 * c, k2 * c]
            }
        }
    }
}

/// Curvature binormal in the given [`BendingForm`]: κb = 2 e⁰ × e¹ / (|e⁰||e¹| + e⁰·e¹) for `Tan`.
pub fn curvature_binormal(e0: &Vector3<f64>, e1: &Vector3<f64>, form: BendingForm) -> Vector3<f64> {
    let ll = e0.norm() * e1.norm();
    let d = ll + e0.dot(e1);
    match form {
        BendingForm::Tan => e0.cross(e1) * (2.0 / d),
        BendingForm::Sin => e0.cross(e1) * (2.0 / (2.0 * ll * d).sqrt()),
    }
}

/// The reference twist as a raw angle in (−π, π]: the signed angle, about t¹, from P(t⁰→t¹) u⁰ to u¹.
pub fn reference_twist_raw(
    t0: &Vector3<f64>,
    u0: &Vector3<f64>,
    t1: &Vector3<f64>,
    u1: &Vector3<f64>,
) -> f64 {
    let p = transport(t0, t1, u0);
    p.cross(u1).dot(t1).atan2(p.dot(u1))
}

/// `a − b` wrapped into (−π, π].
pub fn angle_diff(a: f64, b: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let d = (a - b) % two_pi;
    if d > std::f64::consts::PI {
        d - two_pi
    } else if d <= -std::f64::consts::PI {
        d + two_pi
    } else {
        d
    }
}

/// The continuous reference twist at a new state: the stored twist plus the change of the raw angle, wrapped, so
/// it never jumps by 2π (`docs/yarn-model.md`: "update it by the change of that angle").
pub fn continuous_twist(stored: f64, raw_stored: f64, raw_new: f64) -> f64 {
    stored + angle_diff(raw_new, raw_stored)
}

/// The unit tangent t, reference director u and second reference vector v = t × u of one edge, each with its
/// Jacobian and Hessian with respect to the edge vector e, when the director is parallel-transported from a
/// stored state: u = P(a→t) ū with a the stored unit tangent and ū ⟂ a the stored director.
///
/// Formulas (ℓ = |e|, t = e/ℓ, 𝑃 = I − t tᵀ):
/// - ∂t/∂e = 𝑃/ℓ, ∂²tᵢ/∂eⱼ∂eₖ = −(δᵢₖtⱼ + δⱼₖtᵢ + δᵢⱼtₖ − 3tᵢtⱼtₖ)/ℓ²;
/// - for ū ⟂ a transport reduces to u = ū − q w with s = ū·t, c = 1 + a·t, q = s/c, w = a + t, so
///   ∂q/∂t = ū/c − s a/c², ∂²q/∂t² = −(ū aᵀ + a ūᵀ)/c² + 2 s a aᵀ/c³, ∂u/∂t = −w ∇qᵀ − q I,
///   ∂²uᵢ/∂tⱼ∂tₖ = −wᵢ ∂²q/∂tⱼ∂tₖ − δᵢₖ ∂q/∂tⱼ − δᵢⱼ ∂q/∂tₖ, then the chain rule through t(e);
/// - v = t × u by the product rule.
pub struct EdgeFrame {
    /// unit tangent t = e/|e|
    pub t: VJet<3>,
    /// reference director u, ū transported to t
    pub u: VJet<3>,
    /// v = t × u
    pub v: VJet<3>,
}

/// The frame of edge `e`, transporting the stored director `ubar` from the stored tangent `a`, with derivatives over e (formulas above).
pub fn edge_frame(e: &Vector3<f64>, a: &Vector3<f64>, ubar: &Vector3<f64>) -> EdgeFrame {
    let l = e.norm();
    let t = e / l;
    let p = Matrix3::identity() - t * t.transpose();
    let jt = p / l;
    let mut ht = [Matrix3::zeros(); 3];
    let l2 = l * l;
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                let mut s = -3.0 * t[i] * t[j] * t[k];
                if i == k {
                    s += t[j];
                }
                if j == k {
                    s += t[i];
                }
                if i == j {
                    s += t[k];
                }
                ht[i][(j, k)] = -s / l2;
            }
        }
    }

    // u(t) = ū − q w
    let s = ubar.dot(&t);
    let c = 1.0 + a.dot(&t);
    let q = s / c;
    let w = a + t;
    let gq = ubar / c - a * (s / (c * c));
    let hq = -(ubar * a.transpose() + a * ubar.transpose()) / (c * c)
        + a * a.transpose() * (2.0 * s / (c * c * c));
    let u = ubar - w * q;
    let ju_t = -(w * gq.transpose()) - Matrix3::identity() * q;
    let ju = ju_t * jt;
    let mut hu = [Matrix3::zeros(); 3];
    for i in 0..3 {
        // second derivative of uᵢ in t
        let mut hut = -hq * w[i];
        for j in 0..3 {
            hut[(j, i)] -= gq[j];
            hut[(i, j)] -= gq[j];
        }
        let mut hi = jt.transpose() * hut * jt;
        for m in 0..3 {
            hi += ht[m] * ju_t[(i, m)];
        }
        hu[i] = hi;
    }

    // v = t × u
    let v = t.cross(&u);
    let jv = t.cross_matrix() * ju - u.cross_matrix() * jt;
    let mut hv = [Matrix3::zeros(); 3];
    for i in 0..3 {
        let (m, n) = ((i + 1) % 3, (i + 2) % 3);
        // vᵢ = tₘ uₙ − tₙ uₘ (cyclic)
        let term = |a: usize, b: usize| -> Matrix3<f64> {
            let jta = jt.row(a).transpose();
            let jub = ju.row(b).transpose();
            ht[a] * u[b] + hu[b] * t[a] + jta * jub.transpose() + jub * jta.transpose()
        };
        hv[i] = term(m, n) - term(n, m);
    }

    EdgeFrame {
        t: VJet { v: t, j: jt, h: ht },
        u: VJet { v: u, j: ju, h: hu },
        v: VJet { v, j: jv, h: hv },
    }
}

/// Curvature binormal κb = 2 n / D with n = e⁰ × e¹, D = |e⁰||e¹| + e⁰·e¹, with its Jacobian and Hessians over
/// the six variables (e⁰, e¹). ∂n/∂e⁰ = −[e¹]×, ∂n/∂e¹ = [e⁰]×, ∂²nᵢ/∂e⁰ₐ∂e¹_b = εᵢₐ_b;
/// ∇D = (|e¹| t⁰ + e¹, |e⁰| t¹ + e⁰), ∂²D/∂e⁰² = |e¹| 𝑃⁰/|e⁰|, ∂²D/∂e¹² = |e⁰| 𝑃¹/|e¹|, ∂²D/∂e⁰∂e¹ = t⁰t¹ᵀ + I;
/// then the quotient rule. In the `Sin` form the factor 2/D becomes √2 P^(−1/2) with P = |e⁰||e¹| D, whose
/// derivatives follow from those of |e⁰|, |e¹| and D by the product and power rules.
pub fn curvature_binormal_jet(e0: &Vector3<f64>, e1: &Vector3<f64>, form: BendingForm) -> VJet<6> {
    use nalgebra::{SMatrix, SVector};
    let (l0, l1) = (e0.norm(), e1.norm());
    let (t0, t1) = (e0 / l0, e1 / l1);
    let n = e0.cross(e1);
    let d = l0 * l1 + e0.dot(e1);
    let mut jn = SMatrix::<f64, 3, 6>::zeros();
    jn.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(-e1.cross_matrix()));
    jn.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&e0.cross_matrix());
    let mut gd = SVector::<f64, 6>::zeros();
    gd.fixed_rows_mut::<3>(0).copy_from(&(t0 * l1 + e1));
    gd.fixed_rows_mut::<3>(3).copy_from(&(t1 * l0 + e0));
    let mut hd = SMatrix::<f64, 6, 6>::zeros();
    let i3 = Matrix3::identity();
    hd.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&((i3 - t0 * t0.transpose()) * (l1 / l0)));
    hd.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&((i3 - t1 * t1.transpose()) * (l0 / l1)));
    let off = t0 * t1.transpose() + i3;
    hd.fixed_view_mut::<3, 3>(0, 3).copy_from(&off);
    hd.fixed_view_mut::<3, 3>(3, 0).copy_from(&off.transpose());
    // the factor q with κb = n q: 2/D (Tan) or √2 (|e⁰||e¹| D)^(−1/2) (Sin)
    let dj = Jet::<6> { v: d, g: gd, h: hd };
    let qj = match form {
        BendingForm::Tan => dj.recip().scale(2.0),
        BendingForm::Sin => {
            let norm_jet = |t: &Vector3<f64>, l: f64, at: usize| {
                let mut j = Jet::<6>::constant(l);
                j.g.fixed_rows_mut::<3>(at).copy_from(t);
                j.h.fixed_view_mut::<3, 3>(at, at)
                    .copy_from(&((i3 - t * t.transpose()) / l));
                j
            };
            let p = norm_jet(&t0, l0, 0).mul(&norm_jet(&t1, l1, 3)).mul(&dj);
            p.powf(-0.5).scale(std::f64::consts::SQRT_2)
        }
    };
    let (q, gq, hq) = (qj.v, qj.g, qj.h);
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    let mut h = [SMatrix::<f64, 6, 6>::zeros(); 3];
    for i in 0..3 {
        let gni = jn.row(i).transpose();
        // ∇²nᵢ: ∂²nᵢ/∂e⁰ₐ∂e¹_b = εᵢₐ_b
        let mut hn = SMatrix::<f64, 6, 6>::zeros();
        let (a, b) = ((i + 1) % 3, (i + 2) % 3);
        hn[(a, 3 + b)] = 1.0;
        hn[(b, 3 + a)] = -1.0;
        hn[(3 + b, a)] = 1.0;
        hn[(3 + a, b)] = -1.0;
        j.set_row(i, &(gni * q + gq * n[i]).transpose());
        h[i] = hn * q + gni * gq.transpose() + gq * gni.transpose() + hq * n[i];
    }
    VJet { v: n * q, j, h }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In-plane edges turning by φ: |κb| is 2 tan(φ/2) in the `Tan` form and 2 sin(φ/2) in the `Sin` form, along
    /// the binormal, whatever the edge lengths; `factor_from_tan` maps one measure of an angle to the other.
    #[test]
    fn the_two_forms_measure_the_turning_angle() {
        for (phi, l0, l1) in [(0.3f64, 1.0, 2.0), (1.2, 0.5, 0.7), (2.9, 3.0, 1.0)] {
            let e0 = Vector3::new(l0, 0.0, 0.0);
            let e1 = Vector3::new(phi.cos(), phi.sin(), 0.0) * l1;
            let kt = curvature_binormal(&e0, &e1, BendingForm::Tan);
            let ks = curvature_binormal(&e0, &e1, BendingForm::Sin);
            let tan = 2.0 * (phi / 2.0).tan();
            let sin = 2.0 * (phi / 2.0).sin();
            assert!((kt - Vector3::new(0.0, 0.0, tan)).norm() < 1e-12 * tan);
            assert!((ks - Vector3::new(0.0, 0.0, sin)).norm() < 1e-12);
            assert!((BendingForm::Sin.factor_from_tan(tan) * tan - sin).abs() < 1e-12);
            assert_eq!(BendingForm::Tan.factor_from_tan(tan), 1.0);
            let jet = curvature_binormal_jet(&e0, &e1, BendingForm::Sin);
            assert!((jet.v - ks).norm() < 1e-14);
        }
    }
}
