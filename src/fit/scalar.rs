//! The scalar of the fit's numerical core (`docs/sensitivities.md`, "The tangent of the fit"): FIT1D and FIT2D
//! are written once for any [`FitScalar`], `f64` (the fit itself) or [`Dual64`] (its directional derivative). Every
//! discrete decision of the fit (which argument of a max or min, the argmin of a minimum knot, the sign tests and
//! caps of the monotone limiters, the patch certificate) is taken on the real parts, so a dual pass follows exactly
//! the branch the `f64` fit took and its derivative part is the tangent of that branch. The `f64` instances of
//! [`FitScalar::max_of`], [`FitScalar::min_of`] and [`FitScalar::copysign_of`] are the standard library's, so the
//! `f64` fit computes bit for bit what it computed before it was generic.
//!
//! [`Kinks`] records the decisions that sit at (within a relative 1e-9 of) their switching point and whose two
//! branches have different tangents in the direction of the pass: there the derivative is one-sided.

use crate::real::Real;
use num_dual::Dual64;

/// A scalar the fit runs on: `f64` or [`Dual64`].
pub trait FitScalar: Real + Copy {
    /// The real part.
    fn value(self) -> f64;
    /// The derivative part (0 for `f64`).
    fn tangent(self) -> f64;
    /// The parts of a slice, one vector per part (real part first): a linear map applied to each part and
    /// reassembled by [`FitScalar::from_parts`] is the map applied to the scalars.
    fn parts(xs: &[Self]) -> Vec<Vec<f64>>;
    /// The scalar with these parts (as many as [`FitScalar::parts`] gives).
    fn from_parts(parts: &[f64]) -> Self;
    /// max(a, b), the branch chosen on the real parts (`f64::max` for `f64`).
    fn max_of(self, b: Self) -> Self;
    /// min(a, b), the branch chosen on the real parts (`f64::min` for `f64`).
    fn min_of(self, b: Self) -> Self;
    /// |a| with the sign of `s`'s real part (`f64::copysign` for `f64`).
    fn copysign_of(self, s: f64) -> Self;
    /// a / b with the real part computed as `a.re / b.re` (num-dual's quotient multiplies by the reciprocal,
    /// which can differ in the last bit).
    fn quot(self, b: Self) -> Self;
}

impl FitScalar for f64 {
    fn value(self) -> f64 {
        self
    }
    fn tangent(self) -> f64 {
        0.0
    }
    fn parts(xs: &[f64]) -> Vec<Vec<f64>> {
        vec![xs.to_vec()]
    }
    fn from_parts(parts: &[f64]) -> f64 {
        parts[0]
    }
    fn max_of(self, b: f64) -> f64 {
        self.max(b)
    }
    fn min_of(self, b: f64) -> f64 {
        self.min(b)
    }
    fn copysign_of(self, s: f64) -> f64 {
        self.copysign(s)
    }
    fn quot(self, b: f64) -> f64 {
        self / b
    }
}

impl FitScalar for Dual64 {
    fn value(self) -> f64 {
        self.re
    }
    fn tangent(self) -> f64 {
        self.eps
    }
    fn parts(xs: &[Dual64]) -> Vec<Vec<f64>> {
        vec![
            xs.iter().map(|x| x.re).collect(),
            xs.iter().map(|x| x.eps).collect(),
        ]
    }
    fn from_parts(parts: &[f64]) -> Dual64 {
        Dual64::new(parts[0], parts[1])
    }
    fn max_of(self, b: Dual64) -> Dual64 {
        if b.re > self.re {
            b
        } else {
            self
        }
    }
    fn min_of(self, b: Dual64) -> Dual64 {
        if b.re < self.re {
            b
        } else {
            self
        }
    }
    fn copysign_of(self, s: f64) -> Dual64 {
        // |a| = a sgn(a.re); the sign of a zero real part is taken from its bit, as f64::copysign does
        let a = if self.re.is_sign_negative() {
            -self
        } else {
            self
        };
        if s.is_sign_negative() {
            -a
        } else {
            a
        }
    }
    fn quot(self, b: Dual64) -> Dual64 {
        let q = self.re / b.re;
        Dual64::new(q, (self.eps - q * b.eps) / b.re)
    }
}

/// `f` (linear in its argument) applied to the scalars `ys`, part by part: Σᵢ ℓᵢ yᵢ with ℓ the weights of `f`.
pub(crate) fn linear<T: FitScalar>(parts: &[Vec<f64>], f: impl Fn(&[f64]) -> f64) -> T {
    let v: Vec<f64> = parts.iter().map(|y| f(y)).collect();
    T::from_parts(&v)
}

/// The relative distance below which a decision counts as at its switching point.
pub const KINK_REL: f64 = 1e-9;

/// The rule of a decision of the fit whose derivative is one-sided at a kink.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum KinkRule {
    /// ε = eps_rel · max|Ψ̄| of the symlog: the largest |Ψ̄| is shared by two samples
    SymlogScale,
    /// the minimum knot i_min = argmin p (bending): two knot values tie
    MinimumKnot,
    /// quasi-convexification: a value tied with its inner neighbour + Δt pˣ_min
    QuasiConvexValue,
    /// quasi-convexification: an outward slope tied with ±pˣ_min
    QuasiConvexSlope,
    /// increasing extrapolation: an end or boundary slope tied with ±pˣ_min
    EndSlope,
    /// Fritsch–Carlson: |slope| tied with 3 |secant| of an adjacent cell
    FritschCarlsonCap,
    /// Fritsch–Carlson: the sign test of a slope (slope or secant at 0)
    FritschCarlsonSign,
    /// patch repair: a halved cross slope tied with pˣ_min
    CrossSlopeFloor,
    /// compression excess (step 7′): a value tied with 0 or with an inner neighbour
    CompressionValue,
    /// compression excess (step 7′): an outward slope at 0
    CompressionSlope,
}

impl KinkRule {
    /// What the rule is, in words.
    pub fn describe(self) -> &'static str {
        match self {
            KinkRule::SymlogScale => {
                "symlog ε = eps_rel · max|Ψ̄|: two samples share the largest |Ψ̄|"
            }
            KinkRule::MinimumKnot => "minimum knot argmin p: two knot values tie",
            KinkRule::QuasiConvexValue => {
                "quasi-convexification: p = max(p, inner neighbour + Δt pˣ_min) at a tie"
            }
            KinkRule::QuasiConvexSlope => "quasi-convexification: outward slope = ±pˣ_min",
            KinkRule::EndSlope => "increasing extrapolation: end slope = ±pˣ_min",
            KinkRule::FritschCarlsonCap => "Fritsch–Carlson: |slope| = 3 |secant|",
            KinkRule::FritschCarlsonSign => "Fritsch–Carlson: sign test at a zero slope or secant",
            KinkRule::CrossSlopeFloor => "patch repair: halved cross slope = pˣ_min",
            KinkRule::CompressionValue => {
                "compression excess: value = max(0, inner neighbours) at a tie"
            }
            KinkRule::CompressionSlope => "compression excess: outward slope sign at 0",
        }
    }
}

/// One decision at its switching point: the term, the rule, where (a knot `knot i` or `knot (i, j)` of the term's
/// grid, a cell, or a sample by its plan index), and the two values compared.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Kink {
    /// the term (e.g. `1D term 0 (s_x)`)
    pub term: String,
    /// the rule that decided
    pub rule: KinkRule,
    /// where: a knot, a cell or a sample
    pub site: String,
    /// the two values compared
    pub values: [f64; 2],
}

impl std::fmt::Display for Kink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}, {}: {} ({:e} vs {:e})",
            self.term,
            self.site,
            self.rule.describe(),
            self.values[0],
            self.values[1]
        )
    }
}

/// The kinks of a tangent pass.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct KinkReport {
    /// the kinks, in the order of the fit
    pub kinks: Vec<Kink>,
}

impl KinkReport {
    /// No decision sits at its switching point: the tangent is the derivative.
    pub fn is_empty(&self) -> bool {
        self.kinks.is_empty()
    }

    /// Add the kinks of another pass that are not listed yet (same term, rule and site).
    pub fn merge(&mut self, other: KinkReport) {
        for k in other.kinks {
            if !self
                .kinks
                .iter()
                .any(|e| e.term == k.term && e.rule == k.rule && e.site == k.site)
            {
                self.kinks.push(k);
            }
        }
    }
}

/// The recorder of one pass: off for the `f64` fit, on for a tangent pass, with the name of the term being fitted.
#[derive(Debug, Default)]
pub(crate) struct Kinks {
    on: bool,
    term: String,
    pub(crate) found: Vec<Kink>,
}

impl Kinks {
    /// A recorder that records nothing (the `f64` fit).
    pub(crate) fn off() -> Kinks {
        Kinks::default()
    }

    /// A recorder for the term named `term`.
    pub(crate) fn on(term: &str) -> Kinks {
        Kinks {
            on: true,
            term: term.to_string(),
            found: Vec::new(),
        }
    }

    /// Record a decision between `a` and `b` (switching where they are equal) when their real parts are within
    /// a relative [`KINK_REL`] (|a − b| ≤ 1e-9 max(|a|, |b|); exact equality for zeros) and their tangents differ.
    pub(crate) fn tie<T: FitScalar>(
        &mut self,
        a: T,
        b: T,
        rule: KinkRule,
        site: impl FnOnce() -> String,
    ) {
        if !self.on {
            return;
        }
        let (x, y) = (a.value(), b.value());
        let near = (x - y).abs() <= KINK_REL * x.abs().max(y.abs());
        let (tx, ty) = (a.tangent(), b.tangent());
        let differ = (tx - ty).abs() > 1e-12 * tx.abs().max(ty.abs());
        if near && differ {
            self.found.push(Kink {
                term: self.term.clone(),
                rule,
                site: site(),
                values: [x, y],
            });
        }
    }

    /// max(a, b) ([`FitScalar::max_of`]), recording a tie.
    pub(crate) fn max<T: FitScalar>(
        &mut self,
        a: T,
        b: T,
        rule: KinkRule,
        site: impl FnOnce() -> String,
    ) -> T {
        self.tie(a, b, rule, site);
        a.max_of(b)
    }

    /// min(a, b) ([`FitScalar::min_of`]), recording a tie.
    pub(crate) fn min<T: FitScalar>(
        &mut self,
        a: T,
        b: T,
        rule: KinkRule,
        site: impl FnOnce() -> String,
    ) -> T {
        self.tie(a, b, rule, site);
        a.min_of(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dual_branches_follow_the_real_parts() {
        let a = Dual64::new(1.0, 2.0);
        let b = Dual64::new(3.0, -1.0);
        assert_eq!(a.max_of(b), b);
        assert_eq!(a.min_of(b), a);
        assert_eq!(b.copysign_of(-0.0), Dual64::new(-3.0, 1.0));
        assert_eq!(
            Dual64::new(-2.0, 5.0).copysign_of(1.0),
            Dual64::new(2.0, -5.0)
        );
        let q = a.quot(b);
        assert_eq!(q.re, 1.0 / 3.0);
        assert!((q.eps - (2.0 * 3.0 + 1.0) / 9.0).abs() < 1e-15);
        let mut k = Kinks::on("t");
        k.tie(
            Dual64::new(1.0, 1.0),
            Dual64::new(1.0 + 1e-10, 0.0),
            KinkRule::EndSlope,
            || "knot 0".into(),
        );
        k.tie(
            Dual64::new(1.0, 1.0),
            Dual64::new(1.0 + 1e-8, 0.0),
            KinkRule::EndSlope,
            || "knot 1".into(),
        );
        k.tie(
            Dual64::new(0.0, 0.0),
            Dual64::new(0.0, 0.0),
            KinkRule::EndSlope,
            || "knot 2".into(),
        );
        assert_eq!(k.found.len(), 1);
        assert_eq!(k.found[0].site, "knot 0");
    }
}
