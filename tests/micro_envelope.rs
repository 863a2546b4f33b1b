//! Envelope-theorem derivatives of Ψ̄ against central differences of complete re-solves (`06-verification.md`,
//! section 1: tolerance 1e-4 relative), on the generated plain weave (no external data needed).

use hylc::micro::envelope::{parameter_derivatives, strain_derivatives, PARAMETER_NAMES};
use hylc::micro::{MacroStrain, MicroProblem, SolverOptions, Status};
use hylc::pattern::generate::default_pattern;
use hylc::rod::YarnMaterial;

fn problem(material: &YarnMaterial) -> MicroProblem {
    let options = SolverOptions {
        tolerance: 1e-11,
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
        }
    }
}

#[test]
fn parameter_derivatives_match_resolves() {
    let base = YarnMaterial::default();
    let p = problem(&base);
    let z = MacroStrain::in_plane(0.04, 0.05, 0.01);
    let sol = p.solve(&z, None).unwrap();
    let d = parameter_derivatives(&p, &sol).unwrap();
    let psi0 = sol.psi().unwrap();
    for (k, name) in PARAMETER_NAMES.iter().enumerate() {
        let set = |m: &mut YarnMaterial, v: f64| match k {
            0 => m.young = v,
            1 => m.shear = v,
            2 => m.bend_twist_factor = v,
            3 => m.contact_stiffness = v,
            _ => m.radius = v,
        };
        let get = |m: &YarnMaterial| {
            [
                m.young,
                m.shear,
                m.bend_twist_factor,
                m.contact_stiffness,
                p.pattern.radius,
            ][k]
        };
        let v0 = get(&base);
        let h = 1e-4 * v0;
        let at = |v: f64| {
            let mut m = base.clone();
            set(&mut m, v);
            let mut pat = p.pattern.clone();
            if k == 4 {
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
    }
}
