//! The macro strain a micro solve is asked for (`docs/micro-solver.md`, section 1): z = (s_x, s_a, s_y, Π₀₀, Π₁₁),
//! checked against the admissible set before any work is done.

use serde::{Deserialize, Serialize};
use std::fmt;

use crate::strain::compact;
pub use crate::strain::StrainComponent;

/// A macro strain z = (s_x, s_a, s_y, Π₀₀, Π₁₁): stretches along ξ₁ and ξ₂, the cosine of the angle between the
/// stretched material axes, and the curvatures (1/m) of bending along ξ₁ and along ξ₂.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MacroStrain(pub [f64; 5]);

/// Which closed-form surface map embeds the tile (`docs/micro-solver.md`, section 1). `BendY` with Π₁₁ = 0 is
/// exactly the in-plane map φ = F ξ; `BendX` with Π₀₀ = 0 is the in-plane map rotated in the plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Family {
    /// Cylinder with rulings along ξ₂, curvature Π₀₀ along ξ₁.
    BendX,
    /// Cylinder with rulings along ξ₁, curvature Π₁₁ along ξ₂ (the plane when Π₁₁ = 0).
    BendY,
}

/// Smallest admissible stretch 1 + s_x, 1 + s_y: a tenth of the rest length. Every built-in sampling plan and
/// every plan under `validation/plans` stays above 0.34 (s ≥ −0.66); below a tenth, the yarns of any pattern whose
/// neighbours lie within ten radii of each other overlap across their whole cross-sections, and the start phase's
/// displacement limit r λ_min(Ī) shrinks with the square of the stretch.
pub const MIN_STRETCH: f64 = 0.1;

/// Largest admissible stretch 1 + s_x, 1 + s_y: ten times the rest length. The plans reach 1.99 (s ≤ 0.99); a
/// yarn-level tile pulled ten times its length is far past any yarn's breaking strain. The bound also bounds the
/// work of the start phase, which moves a state to its strain in steps of at most 0.05 (at most 180 steps).
pub const MAX_STRETCH: f64 = 10.0;

/// Largest admissible |Π₀₀|, |Π₁₁| (1/m), whatever the pattern: the inverse of the smallest plausible yarn radius
/// ([`crate::pattern::pyp::MIN_RADIUS`], 1 µm). The plans reach 230 1/m. A pattern's own, tighter bound is
/// [`MAX_CURVATURE_RADIUS`] / r ([`MacroStrain::validate_for_radius`]).
pub const MAX_CURVATURE: f64 = 1e6;

/// Largest admissible |Π| r of a pattern of yarn radius r: the bending radius 1/|Π| may not be smaller than the
/// yarn radius (the yarns of a tile, several radii thick, would be folded through themselves). The plans reach
/// 230 1/m · 1 mm = 0.23 on the original patterns. The start phase moves curvature in steps of 0.125 / p_max, so
/// this bound keeps it within 8 p_max / r steps.
pub const MAX_CURVATURE_RADIUS: f64 = 1.0;

/// A strain outside the set the micro solver supports.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("strain {strain}: {message}")]
pub struct StrainError {
    /// the strain
    pub strain: MacroStrain,
    /// why it is outside the set
    pub message: String,
}

impl fmt::Display for MacroStrain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let z = self.0;
        let [a, b, c, d, e] = z.map(compact);
        write!(f, "(s_x {a}, s_a {b}, s_y {c}, II00 {d}, II11 {e})")
    }
}

impl MacroStrain {
    /// The zero strain.
    pub const ZERO: MacroStrain = MacroStrain([0.0; 5]);

    /// The strain (s_x, s_a, s_y, Π₀₀, Π₁₁).
    pub fn new(s_x: f64, s_a: f64, s_y: f64, ii00: f64, ii11: f64) -> Self {
        MacroStrain([s_x, s_a, s_y, ii00, ii11])
    }

    /// In-plane strain (s_x, s_a, s_y).
    pub fn in_plane(s_x: f64, s_a: f64, s_y: f64) -> Self {
        MacroStrain([s_x, s_a, s_y, 0.0, 0.0])
    }

    /// Check the strain: finite, 1 + s_x and 1 + s_y in [[`MIN_STRETCH`], [`MAX_STRETCH`]], |s_a| < 1,
    /// |Π₀₀|, |Π₁₁| ≤ [`MAX_CURVATURE`], and at most one bending non-zero (`docs/micro-solver.md`, section 1).
    pub fn validate(&self) -> Result<Family, StrainError> {
        let z = self.0;
        let err = |m: String| {
            Err(StrainError {
                strain: *self,
                message: m,
            })
        };
        if let Some(k) = z.iter().position(|v| !v.is_finite()) {
            return err(format!("{} is not finite", StrainComponent::NAMES[k]));
        }
        for k in [0, 2] {
            let stretch = 1.0 + z[k];
            if !(MIN_STRETCH..=MAX_STRETCH).contains(&stretch) {
                return err(format!(
                    "{} = {}: the stretch 1 + {0} = {} must lie in [{MIN_STRETCH}, {MAX_STRETCH}]",
                    StrainComponent::NAMES[k],
                    compact(z[k]),
                    compact(stretch)
                ));
            }
        }
        if z[1].abs() >= 1.0 {
            return err(format!(
                "|s_a| = {} must be below 1 (s_a is the cosine of the angle between the material axes)",
                z[1].abs()
            ));
        }
        for k in [3, 4] {
            if z[k].abs() > MAX_CURVATURE {
                return err(format!(
                    "{} = {} 1/m: |{0}| must be at most {MAX_CURVATURE:e} 1/m",
                    StrainComponent::NAMES[k],
                    compact(z[k])
                ));
            }
        }
        if z[3] != 0.0 && z[4] != 0.0 {
            return err(
                "bending along both ξ₁ and ξ₂ at once is not supported (one of II00, II11 must be 0)".into(),
            );
        }
        Ok(if z[3] != 0.0 {
            Family::BendX
        } else {
            Family::BendY
        })
    }

    /// [`MacroStrain::validate`], then the pattern's curvature bound |Π| r ≤ [`MAX_CURVATURE_RADIUS`] for a yarn
    /// radius `radius` (m).
    pub fn validate_for_radius(&self, radius: f64) -> Result<Family, StrainError> {
        let family = self.validate()?;
        for k in [3, 4] {
            let kr = self.0[k].abs() * radius;
            if kr > MAX_CURVATURE_RADIUS {
                return Err(StrainError {
                    strain: *self,
                    message: format!(
                        "{} = {} 1/m: |{0}| r = {kr} must be at most {MAX_CURVATURE_RADIUS} for the yarn radius \
                         r = {radius} m (a bending radius below the yarn radius)",
                        StrainComponent::NAMES[k],
                        self.0[k]
                    ),
                });
            }
        }
        Ok(family)
    }

    /// The first fundamental form Ī = [[a², abc], [abc, b²]] (a = 1 + s_x, b = 1 + s_y, c = s_a).
    pub fn first_fundamental_form(&self) -> [[f64; 2]; 2] {
        let (a, b, c) = (1.0 + self.0[0], 1.0 + self.0[2], self.0[1]);
        [[a * a, a * b * c], [a * b * c, b * b]]
    }

    /// The smaller eigenvalue of Ī (the displacement limit of `docs/micro-solver.md`, section 4).
    pub fn min_stretch_eigenvalue(&self) -> f64 {
        let [[p, q], [_, r]] = self.first_fundamental_form();
        let m = 0.5 * (p + r);
        let d = (0.25 * (p - r) * (p - r) + q * q).sqrt();
        m - d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn admissible_set() {
        assert_eq!(MacroStrain::ZERO.validate(), Ok(Family::BendY));
        assert_eq!(
            MacroStrain::new(0.1, 0.2, -0.1, 30.0, 0.0).validate(),
            Ok(Family::BendX)
        );
        assert_eq!(
            MacroStrain::new(0.1, 0.2, -0.1, 0.0, -30.0).validate(),
            Ok(Family::BendY)
        );
        for bad in [
            MacroStrain::new(-1.0, 0.0, 0.0, 0.0, 0.0),
            MacroStrain::new(0.0, 0.0, -1.5, 0.0, 0.0),
            MacroStrain::new(0.0, 1.0, 0.0, 0.0, 0.0),
            MacroStrain::new(0.0, -1.0, 0.0, 0.0, 0.0),
            MacroStrain::new(0.0, 0.0, 0.0, 1.0, 1.0),
            MacroStrain::new(f64::NAN, 0.0, 0.0, 0.0, 0.0),
        ] {
            let e = bad.validate().unwrap_err();
            assert!(!e.message.is_empty(), "{e}");
        }
    }

    #[test]
    fn absurd_strains_are_rejected_naming_the_component() {
        for (bad, name) in [
            (MacroStrain::new(1e6, 0.0, 0.0, 0.0, 0.0), "s_x"),
            (MacroStrain::new(1e300, 0.0, 0.0, 0.0, 0.0), "s_x"),
            (MacroStrain::new(0.0, 0.0, 9.5, 0.0, 0.0), "s_y"),
            (MacroStrain::new(0.0, 0.0, -0.95, 0.0, 0.0), "s_y"),
            (
                MacroStrain::new(0.0, 0.0, 0.0, 1e12, 0.0),
                StrainComponent::NAMES[3],
            ),
            (
                MacroStrain::new(0.0, 0.0, 0.0, 0.0, -2e6),
                StrainComponent::NAMES[4],
            ),
        ] {
            let e = bad.validate().unwrap_err();
            assert!(e.message.starts_with(name), "{e}");
        }
        assert!(MacroStrain::new(9.0, 0.0, -0.89, 0.0, 0.0)
            .validate()
            .is_ok());
        let bent = MacroStrain::new(0.0, 0.0, 0.0, 900.0, 0.0);
        assert!(bent.validate_for_radius(1e-3).is_ok());
        let e = bent.validate_for_radius(2e-3).unwrap_err();
        assert!(e.message.contains("yarn radius"), "{e}");
    }

    #[test]
    fn every_built_in_and_validation_plan_is_admissible() {
        use crate::sample::Plan;
        let mut plans = vec![
            ("default".to_string(), Plan::default()),
            ("reduced".into(), Plan::reduced()),
            ("quick".into(), Plan::quick()),
            ("holdout".into(), Plan::holdout()),
        ];
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/validation/plans");
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            let plan = Plan::from_json(&text, Some(&path.display().to_string())).unwrap();
            plans.push((path.display().to_string(), plan));
        }
        assert!(plans.len() >= 14);
        for (name, plan) in &plans {
            for s in plan.samples() {
                // the original patterns' radius, about 1 mm
                if let Err(e) = MacroStrain(s.z).validate_for_radius(1.001e-3) {
                    panic!("{name}: {e}");
                }
            }
        }
    }

    #[test]
    fn eigenvalue_of_first_fundamental_form() {
        let z = MacroStrain::in_plane(0.2, 0.3, -0.1);
        let [[p, q], [_, r]] = z.first_fundamental_form();
        let l = z.min_stretch_eigenvalue();
        let det = (p - l) * (r - l) - q * q;
        assert!(det.abs() < 1e-12, "{det}");
        assert!(l > 0.0 && l < p.min(r));
    }
}
