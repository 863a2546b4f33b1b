//! Rigid obstacles and the cloth's contact with them (`docs/cloth-simulator.md`, "The cloth solver"; docs/cloth-simulator.md): spheres,
//! planes and triangle meshes, a smooth one-sided penalty per cloth vertex, and lagged Coulomb friction.
//!
//! **Distance.** d(p) is the signed distance of p to the obstacle's surface (positive outside) and n = ∇d its
//! outward unit normal. A triangle mesh is queried through parry3d-f64's BVH ([`TriMesh`] with pseudo-normals,
//! so that the inside of a closed mesh is told apart from the outside): with c the closest surface point,
//! d = ±|p − c|, n = ±(p − c)/|p − c|; ∇²d = 0 where c lies inside a face, ±(I − ê êᵀ − n nᵀ)/|p − c| where it
//! lies on an edge of direction ê, ±(I − n nᵀ)/|p − c| at a vertex (the sphere: (I − n nᵀ)/|p − centre|).
//!
//! **Penalty.** With the layer thickness δ and the penetration p = δ − d > 0, E = m k p³/3 per vertex (m the
//! vertex mass, k the stiffness in 1/(m s²)); C² at p = 0. ∇E = −m k p² n and
//! ∇²E = m k (2 p n nᵀ − p² ∇²d); the solver keeps the PSD part 2 m k p n nᵀ (the curvature term is dropped).
//!
//! **Friction** (lagged, as in incremental-potential contact): at the start of a step every vertex in a
//! penalty layer gets its normal force λ = m k p² and normal n, both frozen for the step. With the tangential
//! displacement u = T (x − xₙ), T = I − n nᵀ, the friction potential is D = μ λ f₀(|u|), where f₀ smooths
//! |u| below ε = ε_v h (ε_v the sliding-velocity threshold): f₀(y) = y²/ε − y³/(3ε²) for y < ε and
//! y − ε/3 beyond; f₀′ = f₁ = 2y/ε − y²/ε² resp. 1. Its force −∇D = −μ λ f₁(|u|) û is Coulomb's law
//! (magnitude μ λ when sliding faster than ε_v, opposing the motion) and its Hessian
//! μ λ T [f₁′ ûûᵀ + (f₁/y)(I − ûûᵀ)] T is PSD.

use super::ShellError;
use crate::real::{c, Real};
use parry3d_f64::math::Vector as PVector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

/// A rigid obstacle as the solver uses it.
#[derive(Clone)]
pub enum Obstacle {
    /// A sphere.
    Sphere {
        /// centre (m)
        center: [f64; 3],
        /// radius (m)
        radius: f64,
    },
    /// A half-space bounded by a plane.
    Plane {
        /// a point on the plane (m)
        point: [f64; 3],
        /// the outward normal (the cloth's side)
        normal: [f64; 3],
    },
    /// A closed triangle mesh.
    Mesh(Box<MeshObstacle>),
}

impl std::fmt::Debug for Obstacle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Obstacle::Sphere { center, radius } => write!(f, "Sphere({center:?}, {radius})"),
            Obstacle::Plane { point, normal } => write!(f, "Plane({point:?}, {normal:?})"),
            Obstacle::Mesh(m) => write!(f, "Mesh({}, {} triangles)", m.name, m.triangles.len()),
        }
    }
}

/// A closed, consistently oriented triangle mesh with its BVH.
#[derive(Clone)]
pub struct MeshObstacle {
    /// where it came from (for messages)
    pub name: String,
    /// vertex positions (m)
    pub vertices: Vec<[f64; 3]>,
    /// triangles (vertex indices, outward orientation)
    pub triangles: Vec<[usize; 3]>,
    trimesh: TriMesh,
}

impl MeshObstacle {
    /// Build the BVH and the pseudo-normals; errors (naming `name`) when the mesh is not a manifold triangle
    /// mesh with consistent orientation, or has a degenerate or out-of-range triangle.
    pub fn new(
        name: &str,
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[usize; 3]>,
    ) -> Result<MeshObstacle, ShellError> {
        let bad = |problem: String| ShellError::ObstacleMesh {
            file: name.to_string(),
            problem,
        };
        if triangles.is_empty() {
            return Err(bad("no triangles".into()));
        }
        if let Some(t) = triangles
            .iter()
            .position(|t| t.iter().any(|&v| v >= vertices.len()))
        {
            return Err(bad(format!(
                "triangle {t} refers to a vertex it does not have"
            )));
        }
        if let Some(t) = triangles
            .iter()
            .position(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
        {
            return Err(bad(format!("triangle {t} repeats a vertex")));
        }
        // closed and consistently oriented: every directed edge once, and its reverse once
        let mut edges = std::collections::HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let e = (tri[k], tri[(k + 1) % 3]);
                if edges.insert(e, t).is_some() {
                    return Err(bad(format!(
                        "not a manifold, consistently oriented triangle mesh: the edge {}–{} is used twice in \
                         the same direction (triangle {t})",
                        e.0, e.1
                    )));
                }
            }
        }
        if let Some(((a, b), t)) = edges.iter().find(|(e, _)| !edges.contains_key(&(e.1, e.0))) {
            return Err(bad(format!(
                "not a closed triangle mesh: the edge {a}–{b} of triangle {t} has no neighbour across it"
            )));
        }
        // orient outward: a closed mesh wound inward has a negative signed volume
        let volume: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, cc] = t.map(|v| vertices[v]);
                dot3(
                    a,
                    [
                        b[1] * cc[2] - b[2] * cc[1],
                        b[2] * cc[0] - b[0] * cc[2],
                        b[0] * cc[1] - b[1] * cc[0],
                    ],
                )
            })
            .sum();
        let triangles: Vec<[usize; 3]> = if volume < 0.0 {
            triangles.iter().map(|t| [t[0], t[2], t[1]]).collect()
        } else {
            triangles
        };
        let pts: Vec<PVector> = vertices
            .iter()
            .map(|p| PVector::new(p[0], p[1], p[2]))
            .collect();
        let idx: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
            .collect();
        let trimesh = TriMesh::with_flags(
            pts,
            idx,
            TriMeshFlags::HALF_EDGE_TOPOLOGY | TriMeshFlags::ORIENTED,
        )
        .map_err(|e| {
            bad(format!(
                "not a manifold, consistently oriented triangle mesh ({e})"
            ))
        })?;
        Ok(MeshObstacle {
            name: name.to_string(),
            vertices,
            triangles,
            trimesh,
        })
    }

    fn face_normal(&self, t: usize) -> [f64; 3] {
        let [a, b, cc] = self.triangles[t].map(|v| self.vertices[v]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
        n.map(|x| x / l)
    }
}

/// The surface feature closest to a point, with the sign of the distance (−1 inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Feature {
    /// a sphere: d = |p − centre| − radius
    Sphere {
        /// centre (m)
        center: [f64; 3],
        /// radius (m)
        radius: f64,
    },
    /// a plane or the inside of a mesh face: d = n·(p − a)
    Face {
        /// a point of the face (m)
        a: [f64; 3],
        /// the unit outward normal
        n: [f64; 3],
    },
    /// a mesh edge: d = ±dist(p, line ab)
    Edge {
        /// one end of the edge (m)
        a: [f64; 3],
        /// the other end (m)
        b: [f64; 3],
        /// +1 outside, −1 inside
        sign: f64,
    },
    /// a mesh vertex: d = ±|p − a|
    Vertex {
        /// the vertex (m)
        a: [f64; 3],
        /// +1 outside, −1 inside
        sign: f64,
    },
}

/// Signed distance, its gradient (unit normal) and its Hessian at a point, and the feature they come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proximity {
    /// signed distance d (m; negative inside)
    pub d: f64,
    /// its gradient ∇d, the unit normal
    pub n: [f64; 3],
    /// its Hessian ∇²d (1/m)
    pub hess: [[f64; 3]; 3],
    /// the closest feature
    pub feature: Feature,
}

fn curvature(n: &[f64; 3], s: f64) -> [[f64; 3]; 3] {
    std::array::from_fn(|a| std::array::from_fn(|b| s * ((a == b) as u8 as f64 - n[a] * n[b])))
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Feature {
    /// The feature translated by `o` (m): the closest feature of a shape translated by o to p is the closest
    /// feature of the shape to p − o, translated.
    pub fn translated(&self, o: [f64; 3]) -> Feature {
        let add = |p: [f64; 3]| std::array::from_fn(|c| p[c] + o[c]);
        match *self {
            Feature::Sphere { center, radius } => Feature::Sphere {
                center: add(center),
                radius,
            },
            Feature::Face { a, n } => Feature::Face { a: add(a), n },
            Feature::Edge { a, b, sign } => Feature::Edge {
                a: add(a),
                b: add(b),
                sign,
            },
            Feature::Vertex { a, sign } => Feature::Vertex { a: add(a), sign },
        }
    }

    /// d, ∇d and ∇²d of the feature's distance at p (the radial vector v = p − (closest point) with length r:
    /// n = ±v/r, ∇²d = ±(I − n nᵀ)/r; faces are linear).
    pub fn proximity(&self, p: [f64; 3]) -> Proximity {
        let radial = |v: [f64; 3], sign: f64, offset: f64, fallback: [f64; 3]| {
            let r = dot3(v, v).sqrt();
            if r > 0.0 {
                let n = v.map(|x| sign * x / r);
                (sign * r - offset, n, curvature(&n, sign / r))
            } else {
                (-offset, fallback, [[0.0; 3]; 3])
            }
        };
        let (d, n, hess) = match *self {
            Feature::Sphere { center, radius } => {
                radial(sub3(p, center), 1.0, radius, [0.0, 0.0, 1.0])
            }
            Feature::Face { a, n } => (dot3(sub3(p, a), n), n, [[0.0; 3]; 3]),
            Feature::Edge { a, b, sign } => {
                let e = sub3(b, a);
                let w = sub3(p, a);
                let t = dot3(w, e) / dot3(e, e).max(1e-300);
                let v: [f64; 3] = std::array::from_fn(|k| w[k] - t * e[k]);
                let (d, n, mut hess) = radial(v, sign, 0.0, [0.0, 0.0, 1.0]);
                // across the edge only: ∇²|P w| = (P − n nᵀ)/r with P = I − ê êᵀ
                let r = dot3(v, v).sqrt();
                if r > 0.0 {
                    let ee = dot3(e, e).max(1e-300);
                    for (a, row) in hess.iter_mut().enumerate() {
                        for (b, h) in row.iter_mut().enumerate() {
                            *h -= sign / r * e[a] * e[b] / ee;
                        }
                    }
                }
                (d, n, hess)
            }
            Feature::Vertex { a, sign } => radial(sub3(p, a), sign, 0.0, [0.0, 0.0, 1.0]),
        };
        Proximity {
            d,
            n,
            hess,
            feature: *self,
        }
    }

    /// The signed distance generic over the scalar (the reference of the derivative harness).
    pub fn distance_reference<D: Real>(&self, p: &[D]) -> D {
        let norm = |v: &[D]| {
            v.iter()
                .fold(c::<D>(0.0), |acc, x| acc + x.clone() * x.clone())
                .sqrt()
        };
        match *self {
            Feature::Sphere { center, radius } => {
                let v: Vec<D> = (0..3).map(|k| p[k].clone() - center[k]).collect();
                norm(&v) - radius
            }
            Feature::Face { a, n } => {
                (0..3).fold(c::<D>(0.0), |acc, k| acc + (p[k].clone() - a[k]) * n[k])
            }
            Feature::Edge { a, b, sign } => {
                let e = sub3(b, a);
                let ee = dot3(e, e);
                let w: Vec<D> = (0..3).map(|k| p[k].clone() - a[k]).collect();
                let t = (0..3).fold(c::<D>(0.0), |acc, k| acc + w[k].clone() * e[k]) / ee;
                let v: Vec<D> = (0..3).map(|k| w[k].clone() - t.clone() * e[k]).collect();
                norm(&v) * sign
            }
            Feature::Vertex { a, sign } => {
                let v: Vec<D> = (0..3).map(|k| p[k].clone() - a[k]).collect();
                norm(&v) * sign
            }
        }
    }
}

impl Obstacle {
    /// Signed distance of `p` to the surface, its gradient and Hessian (module documentation).
    pub fn proximity(&self, p: [f64; 3]) -> Proximity {
        self.feature(p).proximity(p)
    }

    /// The closest feature of the surface to `p`.
    pub fn feature(&self, p: [f64; 3]) -> Feature {
        match self {
            Obstacle::Sphere { center, radius } => Feature::Sphere {
                center: *center,
                radius: *radius,
            },
            Obstacle::Plane { point, normal } => {
                let l = dot3(*normal, *normal).sqrt();
                Feature::Face {
                    a: *point,
                    n: normal.map(|x| x / l),
                }
            }
            Obstacle::Mesh(m) => m.feature(p),
        }
    }

    /// A triangle mesh of the surface for pictures (`None` for a plane).
    pub fn surface(&self) -> Option<super::mesh::Surface> {
        match self {
            Obstacle::Sphere { center, radius } => {
                Some(super::render::sphere_mesh(*center, *radius, 48))
            }
            Obstacle::Plane { .. } => None,
            Obstacle::Mesh(m) => Some((m.vertices.clone(), m.triangles.clone())),
        }
    }
}

impl MeshObstacle {
    /// The closest feature (BVH query; the sign from the pseudo-normals): the closest point's barycentric
    /// coordinates in its triangle tell a face (all > 1e-9) from an edge (one ≈ 0) and a vertex (two ≈ 0).
    fn feature(&self, p: [f64; 3]) -> Feature {
        let (proj, _) = self
            .trimesh
            .project_local_point_and_get_feature(PVector::new(p[0], p[1], p[2]));
        let cpt = [proj.point.x, proj.point.y, proj.point.z];
        let sign = if proj.is_inside { -1.0 } else { 1.0 };
        let t = (proj.subshape as usize).min(self.triangles.len() - 1);
        let [ia, ib, ic] = self.triangles[t];
        let [a, b, cc] = [ia, ib, ic].map(|v| self.vertices[v]);
        let (e1, e2, w) = (sub3(b, a), sub3(cc, a), sub3(cpt, a));
        let (d11, d12, d22) = (dot3(e1, e1), dot3(e1, e2), dot3(e2, e2));
        let (w1, w2) = (dot3(w, e1), dot3(w, e2));
        let det = (d11 * d22 - d12 * d12).max(1e-300);
        let l1 = (d22 * w1 - d12 * w2) / det;
        let l2 = (d11 * w2 - d12 * w1) / det;
        let bary = [1.0 - l1 - l2, l1, l2];
        let tol = 1e-9;
        let small: Vec<usize> = (0..3).filter(|&k| bary[k] <= tol).collect();
        let corners = [a, b, cc];
        match small.len() {
            0 => Feature::Face {
                a,
                n: self.face_normal(t),
            },
            1 => {
                let k = small[0];
                Feature::Edge {
                    a: corners[(k + 1) % 3],
                    b: corners[(k + 2) % 3],
                    sign,
                }
            }
            _ => {
                let k = (0..3).find(|k| !small.contains(k)).unwrap_or(0);
                Feature::Vertex {
                    a: corners[k],
                    sign,
                }
            }
        }
    }
}

/// The penalty E = m k p³/3 on p = δ − d (module documentation) for one vertex of mass `m` against a surface at
/// proximity `pr`: value, gradient, and the solver's PSD Hessian 2 m k p n nᵀ; zero outside the layer.
pub fn penalty(pr: &Proximity, m: f64, k: f64, delta: f64) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let pen = delta - pr.d;
    if pen <= 0.0 {
        return (0.0, [0.0; 3], [[0.0; 3]; 3]);
    }
    let mk = m * k;
    let g = pr.n.map(|x| -mk * pen * pen * x);
    let h = std::array::from_fn(|a| std::array::from_fn(|b| 2.0 * mk * pen * pr.n[a] * pr.n[b]));
    (mk * pen * pen * pen / 3.0, g, h)
}

/// The exact Hessian of [`penalty`]: m k (2 p n nᵀ − p² ∇²d) (for the derivative harness).
pub fn penalty_hessian_exact(pr: &Proximity, m: f64, k: f64, delta: f64) -> [[f64; 3]; 3] {
    let pen = delta - pr.d;
    if pen <= 0.0 {
        return [[0.0; 3]; 3];
    }
    let mk = m * k;
    std::array::from_fn(|a| {
        std::array::from_fn(|b| mk * (2.0 * pen * pr.n[a] * pr.n[b] - pen * pen * pr.hess[a][b]))
    })
}

/// A vertex in contact at the start of a step: the frozen normal n and normal force λ of lagged friction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionContact {
    /// the vertex
    pub vertex: usize,
    /// the frozen unit normal n
    pub n: [f64; 3],
    /// normal force magnitude λ = m k p² (N)
    pub lambda: f64,
}

/// f₀ and its first two derivatives at y ≥ 0 for the smoothing width ε (module documentation).
fn f0(y: f64, eps: f64) -> (f64, f64, f64) {
    if y < eps {
        (
            y * y / eps - y * y * y / (3.0 * eps * eps),
            2.0 * y / eps - y * y / (eps * eps),
            2.0 / eps - 2.0 * y / (eps * eps),
        )
    } else {
        (y - eps / 3.0, 1.0, 0.0)
    }
}

/// Friction potential μ λ f₀(|T δ|) of one contact for the displacement δ = x − xₙ over the step: value,
/// gradient and Hessian (PSD, exact where f₀ is C²: everywhere but y = ε, where it is C¹ with the Hessian jump
/// of f₁′).
pub fn friction(
    fc: &FrictionContact,
    mu: f64,
    eps: f64,
    delta: [f64; 3],
) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let n = fc.n;
    let dn: f64 = (0..3).map(|k| n[k] * delta[k]).sum();
    let u: [f64; 3] = std::array::from_fn(|k| delta[k] - dn * n[k]);
    let y = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let s = mu * fc.lambda;
    let (f, f1, f1p) = f0(y, eps);
    let tproj = |a: usize, b: usize| (a == b) as u8 as f64 - n[a] * n[b];
    if y < 1e-300 {
        // f₁/y → 2/ε and f₁′ → 2/ε: the Hessian is (2 s/ε) T
        let h = std::array::from_fn(|a| std::array::from_fn(|b| 2.0 * s / eps * tproj(a, b)));
        return (0.0, [0.0; 3], h);
    }
    let uh = u.map(|x| x / y);
    let g = uh.map(|x| s * f1 * x);
    let over = f1 / y;
    let h = std::array::from_fn(|a| {
        std::array::from_fn(|b| s * ((f1p - over) * uh[a] * uh[b] + over * tproj(a, b)))
    });
    (s * f, g, h)
}

/// D = μ λ f₀(|T δ|) of [`friction`] with the frozen normal `n` and normal force `lambda` as scalars too, generic
/// over the scalar (the trajectory adjoint differentiates μᵀ∇_δD with respect to them by forward-mode AD). Where
/// the tangential displacement vanishes exactly, f₀ = y²/ε (its cubic term has no first or second derivative
/// there).
pub fn friction_lagged_reference<D: Real>(n: &[D], lambda: D, mu: f64, eps: f64, delta: &[D]) -> D {
    let dn = (0..3).fold(c::<D>(0.0), |acc, k| acc + delta[k].clone() * n[k].clone());
    let y2 = (0..3).fold(c::<D>(0.0), |acc, k| {
        let u = delta[k].clone() - dn.clone() * n[k].clone();
        acc + u.clone() * u
    });
    let f = if y2.re() == 0.0 {
        y2 / eps
    } else if y2.re().sqrt() < eps {
        y2.clone() / eps - y2.clone() * y2.sqrt() / (3.0 * eps * eps)
    } else {
        y2.sqrt() - eps / 3.0
    };
    f * lambda * mu
}

/// Reference implementation of [`friction`] generic over the scalar (for the derivative harness).
pub fn friction_reference<D: Real>(fc: &FrictionContact, mu: f64, eps: f64, delta: &[D]) -> D {
    let n = fc.n;
    let dn = (0..3).fold(c::<D>(0.0), |acc, k| acc + delta[k].clone() * n[k]);
    let u: Vec<D> = (0..3)
        .map(|k| delta[k].clone() - dn.clone() * n[k])
        .collect();
    let y2 = u
        .iter()
        .fold(c::<D>(0.0), |acc, x| acc + x.clone() * x.clone());
    let y = y2.sqrt();
    let s = mu * fc.lambda;
    let f = if y.re() < eps {
        y.clone() * y.clone() / eps - y.clone() * y.clone() * y / (3.0 * eps * eps)
    } else {
        y - eps / 3.0
    };
    f * s
}

/// Reference implementation of [`penalty`]'s value (for the derivative harness), through the feature's
/// generic distance.
pub fn penalty_reference<D: Real>(feature: &Feature, m: f64, k: f64, delta: f64, p: &[D]) -> D {
    let pen = -feature.distance_reference(p) + delta;
    if pen.re() <= 0.0 {
        return c(0.0);
    }
    pen.clone() * pen.clone() * pen * (m * k / 3.0)
}
