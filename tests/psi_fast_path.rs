//! The fast ψ path (`Material::eval`; `docs/material.md`, "The fast path") equals the formula it implements, to
//! round-off, at strains chosen to reach every branch: in-plane strains on knots, between knots and beyond the knot
//! ranges; bending with equal eigenvalues (umbilic, the polynomial branch at d = 0), both eigenvalues on one piece
//! (polynomial branch), on different pieces (divided differences), an eigenvalue exactly on a knot, and both beyond
//! the knots. Compared against the generic reference `Material::reference` (value in f64; gradient and Hessian by
//! num-dual), and against the sum of its single-term materials (the fast path sums the bending terms of one bending
//! index before one chain rule; a single-term material takes that path with one term).
//!
//! Tolerances are relative and normwise, ‖a − b‖ ≤ tol · (‖b‖ + scale), with the harness's data scales
//! (`hylc::checks::material`): 1e-12 for ψ, ∇ψ and ∇²ψ against the reference, 1e-13 against the term sum.

mod common;

use hylc::checks::material::PsiCheck;
use hylc::diff::{reference_ad, rel_err, Differentiable};
use hylc::material::synthetic::default_material;
use hylc::material::{Material, PsiVgh};

/// Nudge a point on a knot by 1e-10 (relative) to either side: the fast path normalises z/σ by a reciprocal, the
/// reference by a division, and a 1-ulp difference exactly on a knot would pick different pieces (f″ jumps there).
fn on_knot(x: f64, side: usize) -> f64 {
    let eps = 1e-10 * (1.0 + x.abs());
    if side.is_multiple_of(2) {
        x + eps
    } else {
        x - eps
    }
}

/// Knots (see [`on_knot`]), cell midpoints and points beyond each end of a knot line.
fn knot_points(t: &[f64]) -> Vec<f64> {
    let (lo, hi) = (t[0], t[t.len() - 1]);
    let mut v: Vec<f64> = t.iter().enumerate().map(|(i, &x)| on_knot(x, i)).collect();
    v.extend(t.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    v.extend([
        lo - 0.5 * (hi - lo),
        hi + 0.5 * (hi - lo),
        lo - 3.0,
        hi + 3.0,
    ]);
    v
}

/// Normalised knot points of strain k's 1D term (or a generic spread if the material has none).
fn points(m: &Material, k: usize) -> Vec<f64> {
    m.terms1d
        .iter()
        .find(|t| t.strain.index() == k)
        .map(|t| knot_points(&t.spline.t))
        .unwrap_or_else(|| vec![-1.5, -0.5, -0.1, 0.0, 0.2, 0.6, 1.5])
}

/// Knot lines (normalised) of every term argument that uses strain k: in-plane k directly, bending k = 3, 4 through
/// the eigenvalues of L/σ_k.
fn lines(m: &Material, k: usize) -> Vec<&[f64]> {
    let mut v: Vec<&[f64]> = Vec::new();
    for t in &m.terms1d {
        if t.strain.index() == k {
            v.push(&t.spline.t);
        }
    }
    for t in &m.terms2d {
        if t.strains[0].index() == k {
            v.push(&t.spline.tu);
        }
        if t.strains[1].index() == k {
            v.push(&t.spline.tv);
        }
    }
    v
}

/// A knot of `lines` within 1e-12 (relative) of x, if any.
fn knot_near(lines: &[&[f64]], x: f64) -> Option<f64> {
    lines
        .iter()
        .flat_map(|l| l.iter())
        .copied()
        .find(|&t| (x - t).abs() <= 1e-12 * (1.0 + t.abs()))
}

/// Move z off exact knot hits that [`on_knot`] did not plan (a strain on a knot of one term can fall on a knot of
/// another term's grid): the in-plane component, or both bending diagonals (which shifts both eigenvalues), by
/// 1e-10 relative.
fn off_exact_knots(m: &Material, z: &mut [f64; 6]) {
    let sc = m.strain_scale;
    for k in 0..3 {
        if let Some(t) = knot_near(&lines(m, k), z[k] / sc[k]) {
            z[k] = sc[k] * on_knot(t, 0);
        }
    }
    for _ in 0..10 {
        let mut moved = false;
        for kb in [3, 4] {
            let s = sc[kb];
            let mean = (z[3] + z[5]) / (2.0 * s);
            let d = (((z[3] - z[5]) / (2.0 * s)).powi(2) + (z[4] / s).powi(2)).sqrt();
            // the mean too: below the eigenvalue gap D_MIN its piece is the one used
            for lambda in [mean + d, mean - d, mean] {
                if let Some(t) = knot_near(&lines(m, kb), lambda) {
                    let shift = s * (on_knot(t, 0) - t);
                    z[3] += shift;
                    z[5] += shift;
                    moved = true;
                }
            }
        }
        if !moved {
            return;
        }
    }
    panic!("could not move {z:?} off the knots");
}

/// The test strains of material `m` (see the module documentation).
fn strains(m: &Material) -> Vec<[f64; 6]> {
    let sc = m.strain_scale;
    let inplane: Vec<Vec<f64>> = (0..3).map(|k| points(m, k)).collect();
    let bend = points(m, 3);
    let t3: Vec<f64> = m
        .terms1d
        .iter()
        .find(|t| t.strain.index() == 3)
        .map(|t| t.spline.t.clone())
        .unwrap_or_else(|| vec![-1.0, 0.0, 1.0]);
    let mut zs = Vec::new();
    let mut pick = |i: usize, mean: f64, half_gap: f64, angle: f64| {
        // in-plane components cycle through their point lists at different strides
        let ip: [f64; 3] = std::array::from_fn(|k| {
            let p = &inplane[k];
            p[(i * (2 * k + 1) + k) % p.len()] * sc[k]
        });
        // L/σ₃ = mean I + half_gap [[cos 2θ, sin 2θ], [sin 2θ, −cos 2θ]]
        let (s2, c2) = (2.0 * angle).sin_cos();
        let s = sc[3];
        let mut z = [
            ip[0],
            ip[1],
            ip[2],
            s * (mean + half_gap * c2),
            s * half_gap * s2,
            s * (mean - half_gap * c2),
        ];
        off_exact_knots(m, &mut z);
        zs.push(z);
    };
    let mut i = 0;
    for &mean in &bend {
        // umbilic, then growing gaps: same piece, then (mostly) different pieces
        for gap in [0.0, 0.02, 0.2, 0.7] {
            pick(i, mean, gap, 0.37 * i as f64);
            i += 1;
        }
    }
    // an eigenvalue exactly on a knot, the other on another piece
    for w in t3.windows(2) {
        let mean = 0.5 * (w[0] + w[1]) - 0.01;
        pick(i, mean, on_knot(w[1], i) - mean, 0.0);
        i += 1;
    }
    // nearly umbilic inside a cell (the polynomial branch with d > 0; below and above D_MIN = 1e-9)
    for w in t3.windows(2) {
        for gap in [1e-10, 1e-6] {
            pick(i, w[0] + 0.3 * (w[1] - w[0]), gap, 1.1 * i as f64);
            i += 1;
        }
    }
    zs
}

fn flat(r: &PsiVgh) -> (Vec<f64>, Vec<f64>) {
    (r.grad.to_vec(), r.hess.iter().flatten().copied().collect())
}

/// Largest (value, gradient, Hessian) errors of `eval` against the reference over the test strains.
fn errors_against_reference(name: &str, m: &Material) -> [f64; 3] {
    let check = PsiCheck {
        name: name.into(),
        material: m.clone(),
    };
    let mut worst = [0.0f64; 3];
    for z in strains(m) {
        let s = check.scales_at(&z);
        let fast = m.eval(&z);
        let value = m.reference::<f64>(&z);
        let ad = reference_ad(&check, &z);
        let (g, h) = flat(&fast);
        let e = [
            rel_err(&[fast.value], &[value], s.value),
            rel_err(&g, ad.gradient.as_slice(), s.gradient),
            // nalgebra stores column-major; the Hessian is symmetric
            rel_err(&h, ad.hessian.as_slice(), s.hessian),
        ];
        for (w, x) in worst.iter_mut().zip(e) {
            *w = w.max(x);
        }
        assert!(
            e[0] <= 1e-12 && e[1] <= 1e-12 && e[2] <= 1e-12,
            "{name} at z = {z:?}: errors (value, gradient, Hessian) {e:?}"
        );
    }
    worst
}

/// `eval` of the whole material equals C₀ plus the sum of `eval` over single-term materials.
fn check_term_sum(name: &str, m: &Material) {
    let check = PsiCheck {
        name: name.into(),
        material: m.clone(),
    };
    let mut singles: Vec<Material> = m
        .terms1d
        .iter()
        .map(|t| PsiCheck::only(m, &[t.strain.index()], &[]))
        .collect();
    singles.extend(
        m.terms2d
            .iter()
            .map(|t| PsiCheck::only(m, &[], &[(t.strains[0].index(), t.strains[1].index())])),
    );
    assert_eq!(singles.len(), m.terms1d.len() + m.terms2d.len());
    for z in strains(m) {
        let s = check.scales_at(&z);
        let all = m.eval(&z);
        let mut sum = PsiVgh {
            value: m.constant,
            grad: [0.0; 6],
            hess: [[0.0; 6]; 6],
        };
        for one in &singles {
            let r = one.eval(&z);
            sum.value += r.value;
            for i in 0..6 {
                sum.grad[i] += r.grad[i];
                for j in 0..6 {
                    sum.hess[i][j] += r.hess[i][j];
                }
            }
        }
        let (ga, ha) = flat(&all);
        let (gs, hs) = flat(&sum);
        let e = [
            rel_err(&[all.value], &[sum.value], s.value),
            rel_err(&ga, &gs, s.gradient),
            rel_err(&ha, &hs, s.hessian),
        ];
        assert!(
            e.iter().all(|&x| x <= 1e-13),
            "{name} at z = {z:?}: whole vs sum of terms {e:?}"
        );
        for i in 0..6 {
            for j in 0..6 {
                assert_eq!(all.hess[i][j], all.hess[j][i], "{name}: Hessian symmetric");
            }
        }
    }
}

fn originals() -> Vec<(String, Material)> {
    let Some(shared) = common::shared_or_skip("psi fast path on the original materials") else {
        return Vec::new();
    };
    ["basket1", "stock1"]
        .iter()
        .map(|name| {
            let path = shared.join(format!("data/hylc2020/materials/{name}.json"));
            (name.to_string(), Material::load(&path).unwrap())
        })
        .collect()
}

#[test]
fn fast_path_equals_reference_on_every_branch() {
    let mut mats = vec![("default".to_string(), default_material())];
    mats.extend(originals());
    for (name, m) in &mats {
        let n = strains(m).len();
        assert!(n > 100, "{name}: {n} strains");
        let w = errors_against_reference(name, m);
        eprintln!(
            "{name}: {n} strains, max errors vs reference: value {:.1e}, gradient {:.1e}, Hessian {:.1e}",
            w[0], w[1], w[2]
        );
    }
}

#[test]
fn fast_path_equals_the_sum_of_its_terms() {
    let mut mats = vec![("default".to_string(), default_material())];
    mats.extend(originals());
    for (name, m) in &mats {
        check_term_sum(name, m);
    }
}
