//! Strain components by name (`docs/micro-solver.md`, section 1; `docs/cloth-simulator.md`, "Strains").
//!
//! The micro problem and the material's terms know five components, z = (s_x, s_a, s_y, Π₀₀, Π₁₁): the stretches
//! along ξ₁ and ξ₂, the cosine of the angle between the stretched material axes, and the curvatures of bending
//! along ξ₁ and along ξ₂. The shell's strain has six, z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁) ([`Strain6`]): the
//! mixed curvature II₀₁ sits between the two bending components, so the index of Π₁₁ is 4 in the first and 5 in
//! the second — [`StrainComponent::index`] and [`StrainComponent::index6`] keep the two apart.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// A number for an error message or a strain's display: Rust's shortest round-trip form, in exponent notation
/// from |x| ≥ 1e15 on (so that 1e300 is not printed with 300 digits). No admissible strain is that large, so
/// the display of valid strains is unchanged.
pub fn compact(x: f64) -> String {
    if x.is_finite() && x.abs() >= 1e15 {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// One of the five strain components of the micro problem, a sampling plan and a material's terms. Serialised
/// (and parsed) by its name: `s_x`, `s_a`, `s_y`, `II00`, `II11`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum StrainComponent {
    /// s_x: the stretch along ξ₁.
    #[serde(rename = "s_x")]
    Sx,
    /// s_a: the cosine of the angle between the stretched material axes.
    #[serde(rename = "s_a")]
    Sa,
    /// s_y: the stretch along ξ₂.
    #[serde(rename = "s_y")]
    Sy,
    /// Π₀₀ (II₀₀): the curvature of bending along ξ₁ (1/m).
    #[serde(rename = "II00")]
    II00,
    /// Π₁₁ (II₁₁): the curvature of bending along ξ₂ (1/m).
    #[serde(rename = "II11")]
    II11,
}

impl StrainComponent {
    /// All five, in the order of z.
    pub const ALL: [StrainComponent; 5] = [Self::Sx, Self::Sa, Self::Sy, Self::II00, Self::II11];
    /// The three in-plane components.
    pub const IN_PLANE: [StrainComponent; 3] = [Self::Sx, Self::Sa, Self::Sy];
    /// Their names, in the order of z.
    pub const NAMES: [&'static str; 5] = ["s_x", "s_a", "s_y", "II00", "II11"];

    /// The position in the five-component z (micro strain, sample records, the material's σ and terms).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The position in the shell's six-component z ([`Strain6`]).
    pub fn index6(self) -> usize {
        match self {
            Self::II11 => 5,
            c => c as usize,
        }
    }

    /// The component at `index` of the five-component z.
    pub fn from_index(index: usize) -> Option<Self> {
        Self::ALL.get(index).copied()
    }

    /// Its name (`s_x`, `s_a`, `s_y`, `II00`, `II11`).
    pub fn name(self) -> &'static str {
        Self::NAMES[self.index()]
    }

    /// A stretch or shear (not a bending).
    pub fn is_in_plane(self) -> bool {
        self.index() <= 2
    }
}

impl fmt::Display for StrainComponent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

/// A name that is not a strain component.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown strain {name:?} (expected one of s_x, s_a, s_y, II00, II11)")]
pub struct UnknownStrain {
    /// the name given
    pub name: String,
}

impl FromStr for StrainComponent {
    type Err = UnknownStrain;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| UnknownStrain { name: s.into() })
    }
}

/// The shell's strain z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁), the argument of a material's ψ(z).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Strain6(pub [f64; 6]);

/// Why a text is not a [`Strain6`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Strain6Error {
    /// The text does not have 6 numbers (the count found).
    #[error("expected 6 numbers (s_x, s_a, s_y, II00, II01, II11), found {0}")]
    Count(usize),
    #[error("{name} = {text:?} is not a number")]
    /// A component that is not a number.
    NotANumber {
        /// the component's name
        name: &'static str,
        /// its text
        text: String,
    },
    #[error("{name} = {text} is not finite")]
    /// A component that is not finite.
    NotFinite {
        /// the component's name
        name: &'static str,
        /// its text
        text: String,
    },
}

impl Strain6 {
    /// The names of the six components, in order.
    pub const NAMES: [&'static str; 6] = ["s_x", "s_a", "s_y", "II00", "II01", "II11"];
}

impl FromStr for Strain6 {
    type Err = Strain6Error;

    /// Six finite numbers separated by commas and/or whitespace.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let parts: Vec<&str> = text
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        if parts.len() != 6 {
            return Err(Strain6Error::Count(parts.len()));
        }
        let mut z = [0.0; 6];
        for (i, p) in parts.iter().enumerate() {
            let name = Self::NAMES[i];
            let v: f64 = p.parse().map_err(|_| Strain6Error::NotANumber {
                name,
                text: p.to_string(),
            })?;
            if !v.is_finite() {
                return Err(Strain6Error::NotFinite {
                    name,
                    text: p.to_string(),
                });
            }
            z[i] = v;
        }
        Ok(Strain6(z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_indices_and_parsing_agree() {
        for (i, c) in StrainComponent::ALL.into_iter().enumerate() {
            assert_eq!(c.index(), i);
            assert_eq!(StrainComponent::from_index(i), Some(c));
            assert_eq!(c.name().parse::<StrainComponent>(), Ok(c));
            assert_eq!(Strain6::NAMES[c.index6()], c.name());
            assert_eq!(serde_json::to_string(&c).unwrap(), format!("\"{c}\""));
        }
        assert_eq!(StrainComponent::II11.index(), 4);
        assert_eq!(
            format!("{:<6}|{:>5}", StrainComponent::Sx, StrainComponent::II00),
            "s_x   | II00"
        );
        assert_eq!(StrainComponent::II11.index6(), 5);
        assert_eq!(StrainComponent::from_index(5), None);
        assert!("II01".parse::<StrainComponent>().is_err());
        assert!(serde_json::from_str::<StrainComponent>("\"s_z\"").is_err());
    }

    #[test]
    fn strain6_parses_six_finite_numbers() {
        let z: Strain6 = "0.1, -0.2 0.3,4,5 6".parse().unwrap();
        assert_eq!(z.0, [0.1, -0.2, 0.3, 4.0, 5.0, 6.0]);
        assert_eq!("1,2,3".parse::<Strain6>(), Err(Strain6Error::Count(3)));
        let e = "1,2,3,4,x,6".parse::<Strain6>().unwrap_err();
        assert_eq!(e.to_string(), "II01 = \"x\" is not a number");
        let e = "1,2,3,4,5,inf".parse::<Strain6>().unwrap_err();
        assert_eq!(e.to_string(), "II11 = inf is not finite");
    }
}
