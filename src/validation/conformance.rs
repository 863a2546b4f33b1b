//! Validation against the original method's data (`docs/results.md`, "Validation against the original"): the
//! measurements behind `hylc validate` and the conformance tests. Each function reads `../shared` (the caller
//! passes the folder) and returns numbers; the callers decide what passes.

use super::ValidationError;
use crate::material::Material;
use crate::shell::{RestTriangle, StrainChain};
use serde::Serialize;
use serde_json::Value;
use std::path::Path;

/// The five original materials, by file stem.
pub const ORIGINAL_MATERIALS: [&str; 5] = ["basket1", "honey1", "rib1", "satin1", "stock1"];

/// ‖a − b‖ / ‖b‖ (normwise relative error).
pub fn rel_norm(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt();
    let n: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
    d / n.max(f64::MIN_POSITIVE)
}

/// The numbers of a (nested) JSON array or number of the file `path`, flattened.
fn nums(v: &Value, path: &Path) -> Result<Vec<f64>, ValidationError> {
    match v {
        Value::Array(a) => Ok(a
            .iter()
            .map(|x| nums(x, path))
            .collect::<Result<Vec<_>, _>>()?
            .concat()),
        Value::Number(n) => Ok(vec![n.as_f64().unwrap_or(f64::NAN)]),
        _ => Err(data(path, format!("expected numbers, got {v}"))),
    }
}

fn data(path: &Path, message: String) -> ValidationError {
    ValidationError::Data {
        path: path.to_path_buf(),
        message,
    }
}

/// A JSON file, with the file named in the error.
pub fn read_json(path: &Path) -> Result<Value, ValidationError> {
    let text = std::fs::read_to_string(path).map_err(|source| ValidationError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|source| ValidationError::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// Largest relative normwise errors of value, first and second derivatives over a set of oracle cases, and the
/// cases beyond the given tolerances.
#[derive(Clone, Debug, Serialize)]
pub struct Conformance {
    /// the checked quantity's name
    pub name: String,
    /// oracle cases compared
    pub cases: usize,
    /// largest relative error of the value
    pub value: f64,
    /// largest relative error of the first derivatives
    pub first: f64,
    /// largest relative error of the second derivatives
    pub second: f64,
    /// one line per case beyond the tolerances
    pub failures: Vec<String>,
}

impl Conformance {
    fn new(name: &str, cases: usize) -> Self {
        Conformance {
            name: name.to_string(),
            cases,
            value: 0.0,
            first: 0.0,
            second: 0.0,
            failures: vec![],
        }
    }

    /// Record one case's errors (value, first, second derivative); `failed` gives the line for a failure.
    fn add(&mut self, e: [f64; 3], tol: [f64; 3], failed: impl FnOnce() -> String) {
        if e.iter().zip(&tol).any(|(v, t)| v.is_nan() || v > t) {
            self.failures.push(failed());
        }
        self.value = self.value.max(e[0]);
        self.first = self.first.max(e[1]);
        self.second = self.second.max(e[2]);
    }
}

/// Item 3a for ψ: ψ, ∇ψ, ∇²ψ of each original material against `oracles/psi_oracle.json`; cases beyond `tol`
/// (value and gradient) or `tol_hess` are listed.
pub fn psi_conformance(
    shared: &Path,
    tol: f64,
    tol_hess: f64,
) -> Result<Vec<Conformance>, ValidationError> {
    let path = shared.join("oracles/psi_oracle.json");
    let oracle = read_json(&path)?;
    let mut out = Vec::new();
    for name in ORIGINAL_MATERIALS {
        let mat = Material::load(&shared.join(format!("data/hylc2020/materials/{name}.json")))?;
        let samples = oracle["materials"][name]["samples"]
            .as_array()
            .ok_or_else(|| data(&path, format!("no samples for {name}")))?;
        let mut c = Conformance::new(name, samples.len());
        for s in samples {
            let z = nums(&s["z"], &path)?;
            if z.len() != 6 {
                return Err(data(&path, format!("{name}: a strain without 6 entries")));
            }
            let r = mat.eval(&[z[0], z[1], z[2], z[3], z[4], z[5]]);
            let hv: Vec<f64> = r.hess.iter().flatten().copied().collect();
            let psi = s["psi"].as_f64().unwrap_or(f64::NAN);
            let e = [
                rel_norm(&[r.value], &[psi]),
                rel_norm(&r.grad, &nums(&s["grad"], &path)?),
                rel_norm(&hv, &nums(&s["hess"], &path)?),
            ];
            c.add(e, [tol, tol, tol_hess], || {
                format!(
                    "{name} #{} ({}) z={z:?}: psi {:.2e} grad {:.2e} hess {:.2e}",
                    s["id"], s["kind"], e[0], e[1], e[2]
                )
            });
        }
        out.push(c);
    }
    Ok(out)
}

/// Item 3a for the strain chain: z, the 6×18 Jacobian and the 6×18×18 Hessian of `oracles/strain_oracle.json`'s
/// cases, at the stored positions and translated 2 m from the origin; cases beyond `tol` are listed.
pub fn strain_conformance(shared: &Path, tol: f64) -> Result<Conformance, ValidationError> {
    let path = shared.join("oracles/strain_oracle.json");
    let oracle = read_json(&path)?;
    let cases = oracle["cases"]
        .as_array()
        .ok_or_else(|| data(&path, "no cases".into()))?;
    let mut c = Conformance::new("strain chain", 2 * cases.len());
    for shift in [0.0, 2.0] {
        for case in cases {
            let xloc = nums(&case["xloc"], &path)?;
            let d = nums(&case["invDm"], &path)?;
            let ex = nums(&case["niexists"], &path)?;
            if xloc.len() != 18 || d.len() != 4 || ex.len() != 3 {
                return Err(data(&path, format!("case {}: malformed", case["id"])));
            }
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
            let chain = StrainChain::new(&q, &rest, flaps)
                .ok_or_else(|| data(&path, format!("case {}: degenerate triangle", case["id"])))?;
            let mut z = chain.z;
            // the original's stretches are not shifted by 1
            z[0] += 1.0;
            z[2] += 1.0;
            let jac: Vec<f64> = chain.jac.iter().flatten().copied().collect();
            let mut hess = Vec::new();
            for k in 0..6 {
                let mut w = [0.0; 6];
                w[k] = 1.0;
                hess.extend(chain.weighted_hessian(&w).iter().flatten().copied());
            }
            let e = [
                rel_norm(&z, &nums(&case["value"], &path)?),
                rel_norm(&jac, &nums(&case["grad"], &path)?),
                rel_norm(&hess, &nums(&case["hess"], &path)?),
            ];
            c.add(e, [tol; 3], || {
                format!(
                    "case {} ({}) shift {shift} m: value {:.2e} jacobian {:.2e} hessian {:.2e}",
                    case["id"], case["kind"], e[0], e[1], e[2]
                )
            });
        }
    }
    Ok(c)
}
