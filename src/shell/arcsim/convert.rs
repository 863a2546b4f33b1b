//! From a parsed ARCSim scene to our [`Scene`] (the mapping of every key is listed in the guide,
//! `docs/arcsim.md`).

use super::handlebar::{Handlebar, SIDES};
use super::json::Node;
use super::read::{join, Ctx, Fields, Key};
use crate::shell::motion::{Interpolation, Keyframe, Motion};
use crate::shell::scene::{
    ContactSpec, HandleSpec, MeshSpec, ModelSpec, ObstacleSpec, OutputSpec, Placement, Scene,
    Selection, SolverSpec, Transform, Wind,
};
use crate::shell::{Mesh, Psd, ShellError};

use Key::{Ignored, Used};

/// ARCSim's defaults for keys a scene may leave out (its `conf.cpp`; the key mapping in `docs/arcsim.md`):
/// `wind.density` 1, `magic.handle_stiffness` 1e3 N/m, `magic.repulsion_thickness` 1e-3 m, `obs_friction` 0.3,
/// `gravity` zero, `frame_steps` 1.
pub const DEFAULT_WIND_DENSITY: f64 = 1.0;
/// ARCSim's `magic.handle_stiffness` (N/m).
pub const DEFAULT_HANDLE_STIFFNESS: f64 = 1e3;
/// ARCSim's `magic.repulsion_thickness` (m).
pub const DEFAULT_REPULSION_THICKNESS: f64 = 1e-3;
/// ARCSim's `obs_friction` (Coulomb coefficient μ).
pub const DEFAULT_OBS_FRICTION: f64 = 0.3;

/// The converted scene's `solver.time_tol` (m): implicit Euler with substeps chosen by their estimated error.
/// Measured against dt → 0 on the original's basket, rib and stockinette stretches and honeycomb drape
/// (`docs/time-study.md`), it is the cheapest setting that keeps the handle force within 3 % RMS and the energy
/// within 5 % on all four (largest errors 1.7 % and 4.0 %), where one step per frame is 11–19 % off in energy and
/// BDF2 at the same τ, though 1.2–1.7× cheaper, is 6.2 % off on the basket; and the trajectory adjoint
/// (`docs/sensitivities.md`) differentiates implicit Euler.
pub const DEFAULT_TIME_TOL: f64 = 1e-4;

const REMESHING: &str =
    "adaptive remeshing is not part of the HYLC model (the cloth keeps its mesh)";

/// Convert the scene `root`; `name` is the produced scene's name. The readers below run in the order of the
/// scene's sections, so that warnings come in that order and the first malformed key is the one reported.
pub(super) fn convert(root: &Node, ctx: &mut Ctx, name: &str) -> Result<Scene, ShellError> {
    let top = read_top(ctx, root)?;
    let line = root.line;
    let (material, only_1d) = read_hylc(ctx, &top, line)?;
    let (dt, duration) = read_time(ctx, &top, line)?;
    let cloth = read_cloth(ctx, &top, line)?;
    let wind = read_wind(ctx, top.get("wind").copied())?;
    let motions = match top.get("motions") {
        Some(n) => read_motions(ctx, n)?,
        None => Vec::new(),
    };
    let handles = read_handles(ctx, &top, &motions, &cloth)?;
    let obstacles = match top.get("obstacles") {
        Some(n) => read_obstacles(ctx, n, &motions)?,
        None => Vec::new(),
    };
    let (gravity, friction) = read_gravity_friction(ctx, &top)?;
    let contact_default = ContactSpec::default();
    let (handle_stiffness, thickness) =
        read_magic(ctx, top.get("magic").copied(), &contact_default)?;
    Ok(Scene {
        name: name.to_string(),
        material,
        mesh: MeshSpec::Obj {
            path: cloth.mesh_rel,
            transform: cloth.transform,
        },
        placement: Placement::default(),
        fabric_angle_deg: 0.0,
        duration,
        dt,
        quasi_static: false,
        gravity,
        drag: 0.0,
        damping: cloth.damping,
        wind,
        handle_stiffness: Some(handle_stiffness),
        model: ModelSpec {
            only_1d,
            ..ModelSpec::default()
        },
        psd: Psd::Psi,
        solver: SolverSpec {
            time_tol: Some(DEFAULT_TIME_TOL),
            ..SolverSpec::default()
        },
        pins: Vec::new(),
        handles,
        obstacles,
        contact: ContactSpec {
            thickness,
            friction,
            ..contact_default
        },
        output: OutputSpec::default(),
    })
}

/// The top-level object with its keys checked (warnings for the ignored ones).
fn read_top<'n>(ctx: &mut Ctx, root: &'n Node) -> Result<Fields<'n>, ShellError> {
    ctx.fields(
        root,
        "",
        &[
            ("hylc", Used),
            ("frame_time", Used),
            ("frame_steps", Used),
            ("end_time", Used),
            ("cloths", Used),
            ("wind", Used),
            ("motions", Used),
            ("handles", Used),
            ("handlebars", Used),
            ("handlespheres", Used),
            ("obstacles", Used),
            ("gravity", Used),
            ("obs_friction", Used),
            ("magic", Used),
            ("remeshing", Ignored(REMESHING)),
            (
                "disable",
                Ignored("ARCSim's module switches (remeshing, collision, …) do not apply here"),
            ),
            (
                "implicit",
                Ignored("every step here is implicit (incremental-potential minimisation)"),
            ),
            (
                "friction",
                Ignored("cloth–cloth friction: there is no cloth self-contact here"),
            ),
        ],
    )
}

/// `hylc`: the HYLC material (its name relative to the scene's folder) and `only1D`.
fn read_hylc(ctx: &mut Ctx, top: &Fields, line: usize) -> Result<(String, bool), ShellError> {
    let hylc_node = ctx.required(top, line, "", "hylc")?;
    let hylc = ctx.fields(
        hylc_node,
        "hylc",
        &[
            ("material", Used),
            ("only1D", Used),
            (
                "enabled",
                Ignored("the HYLC material (hylc.material) is always the cloth's material here"),
            ),
        ],
    )?;
    let mat_node = ctx.required(&hylc, hylc_node.line, "hylc", "material")?;
    let (material, _) = ctx.resolve(mat_node, "hylc.material")?;
    let only_1d = match hylc.get("only1D") {
        Some(n) => ctx.boolean(n, "hylc.only1D")?,
        None => false,
    };
    Ok((material, only_1d))
}

/// Time: the step `frame_time` and the duration `end_time`; `frame_steps` is checked and warned about (here the
/// substeps are chosen by their estimated error, [`DEFAULT_TIME_TOL`]).
fn read_time(ctx: &mut Ctx, top: &Fields, line: usize) -> Result<(f64, f64), ShellError> {
    let dt = ctx.positive(ctx.required(top, line, "", "frame_time")?, "frame_time")?;
    let duration = ctx.non_negative(ctx.required(top, line, "", "end_time")?, "end_time")?;
    if let Some(n) = top.get("frame_steps") {
        let k = ctx.number(n, "frame_steps")?;
        if !(k >= 1.0 && k.fract() == 0.0) {
            return Err(ctx.error(
                n.line,
                "frame_steps",
                format!("must be a positive whole number, got {k}"),
            ));
        }
        ctx.warn(
            n.line,
            "frame_steps",
            &format!(
                "ignored: the original's {k} substeps of {:.3e} s per frame; here implicit Euler substeps of each \
                 frame (dt = frame_time = {dt} s) chosen by their estimated error (solver.time_tol \
                 {DEFAULT_TIME_TOL:e} m; `--integrator linearized --substeps {k} --time-tol off` takes the original's steps)",
                dt / k
            ),
        );
    }
    Ok((dt, duration))
}

/// The cloth as the scene names it and as the handles select on it.
struct Cloth {
    /// the mesh file's name relative to the scene's folder
    mesh_rel: String,
    transform: Transform,
    damping: f64,
    /// the rest layout, scaled by the transform
    mesh: Mesh,
    /// the initial positions, transformed
    x0: Vec<[f64; 3]>,
}

/// `cloths`: exactly one, its mesh, transform and damping; the rest layout and the initial state exactly as
/// `Scene::build` makes them.
fn read_cloth(ctx: &mut Ctx, top: &Fields, line: usize) -> Result<Cloth, ShellError> {
    let cloths_node = ctx.required(top, line, "", "cloths")?;
    let cloths = ctx.array(cloths_node, "cloths")?;
    if cloths.len() != 1 {
        return Err(ctx.error(
            cloths_node.line,
            "cloths",
            format!(
                "one cloth is simulated here, the scene has {}",
                cloths.len()
            ),
        ));
    }
    let c0 = &cloths[0];
    let cloth = ctx.fields(
        c0,
        "cloths[0]",
        &[
            ("mesh", Used),
            ("transform", Used),
            ("materials", Used),
            ("remeshing", Ignored(REMESHING)),
        ],
    )?;
    let mesh_node = ctx.required(&cloth, c0.line, "cloths[0]", "mesh")?;
    let (mesh_rel, mesh_path) = ctx.resolve(mesh_node, "cloths[0].mesh")?;
    let transform = match cloth.get("transform") {
        Some(n) => read_transform(ctx, n, "cloths[0].transform")?,
        None => Transform::default(),
    };
    let materials = ctx.required(&cloth, c0.line, "cloths[0]", "materials")?;
    let damping = read_materials(ctx, materials)?;
    let (mut mesh, x) = Mesh::load_obj(&mesh_path)
        .map_err(|e| ctx.error(mesh_node.line, "cloths[0].mesh", e.to_string()))?;
    for r in mesh.rest.iter_mut() {
        *r = r.map(|c| c * transform.scale);
    }
    let x0: Vec<[f64; 3]> = x.into_iter().map(|p| transform.apply(p)).collect();
    Ok(Cloth {
        mesh_rel,
        transform,
        damping,
        mesh,
        x0,
    })
}

/// `wind` (air): density, drag and velocity, each with ARCSim's default.
fn read_wind(ctx: &mut Ctx, node: Option<&Node>) -> Result<Wind, ShellError> {
    let Some(n) = node else {
        return Ok(Wind {
            density: DEFAULT_WIND_DENSITY,
            drag: 0.0,
            velocity: [0.0; 3],
        });
    };
    let f = ctx.fields(
        n,
        "wind",
        &[("density", Used), ("drag", Used), ("velocity", Used)],
    )?;
    Ok(Wind {
        density: match f.get("density") {
            Some(d) => ctx.non_negative(d, "wind.density")?,
            None => DEFAULT_WIND_DENSITY,
        },
        drag: match f.get("drag") {
            Some(d) => ctx.non_negative(d, "wind.drag")?,
            None => 0.0,
        },
        velocity: match f.get("velocity") {
            Some(v) => ctx.numbers::<3>(v, "wind.velocity")?,
            None => [0.0; 3],
        },
    })
}

/// The handles: handlebars (moving strips), handlespheres (fixed or moving balls), node handles, in this order.
fn read_handles(
    ctx: &mut Ctx,
    top: &Fields,
    motions: &[Motion],
    cloth: &Cloth,
) -> Result<Vec<HandleSpec>, ShellError> {
    let (mut handles, held_by_bars) = match top.get("handlebars") {
        Some(n) => read_handlebars(ctx, n, motions, cloth)?,
        None => (Vec::new(), Vec::new()),
    };
    if let Some(n) = top.get("handlespheres") {
        handles.extend(read_handlespheres(ctx, n, motions, cloth, &held_by_bars)?);
    }
    if let Some(n) = top.get("handles") {
        handles.extend(read_node_handles(ctx, n, motions, cloth.mesh.len())?);
    }
    Ok(handles)
}

/// `handlebars`: a handle per bar (named after its side) following its motion, and the vertices each bar holds.
fn read_handlebars(
    ctx: &mut Ctx,
    n: &Node,
    motions: &[Motion],
    cloth: &Cloth,
) -> Result<(Vec<HandleSpec>, Vec<Vec<usize>>), ShellError> {
    let mut handles: Vec<HandleSpec> = Vec::new();
    let mut held_by_bars: Vec<Vec<usize>> = Vec::new();
    for (i, b) in ctx.array(n, "handlebars")?.iter().enumerate() {
        let path = format!("handlebars[{i}]");
        let (bar, motion) = read_handlebar(ctx, b, &path, motions)?;
        let (select, held) = bar.selection(&cloth.mesh, &cloth.x0);
        if held.is_empty() {
            return Err(ctx.error(
                b.line,
                &path,
                "selects no vertex of the cloth (no vertex lies strictly inside its strip)",
            ));
        }
        let mut name = SIDES[bar.side].to_string();
        if handles.iter().any(|h| h.name == name) {
            name = format!("{name}-{i}");
        }
        handles.push(handle(name, select, motion));
        held_by_bars.push(held);
    }
    Ok((handles, held_by_bars))
}

/// One handlebar at `path`: its strip (side and fractions) and its motion.
fn read_handlebar(
    ctx: &mut Ctx,
    b: &Node,
    path: &str,
    motions: &[Motion],
) -> Result<(Handlebar, Motion), ShellError> {
    let f = ctx.fields(
        b,
        path,
        &[
            ("side", Used),
            ("lengthp", Used),
            ("widthp", Used),
            ("insetp", Used),
            ("motion", Used),
        ],
    )?;
    let req = |k: &str| ctx.required(&f, b.line, path, k);
    let side = ctx.index(
        req("side")?,
        &join(path, "side"),
        4,
        "0 (left), 1 (bottom), 2 (right) or 3 (top)",
    )?;
    let bar = Handlebar {
        side,
        lengthp: ctx.fraction(req("lengthp")?, &join(path, "lengthp"))?,
        widthp: ctx.fraction(req("widthp")?, &join(path, "widthp"))?,
        insetp: ctx.fraction(req("insetp")?, &join(path, "insetp"))?,
    };
    let motion = read_motion_index(ctx, req("motion")?, path, motions)?;
    Ok((bar, motion))
}

/// `handlespheres`: the vertices within a ball, fixed or following a motion (`sphere0`, `sphere1`, …); a
/// sphere may not hold a vertex a handlebar moves.
fn read_handlespheres(
    ctx: &mut Ctx,
    n: &Node,
    motions: &[Motion],
    cloth: &Cloth,
    held_by_bars: &[Vec<usize>],
) -> Result<Vec<HandleSpec>, ShellError> {
    let mut out = Vec::new();
    for (i, s) in ctx.array(n, "handlespheres")?.iter().enumerate() {
        let path = format!("handlespheres[{i}]");
        let f = ctx.fields(
            s,
            &path,
            &[("center", Used), ("radius", Used), ("motion", Used)],
        )?;
        let center = ctx.numbers::<3>(
            ctx.required(&f, s.line, &path, "center")?,
            &join(&path, "center"),
        )?;
        let radius = ctx.positive(
            ctx.required(&f, s.line, &path, "radius")?,
            &join(&path, "radius"),
        )?;
        let motion = match f.get("motion") {
            Some(m) => read_motion_index(ctx, m, &path, motions)?,
            None => Motion::fixed(),
        };
        let sel = Selection::Ball { center, radius };
        let held = sel.select(&cloth.mesh, &cloth.x0);
        if held.is_empty() {
            return Err(ctx.error(
                s.line,
                &path,
                "selects no vertex of the cloth (none within its radius of its center)",
            ));
        }
        if let Some(j) = held_by_bars
            .iter()
            .position(|bar| bar.iter().any(|v| held.contains(v)))
        {
            return Err(ctx.error(
                s.line,
                &path,
                format!("holds vertices that handlebars[{j}] moves too"),
            ));
        }
        out.push(handle(format!("sphere{i}"), sel, motion));
    }
    Ok(out)
}

/// `obstacles`: a mesh each (its name relative to the scene's folder), with its transform and motion.
fn read_obstacles(
    ctx: &mut Ctx,
    n: &Node,
    motions: &[Motion],
) -> Result<Vec<ObstacleSpec>, ShellError> {
    let mut obstacles = Vec::new();
    for (i, o) in ctx.array(n, "obstacles")?.iter().enumerate() {
        let path = format!("obstacles[{i}]");
        let f = ctx.fields(
            o,
            &path,
            &[("mesh", Used), ("transform", Used), ("motion", Used)],
        )?;
        let mesh_node = ctx.required(&f, o.line, &path, "mesh")?;
        let (rel, _) = ctx.resolve(mesh_node, &join(&path, "mesh"))?;
        let transform = match f.get("transform") {
            Some(t) => read_transform(ctx, t, &join(&path, "transform"))?,
            None => Transform::default(),
        };
        let motion = match f.get("motion") {
            Some(m) => Some(read_motion_index(ctx, m, &path, motions)?),
            None => None,
        };
        obstacles.push(ObstacleSpec::Mesh {
            path: rel,
            transform,
            motion,
        });
    }
    Ok(obstacles)
}

/// `gravity` (default zero) and `obs_friction` (the obstacles' friction coefficient).
fn read_gravity_friction(ctx: &mut Ctx, top: &Fields) -> Result<([f64; 3], f64), ShellError> {
    let gravity = match top.get("gravity") {
        Some(n) => ctx.numbers::<3>(n, "gravity")?,
        None => [0.0; 3],
    };
    let friction = match top.get("obs_friction") {
        Some(n) => ctx.non_negative(n, "obs_friction")?,
        None => DEFAULT_OBS_FRICTION,
    };
    Ok((gravity, friction))
}

/// `magic`: the handle stiffness and the contact (repulsion) thickness, each with ARCSim's default.
fn read_magic(
    ctx: &mut Ctx,
    node: Option<&Node>,
    contact_default: &ContactSpec,
) -> Result<(f64, f64), ShellError> {
    let (mut handle_stiffness, mut thickness) =
        (DEFAULT_HANDLE_STIFFNESS, DEFAULT_REPULSION_THICKNESS);
    if let Some(n) = node {
        let collision = format!(
            "the obstacle penalty here has its own stiffness (contact.stiffness = {:e} 1/(m s²), a cubic penalty per unit mass)",
            contact_default.stiffness
        );
        let f = ctx.fields(
            n,
            "magic",
            &[
                ("handle_stiffness", Used),
                ("repulsion_thickness", Used),
                ("collision_stiffness", Ignored(&collision)),
                (
                    "relax_initial_state",
                    Ignored("the initial state is simulated as given"),
                ),
            ],
        )?;
        if let Some(k) = f.get("handle_stiffness") {
            handle_stiffness = ctx.positive(k, "magic.handle_stiffness")?;
        }
        if let Some(t) = f.get("repulsion_thickness") {
            thickness = ctx.non_negative(t, "magic.repulsion_thickness")?;
        }
    }
    Ok((handle_stiffness, thickness))
}

/// A `transform`: `scale` (> 0), `translate` (3 numbers), `rotate` ([degrees, axis x, y, z]).
fn read_transform(ctx: &mut Ctx, n: &Node, path: &str) -> Result<Transform, ShellError> {
    let f = ctx.fields(
        n,
        path,
        &[("scale", Used), ("translate", Used), ("rotate", Used)],
    )?;
    let mut t = Transform::default();
    if let Some(s) = f.get("scale") {
        t.scale = ctx.positive(s, &join(path, "scale"))?;
    }
    if let Some(v) = f.get("translate") {
        t.translate = ctx.numbers::<3>(v, &join(path, "translate"))?;
    }
    if let Some(r) = f.get("rotate") {
        t.rotate = ctx.numbers::<4>(r, &join(path, "rotate"))?;
    }
    Ok(t)
}

/// `cloths[0].materials`: the first material's `damping` (s, default 0); further materials are ignored.
fn read_materials(ctx: &mut Ctx, n: &Node) -> Result<f64, ShellError> {
    let key = "cloths[0].materials";
    let mats = ctx.array(n, key)?;
    let Some(m0) = mats.first() else {
        return Err(ctx.error(n.line, key, "needs one material (for its damping)"));
    };
    let path = "cloths[0].materials[0]";
    let f = ctx.fields(
        m0,
        path,
        &[
            ("damping", Used),
            (
                "data",
                Ignored(
                    "the ARCSim material: the internal forces come from the HYLC material alone",
                ),
            ),
            (
                "thicken",
                Ignored("a factor of the ARCSim material, which the HYLC model does not use"),
            ),
        ],
    )?;
    let damping = match f.get("damping") {
        Some(d) => ctx.non_negative(d, &join(path, "damping"))?,
        None => 0.0,
    };
    for (i, m) in mats.iter().enumerate().skip(1) {
        ctx.warn(
            m.line,
            &format!("{key}[{i}]"),
            "ignored: the cloth has one material here (the HYLC material; damping from materials[0])",
        );
    }
    Ok(damping)
}

/// A handle of the converted scene following `motion`.
fn handle(name: String, select: Selection, motion: Motion) -> HandleSpec {
    HandleSpec {
        name,
        select,
        keyframes: motion.keyframes,
        interpolation: motion.interpolation,
    }
}

/// The `motion` key of the object at `path`: the index of one of the scene's motions.
fn read_motion_index(
    ctx: &Ctx,
    n: &Node,
    path: &str,
    motions: &[Motion],
) -> Result<Motion, ShellError> {
    let what = match motions.len() {
        0 => "the index of a motion, but the scene has no `motions`".to_string(),
        m => format!("the index of one of the scene's {m} motions (0-based)"),
    };
    let i = ctx.index(n, &join(path, "motion"), motions.len(), &what)?;
    Ok(motions[i].clone())
}

/// ARCSim's node handles, `handles: [{"nodes": [i, …], "motion": m}]`: the listed cloth vertices (0-based, in
/// the mesh file's order) follow motion m, or stay put without one; named `nodes0`, `nodes1`, ….
fn read_node_handles(
    ctx: &mut Ctx,
    n: &Node,
    motions: &[Motion],
    vertices: usize,
) -> Result<Vec<HandleSpec>, ShellError> {
    let mut out = Vec::new();
    for (i, h) in ctx.array(n, "handles")?.iter().enumerate() {
        let path = format!("handles[{i}]");
        let f = ctx.fields(h, &path, &[("nodes", Used), ("motion", Used)])?;
        let key = join(&path, "nodes");
        let list = ctx.array(ctx.required(&f, h.line, &path, "nodes")?, &key)?;
        if list.is_empty() {
            return Err(ctx.error(h.line, &key, "lists no vertex"));
        }
        let what = format!("a vertex index of the cloth's mesh (0-based; it has {vertices})");
        let nodes = list
            .iter()
            .map(|v| ctx.index(v, &key, vertices, &what))
            .collect::<Result<Vec<usize>, _>>()?;
        let motion = match f.get("motion") {
            Some(m) => read_motion_index(ctx, m, &path, motions)?,
            None => Motion::fixed(),
        };
        out.push(handle(
            format!("nodes{i}"),
            Selection::Vertices(nodes),
            motion,
        ));
    }
    Ok(out)
}

/// `motions`: each a list of keyframes `{"time": t, "transform": {"translate": [..]}, "velocity":
/// {"translate": [..]}}` with increasing times, interpolated as ARCSim does (cubic Hermite; a keyframe without
/// `velocity` gets ARCSim's: zero at the ends, central differences inside). A rotation or scale other than the
/// identity is an error (the handles here translate).
fn read_motions(ctx: &mut Ctx, n: &Node) -> Result<Vec<Motion>, ShellError> {
    let mut out = Vec::new();
    for (i, m) in ctx.array(n, "motions")?.iter().enumerate() {
        let path = format!("motions[{i}]");
        let keys = ctx.array(m, &path)?;
        if keys.is_empty() {
            return Err(ctx.error(m.line, &path, "needs at least one keyframe"));
        }
        let mut motion = Motion {
            keyframes: Vec::new(),
            interpolation: Interpolation::Hermite,
        };
        for (j, k) in keys.iter().enumerate() {
            let kp = format!("{path}[{j}]");
            let f = ctx.fields(
                k,
                &kp,
                &[("time", Used), ("transform", Used), ("velocity", Used)],
            )?;
            let tn = ctx.required(&f, k.line, &kp, "time")?;
            let time = ctx.number(tn, &join(&kp, "time"))?;
            if let Some(prev) = motion.keyframes.last().map(|k| k.time) {
                if time <= prev {
                    return Err(ctx.error(
                        tn.line,
                        &join(&kp, "time"),
                        format!("keyframe times must increase, got {time} after {prev}"),
                    ));
                }
            }
            let offset = match f.get("transform") {
                Some(t) => read_translation(ctx, t, &join(&kp, "transform"), 1.0)?,
                None => [0.0; 3],
            };
            let velocity = match f.get("velocity") {
                Some(v) => Some(read_translation(ctx, v, &join(&kp, "velocity"), 0.0)?),
                None => None,
            };
            motion.keyframes.push(Keyframe {
                time,
                offset,
                velocity,
            });
        }
        out.push(motion);
    }
    Ok(out)
}

/// The translation of a keyframe's `transform` or `velocity` object (`translate`, 3 numbers); a `rotate` with a
/// non-zero angle, or a `scale` other than `identity_scale` (1 for a transform, 0 for a velocity), is an error.
fn read_translation(
    ctx: &mut Ctx,
    t: &Node,
    tp: &str,
    identity_scale: f64,
) -> Result<[f64; 3], ShellError> {
    let tf = ctx.fields(
        t,
        tp,
        &[("translate", Used), ("rotate", Used), ("scale", Used)],
    )?;
    if let Some(r) = tf.get("rotate") {
        let rk = join(tp, "rotate");
        if ctx.numbers::<4>(r, &rk)?[0] != 0.0 {
            return Err(ctx.error(
                r.line,
                &rk,
                "motions are translations here (a keyframe may not rotate)",
            ));
        }
    }
    if let Some(s) = tf.get("scale") {
        let sk = join(tp, "scale");
        if ctx.number(s, &sk)? != identity_scale {
            return Err(ctx.error(
                s.line,
                &sk,
                format!(
                    "motions are translations here (a keyframe's scale must be {identity_scale})"
                ),
            ));
        }
    }
    match tf.get("translate") {
        Some(v) => ctx.numbers::<3>(v, &join(tp, "translate")),
        None => Ok([0.0; 3]),
    }
}
