//! Fitting the spline material from samples (C5–C7, `docs/fitting.md`, section
//! "Fitting (C5, C6, C7)"): the symlog transform ([`symlog`]), moving least squares in 1D and 2D ([`mls`]),
//! FIT1D ([`fit1d`]) and FIT2D ([`fit2d`]), which work on any samples, synthetic ones included, and FITSPLINES
//! ([`model`]), which fits a whole material to the samples of a plan.

pub mod fit1d;
pub mod fit2d;
pub mod mls;
pub mod model;
pub mod plot;
pub mod preset;
pub mod scalar;
pub mod symlog;
pub mod tangent;

pub use fit1d::{
    fit1d, fit1d_with_stress, Fit1D, Fit1DOptions, Fit1DReport, MinimumAt, SlopeSource,
};
pub use fit2d::{fit2d, Fit2D, Fit2DOptions, Fit2DReport};
pub use mls::{Mls1D, Mls2D};
pub use model::{
    check_records, fit_material, model_error, FitOptions, FitReport, MaterialFit, ModelError,
    MAX_SAMPLE_VALUE,
};
pub use plot::PlotError;
pub use preset::FitPreset;
pub use scalar::{FitScalar, Kink, KinkReport, KinkRule};
pub use tangent::{fit_material_tangent, fit_material_tangents, RecordTangent};

/// Why a fit could not be made. Bad input is reported, never a panic.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitError {
    /// X and Ψ have different lengths
    #[error("sample arrays differ in length: {x} abscissae, {psi} values")]
    LengthMismatch {
        /// abscissae given
        x: usize,
        /// values given
        psi: usize,
    },
    /// fewer usable (finite) samples or distinct abscissae than the method needs
    #[error("too few usable samples: {usable} (need at least {needed} distinct finite ones)")]
    TooFewSamples {
        /// usable samples found
        usable: usize,
        /// the fewest the method needs
        needed: usize,
    },
    /// an option outside its valid range
    #[error("invalid fit option: {0}")]
    BadOption(String),
    /// the knot rule left fewer than two knots, or the minimum knot is missing
    #[error("knot placement failed: {0}")]
    Knots(String),
    /// one term of a whole-material fit failed (`term` names it: `1D term 0 (s_x)`, `2D term (s_x, s_a)`)
    #[error("{term}: {source}")]
    Term {
        /// the term's name
        term: String,
        /// its error
        source: Box<FitError>,
    },
    /// the fitted model came out with a non-finite number (named), so no material is written
    #[error("the fit did not converge: {0} is not finite")]
    NotFinite(String),
    /// a tangent pass of the fit ([`tangent`]) whose real parts are not the fit's coefficients (it would not
    /// follow the fit's branch): the first coefficient that differs
    #[error("the tangent pass left the fit's branch: {0}")]
    Branch(String),
    /// a sample record that cannot be fitted: its id, the field and what is wrong
    #[error("sample {id}: {field}: {message}")]
    BadRecord {
        /// the sample's id
        id: String,
        /// the field at fault
        field: String,
        /// what is wrong
        message: String,
    },
}

impl FitError {
    /// Whether the fit did not converge (the computation, not the input, is at fault): too few samples converged
    /// ([`FitError::TooFewSamples`], directly or for one term) or the model came out non-finite
    /// ([`FitError::NotFinite`]). `hylc fit` exits with code 3 then.
    pub fn is_not_converged(&self) -> bool {
        match self {
            FitError::TooFewSamples { .. } | FitError::NotFinite(_) => true,
            FitError::Term { source, .. } => source.is_not_converged(),
            _ => false,
        }
    }
}

/// Relative errors of fitted values against data: √(Σ e²)/√(Σ y²) and max |e| / max |y| (absolute when the data
/// are all 0), with the index of the largest |e|.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RelError {
    se: f64,
    sy: f64,
    emax: f64,
    ymax: f64,
    worst: Option<usize>,
    n: usize,
}

impl RelError {
    /// Add one pair (fitted value, data value).
    pub(crate) fn add(&mut self, fit: f64, data: f64) {
        let e = fit - data;
        self.se += e * e;
        self.sy += data * data;
        self.ymax = self.ymax.max(data.abs());
        if e.abs() >= self.emax {
            self.emax = e.abs();
            self.worst = Some(self.n);
        }
        self.n += 1;
    }

    pub(crate) fn rms_rel(&self) -> f64 {
        if self.sy > 0.0 {
            (self.se / self.sy).sqrt()
        } else {
            self.se.sqrt()
        }
    }

    pub(crate) fn max_rel(&self) -> f64 {
        if self.ymax > 0.0 {
            self.emax / self.ymax
        } else {
            self.emax
        }
    }

    /// The position (in order of [`RelError::add`]) of the largest |e|.
    pub(crate) fn worst(&self) -> Option<usize> {
        self.worst
    }
}

/// The option checks FIT1D and FIT2D share: ε, pˣ_min and the finite-difference step.
fn check_common(eps_rel: f64, min_slope: f64, fd_step: f64) -> Result<(), FitError> {
    let bad = |s: String| Err(FitError::BadOption(s));
    if !(eps_rel.is_finite() && eps_rel > 0.0) {
        return bad(format!("eps_rel = {eps_rel} (need finite, > 0)"));
    }
    if !(min_slope.is_finite() && min_slope > 0.0) {
        return bad(format!("min_slope = {min_slope} (need finite, > 0)"));
    }
    if !(fd_step.is_finite() && fd_step > 0.0 && fd_step <= 0.5) {
        return bad(format!("fd_step = {fd_step} (need in (0, 0.5])"));
    }
    Ok(())
}
