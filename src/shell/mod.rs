//! Macro scale: a triangle-mesh thin shell with the homogenized energy A·ψ(z(q)) per triangle, simulated by
//! implicit Euler as incremental-potential minimisation (`../shared/design/05-macro.md`, Algorithm C8).
//!
//! Data flow, one file per stage: [`strain`] (the strain chain z(q) of a triangle stencil) → [`element`]
//! (triangle energy, gradient, Hessian, PSD options) → [`mesh`] (rectangles, OBJ, stencils) → [`assemble`]
//! (parallel assembly into a fixed sparsity pattern) → [`solver`] (implicit Euler, quasi-static, boundary
//! conditions, obstacles, faer sparse Cholesky) → [`scene`] (JSON scenes and the built-ins). [`checks`] puts the
//! strain chain, the triangle energy and the assembled energy under the derivative harness.
//!
//! Out of scope: remeshing and cloth self-collision.

pub mod strain;

pub use strain::{strain, strain_reference, RestTriangle, StrainChain};
pub mod assemble;
pub mod element;
pub mod mesh;
pub mod render;
pub mod scene;
pub mod solver;

pub use element::{ElementModel, ModelFlags, Psd};
pub use mesh::{Mesh, Stencil};

/// An error of the macro scale: one sentence naming the file, line or field at fault.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShellError(pub String);

impl std::fmt::Display for ShellError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ShellError {}
