//! The derivative-check registry (`docs/derivative-harness.md`, section 1): every energy of the project
//! under the harness of [`crate::diff`], one file per stage. This layer sits above every energy so that the
//! harness itself depends on nothing but the scalar type.

pub mod contact;
pub mod material;
pub mod micro;
pub mod rod;
pub mod shell;
pub mod shell_external;
pub mod tile;

use crate::diff::{run_checks, Check, CheckConfig, Report};

/// Every function the project puts under the harness. Later stages add their rows here.
pub fn registry() -> Vec<Box<dyn Check>> {
    let mut checks: Vec<Box<dyn Check>> = Vec::new();
    checks.extend(material::diff_checks());
    checks.extend(rod::diff_checks());
    checks.extend(contact::diff_checks());
    checks.extend(tile::diff_checks());
    checks.extend(micro::diff_checks());
    checks.extend(shell::diff_checks());
    checks.extend(shell_external::diff_checks());
    checks
}

/// Run every registered check whose name contains `filter` (all when empty).
pub fn run_all(cfg: &CheckConfig, filter: &str) -> Vec<Report> {
    run_checks(&registry(), cfg, filter)
}
