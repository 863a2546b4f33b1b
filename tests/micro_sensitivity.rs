//! Equilibrium sensitivities dy*/dθ to the yarn parameters (`docs/yarn-parameters.md`, "Equilibrium sensitivities
//! to the yarn parameters") against central differences of complete re-solves (relative ≤ 1e-4, normwise over the
//! unknowns with the angles as r θ), on the generated plain weave (no external data needed), at zero strain and at
//! an in-plane strain.

use hylc::generate::default_pattern;
use hylc::micro::sensitivity::{equilibrium_sensitivities, YarnParameter};
use hylc::micro::{MacroStrain, MicroProblem, SolverOptions, Status};
use hylc::rod::YarnMaterial;
use std::time::Instant;

fn problem(material: &YarnMaterial) -> MicroProblem {
    // force test only (the decrement test is looser than 1e-11 k_s on this small tile)
    let options = SolverOptions {
        tolerance: 1e-11,
        decrement_tolerance: 0.0,
        ..Default::default()
    };
    MicroProblem::new(default_pattern("plain").unwrap(), material, options)
}

/// ‖a − b‖ / (‖b‖ + floor) and ‖b‖, with the angle entries (from 3n on) weighted by r.
fn rel(a: &[f64], b: &[f64], n: usize, r: f64, floor: f64) -> (f64, f64) {
    let w = |i: usize| if i < 3 * n { 1.0 } else { r };
    let num: f64 = (0..a.len()).map(|i| ((a[i] - b[i]) * w(i)).powi(2)).sum();
    let den: f64 = (0..a.len()).map(|i| (b[i] * w(i)).powi(2)).sum();
    (num.sqrt() / (den.sqrt() + floor), den.sqrt())
}

#[test]
fn equilibrium_sensitivities_match_resolves() {
    // a contact radius factor other than 1 so that f and r are distinguishable
    let base = YarnMaterial {
        contact_radius_factor: 1.02,
        ..Default::default()
    };
    let p = problem(&base);
    let n = p.pattern.len();
    let r = p.pattern.radius;
    let mut worst: f64 = 0.0;
    for z in [MacroStrain::ZERO, MacroStrain::in_plane(0.04, 0.05, 0.01)] {
        let sol = p.solve(&z, None).unwrap();
        assert_eq!(sol.status, Status::Converged, "{z}");
        let t = Instant::now();
        let dy = equilibrium_sensitivities(&p, &sol).unwrap();
        let time = t.elapsed().as_secs_f64();
        assert_eq!(dy.len(), YarnParameter::ALL.len());
        for (k, param) in YarnParameter::ALL.iter().enumerate() {
            let v0 = param.get(&p.material);
            let h = 1e-4 * v0;
            let at = |v: f64| {
                let mut m = base.clone();
                param.set(&mut m, v);
                let mut pat = p.pattern.clone();
                if *param == YarnParameter::Radius {
                    pat.radius = v;
                }
                let q = MicroProblem::new(pat, &m, p.options.clone());
                let s = q.solve(&z, Some(&sol.state)).unwrap();
                assert_eq!(s.status, Status::Converged, "{z} {}", param.name());
                s.state.y
            };
            let (yp, ym) = (at(v0 + h), at(v0 - h));
            let fd: Vec<f64> = yp
                .iter()
                .zip(&ym)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            // floor: a response of 1e-6 r to a relative change of the parameter by 1 (a symmetric state may
            // not respond to a parameter at all, e.g. to G without twist)
            let (e, size) = rel(&dy[k], &fd, n, r, 1e-6 * r / v0);
            eprintln!(
                "{z}: dy*/d{}: ‖θ dy/dθ‖ = {:.3e} r, relative error {e:.2e}",
                param.name(),
                size * v0 / r
            );
            assert!(
                e <= 1e-4,
                "{z}: dy*/d{}: relative error {e:.2e} against re-solves",
                param.name()
            );
            worst = worst.max(e);
        }
        eprintln!("{z}: six sensitivities in {time:.3} s (one factorisation)");
    }
    eprintln!("dy*/dθ against re-solves: worst relative error {worst:.2e}");
}
