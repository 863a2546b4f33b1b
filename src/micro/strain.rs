//! The macro strain a micro solve is asked for (`03-homogenization.md`, section 1): z = (s_x, s_a, s_y, Π₀₀, Π₁₁),
//! checked against the admissible set before any work is done.

use serde::{Deserialize, Serialize};
use std::fmt;

pub use crate::strain::StrainComponent;

/// A macro strain z = (s_x, s_a, s_y, Π₀₀, Π₁₁): stretches along ξ₁ and ξ₂, the cosine of the angle between the
/// stretched material axes, and the curvatures (1/m) of bending along ξ₁ and along ξ₂.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MacroStrain(pub [f64; 5]);

/// Which closed-form surface map embeds the tile (`03-homogenization.md`, section 1). `BendY` with Π₁₁ = 0 is
/// exactly the in-plane map φ = F ξ; `BendX` with Π₀₀ = 0 is the in-plane map rotated in the plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Family {
    /// Cylinder with rulings along ξ₂, curvature Π₀₀ along ξ₁.
    BendX,
    /// Cylinder with rulings along ξ₁, curvature Π₁₁ along ξ₂ (the plane when Π₁₁ = 0).
    BendY,
}

/// A strain outside the set the micro solver supports.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("strain {strain}: {message}")]
pub struct StrainError {
    pub strain: MacroStrain,
    pub message: String,
}

impl fmt::Display for MacroStrain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let z = self.0;
        write!(
            f,
            "(s_x {}, s_a {}, s_y {}, II00 {}, II11 {})",
            z[0], z[1], z[2], z[3], z[4]
        )
    }
}

impl MacroStrain {
    pub const ZERO: MacroStrain = MacroStrain([0.0; 5]);

    pub fn new(s_x: f64, s_a: f64, s_y: f64, ii00: f64, ii11: f64) -> Self {
        MacroStrain([s_x, s_a, s_y, ii00, ii11])
    }

    /// In-plane strain (s_x, s_a, s_y).
    pub fn in_plane(s_x: f64, s_a: f64, s_y: f64) -> Self {
        MacroStrain([s_x, s_a, s_y, 0.0, 0.0])
    }

    /// Check the strain: finite, 1 + s_x > 0, 1 + s_y > 0, |s_a| < 1, and at most one bending non-zero.
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
        if 1.0 + z[0] <= 0.0 {
            return err(format!("1 + s_x = {} must be positive", 1.0 + z[0]));
        }
        if 1.0 + z[2] <= 0.0 {
            return err(format!("1 + s_y = {} must be positive", 1.0 + z[2]));
        }
        if z[1].abs() >= 1.0 {
            return err(format!(
                "|s_a| = {} must be below 1 (s_a is the cosine of the angle between the material axes)",
                z[1].abs()
            ));
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

    /// The first fundamental form Ī = [[a², abc], [abc, b²]] (a = 1 + s_x, b = 1 + s_y, c = s_a).
    pub fn first_fundamental_form(&self) -> [[f64; 2]; 2] {
        let (a, b, c) = (1.0 + self.0[0], 1.0 + self.0[2], self.0[1]);
        [[a * a, a * b * c], [a * b * c, b * b]]
    }

    /// The smaller eigenvalue of Ī (the displacement limit of `03-homogenization.md`, section 4).
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
    fn eigenvalue_of_first_fundamental_form() {
        let z = MacroStrain::in_plane(0.2, 0.3, -0.1);
        let [[p, q], [_, r]] = z.first_fundamental_form();
        let l = z.min_stretch_eigenvalue();
        let det = (p - l) * (r - l) - q * q;
        assert!(det.abs() < 1e-12, "{det}");
        assert!(l > 0.0 && l < p.min(r));
    }
}
