//! Conformance of the strain chain z(q) with the original macro-scale code (`../shared/oracles/strain_oracle.json`,
//! validation item a of `docs/results.md`; `hylc::validation::conformance::strain_conformance`): value, 6×18 Jacobian
//! and 6×18×18 Hessian (each z_k's Hessian is the weighted Hessian with the unit weight e_k) within 1e-10 relative
//! normwise, at the stored positions and translated 2 m from the origin.

mod common;

use hylc::validation::conformance::strain_conformance;

#[test]
fn strain_chain_matches_the_original() {
    let Some(shared) = common::shared_or_skip("strain_chain_matches_the_original") else {
        return;
    };
    let c = strain_conformance(&shared, 1e-10).unwrap();
    assert_eq!(c.cases, 600);
    eprintln!(
        "strain oracle, 300 cases at the origin and 2 m away: max rel err value {:.2e}, Jacobian {:.2e}, Hessian {:.2e}",
        c.value, c.first, c.second
    );
    assert!(
        c.failures.is_empty(),
        "{} cases off:\n{}",
        c.failures.len(),
        c.failures.join("\n")
    );
}
