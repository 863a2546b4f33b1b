//! Per-stencil projection of the local Hessians to positive semi-definite (`SolverOptions::psd_stencils`; issue 20,
//! item 2; `03-homogenization.md`, section 3), on the generated plain weave (no external data needed).

use hylc::generate::default_pattern;
use hylc::micro::{MacroStrain, MicroProblem, PsdStencils, SolverOptions, Status};
use hylc::rod::stretch::stretch_vgh;
use hylc::rod::YarnMaterial;
use hylc::tile::psd::project_psd;
use hylc::tile::{Terms, Tile, Want};
use nalgebra::{DMatrix, SMatrix, SymmetricEigen, Vector3};

fn eigenvalues(m: &DMatrix<f64>) -> Vec<f64> {
    let mut l: Vec<f64> = SymmetricEigen::new(m.clone())
        .eigenvalues
        .iter()
        .copied()
        .collect();
    l.sort_by(f64::total_cmp);
    l
}

fn dynamic<const N: usize>(h: &SMatrix<f64, N, N>) -> DMatrix<f64> {
    DMatrix::from_column_slice(N, N, h.as_slice())
}

/// A compressed edge's stretch Hessian is indefinite (negative transverse curvature): its projection has the
/// eigenvalues max(λ, 0) of the original (the nearest positive semi-definite matrix), and a stretched edge's
/// (positive semi-definite, singular along the translations) stays bit for bit, as does a positive definite block.
#[test]
fn projected_block_is_psd_and_pd_blocks_stay() {
    let a = Vector3::new(0.0, 0.0, 0.0);
    let b = Vector3::new(0.8e-3, 0.1e-3, 0.0);
    let (_, _, compressed) = stretch_vgh(&a, &b, 1.0e-3, 2.0);
    let before = eigenvalues(&dynamic(&compressed));
    assert!(before[0] < -1e-3 * before[5], "{before:?}");
    let mut h = compressed;
    assert!(project_psd(&mut h));
    let after = eigenvalues(&dynamic(&h));
    let norm = compressed.norm();
    assert!(after[0] >= -1e-12 * norm, "{after:?}");
    let mut clamped: Vec<f64> = before.iter().map(|l| l.max(0.0)).collect();
    clamped.sort_by(f64::total_cmp);
    for (x, y) in after.iter().zip(&clamped) {
        assert!((x - y).abs() <= 1e-12 * norm, "{after:?} vs {clamped:?}");
    }

    let (_, _, stretched) = stretch_vgh(&a, &b, 0.7e-3, 2.0);
    let mut same = stretched;
    assert!(!project_psd(&mut same));
    assert_eq!(same, stretched);

    let m = SMatrix::<f64, 11, 11>::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 - 2.0);
    let pd = m * m.transpose() + SMatrix::<f64, 11, 11>::identity();
    let mut same = pd;
    assert!(!project_psd(&mut same));
    assert_eq!(same, pd);
}

/// With the option on, the whole tile Hessian (rods and contact) at a perturbation of the plain weave's stored
/// state is positive semi-definite, while the exact one there is not.
#[test]
fn assembled_tile_hessian_is_psd() {
    let pattern = default_pattern("plain").unwrap();
    let (state, mut tile, mut y) = Tile::at_rest_state(&pattern, &YarnMaterial::default()).unwrap();
    // every position dof moved by up to 0.2 r (deterministic)
    let r = pattern.radius;
    for (i, v) in y.iter_mut().take(3 * pattern.len()).enumerate() {
        *v += 0.2 * r * (1.7 * i as f64).sin();
    }
    let nd = tile.ndof();
    let exact = tile
        .evaluate(&state, &y, Want::Hessian, &Terms::ALL)
        .unwrap()
        .dense_hessian(nd)
        .unwrap();
    tile.psd_stencils = true;
    let projected = tile
        .evaluate(&state, &y, Want::Hessian, &Terms::ALL)
        .unwrap()
        .dense_hessian(nd)
        .unwrap();
    let (le, lp) = (eigenvalues(&exact), eigenvalues(&projected));
    let norm = exact.norm();
    eprintln!(
        "min eigenvalue: exact {:e}, projected {:e}, norm {norm:e}",
        le[0], lp[0]
    );
    assert!(le[0] < -1e-9 * norm, "exact min eigenvalue {:e}", le[0]);
    assert!(
        lp[0] >= -1e-12 * norm,
        "projected min eigenvalue {:e}",
        lp[0]
    );
}

/// Both variants reach the default solver's equilibrium (Ψ̄ to 1e-8 relative) on stretched samples, where the
/// equilibrium is the minimum the continuation follows.
#[test]
fn psd_stencils_reach_the_same_equilibria() {
    let problem = |psd_stencils| {
        MicroProblem::new(
            default_pattern("plain").unwrap(),
            &YarnMaterial::default(),
            SolverOptions {
                psd_stencils,
                ..Default::default()
            },
        )
    };
    let exact = problem(PsdStencils::Off);
    for variant in [PsdStencils::Always, PsdStencils::Fallback] {
        let p = problem(variant);
        for z in [
            MacroStrain::in_plane(0.1, 0.05, 0.0),
            MacroStrain::in_plane(0.05, 0.1, 0.1),
        ] {
            let a = exact.solve(&z, None).unwrap();
            let b = p.solve(&z, None).unwrap();
            assert_eq!(a.status, Status::Converged, "{z}");
            assert_eq!(b.status, Status::Converged, "{variant:?} {z}");
            let (pa, pb) = (a.psi().unwrap(), b.psi().unwrap());
            eprintln!(
                "{variant:?} {z}: steps {} vs {}, psi {pa} vs {pb}",
                a.steps, b.steps
            );
            assert!(
                (pa - pb).abs() <= 1e-8 * pa.abs(),
                "{variant:?} {z}: {pa} vs {pb}"
            );
        }
    }
}
