//! The built-in scenes (`docs/cloth-simulator.md`, "built-ins reproduce the original's tests").

use super::*;

/// Names of the built-in scenes.
pub const BUILTINS: [&str; 5] = ["stretch-x", "stretch-y", "drape-x", "drape-y", "hanging"];

/// Side of the built-in squares (m) and their default edge length: 51 × 51 cells, 5 202 triangles.
pub const SIDE: f64 = 0.3;
/// The built-ins' default edge length (m): [`SIDE`] / 51.
pub const BUILTIN_EDGE: f64 = 0.3 / 51.0;

/// A built-in scene matching the original's tests (30 × 30 cm, 1 s at 1/60 s steps, PSD option `psi`):
/// - `stretch-x` / `stretch-y`: two strips on opposite sides placed as the original's handlebars
///   (`lengthp` 0.67, `widthp` 0.07, `insetp` 0.16: along the side the middle 67 %, across it the band
///   [0.125, 0.195] × the side measured inward from the edge), pulled apart 2 cm each over 0.25 s, then held;
///   gravity on. The pull follows the original's motion curve: its scenes give two keyframes, which ARCSim
///   interpolates by a cubic Hermite curve that starts and ends at rest (a smoothstep, `super::motion`), not at
///   constant speed. Against the original's per-frame handle forces on `2D/basket_stretchX` that alone took
///   the force error (RMS over the frames from 0.1 s) from 11.0 % to 2.8 %, so the built-ins use it too.
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
        damping: 0.0,
        wind: Wind::default(),
        handle_stiffness: None,
        model: ModelSpec::default(),
        psd: Psd::Psi,
        solver: SolverSpec::default(),
        pins: vec![],
        handles: vec![],
        obstacles: vec![],
        contact: ContactSpec::default(),
        output: OutputSpec::default(),
    };
    let (l0, l1) = (0.165 * SIDE, 0.835 * SIDE);
    let (i0, i1) = ((0.16 - 0.035) * SIDE, (0.16 + 0.035) * SIDE);
    let strip = |name: &str, min: [f64; 2], max: [f64; 2], d: [f64; 3]| HandleSpec {
        name: name.into(),
        select: Selection::Box { min, max },
        keyframes: vec![Keyframe::at(0.0, [0.0; 3]), Keyframe::at(0.25, d)],
        interpolation: Interpolation::Hermite,
    };
    let corner = |p: [f64; 2]| Selection::Near {
        point: p,
        radius: 0.01,
    };
    match name {
        "stretch-x" => {
            s.handles = vec![
                strip("left", [i0, l0], [i1, l1], [-0.02, 0.0, 0.0]),
                strip("right", [SIDE - i1, l0], [SIDE - i0, l1], [0.02, 0.0, 0.0]),
            ]
        }
        "stretch-y" => {
            s.handles = vec![
                strip("bottom", [l0, i0], [l1, i1], [0.0, -0.02, 0.0]),
                strip("top", [l0, SIDE - i1], [l1, SIDE - i0], [0.0, 0.02, 0.0]),
            ]
        }
        "drape-x" | "drape-y" => {
            s.pins = if name == "drape-x" {
                vec![corner([0.0, 0.0]), corner([SIDE, 0.0])]
            } else {
                vec![corner([0.0, 0.0]), corner([0.0, SIDE])]
            };
            s.obstacles = vec![ObstacleSpec::Sphere {
                center: [0.5 * SIDE, 0.5 * SIDE, -0.03 - 0.004],
                radius: 0.03,
                motion: None,
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
