//! Bending+twisting stencil (`docs/yarn-model.md`, "Discrete elastic rods"): the vertex x¹ with its incoming edge
//! e⁰ = x¹ − x⁰ and outgoing edge e¹ = x² − x¹, 11 dofs (x⁰, x¹, x², θ⁰, θ¹), energy
//!
//! E = (B/(2 l̄)) ‖κ − κ̄‖² + (GJ/(2 l̄)) (m − m̄)²,
//!
//! κ = (½ κb·(m₂⁰ + m₂¹), −½ κb·(m₁⁰ + m₁¹)), m = θ¹ − θ⁰ + τ, with the reference frames parallel-transported from
//! the stencil's stored (last accepted) state and the reference twist τ continued from its stored value.
//!
//! The Hessian is the exact second derivative of that function at any state (at the stored state in particular):
//! the transported directors u(e) = P(a→t(e)) ū are differentiated twice (`frame::edge_frame`), and so is the
//! reference twist τ = τ_stored + atan2(S, C) − atan2(S, C)_stored with C = U⁰·u¹ and S = −U⁰·v¹,
//! U⁰ = P(t⁰→t¹) u⁰ = u⁰ − (u⁰·t¹)/(1 + t⁰·t¹) (t⁰ + t¹).

use super::frame::{
    continuous_twist, curvature_binormal, curvature_binormal_jet, edge_frame, reference_twist_raw,
    transport, BendingForm,
};
use super::generic::transport_generic;
use super::jet::{Jet, VJet};
use crate::real::{self as g, Real, V3};
use nalgebra::{SMatrix, SVector, Vector3};

/// The stored state of one stencil: unit tangents and reference directors of its two edges at the last accepted
/// state, and the (continuous) reference twist there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StencilFrames {
    /// unit tangent t⁰ of the first edge
    pub t0: Vector3<f64>,
    /// reference director u⁰ of the first edge
    pub u0: Vector3<f64>,
    /// unit tangent t¹ of the second edge
    pub t1: Vector3<f64>,
    /// reference director u¹ of the second edge
    pub u1: Vector3<f64>,
    /// Reference twist τ at the stored state (continuous in time, may lie outside (−π, π]).
    pub twist: f64,
    /// The raw angle (−π, π] of the stored state, from which τ is continued.
    pub twist_raw: f64,
}

impl StencilFrames {
    /// The frames with the reference twist τ (its raw angle computed).
    pub fn new(
        t0: Vector3<f64>,
        u0: Vector3<f64>,
        t1: Vector3<f64>,
        u1: Vector3<f64>,
        twist: f64,
    ) -> Self {
        let twist_raw = reference_twist_raw(&t0, &u0, &t1, &u1);
        StencilFrames {
            t0,
            u0,
            t1,
            u1,
            twist,
            twist_raw,
        }
    }
}

/// Rest values and stiffnesses of one stencil.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BendTwistParams {
    /// Rest material curvature (κ̄₁, κ̄₂).
    pub rest_curvature: [f64; 2],
    /// Rest twist m̄.
    pub rest_twist: f64,
    /// Voronoi rest length l̄ = (l̄⁰ + l̄¹)/2.
    pub voronoi_length: f64,
    /// Bending stiffness B.
    pub bend: f64,
    /// Twisting stiffness GJ.
    pub twist: f64,
    /// How the curvature measures the turning angle (`Tan`: 2 tan(φ/2), the original's form).
    pub form: BendingForm,
}

/// Current kinematic quantities of a stencil (value level).
#[derive(Clone, Copy, Debug)]
pub struct StencilKinematics {
    /// Material curvature (κ₁, κ₂).
    pub curvature: [f64; 2],
    /// Reference twist τ (continued from the stored state).
    pub ref_twist: f64,
    /// Twist m = θ¹ − θ⁰ + τ.
    pub twist: f64,
    /// Transported reference directors of the two edges.
    pub u0: Vector3<f64>,
    /// Transported reference director of the second edge (u¹; the one above is u⁰).
    pub u1: Vector3<f64>,
}

/// Material frame (m₁, m₂) = (cos θ u + sin θ v, −sin θ u + cos θ v).
fn material_frame(u: &Vector3<f64>, v: &Vector3<f64>, theta: f64) -> (Vector3<f64>, Vector3<f64>) {
    let (s, c) = theta.sin_cos();
    (u * c + v * s, v * c - u * s)
}

/// Curvature (in the `Tan` form, the form rest curvatures are stored in), reference twist and twist of a stencil
/// at positions `x` and angles `theta`.
pub fn kinematics(x: &[Vector3<f64>; 3], theta: [f64; 2], fr: &StencilFrames) -> StencilKinematics {
    kinematics_in(x, theta, fr, BendingForm::Tan)
}

/// [`kinematics`] with the curvature in the given [`BendingForm`].
pub fn kinematics_in(
    x: &[Vector3<f64>; 3],
    theta: [f64; 2],
    fr: &StencilFrames,
    form: BendingForm,
) -> StencilKinematics {
    let e0 = x[1] - x[0];
    let e1 = x[2] - x[1];
    let t0 = e0.normalize();
    let t1 = e1.normalize();
    let u0 = transport(&fr.t0, &t0, &fr.u0);
    let u1 = transport(&fr.t1, &t1, &fr.u1);
    let (m10, m20) = material_frame(&u0, &t0.cross(&u0), theta[0]);
    let (m11, m21) = material_frame(&u1, &t1.cross(&u1), theta[1]);
    let kb = curvature_binormal(&e0, &e1, form);
    let curvature = [0.5 * kb.dot(&(m20 + m21)), -0.5 * kb.dot(&(m10 + m11))];
    let raw = reference_twist_raw(&t0, &u0, &t1, &u1);
    let ref_twist = continuous_twist(fr.twist, fr.twist_raw, raw);
    StencilKinematics {
        curvature,
        ref_twist,
        twist: theta[1] - theta[0] + ref_twist,
        u0,
        u1,
    }
}

/// Energy of one stencil (fast value).
pub fn bend_twist_value(
    x: &[Vector3<f64>; 3],
    theta: [f64; 2],
    fr: &StencilFrames,
    p: &BendTwistParams,
) -> f64 {
    let k = kinematics_in(x, theta, fr, p.form);
    energy_of(&k, p)
}

/// The bending and the twisting energy of one stencil (fast values, one kinematics evaluation).
pub fn bend_twist_parts(
    x: &[Vector3<f64>; 3],
    theta: [f64; 2],
    fr: &StencilFrames,
    p: &BendTwistParams,
) -> [f64; 2] {
    parts_of(&kinematics_in(x, theta, fr, p.form), p)
}

fn energy_of(k: &StencilKinematics, p: &BendTwistParams) -> f64 {
    let [b, t] = parts_of(k, p);
    b + t
}

fn parts_of(k: &StencilKinematics, p: &BendTwistParams) -> [f64; 2] {
    let d1 = k.curvature[0] - p.rest_curvature[0];
    let d2 = k.curvature[1] - p.rest_curvature[1];
    let dm = k.twist - p.rest_twist;
    let h = 0.5 / p.voronoi_length;
    [h * p.bend * (d1 * d1 + d2 * d2), h * p.twist * dm * dm]
}

/// Material frame jets over the 8 local variables (e⁰, e¹, θ⁰, θ¹); θ is variable `col`.
/// ∂m₁/∂θ = m₂, ∂m₂/∂θ = −m₁.
fn material_frame_jet(u: &VJet<8>, v: &VJet<8>, theta: f64, col: usize) -> (VJet<8>, VJet<8>) {
    let (s, c) = theta.sin_cos();
    let mut m1 = VJet {
        v: u.v * c + v.v * s,
        j: u.j * c + v.j * s,
        h: [
            u.h[0] * c + v.h[0] * s,
            u.h[1] * c + v.h[1] * s,
            u.h[2] * c + v.h[2] * s,
        ],
    };
    let mut m2 = VJet {
        v: v.v * c - u.v * s,
        j: v.j * c - u.j * s,
        h: [
            v.h[0] * c - u.h[0] * s,
            v.h[1] * c - u.h[1] * s,
            v.h[2] * c - u.h[2] * s,
        ],
    };
    let (jm1, jm2) = (m1.j, m2.j);
    for i in 0..3 {
        for k in 0..8 {
            // mixed (variable k, θ): ∂/∂θ of row i of the Jacobian
            m1.h[i][(k, col)] += jm2[(i, k)];
            m1.h[i][(col, k)] += jm2[(i, k)];
            m2.h[i][(k, col)] -= jm1[(i, k)];
            m2.h[i][(col, k)] -= jm1[(i, k)];
        }
        m1.h[i][(col, col)] = -m1.v[i];
        m2.h[i][(col, col)] = -m2.v[i];
        m1.j[(i, col)] = m2.v[i];
        m2.j[(i, col)] = -m1.v[i];
    }
    (m1, m2)
}

/// Curvature (κ₁, κ₂) and twist m as jets over the 8 local variables (e⁰, e¹, θ⁰, θ¹).
fn kinematics_jets(
    x: &[Vector3<f64>; 3],
    theta: [f64; 2],
    fr: &StencilFrames,
    form: BendingForm,
) -> (Jet<8>, Jet<8>, Jet<8>) {
    let e0 = x[1] - x[0];
    let e1 = x[2] - x[1];
    let f0 = edge_frame(&e0, &fr.t0, &fr.u0);
    let f1 = edge_frame(&e1, &fr.t1, &fr.u1);
    let c0 = [0, 1, 2];
    let c1 = [3, 4, 5];
    let t0 = VJet::<8>::embed(&f0.t, c0);
    let u0 = VJet::<8>::embed(&f0.u, c0);
    let v0 = VJet::<8>::embed(&f0.v, c0);
    let t1 = VJet::<8>::embed(&f1.t, c1);
    let u1 = VJet::<8>::embed(&f1.u, c1);
    let v1 = VJet::<8>::embed(&f1.v, c1);
    let (m10, m20) = material_frame_jet(&u0, &v0, theta[0], 6);
    let (m11, m21) = material_frame_jet(&u1, &v1, theta[1], 7);
    let kb = VJet::<8>::embed(&curvature_binormal_jet(&e0, &e1, form), [0, 1, 2, 3, 4, 5]);
    let k1 = kb.dot(&m20.add(&m21)).scale(0.5);
    let k2 = kb.dot(&m10.add(&m11)).scale(-0.5);

    // reference twist: C = u⁰·u¹ − (u⁰·t¹)(t⁰·u¹)/(1 + t⁰·t¹), S = −[u⁰·v¹ − (u⁰·t¹)(t⁰·v¹)/(1 + t⁰·t¹)]
    let inv = t0.dot(&t1).add(&Jet::constant(1.0)).recip();
    let u0t1 = u0.dot(&t1).mul(&inv);
    let cc = u0.dot(&u1).sub(&u0t1.mul(&t0.dot(&u1)));
    let ss = u0t1.mul(&t0.dot(&v1)).sub(&u0.dot(&v1));
    let mut tau = Jet::atan2(&ss, &cc);
    tau.v = continuous_twist(fr.twist, fr.twist_raw, tau.v);
    let mut m = tau;
    m.v += theta[1] - theta[0];
    m.g[6] -= 1.0;
    m.g[7] += 1.0;
    (k1, k2, m)
}

/// Energy, gradient and exact Hessian of one stencil over (x⁰, x¹, x², θ⁰, θ¹).
pub fn bend_twist_vgh(
    x: &[Vector3<f64>; 3],
    theta: [f64; 2],
    fr: &StencilFrames,
    p: &BendTwistParams,
) -> (f64, SVector<f64, 11>, SMatrix<f64, 11, 11>) {
    let ([b, t], g, h) = bend_twist_parts_vgh(x, theta, fr, p);
    (b + t, g, h)
}

/// [`bend_twist_vgh`] with the energy split into its bending and twisting parts.
pub fn bend_twist_parts_vgh(
    x: &[Vector3<f64>; 3],
    theta: [f64; 2],
    fr: &StencilFrames,
    p: &BendTwistParams,
) -> ([f64; 2], SVector<f64, 11>, SMatrix<f64, 11, 11>) {
    let (k1, k2, m) = kinematics_jets(x, theta, fr, p.form);
    let iv = 1.0 / p.voronoi_length;
    let mut d1 = k1;
    d1.v -= p.rest_curvature[0];
    let mut d2 = k2;
    d2.v -= p.rest_curvature[1];
    let mut dm = m;
    dm.v -= p.rest_twist;
    let eb = d1.half_square().add(&d2.half_square()).scale(p.bend * iv);
    let et = dm.half_square().scale(p.twist * iv);
    let e = eb.add(&et);
    // local (e⁰, e¹, θ⁰, θ¹) → stencil dofs (x⁰, x¹, x², θ⁰, θ¹): e⁰ = x¹ − x⁰, e¹ = x² − x¹
    let mut map = SMatrix::<f64, 8, 11>::zeros();
    for a in 0..3 {
        map[(a, a)] = -1.0;
        map[(a, 3 + a)] = 1.0;
        map[(3 + a, 3 + a)] = -1.0;
        map[(3 + a, 6 + a)] = 1.0;
    }
    map[(6, 9)] = 1.0;
    map[(7, 10)] = 1.0;
    let g = map.transpose() * e.g;
    let h = map.transpose() * e.h * map;
    ([eb.v, et.v], g, h)
}

/// Reference twin: the energy of the stencil, generic over the scalar, written like `docs/yarn-model.md`.
/// `x` = (x⁰, x¹, x², θ⁰, θ¹); frames are transported from `fr` with Rodrigues' rotation and the reference twist is
/// the signed angle about t¹ from P(t⁰→t¹) u⁰ to u¹, continued from the stored value.
pub fn bend_twist_reference<D: Real>(x: &[D], fr: &StencilFrames, p: &BendTwistParams) -> D {
    let x0 = g::v3(&x[0..3]);
    let x1 = g::v3(&x[3..6]);
    let x2 = g::v3(&x[6..9]);
    let (th0, th1) = (x[9].clone(), x[10].clone());
    let e0 = g::sub(&x1, &x0);
    let e1 = g::sub(&x2, &x1);
    let (l0, l1) = (g::norm(&e0), g::norm(&e1));
    let t0 = g::scale(&e0, &l0.recip());
    let t1 = g::scale(&e1, &l1.recip());
    let u0 = transport_generic(&g::from_f64(&fr.t0), &t0, &g::from_f64(&fr.u0));
    let u1 = transport_generic(&g::from_f64(&fr.t1), &t1, &g::from_f64(&fr.u1));
    let v0 = g::cross(&t0, &u0);
    let v1 = g::cross(&t1, &u1);
    let frame = |u: &V3<D>, v: &V3<D>, th: &D| {
        let (s, c) = th.sin_cos();
        let m1 = g::add(&g::scale(u, &c), &g::scale(v, &s));
        let m2 = g::sub(&g::scale(v, &c), &g::scale(u, &s));
        (m1, m2)
    };
    let (m10, m20) = frame(&u0, &v0, &th0);
    let (m11, m21) = frame(&u1, &v1, &th1);
    let ll = l0 * l1;
    let d = ll.clone() + g::dot(&e0, &e1);
    let factor = match p.form {
        BendingForm::Tan => D::from(2.0) / d,
        BendingForm::Sin => D::from(2.0) / (ll * d * 2.0).sqrt(),
    };
    let kb = g::scale(&g::cross(&e0, &e1), &factor);
    let k1 = g::dot(&kb, &g::add(&m20, &m21)) * 0.5;
    let k2 = g::dot(&kb, &g::add(&m10, &m11)) * (-0.5);
    let pu0 = transport_generic(&t0, &t1, &u0);
    let raw = g::dot(&g::cross(&pu0, &u1), &t1).atan2(g::dot(&pu0, &u1));
    let tau = raw.clone() + (continuous_twist(fr.twist, fr.twist_raw, raw.re()) - raw.re());
    let m = th1 - th0 + tau;
    let d1 = k1 - p.rest_curvature[0];
    let d2 = k2 - p.rest_curvature[1];
    let dm = m - p.rest_twist;
    ((d1.clone() * d1 + d2.clone() * d2) * p.bend + dm.clone() * dm * p.twist)
        * (0.5 / p.voronoi_length)
}

/// `(Vector3, θ)` arrays from a flat 11-vector (x⁰, x¹, x², θ⁰, θ¹).
pub fn unpack(x: &[f64]) -> ([Vector3<f64>; 3], [f64; 2]) {
    (
        [
            Vector3::new(x[0], x[1], x[2]),
            Vector3::new(x[3], x[4], x[5]),
            Vector3::new(x[6], x[7], x[8]),
        ],
        [x[9], x[10]],
    )
}
