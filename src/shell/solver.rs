//! The cloth solver (`05-macro.md`, "The cloth solver"): implicit Euler as minimisation of the incremental
//! potential, and a quasi-static mode.
//!
//! Per step, with x̃ = xₙ + h vₙ, the free dofs minimise
//! Φ(x) = ½‖x − x̃‖²_M / h² + (c/2h)‖x − xₙ‖²_M + E(x) − Σ m_v g·x_v + E_obst(x)
//! (c the linear drag rate, 1/s: implicit drag force −c m v); quasi-static mode minimises E − Σ m g·x + E_obst.
//! Newton's method with a backtracking (Armijo) line search on Φ; converged when the largest residual force on
//! a free vertex, ‖∂Φ/∂x_v‖, is below the force tolerance. The sparse Hessian (free dofs only, the lower triangle
//! in the pattern of [`assemble`](super::assemble)) is factorised by faer's sparse Cholesky with the symbolic
//! analysis computed once per simulation. With `exact_first` (default) the exact Hessian is factorised first and
//! the PSD option's Hessian (`05-macro.md`, options (a)–(c)) used only when that fails (not positive definite):
//! projected Newton far from the solution, Newton's quadratic convergence near it. If the numeric factorisation
//! of the projected Hessian fails (an indefinite matrix, possible with [`Psd::None`](super::Psd) or in
//! quasi-static mode) a diagonal shift μ I is added and increased tenfold until it succeeds.
//!
//! Boundary conditions by dof elimination: pinned vertices keep their initial positions; handle vertices follow
//! keyframed translations (piecewise linear in time, held after the last key). The reaction force of a handle is
//! the force it exerts on the cloth, Σ over its vertices of m a + ∇E − m g − f_obst (quasi-static: ∇E − m g −
//! f_obst).
//!
//! Obstacles (spheres, planes): per vertex a smooth one-sided penalty E = m_v k p³/3 on the penetration
//! p = δ − d > 0 into the layer of thickness δ around the surface (d the signed distance); C² at p = 0. Its
//! Hessian keeps the PSD part 2 m k p n̂n̂ᵀ (the sphere's curvature term is negative and dropped).

use super::assemble::{assemble, energy, gather, Assembled, Pattern};
use super::element::ElementModel;
use super::mesh::Stencil;
use super::ShellError;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::SparseColMatRef;
use faer::Side;
use rayon::prelude::*;
use std::time::Instant;

/// A rigid obstacle.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Obstacle {
    Sphere { center: [f64; 3], radius: f64 },
    Plane { point: [f64; 3], normal: [f64; 3] },
}

impl Obstacle {
    /// Signed distance and outward unit normal at p.
    fn distance(&self, p: [f64; 3]) -> (f64, [f64; 3]) {
        match self {
            Obstacle::Sphere { center, radius } => {
                let d = [p[0] - center[0], p[1] - center[1], p[2] - center[2]];
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if r > 0.0 {
                    (r - radius, d.map(|x| x / r))
                } else {
                    (-radius, [0.0, 0.0, 1.0])
                }
            }
            Obstacle::Plane { point, normal } => {
                let l =
                    (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
                let n = normal.map(|x| x / l);
                let d = (0..3).map(|k| (p[k] - point[k]) * n[k]).sum();
                (d, n)
            }
        }
    }
}

/// A set of vertices following keyframed translations.
#[derive(Clone, Debug)]
pub struct Handle {
    pub name: String,
    pub vertices: Vec<usize>,
    /// (time, translation from the initial positions), increasing times
    pub keyframes: Vec<(f64, [f64; 3])>,
}

impl Handle {
    /// Translation at time t (piecewise linear; constant before the first and after the last key).
    pub fn offset(&self, t: f64) -> [f64; 3] {
        let k = &self.keyframes;
        if k.is_empty() {
            return [0.0; 3];
        }
        if t <= k[0].0 {
            return k[0].1;
        }
        for w in k.windows(2) {
            if t <= w[1].0 {
                let s = (t - w[0].0) / (w[1].0 - w[0].0);
                return std::array::from_fn(|c| w[0].1[c] + s * (w[1].1[c] - w[0].1[c]));
            }
        }
        k[k.len() - 1].1
    }
}

/// Boundary conditions and obstacles of a simulation.
#[derive(Clone, Debug, Default)]
pub struct Boundary {
    /// vertices held at their initial positions
    pub pinned: Vec<usize>,
    pub handles: Vec<Handle>,
    pub obstacles: Vec<Obstacle>,
}

/// Solver settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// time step h (s)
    pub dt: f64,
    /// minimise E − f·x per step instead of the incremental potential
    pub quasi_static: bool,
    /// convergence: largest residual force on a free vertex (N)
    pub force_tol: f64,
    /// Newton iterations per step at most
    pub max_newton: usize,
    /// try the exact Hessian first and fall back to the PSD option's Hessian only when its factorisation fails
    pub exact_first: bool,
    pub gravity: [f64; 3],
    /// linear drag rate c (1/s)
    pub drag: f64,
    /// obstacle layer thickness δ (m)
    pub thickness: f64,
    /// obstacle penalty k (1/(m·s²)): E = m k p³/3
    pub contact_stiffness: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            dt: 1.0 / 60.0,
            quasi_static: false,
            force_tol: 1e-6,
            max_newton: 50,
            exact_first: true,
            gravity: [0.0, 0.0, -9.81],
            drag: 0.0,
            thickness: 0.002,
            contact_stiffness: 1e8,
        }
    }
}

/// What one step did (the JSON-lines log entry).
#[derive(Clone, Debug, serde::Serialize)]
pub struct StepReport {
    pub step: usize,
    pub time: f64,
    pub newton: usize,
    /// largest residual force on a free vertex at the end (N)
    pub residual: f64,
    pub converged: bool,
    pub energy_elastic: f64,
    pub energy_kinetic: f64,
    /// potential energy of gravity relative to the initial state
    pub energy_gravity: f64,
    pub energy_obstacles: f64,
    /// (name, force the handle exerts on the cloth, N)
    pub handle_forces: Vec<(String, [f64; 3])>,
    /// the largest diagonal shift the factorisation needed (0: none)
    pub shift: f64,
    /// wall time of the step (s)
    pub wall: f64,
    pub strain_min: [f64; 6],
    pub strain_max: [f64; 6],
    /// componentwise 1st and 99th percentiles of z over the triangles (what most of the cloth visits, without
    /// the few triangles of a mesh-scale crease; `hylc scene-plan --quantile`)
    pub strain_p01: [f64; 6],
    pub strain_p99: [f64; 6],
}

/// Componentwise quantile q ∈ [0, 1] of per-triangle strains (nearest rank; 0 for an empty mesh).
pub fn strain_quantile(z: &[[f64; 6]], q: f64) -> [f64; 6] {
    let mut out = [0.0; 6];
    if z.is_empty() {
        return out;
    }
    let mut col: Vec<f64> = Vec::with_capacity(z.len());
    for (k, o) in out.iter_mut().enumerate() {
        col.clear();
        col.extend(z.iter().map(|v| v[k]));
        let i = ((q.clamp(0.0, 1.0) * (col.len() - 1) as f64).round()) as usize;
        let (_, v, _) = col.select_nth_unstable_by(i, |a, b| a.total_cmp(b));
        *o = *v;
    }
    out
}

/// An error when a quantity of step `step` (ending at `time`) is not finite: the run diverged
/// ([`ShellError::NonFiniteState`]); a finite state is never reported as a result.
fn check_finite(
    step: usize,
    time: f64,
    quantity: &'static str,
    value: f64,
) -> Result<(), ShellError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ShellError::NonFiniteState {
            step,
            time,
            quantity,
            value,
        })
    }
}

/// When the elastic energy at `x` is undefined, tell a material that does not evaluate to a finite energy at a
/// triangle's strain apart from a degenerate triangle: the first triangle whose strain is defined but whose
/// energy is not, as [`ShellError::NonFiniteMaterial`] (`None` when every such triangle is degenerate). Only
/// called on the error path.
fn non_finite_material(
    model: &ElementModel,
    stencils: &[Stencil],
    x: &[f64],
    step: Option<usize>,
) -> Option<ShellError> {
    stencils.iter().enumerate().find_map(|(t, s)| {
        let q = gather(s, x);
        let z = model
            .strain(&q, &s.rest, s.flaps)
            .filter(|z| z.iter().all(|v| v.is_finite()))?;
        model
            .energy(&q, &s.rest, s.flaps)
            .is_none()
            .then_some(ShellError::NonFiniteMaterial {
                triangle: t,
                z,
                step,
            })
    })
}

/// A running simulation.
pub struct Simulation {
    pub model: ElementModel,
    pub stencils: Vec<Stencil>,
    pub pattern: Pattern,
    symbolic: SymbolicLlt<usize>,
    pub x0: Vec<f64>,
    pub x: Vec<f64>,
    pub v: Vec<f64>,
    /// lumped vertex masses (kg)
    pub mass: Vec<f64>,
    pub pinned: Vec<usize>,
    pub handles: Vec<Handle>,
    pub obstacles: Vec<Obstacle>,
    pub settings: Settings,
    pub time: f64,
    pub steps: usize,
}

/// Per-step constants of the potential.
struct Target {
    xt: Vec<f64>,
    xn: Vec<f64>,
}

/// Where the Newton iterations of a step ended.
struct Minimum {
    x: Vec<f64>,
    /// Newton iterations taken
    newton: usize,
    /// largest residual force on a free vertex at x (N)
    residual: f64,
    converged: bool,
    /// the largest diagonal shift a factorisation needed
    max_shift: f64,
    /// the assembly and the full gradient of Φ at x
    asm: Assembled,
    g_full: Vec<f64>,
}

impl Simulation {
    /// Set up a simulation: `x0` the initial positions (3 per vertex), `mass_multiplier` scales the lumped mass
    /// from the material density.
    pub fn new(
        model: ElementModel,
        stencils: Vec<Stencil>,
        x0: Vec<[f64; 3]>,
        boundary: Boundary,
        settings: Settings,
        mass_multiplier: f64,
    ) -> Result<Simulation, ShellError> {
        let Boundary {
            pinned,
            handles,
            obstacles,
        } = boundary;
        let n = x0.len();
        if !(settings.dt > 0.0 && settings.dt.is_finite()) {
            return Err(ShellError::TimeStep { dt: settings.dt });
        }
        let mut constrained = vec![false; n];
        for &v in pinned
            .iter()
            .chain(handles.iter().flat_map(|h| h.vertices.iter()))
        {
            if v >= n {
                return Err(ShellError::VertexOutOfRange {
                    vertex: v,
                    vertices: n,
                });
            }
            constrained[v] = true;
        }
        let mut mass = vec![0.0; n];
        let rho = model.material.density * mass_multiplier;
        for s in &stencils {
            for a in 0..3 {
                mass[s.v[a]] += rho * s.rest.area / 3.0;
            }
        }
        if !settings.quasi_static && mass.iter().any(|&m| m.is_nan() || m <= 0.0) {
            return Err(ShellError::Mass);
        }
        let pattern = Pattern::new(&stencils, n, &constrained);
        let symbolic = SymbolicLlt::try_new(pattern.lower.symbolic(), Side::Lower)
            .map_err(|source| ShellError::Symbolic { source })?;
        let x: Vec<f64> = x0.iter().flatten().copied().collect();
        if energy(&model, &stencils, &x).is_none() {
            return Err(non_finite_material(&model, &stencils, &x, None)
                .unwrap_or(ShellError::DegenerateInitial));
        }
        Ok(Simulation {
            model,
            stencils,
            pattern,
            symbolic,
            x0: x.clone(),
            v: vec![0.0; x.len()],
            x,
            mass,
            pinned,
            handles,
            obstacles,
            settings,
            time: 0.0,
            steps: 0,
        })
    }

    /// Positions as 3-vectors.
    pub fn positions(&self) -> Vec<[f64; 3]> {
        self.x.chunks(3).map(|p| [p[0], p[1], p[2]]).collect()
    }

    /// Obstacle energy, gradient and Hessian block of one vertex.
    fn obstacle_terms(&self, v: usize, p: [f64; 3]) -> (f64, [f64; 3], [[f64; 3]; 3]) {
        let mut e = 0.0;
        let mut g = [0.0; 3];
        let mut h = [[0.0; 3]; 3];
        let s = &self.settings;
        for o in &self.obstacles {
            let (d, n) = o.distance(p);
            let pen = s.thickness - d;
            if pen > 0.0 {
                let k = self.mass[v] * s.contact_stiffness;
                e += k * pen * pen * pen / 3.0;
                for a in 0..3 {
                    g[a] -= k * pen * pen * n[a];
                    for b in 0..3 {
                        h[a][b] += 2.0 * k * pen * n[a] * n[b];
                    }
                }
            }
        }
        (e, g, h)
    }

    /// Φ at x (None if a triangle is degenerate); relative to xₙ for the linear terms.
    fn potential(&self, x: &[f64], tg: &Target) -> Option<f64> {
        let mut phi = energy(&self.model, &self.stencils, x)?;
        phi += self.external(x, tg).0;
        Some(phi)
    }

    /// The non-elastic part of Φ over free vertices: (value, unused).
    fn external(&self, x: &[f64], tg: &Target) -> (f64, ()) {
        let s = &self.settings;
        let h = s.dt;
        let val: f64 = (0..self.pattern.n)
            .into_par_iter()
            .with_min_len(1024)
            .filter(|&v| self.pattern.free[v].is_some())
            .map(|v| {
                let m = self.mass[v];
                let mut e = 0.0;
                for c in 0..3 {
                    let i = 3 * v + c;
                    let dn = x[i] - tg.xn[i];
                    if !s.quasi_static {
                        let dt = x[i] - tg.xt[i];
                        e += 0.5 * m * dt * dt / (h * h) + 0.5 * s.drag * m * dn * dn / h;
                    }
                    e -= m * s.gravity[c] * dn;
                }
                e + self
                    .obstacle_terms(v, [x[3 * v], x[3 * v + 1], x[3 * v + 2]])
                    .0
            })
            .sum();
        (val, ())
    }

    /// Advance one step: minimise Φ from the start of the step ([`start_of_step`](Self::start_of_step)) by
    /// Newton's method ([`minimise`](Self::minimise)), then take the minimiser as the new state.
    pub fn step(&mut self) -> Result<StepReport, ShellError> {
        let start = Instant::now();
        let h = self.settings.dt;
        let t1 = self.time + h;
        let (tg, x) = self.start_of_step(t1);
        let step = self.steps + 1;
        let phi = match self.potential(&x, &tg) {
            Some(phi) => phi,
            None => {
                return Err(
                    non_finite_material(&self.model, &self.stencils, &x, Some(step))
                        .unwrap_or(ShellError::DegenerateStart { step, time: t1 }),
                )
            }
        };
        let m = self.minimise(x, &tg, phi)?;
        check_finite(step, t1, "largest residual force", m.residual)?;
        check_finite(step, t1, "elastic energy", m.asm.energy)?;
        // reactions: the full gradient of Φ at the handle vertices (`asm` and `g_full` are evaluated at x,
        // except after a failed line search, where x did not change either)
        let handle_forces = self.handle_forces(&m.g_full);
        // update state
        let x = m.x;
        for i in 0..x.len() {
            self.v[i] = if self.settings.quasi_static {
                0.0
            } else {
                (x[i] - tg.xn[i]) / h
            };
        }
        self.x = x;
        self.time = t1;
        self.steps += 1;
        let (ek, eg, eo) = self.energies();
        for (what, v) in [
            ("kinetic energy", ek),
            ("gravitational energy", eg),
            ("obstacle energy", eo),
        ] {
            check_finite(step, t1, what, v)?;
        }
        let asm = m.asm;
        Ok(StepReport {
            step: self.steps,
            time: self.time,
            newton: m.newton,
            residual: m.residual,
            converged: m.converged,
            energy_elastic: asm.energy,
            energy_kinetic: ek,
            energy_gravity: eg,
            energy_obstacles: eo,
            handle_forces,
            shift: m.max_shift,
            wall: start.elapsed().as_secs_f64(),
            strain_min: asm.zmin,
            strain_max: asm.zmax,
            strain_p01: strain_quantile(&asm.z, 0.01),
            strain_p99: strain_quantile(&asm.z, 0.99),
        })
    }

    /// The constants of the step ending at `t1` (x̃ = xₙ + h vₙ, xₙ) and the starting point of its minimisation:
    /// pinned and handle vertices at their prescribed positions, the free ones at the inertial prediction x̃ when Φ
    /// is defined there, else at xₙ (always xₙ in quasi-static mode).
    fn start_of_step(&self, t1: f64) -> (Target, Vec<f64>) {
        let s = &self.settings;
        let h = s.dt;
        let n = self.pattern.n;
        let xn = self.x.clone();
        let mut xt = xn.clone();
        if !s.quasi_static {
            for i in 0..xt.len() {
                xt[i] += h * self.v[i];
            }
        }
        // prescribed positions
        let mut x = xn.clone();
        for &v in &self.pinned {
            for c in 0..3 {
                x[3 * v + c] = self.x0[3 * v + c];
            }
        }
        for hd in &self.handles {
            let o = hd.offset(t1);
            for &v in &hd.vertices {
                for c in 0..3 {
                    x[3 * v + c] = self.x0[3 * v + c] + o[c];
                }
            }
        }
        let tg = Target {
            xt: xt.clone(),
            xn: xn.clone(),
        };
        // initial guess: the inertial prediction when it is valid, else the previous positions
        if !s.quasi_static {
            let mut guess = x.clone();
            for v in 0..n {
                if self.pattern.free[v].is_some() {
                    for c in 0..3 {
                        guess[3 * v + c] = xt[3 * v + c];
                    }
                }
            }
            if self.potential(&guess, &tg).is_some() {
                x = guess;
            }
        }
        (tg, x)
    }

    /// Newton's method on Φ from `x` (where Φ = `phi`): converged when the largest residual force on a free
    /// vertex is below the tolerance (or there is no free vertex); stops unconverged after `max_newton`
    /// iterations or when the line search finds no decrease.
    fn minimise(&self, mut x: Vec<f64>, tg: &Target, mut phi: f64) -> Result<Minimum, ShellError> {
        let s = &self.settings;
        let nf = 3 * self.pattern.nfree;
        let mut newton = 0;
        let mut max_shift: f64 = 0.0;
        loop {
            let (asm, g_full) = self.gradient_hessian(&x, tg)?;
            let (gf, residual) = self.free_gradient(&g_full);
            let converged = residual <= s.force_tol || nf == 0;
            let mut step = None;
            if !converged && newton < s.max_newton {
                newton += 1;
                let (d, shift) = self.solve(&asm.values, &asm.values_exact, &gf)?;
                max_shift = max_shift.max(shift);
                let slope: f64 = gf.iter().zip(&d).map(|(a, b)| a * b).sum();
                step = self.line_search(&x, &d, slope, phi, tg);
            }
            match step {
                Some((xtry, p)) => {
                    x = xtry;
                    phi = p;
                }
                None => {
                    return Ok(Minimum {
                        x,
                        newton,
                        residual,
                        converged,
                        max_shift,
                        asm,
                        g_full,
                    })
                }
            }
        }
    }

    /// The gradient of Φ over the free dofs (free index order) and the largest residual force ‖∂Φ/∂x_v‖ on a free
    /// vertex.
    fn free_gradient(&self, g_full: &[f64]) -> (Vec<f64>, f64) {
        let mut gf = vec![0.0; 3 * self.pattern.nfree];
        let mut residual = 0.0f64;
        for v in 0..self.pattern.n {
            if let Some(k) = self.pattern.free[v] {
                let f2: f64 = (0..3).map(|c| g_full[3 * v + c].powi(2)).sum();
                residual = residual.max(f2.sqrt());
                for c in 0..3 {
                    gf[3 * k + c] = g_full[3 * v + c];
                }
            }
        }
        (gf, residual)
    }

    /// Backtracking (Armijo) line search on Φ from `x` along the free-dof direction `d` with slope gᵀd: steps
    /// α = 1, ½, … down to 1e-12. Returns the accepted point and its Φ.
    fn line_search(
        &self,
        x: &[f64],
        d: &[f64],
        slope: f64,
        phi: f64,
        tg: &Target,
    ) -> Option<(Vec<f64>, f64)> {
        let mut alpha = 1.0;
        let mut xtry = x.to_vec();
        while alpha > 1e-12 {
            for v in 0..self.pattern.n {
                if let Some(k) = self.pattern.free[v] {
                    for c in 0..3 {
                        xtry[3 * v + c] = x[3 * v + c] + alpha * d[3 * k + c];
                    }
                }
            }
            if let Some(p) = self.potential(&xtry, tg) {
                // Armijo, with an allowance for round-off in Φ near convergence
                if p <= phi + 1e-4 * alpha * slope + 1e-13 * phi.abs() {
                    return Some((xtry, p));
                }
            }
            alpha *= 0.5;
        }
        None
    }

    /// The force each handle exerts on the cloth: the sum of the full gradient of Φ over its vertices.
    fn handle_forces(&self, g_full: &[f64]) -> Vec<(String, [f64; 3])> {
        self.handles
            .iter()
            .map(|hd| {
                let mut f = [0.0; 3];
                for &v in &hd.vertices {
                    for c in 0..3 {
                        f[c] += g_full[3 * v + c];
                    }
                }
                (hd.name.clone(), f)
            })
            .collect()
    }

    /// Kinetic energy, gravitational potential energy relative to the initial state and obstacle energy of the
    /// current state.
    fn energies(&self) -> (f64, f64, f64) {
        let s = &self.settings;
        let mut ek = 0.0;
        let mut eg = 0.0;
        let mut eo = 0.0;
        for v in 0..self.pattern.n {
            let m = self.mass[v];
            let p = [self.x[3 * v], self.x[3 * v + 1], self.x[3 * v + 2]];
            for c in 0..3 {
                ek += 0.5 * m * self.v[3 * v + c].powi(2);
                eg -= m * s.gravity[c] * (p[c] - self.x0[3 * v + c]);
            }
            eo += self.obstacle_terms(v, p).0;
        }
        (ek, eg, eo)
    }

    /// The first Newton direction of the next step at the current state (assembly, factorisation, solve): one
    /// Newton iteration without the line search, for benchmarks. Returns the direction and the shift used.
    pub fn newton_direction(&self) -> Result<(Vec<f64>, f64), ShellError> {
        let h = self.settings.dt;
        let xt: Vec<f64> = if self.settings.quasi_static {
            self.x.clone()
        } else {
            self.x.iter().zip(&self.v).map(|(x, v)| x + h * v).collect()
        };
        let tg = Target {
            xt,
            xn: self.x.clone(),
        };
        let (asm, g) = self.gradient_hessian(&self.x, &tg)?;
        let mut gf = vec![0.0; 3 * self.pattern.nfree];
        for v in 0..self.pattern.n {
            if let Some(k) = self.pattern.free[v] {
                gf[3 * k..3 * k + 3].copy_from_slice(&g[3 * v..3 * v + 3]);
            }
        }
        self.solve(&asm.values, &asm.values_exact, &gf)
    }

    /// Assembled elastic terms plus the external ones: (assembly with the full Hessian values, full gradient
    /// of Φ including constrained vertices — with their inertia — for the reaction forces).
    fn gradient_hessian(
        &self,
        x: &[f64],
        tg: &Target,
    ) -> Result<(Assembled, Vec<f64>), ShellError> {
        let s = &self.settings;
        let h = s.dt;
        let mut asm = assemble(
            &self.model,
            &self.stencils,
            &self.pattern,
            x,
            true,
            self.exact_first(),
        )
        .ok_or_else(|| {
            let step = self.steps + 1;
            non_finite_material(&self.model, &self.stencils, x, Some(step))
                .unwrap_or(ShellError::Degenerate { step })
        })?;
        let mut g = std::mem::take(&mut asm.grad);
        for v in 0..self.pattern.n {
            let m = self.mass[v];
            let p = [x[3 * v], x[3 * v + 1], x[3 * v + 2]];
            let (_, go, ho) = self.obstacle_terms(v, p);
            let mut blk = ho;
            for c in 0..3 {
                let i = 3 * v + c;
                g[i] += go[c] - m * s.gravity[c];
                if !s.quasi_static {
                    g[i] += m * (x[i] - tg.xt[i]) / (h * h) + s.drag * m * (x[i] - tg.xn[i]) / h;
                    blk[c][c] += m / (h * h) + s.drag * m / h;
                }
            }
            if let Some(k) = self.pattern.free[v] {
                self.pattern.add_diag_block(&mut asm.values, k, &blk);
                if !asm.values_exact.is_empty() {
                    self.pattern.add_diag_block(&mut asm.values_exact, k, &blk);
                }
            }
        }
        Ok((asm, g))
    }

    /// Whether the assembly also produces the exact Hessian (only useful when the PSD option changes it).
    fn exact_first(&self) -> bool {
        self.settings.exact_first && self.model.psd != super::Psd::None
    }

    /// Solve H d = −g with the reused symbolic analysis; returns d and the diagonal shift used. With
    /// `exact` non-empty, the exact Hessian is tried first (Newton's own direction, quadratic convergence near the
    /// solution) and the PSD option's `values` only when the exact one is not positive definite.
    fn solve(
        &self,
        values: &[f64],
        exact: &[f64],
        g: &[f64],
    ) -> Result<(Vec<f64>, f64), ShellError> {
        let nf = g.len();
        if !exact.is_empty() {
            if let Some(d) = self.factor_solve(exact, g) {
                return Ok((d, 0.0));
            }
        }
        let mut shift = 0.0;
        let mean_diag = self
            .pattern
            .lower
            .diag
            .iter()
            .map(|&k| values[k].abs())
            .sum::<f64>()
            / nf as f64;
        let mut vals = values.to_vec();
        for attempt in 0..30 {
            if attempt > 0 {
                let new_shift = if shift == 0.0 {
                    1e-8 * mean_diag.max(1e-300)
                } else {
                    10.0 * shift
                };
                for &k in &self.pattern.lower.diag {
                    vals[k] += new_shift - shift;
                }
                shift = new_shift;
            }
            if let Some(d) = self.factor_solve(&vals, g) {
                return Ok((d, shift));
            }
        }
        Err(ShellError::Factorization {
            step: self.steps + 1,
        })
    }

    /// d = −H⁻¹ g for the free-dof matrix H with the lower-triangle `values` (the pattern's order): the numeric
    /// Cholesky factorisation with the simulation's symbolic analysis, then one solve. `None` when H is not
    /// positive definite or d is not finite.
    fn factor_solve(&self, values: &[f64], g: &[f64]) -> Option<Vec<f64>> {
        let nf = g.len();
        let mat = SparseColMatRef::new(self.pattern.lower.symbolic(), values);
        let llt = Llt::try_new_with_symbolic(self.symbolic.clone(), mat, Side::Lower).ok()?;
        let mut d: Vec<f64> = g.iter().map(|x| -x).collect();
        llt.solve_in_place(faer::MatMut::from_column_major_slice_mut(&mut d, nf, 1));
        d.iter().all(|x| x.is_finite()).then_some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::strain_quantile;

    /// Nearest-rank quantiles per component, independent of the order of the triangles.
    #[test]
    fn strain_quantiles_are_per_component_nearest_rank() {
        let mut z: Vec<[f64; 6]> = (0..101)
            .map(|i| {
                let v = i as f64;
                [v, -v, 2.0 * v, 0.0, 1e3 - v, v * v]
            })
            .collect();
        z.reverse();
        z.swap(3, 70);
        assert_eq!(
            strain_quantile(&z, 0.01),
            [1.0, -99.0, 2.0, 0.0, 901.0, 1.0]
        );
        assert_eq!(
            strain_quantile(&z, 0.99),
            [99.0, -1.0, 198.0, 0.0, 999.0, 9801.0]
        );
        assert_eq!(strain_quantile(&z, 0.0)[0], 0.0);
        assert_eq!(strain_quantile(&z, 1.0)[0], 100.0);
        assert_eq!(strain_quantile(&[], 0.5), [0.0; 6]);
    }
}
