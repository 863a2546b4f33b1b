//! The fit's presets (`docs/fitting.md`, "Presets"): named [`FitOptions`] that `hylc fit --preset`, Python's
//! `fit(preset=…)` and `hylc run` share, so that a material fitted by hand is the one `hylc run` makes.
//!
//! - `covering` (the default): every term's knots span the whole sampled range, one median spacing of MLS
//!   bandwidth, FIT2D's compressed half-plane kept as a residual ([`FitOptions::covering`]); made for plans
//!   with few samples per axis, such as the quick plan (7 % error on `hylc run`'s samples where `design` has 86 %).
//! - `design`: the method's own settings ([`FitOptions::default`]): 11 knots per 1D term on 0.95 of its range,
//!   9 per 2D axis on 0.9, two spacings of bandwidth, the compressed half-plane zeroed; for dense plans.
//! - `design-stockinette`: `design` with the original stockinette material's layout
//!   ([`FitOptions::stockinette_like`]).

use super::model::FitOptions;
use serde::{Deserialize, Serialize};

/// A named set of [`FitOptions`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FitPreset {
    /// `covering`: knots over the whole sampled range, for plans with few samples per axis ([`FitOptions::covering`]).
    #[default]
    Covering,
    /// `design`: the method's own settings ([`FitOptions::default`]), for dense plans.
    Design,
    /// `design-stockinette`: `design` with the original stockinette material's layout ([`FitOptions::stockinette_like`]).
    DesignStockinette,
}

impl FitPreset {
    /// Every preset, the default first.
    pub const ALL: [FitPreset; 3] = [
        FitPreset::Covering,
        FitPreset::Design,
        FitPreset::DesignStockinette,
    ];

    /// The preset's name on the command line and in Python.
    pub fn name(self) -> &'static str {
        match self {
            FitPreset::Covering => "covering",
            FitPreset::Design => "design",
            FitPreset::DesignStockinette => "design-stockinette",
        }
    }

    /// The options the preset stands for.
    pub fn options(self) -> FitOptions {
        match self {
            FitPreset::Covering => FitOptions::covering(),
            FitPreset::Design => FitOptions::default(),
            FitPreset::DesignStockinette => FitOptions::stockinette_like(),
        }
    }
}

impl std::str::FromStr for FitPreset {
    type Err = String;

    /// A preset by its [`name`](FitPreset::name); the error lists the valid names.
    fn from_str(s: &str) -> Result<FitPreset, String> {
        FitPreset::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = FitPreset::ALL.iter().map(|p| p.name()).collect();
                format!(
                    "unknown fit preset `{s}` (expected one of: {})",
                    names.join(", ")
                )
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_list_the_valid_ones() {
        for p in FitPreset::ALL {
            assert_eq!(p.name().parse::<FitPreset>(), Ok(p));
            let json = serde_json::to_string(&p).unwrap();
            assert_eq!(json, format!("\"{}\"", p.name()));
        }
        let e = "fast".parse::<FitPreset>().unwrap_err();
        assert!(
            e.contains("`fast`") && e.contains("covering, design, design-stockinette"),
            "{e}"
        );
        assert_eq!(FitPreset::default().options(), FitOptions::covering());
    }
}
