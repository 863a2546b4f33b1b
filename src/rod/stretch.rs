//! Stretching stencil (`docs/yarn-model.md`, "Energies"): E_s = ½ k_s l̄ (l/l̄ − 1)² for one edge, 6 dofs
//! (x_start, x_end).

use crate::real::Real;
use crate::real::{norm, sub, v3};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Stretching energy of one edge (fast value).
pub fn stretch_value(x0: &Vector3<f64>, x1: &Vector3<f64>, rest_length: f64, ks: f64) -> f64 {
    let strain = (x1 - x0).norm() / rest_length - 1.0;
    0.5 * ks * rest_length * strain * strain
}

/// Value, gradient and Hessian over (x_start, x_end): with e = x_end − x_start, l = |e|, t = e/l,
/// ∂E/∂e = k_s (l/l̄ − 1) t and ∂²E/∂e² = (k_s/l̄) t tᵀ + k_s (l/l̄ − 1)(I − t tᵀ)/l.
pub fn stretch_vgh(
    x0: &Vector3<f64>,
    x1: &Vector3<f64>,
    rest_length: f64,
    ks: f64,
) -> (f64, SVector<f64, 6>, SMatrix<f64, 6, 6>) {
    let e = x1 - x0;
    let l = e.norm();
    let t = e / l;
    let strain = l / rest_length - 1.0;
    let value = 0.5 * ks * rest_length * strain * strain;
    let ge = t * (ks * strain);
    let tt = t * t.transpose();
    let he = tt * (ks / rest_length) + (Matrix3::identity() - tt) * (ks * strain / l);
    let mut g = SVector::<f64, 6>::zeros();
    g.fixed_rows_mut::<3>(0).copy_from(&(-ge));
    g.fixed_rows_mut::<3>(3).copy_from(&ge);
    let mut h = SMatrix::<f64, 6, 6>::zeros();
    h.fixed_view_mut::<3, 3>(0, 0).copy_from(&he);
    h.fixed_view_mut::<3, 3>(3, 3).copy_from(&he);
    h.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-he));
    h.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-he));
    (value, g, h)
}

/// Reference twin of [`stretch_value`], generic over the scalar: `x` = (x_start, x_end).
pub fn stretch_reference<D: Real>(x: &[D], rest_length: f64, ks: f64) -> D {
    let e = sub(&v3(&x[3..6]), &v3(&x[0..3]));
    let strain = norm(&e) / rest_length - 1.0;
    strain.clone() * strain * (0.5 * ks * rest_length)
}
