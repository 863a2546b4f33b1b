//! Yarn material parameters (`../shared/design/02-yarn-model.md`, "Discrete elastic rods" and "Yarn-yarn
//! contact"): one struct that every yarn energy takes by reference.

/// Parameters of the yarn model. Defaults are the calibrated values (see the README's calibration table):
/// Y = 1e6 Pa, G/Y = 0.4, γ = 0.1, r = 1 mm, ρ = 120 kg/m³, Kaldor contact with k_c = 76 J/m², 4 Gauss–Legendre
/// points per segment and 3 excluded neighbour segments on each side.
#[derive(Clone, Debug, PartialEq)]
pub struct YarnMaterial {
    /// Young's modulus Y (Pa).
    pub young: f64,
    /// Shear modulus G (Pa).
    pub shear: f64,
    /// Factor γ on the bending and twisting stiffness of a solid rod (yarns are fibre bundles).
    pub bend_twist_factor: f64,
    /// Yarn radius r (m).
    pub radius: f64,
    /// Volume density (kg/m³).
    pub density: f64,
    /// Contact stiffness k_c of the Kaldor pair energy (J/m²).
    pub contact_stiffness: f64,
    /// Gauss–Legendre points per segment in the contact quadrature.
    pub contact_quadrature: usize,
    /// Neighbouring segments on each side along the same yarn that never touch (exclusion along the yarn).
    pub contact_exclusion: usize,
}

impl Default for YarnMaterial {
    fn default() -> Self {
        YarnMaterial {
            young: 1e6,
            shear: 4e5,
            bend_twist_factor: 0.1,
            radius: 1e-3,
            density: 120.0,
            contact_stiffness: 76.0,
            contact_quadrature: 4,
            contact_exclusion: 3,
        }
    }
}

impl YarnMaterial {
    /// The defaults with the radius of a pattern.
    pub fn with_radius(radius: f64) -> Self {
        YarnMaterial {
            radius,
            ..Default::default()
        }
    }

    /// Stretching stiffness k_s = Y π r² (N).
    pub fn stretch_stiffness(&self) -> f64 {
        self.young * std::f64::consts::PI * self.radius.powi(2)
    }

    /// Bending stiffness B = γ Y π r⁴ / 4 (N m²).
    pub fn bend_stiffness(&self) -> f64 {
        self.bend_twist_factor * self.young * std::f64::consts::PI * self.radius.powi(4) / 4.0
    }

    /// Twisting stiffness GJ = γ G π r⁴ / 2 (N m²).
    pub fn twist_stiffness(&self) -> f64 {
        self.bend_twist_factor * self.shear * std::f64::consts::PI * self.radius.powi(4) / 2.0
    }
}
