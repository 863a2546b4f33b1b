//! Harness rows of the cloth solver's non-elastic terms (docs/cloth-simulator.md; `docs/derivative-harness.md`, section 1): air drag
//! per face, stiffness-proportional damping per face, the obstacle penalty against a sphere, a plane and a
//! triangle mesh (faces, edges and vertices), and lagged Coulomb friction.
//!
//! Samples and scales (natural magnitudes, as the policy asks):
//! - drag: a random face of edge ~1 cm at xₙ, displaced by velocities up to 2 m/s over h ∈ [1e-3, 1/60] s, a
//!   random wind up to 1 m/s, ρ ∈ [0.5, 10], d ∈ [0, 2]. With U = |u| + 1e-3: value scale h A (ρ U³ + d U²),
//!   gradient scale A (ρ U² + d U), Hessian scale A (ρ U + d)/h. |u_n|³ is C² only: finite differences stay
//!   within 3h |u_n| / 2 of the sample (its kink at u_n = 0).
//! - damping: δq of up to 1 cm per coordinate, H = B Bᵀ/18 with B's entries in [−1, 1] × 10^[0, 4], c/h up to 10:
//!   value scale (c/h) ‖H‖ ‖δq‖², gradient (c/h) ‖H‖ ‖δq‖, Hessian (c/h) ‖H‖.
//! - penalty: points within the contact layer δ of each surface (an icosahedron's faces, edges and vertices, a
//!   sphere, a plane), m k = 1e-2…1e2: with p the penetration, value scale m k δ³, gradient m k δ², Hessian
//!   m k δ (plus m k δ²/r for the curved features, r the distance to the closest point). Finite differences stay
//!   below the distance to the layer's edge and to the boundary of the closest feature's region.
//! - friction: tangential displacements y ∈ (0, 3ε) on both sides of the smoothing width ε, λ μ up to 1 N: value
//!   scale λ μ ε, gradient λ μ, Hessian λ μ / ε; finite differences stay within |y − ε|/2 and y/2.

use crate::diff::{Check, Differentiable, Scales, Vgh};
use crate::real::Real;
use crate::shell::dissipation::{
    damping, damping_reference, drag, drag_face, drag_reference, DragFace, Wind,
};
use crate::shell::obstacle::{
    friction, friction_reference, penalty, penalty_hessian_exact, penalty_reference,
    FrictionContact, MeshObstacle, Obstacle,
};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

fn unit(rng: &mut ChaCha8Rng) -> [f64; 3] {
    loop {
        let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if l > 0.1 && l <= 1.0 {
            return v.map(|x| x / l);
        }
    }
}

fn vgh<const N: usize>(value: f64, g: &[f64], h: &[[f64; N]; N]) -> Vgh {
    Vgh {
        value,
        gradient: DVector::from_column_slice(g),
        hessian: DMatrix::from_fn(N, N, |r, c| h[r][c]),
    }
}

/// Air drag of one face: inputs the 9 coordinates; parameters xₙ (9), wind velocity (3), h, ρ, d.
struct DragCheck;

impl DragCheck {
    fn unpack(x: &[f64]) -> (DragFace, Wind, f64) {
        let p = &x[9..];
        let xn = [0, 1, 2].map(|a| [p[3 * a], p[3 * a + 1], p[3 * a + 2]]);
        let f = drag_face(xn, 5e-5).expect("sampled faces are not degenerate");
        let w = Wind {
            velocity: [p[9], p[10], p[11]],
            density: p[13],
            drag: p[14],
        };
        (f, w, p[12])
    }

    fn u(x: &[f64]) -> ([f64; 3], f64) {
        let (f, w, h) = Self::unpack(x);
        let u: [f64; 3] = std::array::from_fn(|k| {
            w.velocity[k] - (0..3).map(|a| x[3 * a + k] - f.xn[a][k]).sum::<f64>() / (3.0 * h)
        });
        let un = (0..3).map(|k| u[k] * f.n[k]).sum();
        (u, un)
    }
}

impl Differentiable for DragCheck {
    fn name(&self) -> String {
        "shell air drag per face".into()
    }
    fn dim(&self) -> usize {
        9
    }
    fn n_params(&self) -> usize {
        15
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        let (f, w, h) = Self::unpack(x);
        let (u, _) = Self::u(x);
        let uu = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt() + 1e-3;
        let a = f.area;
        Scales {
            value: h * a * (w.density * uu.powi(3) + w.drag * uu * uu),
            gradient: a * (w.density * uu * uu + w.drag * uu),
            hessian: a * (w.density * uu + w.drag) / h,
        }
    }
    fn input_scale(&self, _i: usize) -> f64 {
        1e-2
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        let (_, _, h) = Self::unpack(x);
        1.5 * h * Self::u(x).1.abs()
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let xr: Vec<f64> = x.iter().map(|v| v.re()).collect();
        let (f, w, h) = Self::unpack(&xr);
        drag_reference(&f, &w, h, &x[..9])
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let (f, w, h) = Self::unpack(x);
        let q: [f64; 9] = std::array::from_fn(|i| x[i]);
        let (v, g, hm) = drag(&f, &w, h, &q);
        vgh(v, &g, &hm)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, _i: usize) -> Vec<f64> {
        let h = rng.random_range(1e-3..1.0 / 60.0);
        let base: [f64; 3] = std::array::from_fn(|_| rng.random_range(-0.2..0.2));
        let xn: Vec<f64> = (0..3)
            .flat_map(|_| {
                let o = unit(rng);
                (0..3).map(move |k| base[k] + 0.01 * o[k])
            })
            .collect();
        let v = unit(rng).map(|c| c * rng.random_range(0.0..2.0));
        let mut out: Vec<f64> = (0..9)
            .map(|i| xn[i] + h * (v[i % 3] + rng.random_range(-0.3..0.3)))
            .collect();
        out.extend(&xn);
        out.extend(unit(rng).map(|c| c * rng.random_range(0.0..1.0)));
        out.push(h);
        out.push(rng.random_range(0.5..10.0));
        out.push(rng.random_range(0.0..2.0));
        out
    }
}

/// Damping of one face: inputs δq (18); parameters c/h and H (18 × 18).
struct DampingCheck;

fn damping_params(x: &[f64]) -> (f64, [[f64; 18]; 18]) {
    let h = std::array::from_fn(|r| std::array::from_fn(|c| x[19 + 18 * r + c]));
    (x[18], h)
}

impl Differentiable for DampingCheck {
    fn name(&self) -> String {
        "shell stiffness-proportional damping per face".into()
    }
    fn dim(&self) -> usize {
        18
    }
    fn n_params(&self) -> usize {
        1 + 18 * 18
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        let (coh, h) = damping_params(x);
        let hn = h.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
        let dq = x[..18].iter().map(|v| v * v).sum::<f64>().sqrt();
        Scales {
            value: coh * hn * dq * dq,
            gradient: coh * hn * dq,
            hessian: coh * hn,
        }
    }
    fn input_scale(&self, _i: usize) -> f64 {
        1e-2
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let xr: Vec<f64> = x.iter().map(|v| v.re()).collect();
        let (coh, h) = damping_params(&xr);
        damping_reference(&h, coh, &x[..18])
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let (coh, h) = damping_params(x);
        let dq: [f64; 18] = std::array::from_fn(|i| x[i]);
        let (v, g) = damping(&h, coh, &dq);
        vgh(v, &g, &h.map(|row| row.map(|e| coh * e)))
    }
    fn sample(&self, rng: &mut ChaCha8Rng, _i: usize) -> Vec<f64> {
        let mut out: Vec<f64> = (0..18).map(|_| rng.random_range(-0.01..0.01)).collect();
        out.push(rng.random_range(0.0..10.0));
        let mag = 10f64.powf(rng.random_range(0.0..4.0));
        let b: Vec<f64> = (0..324)
            .map(|_| mag * rng.random_range(-1.0..1.0))
            .collect();
        for r in 0..18 {
            for c in 0..18 {
                out.push((0..18).map(|k| b[18 * r + k] * b[18 * c + k]).sum::<f64>() / 18.0);
            }
        }
        out
    }
}

/// The obstacle penalty of one vertex against an obstacle; inputs the position (3); parameters m k and δ.
struct PenaltyCheck {
    name: &'static str,
    obstacle: Obstacle,
    /// where samples are drawn: (centre, radius) of the surface's bounding sphere, or a plane's point
    center: [f64; 3],
    radius: f64,
}

impl PenaltyCheck {
    /// The largest perturbation per coordinate that keeps the closest feature (tried down to 1e-9 of δ).
    fn feature_distance(&self, p: [f64; 3], delta: f64) -> f64 {
        let f0 = self.obstacle.feature(p);
        let mut s = delta;
        while s > 1e-9 * delta {
            let same = (0..3).all(|k| {
                [-1.0, 1.0].iter().all(|sg| {
                    let mut q = p;
                    q[k] += sg * s;
                    self.obstacle.feature(q) == f0
                })
            });
            if same {
                return s;
            }
            s *= 0.5;
        }
        0.0
    }
}

impl Differentiable for PenaltyCheck {
    fn name(&self) -> String {
        format!("shell obstacle penalty[{}]", self.name)
    }
    fn dim(&self) -> usize {
        3
    }
    fn n_params(&self) -> usize {
        2
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        let (mk, delta) = (x[3], x[4]);
        let pr = self.obstacle.proximity([x[0], x[1], x[2]]);
        let curv = pr
            .hess
            .iter()
            .flatten()
            .map(|v| v.abs())
            .fold(0.0, f64::max);
        Scales {
            value: mk * delta.powi(3),
            gradient: mk * delta * delta,
            hessian: mk * (delta + delta * delta * curv),
        }
    }
    fn input_scale(&self, _i: usize) -> f64 {
        1e-3
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        let p = [x[0], x[1], x[2]];
        let pen = x[4] - self.obstacle.proximity(p).d;
        (0.5 * pen.abs()).min(0.5 * self.feature_distance(p, x[4]))
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let p = [x[0].re(), x[1].re(), x[2].re()];
        let f = self.obstacle.feature(p);
        penalty_reference(&f, 1.0, x[3].re(), x[4].re(), &x[..3])
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let pr = self.obstacle.proximity([x[0], x[1], x[2]]);
        let (v, g, _) = penalty(&pr, 1.0, x[3], x[4]);
        vgh(v, &g, &penalty_hessian_exact(&pr, 1.0, x[3], x[4]))
    }
    fn sample(&self, rng: &mut ChaCha8Rng, _i: usize) -> Vec<f64> {
        let delta = rng.random_range(1e-3..5e-3);
        let mk = 10f64.powf(rng.random_range(-2.0..2.0));
        loop {
            let p: [f64; 3] = match &self.obstacle {
                Obstacle::Plane { point, .. } => {
                    let t = unit(rng);
                    std::array::from_fn(|k| point[k] + 0.1 * t[k])
                }
                _ => {
                    let u = unit(rng);
                    let r = self.radius * rng.random_range(0.7..1.1);
                    std::array::from_fn(|k| self.center[k] + r * u[k])
                }
            };
            // project into the layer: move along n to a random depth in (0, δ) above −δ
            let pr = self.obstacle.proximity(p);
            let target = rng.random_range(-delta..0.95 * delta);
            let q: [f64; 3] = std::array::from_fn(|k| p[k] + (target - pr.d) * pr.n[k]);
            let pq = self.obstacle.proximity(q);
            if pq.d < 0.95 * delta && self.feature_distance(q, delta) > 1e-6 * delta {
                return vec![q[0], q[1], q[2], mk, delta];
            }
        }
    }
}

/// Lagged friction of one contact: inputs δ = x − xₙ (3); parameters n (3), λ, μ, ε.
struct FrictionCheck;

fn friction_params(x: &[f64]) -> (FrictionContact, f64, f64) {
    (
        FrictionContact {
            vertex: 0,
            n: [x[3], x[4], x[5]],
            lambda: x[6],
        },
        x[7],
        x[8],
    )
}

fn tangential(x: &[f64]) -> f64 {
    let n = [x[3], x[4], x[5]];
    let dn: f64 = (0..3).map(|k| n[k] * x[k]).sum();
    (0..3)
        .map(|k| (x[k] - dn * n[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

impl Differentiable for FrictionCheck {
    fn name(&self) -> String {
        "shell obstacle friction (lagged)".into()
    }
    fn dim(&self) -> usize {
        3
    }
    fn n_params(&self) -> usize {
        6
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        let (fc, mu, eps) = friction_params(x);
        let s = fc.lambda * mu;
        Scales {
            value: s * eps,
            gradient: s,
            hessian: s / eps,
        }
    }
    fn input_scale_at(&self, x: &[f64], _i: usize) -> f64 {
        x[8]
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        let y = tangential(x);
        (0.5 * (y - x[8]).abs()).min(0.5 * y)
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let xr: Vec<f64> = x.iter().map(|v| v.re()).collect();
        let (fc, mu, eps) = friction_params(&xr);
        friction_reference(&fc, mu, eps, &x[..3])
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let (fc, mu, eps) = friction_params(x);
        let (v, g, h) = friction(&fc, mu, eps, [x[0], x[1], x[2]]);
        vgh(v, &g, &h)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let n = unit(rng);
        let eps = 10f64.powf(rng.random_range(-7.0..-3.0));
        // tangential length on either side of ε, plus a normal part
        let y = eps
            * if i.is_multiple_of(2) {
                rng.random_range(0.05..0.9)
            } else {
                rng.random_range(1.1..3.0)
            };
        let mut t = unit(rng);
        let tn: f64 = (0..3).map(|k| t[k] * n[k]).sum();
        t = std::array::from_fn(|k| t[k] - tn * n[k]);
        let tl = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        let dn = rng.random_range(-1.0..1.0) * eps;
        let mut out: Vec<f64> = (0..3).map(|k| y * t[k] / tl + dn * n[k]).collect();
        out.extend(n);
        out.push(rng.random_range(1e-4..1.0));
        out.push(rng.random_range(0.01..1.0));
        out.push(eps);
        out
    }
}

/// An icosahedron of circumradius r about c (a closed, outward-wound triangle mesh).
pub fn icosahedron(c: [f64; 3], r: f64) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let raw = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let l = (1.0 + t * t).sqrt();
    let v = raw
        .iter()
        .map(|p| std::array::from_fn(|k| c[k] + r * p[k] / l))
        .collect();
    let f = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    (v, f)
}

/// The rows of this file.
pub fn diff_checks() -> Vec<Box<dyn Check>> {
    let c = [0.01, -0.02, 0.03];
    let (v, f) = icosahedron(c, 0.05);
    let mesh = MeshObstacle::new("icosahedron", v, f).expect("the icosahedron is a closed mesh");
    vec![
        Box::new(DragCheck),
        Box::new(DampingCheck),
        Box::new(PenaltyCheck {
            name: "sphere",
            obstacle: Obstacle::Sphere {
                center: c,
                radius: 0.03,
            },
            center: c,
            radius: 0.03,
        }),
        Box::new(PenaltyCheck {
            name: "plane",
            obstacle: Obstacle::Plane {
                point: c,
                normal: [0.3, -0.2, 0.9],
            },
            center: c,
            radius: 0.0,
        }),
        Box::new(PenaltyCheck {
            name: "mesh",
            obstacle: Obstacle::Mesh(Box::new(mesh)),
            center: c,
            radius: 0.05,
        }),
        Box::new(FrictionCheck),
    ]
}
