//! The deformed mid-surface φ, its frame field R and the tile transforms (`docs/micro-solver.md`, section 1).
//!
//! With a = 1 + s_x, b = 1 + s_y, c = s_a:
//! - `BendY` (rulings along ξ₁, curvature k = Π₁₁ along ξ₂; the plane φ = F ξ when k = 0), α' = b√(1−c²),
//!   ω = k/α': φ = (a ξ₁ + b c ξ₂, α' ξ₂ sinc(ω ξ₂), ½ α' ω ξ₂² sinc²(ω ξ₂/2)), R = rotation about e₁ by ω ξ₂;
//! - `BendX` (rulings along ξ₂, curvature k = Π₀₀ along ξ₁), α = a√(1−c²), β = a c, ω = k/α:
//!   φ = (α ξ₁ sinc(ω ξ₁), β ξ₁ + b ξ₂, ½ α ω ξ₁² sinc²(ω ξ₁/2)), R = rotation about e₂ by −ω ξ₁.
//!
//! The normal is n = R e₃. Both maps satisfy φ(ξ + Δ) = R(Δ) φ(ξ) + φ(Δ), R(ξ + Δ) = R(Δ) R(ξ): the tile
//! transform of offset o is T_o x = R(Δ_o) x + φ(Δ_o) with Δ_o = (o₁p₁, o₂p₂). Everything is generic over the
//! scalar so that derivatives with respect to the strain come from num-dual (the envelope-theorem stress) and the
//! harness can differentiate through the map; sinc uses its Taylor series near 0, so k → 0 is smooth.

use super::strain::{Family, MacroStrain};
use crate::periodic::TileTransforms;
use crate::real::Real;
use nalgebra::{Matrix3, Vector3};

/// sinc(x) = sin(x)/x, by its series for |x| < 1e-2 (truncation below 1e-21).
pub fn sinc<D: Real>(x: &D) -> D {
    if x.re().abs() < 1e-2 {
        let x2 = x.clone() * x.clone();
        D::from(1.0) - x2.clone() * (1.0 / 6.0) + x2.clone() * x2.clone() * (1.0 / 120.0)
            - x2.clone() * x2.clone() * x2 * (1.0 / 5040.0)
    } else {
        x.sin() / x.clone()
    }
}

/// One of the closed-form surface maps for a strain, generic over the scalar.
#[derive(Clone, Debug)]
pub struct SurfaceMap<D> {
    /// the map's family
    pub family: Family,
    a: D,
    b: D,
    /// √(1 − c²)
    sq: D,
    c: D,
    /// the active curvature (Π₀₀ for `BendX`, Π₁₁ for `BendY`)
    k: D,
}

impl<D: Real> SurfaceMap<D> {
    /// The map of `family` for the strain components `z` (the inactive curvature is ignored: callers validate).
    pub fn new(z: &[D; 5], family: Family) -> Self {
        let c = z[1].clone();
        let sq = (D::from(1.0) - c.clone() * c.clone()).sqrt();
        SurfaceMap {
            family,
            a: z[0].clone() + 1.0,
            b: z[2].clone() + 1.0,
            sq,
            c,
            k: match family {
                Family::BendX => z[3].clone(),
                Family::BendY => z[4].clone(),
            },
        }
    }

    /// φ(ξ) and R(ξ) (rows of the rotation matrix).
    pub fn frame(&self, xi: [f64; 2]) -> ([D; 3], [[D; 3]; 3]) {
        let zero = D::from(0.0);
        let one = D::from(1.0);
        match self.family {
            Family::BendX => {
                let alpha = self.a.clone() * self.sq.clone();
                let beta = self.a.clone() * self.c.clone();
                let omega = self.k.clone() / alpha.clone();
                let x = omega.clone() * xi[0];
                let half = sinc(&(x.clone() * 0.5));
                let phi = [
                    alpha.clone() * xi[0] * sinc(&x),
                    beta * xi[0] + self.b.clone() * xi[1],
                    alpha * omega * (0.5 * xi[0] * xi[0]) * half.clone() * half,
                ];
                let (s, co) = (x.sin(), x.cos());
                let r = [
                    [co.clone(), zero.clone(), -s.clone()],
                    [zero.clone(), one, zero.clone()],
                    [s, zero, co],
                ];
                (phi, r)
            }
            Family::BendY => {
                let alpha = self.b.clone() * self.sq.clone();
                let omega = self.k.clone() / alpha.clone();
                let x = omega.clone() * xi[1];
                let half = sinc(&(x.clone() * 0.5));
                let phi = [
                    self.a.clone() * xi[0] + self.b.clone() * self.c.clone() * xi[1],
                    alpha.clone() * xi[1] * sinc(&x),
                    alpha * omega * (0.5 * xi[1] * xi[1]) * half.clone() * half,
                ];
                let (s, co) = (x.sin(), x.cos());
                let r = [
                    [one, zero.clone(), zero.clone()],
                    [zero.clone(), co.clone(), -s.clone()],
                    [zero, s, co],
                ];
                (phi, r)
            }
        }
    }

    /// The world position φ(ξ) + h n(ξ) + R(ξ) ũ of a point with reference coordinates (ξ₁, ξ₂, h) and local
    /// displacement ũ.
    pub fn point(&self, xi: [f64; 2], h: f64, u: &[D; 3]) -> [D; 3] {
        let (phi, r) = self.frame(xi);
        std::array::from_fn(|i| {
            phi[i].clone()
                + r[i][2].clone() * h
                + r[i][0].clone() * u[0].clone()
                + r[i][1].clone() * u[1].clone()
                + r[i][2].clone() * u[2].clone()
        })
    }
}

/// Plain-f64 helpers.
impl SurfaceMap<f64> {
    /// The map for a validated strain.
    pub fn of(z: &MacroStrain, family: Family) -> Self {
        SurfaceMap::new(&z.0, family)
    }

    /// φ(ξ) and R(ξ) as nalgebra values.
    pub fn frame_na(&self, xi: [f64; 2]) -> (Vector3<f64>, Matrix3<f64>) {
        let (phi, r) = self.frame(xi);
        (Vector3::from(phi), Matrix3::from_fn(|i, j| r[i][j]))
    }

    /// The rigid transform T_o = (R(Δ_o), φ(Δ_o)) of offset `o` for periods `p`.
    pub fn transform(&self, o: [i32; 2], p: [f64; 2]) -> (Matrix3<f64>, Vector3<f64>) {
        let (phi, r) = self.frame_na([o[0] as f64 * p[0], o[1] as f64 * p[1]]);
        (r, phi)
    }

    /// The table of tile transforms.
    pub fn transforms(&self, p: [f64; 2]) -> TileTransforms {
        TileTransforms::from_fn(|o| self.transform(o, p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::{first_derivative, Dual64};

    fn maps() -> Vec<(MacroStrain, Family)> {
        vec![
            (MacroStrain::in_plane(0.1, 0.3, -0.2), Family::BendY),
            (MacroStrain::new(0.1, 0.3, -0.2, 40.0, 0.0), Family::BendX),
            (MacroStrain::new(-0.1, -0.4, 0.2, 0.0, -25.0), Family::BendY),
            (MacroStrain::new(0.05, 0.2, 0.1, 1e-9, 0.0), Family::BendX),
        ]
    }

    /// ∂φ/∂ξ by central differences at ξ.
    fn tangents(m: &SurfaceMap<f64>, xi: [f64; 2]) -> [Vector3<f64>; 2] {
        std::array::from_fn(|d| {
            let h = 1e-6;
            let (mut p, mut q) = (xi, xi);
            p[d] += h;
            q[d] -= h;
            (m.frame_na(p).0 - m.frame_na(q).0) / (2.0 * h)
        })
    }

    #[test]
    fn first_and_second_fundamental_forms() {
        for (z, fam) in maps() {
            let m = SurfaceMap::of(&z, fam);
            let ii = z.first_fundamental_form();
            for xi in [[0.0, 0.0], [3e-3, -2e-3], [-7e-3, 5e-3]] {
                let [t1, t2] = tangents(&m, xi);
                let got = [[t1.dot(&t1), t1.dot(&t2)], [t2.dot(&t1), t2.dot(&t2)]];
                for i in 0..2 {
                    for j in 0..2 {
                        assert!(
                            (got[i][j] - ii[i][j]).abs() < 1e-8,
                            "{z} I {got:?} vs {ii:?}"
                        );
                    }
                }
                // normal = R e₃ is perpendicular to both tangents and R is a rotation
                let (_, r) = m.frame_na(xi);
                let n = r.column(2).into_owned();
                assert!(n.dot(&t1).abs() < 1e-8 && n.dot(&t2).abs() < 1e-8);
                assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-14);
                assert!((r.determinant() - 1.0).abs() < 1e-14);
                // second fundamental form by second differences along ξ₁ and ξ₂
                let h = 1e-4;
                for d in 0..2 {
                    let mut p = xi;
                    p[d] += h;
                    let mut q = xi;
                    q[d] -= h;
                    let f = |x| m.frame_na(x).0;
                    let dd = (f(p) - 2.0 * f(xi) + f(q)) / (h * h);
                    let want = if d == 0 { z.0[3] } else { z.0[4] };
                    assert!(
                        (dd.dot(&n) - want).abs() < 1e-5 * (1.0 + want.abs()),
                        "{z} II{d}{d} {} vs {want}",
                        dd.dot(&n)
                    );
                }
            }
        }
    }

    #[test]
    fn tile_transforms_map_the_surface_onto_itself() {
        let p = [8e-3, 6e-3];
        for (z, fam) in maps() {
            let m = SurfaceMap::of(&z, fam);
            for o in [[1, 0], [0, 1], [-1, 1], [2, -1]] {
                let (rt, tt) = m.transform(o, p);
                for xi in [[0.0, 0.0], [2e-3, -1e-3]] {
                    let (phi, r) = m.frame_na(xi);
                    let shifted = [xi[0] + o[0] as f64 * p[0], xi[1] + o[1] as f64 * p[1]];
                    let (phi2, r2) = m.frame_na(shifted);
                    assert!((rt * phi + tt - phi2).norm() < 1e-15, "{z} {o:?}");
                    assert!((rt * r - r2).norm() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn bending_maps_tend_to_the_plane() {
        let z0 = MacroStrain::in_plane(0.1, 0.3, -0.2);
        let plane = SurfaceMap::of(&z0, Family::BendY);
        for k in [1e-9, -1e-6] {
            let zy = MacroStrain::new(0.1, 0.3, -0.2, 0.0, k);
            let my = SurfaceMap::of(&zy, Family::BendY);
            let xi = [4e-3, -3e-3];
            // the map leaves the plane by ½ k ξ₂² (to first order)
            let d = (my.frame_na(xi).0 - plane.frame_na(xi).0).norm();
            assert!(
                d <= 0.5 * k.abs() * xi[1] * xi[1] * (1.0 + 1e-6) + 1e-18,
                "{d}"
            );
        }
        // the curvature derivative of φ is finite and continuous through k = 0 (sinc series)
        let d = |k: f64| {
            first_derivative(
                |kk: Dual64| {
                    let z = [0.1, 0.3, -0.2, 0.0].map(Dual64::from);
                    let zz = [z[0], z[1], z[2], kk, Dual64::from(0.0)];
                    SurfaceMap::new(&zz, Family::BendX).frame([5e-3, 1e-3]).0[2]
                },
                k,
            )
            .1
        };
        let (a, b) = (d(0.0), d(1e-6));
        assert!(a.is_finite() && (a - b).abs() < 1e-10, "{a} {b}");
        // ∂φ_z/∂k at k = 0 is ξ₁²/2
        assert!((a - 0.5 * 25e-6).abs() < 1e-15, "{a}");
    }
}
