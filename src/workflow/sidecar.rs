//! The sidecar of a sample file (`samples.jsonl` → `samples.meta.json`): the plan, the pattern (its `.pyp` text),
//! the yarn parameters, the solver settings, the problem hash and the pattern's areal density, which the fit reads
//! (`docs/sampling.md`, "Sampling plan (C4)").

use super::{write_file, WorkflowError};
use crate::micro::MicroProblem;
use crate::rod::YarnMaterial;
use crate::sample::plan::fnv1a64;
use crate::sample::run::problem_hash;
use crate::sample::Plan;
use std::path::{Path, PathBuf};

/// The sidecar's path: `samples.jsonl` → `samples.meta.json`.
pub fn meta_path(samples: &Path) -> PathBuf {
    samples.with_extension("meta.json")
}

/// Write the sidecar of the sample file `out`; `arg` is the pattern as the user named it.
pub fn write_meta(
    out: &Path,
    arg: &str,
    plan: &Plan,
    problem: &MicroProblem,
) -> Result<(), WorkflowError> {
    let m = &problem.material;
    let pyp = problem.pattern.to_pyp_string();
    let meta = serde_json::json!({
        "pattern": arg,
        "pyp hash": format!("{:016x}", fnv1a64(pyp.as_bytes())),
        "problem": problem_hash(problem),
        "plan": plan,
        "density": problem.pattern.areal_density(m.density),
        "yarn": m,
        "solver": problem.options,
        "periods": problem.pattern.periods,
        "pyp": pyp,
    });
    let text = serde_json::to_string_pretty(&meta).expect("JSON values serialise");
    write_file(&meta_path(out), text + "\n")
}

/// The sidecar of a sample file, if there is one.
pub fn read_meta(
    samples: &Path,
) -> Result<Option<serde_json::Map<String, serde_json::Value>>, WorkflowError> {
    let path = meta_path(samples);
    let bad = |what: String| WorkflowError::Input(format!("{}: {what}", path.display()));
    match std::fs::read_to_string(&path) {
        // a UTF-8 byte-order mark is accepted, as in `.pyp` files
        Ok(text) => match serde_json::from_str::<serde_json::Value>(
            text.strip_prefix('\u{feff}').unwrap_or(&text),
        ) {
            Ok(serde_json::Value::Object(m)) => Ok(Some(m)),
            Ok(_) => Err(bad("expected a JSON object".into())),
            Err(e) => Err(bad(format!("not JSON: {e}"))),
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(WorkflowError::io(&path, "cannot read", e)),
    }
}

/// The yarn parameters a sidecar records (`"yarn"`), `None` when it records none. Sidecars written before the
/// contact radius factor existed lack that key; their contact distance was 2r, so it reads as 1. Any other
/// missing or unknown key is an error naming the sidecar and the key.
pub fn recorded_yarn(
    samples: &Path,
    meta: &serde_json::Map<String, serde_json::Value>,
) -> Result<Option<YarnMaterial>, WorkflowError> {
    let Some(v) = meta.get("yarn") else {
        return Ok(None);
    };
    let mut v = v.clone();
    if let serde_json::Value::Object(m) = &mut v {
        m.entry("contact_radius_factor")
            .or_insert(serde_json::json!(1.0));
    }
    YarnMaterial::from_json_str(&v.to_string(), &meta_path(samples))
        .map(Some)
        .map_err(|e| WorkflowError::Input(format!("{e} (in \"yarn\")")))
}
