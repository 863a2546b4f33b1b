//! Central finite differences with one Richardson extrapolation step (`docs/derivative-harness.md`, section 1).
//!
//! `D(h) = (f(x + h eᵢ) − f(x − h eᵢ)) / 2h` has error `O(h²)`; `(4 D(h/2) − D(h)) / 3` cancels it, leaving
//! `O(h⁴)` truncation and `O(ε |f| / h)` round-off.

use nalgebra::{DMatrix, DVector};

/// Richardson-extrapolated central difference of a vector-valued function along input `i`.
fn richardson<G: Fn(&[f64]) -> DVector<f64>>(g: &G, x: &[f64], i: usize, h: f64) -> DVector<f64> {
    let mut y = x.to_vec();
    let mut central = |step: f64| {
        y[i] = x[i] + step;
        let plus = g(&y);
        y[i] = x[i] - step;
        let minus = g(&y);
        y[i] = x[i];
        (plus - minus) / (2.0 * step)
    };
    let coarse = central(h);
    let fine = central(0.5 * h);
    (fine * 4.0 - coarse) / 3.0
}

/// Gradient of `f` at `x` by Richardson-extrapolated central differences with per-input steps `h`.
pub fn fd_gradient<F: Fn(&[f64]) -> f64>(f: F, x: &[f64], h: &[f64]) -> DVector<f64> {
    let g = |y: &[f64]| DVector::from_element(1, f(y));
    DVector::from_iterator(x.len(), (0..x.len()).map(|i| richardson(&g, x, i, h[i])[0]))
}

/// Hessian of a function by Richardson-extrapolated central differences of its gradient `g`, symmetrised.
pub fn fd_hessian<G: Fn(&[f64]) -> DVector<f64>>(g: G, x: &[f64], h: &[f64]) -> DMatrix<f64> {
    let n = x.len();
    let mut m = DMatrix::zeros(n, n);
    for j in 0..n {
        m.set_column(j, &richardson(&g, x, j, h[j]));
    }
    (&m + m.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn richardson_is_fourth_order_on_a_quintic() {
        // f = x⁵: central differences with Richardson have error h⁴ f⁽⁵⁾ / 480 = h⁴ / 4.
        let f = |y: &[f64]| y[0].powi(5);
        let h = 1e-2;
        let g = fd_gradient(f, &[1.0], &[h]);
        let err = (g[0] - 5.0).abs();
        assert!(err < 1e-8 && err > 1e-10, "error {err}");
    }

    #[test]
    fn hessian_of_a_quadratic_is_exact() {
        let g =
            |y: &[f64]| DVector::from_vec(vec![2.0 * y[0] + 3.0 * y[1], 3.0 * y[0] + 8.0 * y[1]]);
        let h = fd_hessian(g, &[0.3, -0.2], &[1e-3, 1e-3]);
        assert!((h[(0, 0)] - 2.0).abs() < 1e-10);
        assert!((h[(0, 1)] - 3.0).abs() < 1e-10);
        assert!((h[(1, 1)] - 8.0).abs() < 1e-10);
    }
}
