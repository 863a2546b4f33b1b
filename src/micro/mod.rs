//! Micro scale: homogenization of one periodic tile (`docs/micro-solver.md`, Algorithms C1–C3).
//!
//! Data flow: a macro strain ([`strain`]) selects a closed-form surface map ([`surface`]); the kinematics
//! ([`elimination`]) place every vertex copy affinely in the unknowns; the Newton solver ([`solver`]) with its
//! constrained linear system ([`linear`]) finds the equilibrium; [`envelope`] turns it into Ψ̄ and its
//! derivatives; [`sensitivity`] gives the equilibrium's derivatives with respect to the yarn parameters.

pub mod elimination;
pub mod envelope;
pub mod linear;
pub mod options;
pub mod path;
pub mod predict;
pub mod reference;
pub mod sensitivity;
pub mod solver;
pub mod strain;
pub mod surface;

pub use elimination::Elimination;
pub use options::SETTINGS_VERSION;
pub use predict::Predictor;
pub use solver::{
    CrossingGuard, MicroError, MicroProblem, MicroState, Solution, SolverOptions, Status, StepRule,
};
pub use strain::{Family, MacroStrain, StrainError};
