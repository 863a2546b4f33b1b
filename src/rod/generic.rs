//! Rod geometry over a generic scalar, for the reference implementations (num-dual inputs).

use crate::real::{add, cross, dot, scale, Real, V3};

/// Parallel transport P(a→b) x by Rodrigues' formula (see [`super::frame::transport`]).
pub fn transport_generic<D: Real>(a: &V3<D>, b: &V3<D>, x: &V3<D>) -> V3<D> {
    let c = dot(a, b);
    let k = cross(a, b);
    let f = dot(&k, x) / (c.clone() + D::from(1.0));
    add(&add(&scale(x, &c), &cross(&k, x)), &scale(&k, &f))
}
