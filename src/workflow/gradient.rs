//! `hylc gradient`: dJ/dp of one observable of a cloth scene with respect to the scene's scalars, the held sets'
//! and obstacles' positions and every coefficient of the material (`docs/sensitivities.md`): for a quasi-static
//! scene by one adjoint solve at the equilibrium ([`crate::shell::solver::Simulation::sensitivity`]), for a
//! dynamic one by the discrete adjoint of its implicit Euler substeps as they ran
//! ([`crate::shell::solver::Simulation::trajectory_sensitivity`]); optionally checked against central
//! differences of reruns.
//!
//! Observables (at the last step, or the step nearest `at`): `com-x|y|z` (the mass-weighted centre), `energy`
//! (elastic), `handle-force:NAME:x|y|z` (the reaction of a held set, as `handle_forces.csv` reports it),
//! `target:FILE.obj` (½ Σ_v |x_v − x̂_v|² against an OBJ with the scene's vertices).

use super::simulate::run_reporting;
use super::yarn_chain::{yarn_gradient, YarnGradient};
use super::{write_file, Event, WorkflowError};
use crate::material::coefficients::Coefficient;
use crate::shell::mesh::load_obj_surface;
use crate::shell::motion::Motion;
use crate::shell::scene::Scene;
use crate::shell::solver::{Observable, Sensitivity, Simulation};
use crate::shell::ShellError;
use serde_json::{json, Value};
use std::path::Path;
use std::time::Instant;

/// What to differentiate and how.
#[derive(Clone, Debug, Default)]
pub struct GradientOptions {
    /// the observable (module documentation)
    pub observable: String,
    /// instead of the observable, J = Σ_v w_v · x_v for this cotangent w (one vector per vertex): the
    /// gradient is the vector–Jacobian product wᵀ dx*/dp
    pub cotangent: Option<Vec<[f64; 3]>>,
    /// the time of the equilibrium (s): the step nearest it; the last step by default
    pub at: Option<f64>,
    /// also central differences of re-solves for the scene's scalars, the boundary's positions and the
    /// `check_coefficients` material coefficients with the largest |c dJ/dc|
    pub check: bool,
    /// how many material coefficients the check re-solves for (those with the largest |c dJ/dc|)
    pub check_coefficients: usize,
    /// also dJ/dθ for the yarn parameters through the samples the material was fitted to
    /// ([`super::yarn_chain`])
    pub yarn: Option<YarnChainInput>,
}

/// The samples (made with `--sensitivities`) and yarn parameters of the yarn chain.
#[derive(Clone, Debug)]
pub struct YarnChainInput {
    /// the sample file (made with `--sensitivities`)
    pub samples: std::path::PathBuf,
    /// the yarn parameters the samples were made with
    pub yarn: crate::rod::YarnMaterial,
    /// how the yarn parameters are named in messages (their file)
    pub yarn_label: String,
}

/// One row of the finite-difference check.
#[derive(Clone, Debug)]
pub struct CheckRow {
    /// the parameter's name
    pub parameter: String,
    /// dJ/dp by the adjoint
    pub adjoint: f64,
    /// dJ/dp by central differences of re-solves
    pub difference: f64,
    /// |adjoint − difference| / max(|difference|, 1e-6 scale): the scale is the largest |p dJ/dp| checked
    pub error: f64,
}

/// The gradient, its JSON (`gradient.json`) and the check.
pub struct GradientOutcome {
    /// dJ/dp for the scene's parameters, the boundary and the material coefficients
    pub sensitivity: Sensitivity,
    /// dJ/dθ, with [`GradientOptions::yarn`]
    pub yarn: Option<YarnGradient>,
    /// the time of the equilibrium (s)
    pub time: f64,
    /// the content of `gradient.json`
    pub json: Value,
    /// the finite-difference check's rows (empty without [`GradientOptions::check`])
    pub check: Vec<CheckRow>,
    /// wall time of the forward solve and of the gradient (s)
    pub wall_forward: f64,
    /// wall time of the gradient (s)
    pub wall_gradient: f64,
}

/// The observable named by `spec` for `sim`; `dir` resolves a target file.
pub fn parse_observable(spec: &str, sim: &Simulation) -> Result<Observable, WorkflowError> {
    let axis = |a: &str| match a {
        "x" => Ok(0),
        "y" => Ok(1),
        "z" => Ok(2),
        _ => Err(WorkflowError::Input(format!(
            "--observable {spec}: axis {a:?}: expected x, y or z"
        ))),
    };
    if let Some(a) = spec.strip_prefix("com-") {
        return Ok(Observable::CenterOfMass { axis: axis(a)? });
    }
    if spec == "energy" {
        return Ok(Observable::ElasticEnergy);
    }
    if let Some(rest) = spec.strip_prefix("handle-force:") {
        let (set, a) = rest.rsplit_once(':').ok_or_else(|| {
            WorkflowError::Input(format!(
                "--observable {spec}: expected handle-force:NAME:x|y|z"
            ))
        })?;
        if !sim.held_set_names().any(|n| n == set) {
            let names: Vec<String> = sim.held_set_names().map(|n| n.to_string()).collect();
            return Err(WorkflowError::Input(format!(
                "--observable {spec}: the scene has no held set {set:?} (it has: {})",
                if names.is_empty() {
                    "none".into()
                } else {
                    names.join(", ")
                }
            )));
        }
        return Ok(Observable::Reaction {
            set: set.to_string(),
            axis: axis(a)?,
        });
    }
    if let Some(file) = spec.strip_prefix("target:") {
        let (x, _) = load_obj_surface(Path::new(file))
            .map_err(|e| WorkflowError::Input(format!("--observable {spec}: {e}")))?;
        if x.len() != sim.pattern.n {
            return Err(WorkflowError::Input(format!(
                "--observable {spec}: {file} has {} vertices, the scene's mesh {}",
                x.len(),
                sim.pattern.n
            )));
        }
        return Ok(Observable::Target { positions: x });
    }
    Err(WorkflowError::Input(format!(
        "--observable {spec}: expected com-x|y|z, energy, handle-force:NAME:x|y|z or target:FILE.obj"
    )))
}

/// The number of steps to the step nearest `at` (all of them without).
fn steps_to(scene: &Scene, at: Option<f64>) -> Result<usize, WorkflowError> {
    let steps = scene.steps();
    let Some(t) = at else { return Ok(steps) };
    let k = (t / scene.dt).round();
    if !t.is_finite() || k < 1.0 || k > steps as f64 {
        return Err(WorkflowError::Input(format!(
            "--at {t}: outside the run (steps of {} s from {} s to {} s)",
            scene.dt,
            scene.dt,
            steps as f64 * scene.dt
        )));
    }
    Ok(k as usize)
}

/// Every held set's reaction at a step (N), by name.
type Reactions = Vec<(String, [f64; 3])>;

/// Build `scene` and solve it for `steps` steps (writing frames and log to `out` when given); the simulation and
/// the last step's reactions; an error when the last step did not converge (no gradient of an unconverged state).
fn solve(
    scene: &Scene,
    scene_arg: &str,
    dir: &Path,
    steps: usize,
    out: Option<&Path>,
    edit: &dyn Fn(&mut Simulation),
    on_event: &mut (dyn FnMut(Event) + Send),
) -> Result<(Simulation, Reactions), WorkflowError> {
    let (mut sim, tris) = scene.build(scene_arg, dir)?;
    edit(&mut sim);
    if !scene.quasi_static {
        sim.start_tape();
    }
    let summary = run_reporting(&mut sim, &tris, steps, &scene.output, out, None, on_event)?;
    match summary.last {
        Some(r) if !r.converged => Err(WorkflowError::NoGradient(format!(
            "{scene_arg}: the step at t = {:.4} s did not converge (residual {:.2e} N): no gradient of an \
             unconverged state",
            r.time, r.residual
        ))),
        Some(r) => Ok((sim, r.handle_forces)),
        None => Ok((sim, vec![])),
    }
}

/// Run `scene` to the step nearest `opts.at`, take the adjoint gradient of the observable there, write
/// `out/gradient.json` (and the frames and log), and with `opts.check` compare with central differences.
pub fn gradient(
    scene: &Scene,
    scene_arg: &str,
    dir: &Path,
    out: &Path,
    opts: &GradientOptions,
    on_event: &mut (dyn FnMut(Event) + Send),
) -> Result<GradientOutcome, WorkflowError> {
    let mut scene = scene.clone();
    if opts.check {
        // differences of re-solves need equilibria far tighter than the scene's force tolerance
        scene.solver.force_tol = scene.solver.force_tol.min(1e-10);
        scene.solver.max_newton = scene.solver.max_newton.max(200);
    }
    let steps = steps_to(&scene, opts.at)?;
    let t0 = Instant::now();
    let (mut sim, _) = solve(&scene, scene_arg, dir, steps, Some(out), &|_| {}, on_event)?;
    let wall_forward = t0.elapsed().as_secs_f64();
    let obs = match &opts.cotangent {
        Some(w) if w.len() != sim.pattern.n => {
            return Err(WorkflowError::Input(format!(
                "cotangent: {} vectors for the scene's {} vertices",
                w.len(),
                sim.pattern.n
            )))
        }
        Some(w) => Observable::Linear { weights: w.clone() },
        None => parse_observable(&opts.observable, &sim)?,
    };
    let t0 = Instant::now();
    let sens = if scene.quasi_static {
        sim.sensitivity(&obs, true)?
    } else {
        let last = sim.tape().map_or(0, |t| t.steps.len().saturating_sub(1));
        sim.trajectory_sensitivity(&obs, &[last], true)
            .map_err(|e| unsupported(scene_arg, e))?
    };
    let yarn = match (&opts.yarn, &sens.material) {
        (Some(y), Some(djdc)) => Some(yarn_gradient(
            &sim.model.material,
            &scene.material,
            djdc,
            sens.mass_scale,
            &y.samples,
            &y.yarn,
            &y.yarn_label,
        )?),
        _ => None,
    };
    let wall_gradient = t0.elapsed().as_secs_f64();
    let check = if opts.check {
        let p = Probe {
            scene: &scene,
            scene_arg,
            dir,
            steps,
            obs: &obs,
        };
        p.check(&sim, &sens, opts.check_coefficients, on_event)?
    } else {
        vec![]
    };
    let json = to_json(&scene, &sim, opts, &sens, &check, yarn.as_ref());
    write_file(
        &out.join("gradient.json"),
        serde_json::to_string_pretty(&json).expect("a JSON value serialises"),
    )?;
    Ok(GradientOutcome {
        sensitivity: sens,
        yarn,
        time: sim.time,
        json,
        check,
        wall_forward,
        wall_gradient,
    })
}

/// `gradient.json`: the observable, its value, and dJ/dp in the layout of what p belongs to.
fn to_json(
    scene: &Scene,
    sim: &Simulation,
    opts: &GradientOptions,
    sens: &Sensitivity,
    check: &[CheckRow],
    yarn: Option<&YarnGradient>,
) -> Value {
    let held: serde_json::Map<String, Value> = sens
        .held
        .iter()
        .map(|h| {
            (
                h.name.clone(),
                json!({"translation": h.translation, "keyframes": h.keyframes}),
            )
        })
        .collect();
    let material = sens
        .material
        .as_ref()
        .map(|g| g.to_material(&sim.model.material).to_json_value());
    json!({
        "observable": opts.observable,
        "time": sim.time,
        "value": sens.value,
        "residual": sens.residual,
        "scene": {
            "stiffness": sens.stiffness,
            "bending_scale": sens.bending_scale,
            "mass": sens.mass_multiplier(scene.model.mass),
            "gravity": sens.gravity,
        },
        "held": held,
        "obstacles": sens.obstacles,
        "material": material,
        "yarn": yarn.map(|y| y.values.iter().map(|(k, v)| (k.to_string(), json!(v))).collect::<serde_json::Map<_, _>>()),
        "yarn_chain": yarn.map(|y| json!({
            "samples": opts.yarn.as_ref().map(|i| i.samples.display().to_string()),
            "fitted_samples": y.samples,
            "kinks": y.kinks,
            "reference_state": "held fixed",
            "wall": y.wall,
        })),
        "check": check.iter().map(|r| json!({
            "parameter": r.parameter,
            "adjoint": r.adjoint,
            "difference": r.difference,
            "error": r.error,
        })).collect::<Vec<_>>(),
        "provenance": crate::provenance::Provenance::now().to_json(),
    })
}

/// Re-solves of the scene with one parameter moved.
struct Probe<'a> {
    scene: &'a Scene,
    scene_arg: &'a str,
    dir: &'a Path,
    steps: usize,
    obs: &'a Observable,
}

/// A parameter of the check.
#[derive(Clone, Copy)]
enum Param {
    Stiffness,
    BendingScale,
    Mass,
    Gravity(usize),
    /// keyframe `key` of handle number `handle`, component `axis`
    Keyframe {
        handle: usize,
        key: usize,
        axis: usize,
    },
    Obstacle {
        index: usize,
        axis: usize,
    },
    Coef(Coefficient),
}

const AXES: [&str; 3] = ["x", "y", "z"];

impl Probe<'_> {
    /// J with parameter `p` moved by `d`.
    fn value(&self, p: Param, d: f64) -> Result<f64, WorkflowError> {
        let mut s = self.scene.clone();
        match p {
            Param::Stiffness => s.model.stiffness += d,
            Param::BendingScale => s.model.bending_scale += d,
            Param::Mass => s.model.mass += d,
            Param::Gravity(c) => s.gravity[c] += d,
            _ => {}
        }
        let edit = move |sim: &mut Simulation| match p {
            Param::Keyframe { handle, key, axis } => {
                sim.handles[handle].motion.keyframes[key].offset[axis] += d
            }
            Param::Obstacle { index, axis } => {
                let m = &mut sim.obstacle_motions[index];
                if m.keyframes.is_empty() {
                    *m = Motion::linear(&[(0.0, [0.0; 3])]);
                }
                // the offsets' weights sum to one: moving every keyframe moves the obstacle
                for k in &mut m.keyframes {
                    k.offset[axis] += d;
                }
            }
            Param::Coef(c) => {
                let m = &sim.model.material;
                sim.model.material = m.with_coefficient(c, m.coefficient(c) + d);
            }
            _ => {}
        };
        let (sim, forces) = solve(
            &s,
            self.scene_arg,
            self.dir,
            self.steps,
            None,
            &edit,
            &mut |_| {},
        )?;
        match self.obs {
            // a dynamic run's reaction includes the held vertices' inertia: the step report's
            Observable::Reaction { set, axis } if !s.quasi_static => forces
                .iter()
                .find(|f| &f.0 == set)
                .map(|f| f.1[*axis])
                .ok_or_else(|| WorkflowError::Input(format!("no held set {set:?}"))),
            obs => Ok(sim.observable(obs)?),
        }
    }

    /// The parameters to check, their names, values and adjoint derivatives.
    fn parameters(
        &self,
        sim: &Simulation,
        sens: &Sensitivity,
        coefficients: usize,
    ) -> Vec<(Param, String, f64, f64)> {
        let m = &self.scene.model;
        let mut out = vec![
            (
                Param::Stiffness,
                "stiffness".into(),
                m.stiffness,
                sens.stiffness,
            ),
            (
                Param::BendingScale,
                "bending_scale".into(),
                m.bending_scale,
                sens.bending_scale,
            ),
            (
                Param::Mass,
                "mass".into(),
                m.mass,
                sens.mass_multiplier(m.mass),
            ),
        ];
        for c in 0..3 {
            let name = format!("gravity.{}", AXES[c]);
            out.push((
                Param::Gravity(c),
                name,
                self.scene.gravity[c],
                sens.gravity[c],
            ));
        }
        for (handle, h) in sim.handles.iter().enumerate() {
            let g = sens.held.iter().find(|g| g.name == h.name);
            for (key, kf) in h.motion.keyframes.iter().enumerate() {
                for axis in 0..3 {
                    let p = Param::Keyframe { handle, key, axis };
                    let name = format!("held.{}.keyframes[{key}].{}", h.name, AXES[axis]);
                    let adj = g.map_or(0.0, |g| g.keyframes[key][axis]);
                    out.push((p, name, kf.offset[axis], adj));
                }
            }
        }
        for (index, g) in sens.obstacles.iter().enumerate() {
            for axis in 0..3 {
                let name = format!("obstacles[{index}].{}", AXES[axis]);
                out.push((Param::Obstacle { index, axis }, name, 0.0, g[axis]));
            }
        }
        if let Some(g) = &sens.material {
            let mat = &sim.model.material;
            let mut cs: Vec<(f64, Coefficient)> = mat
                .coefficients()
                .into_iter()
                .map(|c| ((g.get(c) * mat.coefficient(c)).abs(), c))
                .filter(|(s, _)| *s > 0.0)
                .collect();
            cs.sort_by(|a, b| b.0.total_cmp(&a.0));
            for &(_, c) in cs.iter().take(coefficients) {
                out.push((
                    Param::Coef(c),
                    format!("material.{c}"),
                    mat.coefficient(c),
                    g.get(c),
                ));
            }
        }
        out
    }

    /// Central differences for every parameter, each with a step relative to its size (1e-4, floors: 1 cm for
    /// positions, 1 m/s² for gravity, the median |c| of the material for a coefficient).
    fn check(
        &self,
        sim: &Simulation,
        sens: &Sensitivity,
        coefficients: usize,
        on_event: &mut (dyn FnMut(Event) + Send),
    ) -> Result<Vec<CheckRow>, WorkflowError> {
        let params = self.parameters(sim, sens, coefficients);
        let coef_floor = {
            let mat = &sim.model.material;
            let mut v: Vec<f64> = mat
                .coefficients()
                .iter()
                .map(|&c| mat.coefficient(c).abs())
                .collect();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(1.0).max(1e-12)
        };
        let mut rows = Vec::new();
        for (k, (p, name, value, adj)) in params.iter().enumerate() {
            let floor = match p {
                Param::Keyframe { .. } | Param::Obstacle { .. } => 1e-2,
                Param::Gravity(_) => 1.0,
                Param::Coef(_) => coef_floor,
                _ => 1e-2,
            };
            let pm = value.abs().max(floor);
            let h = 1e-4 * pm;
            let fd = (self.value(*p, h)? - self.value(*p, -h)?) / (2.0 * h);
            on_event(Event::Print(&format!(
                "check {}/{}: {name}: adjoint {adj:.6e}, difference {fd:.6e}",
                k + 1,
                params.len()
            )));
            rows.push((name.clone(), *adj, fd, pm));
        }
        let scale = rows.iter().map(|r| (r.2 * r.3).abs()).fold(0.0, f64::max);
        Ok(rows
            .into_iter()
            .map(|(parameter, adjoint, difference, pm)| CheckRow {
                parameter,
                adjoint,
                difference,
                error: (adjoint - difference).abs() / difference.abs().max(1e-6 * scale / pm),
            })
            .collect())
    }
}

/// A trajectory adjoint the scene's settings do not allow, as bad input naming the scene.
fn unsupported(scene_arg: &str, e: ShellError) -> WorkflowError {
    match e {
        ShellError::AdjointUnsupported { reason } => WorkflowError::Input(format!(
            "{scene_arg}: no trajectory gradient: {reason} (docs/sensitivities.md, \"Trajectories\")"
        )),
        e => e.into(),
    }
}

/// Whether `e` means that no gradient exists (exit code 3): the equilibrium is not a strict minimum, or the
/// run did not converge.
pub fn no_gradient(e: &WorkflowError) -> bool {
    matches!(
        e,
        WorkflowError::NoGradient(_)
            | WorkflowError::Shell(
                ShellError::NotStrictMinimum { .. }
                    | ShellError::NonFiniteState { .. }
                    | ShellError::StepFailed { .. }
            )
    )
}
