//! Scenes (`docs/cloth-simulator.md`, "Scenes are JSON files; built-ins reproduce the original's tests"): the JSON format,
//! the built-in scenes, and the runner that writes an OBJ per frame and a JSON-lines log per step.
//!
//! Format (unknown keys are errors; every key but `material`, `mesh` and `duration` has a default):
//! ```json
//! {
//!   "material": "default",                       // or a material JSON path, relative to the scene file
//!   "mesh": {"rectangle": {"width": 0.3, "height": 0.3, "edge": 0.006, "perturb": 0.0, "seed": 1}},
//!                                                // or {"obj": {"path": "cloth.obj"}} (flat rest layout)
//!   "placement": {"origin": [0,0,0], "u": [1,0,0], "v": [0,1,0]},   // rectangle: x = origin + X u + Y v
//!   "fabric_angle_deg": 0.0,                     // fabric x axis against the mesh x axis
//!   "duration": 1.0, "dt": 0.016666666666666666, "quasi_static": false,
//!   "gravity": [0, 0, -9.81], "drag": 0.0,
//!   "damping": 0.0,                              // stiffness-proportional damping coefficient c (s)
//!   "wind": {"density": 0, "drag": 0, "velocity": [0, 0, 0]},   // air drag (ARCSim's wind)
//!   "handle_stiffness": null,                    // null: pins and handles are hard constraints; a number k
//!                                                // (N/m): each held vertex is a spring ½ k |x − target|²
//!   "model": {"bending": true, "only_1d": false, "in_plane_only": false,
//!             "stiffness": 1.0, "bending_scale": 1.0, "mass": 1.0,
//!             "fold_barrier": {"angle": 2.5, "stiffness": 1.0},    // null: none (`super::fold`)
//!             "collapse_barrier": {"area": 0.2, "stiffness": 1.0}}, // null: none (`super::fold`)
//!   "psd": "full",                               // "full" (18×18), "psi" (6×6), "none" (diagonal shift)
//!   "solver": {"force_tol": 1e-6, "max_newton": 50, "exact_first": true, "max_halvings": 6,
//!              "time_tol": null,                 // a length (m): substeps chosen by their estimated error
//!              "integrator": "implicit-euler",   // or "linearized" (ARCSim's scheme, one Newton step)
//!              "substeps": 1},                   // equal substeps per step (ARCSim's frame_steps)
//!   "pins": [{"near": {"point": [0, 0], "radius": 0.01}}],
//!   "handles": [{"name": "left", "select": {"box": {"min": [0, 0.05], "max": [0.021, 0.25]}},
//!                "keyframes": [[0, [0, 0, 0]], [0.25, [-0.02, 0, 0]]],
//!                "interpolation": "linear"}],     // or "hermite" (`super::motion`); a Hermite keyframe may
//!                                                 // give its velocity: [t, [x, y, z], [vx, vy, vz]]
//!   "obstacles": [{"sphere": {"center": [0.15, 0.15, -0.032], "radius": 0.03,
//!                             "motion": {"keyframes": [[0, [0, 0, 0]], [1, [0, 0, 0.05]]]}}},  // optional
//!                 {"plane": {"point": [0, 0, -0.5], "normal": [0, 0, 1]}},
//!                 {"mesh": {"path": "sphere.obj", "transform": {"scale": 0.03, "translate": [0, 0, -0.04]}}}],
//!   "contact": {"thickness": 0.002, "stiffness": 1e8, "friction": 0.0, "friction_velocity": 1e-3},
//!   "output": {"obj_every": 1, "vtu": false}
//! }
//! ```
//! Selections are in rest-layout (mesh-plane) coordinates, metres; `{"ball": {"center": [x, y, z], "radius": r}}`
//! selects by initial 3D position; `{"vertices": [..]}` lists 0-based vertex indices (OBJ order). An OBJ mesh's
//! `transform` (`scale`, `translate`, `rotate`: [angle in degrees, axis x, y, z], applied in that order) places it:
//! the rest layout is the scaled OBJ, the initial state the transformed one.
//!
//! Every pin and handle reports its reaction in the log (`handle_forces`, and `handle_forces.csv`): handles
//! under their names, pins as `pin0`, `pin1`, … in the order of `pins`.

pub use super::dissipation::Wind;
use super::element::{ElementModel, ModelFlags, Psd};
pub use super::fold::{CollapseBarrier, FoldBarrier};
use super::mesh::{load_obj_surface, write_obj, Mesh};
pub use super::motion::{Interpolation, Keyframe, Motion};
use super::obstacle::{MeshObstacle, Obstacle};
pub use super::solver::Integrator;
use super::solver::{Boundary, Handle, Settings, Simulation, StepReport};
use super::ShellError;
use crate::material::synthetic::default_material;
use crate::material::Material;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

fn one() -> f64 {
    1.0
}
fn yes() -> bool {
    true
}
fn default_dt() -> f64 {
    1.0 / 60.0
}
fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -9.81]
}
fn default_psd() -> Psd {
    Psd::Full
}
fn default_seed() -> u64 {
    1
}

/// A scene file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// a label for the scene (the built-ins and converted ARCSim scenes carry their names); empty by default
    #[serde(default)]
    pub name: String,
    /// `"default"` (the built-in synthetic material) or a material JSON path, relative to the scene file
    pub material: String,
    /// the cloth mesh: a generated rectangle or an OBJ file
    pub mesh: MeshSpec,
    /// where a rectangle's rest layout is put in space (x = origin + X u + Y v)
    #[serde(default)]
    pub placement: Placement,
    /// angle (degrees) of the fabric x axis (the warp) against the mesh x axis
    #[serde(default)]
    pub fabric_angle_deg: f64,
    /// simulated time (s); the scene takes ⌈duration / dt⌉ steps ([`Scene::steps`])
    pub duration: f64,
    /// time step h (s); 1/60 by default
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// minimise E − f·x per step instead of the incremental potential (no inertia)
    #[serde(default)]
    pub quasi_static: bool,
    /// gravitational acceleration g (m/s²); (0, 0, −9.81) by default
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// linear drag rate c (1/s)
    #[serde(default)]
    pub drag: f64,
    /// stiffness-proportional damping coefficient c (s)
    #[serde(default)]
    pub damping: f64,
    /// air drag (ARCSim's wind); none by default
    #[serde(default)]
    pub wind: Wind,
    /// `None`: pins and handles are hard constraints; `Some(k)`: each held vertex is a spring ½ k |x − target|² (k in N/m)
    #[serde(default)]
    pub handle_stiffness: Option<f64>,
    /// which parts of ψ the elements evaluate, and the stiffness and mass multipliers
    #[serde(default)]
    pub model: ModelSpec,
    /// how the element Hessians are made positive semi-definite (`"full"`, `"psi"`, `"none"`)
    #[serde(default = "default_psd")]
    pub psd: Psd,
    /// Newton and time-stepping settings
    #[serde(default)]
    pub solver: SolverSpec,
    /// vertices held fixed at their initial positions (reported as `pin0`, `pin1`, …)
    #[serde(default)]
    pub pins: Vec<Selection>,
    /// named vertex groups following keyframed translations
    #[serde(default)]
    pub handles: Vec<HandleSpec>,
    /// spheres, planes and meshes the cloth collides with
    #[serde(default)]
    pub obstacles: Vec<ObstacleSpec>,
    /// obstacle contact layer, penalty and friction
    #[serde(default)]
    pub contact: ContactSpec,
    /// which files the runner writes per frame
    #[serde(default)]
    pub output: OutputSpec,
}

/// The cloth mesh of a scene file: a generated rectangle or an OBJ file (`"rectangle"` / `"obj"`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum MeshSpec {
    /// A `width` × `height` rectangle with corner (0, 0), split into squares of alternating diagonals.
    Rectangle {
        /// extent along x (m)
        width: f64,
        /// extent along y (m)
        height: f64,
        /// target edge length (m): the cell size is about this
        edge: f64,
        /// random displacement of the vertices, as a fraction of the cell size (< 0.5; 0: none; boundary vertices move along their side)
        #[serde(default)]
        perturb: f64,
        /// seed of the perturbation
        #[serde(default = "default_seed")]
        seed: u64,
    },
    /// A Wavefront OBJ surface; its (scaled) flat layout is the rest state.
    Obj {
        /// the OBJ file, relative to the scene file
        path: String,
        /// the placement of the initial state (the rest layout is the scaled OBJ)
        #[serde(default, skip_serializing_if = "Transform::is_identity")]
        transform: Transform,
    },
}

/// A rigid placement with a uniform scale (ARCSim's `transform`): x ↦ R(s x) + t, R the rotation by
/// `rotate[0]` degrees about the axis `rotate[1..4]`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Transform {
    /// uniform scale s
    pub scale: f64,
    /// translation t (m)
    pub translate: [f64; 3],
    /// rotation: [angle in degrees, axis x, y, z]
    pub rotate: [f64; 4],
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            scale: 1.0,
            translate: [0.0; 3],
            rotate: [0.0, 0.0, 0.0, 1.0],
        }
    }
}

impl Transform {
    /// Whether this is the default transform (scale 1, no translation, no rotation).
    pub fn is_identity(&self) -> bool {
        *self == Transform::default()
    }

    /// The rotation matrix (Rodrigues); the identity for a zero angle or axis.
    pub fn rotation(&self) -> [[f64; 3]; 3] {
        let [deg, x, y, z] = self.rotate;
        let l = (x * x + y * y + z * z).sqrt();
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        if deg == 0.0 || l == 0.0 {
            return id;
        }
        let k = [x / l, y / l, z / l];
        let (sn, cs) = deg.to_radians().sin_cos();
        let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
        std::array::from_fn(|i| {
            std::array::from_fn(|j| id[i][j] * cs + sn * kx[i][j] + (1.0 - cs) * k[i] * k[j])
        })
    }

    /// R(s p) + t.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = self.rotation();
        std::array::from_fn(|i| {
            (0..3).map(|j| r[i][j] * self.scale * p[j]).sum::<f64>() + self.translate[i]
        })
    }
}

/// An obstacle of a scene file (a mesh is loaded when the scene is built).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum ObstacleSpec {
    /// A sphere.
    Sphere {
        /// centre (m)
        center: [f64; 3],
        /// radius (m)
        radius: f64,
        /// its translation over time (none: fixed)
        #[serde(default, skip_serializing_if = "Option::is_none")]
        motion: Option<Motion>,
    },
    /// A half-space bounded by a plane.
    Plane {
        /// a point on the plane (m)
        point: [f64; 3],
        /// the outward normal (the cloth stays on its side)
        normal: [f64; 3],
        /// its translation over time (none: fixed)
        #[serde(default, skip_serializing_if = "Option::is_none")]
        motion: Option<Motion>,
    },
    /// A triangle mesh read from an OBJ file.
    Mesh {
        /// the OBJ file, relative to the scene file
        path: String,
        /// its placement
        #[serde(default, skip_serializing_if = "Transform::is_identity")]
        transform: Transform,
        /// its translation over time (none: fixed)
        #[serde(default, skip_serializing_if = "Option::is_none")]
        motion: Option<Motion>,
    },
}

impl ObstacleSpec {
    /// The obstacle's translation over time (none: it stays put).
    pub fn motion(&self) -> Option<&Motion> {
        match self {
            ObstacleSpec::Sphere { motion, .. }
            | ObstacleSpec::Plane { motion, .. }
            | ObstacleSpec::Mesh { motion, .. } => motion.as_ref(),
        }
    }
}

/// The placement of a rectangle's rest layout in space: x = origin + X u + Y v.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    /// position of the rest-layout origin (m)
    pub origin: [f64; 3],
    /// image of the rest-layout x axis
    pub u: [f64; 3],
    /// image of the rest-layout y axis
    pub v: [f64; 3],
}

impl Default for Placement {
    fn default() -> Self {
        Placement {
            origin: [0.0; 3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
        }
    }
}

/// "Model only what a scene requires" (`ModelFlags`) plus the mass multiplier.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// evaluate the bending strains (hinges); false: II ≡ 0
    #[serde(default = "yes")]
    pub bending: bool,
    /// keep only the 1D terms of ψ (the original's `only1D`)
    #[serde(default)]
    pub only_1d: bool,
    /// keep only the in-plane terms of ψ; implies no bending
    #[serde(default)]
    pub in_plane_only: bool,
    /// stiffness multiplier k of ψ
    #[serde(default = "one")]
    pub stiffness: f64,
    /// bending scale β (multiplies II before ψ)
    #[serde(default = "one")]
    pub bending_scale: f64,
    /// multiplier of every lumped vertex mass (1: the material's areal density)
    #[serde(default = "one")]
    pub mass: f64,
    /// the fold barrier ([`FoldBarrier`]); on by default, `null` turns it off
    #[serde(default = "default_fold")]
    pub fold_barrier: Option<FoldBarrier>,
    /// the collapse barrier ([`CollapseBarrier`]); on by default, `null` turns it off
    #[serde(default = "default_collapse")]
    pub collapse_barrier: Option<CollapseBarrier>,
}

fn default_collapse() -> Option<CollapseBarrier> {
    Some(CollapseBarrier::default())
}

fn default_fold() -> Option<FoldBarrier> {
    Some(FoldBarrier::default())
}

impl Default for ModelSpec {
    fn default() -> Self {
        ModelSpec {
            bending: true,
            only_1d: false,
            in_plane_only: false,
            stiffness: 1.0,
            bending_scale: 1.0,
            mass: 1.0,
            fold_barrier: default_fold(),
            collapse_barrier: default_collapse(),
        }
    }
}

/// Newton and time-stepping settings of a scene file (defaults those of [`Settings`]).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    /// convergence: largest residual force on a free vertex (N)
    pub force_tol: f64,
    /// Newton iterations per step at most
    pub max_newton: usize,
    /// try the exact Hessian first and fall back to the PSD option's Hessian only when its factorisation fails
    pub exact_first: bool,
    /// a step whose Newton iterations do not converge is retried with the time step halved, at most this many
    /// times (6: down to 1/64 of it)
    pub max_halvings: u32,
    /// the largest estimated local error of a substep (m), `None` (the default): substeps shorten only when
    /// Newton fails (`super::solver`, "Accuracy")
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_tol: Option<f64>,
    /// the scheme of a substep (`super::solver`, "Integrators")
    #[serde(skip_serializing_if = "is_implicit_euler")]
    pub integrator: Integrator,
    /// equal substeps per step (ARCSim's `frame_steps`), before any adaptive halving
    #[serde(skip_serializing_if = "is_one")]
    pub substeps: u32,
}

fn is_implicit_euler(i: &Integrator) -> bool {
    *i == Integrator::ImplicitEuler
}

fn is_one(k: &u32) -> bool {
    *k == 1
}

impl Default for SolverSpec {
    fn default() -> Self {
        let s = Settings::default();
        SolverSpec {
            force_tol: s.force_tol,
            max_newton: s.max_newton,
            exact_first: s.exact_first,
            max_halvings: s.max_halvings,
            time_tol: s.time_tol,
            integrator: s.integrator,
            substeps: s.substeps,
        }
    }
}

/// Obstacle contact of a scene file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// obstacle layer thickness δ (m)
    pub thickness: f64,
    /// obstacle penalty k (1/(m·s²)): E = m k p³/3, p the penetration of the layer
    pub stiffness: f64,
    /// Coulomb friction coefficient μ against obstacles (lagged friction)
    #[serde(default)]
    pub friction: f64,
    /// sliding-velocity threshold ε_v (m/s) of the smoothed friction
    #[serde(default = "default_friction_velocity")]
    pub friction_velocity: f64,
}

fn default_friction_velocity() -> f64 {
    Settings::default().friction_velocity
}

impl Default for ContactSpec {
    fn default() -> Self {
        let s = Settings::default();
        ContactSpec {
            thickness: s.thickness,
            stiffness: s.contact_stiffness,
            friction: s.friction,
            friction_velocity: s.friction_velocity,
        }
    }
}

/// The runner's per-frame output of a scene file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// write an OBJ every this many frames (0: none)
    pub obj_every: usize,
    /// also a `.vtu` beside each OBJ frame, with ψ and the strain per triangle (`shell::vtu`)
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub vtu: bool,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            obj_every: 1,
            vtu: false,
        }
    }
}

/// A vertex selection in rest-layout coordinates.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Selection {
    /// The vertices inside an axis-aligned box of the rest layout.
    Box {
        /// lower corner (m)
        min: [f64; 2],
        /// upper corner (m)
        max: [f64; 2],
    },
    /// The vertices within `radius` of a rest-layout point.
    Near {
        /// the point (m)
        point: [f64; 2],
        /// the radius (m)
        radius: f64,
    },
    /// The vertices whose initial 3D position lies in a ball.
    Ball {
        /// centre (m)
        center: [f64; 3],
        /// radius (m)
        radius: f64,
    },
    /// The listed 0-based vertex indices (OBJ order).
    Vertices(Vec<usize>),
}

impl Selection {
    /// The first listed vertex index the mesh of `vertices` vertices does not have (only `{"vertices": [..]}`
    /// lists indices).
    fn out_of_range(&self, vertices: usize) -> Option<usize> {
        match self {
            Selection::Vertices(list) => list.iter().copied().find(|&v| v >= vertices),
            _ => None,
        }
    }

    /// The selection's vertices, or an error naming `field` when it lists a vertex the mesh does not have or
    /// selects none.
    fn select_checked(
        &self,
        mesh: &Mesh,
        x0: &[[f64; 3]],
        file: &str,
        field: String,
    ) -> Result<Vec<usize>, ShellError> {
        if let Some(index) = self.out_of_range(mesh.len()) {
            return Err(ShellError::SelectionIndex {
                file: file.to_string(),
                field,
                index,
                vertices: mesh.len(),
            });
        }
        let v = self.select(mesh, x0);
        if v.is_empty() {
            return Err(ShellError::Selection {
                file: file.to_string(),
                field,
                problem: "selects no vertex",
            });
        }
        Ok(v)
    }

    /// The selected vertices; `x0` the initial positions (for `ball`).
    pub fn select(&self, mesh: &Mesh, x0: &[[f64; 3]]) -> Vec<usize> {
        let eps = 1e-9;
        (0..mesh.len())
            .filter(|&v| {
                let p = mesh.rest[v];
                match self {
                    Selection::Box { min, max } => {
                        (0..2).all(|k| p[k] >= min[k] - eps && p[k] <= max[k] + eps)
                    }
                    Selection::Near { point, radius } => {
                        (p[0] - point[0]).hypot(p[1] - point[1]) <= radius + eps
                    }
                    Selection::Ball { center, radius } => {
                        let q = x0[v];
                        let d2: f64 = (0..3).map(|k| (q[k] - center[k]).powi(2)).sum();
                        d2.sqrt() <= radius + eps
                    }
                    Selection::Vertices(list) => list.contains(&v),
                }
            })
            .collect()
    }
}

/// A handle of a scene file: a named vertex selection following a keyframed translation
/// ([`Motion`]; `keyframes` and `interpolation` as there).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HandleSpec {
    /// the name its reaction is reported under
    pub name: String,
    /// the vertices it holds
    pub select: Selection,
    /// its keyframes (time in s, offset in m)
    pub keyframes: Vec<Keyframe>,
    /// linear (default) or Hermite interpolation between keyframes
    #[serde(default, skip_serializing_if = "is_linear")]
    pub interpolation: Interpolation,
}

fn is_linear(i: &Interpolation) -> bool {
    *i == Interpolation::Linear
}

impl HandleSpec {
    /// The handle's motion.
    pub fn motion(&self) -> Motion {
        Motion {
            keyframes: self.keyframes.clone(),
            interpolation: self.interpolation,
        }
    }
}

/// The most time steps a scene may take (⌈duration / dt⌉): a million steps are hours of wall time even on the
/// smallest meshes (the built-ins take 60, `hylc run`'s drape 240); checked before the simulation is built.
pub const MAX_STEPS: usize = 1_000_000;

/// The smallest time step (s) a dynamic scene accepts: the inertia term m/dt² of the Newton matrix grows as
/// 1/dt², and below a nanosecond it swamps the elastic terms by more than the precision of a double.
pub const MIN_DT: f64 = 1e-9;

/// The largest coordinate or length (m) a scene accepts in its placement origin, handle offsets and obstacles: a
/// thousand kilometres, far beyond any cloth, and far from overflow when squared.
pub const MAX_COORDINATE: f64 = 1e6;

/// The largest component of the placement axes `u` and `v` (they scale the rest layout into the initial state;
/// unit vectors place it unstretched).
pub const MAX_AXIS: f64 = 1e3;

/// The largest gravity magnitude (m/s²) a scene accepts: a thousand times the Earth's, far beyond any cloth
/// experiment, and small enough that the forces m g stay many orders of magnitude from overflow.
pub const MAX_GRAVITY: f64 = 1e4;

/// The most Newton iterations per step a scene may ask for (`solver.max_newton`): the default is 50; more than
/// 10 000 only delays the report of a step that does not converge.
pub const MAX_NEWTON: usize = 10_000;

/// The most equal substeps per step a scene may ask for (`solver.substeps`; the original's scenes use 50–100).
pub const MAX_SUBSTEPS: u32 = 100_000;

/// The most time-step halvings a scene may allow (`solver.max_halvings`): 2⁻²⁰ of a step is below any
/// useful time scale of cloth.
pub const MAX_HALVINGS: u32 = 20;

impl Scene {
    /// Parse scene JSON (a leading UTF-8 byte-order mark is skipped); `name` (the file) is used in error messages.
    pub fn from_json_str(text: &str, name: &str) -> Result<Scene, ShellError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        serde_json::from_str(text).map_err(|source| ShellError::Json {
            file: name.to_string(),
            source,
        })
    }

    /// Read a scene file, or a built-in by name when no such file exists.
    pub fn load(arg: &str) -> Result<(Scene, PathBuf), ShellError> {
        let p = Path::new(arg);
        if !p.exists() {
            if let Some(s) = builtin(arg) {
                return Ok((s, PathBuf::from(".")));
            }
            return Err(ShellError::UnknownScene {
                name: arg.to_string(),
            });
        }
        let text = std::fs::read_to_string(p).map_err(|e| ShellError::io(p, "cannot read", e))?;
        let s = Scene::from_json_str(&text, arg)?;
        let dir = p.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok((s, dir))
    }

    /// Number of steps for the duration.
    pub fn steps(&self) -> usize {
        (self.duration / self.dt - 1e-9).ceil().max(0.0) as usize
    }
}

mod build;
mod builtin;
mod run;
mod validate;

pub use builtin::{builtin, BUILTINS, BUILTIN_EDGE, SIDE};
pub use run::{run, run_until, run_with, RunSummary};
