//! Value + gradient + Hessian carriers for the chain rule of the rod stencils.
//!
//! The bending+twisting stencil is a composition of a few primitives whose derivatives are written out by hand
//! (the unit tangent, the parallel-transported reference director, the curvature binormal; `frame.rs`). The
//! composition rules — product, quotient, dot product, `atan2` — live here, as the plain product and chain rules
//! for first and second derivatives over the stencil's `N` local variables.

use nalgebra::{SMatrix, SVector, Vector3};

/// A scalar with its gradient and Hessian over `N` variables.
#[derive(Clone, Copy, Debug)]
pub struct Jet<const N: usize> {
    /// the value
    pub v: f64,
    /// the gradient
    pub g: SVector<f64, N>,
    /// the Hessian
    pub h: SMatrix<f64, N, N>,
}

impl<const N: usize> Jet<N> {
    /// A constant.
    pub fn constant(v: f64) -> Self {
        Jet {
            v,
            g: SVector::zeros(),
            h: SMatrix::zeros(),
        }
    }

    /// Variable number `i` (gradient eᵢ, Hessian 0).
    pub fn variable(v: f64, i: usize) -> Self {
        let mut j = Self::constant(v);
        j.g[i] = 1.0;
        j
    }

    /// Sum a + b.
    pub fn add(&self, o: &Self) -> Self {
        Jet {
            v: self.v + o.v,
            g: self.g + o.g,
            h: self.h + o.h,
        }
    }

    /// Difference a − b.
    pub fn sub(&self, o: &Self) -> Self {
        Jet {
            v: self.v - o.v,
            g: self.g - o.g,
            h: self.h - o.h,
        }
    }

    /// Product with the constant s.
    pub fn scale(&self, s: f64) -> Self {
        Jet {
            v: self.v * s,
            g: self.g * s,
            h: self.h * s,
        }
    }

    /// Product rule: (ab)'' = a b'' + b a'' + a' b'ᵀ + b' a'ᵀ.
    pub fn mul(&self, o: &Self) -> Self {
        let cross = self.g * o.g.transpose();
        Jet {
            v: self.v * o.v,
            g: self.g * o.v + o.g * self.v,
            h: self.h * o.v + o.h * self.v + cross + cross.transpose(),
        }
    }

    /// 1/a: gradient −a'/a², Hessian −a''/a² + 2 a' a'ᵀ / a³.
    pub fn recip(&self) -> Self {
        let r = 1.0 / self.v;
        let r2 = r * r;
        Jet {
            v: r,
            g: self.g * (-r2),
            h: self.h * (-r2) + self.g * self.g.transpose() * (2.0 * r2 * r),
        }
    }

    /// Power aᵖ (a > 0): gradient p aᵖ⁻¹ a', Hessian p aᵖ⁻¹ a'' + p (p − 1) aᵖ⁻² a' a'ᵀ.
    pub fn powf(&self, p: f64) -> Self {
        let f = self.v.powf(p);
        let f1 = p * f / self.v;
        let f2 = (p - 1.0) * f1 / self.v;
        Jet {
            v: f,
            g: self.g * f1,
            h: self.h * f1 + self.g * self.g.transpose() * f2,
        }
    }

    /// Half-square ½a² (used by the quadratic energies).
    pub fn half_square(&self) -> Self {
        Jet {
            v: 0.5 * self.v * self.v,
            g: self.g * self.v,
            h: self.h * self.v + self.g * self.g.transpose(),
        }
    }

    /// atan2(s, c) = the angle φ with (cos φ, sin φ) ∝ (c, s): ∇φ = (c∇s − s∇c)/R with R = c² + s², and
    /// ∇²φ = (c∇²s − s∇²c)/R + (∇c∇sᵀ − ∇s∇cᵀ)/R − ∇φ ∇Rᵀ/R, symmetrised (it is symmetric in exact arithmetic).
    pub fn atan2(s: &Self, c: &Self) -> Self {
        let r = c.v * c.v + s.v * s.v;
        let g = (s.g * c.v - c.g * s.v) / r;
        let grad_r = (c.g * c.v + s.g * s.v) * 2.0;
        let h = (s.h * c.v - c.h * s.v) / r + (c.g * s.g.transpose() - s.g * c.g.transpose()) / r
            - g * grad_r.transpose() / r;
        Jet {
            v: s.v.atan2(c.v),
            g,
            h: (h + h.transpose()) * 0.5,
        }
    }
}

/// A 3-vector with its Jacobian (3×N) and the Hessian of each component over `N` variables.
#[derive(Clone, Copy, Debug)]
pub struct VJet<const N: usize> {
    /// the vector
    pub v: Vector3<f64>,
    /// its Jacobian (3 × N)
    pub j: SMatrix<f64, 3, N>,
    /// the Hessian of each component
    pub h: [SMatrix<f64, N, N>; 3],
}

impl<const N: usize> VJet<N> {
    /// Embed a vector function of `M` variables into `N` variables: local variable `k` becomes `cols[k]`.
    pub fn embed<const M: usize>(x: &VJet<M>, cols: [usize; M]) -> Self {
        let mut j = SMatrix::<f64, 3, N>::zeros();
        let mut h = [SMatrix::<f64, N, N>::zeros(); 3];
        for a in 0..M {
            for i in 0..3 {
                j[(i, cols[a])] = x.j[(i, a)];
            }
            for b in 0..M {
                for i in 0..3 {
                    h[i][(cols[a], cols[b])] = x.h[i][(a, b)];
                }
            }
        }
        VJet { v: x.v, j, h }
    }

    /// Dot product: (a·b)'' = Σᵢ (aᵢ bᵢ'' + bᵢ aᵢ'') + Jₐᵀ J_b + J_bᵀ Jₐ.
    pub fn dot(&self, o: &Self) -> Jet<N> {
        let cross = self.j.transpose() * o.j;
        let mut h = cross + cross.transpose();
        for i in 0..3 {
            h += self.h[i] * o.v[i] + o.h[i] * self.v[i];
        }
        Jet {
            v: self.v.dot(&o.v),
            g: self.j.transpose() * o.v + o.j.transpose() * self.v,
            h,
        }
    }

    /// a + b.
    pub fn add(&self, o: &Self) -> Self {
        VJet {
            v: self.v + o.v,
            j: self.j + o.j,
            h: [self.h[0] + o.h[0], self.h[1] + o.h[1], self.h[2] + o.h[2]],
        }
    }
}
