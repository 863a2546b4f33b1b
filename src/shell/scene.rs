//! Scenes (`05-macro.md`, "Scenes are JSON files; built-ins reproduce the original's tests"): the JSON format,
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
//!   "model": {"bending": true, "only_1d": false, "in_plane_only": false,
//!             "stiffness": 1.0, "bending_scale": 1.0, "mass": 1.0},
//!   "psd": "full",                               // "full" (18×18), "psi" (6×6), "none" (diagonal shift)
//!   "solver": {"force_tol": 1e-6, "max_newton": 50, "exact_first": true},
//!   "pins": [{"near": {"point": [0, 0], "radius": 0.01}}],
//!   "handles": [{"name": "left", "select": {"box": {"min": [0, 0.05], "max": [0.021, 0.25]}},
//!                "keyframes": [[0, [0, 0, 0]], [0.25, [-0.02, 0, 0]]]}],
//!   "obstacles": [{"sphere": {"center": [0.15, 0.15, -0.032], "radius": 0.03}},
//!                 {"plane": {"point": [0, 0, -0.5], "normal": [0, 0, 1]}}],
//!   "contact": {"thickness": 0.002, "stiffness": 1e8},
//!   "output": {"obj_every": 1}
//! }
//! ```
//! Selections are in rest-layout (mesh-plane) coordinates, metres; `{"vertices": [..]}` lists 0-based vertex
//! indices (OBJ order).

use super::element::{ElementModel, ModelFlags, Psd};
use super::mesh::{write_obj, Mesh};
use super::solver::{Boundary, Handle, Obstacle, Settings, Simulation, StepReport};
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
    #[serde(default)]
    pub name: String,
    pub material: String,
    pub mesh: MeshSpec,
    #[serde(default)]
    pub placement: Placement,
    #[serde(default)]
    pub fabric_angle_deg: f64,
    pub duration: f64,
    #[serde(default = "default_dt")]
    pub dt: f64,
    #[serde(default)]
    pub quasi_static: bool,
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    #[serde(default)]
    pub drag: f64,
    #[serde(default)]
    pub model: ModelSpec,
    #[serde(default = "default_psd")]
    pub psd: Psd,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub pins: Vec<Selection>,
    #[serde(default)]
    pub handles: Vec<HandleSpec>,
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    #[serde(default)]
    pub contact: ContactSpec,
    #[serde(default)]
    pub output: OutputSpec,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum MeshSpec {
    Rectangle {
        width: f64,
        height: f64,
        edge: f64,
        #[serde(default)]
        perturb: f64,
        #[serde(default = "default_seed")]
        seed: u64,
    },
    Obj {
        path: String,
    },
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    pub origin: [f64; 3],
    pub u: [f64; 3],
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
    #[serde(default = "yes")]
    pub bending: bool,
    #[serde(default)]
    pub only_1d: bool,
    #[serde(default)]
    pub in_plane_only: bool,
    #[serde(default = "one")]
    pub stiffness: f64,
    #[serde(default = "one")]
    pub bending_scale: f64,
    #[serde(default = "one")]
    pub mass: f64,
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
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    pub force_tol: f64,
    pub max_newton: usize,
    pub exact_first: bool,
}

impl Default for SolverSpec {
    fn default() -> Self {
        let s = Settings::default();
        SolverSpec {
            force_tol: s.force_tol,
            max_newton: s.max_newton,
            exact_first: s.exact_first,
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    pub thickness: f64,
    pub stiffness: f64,
}

impl Default for ContactSpec {
    fn default() -> Self {
        let s = Settings::default();
        ContactSpec {
            thickness: s.thickness,
            stiffness: s.contact_stiffness,
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// write an OBJ every this many frames (0: none)
    pub obj_every: usize,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec { obj_every: 1 }
    }
}

/// A vertex selection in rest-layout coordinates.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Selection {
    Box { min: [f64; 2], max: [f64; 2] },
    Near { point: [f64; 2], radius: f64 },
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
        let v = self.select(mesh);
        if v.is_empty() {
            return Err(ShellError::Selection {
                file: file.to_string(),
                field,
                problem: "selects no vertex",
            });
        }
        Ok(v)
    }

    fn select(&self, mesh: &Mesh) -> Vec<usize> {
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
                    Selection::Vertices(list) => list.contains(&v),
                }
            })
            .collect()
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HandleSpec {
    pub name: String,
    pub select: Selection,
    pub keyframes: Vec<(f64, [f64; 3])>,
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

/// Names of the built-in scenes.
pub const BUILTINS: [&str; 5] = ["stretch-x", "stretch-y", "drape-x", "drape-y", "hanging"];

/// Side of the built-in squares (m) and their default edge length: 51 × 51 cells, 5 202 triangles.
pub const SIDE: f64 = 0.3;
pub const BUILTIN_EDGE: f64 = 0.3 / 51.0;

/// A built-in scene matching the original's tests (30 × 30 cm, 1 s at 1/60 s steps, PSD option `psi`):
/// - `stretch-x` / `stretch-y`: two strips on opposite sides (67 % of the side long, 7 % of it wide, inset 16.5 %
///   from the corners) pulled apart 2 cm each over 0.25 s, then held; gravity on.
/// - `drape-x` / `drape-y`: the square held at the two corners of its edge along the fabric x (y) axis (vertices
///   within 1 cm of the corner, the "small spheres"), falling onto a sphere of radius 3 cm under its centre.
/// - `hanging`: the square in a vertical plane, hanging from its two top corners.
pub fn builtin(name: &str) -> Option<Scene> {
    let mut s = Scene {
        name: name.to_string(),
        material: "default".into(),
        mesh: MeshSpec::Rectangle {
            width: SIDE,
            height: SIDE,
            edge: BUILTIN_EDGE,
            perturb: 0.0,
            seed: 1,
        },
        placement: Placement::default(),
        fabric_angle_deg: 0.0,
        duration: 1.0,
        dt: 1.0 / 60.0,
        quasi_static: false,
        gravity: default_gravity(),
        drag: 0.0,
        model: ModelSpec::default(),
        psd: Psd::Psi,
        solver: SolverSpec::default(),
        pins: vec![],
        handles: vec![],
        obstacles: vec![],
        contact: ContactSpec::default(),
        output: OutputSpec::default(),
    };
    let (w, l0, l1) = (0.07 * SIDE, 0.165 * SIDE, 0.835 * SIDE);
    let strip = |name: &str, min: [f64; 2], max: [f64; 2], d: [f64; 3]| HandleSpec {
        name: name.into(),
        select: Selection::Box { min, max },
        keyframes: vec![(0.0, [0.0; 3]), (0.25, d)],
    };
    let corner = |p: [f64; 2]| Selection::Near {
        point: p,
        radius: 0.01,
    };
    match name {
        "stretch-x" => {
            s.handles = vec![
                strip("left", [0.0, l0], [w, l1], [-0.02, 0.0, 0.0]),
                strip("right", [SIDE - w, l0], [SIDE, l1], [0.02, 0.0, 0.0]),
            ]
        }
        "stretch-y" => {
            s.handles = vec![
                strip("bottom", [l0, 0.0], [l1, w], [0.0, -0.02, 0.0]),
                strip("top", [l0, SIDE - w], [l1, SIDE], [0.0, 0.02, 0.0]),
            ]
        }
        "drape-x" | "drape-y" => {
            s.pins = if name == "drape-x" {
                vec![corner([0.0, 0.0]), corner([SIDE, 0.0])]
            } else {
                vec![corner([0.0, 0.0]), corner([0.0, SIDE])]
            };
            s.obstacles = vec![Obstacle::Sphere {
                center: [0.5 * SIDE, 0.5 * SIDE, -0.03 - 0.004],
                radius: 0.03,
            }];
            s.drag = 0.5;
        }
        "hanging" => {
            s.placement = Placement {
                origin: [0.0, 0.0, -SIDE],
                u: [1.0, 0.0, 0.0],
                v: [0.0, 0.0, 1.0],
            };
            s.pins = vec![corner([0.0, SIDE]), corner([SIDE, SIDE])];
            s.drag = 0.5;
        }
        _ => return None,
    }
    Some(s)
}

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

    /// Check values serde cannot (sizes, times, physical parameters, against their ranges and the documented
    /// limits [`MAX_STEPS`], [`MAX_GRAVITY`], [`MAX_NEWTON`]); errors name the field.
    fn validate(&self, file: &str) -> Result<(), ShellError> {
        self.validate_times(file)?;
        self.validate_physics(file)?;
        self.validate_geometry(file)
    }

    /// `duration`, `dt` (not larger than a positive duration), the step count and the handles' keyframe times.
    fn validate_times(&self, file: &str) -> Result<(), ShellError> {
        let bad = |field: &str, msg: String| Err(ShellError::scene(file, field, msg));
        if !(self.duration >= 0.0 && self.duration.is_finite()) {
            return bad(
                "duration",
                format!("must be a non-negative number, got {}", self.duration),
            );
        }
        if !(self.dt > 0.0 && self.dt.is_finite()) {
            return bad("dt", format!("must be positive, got {}", self.dt));
        }
        if self.dt < MIN_DT {
            return bad(
                "dt",
                format!("{} s is below the limit of {MIN_DT:e} s", self.dt),
            );
        }
        if self.duration > 0.0 && self.dt > self.duration {
            return bad(
                "dt",
                format!(
                    "{} s is larger than the duration {} s (one step would overshoot it)",
                    self.dt, self.duration
                ),
            );
        }
        let steps = (self.duration / self.dt - 1e-9).ceil();
        // finite duration ≥ 0 and dt > 0: a number or +inf, never NaN
        if steps > MAX_STEPS as f64 {
            return bad(
                "dt",
                format!(
                    "duration / dt = {steps:e} steps is more than the limit of {MAX_STEPS} (a larger dt or a \
                     shorter duration?)"
                ),
            );
        }
        for (i, h) in self.handles.iter().enumerate() {
            if h.keyframes
                .windows(2)
                .any(|w| w[1].0.is_nan() || w[1].0 <= w[0].0)
                || h.keyframes.iter().any(|k| !k.0.is_finite())
            {
                return bad(
                    &format!("handles[{i}].keyframes"),
                    "times must be finite and increase".into(),
                );
            }
        }
        Ok(())
    }

    /// Gravity (bounded by [`MAX_GRAVITY`]), drag, the model's scales, the solver and the contact parameters.
    fn validate_physics(&self, file: &str) -> Result<(), ShellError> {
        let bad = |field: &str, msg: String| Err(ShellError::scene(file, field, msg));
        let g = self.gravity;
        let gnorm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        if gnorm.is_nan() || gnorm > MAX_GRAVITY {
            return bad(
                "gravity",
                format!("magnitude {gnorm:e} m/s² is more than the limit of {MAX_GRAVITY:e} m/s²"),
            );
        }
        if !(self.drag >= 0.0 && self.drag.is_finite()) {
            return bad(
                "drag",
                format!("must be a non-negative rate (1/s), got {}", self.drag),
            );
        }
        let m = &self.model;
        for (f, v) in [("model.stiffness", m.stiffness), ("model.mass", m.mass)] {
            if !(v > 0.0 && v.is_finite()) {
                return bad(f, format!("must be positive, got {v}"));
            }
        }
        if !(m.bending_scale >= 0.0 && m.bending_scale.is_finite()) {
            return bad(
                "model.bending_scale",
                format!("must be a non-negative number, got {}", m.bending_scale),
            );
        }
        if self.solver.force_tol.is_nan() || self.solver.force_tol <= 0.0 {
            return bad(
                "solver.force_tol",
                format!("must be positive, got {}", self.solver.force_tol),
            );
        }
        if self.solver.max_newton > MAX_NEWTON {
            return bad(
                "solver.max_newton",
                format!(
                    "{} is more than the limit of {MAX_NEWTON}",
                    self.solver.max_newton
                ),
            );
        }
        let c = &self.contact;
        for (f, v) in [
            ("contact.thickness", c.thickness),
            ("contact.stiffness", c.stiffness),
        ] {
            if !(v >= 0.0 && v.is_finite()) {
                return bad(f, format!("must be a non-negative number, got {v}"));
            }
        }
        Ok(())
    }

    /// The fabric angle, the placement, the handle offsets and the obstacles (bounded by [`MAX_COORDINATE`] and
    /// [`MAX_AXIS`]).
    fn validate_geometry(&self, file: &str) -> Result<(), ShellError> {
        let bad = |field: &str, msg: String| Err(ShellError::scene(file, field, msg));
        let within = |v: &[f64], limit: f64| v.iter().all(|x| x.abs() <= limit);
        let pl = &self.placement;
        if !within(&pl.origin, MAX_COORDINATE) {
            return bad(
                "placement.origin",
                format!("coordinates must be within ±{MAX_COORDINATE:e} m"),
            );
        }
        if !(within(&pl.u, MAX_AXIS) && within(&pl.v, MAX_AXIS)) {
            return bad(
                "placement",
                format!("the components of u and v must be within ±{MAX_AXIS:e}"),
            );
        }
        for (i, h) in self.handles.iter().enumerate() {
            if h.keyframes.iter().any(|k| !within(&k.1, MAX_COORDINATE)) {
                return bad(
                    &format!("handles[{i}].keyframes"),
                    format!("offsets must be within ±{MAX_COORDINATE:e} m"),
                );
            }
        }
        if !self.fabric_angle_deg.is_finite() {
            return bad("fabric_angle_deg", "must be finite".into());
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            let ok = match o {
                Obstacle::Sphere { center, radius } => {
                    *radius > 0.0 && *radius <= MAX_COORDINATE && within(center, MAX_COORDINATE)
                }
                Obstacle::Plane { point, normal } if within(point, MAX_COORDINATE) => {
                    let l = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2])
                        .sqrt();
                    l > 0.0 && l.is_finite()
                }
                Obstacle::Plane { .. } => false,
            };
            if !ok {
                return bad(
                    &format!("obstacles[{i}]"),
                    format!(
                        "needs a positive radius / non-zero normal, coordinates within ±{MAX_COORDINATE:e} m"
                    ),
                );
            }
        }
        Ok(())
    }

    /// Load the material, build the mesh and the simulation. `file` names the scene in errors; relative paths
    /// are resolved against `dir`.
    pub fn build(
        &self,
        file: &str,
        dir: &Path,
    ) -> Result<(Simulation, Vec<[usize; 3]>), ShellError> {
        self.validate(file)?;
        let material = if self.material == "default" {
            default_material()
        } else {
            let p = dir.join(&self.material);
            Material::load(&p).map_err(|source| ShellError::Material {
                file: file.to_string(),
                source,
            })?
        };
        let (mesh, x0) = match &self.mesh {
            MeshSpec::Rectangle {
                width,
                height,
                edge,
                perturb,
                seed,
            } => {
                let m = Mesh::rectangle(*width, *height, *edge, *perturb, *seed).map_err(|e| {
                    ShellError::SceneMesh {
                        file: file.to_string(),
                        source: Box::new(e),
                    }
                })?;
                let pl = &self.placement;
                let x0 = m.place(pl.origin, pl.u, pl.v);
                (m, x0)
            }
            MeshSpec::Obj { path } => Mesh::load_obj(&dir.join(path))?,
        };
        let stencils = mesh.stencils(self.fabric_angle_deg.to_radians())?;
        let tris: Vec<[usize; 3]> = stencils.iter().map(|s| [s.v[0], s.v[1], s.v[2]]).collect();
        let flags = ModelFlags {
            bending: self.model.bending,
            only_1d: self.model.only_1d,
            in_plane_only: self.model.in_plane_only,
            stiffness: self.model.stiffness,
            bending_scale: self.model.bending_scale,
        };
        let model = ElementModel::new(&material, &flags, self.psd);
        let mut pins = Vec::new();
        for (i, sel) in self.pins.iter().enumerate() {
            pins.extend(sel.select_checked(&mesh, file, format!("pins[{i}]"))?);
        }
        let mut handles = Vec::new();
        for (i, h) in self.handles.iter().enumerate() {
            let v = h
                .select
                .select_checked(&mesh, file, format!("handles[{i}].select"))?;
            if v.iter().any(|x| pins.contains(x)) {
                return Err(ShellError::Selection {
                    file: file.to_string(),
                    field: format!("handles[{i}].select"),
                    problem: "overlaps a pin",
                });
            }
            handles.push(Handle {
                name: h.name.clone(),
                vertices: v,
                keyframes: h.keyframes.clone(),
            });
        }
        let settings = Settings {
            dt: self.dt,
            quasi_static: self.quasi_static,
            force_tol: self.solver.force_tol,
            max_newton: self.solver.max_newton,
            exact_first: self.solver.exact_first,
            gravity: self.gravity,
            drag: self.drag,
            thickness: self.contact.thickness,
            contact_stiffness: self.contact.stiffness,
        };
        let sim = Simulation::new(
            model,
            stencils,
            x0,
            Boundary {
                pinned: pins,
                handles,
                obstacles: self.obstacles.clone(),
            },
            settings,
            self.model.mass,
        )
        .map_err(|e| ShellError::SceneSetup {
            file: file.to_string(),
            source: Box::new(e),
        })?;
        Ok((sim, tris))
    }

    /// Number of steps for the duration.
    pub fn steps(&self) -> usize {
        (self.duration / self.dt - 1e-9).ceil().max(0.0) as usize
    }
}

/// Summary of a run.
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    pub steps: usize,
    pub triangles: usize,
    pub vertices: usize,
    pub newton_total: usize,
    pub newton_max: usize,
    pub unconverged_steps: usize,
    pub max_residual: f64,
    pub wall: f64,
    pub last: Option<StepReport>,
}

/// Run a built simulation for `steps` steps, writing `frame_NNNN.obj` (frame 0 the initial state) every
/// `obj_every` steps and one JSON line per step to `log.jsonl` in `out` (when given). `progress` is called after
/// every step.
pub fn run(
    sim: &mut Simulation,
    tris: &[[usize; 3]],
    steps: usize,
    obj_every: usize,
    out: Option<&Path>,
    mut progress: impl FnMut(&StepReport),
) -> Result<RunSummary, ShellError> {
    let io = |e: std::io::Error, what: &Path| ShellError::io(what, "cannot write", e);
    let mut log = match out {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .map_err(|e| ShellError::io(dir, "cannot create the folder", e))?;
            if obj_every > 0 {
                let f = dir.join("frame_0000.obj");
                write_obj(&f, &sim.positions(), tris).map_err(|e| io(e, &f))?;
            }
            let f = dir.join("log.jsonl");
            Some((
                std::io::BufWriter::new(std::fs::File::create(&f).map_err(|e| io(e, &f))?),
                f,
            ))
        }
        None => None,
    };
    let start = std::time::Instant::now();
    let mut sum = RunSummary {
        steps,
        triangles: sim.stencils.len(),
        vertices: sim.pattern.n,
        newton_total: 0,
        newton_max: 0,
        unconverged_steps: 0,
        max_residual: 0.0,
        wall: 0.0,
        last: None,
    };
    for k in 1..=steps {
        let r = sim.step()?;
        sum.newton_total += r.newton;
        sum.newton_max = sum.newton_max.max(r.newton);
        sum.unconverged_steps += usize::from(!r.converged);
        sum.max_residual = sum.max_residual.max(r.residual);
        if let (Some(dir), Some((w, f))) = (out, log.as_mut()) {
            let line = serde_json::to_string(&r).expect("a step report serialises");
            writeln!(w, "{line}").map_err(|e| io(e, f))?;
            if obj_every > 0 && k % obj_every == 0 {
                let f = dir.join(format!("frame_{k:04}.obj"));
                write_obj(&f, &sim.positions(), tris).map_err(|e| io(e, &f))?;
            }
        }
        progress(&r);
        sum.last = Some(r);
    }
    if let Some((mut w, f)) = log {
        w.flush().map_err(|e| io(e, &f))?;
    }
    sum.wall = start.elapsed().as_secs_f64();
    Ok(sum)
}
