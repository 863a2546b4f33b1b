//! The records of a sample file: one [`Record`] per line (JSON), how its solve started and ended, and the starts
//! of a multi-start sample ([`StartResult`]). The run ([`super::run`]) writes them, the multi-start rules
//! ([`super::starts`]) combine them, `read_samples` and the fit read them.

use crate::micro::sensitivity::YarnParameter;
use crate::micro::Status;
use serde::{Deserialize, Serialize};

/// One line of a sample file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    /// Stable sample id (plan hash + index).
    pub id: String,
    /// Index in the plan.
    pub index: usize,
    /// Strain z = (s_x, s_a, s_y, Π₀₀, Π₁₁).
    pub z: [f64; 5],
    /// Ψ̄ (J/m²) when converged, else null.
    pub psi: Option<f64>,
    /// Envelope-theorem stress ∂Ψ̄/∂z (J/m² per unit strain) when converged; a component not defined in the
    /// solve's family is null.
    pub stress: Option<[Option<f64>; 5]>,
    /// `Converged`, `Stalled`, `MaxSteps`, `TimeLimit`, or `Error` (see `error`).
    pub status: SampleStatus,
    /// Why the solve could not run (bad strain, overlapping yarns, failed factorisation).
    pub error: Option<String>,
    /// Newton steps.
    pub steps: usize,
    /// Final ‖g‖∞ (N), null on error.
    pub gradient_norm: Option<f64>,
    /// Wall time of the solve (s), its predictor included.
    pub time: f64,
    /// How the solve started: `cold`, `warm` (previous equilibrium) or `predicted` (secant predictor); `tangent`
    /// in files made with the retired tangent predictor.
    pub start: SampleStart,
    /// Hash of (pattern, yarn parameters, solver settings), 16 hex digits ([`problem_hash`](super::run::problem_hash)).
    pub problem: String,
    /// Every start of a multi-start sample ([`RunOptions::starts`](super::RunOptions::starts); docs/sampling.md); empty (omitted) when the
    /// sample was solved from one start.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub starts: Vec<StartResult>,
    /// Which of `starts` the record's `psi`, `stress`, `status` and `steps` are (omitted with one start).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kept: Option<StartKind>,
    /// Yarn crossings along the kept solve's Newton path that do not cancel (`--crossings count|reject`;
    /// omitted when not checked): a solve with crossings ended in another fabric, so it is no sample
    /// ([`Record::converged_psi`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crossings: Option<usize>,
    /// ∂Ψ̄/∂θ (J/m² per unit of each yarn parameter: Y and G in Pa, γ and f dimensionless, k_c in J/m², r in m) at
    /// the kept equilibrium, the reference state held fixed (`--sensitivities`; omitted otherwise, and on records
    /// that do not count as converged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dpsi_dtheta: Option<PerParameter<f64>>,
    /// dσ/dθ, the total derivative of the record's `stress` along the equilibrium, per parameter the five strain
    /// components in the order of `z` (J/m² per unit strain per unit parameter; null where the stress component is
    /// null). Present with `dpsi_dtheta` where the record has a stress.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dstress_dtheta: Option<PerParameter<[Option<f64>; 5]>>,
}

/// One value per yarn parameter, serialised as an object with the keys of the yarn JSON in the fixed order of
/// [`YarnParameter::ALL`]: `young`, `shear`, `bend_twist_factor`, `contact_stiffness`, `contact_radius_factor`,
/// `radius`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerParameter<T> {
    /// for Young's modulus Y (Pa)
    pub young: T,
    /// for the shear modulus G (Pa)
    pub shear: T,
    /// for the bending-twisting factor γ
    pub bend_twist_factor: T,
    /// for the contact stiffness k_c (J/m²)
    pub contact_stiffness: T,
    /// for the contact radius factor f
    pub contact_radius_factor: T,
    /// for the yarn radius r (m)
    pub radius: T,
}

impl<T: Copy> PerParameter<T> {
    /// From the values in the order of [`YarnParameter::ALL`].
    pub fn from_array(v: [T; 6]) -> Self {
        PerParameter {
            young: v[0],
            shear: v[1],
            bend_twist_factor: v[2],
            contact_stiffness: v[3],
            contact_radius_factor: v[4],
            radius: v[5],
        }
    }

    /// The values in the order of [`YarnParameter::ALL`].
    pub fn to_array(&self) -> [T; 6] {
        [
            self.young,
            self.shear,
            self.bend_twist_factor,
            self.contact_stiffness,
            self.contact_radius_factor,
            self.radius,
        ]
    }

    /// The value of one parameter.
    pub fn get(&self, p: YarnParameter) -> T {
        self.to_array()[YarnParameter::ALL
            .iter()
            .position(|q| *q == p)
            .expect("every parameter is in ALL")]
    }
}

impl Record {
    /// The record as one line of JSON (with its newline), as a sample file holds it.
    pub fn to_line(&self) -> String {
        serde_json::to_string(self)
            .expect("sample records serialise (string keys, no custom serialisers)")
            + "\n"
    }

    /// The same solve result as `other` (strain, status, Ψ̄ bitwise, stress): a repeated id with another result
    /// is a conflict that `merge` and `fit` refuse.
    pub fn same_result(&self, other: &Record) -> bool {
        self.z == other.z
            && self.status == other.status
            && self.psi.map(f64::to_bits) == other.psi.map(f64::to_bits)
            && self.stress == other.stress
    }

    /// Ψ̄ when the sample counts as converged: status `Converged`, a finite Ψ̄ and no yarn crossings along its
    /// path ([`Record::crossings`]). A `Stalled`, `MaxSteps` or `TimeLimit` record may carry the Ψ̄ of its last
    /// iterate, which is not an equilibrium, and a solve that pulled yarns through each other found an
    /// equilibrium of another fabric: neither is a sample (the fit counts them as excluded).
    pub fn converged_psi(&self) -> Option<f64> {
        self.psi.filter(|v| {
            self.status == SampleStatus::Converged
                && v.is_finite()
                && self.crossings.unwrap_or(0) == 0
        })
    }
}

/// How a sample's solve ended: the solver's [`Status`], or `Error` when it could not run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SampleStatus {
    /// The solver converged.
    Converged,
    /// No trial step lowered the energy.
    Stalled,
    /// The step limit was reached.
    MaxSteps,
    /// The time limit was reached.
    TimeLimit,
    /// The solve could not run or stopped with an error.
    Error,
}

impl From<Status> for SampleStatus {
    fn from(s: Status) -> Self {
        match s {
            Status::Converged => SampleStatus::Converged,
            Status::Stalled => SampleStatus::Stalled,
            Status::MaxSteps => SampleStatus::MaxSteps,
            Status::TimeLimit => SampleStatus::TimeLimit,
        }
    }
}

/// How a sample's solve started.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SampleStart {
    /// From the reference state.
    Cold,
    /// From the previous equilibrium of its chain.
    Warm,
    /// From the secant predictor along its chain.
    Predicted,
    /// From the tangent predictor y* + (dy*/dz)·Δz of the step it continues: read in sample files made before the
    /// predictor was retired (`docs/notes/retired-micro-solver-rules.md`), no longer written.
    Tangent,
    /// From the kept equilibrium of a step that continues it (the reversed chain; `--starts all`).
    Reverse,
}

/// Which start a [`StartResult`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StartKind {
    /// The chain's start: its predecessor's equilibrium, extrapolated by the predictor (the record's `start`
    /// says how when this start is kept).
    Warm,
    /// The reference state.
    Cold,
    /// The kept equilibrium of a step that continues this one along the chain (`--starts all`).
    Reverse,
}

/// One start of a multi-start sample: Ψ̄ when converged (else null), status and Newton steps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartResult {
    /// which start
    pub kind: StartKind,
    /// Ψ̄ (J/m²) when converged, else null
    pub psi: Option<f64>,
    /// how its solve ended
    pub status: SampleStatus,
    /// Newton steps
    pub steps: usize,
    /// Yarn crossings of this start's path that do not cancel (omitted when not checked).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crossings: Option<usize>,
}
