//! Step 7′ of FIT2D (`docs/fitting.md`, "Fitting (C5, C6, C7)", FIT2D step 7; the option
//! `hylc fit --compression-residual`): instead of zeroing the residual on the compressed half-plane of a stretch
//! axis, keep it there as a non-negative excess that is monotone outward from the axes.
//!
//! The knits couple compression with shear strongly (honeycomb: Ψ̄ = 320 J/m² at (s_x, s_a) = (−0.26, 0.75) where
//! the additive model gives 3.5), which step 7's zero-compression residual cannot represent. On the block of
//! knots with the stretch coordinate ≤ 0 (u ≤ 0 when u is the stretch axis, v ≤ 0 when v is):
//!
//! 1. the line of the stretch axis' knot 0 stays zero (p = pˣ = pʸ = pˣʸ = 0, as step 7 leaves it, so the
//!    tension side is the default's and the term is C¹ across it), and so does the other axis' line v = 0 (u = 0)
//!    inside the block: p and the slope along it are 0 there by step 6, and its slope across it is set to 0;
//! 2. every value is raised to ≥ 0 and to ≥ its inner neighbours along the row and the column (marching outward
//!    from the corner where the two zero lines cross); slopes pointing outward keep their sign or become 0;
//! 3. the slopes across the block's outer boundary and the twists there are 0 (step 8 applied first, so it
//!    changes nothing afterwards);
//! 4. Fritsch–Carlson along every row and column of the block; twists 0 at knots where the value and both slopes
//!    are 0 (minima of the non-negative excess); then every patch of the block is certified
//!    monotone outward in both directions (the certificate of step 5, here including the patches that touch the
//!    zero lines, whose data are zero), halving the twists of failing patches (up to 40 rounds) and then their
//!    cross slopes (up to 60 rounds; in the limit a patch with only values is monotone because its grid lines
//!    are).
//!
//! Along u the block's term then rises monotonically from the zero line outward, so it is ≥ 0 on the whole
//! compressed half-plane and beyond the knots (constant there): added to the 1D terms it raises ψ where the
//! samples couple, and never lowers it below f₀.

use super::{outward, Grid, PatchRounds};
use crate::fit::scalar::{FitScalar, KinkRule, Kinks};

/// The compressed block of a residual grid, as a grid of its own with the stretch axis first (u) and the zero
/// lines at its last column (u = 0) and at row `j0`.
struct Block<T> {
    grid: Grid<T>,
    j0: usize,
    /// whether the block is the transposed grid's (for the kink report's knot names)
    transposed: bool,
}

impl<T: FitScalar> Grid<T> {
    /// The transposed grid (u and v exchanged).
    fn transposed(&self) -> Grid<T> {
        let (nu, nv) = (self.tu.len(), self.tv.len());
        let zero = T::from(0.0);
        let mut t = Grid {
            tu: self.tv.clone(),
            tv: self.tu.clone(),
            p: vec![zero; nu * nv],
            mu: vec![zero; nu * nv],
            mv: vec![zero; nu * nv],
            muv: vec![zero; nu * nv],
        };
        for j in 0..nv {
            for i in 0..nu {
                let (k, kt) = (self.at(i, j), t.at(j, i));
                t.p[kt] = self.p[k];
                t.mu[kt] = self.mv[k];
                t.mv[kt] = self.mu[k];
                t.muv[kt] = self.muv[k];
            }
        }
        t
    }

    /// Columns `0..=i0` of the grid.
    fn left_block(&self, i0: usize) -> Grid<T> {
        let nv = self.tv.len();
        let mut b = Grid {
            tu: self.tu[..=i0].to_vec(),
            tv: self.tv.clone(),
            p: Vec::with_capacity((i0 + 1) * nv),
            mu: Vec::with_capacity((i0 + 1) * nv),
            mv: Vec::with_capacity((i0 + 1) * nv),
            muv: Vec::with_capacity((i0 + 1) * nv),
        };
        for j in 0..nv {
            for i in 0..=i0 {
                let k = self.at(i, j);
                b.p.push(self.p[k]);
                b.mu.push(self.mu[k]);
                b.mv.push(self.mv[k]);
                b.muv.push(self.muv[k]);
            }
        }
        b
    }

    /// Write `b` (columns `0..=i0`) back.
    fn put_left_block(&mut self, b: &Grid<T>) {
        for j in 0..b.tv.len() {
            for i in 0..b.tu.len() {
                let (k, kb) = (self.at(i, j), b.at(i, j));
                self.p[k] = b.p[kb];
                self.mu[k] = b.mu[kb];
                self.mv[k] = b.mv[kb];
                self.muv[k] = b.muv[kb];
            }
        }
    }
}

impl<T: FitScalar> Block<T> {
    /// Steps 1–3 on the block: zero lines, values raised outward, outward slope signs, zero boundary slopes.
    fn raise(&mut self, kinks: &mut Kinks) {
        let (nu, nv, j0) = (self.grid.tu.len(), self.grid.tv.len(), self.j0);
        let i0 = nu - 1;
        let zero = T::from(0.0);
        let transposed = self.transposed;
        let g = &mut self.grid;
        for j in 0..nv {
            let k = g.at(i0, j);
            (g.p[k], g.mu[k], g.mv[k], g.muv[k]) = (zero, zero, zero, zero);
        }
        for i in 0..nu {
            let k = g.at(i, j0);
            (g.p[k], g.mu[k], g.mv[k], g.muv[k]) = (zero, zero, zero, zero);
        }
        let (cv, cs) = (KinkRule::CompressionValue, KinkRule::CompressionSlope);
        for &j in &outward(nv, j0) {
            for i in (0..i0).rev() {
                // the knot's name in the term's grid
                let site = || {
                    if transposed {
                        format!("knot ({j}, {i})")
                    } else {
                        format!("knot ({i}, {j})")
                    }
                };
                let k = g.at(i, j);
                let v = kinks.max(g.p[k], zero, cv, site);
                let mut v = kinks.max(v, g.p[g.at(i + 1, j)], cv, site);
                g.mu[k] = kinks.min(g.mu[k], zero, cs, site);
                if j != j0 {
                    let jj = if j > j0 { j - 1 } else { j + 1 };
                    v = kinks.max(v, g.p[g.at(i, jj)], cv, site);
                    g.mv[k] = if j > j0 {
                        kinks.max(g.mv[k], zero, cs, site)
                    } else {
                        kinks.min(g.mv[k], zero, cs, site)
                    };
                }
                g.p[k] = v;
            }
        }
        // step 3: step 8 on the block (its last column is zero already)
        g.bound_extrapolation();
    }

    /// Twists 0 at the knots where the excess and both its slopes vanish. The excess is ≥ 0, so such a knot is
    /// a minimum: a twist there makes the patch ≈ twist · (u − uᵢ)(v − vⱼ) near it, negative in two quadrants
    /// (a row of zero knots left with twists of 1e-7 dipped to −1e-9 inside its patches, below the certificate's
    /// tolerance; found by `proptests/fit2d_compression.rs`).
    fn flat_knots_untwisted(&mut self) {
        let g = &mut self.grid;
        for k in 0..g.p.len() {
            if g.p[k].value() == 0.0 && g.mu[k].value() == 0.0 && g.mv[k].value() == 0.0 {
                g.muv[k] = T::from(0.0);
            }
        }
    }

    /// The patches failing the outward certificate: along u towards −u everywhere, along v away from row j0.
    fn failing(&self) -> Vec<((usize, usize), bool, bool)> {
        let g = &self.grid;
        let scale =
            g.p.iter()
                .fold(0.0f64, |m, v| m.max(v.value().abs()))
                .max(1e-300);
        let tol = 1e-10 * scale;
        let mut out = Vec::new();
        for cj in 0..g.tv.len() - 1 {
            let sv = if cj < self.j0 { -1.0 } else { 1.0 };
            for ci in 0..g.tu.len() - 1 {
                let (fu, fv) = g.patch_fails((ci, cj), Some(-1.0), Some(sv), tol);
                if fu || fv {
                    out.push(((ci, cj), fu, fv));
                }
            }
        }
        out
    }

    /// Step 4, patches: twists of failing patches halved (≤ 40 rounds), then their twists set to 0 and the cross
    /// slopes halved (≤ 60 rounds).
    fn monotone_patches(&mut self) -> PatchRounds {
        let mut rounds = PatchRounds::default();
        let mut failing = self.failing();
        while !failing.is_empty() && rounds.twist < 40 {
            rounds.twist += 1;
            for k in self.corner_set(&failing) {
                self.grid.muv[k] *= 0.5;
            }
            failing = self.failing();
        }
        while !failing.is_empty() && rounds.slope < 60 {
            rounds.slope += 1;
            let mut seen = std::collections::HashSet::new();
            for &(cell, fu, fv) in &failing {
                for (_, _, k) in self.grid.corners(cell) {
                    if !seen.insert((k, fu, fv)) {
                        continue;
                    }
                    self.grid.muv[k] = T::from(0.0);
                    if fu {
                        self.grid.mv[k] *= 0.5;
                    }
                    if fv {
                        self.grid.mu[k] *= 0.5;
                    }
                }
            }
            failing = self.failing();
        }
        rounds.nonmonotone = failing.len();
        rounds
    }

    /// The distinct corner indices of `failing`.
    fn corner_set(&self, failing: &[((usize, usize), bool, bool)]) -> Vec<usize> {
        let mut ks: Vec<usize> = failing
            .iter()
            .flat_map(|&(cell, _, _)| self.grid.corners(cell).map(|(_, _, k)| k))
            .collect();
        ks.sort_unstable();
        ks.dedup();
        ks
    }
}

impl<T: FitScalar> Grid<T> {
    /// Step 7′ on a residual grid about the knots u = 0 (`i0`) and v = 0 (`j0`): the compressed block of the
    /// stretch axis (`stretch[0]`: u; else `stretch[1]`: v) made a non-negative excess monotone outward from
    /// the zero lines; the rest as step 7 leaves it (zero on the knot line 0 of the stretch axis). A pair with
    /// two stretch axes gets step 7 (zeroed), one without any is unchanged. Returns the patch rounds of the block.
    pub(super) fn compression_excess(
        &mut self,
        stretch: [bool; 2],
        i0: usize,
        j0: usize,
        kinks: &mut Kinks,
    ) -> PatchRounds {
        let transpose = match stretch {
            [true, false] => false,
            [false, true] => true,
            _ => {
                self.zero_compression(stretch);
                return PatchRounds::default();
            }
        };
        let (mut work, c0, r0) = if transpose {
            (self.transposed(), j0, i0)
        } else {
            (self.clone(), i0, j0)
        };
        let mut block = Block {
            grid: work.left_block(c0),
            j0: r0,
            transposed: transpose,
        };
        block.raise(kinks);
        // step 4, grid lines: Fritsch–Carlson along every row and column, no knot exempt (the zero lines'
        // slopes are 0)
        block.grid.limit_lines(None, None, kinks);
        block.flat_knots_untwisted();
        let rounds = block.monotone_patches();
        work.put_left_block(&block.grid);
        *self = if transpose { work.transposed() } else { work };
        rounds
    }
}
