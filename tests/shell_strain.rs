//! Conformance of the strain chain z(q) with the original macro-scale code (`../shared/oracles/strain_oracle.json`,
//! `06-verification.md` 3a): value, 6×18 Jacobian and 6×18×18 Hessian (each z_k's Hessian is the weighted
//! Hessian with the unit weight e_k) within 1e-10 relative normwise, at the stored positions and translated 2 m
//! from the origin.

mod common;

use hylc::shell::{RestTriangle, StrainChain};
use serde_json::Value;

fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().flat_map(nums).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        _ => panic!("unexpected {v}"),
    }
}

#[test]
fn strain_chain_matches_the_original() {
    let Some(shared) = common::shared_or_skip("strain_chain_matches_the_original") else {
        return;
    };
    let text = std::fs::read_to_string(shared.join("oracles/strain_oracle.json")).unwrap();
    let oracle: Value = serde_json::from_str(&text).unwrap();
    let cases = oracle["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 300);
    let mut worst = [0.0f64; 3];
    let mut failures = Vec::new();
    for shift in [0.0, 2.0] {
        for case in cases {
            let xloc = nums(&case["xloc"]);
            let d = nums(&case["invDm"]);
            let ex = nums(&case["niexists"]);
            let flaps = [ex[0] != 0.0, ex[1] != 0.0, ex[2] != 0.0];
            let rest = RestTriangle::from_inv_dm([[d[0], d[1]], [d[2], d[3]]]);
            let mut q = [0.0; 18];
            for j in 0..18 {
                // a missing flap is stored as the origin: leave it there (it does not enter)
                let flap = j / 3 >= 3 && !flaps[j / 3 - 3];
                q[j] = xloc[j]
                    + if flap {
                        0.0
                    } else {
                        shift * [1.0, -0.6, 0.8][j % 3]
                    };
            }
            let chain = StrainChain::new(&q, &rest, flaps).expect("non-degenerate case");
            let mut z = chain.z;
            z[0] += 1.0;
            z[2] += 1.0;
            let jac: Vec<f64> = chain.jac.iter().flatten().copied().collect();
            let mut hess = Vec::new();
            for k in 0..6 {
                let mut w = [0.0; 6];
                w[k] = 1.0;
                hess.extend(chain.weighted_hessian(&w).iter().flatten().copied());
            }
            let errs = [
                common::rel_norm(&z, &nums(&case["value"])),
                common::rel_norm(&jac, &nums(&case["grad"])),
                common::rel_norm(&hess, &nums(&case["hess"])),
            ];
            for k in 0..3 {
                worst[k] = worst[k].max(errs[k]);
            }
            if errs.iter().any(|&e| e.is_nan() || e > 1e-10) {
                failures.push(format!(
                    "case {} ({}) shift {shift} m: value {:.2e} jacobian {:.2e} hessian {:.2e}",
                    case["id"], case["kind"], errs[0], errs[1], errs[2]
                ));
            }
        }
    }
    eprintln!(
        "strain oracle, 300 cases at the origin and 2 m away: max rel err value {:.2e}, Jacobian {:.2e}, Hessian {:.2e}",
        worst[0], worst[1], worst[2]
    );
    assert!(
        failures.is_empty(),
        "{} cases off:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
