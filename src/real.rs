//! The scalar type of the reference implementations and plain 3-vector arithmetic over it: the bottom layer,
//! used by the rods, the contact kernels, the shell and the renderer (`docs/derivative-harness.md`,
//! section 1: every energy has a reference implementation generic over the scalar type).

use num_dual::DualNum;

/// Scalar types the reference implementations are written for: `f64` and num-dual numbers over `f64`.
pub trait Real: DualNum<Primitive = f64> {}
impl<T: DualNum<Primitive = f64>> Real for T {}

/// Shorthand to build a constant of a generic scalar type.
#[inline]
pub fn c<D: Real>(x: f64) -> D {
    D::from(x)
}

/// A 3-vector of a generic scalar.
pub type V3<D> = [D; 3];

/// The first three entries of `x`.
pub fn v3<D: Real>(x: &[D]) -> V3<D> {
    [x[0].clone(), x[1].clone(), x[2].clone()]
}

/// A 3-vector of constants.
pub fn from_f64<D: Real>(x: &nalgebra::Vector3<f64>) -> V3<D> {
    [D::from(x[0]), D::from(x[1]), D::from(x[2])]
}

/// a + b.
pub fn add<D: Real>(a: &V3<D>, b: &V3<D>) -> V3<D> {
    [
        a[0].clone() + b[0].clone(),
        a[1].clone() + b[1].clone(),
        a[2].clone() + b[2].clone(),
    ]
}

/// a − b.
pub fn sub<D: Real>(a: &V3<D>, b: &V3<D>) -> V3<D> {
    [
        a[0].clone() - b[0].clone(),
        a[1].clone() - b[1].clone(),
        a[2].clone() - b[2].clone(),
    ]
}

/// s a.
pub fn scale<D: Real>(a: &V3<D>, s: &D) -> V3<D> {
    [
        a[0].clone() * s.clone(),
        a[1].clone() * s.clone(),
        a[2].clone() * s.clone(),
    ]
}

/// a · b.
pub fn dot<D: Real>(a: &V3<D>, b: &V3<D>) -> D {
    a[0].clone() * b[0].clone() + a[1].clone() * b[1].clone() + a[2].clone() * b[2].clone()
}

/// a × b.
pub fn cross<D: Real>(a: &V3<D>, b: &V3<D>) -> V3<D> {
    [
        a[1].clone() * b[2].clone() - a[2].clone() * b[1].clone(),
        a[2].clone() * b[0].clone() - a[0].clone() * b[2].clone(),
        a[0].clone() * b[1].clone() - a[1].clone() * b[0].clone(),
    ]
}

/// |a| = √(a · a).
pub fn norm<D: Real>(a: &V3<D>) -> D {
    dot(a, a).sqrt()
}
