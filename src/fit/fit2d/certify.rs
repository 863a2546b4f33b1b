//! The certificate of FIT2D's step 5 (`docs/fitting.md`, "Fitting (C5, C6, C7)"): whether a patch's directional
//! derivative, a polynomial in Bernstein form, is non-negative on the whole patch, by de Casteljau subdivision.

/// De Casteljau at ½: the Bernstein coefficients of a polynomial on [0, 1] split into those on [0, ½] and [½, 1].
fn split_half<const N: usize>(c: [f64; N]) -> ([f64; N], [f64; N]) {
    let (mut lo, mut hi, mut w) = (c, c, c);
    for r in 1..N {
        for i in 0..N - r {
            w[i] = 0.5 * (w[i] + w[i + 1]);
        }
        lo[r] = w[0];
        hi[N - 1 - r] = w[N - 1 - r];
    }
    (lo, hi)
}

/// Subdivision depth and box budget of [`nonnegative`]: 2⁻¹² of a patch per side, at most 4096 subdivisions.
const CERTIFY_DEPTH: u32 = 12;
const CERTIFY_BOXES: usize = 4096;

/// Whether the polynomial q(s, t) = Σ c[a][b] B²_a(s) B³_b(t) is ≥ −`tol` on the whole unit square, certified:
/// a polynomial lies between the least and the largest of its Bernstein coefficients, so all of them ≥ −tol proves
/// it; a corner coefficient is a value of q, so one below −tol disproves it; otherwise the square is split in four
/// (de Casteljau), whose coefficients converge to q quadratically, down to [`CERTIFY_DEPTH`] levels and within
/// [`CERTIFY_BOXES`] splits. Undecided boxes count as failing (q is then within rounding of −tol somewhere), so a
/// `true` is a proof and step 5 repairs everything else.
pub(super) fn nonnegative(c: &[[f64; 4]; 3], tol: f64) -> bool {
    fn go(c: &[[f64; 4]; 3], tol: f64, depth: u32, budget: &mut usize) -> bool {
        if c.iter().flatten().all(|&x| x >= -tol) {
            return true;
        }
        if [c[0][0], c[0][3], c[2][0], c[2][3]]
            .iter()
            .any(|&x| x < -tol)
            || depth == 0
            || *budget == 0
        {
            return false;
        }
        *budget -= 1;
        let (mut lo, mut hi) = ([[0.0; 4]; 3], [[0.0; 4]; 3]);
        for b in 0..4 {
            let (l, h) = split_half([c[0][b], c[1][b], c[2][b]]);
            for a in 0..3 {
                lo[a][b] = l[a];
                hi[a][b] = h[a];
            }
        }
        for half in [lo, hi] {
            let (mut l, mut h) = ([[0.0; 4]; 3], [[0.0; 4]; 3]);
            for a in 0..3 {
                (l[a], h[a]) = split_half(half[a]);
            }
            if !go(&l, tol, depth - 1, budget) || !go(&h, tol, depth - 1, budget) {
                return false;
            }
        }
        true
    }
    let mut budget = CERTIFY_BOXES;
    go(c, tol, CERTIFY_DEPTH, &mut budget)
}
