//! Conformance of ψ, ∇ψ, ∇²ψ with the original implementation on its five materials
//! (`../shared/oracles/psi_oracle.json`; `06-verification.md`, 3a). Relative normwise tolerances of issue 2:
//! 1e-10 for ψ and ∇ψ, 1e-8 for ∇²ψ. The oracle README warns of ~1e-6 round-off in one Hessian entry of the
//! original near equal principal curvatures; normwise, every sample (those included) is held to 1e-8.

mod common;

use hylc::material::Material;
use serde_json::Value;

#[test]
fn psi_matches_the_original_on_all_five_materials() {
    let Some(shared) = common::shared_or_skip("psi_matches_the_original_on_all_five_materials")
    else {
        return;
    };
    let text = std::fs::read_to_string(shared.join("oracles/psi_oracle.json")).unwrap();
    let oracle: Value = serde_json::from_str(&text).unwrap();
    let mut report = Vec::new();
    let mut failures = Vec::new();
    for name in ["basket1", "honey1", "rib1", "satin1", "stock1"] {
        let mat =
            Material::load(&shared.join(format!("data/hylc2020/materials/{name}.json"))).unwrap();
        let samples = oracle["materials"][name]["samples"].as_array().unwrap();
        assert_eq!(samples.len(), 200);
        let (mut ev, mut eg, mut eh) = (0.0f64, 0.0f64, 0.0f64);
        for s in samples {
            let z: Vec<f64> = s["z"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let z6 = [z[0], z[1], z[2], z[3], z[4], z[5]];
            let g: Vec<f64> = s["grad"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let h: Vec<f64> = s["hess"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|r| r.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()))
                .collect();
            let r = mat.eval(&z6);
            let hv: Vec<f64> = r.hess.iter().flatten().copied().collect();
            let e_v = common::rel_norm(&[r.value], &[s["psi"].as_f64().unwrap()]);
            let e_g = common::rel_norm(&r.grad, &g);
            let e_h = common::rel_norm(&hv, &h);
            let id = s["id"].as_i64().unwrap();
            if e_v > 1e-10 || e_g > 1e-10 || e_h > 1e-8 {
                failures.push(format!(
                    "{name} #{id} ({}) z={z:?}: psi {e_v:.2e} grad {e_g:.2e} hess {e_h:.2e}",
                    s["kind"]
                ));
            }
            ev = ev.max(e_v);
            eg = eg.max(e_g);
            eh = eh.max(e_h);
        }
        report.push(format!(
            "{name}: max rel err psi {ev:.2e}, grad {eg:.2e}, hess {eh:.2e}"
        ));
    }
    eprintln!("{}", report.join("\n"));
    assert!(
        failures.is_empty(),
        "{} samples off:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
