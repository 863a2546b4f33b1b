//! The micro solver's settings (`03-homogenization.md`, section 4): [`SolverOptions`] and the per-stencil
//! projection choice [`PsdStencils`].

use serde::{Deserialize, Serialize};

/// Solver settings (`03-homogenization.md`, section 4; defaults from there).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverOptions {
    /// Dimensionless force tolerance: converged when ‖g‖_∞ ≤ tolerance · k_s.
    pub tolerance: f64,
    /// Newton-decrement test: converged when |gᵀδy| ≤ decrement_tolerance · (|E| + k_s r) (design default
    /// 1e-14). For a small tile this is looser than the force test (|E| ≪ k_s r), so derivative checks against
    /// re-solves set it to 0 and rely on the force test alone.
    pub decrement_tolerance: f64,
    /// Newton step limit.
    pub max_steps: usize,
    /// Wall-time limit per solve (seconds), none by default.
    pub time_limit: Option<f64>,
    /// Displacement limit factor: d_max = step_factor · r · λ_min(Ī).
    pub step_factor: f64,
    /// Constrain each yarn's slide along itself (the original allowed switching it off).
    pub slide_constraints: bool,
    /// Backtracking factor of the line search: trial steps factorⁱ down to 1e-10 (the design's 0.1ⁱ, i ≤ 10,
    /// is `0.1`).
    pub backtracking: f64,
    /// Broad-phase margin in units of r.
    pub contact_margin: f64,
    /// Where H + μI factorises only with μ above its floor (H indefinite in the full space), take the exact
    /// Newton step on the constraint space when H is positive definite there (projected conjugate gradients
    /// preconditioned by that factorisation), else the shifted step. Off: always the shifted step (the design's
    /// plain μ regularisation, the default: on the original rib the exact steps reach other, lower equilibria
    /// than the shifted ones and take more steps; README-micro.md). Not written to the settings JSON while off,
    /// so the problem hash of existing sample files stays.
    #[serde(skip_serializing_if = "is_false")]
    pub projected_steps: bool,
    /// After a step whose factorisation failed at its first shift (μ had to grow), start the next step at the
    /// μ that worked instead of μ/10: in a region where H is indefinite, each step then saves the
    /// factorisation that would fail again. Off (the default): μ/10 after every accepted step, the design's
    /// rule. Not written to the settings JSON while off.
    #[serde(skip_serializing_if = "is_false")]
    pub keep_shift: bool,
    /// Per-stencil projection of the local Hessians to positive semi-definite (`03-homogenization.md`, section 3,
    /// the alternative to the μ shift; [`crate::tile::psd`]): always, or only where the exact H + μI does not
    /// factorise at μ's floor. Off (the default): the exact Hessian with the μ shift, which converges faster (the projected
    /// steps converge linearly; measured in the README, "Micro-solver speed (issue 20)"). Not written to the
    /// settings JSON while off.
    #[serde(skip_serializing_if = "PsdStencils::is_off")]
    pub psd_stencils: PsdStencils,
    /// Yarn crossings along the Newton path ([`crate::contact::ccd`]; issue 19, item 1): not checked (the
    /// default), counted (each accepted step is tested; [`crate::micro::Solution::crossings`]), or rejected (a
    /// line-search trial whose step passes two yarn centre lines through each other is not accepted, so the solve
    /// stays in the fabric it started in). A sample chain ([`crate::sample`]) applies the same to the way from a
    /// neighbour's equilibrium to a warm or predicted start ([`crate::micro::path`]): counted with the record's
    /// crossings, or the start replaced by the next one that crosses nothing (predicted, warm, cold). Not written
    /// to the settings JSON while off.
    #[serde(skip_serializing_if = "CrossingGuard::is_off")]
    pub crossings: CrossingGuard,
    /// A trust-region Newton step in place of the displacement limit and the backtracking
    /// (`03-homogenization.md`, section 4, steps 3–4): μ is found as before and its factorisation preconditions
    /// truncated (Steihaug–Toint) projected conjugate gradients on the quadratic model with the exact H. These
    /// go beyond the shifted step along soft directions, follow negative curvature on the constraint space to the
    /// boundary, and tend to the exact Newton step inside the region. The region is the largest vertex
    /// displacement (or r·|δθ|) ≤ Δ, Δ starting at d_max = step_factor · r · λ_min(Ī) and never above it; it
    /// shrinks ×0.25 of the step on a rejected trial or a poor ratio of actual to predicted decrease (< 0.25)
    /// and doubles on a good one (> 0.75) that ended on the boundary. Trials are subject to
    /// [`SolverOptions::crossings`] as line-search trials are. Off (the default): the design's shifted step with
    /// backtracking: the trust region takes fewer steps but sends some samples to higher equilibria (measured in
    /// the README, "Micro-solver speed (issue 20)"). Not written to the settings JSON while off.
    #[serde(skip_serializing_if = "is_false")]
    pub trust_region: bool,
    /// Inertia-controlled Newton steps (`03-homogenization.md`, section 3; issue 20), on by default: each step
    /// first factorises H + μI at μ's floor by LDLᵀ and takes the exact constrained Newton step when the KKT
    /// matrix has the inertia of a constrained minimum (H positive definite on the null space of the constraint
    /// rows, even where it is indefinite along them: a yarn held back from sliding) and the energy then falls by
    /// at least a quarter of the decrease the quadratic model predicts; otherwise the step is the design's:
    /// μ grown ×10 until the (inertia-tested) shifted step exists, with backtracking. A backtracked step whose
    /// predicted decrease is at round-off level (≤ 1e-11 (|E| + k_s r)) ends the solve as converged. Off: the design's rule
    /// alone, μ grown until H + μI is positive definite in the full space (measured in the README,
    /// "Micro-solver speed (issue 20)"). Ignored (the design's rule) with [`SolverOptions::projected_steps`],
    /// [`SolverOptions::trust_region`] or [`SolverOptions::psd_stencils`], which were measured against it.
    /// Written to the settings JSON only while on: a settings record without the key (every file made before this
    /// option) reads as off, the rule it was made with, so sample files made before it resume with it off
    /// (`--no-inertia`) under their problem hash.
    #[serde(default, skip_serializing_if = "is_false")]
    pub inertia: bool,
    /// With [`SolverOptions::inertia`]: after an exact step that was refused (the KKT matrix at μ's floor without
    /// the inertia of a constrained minimum, or the energy not following its model), skip the exact attempt for
    /// the next 1, 2, 4, …, [`EXACT_BACKOFF_MAX`] steps (doubled after each consecutive refusal, back to every
    /// step after an accepted exact step), so that a solve deep in an indefinite region stops paying a
    /// factorisation that fails again. Off (the default): the exact attempt at every step where μ is above its
    /// floor. Not written to the settings JSON while off.
    #[serde(default, skip_serializing_if = "is_false")]
    pub exact_backoff: bool,
    /// The line search's trial steps by safeguarded quadratic interpolation (`03-homogenization.md`, section 4,
    /// step 5, with the step length chosen as in a standard interpolating backtracking): after a refused trial t
    /// with energy E(t), the next is the minimiser of the parabola through E(0), the slope gᵀδ at 0 and E(t),
    /// kept within [0.1 t, 0.5 t] (0.1 t when E(t) is not finite or the trial crossed yarns). Acceptance is
    /// unchanged (any lower energy). Off (the default): trial steps factorⁱ ([`SolverOptions::backtracking`]).
    /// Not written to the settings JSON while off.
    #[serde(default, skip_serializing_if = "is_false")]
    pub interpolating_search: bool,
    /// Emit one `tracing` event (info level) per Newton step: energy, ‖g‖∞, decrement, μ, step length (`hylc
    /// solve --trace` prints them to stderr).
    pub trace: bool,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            tolerance: 1e-8,
            decrement_tolerance: 1e-14,
            max_steps: 2000,
            time_limit: None,
            step_factor: 1.0,
            slide_constraints: true,
            backtracking: 0.1,
            contact_margin: crate::tile::contact::DEFAULT_MARGIN,
            projected_steps: false,
            keep_shift: false,
            psd_stencils: PsdStencils::Off,
            crossings: CrossingGuard::Off,
            trust_region: false,
            inertia: true,
            exact_backoff: false,
            interpolating_search: false,
            trace: false,
        }
    }
}

/// The longest run of Newton steps without an exact attempt under [`SolverOptions::exact_backoff`].
pub const EXACT_BACKOFF_MAX: usize = 16;

/// When the Newton matrix is built from per-stencil positive semi-definite projections of the local Hessians
/// ([`SolverOptions::psd_stencils`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PsdStencils {
    /// Never: the exact Hessian, μ grown ×10 until H + μI factorises (the design's default).
    #[default]
    Off,
    /// At every Newton step: H is positive semi-definite by construction and μ stays at its floor.
    Always,
    /// Only at the steps where the exact H + μI does not factorise (or gives no descent direction) at μ's floor:
    /// the projected H is tried at the floor before μ grows.
    Fallback,
}

impl PsdStencils {
    /// serde's `skip_serializing_if`.
    fn is_off(&self) -> bool {
        *self == PsdStencils::Off
    }
}

/// Whether the micro solver checks its steps for yarn crossings ([`SolverOptions::crossings`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum CrossingGuard {
    /// Not checked.
    #[default]
    Off,
    /// Every accepted step (and a chain's start path) is checked and the crossings are reported; the solve is
    /// unchanged.
    Count,
    /// A line-search trial that crosses yarns is rejected (the search backtracks further); a chain's start whose
    /// path crosses is replaced by the next candidate (predicted, warm, cold).
    Reject,
}

impl CrossingGuard {
    /// serde's `skip_serializing_if`.
    fn is_off(&self) -> bool {
        *self == CrossingGuard::Off
    }
}

/// serde's `skip_serializing_if` for options that are not written while off.
fn is_false(v: &bool) -> bool {
    !*v
}

impl SolverOptions {
    /// Whether the Newton steps are inertia-controlled ([`SolverOptions::inertia`] and none of the options it
    /// gives way to).
    pub fn inertia_steps(&self) -> bool {
        self.inertia
            && !self.projected_steps
            && !self.trust_region
            && self.psd_stencils == PsdStencils::Off
    }
}
