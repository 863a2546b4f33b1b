//! Macro scale: a triangle-mesh thin shell with the homogenized energy A·ψ(z(q)) per triangle, simulated by
//! implicit Euler as incremental-potential minimisation (`docs/cloth-simulator.md`, Algorithm C8).
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
pub mod arcsim;
pub mod assemble;
pub mod damping_lag;
pub mod dissipation;
pub mod element;
pub mod fold;
pub mod mesh;
pub mod motion;
pub mod obstacle;
pub mod render;
pub mod scene;
pub mod solver;
pub mod vtu;

pub use element::{ElementModel, ModelFlags, Psd};
pub use mesh::{Mesh, Stencil};

use std::path::{Path, PathBuf};

/// An error of the macro scale: one sentence naming the file, line, field or value at fault.
#[derive(Debug, thiserror::Error)]
pub enum ShellError {
    /// A file or folder could not be read or written.
    #[error("{}: {action}: {source}", path.display())]
    Io {
        /// the file or folder
        path: PathBuf,
        /// What was being done ("cannot read", "cannot write", …).
        action: &'static str,
        /// the underlying I/O error
        source: std::io::Error,
    },
    /// A PNG snapshot could not be encoded or written.
    #[error("{}: cannot write PNG: {source}", path.display())]
    Png {
        /// the PNG file
        path: PathBuf,
        /// the encoder's error
        source: image::ImageError,
    },
    /// A scene file that is not valid scene JSON (syntax, unknown or missing keys, wrong types).
    #[error("{file}: {source}")]
    Json {
        /// the scene file
        file: String,
        /// the parser's error (with line and column)
        source: serde_json::Error,
    },
    /// Neither a scene file nor the name of a built-in scene.
    #[error("{name}: no such scene file and not a built-in scene ({})", scene::BUILTINS.join(", "))]
    UnknownScene {
        /// the argument given
        name: String,
    },
    /// An ARCSim scene file (`arcsim`) that is not JSON with comments: the file, line and column at fault.
    #[error("{file}:{line}:{column}: not an ARCSim scene file: {message}")]
    ArcsimSyntax {
        /// the ARCSim file
        file: String,
        /// line (1-based)
        line: usize,
        /// column (1-based)
        column: usize,
        /// what is wrong
        message: String,
    },
    /// A key of an ARCSim scene file (`arcsim`) that is missing, of the wrong type or out of range: the file,
    /// the line of the value (or of the enclosing object for a missing key) and the key's path.
    #[error("{file}:{line}: key `{key}`: {message}")]
    Arcsim {
        /// the ARCSim file
        file: String,
        /// line (1-based) of the value, or of the enclosing object for a missing key
        line: usize,
        /// the key's path
        key: String,
        /// what is wrong
        message: String,
    },
    /// A scene field with a value the scene cannot use.
    #[error("{file}: field `{field}`: {message}")]
    Scene {
        /// the scene file
        file: String,
        /// the field's path
        field: String,
        /// what is wrong
        message: String,
    },
    /// A vertex selection of a scene (a pin or a handle) that cannot be used.
    #[error("{file}: field `{field}` {problem}")]
    Selection {
        /// the scene file
        file: String,
        /// the selection's field path
        field: String,
        /// "selects no vertex"
        problem: &'static str,
    },
    /// A vertex selection of a scene listing a vertex index the mesh does not have.
    #[error("{file}: field `{field}`: vertex index {index} out of range (the mesh has {vertices} vertices, 0-based)")]
    SelectionIndex {
        /// the scene file
        file: String,
        /// the selection's field path
        field: String,
        /// the listed vertex index (0-based)
        index: usize,
        /// the number of vertices of the mesh
        vertices: usize,
    },
    /// The material file a scene names could not be loaded.
    #[error("{file}: field `material`: {source}")]
    Material {
        /// the scene file
        file: String,
        /// the material loader's error
        source: crate::material::json::MaterialError,
    },
    /// The rectangle mesh a scene describes could not be generated.
    #[error("{file}: field `mesh`: {source}")]
    SceneMesh {
        /// the scene file
        file: String,
        /// the mesh generator's error
        source: Box<ShellError>,
    },
    /// An obstacle mesh that cannot be used (not a manifold, consistently oriented triangle mesh).
    #[error("{file}: {problem}")]
    ObstacleMesh {
        /// the obstacle's OBJ file
        file: String,
        /// what is wrong
        problem: String,
    },
    /// A time tolerance that is not a positive finite length.
    #[error("time tolerance {tol}: expected a positive finite length (m)")]
    TimeTolerance {
        /// the tolerance given (m)
        tol: f64,
    },
    /// Zero substeps per step.
    #[error("substeps per step: expected at least 1, got 0")]
    Substeps,
    /// More obstacle motions than obstacles were given to a simulation.
    #[error("{motions} obstacle motions for {obstacles} obstacles (one per obstacle at most)")]
    ObstacleMotions {
        /// the number of motions given
        motions: usize,
        /// the number of obstacles
        obstacles: usize,
    },
    /// A scene's simulation could not be set up.
    #[error("{file}: {source}")]
    SceneSetup {
        /// the scene file
        file: String,
        /// the setup's error
        source: Box<ShellError>,
    },
    /// Bad rectangle dimensions.
    #[error("rectangle: {message}")]
    Rectangle {
        /// what is wrong
        message: String,
    },
    /// A problem in an OBJ file, at a line when it has one.
    #[error("{file}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Obj {
        /// the OBJ file
        file: String,
        /// line (1-based), if the problem has one
        line: Option<usize>,
        /// what is wrong
        message: String,
    },
    /// A bad triangle of a mesh; `origin` is where it came from (`file:line`, or a rectangle's triangle number).
    #[error("{origin}: {message}")]
    Triangle {
        /// where the triangle came from (`file:line` or a rectangle's triangle number)
        origin: String,
        /// what is wrong
        message: String,
    },
    /// A time step that is not a positive number.
    #[error("time step must be positive, got {dt}")]
    TimeStep {
        /// the time step given (s)
        dt: f64,
    },
    /// A pinned or handle vertex that the mesh does not have.
    #[error("constrained vertex {vertex} out of range ({vertices} vertices)")]
    VertexOutOfRange {
        /// the vertex index (0-based)
        vertex: usize,
        /// the number of vertices of the mesh
        vertices: usize,
    },
    /// A vertex without positive mass in a dynamic simulation.
    #[error(
        "every vertex needs a positive mass (material density, mass multiplier, unused vertices?)"
    )]
    Mass,
    /// The symbolic analysis of the Newton matrix failed.
    #[error("symbolic factorisation failed: {source:?}")]
    Symbolic {
        /// faer's error
        source: faer::sparse::FaerError,
    },
    /// A triangle of the initial state is degenerate.
    #[error("a triangle is degenerate in the initial state")]
    DegenerateInitial,
    /// A triangle is degenerate at the start of a step (before any Newton iteration), at time `time`.
    #[error(
        "step {step} (t = {time:.4} s): a triangle is degenerate at the start of the step (handles moved too far \
         in one step?)"
    )]
    DegenerateStart {
        /// the step number
        step: usize,
        /// the simulated time (s)
        time: f64,
    },
    /// A triangle became degenerate during a step's Newton iterations.
    #[error("step {step}: a triangle became degenerate")]
    Degenerate {
        /// the step number
        step: usize,
    },
    /// The material's energy is not finite (NaN or infinite) at a triangle's strain, in the initial state
    /// (`step` None) or during step `step`.
    #[error(
        "{}the material's energy is not finite at triangle {triangle} (strain z = {z:?}): the material evaluates \
         to NaN or infinity there",
        step.map(|s| format!("step {s}: ")).unwrap_or_default()
    )]
    NonFiniteMaterial {
        /// the triangle's index
        triangle: usize,
        /// its strain z = (s_x, s_a, s_y, II_x, II_a, II_y)
        z: [f64; 6],
        /// the step, `None` in the initial state
        step: Option<usize>,
    },
    /// A quantity of a step is not finite: the simulation diverged and stops (no NaN or infinity is reported as a
    /// result); `hylc simulate` exits with code 3.
    #[error(
        "step {step} (t = {time:.4} s): the {quantity} is {value}: the simulation diverged (a smaller dt, smaller \
         loads?)"
    )]
    NonFiniteState {
        /// the step number
        step: usize,
        /// the simulated time (s)
        time: f64,
        /// the quantity that is not finite (e.g. the energy)
        quantity: &'static str,
        /// its value
        value: f64,
    },
    /// A step that did not converge even at the smallest allowed substep: the run stops (what was written
    /// stays); `hylc simulate` exits with code 3.
    #[error(
        "step {step} (t = {time:.4} s): Newton did not converge even with the time step halved {halvings} times \
         (substep {dt:.3e} s; residual force {residual:.3e} N after {newton} iterations): a larger \
         solver.max_newton or max_halvings, a smaller dt?"
    )]
    StepFailed {
        /// the step number
        step: usize,
        /// the simulated time (s)
        time: f64,
        /// how many times the time step was halved
        halvings: u32,
        /// the last substep tried (s)
        dt: f64,
        /// the largest residual force on a free vertex at the end (N)
        residual: f64,
        /// Newton iterations of the last attempt
        newton: usize,
    },
    /// The Newton matrix of a step could not be factorised at any diagonal shift.
    #[error("step {step}: the Newton system could not be factorised even with a diagonal shift")]
    Factorization {
        /// the step number
        step: usize,
    },
    /// The exact Hessian at an equilibrium is not positive definite: it is not a strict minimum and its
    /// sensitivities are undefined (`solver::adjoint`).
    #[error(
        "the exact Hessian at the state (largest residual force {residual:e} N) is not positive definite: \
         not a strict minimum, so its sensitivities are undefined"
    )]
    NotStrictMinimum {
        /// the largest residual force on a free vertex (N)
        residual: f64,
    },
    /// Sensitivities asked for where the adjoint does not apply.
    #[error("sensitivities unavailable: {reason}")]
    AdjointUnsupported {
        /// why
        reason: &'static str,
    },
    /// A reaction asked for a held set that does not exist.
    #[error("no held set named {set:?} (the handles' names, or `pinned`)")]
    UnknownHeldSet {
        /// the name asked for
        set: String,
    },
}

impl ShellError {
    /// An I/O error on `path` while doing `action`.
    pub fn io(path: &Path, action: &'static str, source: std::io::Error) -> Self {
        ShellError::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    }

    /// A bad value of a scene field.
    pub fn scene(file: &str, field: &str, message: impl Into<String>) -> Self {
        ShellError::Scene {
            file: file.to_string(),
            field: field.to_string(),
            message: message.into(),
        }
    }
}
