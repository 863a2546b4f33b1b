//! Derivative-check harness (`docs/derivative-harness.md`, section 1).
//!
//! Every hand-written gradient and Hessian in the project is compared with
//! 1. forward-mode automatic differentiation (num-dual, second order) of a plain *reference* implementation that is
//!    generic over the scalar type, and
//! 2. central finite differences (Richardson-extrapolated) of the fast implementation itself.
//!
//! Registering a new energy means implementing one trait, [`Differentiable`], and adding one line to the
//! registry in `src/checks/`. The CLI command `check-derivatives` runs every registered function and exits
//! non-zero on any failure; CI runs it.
//!
//! Tolerance policy (relative, normwise): a comparison of a computed quantity `a` against a trusted one `b` passes
//! when `‖a − b‖ ≤ tol · (‖b‖ + scale)`, with `‖·‖` the Euclidean (vector) or Frobenius (matrix) norm and `scale` a
//! documented per-function magnitude ([`Scales`]) that keeps exact zeros from producing meaningless relative errors.

mod fd;
mod report;

pub use fd::{fd_gradient, fd_hessian};
pub use report::{format_table, Report};

use nalgebra::{DMatrix, DVector};
use num_dual::Dual2DVec64;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

pub use crate::real::{c, Real};

/// The tolerances of `docs/derivative-harness.md`, section 1 (relative, normwise).
#[derive(Clone, Copy, Debug)]
pub struct Tolerances {
    /// fast value against the reference value evaluated in f64
    pub value: f64,
    /// fast gradient against the num-dual gradient of the reference
    pub gradient_ad: f64,
    /// fast Hessian against the num-dual Hessian of the reference
    pub hessian_ad: f64,
    /// fast gradient against finite differences of the fast value
    pub gradient_fd: f64,
    /// fast Hessian against finite differences of the fast gradient
    pub hessian_fd: f64,
}

/// The policy of `docs/derivative-harness.md`. Never loosen these to make a check pass.
pub const POLICY: Tolerances = Tolerances {
    value: 1e-12,
    gradient_ad: 1e-9,
    hessian_ad: 1e-8,
    gradient_fd: 1e-6,
    hessian_fd: 1e-5,
};

/// Per-function magnitudes added to the norm of the trusted quantity in the tolerance test
/// `‖a − b‖ ≤ tol · (‖b‖ + scale)`. Each implementation documents its choice.
#[derive(Clone, Copy, Debug)]
pub struct Scales {
    /// magnitude added to |b| in the value test
    pub value: f64,
    /// magnitude added to ‖b‖ in the gradient tests
    pub gradient: f64,
    /// magnitude added to ‖b‖ in the Hessian tests
    pub hessian: f64,
}

impl Default for Scales {
    fn default() -> Self {
        Scales {
            value: 1.0,
            gradient: 1.0,
            hessian: 1.0,
        }
    }
}

/// Value, gradient and Hessian of a scalar function (the output of every fast implementation).
#[derive(Clone, Debug, PartialEq)]
pub struct Vgh {
    /// the value f(x)
    pub value: f64,
    /// the gradient ∇f(x)
    pub gradient: DVector<f64>,
    /// the Hessian ∇²f(x)
    pub hessian: DMatrix<f64>,
}

/// A function with a fast hand-written value/gradient/Hessian and a generic reference twin.
///
/// This is the one trait to implement to put a new energy under the harness.
pub trait Differentiable: Sync {
    /// Row name in the report.
    fn name(&self) -> String;
    /// Number of inputs (the variables the derivatives are taken with respect to).
    fn dim(&self) -> usize;
    /// Number of fixed parameters that follow the `dim()` inputs in every sampled vector (stored frames, rest
    /// values, stiffnesses): passed to `reference` and `fast` but never differentiated or perturbed.
    fn n_params(&self) -> usize {
        0
    }
    /// Magnitudes for the tolerance test (document the choice in the implementation).
    fn scales(&self) -> Scales {
        Scales::default()
    }
    /// Scales at a particular input (for functions whose natural magnitudes depend on the sample, such as rod
    /// stencils with edges from 1e-3 r to 1e3 r); defaults to [`Differentiable::scales`].
    fn scales_at(&self, _x: &[f64]) -> Scales {
        self.scales()
    }
    /// Typical magnitude of input `i`; finite-difference steps are relative to it.
    fn input_scale(&self, _i: usize) -> f64 {
        1.0
    }
    /// Typical magnitude of input `i` at a particular input `x`; defaults to [`Differentiable::input_scale`].
    fn input_scale_at(&self, _x: &[f64], i: usize) -> f64 {
        self.input_scale(i)
    }
    /// The plain reference implementation of the value, generic over the scalar. `x` holds the `dim()` inputs
    /// followed by the `n_params()` parameters (as constants of type `D`).
    fn reference<D: Real>(&self, x: &[D]) -> D;
    /// The fast hand-written value, gradient and Hessian with respect to the first `dim()` entries of `x` (the
    /// parameters follow them).
    fn fast(&self, x: &[f64]) -> Vgh;
    /// Fast value only (used by finite differences); defaults to [`Differentiable::fast`].
    fn fast_value(&self, x: &[f64]) -> f64 {
        self.fast(x).value
    }
    /// Distance from `x` to the nearest point where the function is not C³ (spline knots, cut-offs), measured as
    /// the largest step that may be added to any single input without crossing one. Finite differences use steps
    /// below this and are skipped (and counted) when that would be below the round-off limit.
    fn kink_distance(&self, _x: &[f64]) -> f64 {
        f64::INFINITY
    }
    /// The same for input `i` alone, for functions whose inputs have different units (positions and angles);
    /// defaults to [`Differentiable::kink_distance`].
    fn kink_distance_of(&self, x: &[f64], _i: usize) -> f64 {
        self.kink_distance(x)
    }
    /// Number of cases to run when `requested` are asked for: expensive functions (a whole tile with hundreds of
    /// inputs) cap it; defaults to `requested`.
    fn cases(&self, requested: usize) -> usize {
        requested
    }
    /// The `i`-th random test input (`dim()` inputs, then `n_params()` parameters). Implementations cycle through their categories of inputs (generic, extremes,
    /// singular points) with `i`.
    fn sample(&self, rng: &mut ChaCha8Rng, i: usize) -> Vec<f64>;
}

/// Settings of one harness run.
#[derive(Clone, Copy, Debug)]
pub struct CheckConfig {
    /// random input cases per function
    pub cases: usize,
    /// seed of the random inputs
    pub seed: u64,
    /// the tolerances (default [`POLICY`])
    pub tolerances: Tolerances,
    /// Finite-difference step relative to the input scale (before Richardson halving).
    pub fd_step: f64,
    /// Smallest relative step worth taking; below it the finite-difference comparison is skipped.
    pub fd_min_step: f64,
}

impl Default for CheckConfig {
    fn default() -> Self {
        CheckConfig {
            cases: 1000,
            seed: 1,
            tolerances: POLICY,
            fd_step: 1e-3,
            fd_min_step: 1e-6,
        }
    }
}

/// Object-safe view of a [`Differentiable`]: what the registry stores.
pub trait Check: Sync {
    /// The function's name in reports.
    fn name(&self) -> String;
    /// Run the harness on the function ([`check_function`]).
    fn check(&self, cfg: &CheckConfig) -> Report;
}

impl<T: Differentiable> Check for T {
    fn name(&self) -> String {
        Differentiable::name(self)
    }
    fn check(&self, cfg: &CheckConfig) -> Report {
        check_function(self, cfg)
    }
}

/// Relative normwise error `‖a − b‖ / (‖b‖ + scale)`; NaN anywhere gives +∞.
pub fn rel_err(a: &[f64], b: &[f64], scale: f64) -> f64 {
    let mut diff = 0.0;
    let mut norm = 0.0;
    for (x, y) in a.iter().zip(b) {
        if !x.is_finite() || !y.is_finite() {
            return f64::INFINITY;
        }
        diff += (x - y) * (x - y);
        norm += y * y;
    }
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    diff.sqrt() / (norm.sqrt() + scale)
}

/// Value, gradient and Hessian of the reference implementation by num-dual (second-order dual numbers).
pub fn reference_ad<F: Differentiable + ?Sized>(f: &F, x: &[f64]) -> Vgh {
    let n = f.dim();
    let xv = DVector::from_column_slice(&x[..n]);
    let (value, gradient, hessian) = num_dual::hessian(
        |xd: DVector<Dual2DVec64>| {
            let mut v: Vec<Dual2DVec64> = xd.iter().cloned().collect();
            v.extend(x[n..].iter().map(|&p| Dual2DVec64::from(p)));
            f.reference(&v)
        },
        &xv,
    );
    Vgh {
        value,
        gradient,
        hessian,
    }
}

/// Errors of one input case (relative normwise, see [`rel_err`]); `None` when a check was skipped.
#[derive(Clone, Debug)]
pub struct CaseErrors {
    /// fast value against the reference value in f64
    pub value: f64,
    /// fast gradient against the num-dual gradient of the reference
    pub gradient_ad: f64,
    /// fast Hessian against the num-dual Hessian of the reference
    pub hessian_ad: f64,
    /// fast gradient against finite differences (`None`: skipped)
    pub gradient_fd: Option<f64>,
    /// fast Hessian against finite differences (`None`: skipped)
    pub hessian_fd: Option<f64>,
}

impl CaseErrors {
    /// Largest error-to-tolerance ratio of this case (> 1 means failure).
    pub fn worst_ratio(&self, tol: &Tolerances) -> f64 {
        let mut r = (self.value / tol.value)
            .max(self.gradient_ad / tol.gradient_ad)
            .max(self.hessian_ad / tol.hessian_ad);
        if let Some(e) = self.gradient_fd {
            r = r.max(e / tol.gradient_fd);
        }
        if let Some(e) = self.hessian_fd {
            r = r.max(e / tol.hessian_fd);
        }
        if r.is_nan() {
            f64::INFINITY
        } else {
            r
        }
    }
}

/// Compare fast and reference implementations at one input.
pub fn check_case<F: Differentiable + ?Sized>(f: &F, x: &[f64], cfg: &CheckConfig) -> CaseErrors {
    let s = f.scales_at(x);
    let fast = f.fast(x);
    let xr: Vec<f64> = x.to_vec();
    let ref_value = f.reference::<f64>(&xr);
    let ad = reference_ad(f, x);
    let value = rel_err(&[fast.value], &[ref_value], s.value);
    let gradient_ad = rel_err(fast.gradient.as_slice(), ad.gradient.as_slice(), s.gradient);
    let hessian_ad = rel_err(fast.hessian.as_slice(), ad.hessian.as_slice(), s.hessian);
    let steps: Vec<f64> = (0..f.dim())
        .map(|i| cfg.fd_step * f.input_scale_at(x, i))
        .collect();
    // The Richardson stencil reaches ±h; stay strictly inside the smooth region.
    let shrink = steps
        .iter()
        .enumerate()
        .fold(1.0_f64, |acc, (i, &h)| {
            acc.min(0.5 * f.kink_distance_of(x, i) / h)
        })
        .min(1.0);
    let (gradient_fd, hessian_fd) = if shrink * cfg.fd_step >= cfg.fd_min_step {
        let h: Vec<f64> = steps.iter().map(|h| h * shrink).collect();
        let n = f.dim();
        let full = |y: &[f64]| {
            let mut v = y.to_vec();
            v.extend_from_slice(&x[n..]);
            v
        };
        let g = fd_gradient(|y| f.fast_value(&full(y)), &x[..n], &h);
        let hh = fd_hessian(|y| f.fast(&full(y)).gradient, &x[..n], &h);
        (
            Some(rel_err(fast.gradient.as_slice(), g.as_slice(), s.gradient)),
            Some(rel_err(fast.hessian.as_slice(), hh.as_slice(), s.hessian)),
        )
    } else {
        (None, None)
    };
    CaseErrors {
        value,
        gradient_ad,
        hessian_ad,
        gradient_fd,
        hessian_fd,
    }
}

/// Run the harness on one function: `cfg.cases` random inputs from its own sampler.
pub fn check_function<F: Differentiable + ?Sized>(f: &F, cfg: &CheckConfig) -> Report {
    let name = f.name();
    let seed = cfg.seed ^ fxhash(&name);
    let inputs: Vec<Vec<f64>> = {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..f.cases(cfg.cases))
            .map(|i| f.sample(&mut rng, i))
            .collect()
    };
    let results: Vec<(Vec<f64>, CaseErrors)> = inputs
        .into_par_iter()
        .map(|x| {
            let e = check_case(f, &x, cfg);
            (x, e)
        })
        .collect();
    Report::from_cases(name, &results, &cfg.tolerances)
}

/// A small deterministic string hash so every function gets its own input stream for a given seed.
fn fxhash(s: &str) -> u64 {
    s.bytes().fold(0xcbf29ce484222325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100000001b3)
    })
}

/// Run every check of `checks` whose name contains `filter` (all when empty).
pub fn run_checks(checks: &[Box<dyn Check>], cfg: &CheckConfig, filter: &str) -> Vec<Report> {
    checks
        .iter()
        .filter(|c| filter.is_empty() || c.name().contains(filter))
        .map(|c| c.check(cfg))
        .collect()
}
