//! The micro solver's settings (`docs/micro-solver.md`, section 4): [`SolverOptions`], the Newton step rule
//! [`StepRule`] and the crossing guard [`CrossingGuard`].
//!
//! **Settings files.** The settings are written as JSON with a `version` key ([`SETTINGS_VERSION`], every key
//! written; a key left out of a file reads as its default). A settings object without `version` is one written
//! before that key existed (version 1): it loads with that version's reading (a missing `inertia` key is the shift
//! rule, [`StepRule::Shift`], the rule such files were made with). Version 1 also had options of micro-solver rules
//! that were measured and not adopted (`docs/notes/retired-micro-solver-rules.md`); a version-1 object that sets
//! one of them to anything but its default value is refused with a message naming the option.
//!
//! **The problem hash** of a sample file ([`crate::sample::run::problem_hash`]) hashes the settings in the version-1
//! form ([`SolverOptions::hash_text`]), which is frozen: the hash of any settings that version 1 could express is
//! the one it had then, so sample files made before the version key resume under their hash.

use serde::{Deserialize, Serialize};

/// The settings format written now (the `version` key of a settings object).
pub const SETTINGS_VERSION: u32 = 2;

/// Solver settings (`docs/micro-solver.md`, section 4; defaults from there).
#[derive(Clone, Debug, PartialEq)]
pub struct SolverOptions {
    /// Dimensionless force tolerance: converged when ‖g‖_∞ ≤ tolerance · k_s.
    pub tolerance: f64,
    /// Newton-decrement test: converged when |gᵀδy| ≤ decrement_tolerance · (|E| + k_s r) (default
    /// 1e-14). For a small tile this is looser than the force test (|E| ≪ k_s r), so derivative checks against
    /// re-solves set it to 0 and rely on the force test alone.
    pub decrement_tolerance: f64,
    /// Newton step limit.
    pub max_steps: usize,
    /// Wall-time limit per solve (seconds), none by default.
    pub time_limit: Option<f64>,
    /// Constrain each yarn's slide along itself (on by default; off reproduces the original, which allowed
    /// switching it off).
    pub slide_constraints: bool,
    /// Broad-phase margin in units of r.
    pub contact_margin: f64,
    /// How a Newton step treats an indefinite Hessian ([`StepRule`]): inertia-controlled steps (the default) or
    /// the shift rule alone (reproduces the solver and the sample files from before 5 December 2026).
    pub step_rule: StepRule,
    /// Yarn crossings along the Newton path ([`crate::contact::ccd`]; docs/sampling.md): not checked (the
    /// default), counted (each accepted step is tested; [`crate::micro::Solution::crossings`]), or rejected (a
    /// line-search trial whose step passes two yarn centre lines through each other is not accepted, so the solve
    /// stays in the fabric it started in). A sample chain ([`crate::sample`]) applies the same to the way from a
    /// neighbour's equilibrium to a warm or predicted start ([`crate::micro::path`]): counted with the record's
    /// crossings, or the start replaced by the next one that crosses nothing (predicted, warm, cold). A measured
    /// trade (the guide, "The crossing guard"): `reject` keeps every sample in its fabric at 0.34–1.2× the speed.
    pub crossings: CrossingGuard,
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
            slide_constraints: true,
            contact_margin: crate::tile::contact::DEFAULT_MARGIN,
            step_rule: StepRule::Inertia,
            crossings: CrossingGuard::Off,
            trace: false,
        }
    }
}

/// How a Newton step treats a Hessian H that is not positive definite (`docs/micro-solver.md`, "Inertia-controlled
/// Newton steps").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StepRule {
    /// Inertia-controlled steps (the default): each step first factorises H + μI at μ's floor by LDLᵀ and takes the
    /// exact constrained Newton step when the KKT matrix has the inertia of a constrained minimum (H positive
    /// definite on the null space of the constraint rows, even where it is indefinite along them: a yarn held
    /// back from sliding) and the energy then falls by at least a quarter of the decrease the quadratic model
    /// predicts; otherwise the step is the shift rule's: μ grown ×10 until the (inertia-tested) shifted step exists,
    /// with backtracking. A backtracked step whose predicted decrease is at round-off level
    /// (≤ 1e-11 (|E| + k_s r)) ends the solve as converged. Measured in docs/notes/micro-solver-speed.md.
    #[default]
    Inertia,
    /// The shift rule alone: μ grown ×10 until H + μI is positive definite in the full space, with
    /// backtracking (`--no-inertia`). It reproduces the solver before 5 December 2026 bit for bit, the results
    /// measured with it and the sample files made with it.
    Shift,
}

/// Whether the micro solver checks its steps for yarn crossings ([`SolverOptions::crossings`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
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
    /// serde's `skip_serializing_if` in the version-1 form.
    fn is_off(&self) -> bool {
        *self == CrossingGuard::Off
    }
}

impl SolverOptions {
    /// Whether the Newton steps are inertia-controlled ([`StepRule::Inertia`]).
    pub fn inertia_steps(&self) -> bool {
        self.step_rule == StepRule::Inertia
    }

    /// The settings as the problem hash reads them: the version-1 JSON form (frozen; module documentation), the
    /// text every sample file made before the version key was hashed with.
    pub fn hash_text(&self) -> String {
        serde_json::to_string(&SettingsV1::from(self)).expect("settings serialise")
    }
}

/// The settings object written now (version [`SETTINGS_VERSION`]); a key left out reads as its default.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SettingsV2 {
    version: u32,
    tolerance: f64,
    decrement_tolerance: f64,
    max_steps: usize,
    time_limit: Option<f64>,
    slide_constraints: bool,
    contact_margin: f64,
    step_rule: StepRule,
    crossings: CrossingGuard,
    trace: bool,
}

impl Default for SettingsV2 {
    fn default() -> Self {
        SettingsV2::from(&SolverOptions::default())
    }
}

impl From<&SolverOptions> for SettingsV2 {
    fn from(o: &SolverOptions) -> Self {
        SettingsV2 {
            version: SETTINGS_VERSION,
            tolerance: o.tolerance,
            decrement_tolerance: o.decrement_tolerance,
            max_steps: o.max_steps,
            time_limit: o.time_limit,
            slide_constraints: o.slide_constraints,
            contact_margin: o.contact_margin,
            step_rule: o.step_rule,
            crossings: o.crossings,
            trace: o.trace,
        }
    }
}

impl From<SettingsV2> for SolverOptions {
    fn from(s: SettingsV2) -> Self {
        SolverOptions {
            tolerance: s.tolerance,
            decrement_tolerance: s.decrement_tolerance,
            max_steps: s.max_steps,
            time_limit: s.time_limit,
            slide_constraints: s.slide_constraints,
            contact_margin: s.contact_margin,
            step_rule: s.step_rule,
            crossings: s.crossings,
            trace: s.trace,
        }
    }
}

/// The version-1 settings object (no `version` key; written before the key existed), frozen: the problem hash's
/// text ([`SolverOptions::hash_text`]) and the reading of old files. Its options that are off by default were
/// written only while on, and `inertia` only while true, so a missing key reads as off (false); the options of
/// the retired rules (`docs/notes/retired-micro-solver-rules.md`) load only at their default values.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SettingsV1 {
    tolerance: f64,
    decrement_tolerance: f64,
    max_steps: usize,
    time_limit: Option<f64>,
    step_factor: f64,
    slide_constraints: bool,
    backtracking: f64,
    contact_margin: f64,
    #[serde(skip_serializing_if = "is_false")]
    projected_steps: bool,
    #[serde(skip_serializing_if = "is_false")]
    keep_shift: bool,
    #[serde(skip_serializing_if = "is_off")]
    psd_stencils: String,
    #[serde(skip_serializing_if = "CrossingGuard::is_off")]
    crossings: CrossingGuard,
    #[serde(skip_serializing_if = "is_false")]
    trust_region: bool,
    #[serde(skip_serializing_if = "is_false")]
    inertia: bool,
    #[serde(skip_serializing_if = "is_false")]
    exact_backoff: bool,
    #[serde(skip_serializing_if = "is_false")]
    interpolating_search: bool,
    trace: bool,
}

/// The version-1 values of the retired options' keys that the current solver reproduces (their defaults).
const V1_STEP_FACTOR: f64 = 1.0;
const V1_BACKTRACKING: f64 = 0.1;

impl Default for SettingsV1 {
    fn default() -> Self {
        let mut s = SettingsV1::from(&SolverOptions::default());
        s.inertia = false;
        s
    }
}

impl From<&SolverOptions> for SettingsV1 {
    fn from(o: &SolverOptions) -> Self {
        SettingsV1 {
            tolerance: o.tolerance,
            decrement_tolerance: o.decrement_tolerance,
            max_steps: o.max_steps,
            time_limit: o.time_limit,
            step_factor: V1_STEP_FACTOR,
            slide_constraints: o.slide_constraints,
            backtracking: V1_BACKTRACKING,
            contact_margin: o.contact_margin,
            projected_steps: false,
            keep_shift: false,
            psd_stencils: "off".into(),
            crossings: o.crossings,
            trust_region: false,
            inertia: o.step_rule == StepRule::Inertia,
            exact_backoff: false,
            interpolating_search: false,
            trace: o.trace,
        }
    }
}

impl TryFrom<SettingsV1> for SolverOptions {
    type Error = String;

    fn try_from(s: SettingsV1) -> Result<Self, String> {
        let retired = [
            ("step_factor", s.step_factor != V1_STEP_FACTOR),
            ("backtracking", s.backtracking != V1_BACKTRACKING),
            ("projected_steps", s.projected_steps),
            ("keep_shift", s.keep_shift),
            ("psd_stencils", s.psd_stencils != "off"),
            ("trust_region", s.trust_region),
            ("exact_backoff", s.exact_backoff),
            ("interpolating_search", s.interpolating_search),
        ];
        if let Some((key, _)) = retired.iter().find(|(_, set)| *set) {
            return Err(format!(
                "settings without \"version\" (version 1) set `{key}`, an option of a micro-solver rule that was \
                 retired (docs/notes/retired-micro-solver-rules.md); only its default value still loads"
            ));
        }
        Ok(SolverOptions {
            tolerance: s.tolerance,
            decrement_tolerance: s.decrement_tolerance,
            max_steps: s.max_steps,
            time_limit: s.time_limit,
            slide_constraints: s.slide_constraints,
            contact_margin: s.contact_margin,
            step_rule: if s.inertia {
                StepRule::Inertia
            } else {
                StepRule::Shift
            },
            crossings: s.crossings,
            trace: s.trace,
        })
    }
}

/// serde's `skip_serializing_if` for version-1 options that were not written while off.
fn is_false(v: &bool) -> bool {
    !*v
}

/// serde's `skip_serializing_if` for version 1's `psd_stencils`.
fn is_off(v: &str) -> bool {
    v == "off"
}

impl Serialize for SolverOptions {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        SettingsV2::from(self).serialize(s)
    }
}

impl<'de> Deserialize<'de> for SolverOptions {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let value = serde_json::Value::deserialize(d)?;
        match value.get("version") {
            None => {
                let v1: SettingsV1 = serde_json::from_value(value).map_err(D::Error::custom)?;
                SolverOptions::try_from(v1).map_err(D::Error::custom)
            }
            Some(v) if v.as_u64() == Some(u64::from(SETTINGS_VERSION)) => {
                let v2: SettingsV2 = serde_json::from_value(value).map_err(D::Error::custom)?;
                Ok(v2.into())
            }
            Some(v) => Err(D::Error::custom(format!(
                "settings version {v}: this hylc reads versions 1 (no key) and {SETTINGS_VERSION}"
            ))),
        }
    }
}
