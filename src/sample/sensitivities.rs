//! Per-sample sensitivities to the yarn parameters (`hylc sample --sensitivities`; docs/sampling.md, section
//! "Sensitivities to the yarn parameters"): ∂Ψ̄/∂θ and dσ/dθ at a sample's kept equilibrium, the reference state
//! held fixed, and the rewrite of a sample file that adds them to finished records.
//!
//! - ∂Ψ̄/∂θ by the envelope theorem ([`parameter_derivatives_at`]; `docs/micro-solver.md`, section 5).
//! - dσ/dθ = ∂σ/∂θ + (∂σ/∂y) dy*/dθ with dy*/dθ = −H⁻¹ ∂(∇_y E)/∂θ on the constraint space (one factorisation,
//!   [`equilibrium_response`]) and the directional central difference of the analytic stress
//!   ([`stress_parameter_derivatives`]).

use super::record::{PerParameter, Record};
use super::SampleError;
use crate::micro::envelope::{parameter_derivatives_at, stress_parameter_derivatives};
use crate::micro::sensitivity::{equilibrium_response, parameter_mixed_gradients};
use crate::micro::{MicroError, MicroProblem, MicroState};
use std::collections::HashMap;
use std::path::Path;

/// Whether a record should carry sensitivities but does not: it counts as converged
/// ([`Record::converged_psi`]) and has no `dpsi_dtheta`.
pub fn lacks_sensitivities(record: &Record) -> bool {
    record.converged_psi().is_some() && record.dpsi_dtheta.is_none()
}

/// Set `record.dpsi_dtheta` and, where the record has a stress, `record.dstress_dtheta` at `state`, the record's
/// kept equilibrium (module docs). A stress component that is null in the record is null in every dσ/dθ.
pub fn add_sensitivities(
    problem: &MicroProblem,
    record: &mut Record,
    state: &MicroState,
) -> Result<(), MicroError> {
    let psi = parameter_derivatives_at(problem, state)?;
    let stress = match record.stress {
        Some(sigma) => {
            let b = parameter_mixed_gradients(problem, state)?;
            let dy = equilibrium_response(problem, state, &b)?;
            let d = stress_parameter_derivatives(problem, state, &dy)?;
            Some(PerParameter::from_array(std::array::from_fn(|k| {
                std::array::from_fn(|j| d[k][j].filter(|_| sigma[j].is_some()))
            })))
        }
        None => None,
    };
    record.dpsi_dtheta = Some(PerParameter::from_array(psi));
    record.dstress_dtheta = stress;
    Ok(())
}

/// Rewrite the sample file `out` with the sensitivities of `found` (records by id) put into the records that lack
/// them; every other line is kept as it is. Written to a temporary file and renamed. Returns the records changed.
pub fn fill_file(out: &Path, found: &HashMap<String, Record>) -> Result<usize, SampleError> {
    let io = |action, source| SampleError::Io {
        path: out.to_path_buf(),
        action,
        source,
    };
    let text = std::fs::read_to_string(out).map_err(|e| io("cannot read", e))?;
    let mut changed = 0;
    let mut lines = String::with_capacity(text.len() + found.len() * 600);
    for (i, line) in text.split_inclusive('\n').enumerate() {
        let body = line.trim_start_matches('\u{feff}');
        let replacement = match serde_json::from_str::<Record>(body.trim_end()) {
            Ok(mut r) if r.dpsi_dtheta.is_none() => found.get(&r.id).map(|f| {
                r.dpsi_dtheta = f.dpsi_dtheta;
                r.dstress_dtheta = f.dstress_dtheta;
                r
            }),
            Ok(_) => None,
            Err(_) if body.trim().is_empty() => None,
            Err(e) => {
                return Err(SampleError::Line {
                    path: out.to_path_buf(),
                    line: i + 1,
                    message: format!("not a sample record: {e}"),
                })
            }
        };
        match replacement {
            Some(r) => {
                changed += 1;
                lines.push_str(&line[..line.len() - body.len()]);
                lines.push_str(&r.to_line());
            }
            None => lines.push_str(line),
        }
    }
    let tmp = out.with_extension("sensitivities-tmp");
    std::fs::write(&tmp, lines)
        .and_then(|_| std::fs::rename(&tmp, out))
        .map_err(|e| io("cannot write", e))?;
    Ok(changed)
}
