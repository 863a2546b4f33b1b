//! Per-stencil projection of local Hessians to positive semi-definite (`03-homogenization.md`, section 3: "Per-stencil
//! projection of Hessians to positive semi-definite is an alternative" to the μ shift of the micro solver; issue 20).
//!
//! Each rod stencil's and contact pair's local Hessian is replaced by its projection on the positive semi-definite
//! cone (negative eigenvalues clamped at 0). A sum of such blocks, rotated into the dof frame and scattered, is
//! positive semi-definite, so H + μI factorises at the solver's floor μ. A Cholesky test first keeps the blocks
//! that are already positive semi-definite to within round-off bit for bit, without an eigen-decomposition.

use nalgebra::{DMatrix, SMatrix, SymmetricEigen};

/// Relative tolerance of the Cholesky test: a block whose eigenvalues are all above −`TOLERANCE` · max|Hᵢᵢ| stays as
/// it is (rod stencils have rigid-motion null spaces, so their Hessians are never strictly positive definite).
pub const TOLERANCE: f64 = 1e-13;

/// Project the symmetric `h` on the positive semi-definite cone in place: unchanged when the Cholesky factorisation
/// of h + `TOLERANCE` · max|hᵢᵢ| · I succeeds, else h + Σ_{λₖ<0} (−λₖ) vₖ vₖᵀ from the eigen-decomposition of its
/// symmetric part (every negative eigenvalue clamped at 0). Returns whether `h` changed. A block with a non-finite
/// entry is left alone (the energy test of the solver reports it).
pub fn project_psd<const N: usize>(h: &mut SMatrix<f64, N, N>) -> bool {
    if h.iter().any(|v| !v.is_finite()) {
        return false;
    }
    let scale = (0..N).fold(0.0f64, |m, i| m.max(h[(i, i)].abs()));
    if scale == 0.0 && h.iter().all(|&v| v == 0.0) {
        return false;
    }
    if cholesky_succeeds(h, TOLERANCE * scale) {
        return false;
    }
    let sym = 0.5 * (*h + h.transpose());
    // the dynamic eigen-decomposition (nalgebra's static one needs N − 1 as a type): only on this slow path
    let eig = SymmetricEigen::new(DMatrix::from_column_slice(N, N, sym.as_slice()));
    let mut out = sym;
    let mut changed = false;
    for k in 0..N {
        let l = eig.eigenvalues[k];
        if l < 0.0 {
            let v = eig.eigenvectors.column(k);
            for a in 0..N {
                for b in 0..N {
                    out[(a, b)] -= l * v[a] * v[b];
                }
            }
            changed = true;
        }
    }
    if changed {
        *h = out;
    }
    changed
}

/// Whether the Cholesky factorisation of the lower triangle of m + shift·I succeeds (every pivot positive): then
/// every eigenvalue of m is above −shift.
fn cholesky_succeeds<const N: usize>(m: &SMatrix<f64, N, N>, shift: f64) -> bool {
    let mut l = SMatrix::<f64, N, N>::zeros();
    for a in 0..N {
        for b in 0..=a {
            let mut s = m[(a, b)] + if a == b { shift } else { 0.0 };
            for k in 0..b {
                s -= l[(a, k)] * l[(b, k)];
            }
            if a == b {
                if s.is_nan() || s <= 0.0 {
                    return false;
                }
                l[(a, a)] = s.sqrt();
            } else {
                l[(a, b)] = s / l[(b, b)];
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    #[test]
    fn indefinite_block_becomes_psd_and_pd_block_stays() {
        let mut h = Matrix3::new(2.0, 1.0, 0.0, 1.0, -3.0, 0.5, 0.0, 0.5, 1.0);
        assert!(project_psd(&mut h));
        let min = SymmetricEigen::new(h).eigenvalues.min();
        assert!(min >= -1e-12 * h.norm(), "{min}");
        let pd = Matrix3::new(4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 2.0);
        let mut same = pd;
        assert!(!project_psd(&mut same));
        assert_eq!(same, pd);
    }
}
