//! Dissipation in the incremental potential (docs/cloth-simulator.md; ARCSim-HYLC's damping and air drag): forces that depend
//! on the velocity v = (x − xₙ)/h of the step enter Φ as potentials whose gradient is minus the force, with the
//! geometry lagged at xₙ so that every term has an exact Jacobian.
//!
//! **Stiffness-proportional damping**, force −c H v per face (c in seconds, H the face's elastic Hessian): with
//! H frozen at xₙ and δq = q(x) − q(xₙ) the face's 18 coordinates' change,
//! D_f = (c / 2h) δqᵀ H δq, ∇D_f = (c/h) H δq = c H v, ∇²D_f = (c/h) H. H is the model's PSD Hessian (option
//! (a) or (b); option (c) uses (b)), so D_f is convex. The original's linearised step solves
//! (M − h(h + c)H)Δv = h(F + (h + c)H v): the same damping force, taken at the end of the step.
//!
//! **Air drag** (ARCSim's wind), per face of rest area A with the three vertices' mean velocity v̄ and the unit
//! normal n at xₙ: u = w − v̄ (w the wind velocity), u_n = n·u, u_t = u − u_n n, force
//! f = A (ρ |u_n| u_n n + d u_t), a third on each vertex. With Q(u) = A (ρ |u_n|³/3 + d |u_t|²/2), ∂Q/∂u = f and
//! v̄ = Σ (x_a − xₙ_a)/(3h), the potential Π_f = h Q(u(x)) has ∂Π_f/∂x_a = −f/3 and the Hessian blocks
//! (A / 9h)(2ρ|u_n| n nᵀ + d (I − n nᵀ)), PSD for ρ, d ≥ 0 (C² since |u_n|³ is).

use crate::real::{c, Real};

/// Air-drag parameters (ARCSim's `wind`): density ρ (kg/m³), tangential drag d (kg/(m² s)), wind velocity w.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Wind {
    /// air density ρ (kg/m³)
    pub density: f64,
    /// tangential drag d (kg/(m² s))
    pub drag: f64,
    /// wind velocity w (m/s)
    pub velocity: [f64; 3],
}

impl Default for Wind {
    /// No air: ρ = d = 0, w = 0.
    fn default() -> Self {
        Wind {
            density: 0.0,
            drag: 0.0,
            velocity: [0.0; 3],
        }
    }
}

impl Wind {
    /// Whether the drag force vanishes identically.
    pub fn is_off(&self) -> bool {
        self.density == 0.0 && self.drag == 0.0
    }
}

/// The lagged data of one face's air drag over a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DragFace {
    /// rest area A (m²)
    pub area: f64,
    /// unit normal at xₙ
    pub n: [f64; 3],
    /// the face's vertex positions at xₙ
    pub xn: [[f64; 3]; 3],
}

/// u = w − Σ_a (x_a − xₙ_a)/(3h) for the face's current positions `x` (9 numbers).
fn relative_velocity(f: &DragFace, wind: &Wind, h: f64, x: &[f64; 9]) -> [f64; 3] {
    std::array::from_fn(|k| {
        let vbar: f64 = (0..3).map(|a| x[3 * a + k] - f.xn[a][k]).sum::<f64>() / (3.0 * h);
        wind.velocity[k] - vbar
    })
}

/// Π_f = h Q(u): value, gradient (9) and Hessian (9×9) for the face's positions `x`.
pub fn drag(f: &DragFace, wind: &Wind, h: f64, x: &[f64; 9]) -> (f64, [f64; 9], [[f64; 9]; 9]) {
    let u = relative_velocity(f, wind, h, x);
    let n = f.n;
    let un = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
    let ut: [f64; 3] = std::array::from_fn(|k| u[k] - un * n[k]);
    let ut2 = ut[0] * ut[0] + ut[1] * ut[1] + ut[2] * ut[2];
    let (rho, d, a) = (wind.density, wind.drag, f.area);
    let value = h * a * (rho * un.abs().powi(3) / 3.0 + d * ut2 / 2.0);
    let force: [f64; 3] = std::array::from_fn(|k| a * (rho * un.abs() * un * n[k] + d * ut[k]));
    let mut g = [0.0; 9];
    for v in 0..3 {
        for k in 0..3 {
            g[3 * v + k] = -force[k] / 3.0;
        }
    }
    let blk: [[f64; 3]; 3] = std::array::from_fn(|p| {
        std::array::from_fn(|q| {
            let nn = n[p] * n[q];
            a / (9.0 * h) * (2.0 * rho * un.abs() * nn + d * ((p == q) as u8 as f64 - nn))
        })
    });
    let mut hm = [[0.0; 9]; 9];
    for va in 0..3 {
        for vb in 0..3 {
            for p in 0..3 {
                for q in 0..3 {
                    hm[3 * va + p][3 * vb + q] = blk[p][q];
                }
            }
        }
    }
    (value, g, hm)
}

/// Reference implementation of [`drag`]'s value, generic over the scalar (derivative harness).
pub fn drag_reference<D: Real>(f: &DragFace, wind: &Wind, h: f64, x: &[D]) -> D {
    let u: Vec<D> = (0..3)
        .map(|k| {
            let s = (0..3).fold(c::<D>(0.0), |acc, a| {
                acc + x[3 * a + k].clone() - f.xn[a][k]
            });
            -(s / (3.0 * h)) + wind.velocity[k]
        })
        .collect();
    let un = (0..3).fold(c::<D>(0.0), |acc, k| acc + u[k].clone() * f.n[k]);
    let ut: Vec<D> = (0..3).map(|k| u[k].clone() - un.clone() * f.n[k]).collect();
    let ut2 = ut
        .iter()
        .fold(c::<D>(0.0), |acc, t| acc + t.clone() * t.clone());
    let un3 = un.clone() * un.clone() * un.abs();
    (un3 * (wind.density / 3.0) + ut2 * (wind.drag / 2.0)) * (h * f.area)
}

/// Π_f of [`drag`] as a function of both the positions `x` and the positions `xn` the face is lagged at (9 each):
/// the normal n = (e₁ × e₂)/|e₁ × e₂| of `xn` (as [`drag_face`] makes it) and the velocity's origin, generic over
/// the scalar (the trajectory adjoint differentiates μᵀ∇_xΠ_f with respect to `xn` by forward-mode AD).
pub fn drag_lagged_reference<D: Real>(area: f64, wind: &Wind, h: f64, x: &[D], xn: &[D]) -> D {
    let p = |a: usize| crate::real::v3(&xn[3 * a..]);
    let (p0, p1, p2) = (p(0), p(1), p(2));
    let m = crate::real::cross(&crate::real::sub(&p1, &p0), &crate::real::sub(&p2, &p0));
    let l = crate::real::norm(&m);
    let n: Vec<D> = m.iter().map(|mk| mk.clone() / l.clone()).collect();
    let u: Vec<D> = (0..3)
        .map(|k| {
            let s = (0..3).fold(c::<D>(0.0), |acc, a| {
                acc + x[3 * a + k].clone() - xn[3 * a + k].clone()
            });
            -(s / (3.0 * h)) + wind.velocity[k]
        })
        .collect();
    let un = (0..3).fold(c::<D>(0.0), |acc, k| acc + u[k].clone() * n[k].clone());
    let ut2 = (0..3).fold(c::<D>(0.0), |acc, k| {
        let t = u[k].clone() - un.clone() * n[k].clone();
        acc + t.clone() * t
    });
    let un3 = un.clone() * un.clone() * un.abs();
    (un3 * (wind.density / 3.0) + ut2 * (wind.drag / 2.0)) * (h * area)
}

/// The unit normal and rest-area data of a face at xₙ (`None` for a degenerate face).
pub fn drag_face(xn: [[f64; 3]; 3], area: f64) -> Option<DragFace> {
    let e1: [f64; 3] = std::array::from_fn(|k| xn[1][k] - xn[0][k]);
    let e2: [f64; 3] = std::array::from_fn(|k| xn[2][k] - xn[0][k]);
    let m = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let l = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    (l > 0.0 && l.is_finite()).then(|| DragFace {
        area,
        n: m.map(|x| x / l),
        xn,
    })
}

/// D_f = (c/2h) δqᵀ H δq for a face's coordinate change δq (18, zero on absent flaps) with the frozen PSD
/// Hessian `hess`: value and gradient (the Hessian is (c/h) H).
pub fn damping(hess: &[[f64; 18]; 18], c_over_h: f64, dq: &[f64; 18]) -> (f64, [f64; 18]) {
    let mut g = [0.0; 18];
    for (r, row) in hess.iter().enumerate() {
        g[r] = c_over_h * row.iter().zip(dq).map(|(a, b)| a * b).sum::<f64>();
    }
    let value = 0.5 * g.iter().zip(dq).map(|(a, b)| a * b).sum::<f64>();
    (value, g)
}

/// Reference implementation of [`damping`]'s value, generic over the scalar (derivative harness).
pub fn damping_reference<D: Real>(hess: &[[f64; 18]; 18], c_over_h: f64, dq: &[D]) -> D {
    let mut acc = c::<D>(0.0);
    for r in 0..18 {
        for s in 0..18 {
            acc += dq[r].clone() * dq[s].clone() * hess[r][s];
        }
    }
    acc * (0.5 * c_over_h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Const, U1};
    use num_dual::{Dual, DualSVec64};

    /// ∇_{xₙ}(μᵀ∇_xΠ) by AD of [`drag_lagged_reference`] equals central differences of [`drag`]'s gradient over
    /// faces re-made at moved xₙ, and the generic value equals [`drag`]'s.
    #[test]
    fn lagged_drag_derivative_matches_differences() {
        let wind = Wind {
            density: 1.2,
            drag: 0.5,
            velocity: [0.3, -0.2, 1.0],
        };
        let (h, area) = (1.0 / 120.0, 2e-4);
        let xn = [0.0, 0.0, 0.0, 0.02, 0.001, 0.002, 0.003, 0.021, -0.001];
        let x: [f64; 9] = std::array::from_fn(|i| xn[i] + 1e-3 * ((i * 7 % 5) as f64 - 2.0));
        let mu: [f64; 9] = std::array::from_fn(|i| ((i * 3 % 4) as f64 - 1.5) * 0.7);
        let face = |xn: &[f64; 9]| {
            drag_face(
                std::array::from_fn(|a| [xn[3 * a], xn[3 * a + 1], xn[3 * a + 2]]),
                area,
            )
            .unwrap()
        };
        let mug = |xn: &[f64; 9]| -> f64 {
            let (_, g, _) = drag(&face(xn), &wind, h, &x);
            (0..9).map(|i| mu[i] * g[i]).sum()
        };
        let v = drag_lagged_reference(area, &wind, h, &x, &xn);
        assert!((v - drag(&face(&xn), &wind, h, &x).0).abs() <= 1e-14 * v.abs());
        type D9 = DualSVec64<9>;
        let xd: Vec<Dual<D9>> = (0..9)
            .map(|i| Dual::new(D9::from_re(x[i]), D9::from_re(mu[i])))
            .collect();
        let xnd: Vec<Dual<D9>> = (0..9)
            .map(|i| Dual::new(D9::from_re(xn[i]).derivative(i), D9::from_re(0.0)))
            .collect();
        let p = drag_lagged_reference(area, &wind, h, &xd, &xnd);
        assert!((p.eps.re - mug(&xn)).abs() <= 1e-12 * mug(&xn).abs());
        let g = p.eps.eps.unwrap_generic(Const::<9>, U1);
        let gs = g.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        for i in 0..9 {
            let d = 1e-7;
            let (mut a, mut b) = (xn, xn);
            a[i] += d;
            b[i] -= d;
            let fd = (mug(&a) - mug(&b)) / (2.0 * d);
            assert!((g[i] - fd).abs() <= 1e-6 * gs, "{i}: {} vs {fd}", g[i]);
        }
    }
}
