//! The embedded default material: a synthetic spline material generated from closed-form energy terms.
//!
//! It lets the project run, test and benchmark the macro scale without any external data. It is *not* derived
//! from yarn simulations (the `run` pipeline produces such a material from a generated knit); its terms are
//! smooth, convex in each strain, stiffening in tension and soft in compression, with magnitudes like the original
//! fitted materials (ψ of order 1 J/m² at 50 % stretch, bending of order 0.05 J/m² at 100 m⁻¹). Each term is
//! sampled at its knots with exact values and slopes, in the original's file layout (same knot counts, residual
//! 2D terms that vanish on both axes).

use super::{Hermite1D, Hermite2D, Material, StrainComponent, Term1D, Term2D};
use serde_json::{json, Map};

/// f and f′ of each closed-form 1D term, in normalised units x = z_k/σ_k.
fn term1d(k: usize, x: f64) -> (f64, f64) {
    match k {
        // tension stiffening, soft compression: a (e^{bx} − 1 − bx)/b² + c x²/2
        0 | 2 => {
            let (a, b, c) = if k == 0 {
                (2.0, 3.0, 0.5)
            } else {
                (1.4, 3.0, 0.35)
            };
            let e = (b * x).exp();
            (
                a * (e - 1.0 - b * x) / (b * b) + 0.5 * c * x * x,
                a * (e - 1.0) / b + c * x,
            )
        }
        // shear: symmetric, stiffening
        1 => (0.3 * x * x + 0.5 * x.powi(4), 0.6 * x + 2.0 * x.powi(3)),
        // bending: quadratic with mild stiffening (x = II/σ)
        _ => {
            let a = if k == 3 { 0.05 } else { 0.035 };
            (a * (x * x + 0.25 * x.powi(4)), a * (2.0 * x + x.powi(3)))
        }
    }
}

/// Coupling coefficient c of the residual 2D term g(u, v) = c u² v² e^{u/2 + 3v/10} (vanishes on both axes).
fn coupling(k0: usize, k1: usize) -> f64 {
    match (k0, k1) {
        (0, 2) => 0.3,
        (0, 1) | (1, 2) => 0.2,
        _ => 0.01,
    }
}

/// `n` knots with spacing `h`, `neg` of them below 0 and 0 itself a knot (exactly: multiples of h).
fn knots(neg: usize, h: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| (i as f64 - neg as f64) * h).collect()
}

/// Knot line of strain k in normalised units, 0 always a knot (so every term is exactly 0 at z = 0):
/// in-plane stretch on about [−0.6, 0.9], shear and bending on about [−0.95, 0.95].
fn line(k: usize, n: usize) -> Vec<f64> {
    match (k, n) {
        (0 | 2, 11) => knots(4, 0.15, 11),
        (0 | 2, _) => knots(3, 0.2, n),
        (_, 11) => knots(5, 0.19, 11),
        _ => knots(n / 2, 0.95 / (n / 2) as f64, n),
    }
}

/// The default material (see the module documentation).
pub fn default_material() -> Material {
    let strain_scale = [1.0, 0.75, 1.0, 150.0, 150.0];
    let terms1d = (0..5)
        .map(|k| {
            let t = line(k, 11);
            let (p, m): (Vec<f64>, Vec<f64>) = t.iter().map(|&x| term1d(k, x)).unzip();
            Term1D {
                strain: StrainComponent::ALL[k],
                spline: Hermite1D::new(t, p, m),
            }
        })
        .collect();
    let pairs = [
        (0, 1),
        (0, 2),
        (0, 3),
        (0, 4),
        (1, 2),
        (1, 3),
        (1, 4),
        (2, 3),
        (2, 4),
    ];
    let terms2d = pairs
        .iter()
        .map(|&(k0, k1)| {
            let (tu, tv) = (line(k0, 8), line(k1, 9));
            let c = coupling(k0, k1);
            let mut arrs = [vec![], vec![], vec![], vec![]];
            for &v in &tv {
                for &u in &tu {
                    let e = c * (0.5 * u + 0.3 * v).exp();
                    let (au, av) = (2.0 * u + 0.5 * u * u, 2.0 * v + 0.3 * v * v);
                    arrs[0].push(e * u * u * v * v);
                    arrs[1].push(e * v * v * au);
                    arrs[2].push(e * u * u * av);
                    arrs[3].push(e * au * av);
                }
            }
            let [p, mu, mv, muv] = arrs;
            Term2D {
                strains: [StrainComponent::ALL[k0], StrainComponent::ALL[k1]],
                spline: Hermite2D::new(tu, tv, p, mu, mv, muv),
            }
        })
        .collect();
    let mut extra = Map::new();
    extra.insert("strain shift".into(), json!([1, 0, 1, 0, 0]));
    extra.insert(
        "meta".into(),
        json!({
            "generator": "hylc synthetic default material",
            "note": "closed-form terms sampled at the knots; not derived from yarn simulations"
        }),
    );
    Material {
        density: 0.3,
        strain_scale,
        constant: 0.0,
        terms1d,
        terms2d,
        extra,
    }
}
