//! Fitting the spline material from samples (C5–C7, `../shared/design/04-sampling-fitting.md`, section
//! "Fitting (C5, C6, C7)"). So far the 1D part: the symlog transform ([`symlog`]), moving least squares ([`mls`])
//! and FIT1D ([`fit1d`]), which works on any (X, Ψ) samples, synthetic ones included.

pub mod fit1d;
pub mod mls;
pub mod symlog;

pub use fit1d::{fit1d, Fit1D, Fit1DOptions, Fit1DReport, MinimumAt};
pub use mls::Mls1D;

use std::fmt;

/// Why a fit could not be made. Bad input is reported, never a panic.
#[derive(Clone, Debug, PartialEq)]
pub enum FitError {
    /// X and Ψ have different lengths
    LengthMismatch { x: usize, psi: usize },
    /// fewer usable (finite) samples or distinct abscissae than the method needs
    TooFewSamples { usable: usize, needed: usize },
    /// an option outside its valid range
    BadOption(String),
    /// the knot rule left fewer than two knots, or the minimum knot is missing
    Knots(String),
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FitError::LengthMismatch { x, psi } => {
                write!(
                    f,
                    "sample arrays differ in length: {x} abscissae, {psi} values"
                )
            }
            FitError::TooFewSamples { usable, needed } => {
                write!(f, "too few usable samples: {usable} (need at least {needed} distinct finite ones)")
            }
            FitError::BadOption(s) => write!(f, "invalid fit option: {s}"),
            FitError::Knots(s) => write!(f, "knot placement failed: {s}"),
        }
    }
}

impl std::error::Error for FitError {}
