//! Cubic and bicubic Hermite splines with the original's linear extrapolation (`docs/material.md`, "Material ψ(z)";
//! storage in `docs/material.md`, "Material JSON").
//!
//! A spline is stored as knots plus values and slopes. For evaluation the knot line is split into *pieces*:
//! piece 0 is the left exterior (x < t₀), pieces 1..n−1 the cells [tᵢ, tᵢ₊₁], piece n the right exterior
//! (x > tₙ₋₁). On every piece the spline is a polynomial in the local coordinate s = (x − x₀)/h: cubic on cells,
//! linear on the exterior pieces (value and slope of the end knot). The 2D spline is the tensor product, so outside
//! the grid it continues linearly in each direction that left the grid, with the product (cross) term in the corners.
//!
//! Fast evaluation uses power-basis coefficients precomputed per piece. The generic reference implementation
//! ([`basis_weights`]) evaluates the Hermite basis functions directly from the stored knots, values and slopes.

use crate::real::Real;

/// Hermite basis in the local coordinate s ∈ [0, 1] of a cell, as power-basis coefficients (rows: weights of
/// pᵢ, pᵢ₊₁, h·mᵢ, h·mᵢ₊₁; columns: s⁰..s³).
const HERMITE: [[f64; 4]; 4] = [
    [1.0, 0.0, -3.0, 2.0], // h00
    [0.0, 0.0, 3.0, -2.0], // h01
    [0.0, 1.0, -2.0, 1.0], // h10
    [0.0, 0.0, -1.0, 1.0], // h11
];

/// Where a coordinate falls on a knot line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Piece {
    /// 0 = left exterior, 1..n−1 = cell i−1, n = right exterior
    pub index: usize,
    /// the cell whose data defines this piece (the end cell for exterior pieces)
    pub cell: usize,
}

/// The piece with a given index on a knot line of `n` knots.
#[inline]
pub fn piece_from_index(n: usize, index: usize) -> Piece {
    Piece {
        index,
        cell: if index == 0 {
            0
        } else {
            (index - 1).min(n - 2)
        },
    }
}

/// Locate `x` on strictly increasing knots `t` (at least two). NaN lands in the first cell (and stays NaN).
///
/// The cell is guessed by linear interpolation over the knot range (exact for uniform knots, off by a few for the
/// originals' two-spacing grids) and then corrected, so the result is always the cell with tᵢ ≤ x < tᵢ₊₁.
#[inline]
pub fn locate(t: &[f64], x: f64) -> Piece {
    locate_scaled(t, guess_scale(t), x)
}

/// (n − 1)/(tₙ₋₁ − t₀): the factor of [`locate`]'s first guess, stored by the splines so that a lookup needs no
/// division.
pub fn guess_scale(t: &[f64]) -> f64 {
    (t.len() - 1) as f64 / (t[t.len() - 1] - t[0])
}

/// [`locate`] with its guess factor `scale` = [`guess_scale`]`(t)` precomputed. The guess only picks where the
/// correction starts, so the result is the same cell for any finite factor.
#[inline(always)]
pub fn locate_scaled(t: &[f64], scale: f64, x: f64) -> Piece {
    let n = t.len();
    let (first, last) = (t[0], t[n - 1]);
    if x < first {
        Piece { index: 0, cell: 0 }
    } else if x > last {
        Piece {
            index: n,
            cell: n - 2,
        }
    } else {
        // x = t_{n−1} belongs to the last cell; NaN fails both comparisons above and the guess is 0
        let guess = ((x - first) * scale) as usize;
        let mut cell = guess.min(n - 2);
        while cell > 0 && t[cell] > x {
            cell -= 1;
        }
        while cell < n - 2 && t[cell + 1] <= x {
            cell += 1;
        }
        Piece {
            index: cell + 1,
            cell,
        }
    }
}

/// Power-basis description of the four Hermite weights on one piece: weight b at x is
/// `Σ_j w[b][j] sʲ` with `s = (x − origin) / h`. The weights multiply (p_i, p_{i+1}, m_i, m_{i+1}) of `cell`.
#[derive(Clone, Copy, Debug)]
pub struct BasisPiece {
    /// origin x₀ of the local coordinate s (the cell's left knot, or the end knot on an exterior piece)
    pub origin: f64,
    /// length h of the cell (of the end cell on an exterior piece)
    pub h: f64,
    /// power-basis coefficients: weight b is `Σ_j w[b][j] sʲ`
    pub w: [[f64; 4]; 4],
}

/// The basis on a piece of knot line `t`.
pub fn basis_piece(t: &[f64], piece: Piece) -> BasisPiece {
    let n = t.len();
    let i = piece.cell;
    let h = t[i + 1] - t[i];
    if piece.index == 0 {
        // p₀ + m₀ (x − t₀) = p₀ + (h m₀) s
        BasisPiece {
            origin: t[0],
            h,
            w: [[1.0, 0.0, 0.0, 0.0], [0.0; 4], [0.0, h, 0.0, 0.0], [0.0; 4]],
        }
    } else if piece.index == n {
        BasisPiece {
            origin: t[n - 1],
            h,
            w: [[0.0; 4], [1.0, 0.0, 0.0, 0.0], [0.0; 4], [0.0, h, 0.0, 0.0]],
        }
    } else {
        let mut w = HERMITE;
        for row in w.iter_mut().skip(2) {
            for c in row.iter_mut() {
                *c *= h;
            }
        }
        BasisPiece { origin: t[i], h, w }
    }
}

/// Generic reference: the four Hermite weights at `x` (multiplying p_i, p_{i+1}, m_i, m_{i+1} of the returned
/// cell), with the linear extrapolation beyond the end knots.
pub fn basis_weights<D: Real>(t: &[f64], x: &D) -> (usize, [D; 4]) {
    let piece = locate(t, x.re());
    let b = basis_piece(t, piece);
    let s = (x.clone() - b.origin) / b.h;
    let w = std::array::from_fn(|k| {
        let c = &b.w[k];
        ((s.clone() * c[3] + c[2]) * s.clone() + c[1]) * s.clone() + c[0]
    });
    (piece.cell, w)
}

/// A 1D cubic Hermite spline (knots t, values p, slopes m) with linear extrapolation.
#[derive(Clone, Debug)]
pub struct Hermite1D {
    /// knots tᵢ (increasing)
    pub t: Vec<f64>,
    /// values pᵢ at the knots
    pub p: Vec<f64>,
    /// slopes mᵢ at the knots
    pub m: Vec<f64>,
    /// per piece: origin, 1/h and power-basis coefficients c₀..c₃ in s
    pieces: Vec<(f64, f64, [f64; 4])>,
    /// [`guess_scale`] of t
    scale: f64,
}

impl Hermite1D {
    /// Build from knots, values and slopes. The caller validates lengths (≥ 2, equal) and strictly increasing,
    /// finite knots; [`crate::material::json`] does so with file-and-field errors.
    pub fn new(t: Vec<f64>, p: Vec<f64>, m: Vec<f64>) -> Hermite1D {
        let n = t.len();
        assert!(
            n >= 2 && p.len() == n && m.len() == n,
            "Hermite1D: invalid sizes"
        );
        let pieces = (0..=n)
            .map(|index| {
                let cell = if index == 0 {
                    0
                } else {
                    (index - 1).min(n - 2)
                };
                let b = basis_piece(&t, Piece { index, cell });
                let data = [p[cell], p[cell + 1], m[cell], m[cell + 1]];
                let mut c = [0.0; 4];
                for (k, d) in data.iter().enumerate() {
                    for j in 0..4 {
                        c[j] += b.w[k][j] * d;
                    }
                }
                (b.origin, 1.0 / b.h, c)
            })
            .collect();
        let scale = guess_scale(&t);
        Hermite1D {
            t,
            p,
            m,
            pieces,
            scale,
        }
    }

    /// The piece of x: 0 left of t₀, i for [tᵢ₋₁, tᵢ], n right of tₙ₋₁.
    #[inline(always)]
    pub fn piece(&self, x: f64) -> usize {
        locate_scaled(&self.t, self.scale, x).index
    }

    /// Derivatives f, f′, f″, f‴ at `x` using the polynomial of piece `piece` (which need not contain x).
    #[inline(always)]
    pub fn derivs_on(&self, piece: usize, x: f64) -> [f64; 4] {
        let (x0, ih, c) = &self.pieces[piece];
        let s = (x - x0) * ih;
        poly_derivs(c, s, *ih)
    }

    /// f, f′, f″ at x.
    #[inline(always)]
    pub fn eval2(&self, x: f64) -> [f64; 3] {
        let d = self.derivs_on(self.piece(x), x);
        [d[0], d[1], d[2]]
    }

    /// Generic reference value.
    pub fn reference<D: Real>(&self, x: &D) -> D {
        let (i, w) = basis_weights(&self.t, x);
        let data = [self.p[i], self.p[i + 1], self.m[i], self.m[i + 1]];
        w.into_iter()
            .zip(data)
            .fold(D::from(0.0), |acc, (wk, dk)| acc + wk * dk)
    }
}

/// Value and first three derivatives of `Σ cⱼ sʲ` with respect to x, where ds/dx = `ih`.
#[inline(always)]
pub fn poly_derivs(c: &[f64; 4], s: f64, ih: f64) -> [f64; 4] {
    let v = ((c[3] * s + c[2]) * s + c[1]) * s + c[0];
    let d1 = ((3.0 * c[3]) * s + 2.0 * c[2]) * s + c[1];
    let d2 = 6.0 * c[3] * s + 2.0 * c[2];
    let d3 = 6.0 * c[3];
    [v, d1 * ih, d2 * ih * ih, d3 * ih * ih * ih]
}

/// A 2D bicubic Hermite spline on the tensor grid (tu, tv); arrays are stored with the v index outer:
/// entry (iv, iu) at `iv·|tu| + iu` (the original's layout).
#[derive(Clone, Debug)]
pub struct Hermite2D {
    /// knots along u (increasing)
    pub tu: Vec<f64>,
    /// knots along v (increasing)
    pub tv: Vec<f64>,
    /// values p at the knots
    pub p: Vec<f64>,
    /// slopes ∂p/∂u at the knots
    pub mu: Vec<f64>,
    /// slopes ∂p/∂v at the knots
    pub mv: Vec<f64>,
    /// twists ∂²p/∂u∂v at the knots
    pub muv: Vec<f64>,
    /// per (u piece, v piece), u piece inner: origins, 1/h and coefficients c[i][j] of sⁱ tʲ
    pieces: Vec<Piece2>,
    nu_pieces: usize,
    /// [`guess_scale`] of tu and tv
    scale_u: f64,
    scale_v: f64,
}

#[derive(Clone, Debug)]
struct Piece2 {
    u0: f64,
    ihu: f64,
    v0: f64,
    ihv: f64,
    c: [[f64; 4]; 4],
}

/// Derivatives ∂ᵃ_u ∂ᵇ_v of the 2D spline at one point, a ≤ 2, b ≤ 3: `d[a][b]`.
pub type Derivs2 = [[f64; 4]; 3];

/// A 2D spline restricted to one u position: the three polynomials in t = (v − v₀)/h_v of ∂ᵃ_u f, a = 0, 1, 2,
/// for each v piece being picked lazily. Used by the spectral (bending) terms, which evaluate many v at one u.
pub struct AtU<'a> {
    spline: &'a Hermite2D,
    upiece: usize,
    /// dᵃ/duᵃ of (1, s, s², s³) for a = 0, 1, 2, s = (u − u₀)/h_u on the u piece
    srow: [[f64; 4]; 3],
}

/// dᵃ/dxᵃ of the monomials (1, s, s², s³), a = 0, 1, 2, for s = (x − x₀)·`ih`.
#[inline(always)]
fn monomial_rows(s: f64, ih: f64) -> [[f64; 4]; 3] {
    let ih2 = ih * ih;
    [
        [1.0, s, s * s, s * s * s],
        [0.0, ih, 2.0 * s * ih, 3.0 * s * s * ih],
        [0.0, 0.0, 2.0 * ih2, 6.0 * s * ih2],
    ]
}

impl Hermite2D {
    /// Build from the grid and the four arrays (validated by the caller: sizes |tu|·|tv|, knots increasing).
    pub fn new(
        tu: Vec<f64>,
        tv: Vec<f64>,
        p: Vec<f64>,
        mu: Vec<f64>,
        mv: Vec<f64>,
        muv: Vec<f64>,
    ) -> Hermite2D {
        let (nu, nv) = (tu.len(), tv.len());
        assert!(nu >= 2 && nv >= 2, "Hermite2D: need two knots per axis");
        assert!(
            p.len() == nu * nv
                && mu.len() == nu * nv
                && mv.len() == nu * nv
                && muv.len() == nu * nv
        );
        let at = |a: &Vec<f64>, iu: usize, iv: usize| a[iv * nu + iu];
        let mut pieces = Vec::with_capacity((nu + 1) * (nv + 1));
        for jv in 0..=nv {
            for ju in 0..=nu {
                let pu = Piece {
                    index: ju,
                    cell: if ju == 0 { 0 } else { (ju - 1).min(nu - 2) },
                };
                let pv = Piece {
                    index: jv,
                    cell: if jv == 0 { 0 } else { (jv - 1).min(nv - 2) },
                };
                let bu = basis_piece(&tu, pu);
                let bv = basis_piece(&tv, pv);
                let (i, j) = (pu.cell, pv.cell);
                // data[a][b]: a over (p_i, p_{i+1}, slope_i, slope_{i+1}) in u, b likewise in v
                let mut data = [[0.0; 4]; 4];
                for (a, (iu, du)) in [(i, false), (i + 1, false), (i, true), (i + 1, true)]
                    .into_iter()
                    .enumerate()
                {
                    for (b, (iv, dv)) in [(j, false), (j + 1, false), (j, true), (j + 1, true)]
                        .into_iter()
                        .enumerate()
                    {
                        data[a][b] = match (du, dv) {
                            (false, false) => at(&p, iu, iv),
                            (true, false) => at(&mu, iu, iv),
                            (false, true) => at(&mv, iu, iv),
                            (true, true) => at(&muv, iu, iv),
                        };
                    }
                }
                // c = Wuᵀ · data · Wv
                let mut c = [[0.0; 4]; 4];
                for a in 0..4 {
                    for b in 0..4 {
                        let d = data[a][b];
                        if d == 0.0 {
                            continue;
                        }
                        for (ii, ci) in c.iter_mut().enumerate() {
                            let wa = bu.w[a][ii];
                            if wa == 0.0 {
                                continue;
                            }
                            for (jj, cij) in ci.iter_mut().enumerate() {
                                *cij += wa * d * bv.w[b][jj];
                            }
                        }
                    }
                }
                pieces.push(Piece2 {
                    u0: bu.origin,
                    ihu: 1.0 / bu.h,
                    v0: bv.origin,
                    ihv: 1.0 / bv.h,
                    c,
                });
            }
        }
        let (scale_u, scale_v) = (guess_scale(&tu), guess_scale(&tv));
        Hermite2D {
            tu,
            tv,
            p,
            mu,
            mv,
            muv,
            pieces,
            nu_pieces: nu + 1,
            scale_u,
            scale_v,
        }
    }

    /// Restrict to one u (for repeated evaluation along v).
    #[inline(always)]
    pub fn at_u(&self, u: f64) -> AtU<'_> {
        let upiece = locate_scaled(&self.tu, self.scale_u, u).index;
        self.at_u_piece(upiece, u)
    }

    /// Restrict to one u with the polynomial of u piece `upiece` (which need not contain u), for continuity
    /// checks across grid lines.
    #[inline(always)]
    pub fn at_u_piece(&self, upiece: usize, u: f64) -> AtU<'_> {
        let pc = &self.pieces[upiece];
        AtU {
            spline: self,
            upiece,
            srow: monomial_rows((u - pc.u0) * pc.ihu, pc.ihu),
        }
    }

    /// The piece of v along tv (as [`Hermite1D::piece`] along t).
    #[inline(always)]
    pub fn v_piece(&self, v: f64) -> usize {
        locate_scaled(&self.tv, self.scale_v, v).index
    }

    /// f, f_u, f_v, f_uu, f_uv, f_vv at (u, v).
    #[inline(always)]
    pub fn eval2(&self, u: f64, v: f64) -> [f64; 6] {
        self.at_u(u).low_on(self.v_piece(v), v)
    }

    /// Generic reference value (tensor product of the Hermite basis weights, extrapolation included).
    pub fn reference<D: Real>(&self, u: &D, v: &D) -> D {
        let nu = self.tu.len();
        let (i, wu) = basis_weights(&self.tu, u);
        let (j, wv) = basis_weights(&self.tv, v);
        let mut acc = D::from(0.0);
        for (a, wa) in wu.iter().enumerate() {
            let (iu, du) = [(i, false), (i + 1, false), (i, true), (i + 1, true)][a];
            for (b, wb) in wv.iter().enumerate() {
                let (iv, dv) = [(j, false), (j + 1, false), (j, true), (j + 1, true)][b];
                let arr = match (du, dv) {
                    (false, false) => &self.p,
                    (true, false) => &self.mu,
                    (false, true) => &self.mv,
                    (true, true) => &self.muv,
                };
                acc += wa.clone() * wb.clone() * arr[iv * nu + iu];
            }
        }
        acc
    }
}

impl AtU<'_> {
    /// The v piece of `v` (see [`Hermite2D::v_piece`]).
    #[inline(always)]
    pub fn v_piece_of(&self, v: f64) -> usize {
        self.spline.v_piece(v)
    }

    /// q_a(t) = ∂ᵃ_u f(u, v) on v piece `vpiece` as power-basis coefficients in t = (v − v₀)/h_v, a = 0, 1, 2:
    /// q_a[j] = Σᵢ c[i][j] dᵃ/duᵃ sⁱ. Returns them with v₀ and 1/h_v.
    #[inline(always)]
    fn rows_on(&self, vpiece: usize) -> ([[f64; 4]; 3], f64, f64) {
        let pc = &self.spline.pieces[vpiece * self.spline.nu_pieces + self.upiece];
        let [s0, s1, s2] = &self.srow;
        let c = &pc.c;
        // the rows' leading zeros skipped (s1[0] = s2[0] = s2[1] = 0)
        let q0 =
            std::array::from_fn(|j| c[0][j] + s0[1] * c[1][j] + s0[2] * c[2][j] + s0[3] * c[3][j]);
        let q1 = std::array::from_fn(|j| s1[1] * c[1][j] + s1[2] * c[2][j] + s1[3] * c[3][j]);
        let q2 = std::array::from_fn(|j| s2[2] * c[2][j] + s2[3] * c[3][j]);
        ([q0, q1, q2], pc.v0, pc.ihv)
    }

    /// `d[a][b]` = ∂ᵃ_u ∂ᵇ_v f(u, v) for a ≤ 2, b ≤ 3, using the polynomial of v piece `vpiece` (which need not
    /// contain v: the spectral terms evaluate one piece's polynomial at the mean eigenvalue).
    #[inline(always)]
    pub fn derivs_on(&self, vpiece: usize, v: f64) -> Derivs2 {
        let (q, v0, ihv) = self.rows_on(vpiece);
        let t = (v - v0) * ihv;
        [
            poly_derivs(&q[0], t, ihv),
            poly_derivs(&q[1], t, ihv),
            poly_derivs(&q[2], t, ihv),
        ]
    }

    /// Derivatives of total order ≤ 2 on v piece `vpiece`: (f, f_u, f_v, f_uu, f_uv, f_vv).
    #[inline(always)]
    pub fn low_on(&self, vpiece: usize, v: f64) -> [f64; 6] {
        let (q, v0, ihv) = self.rows_on(vpiece);
        let t = (v - v0) * ihv;
        let [q0, q1, q2] = q;
        let f = ((q0[3] * t + q0[2]) * t + q0[1]) * t + q0[0];
        let fu = ((q1[3] * t + q1[2]) * t + q1[1]) * t + q1[0];
        let fuu = ((q2[3] * t + q2[2]) * t + q2[1]) * t + q2[0];
        let fv = ((3.0 * q0[3] * t + 2.0 * q0[2]) * t + q0[1]) * ihv;
        let fuv = ((3.0 * q1[3] * t + 2.0 * q1[2]) * t + q1[1]) * ihv;
        let fvv = (6.0 * q0[3] * t + 2.0 * q0[2]) * ihv * ihv;
        [f, fu, fv, fuu, fuv, fvv]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample1d() -> Hermite1D {
        Hermite1D::new(
            vec![-1.0, -0.2, 0.5, 2.0],
            vec![3.0, 0.1, 0.4, 5.0],
            vec![-2.0, 0.3, 1.0, 4.0],
        )
    }

    #[test]
    fn fast_and_reference_agree_inside_and_outside() {
        let s = sample1d();
        for k in 0..=400 {
            let x = -3.0 + 7.0 * k as f64 / 400.0;
            let a = s.eval2(x)[0];
            let b = s.reference(&x);
            assert!(
                (a - b).abs() <= 1e-13 * (1.0 + b.abs()),
                "x={x}: {a} vs {b}"
            );
        }
    }

    #[test]
    fn linear_extrapolation_uses_end_slopes() {
        let s = sample1d();
        assert!((s.eval2(-2.0)[0] - (3.0 + 2.0)).abs() < 1e-14);
        assert_eq!(s.eval2(-2.0)[2], 0.0);
        assert!((s.eval2(3.0)[0] - (5.0 + 4.0)).abs() < 1e-14);
    }

    #[test]
    fn locate_agrees_with_bisection_on_uneven_knots() {
        let t = [-0.9, -0.85, -0.3, 0.0, 0.01, 0.5, 2.0];
        for k in 0..=3000 {
            let x = -0.9 + 2.9 * k as f64 / 3000.0;
            let cell = t.partition_point(|&tk| tk <= x).clamp(1, t.len() - 1) - 1;
            assert_eq!(locate(&t, x).cell, cell, "x = {x}");
        }
        for &x in &t {
            let cell = t.partition_point(|&tk| tk <= x).clamp(1, t.len() - 1) - 1;
            assert_eq!(locate(&t, x).cell, cell, "knot {x}");
        }
    }

    #[test]
    fn locate_handles_ends_and_nan() {
        let t = [0.0, 1.0, 2.0];
        assert_eq!(locate(&t, -0.1).index, 0);
        assert_eq!(locate(&t, 0.0).index, 1);
        assert_eq!(locate(&t, 1.0).index, 2);
        assert_eq!(locate(&t, 2.0).index, 2);
        assert_eq!(locate(&t, 2.1).index, 3);
        let _ = locate(&t, f64::NAN);
    }
}
