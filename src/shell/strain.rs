//! The strain chain z(q) of a triangle stencil (`docs/cloth-simulator.md`, "Strain chain z(q) of a triangle stencil").
//!
//! Stencil dofs q (18): x₀, x₁, x₂, then the flap vertices across edges (x₀,x₁), (x₁,x₂), (x₂,x₀). Output
//! z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁) with
//! - F = [x₁−x₀ | x₂−x₀] D_m⁻¹, s_x = ‖F₀‖ − 1, s_y = ‖F₁‖ − 1, s_a = F₀·F₁/(‖F₀‖‖F₁‖);
//! - θ_i = −atan2(ê_i·(n₀×n_i), n₀·n_i) with n₀ = (x₁−x₀)×(x₂−x₀), n_i = (x_{3+i}−x_i)×e_i;
//! - II = Σ_i θ_i h_i r_i r_iᵀ over the edges that have a flap, h_i = ‖n₀‖/‖e_i‖ (the height of the opposite
//!   vertex over edge i), r₀ = row 1 of D_m⁻¹, r₂ = row 0, r₁ = r₀ + r₂.
//!
//! Everything is computed from coordinate differences (edge vectors), never from absolute coordinates, so results
//! do not lose accuracy far from the origin.
//!
//! Hand-written derivatives. In-plane: F is linear in q (∂F_c/∂x_v = β_{c,v} I), and the Hessians of ‖F_c‖ and
//! of the cosine u₀·u₁ with respect to (F₀, F₁) are written in closed form. Bending, per hinge with edge vertices
//! (p₀, p₁), opposite vertex p₂ and flap vertex p₃, in the edge vectors e = p₁−p₀, a = p₂−p₀, b = p₃−p₀:
//! with G(e, w) = ‖e‖ (e×w)/‖e×w‖² and t(e, w) = w·e/‖e‖²,
//! ∂θ/∂p₂ = G(e,a), ∂θ/∂p₃ = −G(e,b), ∂θ/∂p₁ = t_b G_b − t_a G_a, ∂θ/∂p₀ = (1−t_b) G_b − (1−t_a) G_a
//! (the hinge-angle gradient of Bridson et al. 2003 in these sign conventions: each wing's rows
//! ((1−t)G, tG, −G) on (p₀, p₁, p_w), with sign −1 for the triangle's own wing); the Hessian of θ differentiates
//! these expressions (each wing depends on (e, w) only), and κ_i = θ_i h_i by the product rule.
//! Only the contraction Σ_k w_k ∇²z_k is formed; the full 6×18×18 tensor is the contraction with unit vectors.

use crate::real::{self, Real, V3 as V3r};
use nalgebra::{Matrix3, Vector3};

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

/// Number of stencil dofs.
pub const NDOF: usize = 18;

/// The largest |coordinate| (m) of a stencil the strain chain accepts: the scenes' own bound on positions
/// (`scene::MAX_COORDINATE`); beyond it the products of the Hessian overflow. A stencil outside is treated as
/// degenerate (`None`).
pub const MAX_POSITION: f64 = 1e6;

/// Every coordinate finite and within ±[`MAX_POSITION`].
fn admissible_positions(q: &[f64; NDOF]) -> bool {
    q.iter().all(|v| v.abs() <= MAX_POSITION)
}

/// Rest (material) data of a triangle: D_m⁻¹ (row-major), rest area, and the edge vectors r_i of the bending sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestTriangle {
    /// D_m⁻¹ with D_m = [X₁−X₀ | X₂−X₀] (row-major)
    pub inv_dm: [[f64; 2]; 2],
    /// rest area A = |det D_m| / 2 (m²)
    pub area: f64,
}

impl RestTriangle {
    /// From rest positions in the fabric plane (warp/weft coordinates). `None` for a degenerate (zero-area or
    /// non-finite) triangle.
    pub fn new(x0: [f64; 2], x1: [f64; 2], x2: [f64; 2]) -> Option<Self> {
        let (a, b) = (
            [x1[0] - x0[0], x1[1] - x0[1]],
            [x2[0] - x0[0], x2[1] - x0[1]],
        );
        let det = a[0] * b[1] - b[0] * a[1];
        let scale = (a[0].hypot(a[1])) * (b[0].hypot(b[1]));
        if !det.is_finite() || det.abs() <= 1e-14 * scale || scale.is_nan() {
            return None;
        }
        let inv = 1.0 / det;
        Some(RestTriangle {
            inv_dm: [[b[1] * inv, -b[0] * inv], [-a[1] * inv, a[0] * inv]],
            area: 0.5 * det.abs(),
        })
    }

    /// From D_m⁻¹ directly (as the conformance vectors store it); the area is 1/(2|det D_m⁻¹|).
    pub fn from_inv_dm(inv_dm: [[f64; 2]; 2]) -> Self {
        let det = inv_dm[0][0] * inv_dm[1][1] - inv_dm[0][1] * inv_dm[1][0];
        RestTriangle {
            inv_dm,
            area: 0.5 / det.abs(),
        }
    }

    /// r_i of the bending sum: r₀ = row 1 of D_m⁻¹, r₂ = row 0, r₁ = r₀ + r₂.
    #[inline]
    pub fn r(&self) -> [[f64; 2]; 3] {
        let d = &self.inv_dm;
        [d[1], [d[0][0] + d[1][0], d[0][1] + d[1][1]], d[0]]
    }

    /// Coefficients of II₀₀, II₀₁, II₁₁ in κ_i for each edge: (r_i0², r_i0 r_i1, r_i1²).
    #[inline]
    pub fn bend_coeffs(&self) -> [[f64; 3]; 3] {
        self.r().map(|r| [r[0] * r[0], r[0] * r[1], r[1] * r[1]])
    }

    /// β_{c,v}: ∂F_c/∂x_v = β_{c,v} I for columns c = 0, 1 and triangle vertices v = 0, 1, 2.
    #[inline]
    pub fn beta(&self) -> [[f64; 3]; 2] {
        let d = &self.inv_dm;
        [
            [-d[0][0] - d[1][0], d[0][0], d[1][0]],
            [-d[0][1] - d[1][1], d[0][1], d[1][1]],
        ]
    }
}

#[inline]
fn vtx(q: &[f64; NDOF], v: usize) -> V3 {
    V3::new(q[3 * v], q[3 * v + 1], q[3 * v + 2])
}

/// Cross-product matrix: [v]× u = v × u.
#[inline]
fn skew(v: &V3) -> M3 {
    M3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Hinge vertex indices (p₀, p₁, p₂, p₃) of edge i within the stencil.
#[inline]
pub fn hinge(i: usize) -> [usize; 4] {
    [i, (i + 1) % 3, (i + 2) % 3, 3 + i]
}

/// Cached intermediate quantities of one hinge (edge with a flap).
#[derive(Clone, Copy, Debug)]
struct Hinge {
    e: V3,
    a: V3,
    b: V3,
    theta: f64,
    h: f64,
    /// ∂θ/∂p_j, j = 0..3
    dtheta: [V3; 4],
    /// ∂h/∂p_j, j = 0..2 (h does not depend on the flap vertex)
    dh: [V3; 3],
}

/// z, the 6×18 Jacobian and the cached quantities needed for the weighted Hessian.
#[derive(Clone, Debug)]
pub struct StrainChain {
    /// z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁)
    pub z: [f64; 6],
    /// ∂z_k/∂q_j (row k)
    pub jac: [[f64; NDOF]; 6],
    rest: RestTriangle,
    f: [V3; 2],
    norm: [f64; 2],
    hinges: [Option<Hinge>; 3],
}

/// The angle θ of a hinge from the triangle normal n₀ = (x₁−x₀)×(x₂−x₀) (computed once per triangle, exactly as
/// the note defines it, so that every hinge sees the same n₀), its edge vector e and b = p₃ − p₀.
#[inline]
fn hinge_angle(e: &V3, n0: &V3, b: &V3) -> f64 {
    let n1 = b.cross(e);
    let y = e.dot(&n0.cross(&n1)) / e.norm();
    -y.atan2(n0.dot(&n1))
}

/// The in-plane strains (s_x, s_a, s_y) and bending-sum values; `None` on a degenerate configuration.
#[inline]
fn in_plane(q: &[f64; NDOF], rest: &RestTriangle) -> Option<([V3; 2], [f64; 2])> {
    let (x0, x1, x2) = (vtx(q, 0), vtx(q, 1), vtx(q, 2));
    let (d1, d2) = (x1 - x0, x2 - x0);
    let d = &rest.inv_dm;
    let f0 = d1 * d[0][0] + d2 * d[1][0];
    let f1 = d1 * d[0][1] + d2 * d[1][1];
    let (n0, n1) = (f0.norm(), f1.norm());
    if !(n0 > 0.0 && n1 > 0.0 && n0.is_finite() && n1.is_finite()) {
        return None;
    }
    Some(([f0, f1], [n0, n1]))
}

/// z(q) only (the fast value path). `None` when the deformed triangle or a hinge is degenerate (zero-length
/// edge, zero area, non-finite input).
pub fn strain(q: &[f64; NDOF], rest: &RestTriangle, flaps: [bool; 3]) -> Option<[f64; 6]> {
    strain_angles(q, rest, flaps).map(|(z, _)| z)
}

/// z(q) and the hinge angles θ_i (0 for a missing flap), as [`strain`].
pub fn strain_angles(
    q: &[f64; NDOF],
    rest: &RestTriangle,
    flaps: [bool; 3],
) -> Option<([f64; 6], [f64; 3])> {
    if !admissible_positions(q) {
        return None;
    }
    let (f, n) = in_plane(q, rest)?;
    let mut z = [
        n[0] - 1.0,
        f[0].dot(&f[1]) / (n[0] * n[1]),
        n[1] - 1.0,
        0.0,
        0.0,
        0.0,
    ];
    let coef = rest.bend_coeffs();
    let n0 = (vtx(q, 1) - vtx(q, 0)).cross(&(vtx(q, 2) - vtx(q, 0)));
    let na = n0.norm();
    let mut angles = [0.0; 3];
    for i in 0..3 {
        if !flaps[i] {
            continue;
        }
        let [p0, p1, _, p3] = hinge(i);
        let x0 = vtx(q, p0);
        let (e, b) = (vtx(q, p1) - x0, vtx(q, p3) - x0);
        let le = e.norm();
        if !(le > 0.0 && na > 0.0) {
            return None;
        }
        angles[i] = hinge_angle(&e, &n0, &b);
        let kappa = angles[i] * na / le;
        if !kappa.is_finite() {
            return None;
        }
        for c in 0..3 {
            z[3 + c] += kappa * coef[i][c];
        }
    }
    Some((z, angles))
}

impl StrainChain {
    /// z and its Jacobian. `None` on a degenerate configuration (see [`strain`]); a flap whose vertex lies on the
    /// edge line contributes θ = 0 (its derivatives are then undefined, and it is reported as degenerate too).
    pub fn new(q: &[f64; NDOF], rest: &RestTriangle, flaps: [bool; 3]) -> Option<Self> {
        if !admissible_positions(q) {
            return None;
        }
        let (f, n) = in_plane(q, rest)?;
        let beta = rest.beta();
        let u = [f[0] / n[0], f[1] / n[1]];
        let c = u[0].dot(&u[1]);
        let g = [(u[1] - u[0] * c) / n[0], (u[0] - u[1] * c) / n[1]];
        let mut z = [n[0] - 1.0, c, n[1] - 1.0, 0.0, 0.0, 0.0];
        let mut jac = [[0.0; NDOF]; 6];
        for v in 0..3 {
            for k in 0..3 {
                jac[0][3 * v + k] = beta[0][v] * u[0][k];
                jac[2][3 * v + k] = beta[1][v] * u[1][k];
                jac[1][3 * v + k] = beta[0][v] * g[0][k] + beta[1][v] * g[1][k];
            }
        }
        let coef = rest.bend_coeffs();
        let mut hinges = [None; 3];
        let na_v = (vtx(q, 1) - vtx(q, 0)).cross(&(vtx(q, 2) - vtx(q, 0)));
        for i in 0..3 {
            if !flaps[i] {
                continue;
            }
            let idx = hinge(i);
            let x0 = vtx(q, idx[0]);
            let (e, a, b) = (
                vtx(q, idx[1]) - x0,
                vtx(q, idx[2]) - x0,
                vtx(q, idx[3]) - x0,
            );
            let le = e.norm();
            let nb_v = e.cross(&b);
            let (na, nb) = (na_v.norm(), nb_v.norm());
            if !(le > 0.0 && na > 0.0 && nb > 0.0) {
                return None;
            }
            let theta = hinge_angle(&e, &na_v, &b);
            let h = na / le;
            // θ gradient
            let ga = na_v * (le / (na * na));
            let gb = nb_v * (le / (nb * nb));
            let l2 = le * le;
            let (ta, tb) = (a.dot(&e) / l2, b.dot(&e) / l2);
            let dtheta = [
                gb * (1.0 - tb) - ga * (1.0 - ta),
                gb * tb - ga * ta,
                ga,
                -gb,
            ];
            // h gradient: ∂h/∂e = (a × n̂)/|e| − h ê/|e|, ∂h/∂a = (n̂ × e)/|e|
            let nh = na_v / na;
            let dhe = a.cross(&nh) / le - e * (h / l2);
            let dha = nh.cross(&e) / le;
            let dh = [-dhe - dha, dhe, dha];
            let kappa = theta * h;
            if !kappa.is_finite() {
                return None;
            }
            for cc in 0..3 {
                z[3 + cc] += kappa * coef[i][cc];
            }
            for (j, &p) in idx.iter().enumerate() {
                let mut dk = dtheta[j] * h;
                if j < 3 {
                    dk += dh[j] * theta;
                }
                for cc in 0..3 {
                    for k in 0..3 {
                        jac[3 + cc][3 * p + k] += coef[i][cc] * dk[k];
                    }
                }
            }
            hinges[i] = Some(Hinge {
                e,
                a,
                b,
                theta,
                h,
                dtheta,
                dh,
            });
        }
        Some(StrainChain {
            z,
            jac,
            rest: *rest,
            f,
            norm: n,
            hinges,
        })
    }

    /// Add Σ_k w_k ∇²z_k (18×18) to `out`.
    pub fn add_weighted_hessian(&self, w: &[f64; 6], out: &mut [[f64; NDOF]; NDOF]) {
        self.add_in_plane_hessian(w, out);
        let coef = self.rest.bend_coeffs();
        for i in 0..3 {
            if let Some(hg) = &self.hinges[i] {
                let omega = w[3] * coef[i][0] + w[4] * coef[i][1] + w[5] * coef[i][2];
                if omega != 0.0 {
                    add_hinge_hessian(hg, omega, hinge(i), out);
                }
            }
        }
    }

    /// The angle θ_i of hinge i (`None` without its flap).
    pub fn hinge_angle(&self, i: usize) -> Option<f64> {
        self.hinges[i].as_ref().map(|hg| hg.theta)
    }

    /// For a function φ(θ_i) of hinge i's angle with derivatives φ′ = `d1`, φ″ = `d2`: add φ′ ∇θ_i to `grad` and
    /// φ″ ∇θ_i ∇θ_iᵀ (+ φ′ ∇²θ_i when `curvature`) to `hess`. Nothing without the flap.
    pub fn add_hinge_angle_terms(
        &self,
        i: usize,
        d1: f64,
        d2: f64,
        curvature: bool,
        grad: &mut [f64; NDOF],
        hess: &mut [[f64; NDOF]; NDOF],
    ) {
        let Some(hg) = &self.hinges[i] else {
            return;
        };
        let idx = hinge(i);
        let mut hb = [[M3::zeros(); 4]; 4];
        if curvature {
            add_theta_hessian(hg, d1, &mut hb);
        }
        for j in 0..4 {
            for l in 0..4 {
                hb[j][l] += hg.dtheta[j] * hg.dtheta[l].transpose() * d2;
            }
            for k in 0..3 {
                grad[3 * idx[j] + k] += d1 * hg.dtheta[j][k];
            }
        }
        scatter(&hb, idx, hess);
    }

    /// Σ_k w_k ∇²z_k as a fresh matrix.
    pub fn weighted_hessian(&self, w: &[f64; 6]) -> [[f64; NDOF]; NDOF] {
        let mut out = [[0.0; NDOF]; NDOF];
        self.add_weighted_hessian(w, &mut out);
        out
    }

    fn add_in_plane_hessian(&self, w: &[f64; 6], out: &mut [[f64; NDOF]; NDOF]) {
        let [n0, n1] = self.norm;
        let u0 = self.f[0] / n0;
        let u1 = self.f[1] / n1;
        let c = u0.dot(&u1);
        let g0 = (u1 - u0 * c) / n0;
        let g1 = (u0 - u1 * c) / n1;
        let id = M3::identity();
        let p0 = id - u0 * u0.transpose();
        let p1 = id - u1 * u1.transpose();
        let h00 = p0 * (w[0] / n0)
            + ((u0 * g0.transpose() + g0 * u0.transpose()) / n0 + p0 * (c / (n0 * n0))) * (-w[1]);
        let h11 = p1 * (w[2] / n1)
            + ((u1 * g1.transpose() + g1 * u1.transpose()) / n1 + p1 * (c / (n1 * n1))) * (-w[1]);
        let h01 = (id - u0 * u0.transpose() - u1 * u1.transpose() + u0 * u1.transpose() * c)
            * (w[1] / (n0 * n1));
        let beta = self.rest.beta();
        for v in 0..3 {
            for x in 0..3 {
                let (b0v, b1v, b0x, b1x) = (beta[0][v], beta[1][v], beta[0][x], beta[1][x]);
                let blk = h00 * (b0v * b0x)
                    + h11 * (b1v * b1x)
                    + h01 * (b0v * b1x)
                    + h01.transpose() * (b1v * b0x);
                for r in 0..3 {
                    for s in 0..3 {
                        out[3 * v + r][3 * x + s] += blk[(r, s)];
                    }
                }
            }
        }
    }
}

/// G(e, w) = ‖e‖ n/‖n‖² with n = e × w, and its derivatives ∂G/∂e, ∂G/∂w; also t = w·e/‖e‖² with ∇_e t, ∇_w t.
#[inline]
fn wing(e: &V3, w: &V3) -> (V3, M3, M3, f64, V3, V3) {
    let n = e.cross(w);
    let n2 = n.norm_squared();
    let le = e.norm();
    let l2 = le * le;
    let g = n * (le / n2);
    let proj = M3::identity() - n * n.transpose() * (2.0 / n2);
    let dge = n * e.transpose() / (le * n2) - proj * skew(w) * (le / n2);
    let dgw = proj * skew(e) * (le / n2);
    let t = w.dot(e) / l2;
    let te = w / l2 - e * (2.0 * w.dot(e) / (l2 * l2));
    let tw = e / l2;
    (g, dge, dgw, t, te, tw)
}

/// Add c ∇²θ of one hinge to its 4×4 blocks (p₀, p₁, p₂, p₃), wing by wing: the wing's gradient rows
/// (p₀, p₁, p_w) = ±((1−t)G, tG, −G) differentiated in (e, w).
fn add_theta_hessian(hg: &Hinge, c: f64, hb: &mut [[M3; 4]; 4]) {
    for (w, pw, sign) in [(&hg.a, 2usize, -1.0), (&hg.b, 3usize, 1.0)] {
        let (g, dge, dgw, t, te, tw) = wing(&hg.e, w);
        let k1e = g * te.transpose() + dge * t;
        let k1w = g * tw.transpose() + dgw * t;
        let rows = [
            (0usize, dge - k1e, dgw - k1w),
            (1, k1e, k1w),
            (pw, -dge, -dgw),
        ];
        for (r, ke, kw) in rows {
            // columns: ∂/∂p₁ = ∂/∂e, ∂/∂p_w = ∂/∂w, ∂/∂p₀ = −∂/∂e − ∂/∂w
            let ke = ke * (sign * c);
            let kw = kw * (sign * c);
            hb[r][1] += ke;
            hb[r][pw] += kw;
            hb[r][0] -= ke + kw;
        }
    }
}

/// Add the 4×4 blocks of a hinge (vertices `idx` of the stencil) to the stencil Hessian.
fn scatter(hb: &[[M3; 4]; 4], idx: [usize; 4], out: &mut [[f64; NDOF]; NDOF]) {
    for (j, &pj) in idx.iter().enumerate() {
        for (l, &pl) in idx.iter().enumerate() {
            let blk = &hb[j][l];
            for r in 0..3 {
                for s in 0..3 {
                    out[3 * pj + r][3 * pl + s] += blk[(r, s)];
                }
            }
        }
    }
}

/// Add ω ∇²κ of one hinge (κ = θ h) to the stencil Hessian.
fn add_hinge_hessian(hg: &Hinge, omega: f64, idx: [usize; 4], out: &mut [[f64; NDOF]; NDOF]) {
    let mut hb = [[M3::zeros(); 4]; 4];
    add_theta_hessian(hg, hg.h * omega, &mut hb);
    // θ ∇²h in (e, a), mapped to (p₀, p₁, p₂)
    {
        let (e, a) = (&hg.e, &hg.a);
        let n = e.cross(a);
        let nn = n.norm();
        let nh = n / nn;
        let le = e.norm();
        let inv = 1.0 / le;
        // ∇N and ∇²N, N = ‖e × a‖
        let dne = a.cross(&nh);
        let dna = nh.cross(e);
        let jne = -skew(a);
        let jna = skew(e);
        let pn = (M3::identity() - nh * nh.transpose()) / nn;
        let nee = jne.transpose() * pn * jne;
        let naa = jna.transpose() * pn * jna;
        let nea = jne.transpose() * pn * jna - skew(&nh);
        // M = 1/‖e‖: ∇M = −e/‖e‖³, ∇²M = (3 êêᵀ − I)/‖e‖³
        let dm = -e * (inv * inv * inv);
        let mee = (e * e.transpose() * (3.0 * inv * inv) - M3::identity()) * (inv * inv * inv);
        let hee = nee * inv + mee * nn + dne * dm.transpose() + dm * dne.transpose();
        let hea = nea * inv + dm * dna.transpose();
        let haa = naa * inv;
        let s = hg.theta * omega;
        let (hee, hea, haa) = (hee * s, hea * s, haa * s);
        let hae = hea.transpose();
        // p₁ ↔ e, p₂ ↔ a, p₀ ↔ −e − a
        hb[1][1] += hee;
        hb[1][2] += hea;
        hb[2][1] += hae;
        hb[2][2] += haa;
        let r0e = -hee - hae; // row p₀ against e
        let r0a = -hea - haa;
        hb[0][1] += r0e;
        hb[0][2] += r0a;
        hb[1][0] += r0e.transpose();
        hb[2][0] += r0a.transpose();
        hb[0][0] += hee + hea + hae + haa;
    }
    // ∇θ ∇hᵀ + ∇h ∇θᵀ
    for j in 0..4 {
        for l in 0..3 {
            let m = hg.dtheta[j] * hg.dh[l].transpose() * omega;
            hb[j][l] += m;
            hb[l][j] += m.transpose();
        }
    }
    scatter(&hb, idx, out);
}

/// Generic reference twin of z(q), written from the definitions of `docs/cloth-simulator.md` (absolute difference vectors,
/// atan2 for the angles).
pub fn strain_reference<D: Real>(q: &[D], rest: &RestTriangle, flaps: [bool; 3]) -> [D; 6] {
    let x: [V3r<D>; 6] = std::array::from_fn(|v| real::v3(&q[3 * v..]));
    let (d1, d2) = (real::sub(&x[1], &x[0]), real::sub(&x[2], &x[0]));
    let d = &rest.inv_dm;
    let col = |c: usize| [0, 1, 2].map(|k| d1[k].clone() * d[0][c] + d2[k].clone() * d[1][c]);
    let (f0, f1) = (col(0), col(1));
    let (l0, l1) = (real::norm(&f0), real::norm(&f1));
    let sa = real::dot(&f0, &f1) / (l0.clone() * l1.clone());
    let n0_len = real::norm(&real::cross(&d1, &d2));
    let r = rest.r();
    let mut ii = [D::from(0.0), D::from(0.0), D::from(0.0)];
    for (i, angle) in hinge_angles_reference(q, flaps).into_iter().enumerate() {
        let Some(theta) = angle else {
            continue;
        };
        let kappa = theta * n0_len.clone() / real::norm(&real::sub(&x[(i + 1) % 3], &x[i]));
        ii[0] += kappa.clone() * (r[i][0] * r[i][0]);
        ii[1] += kappa.clone() * (r[i][0] * r[i][1]);
        ii[2] += kappa * (r[i][1] * r[i][1]);
    }
    let [i00, i01, i11] = ii;
    [l0 - 1.0, sa, l1 - 1.0, i00, i01, i11]
}

/// Generic reference twin of the hinge angles θ_i = −atan2(ê_i·(n₀×n_i), n₀·n_i) of a stencil (`None` without
/// the flap).
pub fn hinge_angles_reference<D: Real>(q: &[D], flaps: [bool; 3]) -> [Option<D>; 3] {
    let x: [V3r<D>; 6] = std::array::from_fn(|v| real::v3(&q[3 * v..]));
    let n0 = real::cross(&real::sub(&x[1], &x[0]), &real::sub(&x[2], &x[0]));
    std::array::from_fn(|i| {
        flaps[i].then(|| {
            let e = real::sub(&x[(i + 1) % 3], &x[i]);
            let ni = real::cross(&real::sub(&x[3 + i], &x[i]), &e);
            let y = real::dot(&e, &real::cross(&n0, &ni)) / real::norm(&e);
            -y.atan2(real::dot(&n0, &ni))
        })
    })
}
