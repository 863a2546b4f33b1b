//! The tangent of the fit (`docs/sensitivities.md`, "The tangent of the fit"): `fit_material_tangent` against
//! central differences of complete refits, `fit_material` at Ψ̄ ± h Ψ̄̇ (and σ ± h σ̇), on synthetic samples of a
//! generated plan (a known material's ψ with 2 % deterministic noise and a failed sample every 37), for the
//! default options and `covering` (the settings of `hylc run`), with finite-difference slopes and with slopes
//! from the stresses; and the kink report, empty on these cases and naming a clamp a case sits on.

use hylc::fit::model::{fit_material, strain6, FitOptions};
use hylc::fit::{fit_material_tangents, KinkReport, KinkRule, RecordTangent, SlopeSource};
use hylc::material::coefficients::{Coefficient, MaterialGradient};
use hylc::material::synthetic::default_material;
use hylc::material::Material;
use hylc::sample::{Plan, Record, SampleStart, SampleStatus};

/// 30 samples per 1D range, 8 × 8 per 2D plane.
fn plan() -> Plan {
    Plan {
        count_1d: 30,
        count_2d: 8,
        ..Plan::default()
    }
}

/// Records of `plan` whose Ψ̄ is the default material's ψ times 1 + 0.02 sin(1.7 i) (no two samples tie) and whose
/// stresses are its gradient; every 37th sample failed.
fn records(plan: &Plan) -> Vec<Record> {
    let truth = default_material();
    plan.samples()
        .iter()
        .map(|s| {
            let e = truth.eval(&strain6(&s.z));
            let ok = s.index % 37 != 5;
            let noise = 1.0 + 0.02 * (1.7 * s.index as f64).sin();
            let g = e.grad;
            Record {
                id: s.id.clone(),
                index: s.index,
                z: s.z,
                psi: ok.then_some(e.value * noise),
                stress: ok.then_some([Some(g[0]), Some(g[1]), Some(g[2]), Some(g[3]), Some(g[5])]),
                status: if ok {
                    SampleStatus::Converged
                } else {
                    SampleStatus::MaxSteps
                },
                error: None,
                steps: 1,
                gradient_norm: Some(0.0),
                time: 0.0,
                start: SampleStart::Cold,
                problem: "0000000000000000".into(),
                starts: vec![],
                kept: None,
                crossings: None,
                dpsi_dtheta: None,
                dstress_dtheta: None,
            }
        })
        .collect()
}

/// A deterministic uniform number in [−1, 1) (a 64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// Random tangents relative to the values: Ψ̄̇ = u Ψ̄ and σ̇ = u' σ with u, u' uniform in [−1, 1).
fn tangents(records: &[Record], seed: u64) -> Vec<RecordTangent> {
    let mut rng = Lcg(seed);
    records
        .iter()
        .map(|r| RecordTangent {
            psi: rng.next() * r.psi.unwrap_or(0.0),
            stress: r.stress.map(|s| s.map(|v| v.map(|v| v * rng.next()))),
        })
        .collect()
}

/// The records moved by h along the tangents.
fn moved(records: &[Record], t: &[RecordTangent], h: f64) -> Vec<Record> {
    records
        .iter()
        .zip(t)
        .map(|(r, t)| {
            let mut r = r.clone();
            r.psi = r.psi.map(|p| p + h * t.psi);
            if let (Some(s), Some(ts)) = (r.stress.as_mut(), t.stress) {
                for (v, dv) in s.iter_mut().zip(ts) {
                    if let (Some(v), Some(dv)) = (v.as_mut(), dv) {
                        *v += h * dv;
                    }
                }
            }
            r
        })
        .collect()
}

/// The coefficients of a material, in layout order.
fn coefficients(m: &Material) -> Vec<f64> {
    m.coefficients()
        .into_iter()
        .map(|c| m.coefficient(c))
        .collect()
}

/// The kinds of coefficients compared: values (f₀, p), slopes (m, pˣ, pʸ), twists (pˣʸ).
const KINDS: [&str; 3] = ["values", "slopes", "twists"];

fn kind(c: &Coefficient) -> usize {
    match *c {
        Coefficient::Constant => 0,
        Coefficient::Term1D { slope, .. } => usize::from(slope),
        Coefficient::Term2D { array, .. } => [0, 1, 1, 2][array],
    }
}

/// Steps of the central differences: the refits' rounding, amplified by 1/h, limits the small ones; a decision
/// switching within h Ψ̄̇ (a kink between 1e-9 and h away) spoils the large ones.
const STEPS: [f64; 4] = [1e-3, 1e-4, 1e-5, 1e-6];

/// `jvp` against the central differences D_h = (c(Ψ̄ + h Ψ̄̇) − c(Ψ̄ − h Ψ̄̇)) / 2h of refits, per kind of coefficient:
/// (coefficients compared, worst over them of the best relative error min_h |jvp − D_h| / |D_h|) over those with
/// |D_1e-4| ≥ 1e-6 of their term's largest, and the worst absolute error of the others in units of that largest.
fn compare(
    plan: &Plan,
    records: &[Record],
    opts: &FitOptions,
    t: &[RecordTangent],
    jvp: &MaterialGradient,
    like: &Material,
) -> ([(usize, f64); 3], f64) {
    let fit = |h: f64| {
        let f = fit_material(plan, &moved(records, t, h), 0.2, Default::default(), opts).unwrap();
        coefficients(&f.material)
    };
    let fds: Vec<Vec<f64>> = STEPS
        .iter()
        .map(|&h| {
            let (plus, minus) = (fit(h), fit(-h));
            plus.iter()
                .zip(&minus)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect()
        })
        .collect();
    let coeffs = like.coefficients();
    let term_of = |c: &Coefficient| format!("{c}").split(']').next().map(String::from);
    let mut scale = std::collections::HashMap::new();
    for (c, d) in coeffs.iter().zip(&fds[1]) {
        let s = scale.entry(term_of(c)).or_insert(0.0f64);
        *s = s.max(d.abs());
    }
    let mut out = [(0, 0.0f64); 3];
    let mut small = 0.0f64;
    for (n, c) in coeffs.iter().enumerate() {
        let (j, s, d) = (jvp.get(*c), scale[&term_of(c)], fds[1][n]);
        if d.abs() < 1e-6 * s {
            let e = fds
                .iter()
                .map(|f| (j - f[n]).abs())
                .fold(f64::INFINITY, f64::min);
            small = small.max(e / s);
            continue;
        }
        let e = fds
            .iter()
            .map(|f| (j - f[n]).abs() / f[n].abs())
            .fold(f64::INFINITY, f64::min);
        let o = &mut out[kind(c)];
        if e > o.1.max(1e-7) {
            let all: Vec<String> = fds.iter().map(|f| format!("{:e}", f[n])).collect();
            println!("  {c}: jvp {j:e}, D {}: {e:.2e}", all.join(", "));
        }
        o.0 += 1;
        o.1 = o.1.max(e);
    }
    (out, small)
}

/// JVP against central differences of refits for two random tangents of `opts`, as configured and with slopes by
/// central differences of step 0.05 of the knot spacing instead of 1e-3; asserts the kink report is empty.
fn check(name: &str, opts: &FitOptions, seeds: [u64; 2]) {
    let wide = FitOptions {
        fd_step: 0.05,
        ..opts.clone()
    };
    // the fit's slopes are central differences of g with step 1e-3 of the knot spacing, its twists second
    // differences: they carry the rounding of g amplified ~10³ and ~10⁷ times, and the refits' differences
    // amplify it again by 1/h, so the reference itself is good to ~1e-5 (slopes) and ~1e-3 (twists) only
    check_one(name, opts, seeds, [5e-6, 5e-4, 5e-3]);
    // with step 0.05 the reference is accurate for every kind
    check_one(&format!("{name}, fd step 0.05"), &wide, seeds, [5e-6; 3]);
}

/// `tols`: the largest relative error allowed per kind of coefficient (values, slopes, twists).
fn check_one(name: &str, opts: &FitOptions, seeds: [u64; 2], tols: [f64; 3]) {
    let plan = plan();
    let records = records(&plan);
    let ts: Vec<Vec<RecordTangent>> = seeds.iter().map(|&s| tangents(&records, s)).collect();
    let t0 = std::time::Instant::now();
    let plain = fit_material(&plan, &records, 0.2, Default::default(), opts).unwrap();
    let t_fit = t0.elapsed().as_secs_f64();
    let t0 = std::time::Instant::now();
    let (fit, grads, kinks) =
        fit_material_tangents(&plan, &records, 0.2, Default::default(), opts, &ts).unwrap();
    let t_tan = t0.elapsed().as_secs_f64();
    assert_eq!(
        coefficients(&fit.material),
        coefficients(&plain.material),
        "the tangent's fit is the fit"
    );
    println!(
        "{name}: fit {:.1} ms, fit + {} tangent passes {:.1} ms",
        1e3 * t_fit,
        ts.len(),
        1e3 * t_tan
    );
    assert_no_kinks(name, &kinks);
    for (t, g) in ts.iter().zip(&grads) {
        let (c, small) = compare(&plan, &records, opts, t, g, &fit.material);
        for (k, (n, worst)) in KINDS.iter().zip(c) {
            println!("{name}: {k}: {n} compared, worst relative error {worst:.2e}");
        }
        println!("{name}: the negligible ones within {small:.2e} of their term's largest");
        for (k, ((_, worst), tol)) in c.iter().zip(tols).enumerate() {
            assert!(*worst <= tol, "{name}: {}: {worst:e} > {tol:e}", KINDS[k]);
        }
        assert!(small <= 1e-9, "{name}: {small:e}");
    }
}

fn assert_no_kinks(name: &str, kinks: &KinkReport) {
    for k in &kinks.kinks {
        println!("{name}: kink {k}");
    }
    assert!(kinks.is_empty(), "{name}: {} kinks", kinks.kinks.len());
}

#[test]
fn tangent_of_the_default_fit_matches_refits() {
    check("default", &FitOptions::default(), [1, 2]);
}

#[test]
fn tangent_of_the_covering_fit_matches_refits() {
    check("covering", &FitOptions::covering(), [3, 4]);
}

#[test]
fn tangent_with_stress_slopes_matches_refits() {
    let stress = |o: FitOptions| FitOptions {
        slopes: SlopeSource::Stress,
        ..o
    };
    check(
        "default, stress slopes",
        &stress(FitOptions::default()),
        [5, 6],
    );
    check(
        "covering, stress slopes",
        &stress(FitOptions::covering()),
        [7, 8],
    );
}

/// pˣ_min set to the secant of the s_x term's first cell right of the knot 0 puts the quasi-convexification of
/// the knot after it exactly on its clamp p = max(p, p(0) + Δt pˣ_min); the report names it.
#[test]
fn a_fit_on_a_clamp_reports_it() {
    let plan = plan();
    let records = records(&plan);
    let opts = FitOptions::default();
    let fit = fit_material(&plan, &records, 0.2, Default::default(), &opts).unwrap();
    let sp = &fit.material.terms1d[0].spline;
    let i0 = fit.report.terms1d[0].i_min;
    let b = i0 + 1;
    let on_clamp = FitOptions {
        min_slope: (sp.p[b] - sp.p[i0]) / (sp.t[b] - sp.t[i0]),
        ..opts
    };
    let ts = vec![tangents(&records, 9)];
    let (_, _, kinks) =
        fit_material_tangents(&plan, &records, 0.2, Default::default(), &on_clamp, &ts).unwrap();
    for k in &kinks.kinks {
        println!("on a clamp: kink {k}");
    }
    assert!(
        kinks.kinks.iter().any(|k| k.term == "1D term 0 (s_x)"
            && k.rule == KinkRule::QuasiConvexValue
            && k.site == format!("knot {b}")),
        "the clamp at knot {b} of s_x is not reported"
    );
    // two samples sharing the largest |Ψ̄| of the s_x range: ε of the symlog is a max over them
    let mut tied = records.clone();
    let range = plan.range_1d(0);
    let top = range
        .clone()
        .max_by(|&a, &b| {
            tied[a]
                .psi
                .unwrap_or(0.0)
                .total_cmp(&tied[b].psi.unwrap_or(0.0))
        })
        .unwrap();
    let other = if top == range.start {
        range.start + 1
    } else {
        range.start
    };
    tied[other].psi = tied[top].psi;
    let ts = vec![tangents(&tied, 10)];
    let (_, _, kinks) =
        fit_material_tangents(&plan, &tied, 0.2, Default::default(), &opts, &ts).unwrap();
    assert!(
        kinks
            .kinks
            .iter()
            .any(|k| k.term == "1D term 0 (s_x)" && k.rule == KinkRule::SymlogScale),
        "the tie of the largest |Ψ̄| is not reported: {kinks:?}"
    );
}
