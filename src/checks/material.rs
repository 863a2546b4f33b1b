//! Harness rows for the material (`docs/derivative-harness.md`, section 1): the 1D and 2D Hermite splines, the bending
//! matrix-function terms (1D and 2D, both components) and ψ itself.
//!
//! Scales (the `scale` of the tolerance test, `docs/derivative-harness.md`): the magnitude of the function's spline data,
//! V = |C₀| + Σ_terms max|p| (J/m²), because round-off in evaluating a piecewise polynomial is proportional to its
//! coefficients, not to its value (a residual 2D term is ~1e-8 near its axes while its data are ~1e-2). Gradient
//! and Hessian scales are V/σ and V/σ² with σ the smallest strain scale among the inputs the function uses.

use crate::diff::{Check, Differentiable, Scales, Vgh};
use crate::material::synthetic::default_material;
use crate::material::{Hermite1D, Hermite2D, Material};
use crate::real::Real;
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Scales for spline data of magnitude `v` on inputs of scale `sigma` (see the module documentation).
fn data_scales(v: f64, sigma: f64) -> Scales {
    Scales {
        value: v,
        gradient: v / sigma,
        hessian: v / (sigma * sigma),
    }
}

fn max_abs(p: &[f64]) -> f64 {
    p.iter().fold(0.0, |a, x| a.max(x.abs()))
}

fn nearest(t: &[f64], x: f64) -> f64 {
    t.iter()
        .map(|k| (k - x).abs())
        .fold(f64::INFINITY, f64::min)
}

/// A spline on a non-polynomial function so that every cell has a different cubic.
pub fn test_spline1d() -> Hermite1D {
    let t: Vec<f64> = vec![-0.9, -0.55, -0.3, -0.1, 0.0, 0.15, 0.4, 0.6, 0.95];
    let f = |x: f64| (1.3 * x).exp() * (3.0 * x).sin() + x * x;
    let df = |x: f64| (1.3 * x).exp() * (1.3 * (3.0 * x).sin() + 3.0 * (3.0 * x).cos()) + 2.0 * x;
    let p = t.iter().map(|&x| f(x)).collect();
    let m = t.iter().map(|&x| df(x)).collect();
    Hermite1D::new(t, p, m)
}

/// A bicubic spline on a non-polynomial function with a non-uniform grid.
pub fn test_spline2d() -> Hermite2D {
    let tu = vec![-0.8, -0.4, -0.1, 0.0, 0.3, 0.7, 0.9];
    let tv = vec![-0.95, -0.5, 0.0, 0.2, 0.45, 0.95];
    let g = |u: f64, v: f64| (0.7 * u - 0.4 * v).exp() * (1.0 + (2.0 * u * v).sin());
    // derivatives by hand: g = e·(1 + sin w), w = 2uv
    let gd = |u: f64, v: f64| {
        let e = (0.7 * u - 0.4 * v).exp();
        let (s, c) = (2.0 * u * v).sin_cos();
        let gu = e * (0.7 * (1.0 + s) + 2.0 * v * c);
        let gv = e * (-0.4 * (1.0 + s) + 2.0 * u * c);
        let guv = e
            * (-0.28 * (1.0 + s) + 0.7 * 2.0 * u * c - 0.4 * 2.0 * v * c + 2.0 * c
                - 4.0 * u * v * s);
        (gu, gv, guv)
    };
    let mut arrs = [vec![], vec![], vec![], vec![]];
    for &v in &tv {
        for &u in &tu {
            let (gu, gv, guv) = gd(u, v);
            arrs[0].push(g(u, v));
            arrs[1].push(gu);
            arrs[2].push(gv);
            arrs[3].push(guv);
        }
    }
    let [p, mu, mv, muv] = arrs;
    Hermite2D::new(tu, tv, p, mu, mv, muv)
}

struct Spline1DCheck(Hermite1D);

impl Differentiable for Spline1DCheck {
    fn name(&self) -> String {
        "hermite1d".into()
    }
    fn dim(&self) -> usize {
        1
    }
    fn scales(&self) -> Scales {
        data_scales(max_abs(&self.0.p), 1.0)
    }
    fn input_scale(&self, _i: usize) -> f64 {
        0.1
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        self.0.reference(&x[0])
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let [f, f1, f2] = self.0.eval2(x[0]);
        Vgh {
            value: f,
            gradient: DVector::from_element(1, f1),
            hessian: DMatrix::from_element(1, 1, f2),
        }
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        nearest(&self.0.t, x[0])
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        // inside the knots, then beyond them on either side
        vec![match i % 3 {
            0 => rng.random_range(-0.9..0.95),
            1 => rng.random_range(-3.0..-0.9),
            _ => rng.random_range(0.95..3.0),
        }]
    }
}

struct Spline2DCheck(Hermite2D);

impl Differentiable for Spline2DCheck {
    fn name(&self) -> String {
        "hermite2d".into()
    }
    fn dim(&self) -> usize {
        2
    }
    fn scales(&self) -> Scales {
        data_scales(max_abs(&self.0.p), 1.0)
    }
    fn input_scale(&self, _i: usize) -> f64 {
        0.1
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        self.0.reference(&x[0], &x[1])
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let [f, fu, fv, fuu, fuv, fvv] = self.0.eval2(x[0], x[1]);
        Vgh {
            value: f,
            gradient: DVector::from_vec(vec![fu, fv]),
            hessian: DMatrix::from_row_slice(2, 2, &[fuu, fuv, fuv, fvv]),
        }
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        nearest(&self.0.tu, x[0]).min(nearest(&self.0.tv, x[1]))
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        // inside; u beyond; v beyond; both beyond (corner extrapolation)
        let inside_u = |r: &mut ChaCha8Rng| r.random_range(-0.8..0.9);
        let inside_v = |r: &mut ChaCha8Rng| r.random_range(-0.95..0.95);
        let out = |r: &mut ChaCha8Rng| {
            let x: f64 = r.random_range(1.0..2.5);
            if r.random_bool(0.5) {
                x
            } else {
                -x
            }
        };
        match i % 4 {
            0 => vec![inside_u(rng), inside_v(rng)],
            1 => vec![out(rng), inside_v(rng)],
            2 => vec![inside_u(rng), out(rng)],
            _ => vec![out(rng), out(rng)],
        }
    }
}

/// ψ (or a single term of it, as a material holding only that term) under the harness.
pub struct PsiCheck {
    /// the check's name
    pub name: String,
    /// the material (or a material holding only the checked term)
    pub material: Material,
}

impl PsiCheck {
    /// A material with only the selected terms of `m` (C₀ = 0), for single-term rows.
    pub fn only(m: &Material, one: &[usize], two: &[(usize, usize)]) -> Material {
        let mut s = m.clone();
        s.constant = 0.0;
        s.terms1d.retain(|t| one.contains(&t.strain.index()));
        s.terms2d
            .retain(|t| two.contains(&(t.strains[0].index(), t.strains[1].index())));
        s
    }
}

fn arr6(x: &[f64]) -> [f64; 6] {
    [x[0], x[1], x[2], x[3], x[4], x[5]]
}

impl Differentiable for PsiCheck {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn dim(&self) -> usize {
        6
    }
    fn scales(&self) -> Scales {
        let m = &self.material;
        let mut v = m.constant.abs();
        let mut sigma = f64::INFINITY;
        for t in &m.terms1d {
            v += max_abs(&t.spline.p);
            sigma = sigma.min(m.strain_scale[t.strain.index()]);
        }
        for t in &m.terms2d {
            v += max_abs(&t.spline.p);
            for c in t.strains {
                sigma = sigma.min(m.strain_scale[c.index()]);
            }
        }
        data_scales(v, sigma)
    }
    fn input_scale(&self, i: usize) -> f64 {
        if i < 3 {
            0.1
        } else {
            10.0
        }
    }
    fn reference<D: Real>(&self, x: &[D]) -> D {
        self.material.reference(x)
    }
    fn fast(&self, x: &[f64]) -> Vgh {
        let r = self.material.eval(&arr6(x));
        Vgh {
            value: r.value,
            gradient: DVector::from_row_slice(&r.grad),
            hessian: DMatrix::from_fn(6, 6, |i, j| r.hess[i][j]),
        }
    }
    fn fast_value(&self, x: &[f64]) -> f64 {
        self.material.value(&arr6(x))
    }
    fn kink_distance(&self, x: &[f64]) -> f64 {
        self.material.kink_distance(&arr6(x))
    }
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
        sample_strain(&self.material, rng, i)
    }
}

/// Random strains for ψ: inside the knot ranges, beyond them (s down to −0.9 and up to 2, |s_a| to 0.99,
/// |II| to 1e3), exactly umbilic (II₀₁ = 0, II₀₀ = II₁₁), nearly umbilic, diagonal (II₀₁ = 0), and
/// II₀₀ = II₁₁ with II₀₁ ≠ 0.
pub fn sample_strain(m: &Material, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64> {
    let inside = |r: &mut ChaCha8Rng, k: usize| {
        let (lo, hi) = m.knot_range(k);
        let (lo, hi) = if lo.is_finite() {
            (lo, hi)
        } else {
            (-0.5, 0.5)
        };
        r.random_range(0.98 * lo..0.98 * hi)
    };
    let mut z: Vec<f64> = (0..6).map(|k| inside(rng, [0, 1, 2, 3, 3, 4][k])).collect();
    match i % 6 {
        0 => {}
        1 => {
            z[0] = rng.random_range(-0.9..2.0);
            z[1] = rng.random_range(-0.99..0.99);
            z[2] = rng.random_range(-0.9..2.0);
            for zk in z.iter_mut().skip(3) {
                *zk = rng.random_range(-1e3..1e3);
            }
        }
        2 => {
            z[4] = 0.0;
            z[5] = z[3];
        }
        3 => {
            let eps = 10f64.powf(rng.random_range(-9.0..-4.0));
            z[4] = eps * rng.random_range(-1.0..1.0);
            z[5] = z[3] + eps * rng.random_range(-1.0..1.0);
        }
        4 => z[4] = 0.0,
        _ => z[5] = z[3],
    }
    z
}

/// A single-term harness row: name, 1D terms kept, 2D terms kept.
type TermRow<'a> = (&'a str, &'a [usize], &'a [(usize, usize)]);

/// The material rows of the harness: splines, bending terms and ψ of the embedded default material, and ψ of
/// the original materials when `../shared` is present.
pub fn diff_checks() -> Vec<Box<dyn Check>> {
    let m = default_material();
    let mut v: Vec<Box<dyn Check>> = vec![
        Box::new(Spline1DCheck(test_spline1d())),
        Box::new(Spline2DCheck(test_spline2d())),
    ];
    let rows: [TermRow; 4] = [
        ("bending1d [f3(L)]00", &[3], &[]),
        ("bending1d [f4(L)]11", &[4], &[]),
        ("bending2d [f03(u,L)]00", &[], &[(0, 3)]),
        ("bending2d [f14(u,L)]11", &[], &[(1, 4)]),
    ];
    for (name, one, two) in rows {
        v.push(Box::new(PsiCheck {
            name: name.into(),
            material: PsiCheck::only(&m, one, two),
        }));
    }
    // basis functions φ_j = ∂ψ/∂c_j of single coefficients (`material::coefficients`): their unit materials
    use crate::material::coefficients::Coefficient;
    let basis = [
        (
            "basis phi[f0 p5]",
            Coefficient::Term1D {
                term: 0,
                slope: false,
                index: 5,
            },
        ),
        (
            "basis phi[f3 p5]",
            Coefficient::Term1D {
                term: 3,
                slope: false,
                index: 5,
            },
        ),
        (
            "basis phi[f03 p36]",
            Coefficient::Term2D {
                term: 2,
                array: 0,
                index: 36,
            },
        ),
    ];
    for (name, c) in basis {
        v.push(Box::new(PsiCheck {
            name: name.into(),
            material: m.unit_material(c),
        }));
    }
    v.push(Box::new(PsiCheck {
        name: "psi[default]".into(),
        material: m,
    }));
    if let Some(dir) = crate::shared_dir() {
        for name in ["basket1", "stock1"] {
            let path = dir
                .join("data/hylc2020/materials")
                .join(format!("{name}.json"));
            if let Ok(mat) = Material::load(&path) {
                v.push(Box::new(PsiCheck {
                    name: format!("psi[{name}]"),
                    material: mat,
                }));
            }
        }
    }
    v
}
