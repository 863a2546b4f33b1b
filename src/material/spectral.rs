//! Bending terms as 2×2 symmetric matrix functions (`docs/material.md`, "Material ψ(z)").
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
    #[inline(always)]
    fn piece(&self, lambda: f64) -> usize {
        Hermite1D::piece(self, lambda)
    }
    #[inline(always)]
    fn derivs_on(&self, piece: usize, lambda: f64) -> Derivs2 {
        [
            Hermite1D::derivs_on(self, piece, lambda),
            [0.0; 4],
            [0.0; 4],
        ]
    }
    #[inline(always)]
    fn low_on(&self, piece: usize, lambda: f64) -> [f64; 6] {
        let d = Hermite1D::derivs_on(self, piece, lambda);
        [d[0], 0.0, d[1], 0.0, 0.0, d[2]]
    }
}

impl LambdaFamily for super::hermite::AtU<'_> {
    #[inline(always)]
    fn piece(&self, lambda: f64) -> usize {
        self.v_piece_of(lambda)
    }
    #[inline(always)]
    fn derivs_on(&self, piece: usize, lambda: f64) -> Derivs2 {
        super::hermite::AtU::derivs_on(self, piece, lambda)
    }
    #[inline(always)]
    fn low_on(&self, piece: usize, lambda: f64) -> [f64; 6] {
        super::hermite::AtU::low_on(self, piece, lambda)
    }
}

/// The eigen-geometry of one bending group (all terms of one bending index share it): m, δ, b of L/σ (δ sign-flipped
/// for the 11 component), q = δ² + b², d = √q and the eigenvalues λ₁,₂ = m ± d.
#[derive(Clone, Copy, Debug)]
pub struct Eigen2 {
    /// m = (L₀₀ + L₁₁)/2, the mean of the eigenvalues
    pub m: f64,
    /// δ = (L₀₀ − L₁₁)/2 (sign-flipped for the 11 component)
    pub delta: f64,
    /// b = L₀₁
    pub b: f64,
    /// q = δ² + b²
    pub q: f64,
    /// d = √q, half the eigenvalue gap
    pub d: f64,
}

impl Eigen2 {
    /// The geometry of m, δ, b (q and d computed).
    #[inline(always)]
    pub fn new(m: f64, delta: f64, b: f64) -> Eigen2 {
        let q = delta * delta + b * b;
        Eigen2 {
            m,
            delta,
            b,
            q,
            d: q.sqrt(),
        }
    }
}

/// Sum of the spectral terms [φ(u_k, L)]₀₀ = c₀ + c₁ δ of one bending group, with first and second derivatives in
/// w = (m, δ, b) and in the in-plane arguments u_k (k = 0, 1, 2; one per 2D term, none for the 1D term).
///
/// Each term is accumulated in its own chart y = (m, s, δ): s = q on the polynomial branch (both eigenvalues on
/// one piece, see the module documentation), s = d on the divided-difference branch. The chain y → w (through
/// s(δ, b)) is linear in the accumulated derivatives, so it is applied once per branch in [`SpectralSum::finish`]
/// instead of once per term.
#[derive(Clone, Copy, Debug, Default)]
pub struct SpectralSum {
    value: f64,
    /// per branch (0: s = q, 1: s = d): whether any term took it
    used: [bool; 2],
    /// per branch: gradient in y = (m, s, δ)
    g: [[f64; 3]; 2],
    /// per branch: Hessian in y, packed (mm, ms, mδ, ss, sδ, δδ)
    h: [[f64; 6]; 2],
    /// ∂/∂u_k and ∂²/∂u_k² (no chain needed)
    gu: [f64; 3],
    huu: [f64; 3],
    /// per branch: ∂²/∂u_k ∂y
    hu: [[[f64; 3]; 3]; 2],
}

/// [`SpectralSum`] mapped to w = (m, δ, b): value, gradient, Hessian packed (mm, mδ, mb, δδ, δb, bb), and for
/// each u_k its first and second derivative and the mixed derivatives ∂²/∂u_k ∂w.
#[derive(Clone, Copy, Debug, Default)]
pub struct SpectralW {
    /// the value
    pub value: f64,
    /// gradient in w = (m, δ, b)
    pub g: [f64; 3],
    /// Hessian in w, packed (mm, mδ, mb, δδ, δb, bb)
    pub h: [f64; 6],
    /// ∂/∂u_k
    pub gu: [f64; 3],
    /// ∂²/∂u_k²
    pub huu: [f64; 3],
    /// ∂²/∂u_k ∂w, row k
    pub hu: [[f64; 3]; 3],
}

impl SpectralSum {
    /// Add [φ(u_k, L)]₀₀ for the family `f` (φ(λ) for a 1D term, `u = None`; φ(u_k, λ) for a 2D term, `u = Some(k)`).
    #[inline(always)]
    pub fn add<F: LambdaFamily>(&mut self, f: &F, e: &Eigen2, u: Option<usize>) {
        let (l1, l2) = (e.m + e.d, e.m - e.d);
        let (p1, p2) = (f.piece(l1), f.piece(l2));
        if p1 == p2 || e.d <= D_MIN {
            let piece = if p1 == p2 { p1 } else { f.piece(e.m) };
            self.add_same_piece(f, piece, e, u);
        } else {
            self.add_different_pieces(f, (p1, l1), (p2, l2), e, u);
        }
    }

    /// Both eigenvalues on one cubic: G = c₀ + c₁ δ with c₀ = p(m) + p″(m) q/2, c₁ = p′(m) + p‴ q/6, in y = (m, q, δ).
    #[inline(always)]
    fn add_same_piece<F: LambdaFamily>(
        &mut self,
        f: &F,
        piece: usize,
        e: &Eigen2,
        u: Option<usize>,
    ) {
        let (q, delta) = (e.q, e.delta);
        let [f0, f1, f2] = f.derivs_on(piece, e.m);
        self.value += f0[0] + 0.5 * f0[2] * q + f0[1] * delta + f0[3] * q * delta / 6.0;
        self.used[0] = true;
        let g = &mut self.g[0];
        g[0] += f0[1] + 0.5 * f0[3] * q + f0[2] * delta;
        g[1] += 0.5 * f0[2] + f0[3] * delta / 6.0;
        g[2] += f0[1] + f0[3] * q / 6.0;
        // (mm, mq, mδ, qq, qδ, δδ); G is linear in q and in δ
        let h = &mut self.h[0];
        h[0] += f0[2] + f0[3] * delta;
        h[1] += 0.5 * f0[3];
        h[2] += f0[2];
        h[4] += f0[3] / 6.0;
        if let Some(k) = u {
            self.gu[k] += f1[0] + 0.5 * f1[2] * q + f1[1] * delta + f1[3] * q * delta / 6.0;
            self.huu[k] += f2[0] + 0.5 * f2[2] * q + f2[1] * delta + f2[3] * q * delta / 6.0;
            let hu = &mut self.hu[0][k];
            hu[0] += f1[1] + 0.5 * f1[3] * q + f1[2] * delta;
            hu[1] += 0.5 * f1[2] + f1[3] * delta / 6.0;
            hu[2] += f1[1] + f1[3] * q / 6.0;
        }
    }

    /// Eigenvalues on different pieces: G = c₀ + c₁ δ with c₀ = (φ(λ₁) + φ(λ₂))/2, c₁ = N/d,
    /// N = (φ(λ₁) − φ(λ₂))/2, in y = (m, d, δ) (λ₁,₂ = m ± d).
    #[inline(always)]
    fn add_different_pieces<F: LambdaFamily>(
        &mut self,
        f: &F,
        at1: (usize, f64),
        at2: (usize, f64),
        e: &Eigen2,
        u: Option<usize>,
    ) {
        let delta = e.delta;
        // (φ, φ_u, φ_λ, φ_uu, φ_uλ, φ_λλ) at λ₁ and λ₂: only total order ≤ 2 enters
        let (a, bb) = (f.low_on(at1.0, at1.1), f.low_on(at2.0, at2.1));
        let hs = |i: usize| 0.5 * (a[i] + bb[i]);
        let hd = |i: usize| 0.5 * (a[i] - bb[i]);
        let id = 1.0 / e.d;
        // c₀(m, d) and N(m, d) with their derivatives in (m, d)
        let (c0, c0m, c0d) = (hs(0), hs(2), hd(2));
        let (c0mm, c0md, c0dd) = (hs(5), hd(5), hs(5));
        let (n, nm, nd) = (hd(0), hd(2), hs(2));
        let (nmm, nmd, ndd) = (hd(5), hs(5), hd(5));
        let c1 = n * id;
        let c1m = nm * id;
        let c1d = (nd - c1) * id;
        let c1mm = nmm * id;
        let c1md = (nmd - c1m) * id;
        let c1dd = (ndd - 2.0 * c1d) * id;
        self.value += c0 + c1 * delta;
        self.used[1] = true;
        let g = &mut self.g[1];
        g[0] += c0m + c1m * delta;
        g[1] += c0d + c1d * delta;
        g[2] += c1;
        // (mm, md, mδ, dd, dδ, δδ)
        let h = &mut self.h[1];
        h[0] += c0mm + c1mm * delta;
        h[1] += c0md + c1md * delta;
        h[2] += c1m;
        h[3] += c0dd + c1dd * delta;
        h[4] += c1d;
        if let Some(k) = u {
            let (c0u, c0uu, c0um, c0ud) = (hs(1), hs(3), hs(4), hd(4));
            let (nu, nuu, num, nud) = (hd(1), hd(3), hd(4), hs(4));
            let c1u = nu * id;
            let c1ud = (nud - c1u) * id;
            self.gu[k] += c0u + c1u * delta;
            self.huu[k] += c0uu + nuu * id * delta;
            let hu = &mut self.hu[1][k];
            hu[0] += c0um + num * id * delta;
            hu[1] += c0ud + c1ud * delta;
            hu[2] += c1u;
        }
    }

    /// Map the accumulated y-derivatives to w = (m, δ, b): H_w = Jᵀ H_y J + G_s ∇²s with J = ∂y/∂w (columns
    /// e_m, s_δ e_s + e_δ, s_b e_s), per branch, summed.
    #[inline(always)]
    pub fn finish(&self, e: &Eigen2) -> SpectralW {
        let mut out = SpectralW {
            value: self.value,
            gu: self.gu,
            huu: self.huu,
            ..SpectralW::default()
        };
        for branch in 0..2 {
            if !self.used[branch] {
                continue;
            }
            // (s_δ, s_b, s_δδ, s_δb, s_bb) for s = q or s = d
            let (sd, sb, sdd, sdb, sbb) = if branch == 0 {
                (2.0 * e.delta, 2.0 * e.b, 2.0, 0.0, 2.0)
            } else {
                let id = 1.0 / e.d;
                let id3 = id * id * id;
                (
                    e.delta * id,
                    e.b * id,
                    e.b * e.b * id3,
                    -e.delta * e.b * id3,
                    e.delta * e.delta * id3,
                )
            };
            let (g, h) = (&self.g[branch], &self.h[branch]);
            let gs = g[1];
            out.g[0] += g[0];
            out.g[1] += gs * sd + g[2];
            out.g[2] += gs * sb;
            let (hmm, hms, hmd, hss, hsd, hdd) = (h[0], h[1], h[2], h[3], h[4], h[5]);
            out.h[0] += hmm;
            out.h[1] += hms * sd + hmd;
            out.h[2] += hms * sb;
            out.h[3] += (hss * sd + 2.0 * hsd) * sd + hdd + gs * sdd;
            out.h[4] += (hss * sd + hsd) * sb + gs * sdb;
            out.h[5] += hss * sb * sb + gs * sbb;
            for k in 0..3 {
                let hu = &self.hu[branch][k];
                out.hu[k][0] += hu[0];
                out.hu[k][1] += hu[1] * sd + hu[2];
                out.hu[k][2] += hu[1] * sb;
            }
        }
        out
    }
}

/// Generic reference twin of [`SpectralSum`] for one term: [φ(L)]₀₀ = c₀ + c₁ δ with c₀, c₁ written as symmetric functions of
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
