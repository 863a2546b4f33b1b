//! Frames, parallel transport, curvature binormal and reference twist (`02-yarn-model.md`, "Discrete elastic
//! rods"), as plain values and as hand-differentiated primitives (value, Jacobian, Hessian).

use super::jet::VJet;
use nalgebra::{Matrix3, Vector3};

/// Parallel transport P(a→b) x of a vector x from unit tangent a to unit tangent b: the rotation about a × b by
/// the angle between a and b (identity when a = b). Rodrigues' formula written without the angle:
/// P x = (a·b) x + (a×b)×x + ((a×b)·x)/(1 + a·b) (a×b). Undefined for b = −a.
pub fn transport(a: &Vector3<f64>, b: &Vector3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
    let c = a.dot(b);
    let k = a.cross(b);
    x * c + k.cross(x) + k * (k.dot(x) / (1.0 + c))
}

/// Curvature binormal κb = 2 e⁰ × e¹ / (|e⁰||e¹| + e⁰·e¹).
pub fn curvature_binormal(e0: &Vector3<f64>, e1: &Vector3<f64>) -> Vector3<f64> {
    e0.cross(e1) * (2.0 / (e0.norm() * e1.norm() + e0.dot(e1)))
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
/// it never jumps by 2π (`02-yarn-model.md`: "update it by the change of that angle").
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
    pub t: VJet<3>,
    pub u: VJet<3>,
    pub v: VJet<3>,
}

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
/// then the quotient rule.
pub fn curvature_binormal_jet(e0: &Vector3<f64>, e1: &Vector3<f64>) -> VJet<6> {
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
    // q = 1/D
    let q = 1.0 / d;
    let gq = -gd * (q * q);
    let hq = -hd * (q * q) + gd * gd.transpose() * (2.0 * q * q * q);
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
        j.set_row(i, &((gni * q + gq * n[i]) * 2.0).transpose());
        h[i] = (hn * q + gni * gq.transpose() + gq * gni.transpose() + hq * n[i]) * 2.0;
    }
    VJet {
        v: n * (2.0 * q),
        j,
        h,
    }
}
