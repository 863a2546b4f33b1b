//! Triangle meshes of the cloth (`docs/cloth-simulator.md`, "Meshes"): generated rectangles (regular or randomly perturbed),
//! OBJ import, the triangle stencils (triangle + flap vertices), OBJ export.
//!
//! The rest (material) layout is flat: a rectangle is generated in its plane; an OBJ mesh must lie in a plane
//! z = const (its x, y are the rest layout, its 3D positions the initial state). The fabric axes may be rotated
//! by an angle α against the mesh: material coordinates are X = R(−α) X_mesh, so the warp (x) direction of the
//! fabric points at angle α in the mesh plane. Rest triangles are oriented counter-clockwise in material
//! coordinates (reordered if needed), so n₀ points to the fabric's +h side (the sign convention of the note).

use super::strain::RestTriangle;
use super::ShellError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;
use std::path::Path;

/// The most vertices a mesh may have (rectangle or OBJ): 5 million vertices are about 1.3 GB of simulation state
/// and sparse Hessian (about 260 bytes per vertex) and hours per simulated second on a workstation, far beyond
/// any cloth the homogenized model is meant for (the built-ins have 2 704); checked before any allocation.
pub const MAX_VERTICES: usize = 5_000_000;

/// The most triangles a mesh may have: twice [`MAX_VERTICES`] (a regular grid has about two triangles per
/// vertex); checked before any allocation.
pub const MAX_TRIANGLES: usize = 2 * MAX_VERTICES;

/// A flat triangle mesh: rest layout (m) and triangles (vertex indices).
#[derive(Clone, Debug)]
pub struct Mesh {
    /// rest layout of the vertices (m)
    pub rest: Vec<[f64; 2]>,
    /// triangles (vertex indices)
    pub tris: Vec<[usize; 3]>,
    /// where each triangle came from, for error messages (e.g. "cloth.obj:12")
    pub origin: Vec<String>,
}

/// One triangle's stencil: triangle vertices, flap vertices across edges (v₀,v₁), (v₁,v₂), (v₂,v₀) (a missing
/// flap repeats v₀ and is flagged false), rest data.
#[derive(Clone, Copy, Debug)]
pub struct Stencil {
    /// the triangle's vertices v₀, v₁, v₂, then the flap vertices across (v₀,v₁), (v₁,v₂), (v₂,v₀)
    pub v: [usize; 6],
    /// which flaps exist (a boundary edge has none)
    pub flaps: [bool; 3],
    /// the triangle's rest data
    pub rest: RestTriangle,
}

impl Mesh {
    /// A `width` × `height` rectangle with corner (0, 0) and edges of about `edge`, split into squares of
    /// alternating diagonals. `perturb` (fraction of the edge length, < 0.5) moves interior vertices randomly and
    /// boundary vertices along their side (seeded).
    pub fn rectangle(
        width: f64,
        height: f64,
        edge: f64,
        perturb: f64,
        seed: u64,
    ) -> Result<Mesh, ShellError> {
        let (nx, ny) = Self::rectangle_cells(width, height, edge, perturb)?;
        let (hx, hy) = (width / nx as f64, height / ny as f64);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut rest = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                let mut p = [i as f64 * hx, j as f64 * hy];
                if perturb > 0.0 {
                    if i > 0 && i < nx {
                        p[0] += perturb * hx * rng.random_range(-1.0..1.0);
                    }
                    if j > 0 && j < ny {
                        p[1] += perturb * hy * rng.random_range(-1.0..1.0);
                    }
                }
                rest.push(p);
            }
        }
        let id = |i: usize, j: usize| j * (nx + 1) + i;
        let mut tris = Vec::with_capacity(2 * nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if (i + j) % 2 == 0 {
                    tris.push([a, b, c]);
                    tris.push([a, c, d]);
                } else {
                    tris.push([a, b, d]);
                    tris.push([b, c, d]);
                }
            }
        }
        let origin = (0..tris.len())
            .map(|t| format!("rectangle triangle {t}"))
            .collect();
        Ok(Mesh { rest, tris, origin })
    }

    /// The cells (nx, ny) of a rectangle: checks the sizes (finite and positive), `perturb` and the vertex count
    /// against [`MAX_VERTICES`] in floating point, before anything is allocated or cast.
    fn rectangle_cells(
        width: f64,
        height: f64,
        edge: f64,
        perturb: f64,
    ) -> Result<(usize, usize), ShellError> {
        let finite_positive = |v: f64| v > 0.0 && v.is_finite();
        if !(finite_positive(width) && finite_positive(height) && finite_positive(edge)) {
            return Err(ShellError::Rectangle {
                message: format!(
                    "width, height and edge must be positive finite numbers (got {width}, {height}, {edge})"
                ),
            });
        }
        if !(0.0..0.5).contains(&perturb) {
            return Err(ShellError::Rectangle {
                message: format!("perturb must be in [0, 0.5), got {perturb}"),
            });
        }
        let fx = (width / edge).round().max(1.0);
        let fy = (height / edge).round().max(1.0);
        let vertices = (fx + 1.0) * (fy + 1.0);
        // finite positive sizes: the count is a number or +inf, never NaN
        if vertices > MAX_VERTICES as f64 {
            return Err(ShellError::Rectangle {
                message: format!(
                    "{fx:e} x {fy:e} cells ({vertices:e} vertices) is too many (at most {MAX_VERTICES} vertices: \
                     a larger edge?)"
                ),
            });
        }
        Ok((fx as usize, fy as usize))
    }

    /// Read an OBJ file (`v` and `f` lines; other statements are ignored; polygons are fan-triangulated). The
    /// mesh must be flat in a plane z = const; returns the mesh and the 3D vertex positions.
    pub fn load_obj(path: &Path) -> Result<(Mesh, Vec<[f64; 3]>), ShellError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ShellError::io(path, "cannot read the mesh", e))?;
        Self::parse_obj(&text, &path.display().to_string())
    }

    /// Parse OBJ text; `name` is used in error messages.
    pub fn parse_obj(text: &str, name: &str) -> Result<(Mesh, Vec<[f64; 3]>), ShellError> {
        let (pos, tris, origin, vline) = parse_obj_surface(text, name)?;
        Self::flat(pos, tris, origin, &vline, name)
    }
}

/// A triangle surface: vertex positions and triangles (obstacles, pictures).
pub type Surface = (Vec<[f64; 3]>, Vec<[usize; 3]>);

/// An OBJ surface: positions, fan-triangulated faces, each face's `file:line`, each vertex's line.
type ObjSurface = (Vec<[f64; 3]>, Vec<[usize; 3]>, Vec<String>, Vec<usize>);

/// Read any OBJ triangle surface (`v` and `f` lines; polygons fan-triangulated) for an obstacle; errors name
/// the file and line.
pub fn load_obj_surface(path: &Path) -> Result<Surface, ShellError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| ShellError::io(path, "cannot read the mesh", e))?;
    let (pos, tris, _, _) = parse_obj_surface(&text, &path.display().to_string())?;
    Ok((pos, tris))
}

fn parse_obj_surface(text: &str, name: &str) -> Result<ObjSurface, ShellError> {
    {
        let mut pos: Vec<[f64; 3]> = Vec::new();
        let mut vline: Vec<usize> = Vec::new();
        let mut tris = Vec::new();
        let mut origin = Vec::new();
        for (ln, line) in text.lines().enumerate() {
            let ln = ln + 1;
            let err = |message: String| ShellError::Obj {
                file: name.to_string(),
                line: Some(ln),
                message,
            };
            let line = line.split('#').next().unwrap_or("");
            let mut it = line.split_whitespace();
            match it.next() {
                Some("v") => {
                    let c: Vec<&str> = it.collect();
                    if c.len() < 3 {
                        return Err(err(format!("vertex needs 3 coordinates, got {}", c.len())));
                    }
                    let mut p = [0.0; 3];
                    for k in 0..3 {
                        p[k] = c[k]
                            .parse::<f64>()
                            .ok()
                            .filter(|x| x.is_finite())
                            .ok_or_else(|| err(format!("bad vertex coordinate {:?}", c[k])))?;
                    }
                    if pos.len() == MAX_VERTICES {
                        return Err(err(format!(
                            "more than {MAX_VERTICES} vertices (the limit of a mesh)"
                        )));
                    }
                    pos.push(p);
                    vline.push(ln);
                }
                Some("f") => {
                    let mut idx = Vec::new();
                    for tok in it {
                        let first = tok.split('/').next().unwrap_or("");
                        let i: i64 = first
                            .parse()
                            .map_err(|_| err(format!("bad face index {tok:?}")))?;
                        let n = pos.len() as i64;
                        let k = if i > 0 { i - 1 } else { n + i };
                        if i == 0 || k < 0 || k >= n {
                            return Err(err(format!(
                                "face index {i} out of range ({n} vertices so far)"
                            )));
                        }
                        idx.push(k as usize);
                    }
                    if idx.len() < 3 {
                        return Err(err(format!(
                            "face needs at least 3 vertices, got {}",
                            idx.len()
                        )));
                    }
                    if tris.len() + idx.len() - 2 > MAX_TRIANGLES {
                        return Err(err(format!(
                            "more than {MAX_TRIANGLES} triangles (the limit of a mesh)"
                        )));
                    }
                    for k in 1..idx.len() - 1 {
                        tris.push([idx[0], idx[k], idx[k + 1]]);
                        origin.push(format!("{name}:{ln}"));
                    }
                }
                _ => {}
            }
        }
        if tris.is_empty() {
            return Err(ShellError::Obj {
                file: name.to_string(),
                line: None,
                message: "no faces".into(),
            });
        }
        Ok((pos, tris, origin, vline))
    }
}

impl Mesh {
    /// The mesh of a parsed OBJ surface that must be flat in a plane z = const (the rest layout).
    fn flat(
        pos: Vec<[f64; 3]>,
        tris: Vec<[usize; 3]>,
        origin: Vec<String>,
        vline: &[usize],
        name: &str,
    ) -> Result<(Mesh, Vec<[f64; 3]>), ShellError> {
        let (zmin, zmax) = pos
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p[2]), b.max(p[2]))
            });
        let extent = pos
            .iter()
            .fold(0.0f64, |a, p| a.max(p[0].abs()).max(p[1].abs()))
            .max(1e-300);
        if zmax - zmin > 1e-9 * extent {
            let (k, _) = pos
                .iter()
                .enumerate()
                .find(|(_, p)| (p[2] - zmin).abs() > 1e-9 * extent)
                .expect("a vertex off the plane exists");
            return Err(ShellError::Obj {
                file: name.to_string(),
                line: Some(vline[k]),
                message: format!(
                    "the rest layout must be flat in a plane z = const (this vertex has z = {}, others {zmin})",
                    pos[k][2]
                ),
            });
        }
        let rest = pos.iter().map(|p| [p[0], p[1]]).collect();
        Ok((Mesh { rest, tris, origin }, pos))
    }

    /// Initial 3D positions of the rest layout placed in a plane: `frame` = (origin, u axis, v axis) so that
    /// x = origin + X u + Y v.
    pub fn place(&self, origin: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Vec<[f64; 3]> {
        self.rest
            .iter()
            .map(|p| std::array::from_fn(|k| origin[k] + p[0] * u[k] + p[1] * v[k]))
            .collect()
    }

    /// The stencils of all triangles with the fabric axes at `angle` (rad) against the mesh. Errors (naming the
    /// triangle's origin) on a degenerate rest triangle or a non-manifold edge (shared by more than two triangles).
    pub fn stencils(&self, angle: f64) -> Result<Vec<Stencil>, ShellError> {
        let (s, c) = angle.sin_cos();
        let mat = |p: [f64; 2]| [c * p[0] + s * p[1], -s * p[0] + c * p[1]];
        let mut tris = self.tris.clone();
        let mut rests = Vec::with_capacity(tris.len());
        for (t, tri) in tris.iter_mut().enumerate() {
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(ShellError::Triangle {
                    origin: self.origin[t].clone(),
                    message: "degenerate triangle (repeated vertex)".into(),
                });
            }
            let x = tri.map(|v| mat(self.rest[v]));
            let det = (x[1][0] - x[0][0]) * (x[2][1] - x[0][1])
                - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]);
            if det < 0.0 {
                tri.swap(1, 2);
            }
            let x = tri.map(|v| mat(self.rest[v]));
            let r = RestTriangle::new(x[0], x[1], x[2]).ok_or_else(|| ShellError::Triangle {
                origin: self.origin[t].clone(),
                message: "degenerate rest triangle (zero area)".into(),
            })?;
            rests.push(r);
        }
        let mut edges: HashMap<(usize, usize), Vec<(usize, usize)>> = HashMap::new();
        for (t, tri) in tris.iter().enumerate() {
            for i in 0..3 {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                let list = edges.entry((a.min(b), a.max(b))).or_default();
                list.push((t, i));
                if list.len() > 2 {
                    return Err(ShellError::Triangle {
                        origin: self.origin[t].clone(),
                        message: format!(
                            "non-manifold edge ({}, {}) shared by more than two triangles (also {} and {})",
                            a + 1,
                            b + 1,
                            self.origin[list[0].0],
                            self.origin[list[1].0]
                        ),
                    });
                }
            }
        }
        let mut out = Vec::with_capacity(tris.len());
        for (t, tri) in tris.iter().enumerate() {
            let mut v = [tri[0], tri[1], tri[2], tri[0], tri[0], tri[0]];
            let mut flaps = [false; 3];
            for i in 0..3 {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                for &(u, _) in &edges[&(a.min(b), a.max(b))] {
                    if u != t {
                        let other = tris[u];
                        let w = other.iter().copied().find(|&x| x != a && x != b);
                        if let Some(w) = w {
                            if !tri.contains(&w) {
                                v[3 + i] = w;
                                flaps[i] = true;
                            }
                        }
                    }
                }
            }
            out.push(Stencil {
                v,
                flaps,
                rest: rests[t],
            });
        }
        Ok(out)
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.rest.len()
    }

    /// True for a mesh without vertices.
    pub fn is_empty(&self) -> bool {
        self.rest.is_empty()
    }
}

/// Write positions and triangles as an OBJ file, each line of `header` first as a comment.
pub fn write_obj(
    path: &Path,
    header: &str,
    x: &[[f64; 3]],
    tris: &[[usize; 3]],
) -> std::io::Result<()> {
    use std::io::Write;
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    for line in header.lines() {
        writeln!(f, "# {line}")?;
    }
    for p in x {
        writeln!(f, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for t in tris {
        writeln!(f, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    f.flush()
}
