//! ARCSim-HYLC scene files: `hylc simulate path/to/arcsim_scene.json` recognises an ARCSim scene (comments
//! allowed) and runs it; the same scene can be converted once to our scene JSON (`--print`).
//!
//! An ARCSim scene is read with [`json`] (JSON with `//` and `/* */` comments, every value with its line) and
//! converted to a [`Scene`] plus one-line warnings for the keys it does not use. The mapping (`docs/arcsim.md`
//! lists it in full):
//! - `hylc.material` → `material`, `hylc.only1D` → `model.only_1d`; `psd` is `psi` as in our built-ins;
//! - `cloths[0].mesh` + `transform` → `mesh: {"obj": ..}` (rest layout = scaled OBJ x, y; initial state = the
//!   transformed OBJ); `cloths[0].materials[0].damping` → `damping`;
//! - `frame_time` → `dt`, one OBJ per frame; implicit Euler substeps chosen by their estimated error
//!   (`solver.time_tol` = [`DEFAULT_TIME_TOL`], where the original took `frame_steps` substeps); `end_time` →
//!   `duration`;
//! - `motions` → translation keyframes interpolated as ARCSim does (cubic Hermite with its velocities,
//!   `velocity` keys honoured; [`crate::shell::motion`]);
//! - `handlebars` → `handles` with a box selection in the rest layout ([`Handlebar`]) following
//!   `motions[motion]`, named by their side; `handlespheres` → `handles` named `sphere0`, `sphere1`, …
//!   selecting a ball of the initial positions (fixed, or following their `motion`); node handles
//!   (`handles: [{"nodes": [..], "motion": m}]`) → `handles` named `nodes0`, … selecting those vertices;
//!   obstacles with a `motion` move with it; `magic.handle_stiffness` (default 1e3 N/m) → `handle_stiffness`, so
//!   every held vertex is a spring, and each held set reports its reaction by name;
//! - `wind` → `wind` (density 1 when absent, as ARCSim), `gravity` (zero when absent, as ARCSim), `obstacles` →
//!   mesh obstacles, `obs_friction` → `contact.friction` (0.3 when absent, as ARCSim),
//!   `magic.repulsion_thickness` → `contact.thickness` (default 1e-3 m).
//!
//! Paths in the produced scene are relative to the ARCSim file's folder, so a converted scene saved next to the
//! ARCSim file resolves the same files. Bad values are [`ShellError::Arcsim`] errors naming the file, line and
//! key; nothing panics.

mod convert;
mod handlebar;
pub mod json;
mod read;

pub use convert::{
    DEFAULT_HANDLE_STIFFNESS, DEFAULT_OBS_FRICTION, DEFAULT_REPULSION_THICKNESS, DEFAULT_TIME_TOL,
    DEFAULT_WIND_DENSITY,
};
pub use handlebar::{bounds, Handlebar, GROW, SIDES};

use super::scene::Scene;
use super::ShellError;
use json::Value;
use std::path::{Path, PathBuf};

/// A converted ARCSim scene, the warnings of its conversion (one line each, naming file, line and key: keys
/// ignored or unknown) and its notes (one line each: what the conversion did that is worth knowing, such as a
/// link file followed).
#[derive(Clone, Debug)]
pub struct Converted {
    /// the scene
    pub scene: Scene,
    /// keys ignored or unknown, one line each (file, line, key)
    pub warnings: Vec<String>,
    /// what the conversion did that is worth knowing, one line each
    pub notes: Vec<String>,
}

/// The top-level keys that only ARCSim scenes have (ours have `mesh` and `duration` instead).
const ARCSIM_KEYS: [&str; 4] = ["cloths", "frame_time", "handlebars", "handlespheres"];

/// Whether `text` is an ARCSim scene rather than one of ours: its top-level object has an ARCSim key (`cloths`,
/// `frame_time`, `handlebars`, `handlespheres`) and no `mesh`. A text that does not parse counts as ARCSim when
/// it names `"cloths"` or `"frame_time"` and is not strict JSON either (so that its syntax error is reported by
/// the ARCSim reader, with comments understood).
pub fn is_arcsim(text: &str) -> bool {
    match json::parse(text) {
        Ok(root) => match root.value {
            Value::Object(entries) => {
                let has = |k: &str| entries.iter().any(|(key, _)| key == k);
                !has("mesh") && ARCSIM_KEYS.iter().any(|k| has(k))
            }
            _ => false,
        },
        Err(_) => {
            serde_json::from_str::<serde_json::Value>(text).is_err()
                && (text.contains("\"cloths\"") || text.contains("\"frame_time\""))
        }
    }
}

/// Convert the ARCSim scene `text`; `file` names it in messages (and its stem names the scene), `dir` is its
/// folder (relative paths are looked up from there upwards and written relative to it).
pub fn convert_str(text: &str, file: &str, dir: &Path) -> Result<Converted, ShellError> {
    let root = json::parse(text).map_err(|e| ShellError::ArcsimSyntax {
        file: file.to_string(),
        line: e.line,
        column: e.column,
        message: e.message,
    })?;
    let mut ctx = read::Ctx {
        file,
        dir,
        warnings: Vec::new(),
        notes: Vec::new(),
    };
    let name = Path::new(file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let scene = convert::convert(&root, &mut ctx, &name)?;
    Ok(Converted {
        scene,
        warnings: ctx.warnings,
        notes: ctx.notes,
    })
}

/// Read and convert the ARCSim scene file `path`.
pub fn load(path: &Path) -> Result<Converted, ShellError> {
    let text = std::fs::read_to_string(path).map_err(|e| ShellError::io(path, "cannot read", e))?;
    convert_str(&text, &path.display().to_string(), &folder(path))
}

/// A scene argument of `hylc simulate`: an ARCSim scene file (converted, with its warnings), or else what
/// [`Scene::load`] reads (our scene files and the built-ins, no warnings). Returns the scene, the folder its
/// relative paths start from and the conversion's warnings and notes.
pub fn load_scene(arg: &str) -> Result<(Scene, PathBuf, Vec<String>), ShellError> {
    let p = Path::new(arg);
    if p.is_file() {
        let text = std::fs::read_to_string(p).map_err(|e| ShellError::io(p, "cannot read", e))?;
        if is_arcsim(&text) {
            let c = convert_str(&text, arg, &folder(p))?;
            let lines = c.warnings.into_iter().chain(c.notes).collect();
            return Ok((c.scene, folder(p), lines));
        }
    }
    let (scene, dir) = Scene::load(arg)?;
    Ok((scene, dir, Vec::new()))
}

/// The folder of a file as `Scene::load` takes it (empty for a bare file name).
fn folder(p: &Path) -> PathBuf {
    p.parent().map(Path::to_path_buf).unwrap_or_default()
}
