//! Harness rows of the macro scale (`docs/derivative-harness.md`, section 1): the strain chain z(q) of a triangle stencil
//! (as the scalar w·z(q) for a weight vector w, so its gradient is Jᵀw and its Hessian the contraction
//! Σ_k w_k ∇²z_k; unit weights give each row of the Jacobian and each slice of the 6×18×18 tensor), the triangle
//! energy A·ψ(z(q)), and the assembled energy of a small mesh.
//!
//! Samples: random rest triangles (edges 1–3.5 cm, any orientation; every fifth a sliver of aspect ratio 1e-3),
//! deformed by a random in-plane map with principal stretches in [0.1, 3], a random rotation and translation (up
//! to 2 m), flaps folded about their edges by random angles (every fourth case to exactly ±170°); every third case
//! has one flap missing, every ninth two or three (with fewer than two flaps II has a zero eigenvalue, on a knot
//! of the bending splines, and finite differences are skipped there; the AD comparisons still run). Finite-difference steps are relative to the smallest height in the stencil.
//!
//! Scales (natural magnitudes, documented as the policy asks): with ρ = max_i ‖r_i‖ (1/m), h_max and h_min the
//! largest triangle height and the smallest height in the stencil (triangle and flaps), and ‖F‖_min the smaller
//! column norm of F: for s_x, s_a, s_y the value scale is 1, the gradient scale ρ, the Hessian scale
//! ρ²/‖F‖_min; for II the value scale is π ρ² h_max, the gradient scale ρ² h_max/h_min and the Hessian scale
//! ρ² h_max/h_min². The row of w·z uses Σ|w_k| times these; the energy rows use A·k·V (V the material's data
//! magnitude, as the ψ rows) times the chain magnitudes divided by the strain scales σ.

use crate::diff::{Check, Differentiable, Scales, Vgh};
use crate::material::synthetic::default_material;
use crate::material::Material;
use crate::real::Real;
use crate::shell::assemble::{gather, Pattern};
use crate::shell::element::{energy_reference, ElementModel, ModelFlags, Psd};
use crate::shell::fold::{CollapseBarrier, FoldBarrier};
use crate::shell::mesh::{Mesh, Stencil};
use crate::shell::strain::{
    hinge_angles_reference, strain_reference, RestTriangle, StrainChain, NDOF,
};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Parameters stored after the 18 positions in a sampled vector: D_m⁻¹ (4), flap flags (3), weights (6).
const NPAR: usize = 13;

fn rest_of(x: &[f64]) -> (RestTriangle, [bool; 3]) {
    let p = &x[NDOF..];
    (
        RestTriangle::from_inv_dm([[p[0], p[1]], [p[2], p[3]]]),
        [p[4] != 0.0, p[5] != 0.0, p[6] != 0.0],
    )
}

fn q_of(x: &[f64]) -> [f64; NDOF] {
    std::array::from_fn(|j| x[j])
}

/// Chain magnitudes at a sample: (value, gradient, Hessian) for the stretch part and for the bending part.
fn chain_magnitudes(x: &[f64]) -> ([f64; 3], [f64; 3], f64) {
    let (rest, flaps) = rest_of(x);
    let rho = rest
        .r()
        .iter()
        .map(|r| r[0].hypot(r[1]))
        .fold(0.0, f64::max);
    let v = |k: usize| Vector3::new(x[3 * k], x[3 * k + 1], x[3 * k + 2]);
    let (hmax, hmin) = heights(&[v(0), v(1), v(2), v(3), v(4), v(5)], flaps);
    let d = &rest.inv_dm;
    let (d1, d2) = (v(1) - v(0), v(2) - v(0));
    let fmin = (d1 * d[0][0] + d2 * d[1][0])
        .norm()
        .min((d1 * d[0][1] + d2 * d[1][1]).norm());
    (
        [1.0, rho, rho * rho / fmin],
        [
            std::f64::consts::PI * rho * rho * hmax,
            rho * rho * hmax / hmin,
            rho * rho * hmax / (hmin * hmin),
        ],
        hmin,
    )
}

/// Largest triangle height and smallest height of triangle or flap over its edge.
fn heights(p: &[Vector3<f64>; 6], flaps: [bool; 3]) -> (f64, f64) {
    let n = (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
    let mut hmax: f64 = 0.0;
    let mut hmin = f64::INFINITY;
    for i in 0..3 {
        let e = p[(i + 1) % 3] - p[i];
        let h = n / e.norm();
        hmax = hmax.max(h);
        hmin = hmin.min(h);
        if flaps[i] {
            hmin = hmin.min((p[3 + i] - p[i]).cross(&e).norm() / e.norm());
        }
    }
    (hmax, hmin)
}

fn rotation(axis: Vector3<f64>, angle: f64) -> Matrix3<f64> {
    nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).into_inner()
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Matrix3<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    ) + Vector3::new(1e-3, 0.0, 0.0);
    rotation(axis, rng.random_range(-3.1..3.1))
}

/// A random stencil (18 positions) with its rest data and flap flags (see the module documentation).
pub fn sample_stencil(rng: &mut ChaCha8Rng, i: usize) -> ([f64; NDOF], RestTriangle, [bool; 3]) {
    loop {
        // rest triangle in material coordinates
        let l1: f64 = rng.random_range(0.01..0.035);
        let l2: f64 = rng.random_range(0.01..0.035);
        let ang: f64 = if i % 5 == 1 {
            1e-3 * l1 / l2 * rng.random_range(0.9..1.1)
        } else {
            rng.random_range(0.35..2.8)
        };
        let phi: f64 = rng.random_range(-3.1..3.1);
        let x0 = [rng.random_range(-0.05..0.05), rng.random_range(-0.05..0.05)];
        let dir = |a: f64, l: f64| [l * (phi + a).cos(), l * (phi + a).sin()];
        let (a, b) = (dir(0.0, l1), dir(ang, l2));
        let xr = [
            x0,
            [x0[0] + a[0], x0[1] + a[1]],
            [x0[0] + b[0], x0[1] + b[1]],
        ];
        let Some(rest) = RestTriangle::new(xr[0], xr[1], xr[2]) else {
            continue;
        };
        // flap rest positions: across each edge, at a random point on the far side
        let mut flr = [[0.0; 2]; 3];
        for k in 0..3 {
            let (p, q, o) = (xr[k], xr[(k + 1) % 3], xr[(k + 2) % 3]);
            let s: f64 = rng.random_range(0.2..0.8);
            let foot = [p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])];
            let e = [q[0] - p[0], q[1] - p[1]];
            let le = e[0].hypot(e[1]);
            let mut nrm = [-e[1] / le, e[0] / le];
            if nrm[0] * (o[0] - p[0]) + nrm[1] * (o[1] - p[1]) > 0.0 {
                nrm = [-nrm[0], -nrm[1]];
            }
            let h = rng.random_range(0.3..1.0) * le;
            flr[k] = [foot[0] + h * nrm[0], foot[1] + h * nrm[1]];
        }
        // in-plane map: U diag(λ) Vᵀ with λ in [0.1, 3]
        let l0: f64 = rng.random_range(0.1..3.0);
        let l1s: f64 = rng.random_range(0.1..3.0);
        let (u, v) = (
            rng.random_range(-3.1..3.1f64),
            rng.random_range(-3.1..3.1f64),
        );
        let r2 = |t: f64| nalgebra::Matrix2::new(t.cos(), -t.sin(), t.sin(), t.cos());
        let f2 = r2(u) * nalgebra::Matrix2::new(l0, 0.0, 0.0, l1s) * r2(v).transpose();
        let rot = random_rotation(rng);
        let shift = if i % 3 == 2 {
            Vector3::new(2.0, -1.2, 0.9)
        } else {
            Vector3::new(
                rng.random_range(-0.05..0.05),
                rng.random_range(-0.05..0.05),
                rng.random_range(-0.05..0.05),
            )
        };
        let map = |p: [f64; 2]| {
            let m = f2 * nalgebra::Vector2::new(p[0], p[1]);
            rot * Vector3::new(m[0], m[1], 0.0) + shift
        };
        let mut pts = [Vector3::zeros(); 6];
        for k in 0..3 {
            pts[k] = map(xr[k]);
        }
        let mut flaps = [true; 3];
        if i % 9 == 1 {
            let keep = rng.random_range(0..3);
            for k in 0..3 {
                flaps[k] = k == keep && rng.random_bool(0.5);
            }
        } else if i % 3 == 1 {
            flaps[rng.random_range(0..3)] = false;
        }
        for k in 0..3 {
            let fold: f64 = if i % 4 == 3 {
                if rng.random_bool(0.5) {
                    170f64.to_radians()
                } else {
                    -170f64.to_radians()
                }
            } else {
                rng.random_range(-2.9..2.9)
            };
            let (p, q) = (pts[k], pts[(k + 1) % 3]);
            let rf = rotation(q - p, fold);
            pts[3 + k] = p + rf * (map(flr[k]) - p);
        }
        let mut q = [0.0; NDOF];
        for k in 0..6 {
            for c in 0..3 {
                q[3 * k + c] = pts[k][c];
            }
        }
        if StrainChain::new(&q, &rest, flaps).is_some() {
            return (q, rest, flaps);
        }
    }
}

fn pack(q: &[f64; NDOF], rest: &RestTriangle, flaps: [bool; 3], w: [f64; 6]) -> Vec<f64> {
    let d = rest.inv_dm;
    let mut x = q.to_vec();
    x.extend([d[0][0], d[0][1], d[1][0], d[1][1]]);
    x.extend(flaps.map(|f| if f { 1.0 } else { 0.0 }));
    x.extend(w);
    x
}

/// w·z(q) for the strain chain.
pub struct StrainCheck;

impl Differentiable for StrainCheck {
    fn name(&self) -> String {
        "shell strain chain w.z(q)".into()
    }
    fn dim(&self) -> usize {
        NDOF
    }
    fn n_params(&self) -> usize {
        NPAR
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        let (s, b, _) = chain_magnitudes(x);
        let w = &x[NDOF + 7..];
        let ws = w[0].abs() + w[1].abs() + w[2].abs();
        let wb = w[3].abs() + w[4].abs() + w[5].abs();
        Scales {
            value: ws * s[0] + wb * b[0],
            gradient: ws * s[1] + wb * b[1],
            hessian: ws * s[2] + wb * b[2],
        }
    }
    fn input_scale_at(&self, x: &[f64], _i: usize) -> f64 {
        chain_magnitudes(x).2
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let p: Vec<f64> = x[NDOF..].iter().map(|d| d.re()).collect();
        let d = &p;
        let rest = RestTriangle::from_inv_dm([[d[0], d[1]], [d[2], d[3]]]);
        let flaps = [d[4] != 0.0, d[5] != 0.0, d[6] != 0.0];
        let z = strain_reference(&x[..NDOF], &rest, flaps);
        let mut acc = D::from(0.0);
        for k in 0..6 {
            acc += z[k].clone() * d[7 + k];
        }
        acc
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let (rest, flaps) = rest_of(x);
        let w: [f64; 6] = std::array::from_fn(|k| x[NDOF + 7 + k]);
        match StrainChain::new(&q_of(x), &rest, flaps) {
            Some(ch) => {
                let h = ch.weighted_hessian(&w);
                Vgh {
                    value: (0..6).map(|k| w[k] * ch.z[k]).sum(),
                    gradient: DVector::from_fn(NDOF, |j, _| {
                        (0..6).map(|k| w[k] * ch.jac[k][j]).sum()
                    }),
                    hessian: DMatrix::from_fn(NDOF, NDOF, |i, j| h[i][j]),
                }
            }
            None => Vgh {
                value: f64::NAN,
                gradient: DVector::from_element(NDOF, f64::NAN),
                hessian: DMatrix::from_element(NDOF, NDOF, f64::NAN),
            },
        }
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let (q, rest, flaps) = sample_stencil(rng, i);
        let w: [f64; 6] = if i % 7 < 6 && i.is_multiple_of(2) {
            std::array::from_fn(|k| if k == i % 7 { 1.0 } else { 0.0 })
        } else {
            std::array::from_fn(|_| rng.random_range(-1.0..1.0))
        };
        pack(&q, &rest, flaps, w)
    }
}

/// |∂θ_k/∂x_i| of the three hinge angles at a sample, by central differences (a slope bound for the kink
/// distance only).
fn strain_angles_gradient(x: &[f64], i: usize) -> [f64; 3] {
    let (_, flaps) = rest_of(x);
    let h = 1e-7 * chain_magnitudes(x).2;
    let at = |s: f64| {
        let mut q = q_of(x);
        q[i] += s;
        hinge_angles_reference(&q, flaps).map(|t| t.unwrap_or(0.0))
    };
    let (p, m) = (at(h), at(-h));
    std::array::from_fn(|k| ((p[k] - m[k]) / (2.0 * h)).abs())
}

/// Data magnitude V of a material and its smallest in-plane and bending strain scales.
fn material_magnitudes(m: &Material) -> (f64, f64, f64) {
    let max_abs = |p: &[f64]| p.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut v = m.constant.abs();
    for t in &m.terms1d {
        v += max_abs(&t.spline.p);
    }
    for t in &m.terms2d {
        v += max_abs(&t.spline.p);
    }
    let s = m.strain_scale;
    (v, s[0].min(s[1]).min(s[2]), s[3].min(s[4]))
}

/// The triangle energy A·k·ψ(S z(q)).
pub struct TriangleCheck {
    /// the check's name
    pub name: String,
    /// the element model (material, multipliers)
    pub model: ElementModel,
}

impl TriangleCheck {
    fn energy_scales(&self, x: &[f64]) -> Scales {
        let (s, b, _) = chain_magnitudes(x);
        let (v, ss, sb) = material_magnitudes(&self.model.material);
        let (rest, _) = rest_of(x);
        let c = rest.area * self.model.stiffness * v;
        let beta = self.model.bending_scale;
        let (gs, gb) = (s[1] / ss, beta * b[1] / sb);
        let f = self.fold_scales(x);
        let k = self.collapse_scales(x);
        Scales {
            value: c + f[0] + k[0],
            gradient: c * (gs + gb) + f[1] + k[1],
            hessian: c * (gs * gs + gb * gb + s[2] / ss + beta * b[2] / sb) + f[2] + k[2],
        }
    }

    /// The collapse barrier's magnitudes at a sample: A k (|φ|, ‖∇_z φ‖₁ g_s, ‖∇²_z φ‖ g_s² + ‖∇_z φ‖₁ h_s) for its
    /// density φ, with (g_s, h_s) the in-plane chain's gradient and Hessian scales; zeros without a barrier.
    fn collapse_scales(&self, x: &[f64]) -> [f64; 3] {
        let Some(cb) = &self.model.collapse else {
            return [0.0; 3];
        };
        let (rest, flaps) = rest_of(x);
        let (s, _, _) = chain_magnitudes(x);
        let Some(z) = crate::shell::strain::strain(&q_of(x), &rest, flaps) else {
            return [0.0; 3];
        };
        let (mut v, mut g, mut h) = (0.0, [0.0; 6], [[0.0; 6]; 6]);
        if cb.add_to(&z, &mut v, &mut g, &mut h).is_none() {
            return [0.0; 3];
        }
        let c = rest.area * self.model.stiffness;
        let g1: f64 = g.iter().map(|a| a.abs()).sum();
        let hn = h.iter().flatten().map(|a| a * a).sum::<f64>().sqrt();
        [
            c * v.abs(),
            c * g1 * s[1],
            c * (hn * s[1] * s[1] + g1 * s[2]),
        ]
    }

    /// The fold barrier's magnitudes at a sample: k_f A/3 Σ_i (β, |β′| g_θ, β″ g_θ² + |β′| g_θ²) with g_θ =
    /// 1/h_min the natural scale of ∇θ (∇²θ scales as g_θ²); zeros without a barrier.
    fn fold_scales(&self, x: &[f64]) -> [f64; 3] {
        let Some(fold) = &self.model.fold else {
            return [0.0; 3];
        };
        let (rest, flaps) = rest_of(x);
        let g = 1.0 / chain_magnitudes(x).2;
        let c = fold.weight(rest.area);
        let mut out = [0.0; 3];
        let Some(ch) = StrainChain::new(&q_of(x), &rest, flaps) else {
            return out;
        };
        for i in 0..3 {
            if let Some([b, b1, b2]) = ch.hinge_angle(i).and_then(|t| fold.profile(t)) {
                out[0] += c * b;
                out[1] += c * b1.abs() * g;
                out[2] += c * (b2 + b1.abs()) * g * g;
            }
        }
        out
    }
}

impl Differentiable for TriangleCheck {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn dim(&self) -> usize {
        NDOF
    }
    fn n_params(&self) -> usize {
        NPAR
    }
    fn scales_at(&self, x: &[f64]) -> Scales {
        self.energy_scales(x)
    }
    fn input_scale_at(&self, x: &[f64], _i: usize) -> f64 {
        chain_magnitudes(x).2
    }
    fn kink_distance_of(&self, x: &[f64], i: usize) -> f64 {
        let (rest, flaps) = rest_of(x);
        let Some(ch) = StrainChain::new(&q_of(x), &rest, flaps) else {
            return 0.0;
        };
        let b = self.model.bending_scale;
        let s = [1.0, 1.0, 1.0, b, b, b];
        let zs: [f64; 6] = std::array::from_fn(|k| s[k] * ch.z[k]);
        let slope = (0..6).fold(0.0f64, |a, k| a.max((s[k] * ch.jac[k][i]).abs()));
        let mut d = 0.5 * self.model.material.kink_distance(&zs) / slope.max(1e-300);
        // the collapse barrier's threshold J = J_t (C² there)
        if let Some(cb) = &self.model.collapse {
            let z = &ch.z;
            let c = (1.0 - z[1] * z[1]).max(0.0).sqrt();
            let (a, bb) = (1.0 + z[0], 1.0 + z[2]);
            let gj = [bb * c, -a * bb * z[1] / c.max(1e-300), a * c];
            let dj = (0..3).map(|k| gj[k] * ch.jac[k][i]).sum::<f64>().abs();
            d = d.min(0.5 * (a * bb * c - cb.area).abs() / dj.max(1e-300));
        }
        // the fold barrier's threshold |θ| = θ_t (β is C² there; its third derivative jumps)
        if let Some(fold) = &self.model.fold {
            let theta = hinge_angles_reference(&q_of(x), flaps);
            let probe = strain_angles_gradient(x, i);
            for (k, t) in theta.iter().enumerate() {
                if let Some(t) = t {
                    d = d.min(0.5 * (t.abs() - fold.angle).abs() / probe[k].max(1e-300));
                }
            }
        }
        d
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let d: Vec<f64> = x[NDOF..].iter().map(|d| d.re()).collect();
        let rest = RestTriangle::from_inv_dm([[d[0], d[1]], [d[2], d[3]]]);
        let flaps = [d[4] != 0.0, d[5] != 0.0, d[6] != 0.0];
        energy_reference(&self.model, &x[..NDOF], &rest, flaps)
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let (rest, flaps) = rest_of(x);
        let mut g = [0.0; NDOF];
        let mut h = [[0.0; NDOF]; NDOF];
        match self
            .model
            .energy_gradient_hessian(&q_of(x), &rest, flaps, &mut g, &mut h)
        {
            Some((e, _)) => Vgh {
                value: e,
                gradient: DVector::from_row_slice(&g),
                hessian: DMatrix::from_fn(NDOF, NDOF, |i, j| h[i][j]),
            },
            None => Vgh {
                value: f64::NAN,
                gradient: DVector::from_element(NDOF, f64::NAN),
                hessian: DMatrix::from_element(NDOF, NDOF, f64::NAN),
            },
        }
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        let (rest, flaps) = rest_of(x);
        self.model
            .energy(&q_of(x), &rest, flaps)
            .unwrap_or(f64::NAN)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        let (q, rest, flaps) = sample_stencil(rng, i);
        pack(&q, &rest, flaps, [0.0; 6])
    }
}

/// The assembled elastic energy of a small perturbed mesh (all vertices free).
pub struct MeshCheck {
    /// the element model
    pub model: ElementModel,
    /// the mesh's stencils
    pub stencils: Vec<Stencil>,
    /// the rest layout of the vertices (m)
    pub rest: Vec<[f64; 2]>,
    /// the Hessian's sparsity pattern
    pub pattern: Pattern,
}

impl MeshCheck {
    /// A 4 cm × 2 cm perturbed rectangle with 1 cm edges (16 triangles, 15 vertices), fabric axes at 30°. An even
    /// number of cells each way keeps every triangle with at least two flaps: a single flap makes II rank one,
    /// with an eigenvalue exactly on the bending splines' knot at 0, where finite differences do not apply.
    pub fn new(material: &Material) -> Self {
        let mesh = Mesh::rectangle(0.04, 0.02, 0.01, 0.2, 3).expect("valid rectangle");
        let stencils = mesh.stencils(30f64.to_radians()).expect("valid mesh");
        let n = mesh.len();
        let pattern = Pattern::new(&stencils, n, &vec![false; n]);
        MeshCheck {
            model: ElementModel::new(material, &ModelFlags::default(), Psd::None),
            stencils,
            rest: mesh.rest,
            pattern,
        }
    }
}

impl Differentiable for MeshCheck {
    fn name(&self) -> String {
        format!("shell assembled energy ({} triangles)", self.stencils.len())
    }
    fn dim(&self) -> usize {
        3 * self.rest.len()
    }
    fn cases(&self, requested: usize) -> usize {
        requested.min(60)
    }
    fn scales(&self) -> Scales {
        // per-triangle magnitudes at 1 cm edges, summed in norm over √(triangles)
        let (v, ss, sb) = material_magnitudes(&self.model.material);
        let a = self.stencils.iter().map(|s| s.rest.area).sum::<f64>() / self.stencils.len() as f64;
        let rho = 1.0 / 0.01;
        let nt = (self.stencils.len() as f64).sqrt();
        let (gs, gb) = (rho / ss, rho / sb);
        Scales {
            value: nt * nt * a * v,
            gradient: nt * a * v * (gs + gb),
            hessian: nt * a * v * (gs * gs + gb * gb + rho * rho / ss + rho * rho * 10.0 / sb),
        }
    }
    fn input_scale(&self, _i: usize) -> f64 {
        0.002
    }
    fn kink_distance_of(&self, x: &[f64], i: usize) -> f64 {
        let mut d = f64::INFINITY;
        for s in &self.stencils {
            if !(0..6).any(|a| (a < 3 || s.flaps[a - 3]) && 3 * s.v[a] <= i && i < 3 * s.v[a] + 3) {
                continue;
            }
            let Some(ch) = StrainChain::new(&gather(s, x), &s.rest, s.flaps) else {
                return 0.0;
            };
            let slope = (0..6).fold(0.0f64, |acc, k| {
                let mut m: f64 = 0.0;
                for a in 0..6 {
                    if 3 * s.v[a] <= i && i < 3 * s.v[a] + 3 && (a < 3 || s.flaps[a - 3]) {
                        m = m.max(ch.jac[k][3 * a + i - 3 * s.v[a]].abs());
                    }
                }
                acc.max(m)
            });
            d = d.min(0.5 * self.model.material.kink_distance(&ch.z) / slope.max(1e-300));
        }
        d
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        let mut acc = D::from(0.0);
        for s in &self.stencils {
            let q: Vec<D> = (0..NDOF)
                .map(|j| x[3 * s.v[j / 3] + j % 3].clone())
                .collect();
            acc += energy_reference(&self.model, &q, &s.rest, s.flaps);
        }
        acc
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let n = self.dim();
        match crate::shell::assemble::assemble(
            &self.model,
            &self.stencils,
            &self.pattern,
            x,
            true,
            false,
        ) {
            Some(a) => {
                let mut h = DMatrix::zeros(n, n);
                for c in 0..n {
                    for k in self.pattern.lower.col_ptr[c]..self.pattern.lower.col_ptr[c + 1] {
                        let r = self.pattern.lower.row_idx[k];
                        h[(r, c)] = a.values[k];
                        h[(c, r)] = a.values[k];
                    }
                }
                Vgh {
                    value: a.energy,
                    gradient: DVector::from_vec(a.grad),
                    hessian: h,
                }
            }
            None => Vgh {
                value: f64::NAN,
                gradient: DVector::from_element(n, f64::NAN),
                hessian: DMatrix::from_element(n, n, f64::NAN),
            },
        }
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        crate::shell::assemble::energy(&self.model, &self.stencils, x).unwrap_or(f64::NAN)
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        // a smooth random deformation: in-plane stretch/shear, bending into a cylinder-like sheet, noise
        let sx = rng.random_range(0.7..1.6);
        let sy = rng.random_range(0.7..1.6);
        let sh = rng.random_range(-0.4..0.4);
        let k1 = rng.random_range(-40.0..40.0);
        let k2 = rng.random_range(-40.0..40.0);
        let noise = if i.is_multiple_of(2) { 0.0005 } else { 0.002 };
        let rot = random_rotation(rng);
        let shift = if i.is_multiple_of(3) { 2.0 } else { 0.0 };
        let mut x = Vec::with_capacity(self.dim());
        for p in &self.rest {
            let u = sx * p[0] + sh * p[1];
            let v = sy * p[1];
            let w = 0.5 * k1 * u * u + 0.5 * k2 * v * v;
            let pt =
                rot * Vector3::new(
                    u + rng.random_range(-noise..noise),
                    v + rng.random_range(-noise..noise),
                    w + rng.random_range(-noise..noise),
                ) + Vector3::new(shift, -shift, 0.5 * shift);
            x.extend([pt[0], pt[1], pt[2]]);
        }
        x
    }
}

/// The shell rows of the harness (default material; basket1 too when `../shared` is present).
pub fn diff_checks() -> Vec<Box<dyn Check>> {
    let m = default_material();
    let mut v: Vec<Box<dyn Check>> = vec![Box::new(StrainCheck)];
    let flags = ModelFlags {
        bending_scale: 0.7,
        stiffness: 1.3,
        ..ModelFlags::default()
    };
    v.push(Box::new(TriangleCheck {
        name: "shell triangle energy[default]".into(),
        model: ElementModel::new(&m, &flags, Psd::None),
    }));
    // the fold barrier at a lower threshold than its default, so that a third of the sampled hinges (random
    // folds in ±2.9 rad, every fourth stencil at ±170°) are beyond it
    let folded = ModelFlags {
        fold: Some(FoldBarrier {
            angle: 2.0,
            stiffness: 5.0,
        }),
        ..flags
    };
    v.push(Box::new(TriangleCheck {
        name: "shell triangle energy with fold barrier[default]".into(),
        model: ElementModel::new(&m, &folded, Psd::None),
    }));
    // the collapse barrier at J_t = 0.6, beyond which a fifth of the sampled triangles lie (principal stretches
    // in [0.1, 3])
    let collapsing = ModelFlags {
        collapse: Some(CollapseBarrier {
            area: 0.6,
            stiffness: 5.0,
        }),
        ..flags
    };
    v.push(Box::new(TriangleCheck {
        name: "shell triangle energy with collapse barrier[default]".into(),
        model: ElementModel::new(&m, &collapsing, Psd::None),
    }));
    if let Some(dir) = crate::shared_dir() {
        if let Ok(mat) = Material::load(&dir.join("data/hylc2020/materials/basket1.json")) {
            v.push(Box::new(TriangleCheck {
                name: "shell triangle energy[basket1]".into(),
                model: ElementModel::new(&mat, &ModelFlags::default(), Psd::None),
            }));
        }
    }
    v.push(Box::new(MeshCheck::new(&m)));
    v
}
