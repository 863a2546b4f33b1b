//! Bending terms as 2×2 symmetric matrix functions (`05-macro.md`, "Material ψ(z)").
//!
//! For a symmetric L = [[L₀₀, L₀₁], [L₀₁, L₁₁]] with eigenvalues λ₁,₂ = m ± d, where m = (L₀₀ + L₁₁)/2,
//! δ = (L₀₀ − L₁₁)/2, b = L₀₁ and d = √(δ² + b²), the spectral matrix function f(L) = Σᵢ f(λᵢ) vᵢvᵢᵀ is
//!
//!   f(L) = c₀ I + c₁ (L − m I),   c₀ = (f(λ₁) + f(λ₂))/2,   c₁ = f[λ₁, λ₂] (first divided difference),
//!
//! so [f(L)]₀₀ = c₀ + c₁ δ and [f(L)]₁₁ = c₀ − c₁ δ (the 11 component is the 00 component with δ → −δ). This is
//! the Daleckii–Krein (divided-difference) form: no eigenvectors, exact and smooth at equal eigenvalues.
//!
//! When both eigenvalues fall on the same polynomial piece of f (always true at and near umbilic points), f is a
//! cubic p there and, exactly,
//!
//!   c₀ = p(m) + p″(m) q/2,   c₁ = p′(m) + p‴ q/6,   q = d² = δ² + b²,
//!
//! a polynomial in (m, δ, b): value, gradient and Hessian are finite and exact at umbilic points. Otherwise
//! d > 0 and c₀, c₁ are evaluated from f at λ₁ and λ₂ directly. The 2D terms apply this to f(u, ·) for fixed
//! u = z_k/σ_k. Derivatives are taken with respect to w = (u, m, δ, b); the caller maps them to z.

use super::hermite::{Derivs2, Hermite1D};
use crate::real::Real;

/// Below this eigenvalue half-gap (in units of the spline's knot coordinate) two eigenvalues on different pieces
/// are treated with the polynomial of the piece containing their mean: the error is at most the jump of f″ times
/// d² (value) and d (gradient), i.e. below round-off of the values involved, while the direct divided difference
/// would lose all digits to cancellation.
pub const D_MIN: f64 = 1e-9;

/// A function family φ(u, λ), piecewise polynomial in λ, as seen by the spectral term.
pub trait LambdaFamily {
    /// Which polynomial piece λ falls on.
    fn piece(&self, lambda: f64) -> usize;
    /// `d[a][b]` = ∂ᵃ_u ∂ᵇ_λ φ for a ≤ 2, b ≤ 3, with the polynomial of `piece` (λ need not lie on it).
    fn derivs_on(&self, piece: usize, lambda: f64) -> Derivs2;
    /// Derivatives of total order ≤ 2 on `piece`: (φ, φ_u, φ_λ, φ_uu, φ_uλ, φ_λλ).
    fn low_on(&self, piece: usize, lambda: f64) -> [f64; 6];
}

impl LambdaFamily for Hermite1D {
    #[inline]
    fn piece(&self, lambda: f64) -> usize {
        Hermite1D::piece(self, lambda)
    }
    #[inline]
    fn derivs_on(&self, piece: usize, lambda: f64) -> Derivs2 {
        [
            Hermite1D::derivs_on(self, piece, lambda),
            [0.0; 4],
            [0.0; 4],
        ]
    }
    #[inline]
    fn low_on(&self, piece: usize, lambda: f64) -> [f64; 6] {
        let d = Hermite1D::derivs_on(self, piece, lambda);
        [d[0], 0.0, d[1], 0.0, 0.0, d[2]]
    }
}

impl LambdaFamily for super::hermite::AtU<'_> {
    #[inline]
    fn piece(&self, lambda: f64) -> usize {
        self.v_piece_of(lambda)
    }
    #[inline]
    fn derivs_on(&self, piece: usize, lambda: f64) -> Derivs2 {
        super::hermite::AtU::derivs_on(self, piece, lambda)
    }
    #[inline]
    fn low_on(&self, piece: usize, lambda: f64) -> [f64; 6] {
        super::hermite::AtU::low_on(self, piece, lambda)
    }
}

/// Value, gradient and Hessian with respect to w = (u, m, δ, b).
#[derive(Clone, Copy, Debug, Default)]
pub struct SpectralVgh {
    pub value: f64,
    pub grad: [f64; 4],
    pub hess: [[f64; 4]; 4],
}

/// G(y) with its gradient and Hessian in y = (u, m, s, δ).
type GyHy = (f64, [f64; 4], [[f64; 4]; 4]);

/// G = c₀ + c₁ δ on one polynomial piece, in y = (u, m, q, δ) (see the module documentation).
#[inline]
fn same_piece<F: LambdaFamily>(f: &F, piece: usize, m: f64, delta: f64, q: f64) -> GyHy {
    let [f0, f1, f2] = f.derivs_on(piece, m);
    let s = q;
    let g = f0[0] + 0.5 * f0[2] * s + f0[1] * delta + f0[3] * s * delta / 6.0;
    let gy = [
        f1[0] + 0.5 * f1[2] * s + f1[1] * delta + f1[3] * s * delta / 6.0,
        f0[1] + 0.5 * f0[3] * s + f0[2] * delta,
        0.5 * f0[2] + f0[3] * delta / 6.0,
        f0[1] + f0[3] * s / 6.0,
    ];
    let huu = f2[0] + 0.5 * f2[2] * s + f2[1] * delta + f2[3] * s * delta / 6.0;
    let hum = f1[1] + 0.5 * f1[3] * s + f1[2] * delta;
    let hus = 0.5 * f1[2] + f1[3] * delta / 6.0;
    let hud = f1[1] + f1[3] * s / 6.0;
    let hmm = f0[2] + f0[3] * delta;
    let hms = 0.5 * f0[3];
    let hmd = f0[2];
    let hsd = f0[3] / 6.0;
    let hy = [
        [huu, hum, hus, hud],
        [hum, hmm, hms, hmd],
        [hus, hms, 0.0, hsd],
        [hud, hmd, hsd, 0.0],
    ];
    (g, gy, hy)
}

/// G = c₀ + c₁ δ from φ at λ₁ = m + d on piece `p1` and λ₂ = m − d on piece `p2`, in y = (u, m, d, δ):
/// c₀ = (φ(λ₁) + φ(λ₂))/2 and c₁ = N/d with N = (φ(λ₁) − φ(λ₂))/2.
#[inline]
fn different_pieces<F: LambdaFamily>(
    f: &F,
    (p1, l1): (usize, f64),
    (p2, l2): (usize, f64),
    delta: f64,
    d: f64,
) -> GyHy {
    // (φ, φ_u, φ_λ, φ_uu, φ_uλ, φ_λλ) at λ₁ and λ₂: only total order ≤ 2 enters
    let a = f.low_on(p1, l1);
    let bb = f.low_on(p2, l2);
    // positions in `low_on`'s output of ∂ᵃ_u ∂ᵇ_λ, keyed (a, b)
    let at = |i: usize, j: usize| match (i, j) {
        (0, 0) => 0,
        (1, 0) => 1,
        (0, 1) => 2,
        (2, 0) => 3,
        (1, 1) => 4,
        _ => 5,
    };
    let half_sum = |i: usize, j: usize| 0.5 * (a[at(i, j)] + bb[at(i, j)]);
    let half_dif = |i: usize, j: usize| 0.5 * (a[at(i, j)] - bb[at(i, j)]);
    // c₀(u, m, d) and its derivatives (λ₁ = m + d, λ₂ = m − d)
    let c0 = half_sum(0, 0);
    let (c0u, c0m, c0d) = (half_sum(1, 0), half_sum(0, 1), half_dif(0, 1));
    let (c0uu, c0um, c0ud) = (half_sum(2, 0), half_sum(1, 1), half_dif(1, 1));
    let (c0mm, c0md, c0dd) = (half_sum(0, 2), half_dif(0, 2), half_sum(0, 2));
    // N = (φ(λ₁) − φ(λ₂))/2 and c₁ = N/d
    let n = half_dif(0, 0);
    let (nu, nm, nd) = (half_dif(1, 0), half_dif(0, 1), half_sum(0, 1));
    let (nuu, num, nud) = (half_dif(2, 0), half_dif(1, 1), half_sum(1, 1));
    let (nmm, nmd, ndd) = (half_dif(0, 2), half_sum(0, 2), half_dif(0, 2));
    let id = 1.0 / d;
    let c1 = n * id;
    let (c1u, c1m) = (nu * id, nm * id);
    let c1d = (nd - c1) * id;
    let (c1uu, c1um, c1mm) = (nuu * id, num * id, nmm * id);
    let c1ud = (nud - c1u) * id;
    let c1md = (nmd - c1m) * id;
    let c1dd = (ndd - 2.0 * c1d) * id;
    let g = c0 + c1 * delta;
    let gy = [c0u + c1u * delta, c0m + c1m * delta, c0d + c1d * delta, c1];
    let hy = [
        [
            c0uu + c1uu * delta,
            c0um + c1um * delta,
            c0ud + c1ud * delta,
            c1u,
        ],
        [
            c0um + c1um * delta,
            c0mm + c1mm * delta,
            c0md + c1md * delta,
            c1m,
        ],
        [
            c0ud + c1ud * delta,
            c0md + c1md * delta,
            c0dd + c1dd * delta,
            c1d,
        ],
        [c1u, c1m, c1d, 0.0],
    ];
    (g, gy, hy)
}

/// The chain rule y = (u, m, s(δ, b), δ) ← w = (u, m, δ, b): (s_δ, s_b, s_δδ, s_δb, s_bb) for s = q = δ² + b²
/// (`s_is_q`) or s = d = √q.
#[inline]
fn s_derivs(delta: f64, b: f64, d: f64, s_is_q: bool) -> (f64, f64, f64, f64, f64) {
    if s_is_q {
        (2.0 * delta, 2.0 * b, 2.0, 0.0, 2.0)
    } else {
        let id = 1.0 / d;
        let id3 = id * id * id;
        (
            delta * id,
            b * id,
            b * b * id3,
            -delta * b * id3,
            delta * delta * id3,
        )
    }
}

/// [φ(u, L)]₀₀ = c₀ + c₁ δ with its first and second derivatives in w = (u, m, δ, b).
/// For the 11 component pass −δ and flip the sign of the δ row/column of the result.
pub fn spectral_00<F: LambdaFamily>(f: &F, m: f64, delta: f64, b: f64) -> SpectralVgh {
    let q = delta * delta + b * b;
    let d = q.sqrt();
    let (l1, l2) = (m + d, m - d);
    let (p1, p2) = (f.piece(l1), f.piece(l2));
    // G(y), y = (u, m, s, δ), with s = q (same piece) or s = d (different pieces); gy and hy its derivatives.
    let s_is_q = p1 == p2 || d <= D_MIN;
    let (g, gy, hy) = if s_is_q {
        let piece = if p1 == p2 { p1 } else { f.piece(m) };
        same_piece(f, piece, m, delta, q)
    } else {
        different_pieces(f, (p1, l1), (p2, l2), delta, d)
    };
    // Chain y = (u, m, s(δ, b), δ) ← w = (u, m, δ, b).
    let (sd, sb, sdd, sdb, sbb) = s_derivs(delta, b, d, s_is_q);
    // H_w = Jᵀ H_y J + G_s ∇²s with J = ∂y/∂w: columns e_u, e_m, s_δ e_s + e_δ, s_b e_s
    let h = &hy;
    let gs = gy[2];
    let h02 = h[0][2] * sd + h[0][3];
    let h12 = h[1][2] * sd + h[1][3];
    let h22 = h[2][2] * sd * sd + 2.0 * h[2][3] * sd + h[3][3] + gs * sdd;
    let h23 = (h[2][2] * sd + h[2][3]) * sb + gs * sdb;
    let h33 = h[2][2] * sb * sb + gs * sbb;
    let (h03, h13) = (h[0][2] * sb, h[1][2] * sb);
    SpectralVgh {
        value: g,
        grad: [gy[0], gy[1], gs * sd + gy[3], gs * sb],
        hess: [
            [h[0][0], h[0][1], h02, h03],
            [h[0][1], h[1][1], h12, h13],
            [h02, h12, h22, h23],
            [h03, h13, h23, h33],
        ],
    }
}

/// Generic reference twin of [`spectral_00`]: [φ(L)]₀₀ = c₀ + c₁ δ with c₀, c₁ written as symmetric functions of
/// the eigenvalues. `eval(piece, λ)` evaluates φ at λ with the polynomial of `piece`; `poly(piece)` gives that
/// polynomial's power-basis coefficients in t = (λ − origin)/h as generic scalars (they depend on u for 2D terms)
/// together with origin and h.
pub fn spectral_00_reference<D: Real>(
    piece_of: impl Fn(f64) -> usize,
    eval: impl Fn(&D) -> D,
    poly: impl Fn(usize) -> ([D; 4], f64, f64),
    m: &D,
    delta: &D,
    b: &D,
) -> D {
    let q = delta.clone() * delta.clone() + b.clone() * b.clone();
    let dre = q.re().sqrt();
    let (p1, p2) = (piece_of(m.re() + dre), piece_of(m.re() - dre));
    if p1 == p2 || dre <= D_MIN {
        // Same cubic p(t) = Σ cⱼ tʲ on both eigenvalues, t₁,₂ = tm ± td:
        // (p(t₁) + p(t₂))/2 = c₀ + c₁ tm + c₂ (tm² + td²) + c₃ (tm³ + 3 tm td²)
        // (p(t₁) − p(t₂))/(λ₁ − λ₂) = (c₁ + 2 c₂ tm + c₃ (3 tm² + td²)) / h
        let piece = if p1 == p2 { p1 } else { piece_of(m.re()) };
        let (cf, origin, h) = poly(piece);
        let tm = (m.clone() - origin) / h;
        let td2 = q / (h * h);
        let [c0, c1, c2, c3] = cf;
        let mean = c0
            + c1.clone() * tm.clone()
            + c2.clone() * (tm.clone() * tm.clone() + td2.clone())
            + c3.clone() * (tm.clone() * tm.clone() * tm.clone() + tm.clone() * td2.clone() * 3.0);
        let dd = (c1 + c2 * tm.clone() * 2.0 + c3 * (tm.clone() * tm * 3.0 + td2)) / h;
        mean + dd * delta.clone()
    } else {
        let d = q.sqrt();
        let l1 = m.clone() + d.clone();
        let l2 = m.clone() - d.clone();
        let (f1, f2) = (eval(&l1), eval(&l2));
        (f1.clone() + f2.clone()) * 0.5 + (f1 - f2) / (d * 2.0) * delta.clone()
    }
}
