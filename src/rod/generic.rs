//! Plain 3-vector arithmetic over a generic scalar, for the reference implementations (num-dual inputs).

use crate::diff::Real;

pub type V3<D> = [D; 3];

pub fn v3<D: Real>(x: &[D]) -> V3<D> {
    [x[0].clone(), x[1].clone(), x[2].clone()]
}

pub fn from_f64<D: Real>(x: &nalgebra::Vector3<f64>) -> V3<D> {
    [D::from(x[0]), D::from(x[1]), D::from(x[2])]
}

pub fn add<D: Real>(a: &V3<D>, b: &V3<D>) -> V3<D> {
    [
        a[0].clone() + b[0].clone(),
        a[1].clone() + b[1].clone(),
        a[2].clone() + b[2].clone(),
    ]
}

pub fn sub<D: Real>(a: &V3<D>, b: &V3<D>) -> V3<D> {
    [
        a[0].clone() - b[0].clone(),
        a[1].clone() - b[1].clone(),
        a[2].clone() - b[2].clone(),
    ]
}

pub fn scale<D: Real>(a: &V3<D>, s: &D) -> V3<D> {
    [
        a[0].clone() * s.clone(),
        a[1].clone() * s.clone(),
        a[2].clone() * s.clone(),
    ]
}

pub fn dot<D: Real>(a: &V3<D>, b: &V3<D>) -> D {
    a[0].clone() * b[0].clone() + a[1].clone() * b[1].clone() + a[2].clone() * b[2].clone()
}

pub fn cross<D: Real>(a: &V3<D>, b: &V3<D>) -> V3<D> {
    [
        a[1].clone() * b[2].clone() - a[2].clone() * b[1].clone(),
        a[2].clone() * b[0].clone() - a[0].clone() * b[2].clone(),
        a[0].clone() * b[1].clone() - a[1].clone() * b[0].clone(),
    ]
}

pub fn norm<D: Real>(a: &V3<D>) -> D {
    dot(a, a).sqrt()
}

/// Parallel transport P(a→b) x by Rodrigues' formula (see [`super::frame::transport`]).
pub fn transport<D: Real>(a: &V3<D>, b: &V3<D>, x: &V3<D>) -> V3<D> {
    let c = dot(a, b);
    let k = cross(a, b);
    let f = dot(&k, x) / (c.clone() + D::from(1.0));
    add(&add(&scale(x, &c), &cross(&k, x)), &scale(&k, &f))
}
