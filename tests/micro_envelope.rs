//! Envelope-theorem derivatives of Ψ̄ against central differences of complete re-solves (tolerance 1e-4 relative;
//! `docs/derivative-harness.md`), on the generated plain weave (no external data needed).

use hylc::generate::default_pattern;
use hylc::micro::envelope::{parameter_derivatives, strain_derivatives, PARAMETER_NAMES};
use hylc::micro::sensitivity::YarnParameter;
use hylc::micro::{MacroStrain, MicroProblem, SolverOptions, Status};
use hylc::rod::YarnMaterial;

fn problem(material: &YarnMaterial) -> MicroProblem {
    // force test only (the decrement test is looser than 1e-11 k_s on this small tile)
    let options = SolverOptions {
        tolerance: 1e-11,
        decrement_tolerance: 0.0,
        ..Default::default()
    };
    MicroProblem::new(default_pattern("plain").unwrap(), material, options)
}

fn psi(p: &MicroProblem, z: &MacroStrain, warm: &hylc::micro::MicroState) -> f64 {
    let s = p.solve(z, Some(warm)).unwrap();
    assert_eq!(s.status, Status::Converged, "{z}");
    s.psi().unwrap()
}

/// Relative error of `a` against `b` with a floor `scale`.
fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / (b.abs() + scale)
}

#[test]
fn strain_derivatives_match_resolves() {
    let m = YarnMaterial::default();
    let p = problem(&m);
    let mut worst: f64 = 0.0;
    for z in [
        MacroStrain::in_plane(0.03, 0.1, -0.02),
        MacroStrain::new(0.03, 0.1, -0.02, 40.0, 0.0),
        MacroStrain::new(0.03, -0.1, 0.02, 0.0, -30.0),
    ] {
        let sol = p.solve(&z, None).unwrap();
        assert_eq!(sol.status, Status::Converged);
        let d = strain_derivatives(&p, &sol.state).unwrap();
        let psi0 = sol.psi().unwrap();
        for j in 0..5 {
            let Some(an) = d[j] else {
                continue;
            };
            let h = if j < 3 { 1e-4 } else { 1e-1 };
            let mut zp = z;
            zp.0[j] += h;
            let mut zm = z;
            zm.0[j] -= h;
            // the other bending component at zero curvature: one-sided families are fine (both reach Π = ±h)
            let fd = (psi(&p, &zp, &sol.state) - psi(&p, &zm, &sol.state)) / (2.0 * h);
            let scale = psi0.abs() * if j < 3 { 1.0 } else { 0.01 };
            let e = rel(an, fd, scale);
            assert!(
                e <= 1e-4,
                "{z} component {j}: envelope {an:e} vs re-solve FD {fd:e} (rel {e:.2e})"
            );
            worst = worst.max(e);
        }
    }
    eprintln!("∂Ψ̄/∂z against re-solves: worst relative error {worst:.2e}");
}

#[test]
fn parameter_derivatives_match_resolves() {
    let base = YarnMaterial::default();
    let p = problem(&base);
    let z = MacroStrain::in_plane(0.04, 0.05, 0.01);
    let sol = p.solve(&z, None).unwrap();
    let d = parameter_derivatives(&p, &sol).unwrap();
    let psi0 = sol.psi().unwrap();
    let mut worst: f64 = 0.0;
    for (k, name) in PARAMETER_NAMES.iter().enumerate() {
        let param = YarnParameter::ALL[k];
        assert_eq!(param.name(), *name);
        let v0 = param.get(&p.material);
        let h = 1e-4 * v0;
        let at = |v: f64| {
            let mut m = base.clone();
            param.set(&mut m, v);
            let mut pat = p.pattern.clone();
            if param == YarnParameter::Radius {
                pat.radius = v;
            }
            let q = MicroProblem::new(pat, &m, p.options.clone());
            let s = q.solve(&z, Some(&sol.state)).unwrap();
            assert_eq!(s.status, Status::Converged);
            s.psi().unwrap()
        };
        let fd = (at(v0 + h) - at(v0 - h)) / (2.0 * h);
        let e = rel(d[k], fd, psi0.abs() / v0);
        assert!(
            e <= 1e-4,
            "∂Ψ̄/∂{name}: envelope {:e} vs re-solve FD {fd:e} (rel {e:.2e})",
            d[k]
        );
        worst = worst.max(e);
    }
    eprintln!("∂Ψ̄/∂(Y, G, γ, k_c, f, r) against re-solves: worst relative error {worst:.2e}");
}

#[test]
fn second_derivatives_and_shape_sensitivity_match_resolves() {
    use hylc::micro::envelope::strain_stiffness;
    let m = YarnMaterial::default();
    let p = problem(&m);
    let (mut worst_h, mut worst_y): (f64, f64) = (0.0, 0.0);
    for z in [
        MacroStrain::in_plane(0.03, 0.1, -0.02),
        MacroStrain::new(0.03, 0.1, -0.02, 40.0, 0.0),
    ] {
        let sol = p.solve(&z, None).unwrap();
        let st = strain_stiffness(&p, &sol.state).unwrap();
        let stress = |s: &hylc::micro::MicroState| strain_derivatives(&p, s).unwrap();
        let hmax = st.hessian.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for (col, &j) in st.components.iter().enumerate() {
            // steps large enough that the re-solves' own accuracy (force test 1e-11 k_s) does not dominate
            let h = if j < 3 { 1e-3 } else { 0.5 };
            let solve = |sign: f64| {
                let mut zz = z;
                zz.0[j] += sign * h;
                let s = p.solve(&zz, Some(&sol.state)).unwrap();
                assert_eq!(s.status, Status::Converged);
                s
            };
            let (sp, sm) = (solve(1.0), solve(-1.0));
            let (dp, dm) = (stress(&sp.state), stress(&sm.state));
            for (row, &i) in st.components.iter().enumerate() {
                let fd = (dp[i].unwrap() - dm[i].unwrap()) / (2.0 * h);
                let an = st.hessian[(row, col)];
                let e = (an - fd).abs() / (fd.abs() + 1e-3 * hmax);
                assert!(
                    e <= 1e-4,
                    "{z} d²Ψ̄/dz{i}dz{j}: {an:e} vs re-solve FD {fd:e} (rel {e:.2e})"
                );
                worst_h = worst_h.max(e);
            }
            let fd: Vec<f64> = sp
                .state
                .y
                .iter()
                .zip(&sm.state.y)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            let diff = fd
                .iter()
                .zip(&st.dy[col])
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            let norm = fd.iter().map(|a| a * a).sum::<f64>().sqrt();
            let nu = 3 * p.pattern.len();
            let part = |lo: usize, hi: usize| {
                let d = (lo..hi)
                    .map(|i| (fd[i] - st.dy[col][i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let n = (lo..hi).map(|i| fd[i].powi(2)).sum::<f64>().sqrt();
                (d, n)
            };
            assert!(
                diff <= 1e-4 * norm,
                "{z} dy*/dz{j}: rel {:.2e}; displacements (err, norm) {:?}, angles {:?}",
                diff / norm,
                part(0, nu),
                part(nu, fd.len())
            );
            worst_y = worst_y.max(diff / norm);
        }
    }
    eprintln!(
        "d²Ψ̄/dz² and dy*/dz against re-solves: worst relative errors {worst_h:.2e}, {worst_y:.2e}"
    );
}
