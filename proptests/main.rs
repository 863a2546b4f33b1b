//! Property tests. Rods (`rod.rs`), contact (`contact.rs`) and the micro solver
//! (`micro.rs`) have their own
//! modules; this file holds those of the spline material (`docs/material.md`): Hermite interpolation at
//! knots, C¹ continuity across knots and at the extrapolation boundary, invariance of the bending terms under the
//! order of the eigenpairs, ψ as the sum of its parts, finite values and derivatives at umbilic points and for
//! |II| up to 1e4.

mod contact;
mod fit;
mod fit2d;
mod fit2d_compression;
mod micro;
mod rod;

use hylc::material::hermite::{Hermite1D, Hermite2D};
use hylc::material::synthetic::default_material;
use hylc::material::Material;
use proptest::prelude::*;

/// Strictly increasing knots with gaps in [0.05, 1].
fn knots(n: std::ops::Range<usize>) -> impl Strategy<Value = Vec<f64>> {
    (-2.0..0.0f64, prop::collection::vec(0.05..1.0f64, n)).prop_map(|(start, gaps)| {
        let mut t = vec![start];
        for g in gaps {
            t.push(t.last().unwrap() + g);
        }
        t
    })
}

fn spline1d() -> impl Strategy<Value = Hermite1D> {
    knots(1..10).prop_flat_map(|t| {
        let n = t.len();
        (
            Just(t),
            prop::collection::vec(-5.0..5.0f64, n),
            prop::collection::vec(-5.0..5.0f64, n),
        )
            .prop_map(|(t, p, m)| Hermite1D::new(t, p, m))
    })
}

fn spline2d() -> impl Strategy<Value = Hermite2D> {
    (knots(1..6), knots(1..6)).prop_flat_map(|(tu, tv)| {
        let n = tu.len() * tv.len();
        let v = || prop::collection::vec(-3.0..3.0f64, n);
        (Just(tu), Just(tv), v(), v(), v(), v())
            .prop_map(|(tu, tv, p, mu, mv, muv)| Hermite2D::new(tu, tv, p, mu, mv, muv))
    })
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn hermite1d_interpolates_and_is_c1_at_every_knot(s in spline1d()) {
        let n = s.t.len();
        for i in 0..n {
            let x = s.t[i];
            // pieces on both sides of knot i: piece i is left of it (exterior for i = 0), piece i + 1 right of it
            for piece in [i, i + 1] {
                let d = s.derivs_on(piece, x);
                prop_assert!(close(d[0], s.p[i], 1e-12), "value at knot {i} from piece {piece}: {} vs {}", d[0], s.p[i]);
                prop_assert!(close(d[1], s.m[i], 1e-11), "slope at knot {i} from piece {piece}: {} vs {}", d[1], s.m[i]);
            }
        }
        // linear beyond the ends with the end slopes
        let (a, b) = (s.t[0], s.t[n - 1]);
        prop_assert!(close(s.eval2(a - 1.5)[0], s.p[0] - 1.5 * s.m[0], 1e-12));
        prop_assert!(close(s.eval2(b + 2.0)[0], s.p[n - 1] + 2.0 * s.m[n - 1], 1e-12));
        prop_assert_eq!(s.eval2(b + 2.0)[2], 0.0);
    }

    #[test]
    fn hermite2d_interpolates_and_is_c1_across_grid_lines(s in spline2d(), fu in 0.0..1.0f64, fv in 0.0..1.0f64) {
        let (nu, nv) = (s.tu.len(), s.tv.len());
        // interpolation at every node, from all four adjacent pieces (exterior ones included)
        for iv in 0..nv {
            for iu in 0..nu {
                let k = iv * nu + iu;
                let (u, v) = (s.tu[iu], s.tv[iv]);
                for pu in [iu, iu + 1] {
                    let at = s.at_u_piece(pu, u);
                    for pv in [iv, iv + 1] {
                        let d = at.derivs_on(pv, v);
                        prop_assert!(close(d[0][0], s.p[k], 1e-11));
                        prop_assert!(close(d[1][0], s.mu[k], 1e-10));
                        prop_assert!(close(d[0][1], s.mv[k], 1e-10));
                        prop_assert!(close(d[1][1], s.muv[k], 1e-10));
                    }
                }
            }
        }
        // C¹ across every u grid line at an arbitrary v (inside or outside the v range)
        let v = s.tv[0] - 1.0 + fv * (s.tv[nv - 1] - s.tv[0] + 2.0);
        let pv = s.v_piece(v);
        for iu in 0..nu {
            let u = s.tu[iu];
            let (l, r) = (s.at_u_piece(iu, u).derivs_on(pv, v), s.at_u_piece(iu + 1, u).derivs_on(pv, v));
            prop_assert!(close(l[0][0], r[0][0], 1e-11) && close(l[1][0], r[1][0], 1e-10) && close(l[0][1], r[0][1], 1e-10),
                "u line {iu} at v = {v}: {l:?} vs {r:?}");
        }
        // and across every v grid line at an arbitrary u
        let u = s.tu[0] - 1.0 + fu * (s.tu[nu - 1] - s.tu[0] + 2.0);
        let at = s.at_u(u);
        for iv in 0..nv {
            let v = s.tv[iv];
            let (l, r) = (at.derivs_on(iv, v), at.derivs_on(iv + 1, v));
            prop_assert!(close(l[0][0], r[0][0], 1e-11) && close(l[1][0], r[1][0], 1e-10) && close(l[0][1], r[0][1], 1e-10),
                "v line {iv} at u = {u}: {l:?} vs {r:?}");
        }
    }

    #[test]
    fn bending_term_is_invariant_under_the_eigenpair_order(
        s in spline1d(), l00 in -3.0..3.0f64, l01 in -3.0..3.0f64, l11 in -3.0..3.0f64, x_bending in any::<bool>()
    ) {
        // explicit spectral formula Σᵢ f(λᵢ) (vᵢ)ₖ² with the pairs in either order, against the divided-difference form
        let mut m = default_material();
        let kb = if x_bending { 3 } else { 4 };
        m.constant = 0.0;
        m.terms2d.clear();
        m.terms1d.retain(|t| t.strain.index() == kb);
        m.terms1d[0].spline = s.clone();
        m.strain_scale[kb] = 1.0;
        let psi = m.eval(&[0.0, 0.0, 0.0, l00, l01, l11]).value;
        let e = nalgebra::Matrix2::new(l00, l01, l01, l11).symmetric_eigen();
        let comp = if x_bending { 0 } else { 1 };
        let f = |i: usize| s.eval2(e.eigenvalues[i])[0] * e.eigenvectors[(comp, i)].powi(2);
        let (a, b) = (f(0) + f(1), f(1) + f(0));
        let gap = (e.eigenvalues[0] - e.eigenvalues[1]).abs();
        prop_assume!(gap > 1e-6);
        let scale = s.p.iter().fold(0.0f64, |acc, p| acc.max(p.abs())) + s.m.iter().fold(0.0f64, |acc, p| acc.max(p.abs()));
        prop_assert!((a - psi).abs() <= 1e-11 * scale * (1.0 + l00.abs() + l01.abs() + l11.abs()), "{a} vs {psi}");
        prop_assert!((b - psi).abs() <= 1e-11 * scale * (1.0 + l00.abs() + l01.abs() + l11.abs()), "{b} vs {psi}");
        // swapping the axes (L00 ↔ L11) exchanges the 00 and 11 components, i.e. the eigenvector roles
        let mut swapped = m.clone();
        swapped.terms1d[0].strain = hylc::strain::StrainComponent::ALL[7 - kb];
        swapped.strain_scale[7 - kb] = 1.0;
        let psi_swapped = swapped.eval(&[0.0, 0.0, 0.0, l11, l01, l00]).value;
        prop_assert!(close(psi, psi_swapped, 1e-12), "{psi} vs {psi_swapped}");
    }

    #[test]
    fn psi_is_the_sum_of_its_parts(z in prop::array::uniform6(-1.0..1.0f64), c in 1.0..300.0f64) {
        let m = default_material();
        let z = [z[0], z[1], z[2], c * z[3], c * z[4], c * z[5]];
        let whole = m.eval(&z);
        let mut sum = m.constant;
        let mut g = [0.0; 6];
        for part in parts(&m) {
            let r = part.eval(&z);
            sum += r.value;
            for k in 0..6 { g[k] += r.grad[k]; }
        }
        prop_assert!(close(whole.value, sum, 1e-13));
        for k in 0..6 { prop_assert!(close(whole.grad[k], g[k], 1e-13)); }
    }

    #[test]
    fn psi_is_finite_and_exact_at_umbilic_points(
        s in prop::array::uniform3(-0.9..2.0f64), k in -1e4..1e4f64, eps in 1e-9..1e-5f64
    ) {
        let m = default_material();
        let z = [s[0], s[1].clamp(-0.99, 0.99), s[2], k, 0.0, k];
        let r = m.eval(&z);
        prop_assert!(r.value.is_finite());
        prop_assert!(r.grad.iter().chain(r.hess.iter().flatten()).all(|x| x.is_finite()));
        // continuity of the Hessian into the umbilic point from a nearby non-umbilic one (same pieces)
        let zn = [z[0], z[1], z[2], k + eps * k.abs().max(1.0), eps * k.abs().max(1.0), k];
        if m.kink_distance(&z) > 1e-3 * k.abs().max(1.0) {
            let rn = m.eval(&zn);
            let hmax = r.hess.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
            for i in 0..6 {
                for j in 0..6 {
                    prop_assert!((r.hess[i][j] - rn.hess[i][j]).abs() <= 1e-3 * hmax + 1e-12,
                        "H[{i}][{j}] {} vs {}", r.hess[i][j], rn.hess[i][j]);
                }
            }
        }
    }

    #[test]
    fn psi_is_finite_for_curvatures_up_to_1e4(
        s in prop::array::uniform3(-0.9..2.0f64), l in prop::array::uniform3(-1e4..1e4f64)
    ) {
        for m in [default_material()].iter().chain(originals().iter()) {
            let r = m.eval(&[s[0], s[1].clamp(-0.99, 0.99), s[2], l[0], l[1], l[2]]);
            prop_assert!(r.value.is_finite());
            prop_assert!(r.grad.iter().chain(r.hess.iter().flatten()).all(|x| x.is_finite()));
        }
    }
}

/// Single-term materials of `m` (C₀ = 0).
fn parts(m: &Material) -> Vec<Material> {
    let mut out = Vec::new();
    for t in &m.terms1d {
        let mut p = m.clone();
        p.constant = 0.0;
        p.terms1d.retain(|u| u.strain == t.strain);
        p.terms2d.clear();
        out.push(p);
    }
    for t in &m.terms2d {
        let mut p = m.clone();
        p.constant = 0.0;
        p.terms1d.clear();
        p.terms2d.retain(|u| u.strains == t.strains);
        out.push(p);
    }
    out
}

/// The original materials when `../shared` is present (none otherwise: the property still runs on the default).
fn originals() -> Vec<Material> {
    static CACHE: std::sync::OnceLock<Vec<Material>> = std::sync::OnceLock::new();
    CACHE
        .get_or_init(|| {
            let Some(dir) = hylc::shared_dir() else {
                eprintln!(
                    "note: ../shared not found; finiteness checked on the default material only"
                );
                return Vec::new();
            };
            ["basket1", "honey1", "rib1", "satin1", "stock1"]
                .iter()
                .filter_map(|n| {
                    Material::load(&dir.join(format!("data/hylc2020/materials/{n}.json"))).ok()
                })
                .collect()
        })
        .clone()
}
