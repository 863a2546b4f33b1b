//! Yarn material parameters (`docs/yarn-model.md`, "Discrete elastic rods" and "Yarn-yarn
//! contact"): one struct that every yarn energy takes by reference, read from and written to JSON (docs/yarn-parameters.md,
//! "Yarn parameters as data").
//!
//! The JSON form is one object with every field of [`YarnMaterial`] as a key, all required (a file names every
//! parameter it was made with, so a later change of the defaults cannot silently change what it means), unknown
//! keys refused. `hylc yarn` prints the defaults in this form. Errors name the file and the key at fault on one
//! line ([`YarnFileError`]).

use super::frame::BendingForm;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Parameters of the yarn model. Defaults are the calibrated values (see the README's calibration table):
/// Y = 1e6 Pa, G/Y = 0.4, γ = 0.1, r = 1 mm, ρ = 120 kg/m³, Kaldor contact with k_c = 76 J/m² at the contact
/// distance 2r (radius factor 1), 4 Gauss–Legendre points per segment and 3 excluded neighbour segments on each
/// side.
///
/// The radius r of a pattern is part of its geometry: a micro problem or tile replaces `radius` by its pattern's
/// (the value here is the radius of generated patterns and the one recorded when no pattern gives one).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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
    /// Contact radius factor f: the contact distance is 2 f r (1: the yarns touch at their surfaces).
    pub contact_radius_factor: f64,
    /// How the discrete curvature measures a turning angle φ: `"tan"` (2 tan(φ/2), the original's form) or `"sin"`
    /// (2 sin(φ/2)); rest curvatures, stored in the `tan` form, keep their angles. The one key added after the
    /// format was fixed: a file without it means `"tan"`, the form every earlier file was made with.
    #[serde(default)]
    pub bending: BendingForm,
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
            contact_radius_factor: 1.0,
            bending: BendingForm::Tan,
        }
    }
}

/// Largest contact quadrature order a yarn file may ask for (the kernel's cost grows as Q²).
pub const MAX_CONTACT_QUADRATURE: usize = 32;

/// A yarn file or yarn parameters that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum YarnFileError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file could not be written.
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Not JSON, not an object, an unknown or a missing key, a value of the wrong type (serde's message names
    /// the key and the line).
    #[error("{}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// serde's message.
        message: String,
    },
    /// A value outside the admissible range.
    #[error("{}key `{key}` = {value}: {expected}", where_prefix(.path))]
    Value {
        /// The file, when the parameters came from one.
        path: Option<PathBuf>,
        /// The key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// The admissible range.
        expected: &'static str,
    },
}

fn where_prefix(path: &Option<PathBuf>) -> String {
    path.as_ref()
        .map(|p| format!("{}: ", p.display()))
        .unwrap_or_default()
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

    /// The admissible parameter set: Y, G, γ, r, f finite and positive; ρ and k_c finite and non-negative;
    /// 1 ≤ Q ≤ [`MAX_CONTACT_QUADRATURE`]. The first violation is named by its key.
    pub fn validate(&self) -> Result<(), YarnFileError> {
        let bad = |key, value, expected| {
            Err(YarnFileError::Value {
                path: None,
                key,
                value,
                expected,
            })
        };
        let positive = "expected a finite positive number";
        let non_negative = "expected a finite non-negative number";
        for (key, v) in [
            ("young", self.young),
            ("shear", self.shear),
            ("bend_twist_factor", self.bend_twist_factor),
            ("radius", self.radius),
            ("contact_radius_factor", self.contact_radius_factor),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(key, v, positive);
            }
        }
        for (key, v) in [
            ("density", self.density),
            ("contact_stiffness", self.contact_stiffness),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(key, v, non_negative);
            }
        }
        if !(1..=MAX_CONTACT_QUADRATURE).contains(&self.contact_quadrature) {
            return bad(
                "contact_quadrature",
                self.contact_quadrature as f64,
                "expected 1 to 32 points per segment",
            );
        }
        Ok(())
    }

    /// Parse the JSON form (a leading UTF-8 byte-order mark is skipped) and validate it; `path` names the source
    /// in errors.
    pub fn from_json_str(text: &str, path: &Path) -> Result<Self, YarnFileError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let m: YarnMaterial = serde_json::from_str(text).map_err(|e| YarnFileError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        m.validate().map_err(|e| match e {
            YarnFileError::Value {
                key,
                value,
                expected,
                ..
            } => YarnFileError::Value {
                path: Some(path.to_path_buf()),
                key,
                value,
                expected,
            },
            other => other,
        })?;
        Ok(m)
    }

    /// Read and validate a yarn file.
    pub fn load_json(path: &Path) -> Result<Self, YarnFileError> {
        let text = std::fs::read_to_string(path).map_err(|source| YarnFileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json_str(&text, path)
    }

    /// The JSON form, pretty-printed with a final newline.
    pub fn to_json_string(&self) -> String {
        serde_json::to_string_pretty(self).expect("a struct of numbers serialises") + "\n"
    }

    /// Write the JSON form to `path`.
    pub fn save_json(&self, path: &Path) -> Result<(), YarnFileError> {
        std::fs::write(path, self.to_json_string()).map_err(|source| YarnFileError::Write {
            path: path.to_path_buf(),
            source,
        })
    }

    /// The text the sample files' problem hash is taken of: the fields as `Debug` printed them before the
    /// contact radius factor existed, with `contact_radius_factor` appended only when it is not 1, so that the
    /// hashes of sample files written with the default contact distance stay valid (resume keeps working).
    pub fn hash_text(&self) -> String {
        let mut s = format!(
            "YarnMaterial {{ young: {:?}, shear: {:?}, bend_twist_factor: {:?}, radius: {:?}, density: {:?}, \
             contact_stiffness: {:?}, contact_quadrature: {:?}, contact_exclusion: {:?} }}",
            self.young,
            self.shear,
            self.bend_twist_factor,
            self.radius,
            self.density,
            self.contact_stiffness,
            self.contact_quadrature,
            self.contact_exclusion
        );
        if self.contact_radius_factor != 1.0 {
            s += &format!(" contact_radius_factor: {:?}", self.contact_radius_factor);
        }
        if self.bending != BendingForm::Tan {
            s += &format!(" bending: {:?}", self.bending);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<YarnMaterial, YarnFileError> {
        YarnMaterial::from_json_str(text, Path::new("yarn.json"))
    }

    #[test]
    fn default_round_trips_through_json() {
        let m = YarnMaterial::default();
        assert_eq!(parse(&m.to_json_string()).unwrap(), m);
        let odd = YarnMaterial {
            young: 1.234_567_890_123e7,
            contact_radius_factor: 0.93,
            contact_quadrature: 7,
            ..m
        };
        assert_eq!(parse(&odd.to_json_string()).unwrap(), odd);
    }

    #[test]
    fn unknown_and_missing_keys_are_one_line_errors_naming_file_and_key() {
        let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
        v["stiffness"] = serde_json::json!(1.0);
        let e = parse(&v.to_string()).unwrap_err().to_string();
        assert!(
            e.starts_with("yarn.json: ") && e.contains("`stiffness`"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
        let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
        v.as_object_mut().unwrap().remove("contact_radius_factor");
        let e = parse(&v.to_string()).unwrap_err().to_string();
        assert!(
            e.starts_with("yarn.json: ") && e.contains("`contact_radius_factor`"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }

    #[test]
    fn the_bending_key_defaults_to_tan_and_names_itself_when_wrong() {
        let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
        assert_eq!(v["bending"], serde_json::json!("tan"));
        v.as_object_mut().unwrap().remove("bending");
        assert_eq!(parse(&v.to_string()).unwrap(), YarnMaterial::default());
        v["bending"] = serde_json::json!("sin");
        assert_eq!(parse(&v.to_string()).unwrap().bending, BendingForm::Sin);
        v["bending"] = serde_json::json!("cos");
        let e = parse(&v.to_string()).unwrap_err().to_string();
        assert!(e.starts_with("yarn.json: ") && e.contains("`cos`"), "{e}");
        assert!(!e.contains('\n'), "{e}");
        let sin = YarnMaterial {
            bending: BendingForm::Sin,
            ..Default::default()
        };
        assert_ne!(sin.hash_text(), YarnMaterial::default().hash_text());
    }

    #[test]
    fn out_of_range_values_name_the_key() {
        let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
        v["young"] = serde_json::json!(-1.0);
        let e = parse(&v.to_string()).unwrap_err().to_string();
        assert_eq!(
            e,
            "yarn.json: key `young` = -1: expected a finite positive number"
        );
        let mut v = serde_json::to_value(YarnMaterial::default()).unwrap();
        v["contact_quadrature"] = serde_json::json!(0);
        let e = parse(&v.to_string()).unwrap_err().to_string();
        assert!(e.contains("`contact_quadrature`"), "{e}");
    }

    #[test]
    fn hash_text_of_the_default_is_the_old_debug_text() {
        // the text the problem hash was taken of before `contact_radius_factor` existed
        let old = "YarnMaterial { young: 1000000.0, shear: 400000.0, bend_twist_factor: 0.1, radius: 0.001, \
                   density: 120.0, contact_stiffness: 76.0, contact_quadrature: 4, contact_exclusion: 3 }";
        assert_eq!(YarnMaterial::default().hash_text(), old);
        let f = YarnMaterial {
            contact_radius_factor: 0.9,
            ..Default::default()
        };
        assert_ne!(f.hash_text(), old);
    }
}
