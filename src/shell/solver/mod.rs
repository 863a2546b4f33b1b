//! The cloth solver (`docs/cloth-simulator.md`, "The cloth solver"; docs/cloth-simulator.md): implicit Euler as minimisation of the
//! incremental potential, adaptive substeps, and a quasi-static mode.
//!
//! Per (sub)step of length h, with x̃ = xₙ + h vₙ, the free dofs minimise
//! Φ(x) = ½‖x − x̃‖²_M / h² + (c/2h)‖x − xₙ‖²_M + E(x) − Σ m_v g·x_v + E_obst(x) + D_fric(x)
//!        + Σ_faces (D_damp + Π_drag) + Σ_held ½ k |x_v − p_v(t)|²
//! (c the linear drag rate, 1/s: implicit drag force −c m v; the dissipation terms of [`dissipation`] and the
//! obstacle terms of [`obstacle`] with their geometry lagged at xₙ; the last sum only with handle springs);
//! quasi-static mode minimises E − Σ m g·x + E_obst (+ springs). Newton's method with a backtracking (Armijo)
//! line search on Φ; converged when the largest residual force on a free vertex, ‖∂Φ/∂x_v‖, is below the force
//! tolerance. The sparse Hessian (free dofs only, the lower triangle in the pattern of
//! [`assemble`](super::assemble)) is factorised by faer's sparse Cholesky with the symbolic analysis computed
//! once per simulation ([`linear`]). With `exact_first` (default) the exact Hessian is factorised first and the
//! PSD option's Hessian (`docs/cloth-simulator.md`, options (a)–(c)) used only when that fails (not positive definite):
//! projected Newton far from the solution, Newton's quadratic convergence near it. If the numeric factorisation
//! of the projected Hessian fails (an indefinite matrix, possible with [`Psd::None`](super::Psd) or in
//! quasi-static mode) a diagonal shift μ I is added and increased tenfold until it succeeds.
//!
//! **Adaptive substeps.** A step of length dt that does not converge within `max_newton` iterations (or whose
//! line search stalls, or whose start is degenerate) is retried from its start with h halved, down to
//! dt / 2^`max_halvings`; after two converged substeps in a row h doubles again (never beyond dt, never past
//! the end of the step). A step that fails at the smallest substep ends the run with
//! [`ShellError::StepFailed`].
//!
//! **Integrators.** [`Integrator::ImplicitEuler`] (the default) minimises Φ to the force tolerance in every
//! substep; [`Integrator::Bdf2`] minimises the same potential with BDF2's constants (second order; [`integrator`]
//! gives them and its error estimate). [`Integrator::Linearized`] is the original simulator's (ARCSim's)
//! linearised implicit Euler: exactly one Newton step on Φ with the PSD option's Hessian and no line search, from
//! the inertial prediction x̃ = xₙ + h vₙ, so that every force is linearised about the current velocity vₙ:
//! (M + h(h + c) K)(vₙ₊₁ − vₙ) = h F(x̃, vₙ), the Baraff–Witkin step with the forces evaluated at the predicted
//! position instead of at xₙ (the two differ by O(h²) per substep). Starting from xₙ instead would linearise the
//! velocity-dependent forces about zero velocity: the quadratic air drag would vanish from the step (its gradient
//! and Hessian are zero at zero relative velocity), and on the original's `basket_stretchX` the elastic energy
//! then converged (20, 80 and 320 substeps alike) to a solution 34 % above the implicit-Euler and BDF2 limit at
//! 0.083 s. With `substeps` = ARCSim's `frame_steps` it takes the original's steps; its residual is logged, not
//! driven to zero. `substeps` = k divides every step into k equal substeps before any adaptive halving.
//!
//! **Accuracy.** Every converged substep of a dynamic run estimates its local error (m, the largest over the free
//! vertices; [`integrator`]): for implicit Euler ½ |x − x̃|, the distance between its position and the
//! second-order trapezoidal rule's, h (vₙ₊₁ − vₙ)/2 (exactly h² |g|/2 in free fall); for BDF2 8/23 of the distance
//! to an explicit second-order predictor. The log reports the largest estimate of a step (`error_estimate`). With
//! `time_tol` = τ the substep length is chosen by it: a substep with e > τ is rejected and retried with
//! h · max(0.2, 0.9 (τ/e)^(1/(p+1))) (p the scheme's order; not below dt / 2^`max_halvings`, where it is accepted
//! as it is), an accepted one sets the next h to h · min(2, 0.9 (τ/e)^(1/(p+1))) (at most dt; a substep shortened
//! only to end the step does not shrink it; when less than two substeps are left, the last two share them), and
//! Newton failures halve h as without τ.
//!
//! Boundary conditions: pinned vertices keep their initial positions; handle vertices follow keyframed
//! translations ([`Motion`]: piecewise linear or cubic Hermite in time, held after the last key), evaluated at
//! the end of each substep. By default both are hard constraints (dof elimination); with a handle stiffness k
//! (ARCSim's `handle_stiffness`) every held vertex is instead free and pulled to its target by a spring
//! ½ k |x − p(t)|². Every held set reports its reaction, the force it exerts on the cloth: with hard constraints
//! Σ over its vertices of ∂Φ/∂x_v (inertia, elastic, gravity, obstacle and dissipation terms), with springs
//! Σ k (p_v − x_v); each handle under its name, the pinned vertices together as `pinned`.
//!
//! Obstacles may move ([`Boundary::obstacle_motions`]): obstacle i at time t is its shape translated by
//! oᵢ(t), so its penalty is evaluated at the end of the substep with the shape at oᵢ(t₁) (the closest feature
//! of p − oᵢ found in the shape's own placement, then translated), and lagged friction charges the tangential
//! displacement relative to the obstacle, δ = x − xₙ − (oᵢ(t₁) − oᵢ(tₙ)).

mod adjoint;
mod integrator;
mod linear;
mod ordering;
mod stepping;
mod terms;

pub use stepping::strain_quantile;

pub use adjoint::{HeldGradient, Observable, Sensitivity, Tape, TapeStep};
pub use integrator::{bdf2_coefficients, Integrator};
use integrator::{Anchor, History};
pub use ordering::FillOrdering;

use super::assemble::{energy, gather, Assembled, Pattern};
use super::dissipation::{self, Wind};
use super::element::ElementModel;
use super::mesh::Stencil;
pub use super::motion::Motion;
use super::obstacle::{self, Obstacle, Proximity};
use super::strain::NDOF;
use super::ShellError;
use faer::sparse::linalg::cholesky::SymbolicCholesky;
use terms::Lagged;

/// A named set of vertices following a keyframed translation from their initial positions.
#[derive(Clone, Debug)]
pub struct Handle {
    /// the name its reaction is reported under
    pub name: String,
    /// the vertices it moves
    pub vertices: Vec<usize>,
    /// their translation from the initial positions over time (m)
    pub motion: Motion,
}

impl Handle {
    /// Translation at time t ([`Motion::position`]).
    pub fn offset(&self, t: f64) -> [f64; 3] {
        self.motion.position(t)
    }
}

/// Boundary conditions and obstacles of a simulation.
#[derive(Clone, Debug, Default)]
pub struct Boundary {
    /// vertices held at their initial positions (their reaction is reported as `pinned`)
    pub pinned: Vec<usize>,
    /// vertex sets following keyframed translations
    pub handles: Vec<Handle>,
    /// the obstacles the cloth collides with
    pub obstacles: Vec<Obstacle>,
    /// the translation of each obstacle over time, in the order of `obstacles` (missing ones stay put)
    pub obstacle_motions: Vec<Motion>,
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
    /// gravitational acceleration g (m/s²)
    pub gravity: [f64; 3],
    /// linear drag rate c (1/s)
    pub drag: f64,
    /// obstacle layer thickness δ (m)
    pub thickness: f64,
    /// obstacle penalty k (1/(m·s²)): E = m k p³/3
    pub contact_stiffness: f64,
    /// Coulomb friction coefficient μ against obstacles
    pub friction: f64,
    /// sliding-velocity threshold ε_v of the smoothed friction (m/s)
    pub friction_velocity: f64,
    /// stiffness-proportional damping coefficient c (s)
    pub damping: f64,
    /// air drag
    pub wind: Wind,
    /// `None`: pins and handles are hard constraints; `Some(k)`: springs of stiffness k (N/m) per held vertex
    pub handle_stiffness: Option<f64>,
    /// a step is retried with h halved at most this many times
    pub max_halvings: u32,
    /// `Some(τ)`: substep lengths chosen so that the estimated local error of each substep is at most τ (m)
    /// (module documentation, "Accuracy"); `None`: substeps only shorten when Newton fails
    pub time_tol: Option<f64>,
    /// the scheme of a substep
    pub integrator: Integrator,
    /// every step is divided into this many equal substeps (≥ 1) before any adaptive halving
    pub substeps: u32,
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
            friction: 0.0,
            friction_velocity: 1e-3,
            damping: 0.0,
            wind: Wind::default(),
            handle_stiffness: None,
            max_halvings: 6,
            time_tol: None,
            integrator: Integrator::ImplicitEuler,
            substeps: 1,
        }
    }
}

/// What one step did (the JSON-lines log entry).
#[derive(Clone, Debug, serde::Serialize)]
pub struct StepReport {
    /// the number of the step (1 for the first)
    pub step: usize,
    /// the simulated time at the end of the step (s)
    pub time: f64,
    /// Newton iterations over all substeps
    pub newton: usize,
    /// converged substeps the step took (1: none halved)
    pub substeps: usize,
    /// the smallest substep used (s)
    pub dt_min: f64,
    /// substeps rejected because their estimated error exceeded `time_tol`
    pub rejected: usize,
    /// the largest estimated local error of the step's accepted substeps, maxᵥ ½ |xᵥ − x̃ᵥ| (m; 0 in
    /// quasi-static mode)
    pub error_estimate: f64,
    /// largest residual force on a free vertex at the end (N)
    pub residual: f64,
    /// always true: a substep that does not converge is retried with h halved, and a step that cannot converge
    /// ends the run with [`ShellError::StepFailed`] instead of a report (kept in the log for the tools that read
    /// it)
    pub converged: bool,
    /// elastic energy E(x) = Σ_triangles k A ψ(z) (barriers included) at the end of the step (J)
    pub energy_elastic: f64,
    /// kinetic energy ½ Σ m_v |v_v|² at the end of the step (J)
    pub energy_kinetic: f64,
    /// potential energy of gravity relative to the initial state
    pub energy_gravity: f64,
    /// obstacle penalty energy E_obst at the end of the step (J)
    pub energy_obstacles: f64,
    /// (name, force the held set exerts on the cloth, N) for every handle, then `pinned` (scenes hold their
    /// pins as fixed handles named `pin0`, `pin1`, …)
    pub handle_forces: Vec<(String, [f64; 3])>,
    /// the largest diagonal shift the factorisation needed (0: none)
    pub shift: f64,
    /// wall time of the step (s)
    pub wall: f64,
    /// componentwise minimum of the strain z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁) over the triangles
    pub strain_min: [f64; 6],
    /// componentwise maximum of z over the triangles
    pub strain_max: [f64; 6],
    /// componentwise 1st and 99th percentiles of z over the triangles (what most of the cloth visits, without
    /// the few triangles of a mesh-scale crease; `hylc scene-plan --quantile`)
    pub strain_p01: [f64; 6],
    /// componentwise 99th percentile of z over the triangles
    pub strain_p99: [f64; 6],
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
    /// the per-triangle model (reduced material, multipliers, PSD option)
    pub model: ElementModel,
    /// the triangles with their rest shapes and hinge neighbours
    pub stencils: Vec<Stencil>,
    /// the sparsity pattern of the free-dof Hessian and the stencils' scatter maps
    pub pattern: Pattern,
    symbolic: SymbolicCholesky<usize>,
    /// the Cholesky factor's values and faer's workspace, kept from one factorisation to the next
    factor_scratch: std::sync::Mutex<(Vec<f64>, faer::dyn_stack::MemBuffer)>,
    /// initial positions, 3 per vertex (m)
    pub x0: Vec<f64>,
    /// current positions, 3 per vertex (m)
    pub x: Vec<f64>,
    /// current velocities, 3 per vertex (m/s)
    pub v: Vec<f64>,
    /// lumped vertex masses (kg)
    pub mass: Vec<f64>,
    /// vertices held at their initial positions
    pub pinned: Vec<usize>,
    /// vertex sets following keyframed translations
    pub handles: Vec<Handle>,
    /// the obstacles
    pub obstacles: Vec<Obstacle>,
    /// one per obstacle
    pub obstacle_motions: Vec<Motion>,
    /// the solver settings
    pub settings: Settings,
    /// the simulated time (s)
    pub time: f64,
    /// steps taken so far
    pub steps: usize,
    /// current substep level: h = dt / 2^level
    level: u32,
    /// converged substeps in a row at the current level
    streak: u32,
    /// the next substep length under `time_tol` (s)
    h_next: f64,
    /// the start of the previous accepted substep (BDF2 only)
    history: Option<History>,
    /// the local PSD Hessians at the state `.0` (the last converged assembly), which the next substep's damping
    /// reuses instead of assembling them again
    damping_cache: Option<DampingCache>,
    /// the states of the run for its adjoint, when recorded ([`Simulation::start_tape`])
    tape: Option<Tape>,
}

/// The state and the local PSD Hessians assembled there.
type DampingCache = (Vec<f64>, std::sync::Arc<Vec<[[f64; NDOF]; NDOF]>>);

/// Per-substep constants of the potential ([`integrator`]'s scheme constants).
struct Target {
    /// the effective step ĥ of the inertia and dissipation terms (the substep length for implicit Euler)
    h: f64,
    /// the substep length (s)
    step: f64,
    /// the time at the end of the substep, t₁ = tₙ + h
    time: f64,
    /// the inertial target x̂
    xt: Vec<f64>,
    /// the velocity anchor x_b: v = (x − x_b)/ĥ (xₙ for implicit Euler)
    xn: Vec<f64>,
    /// BDF2's predictor (its error estimate)
    xp: Option<Vec<f64>>,
    /// the order of the substep's scheme (its error is O(h^(order + 1)))
    order: i32,
    /// spring targets of the held vertices (vertex, position) when handles are springs
    springs: Vec<(usize, [f64; 3])>,
    /// geometry and forces frozen at xₙ (damping Hessians, drag faces, friction contacts)
    lagged: Lagged,
}

/// Where the Newton iterations of a substep ended.
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

/// A substep's outcome: its minimum and constants, or why it must be retried with a smaller h.
enum Substep {
    Done(Box<(Minimum, Target)>),
    Retry {
        error: Option<ShellError>,
        residual: f64,
        newton: usize,
    },
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
            mut obstacle_motions,
        } = boundary;
        let n = x0.len();
        if obstacle_motions.len() > obstacles.len() {
            return Err(ShellError::ObstacleMotions {
                motions: obstacle_motions.len(),
                obstacles: obstacles.len(),
            });
        }
        obstacle_motions.resize(obstacles.len(), Motion::fixed());
        if !(settings.dt > 0.0 && settings.dt.is_finite()) {
            return Err(ShellError::TimeStep { dt: settings.dt });
        }
        if let Some(tol) = settings.time_tol {
            if !(tol > 0.0 && tol.is_finite()) {
                return Err(ShellError::TimeTolerance { tol });
            }
        }
        if settings.substeps == 0 {
            return Err(ShellError::Substeps);
        }
        let settings_dt = settings.dt / f64::from(settings.substeps);
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
            constrained[v] = settings.handle_stiffness.is_none();
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
        let x: Vec<f64> = x0.iter().flatten().copied().collect();
        let symbolic = linear::symbolic_analysis(&pattern, &x, FillOrdering::default())?;
        if energy(&model, &stencils, &x).is_none() {
            return Err(non_finite_material(&model, &stencils, &x, None)
                .unwrap_or(ShellError::DegenerateInitial));
        }
        Ok(Simulation {
            model,
            stencils,
            pattern,
            symbolic,
            factor_scratch: std::sync::Mutex::new((
                vec![],
                faer::dyn_stack::MemBuffer::new(Default::default()),
            )),
            x0: x.clone(),
            v: vec![0.0; x.len()],
            x,
            mass,
            pinned,
            handles,
            obstacles,
            obstacle_motions,
            settings,
            time: 0.0,
            steps: 0,
            level: 0,
            streak: 0,
            h_next: settings_dt,
            history: None,
            damping_cache: None,
            tape: None,
        })
    }

    /// Positions as 3-vectors.
    pub fn positions(&self) -> Vec<[f64; 3]> {
        self.x.chunks(3).map(|p| [p[0], p[1], p[2]]).collect()
    }

    /// The proximity of `p` to obstacle i placed as at time t.
    fn obstacle_proximity(&self, i: usize, p: [f64; 3], t: f64) -> Proximity {
        let o = self.obstacle_motions[i].position(t);
        let shape = &self.obstacles[i];
        if o == [0.0; 3] {
            return shape.proximity(p);
        }
        let local = std::array::from_fn(|c| p[c] - o[c]);
        shape.feature(local).translated(o).proximity(p)
    }

    /// Triangle meshes of the obstacles' surfaces placed as at the current time, for pictures (planes have
    /// none).
    pub fn obstacle_surfaces(&self) -> Vec<super::mesh::Surface> {
        self.obstacles
            .iter()
            .zip(&self.obstacle_motions)
            .filter_map(|(o, m)| {
                let (x, t) = o.surface()?;
                let d = m.position(self.time);
                Some((
                    x.iter()
                        .map(|p| std::array::from_fn(|c| p[c] + d[c]))
                        .collect(),
                    t,
                ))
            })
            .collect()
    }

    /// Obstacle penalty energy, gradient and (PSD) Hessian block of one vertex at p, obstacles as at time t.
    fn obstacle_terms(&self, v: usize, p: [f64; 3], t: f64) -> (f64, [f64; 3], [[f64; 3]; 3]) {
        let mut e = 0.0;
        let mut g = [0.0; 3];
        let mut h = [[0.0; 3]; 3];
        let s = &self.settings;
        for i in 0..self.obstacles.len() {
            let (eo, go, ho) = obstacle::penalty(
                &self.obstacle_proximity(i, p, t),
                self.mass[v],
                s.contact_stiffness,
                s.thickness,
            );
            e += eo;
            for a in 0..3 {
                g[a] += go[a];
                for b in 0..3 {
                    h[a][b] += ho[a][b];
                }
            }
        }
        (e, g, h)
    }

    /// Φ at x (None if a triangle is degenerate); relative to xₙ for the linear terms.
    fn potential(&self, x: &[f64], tg: &Target) -> Option<f64> {
        let mut phi = energy(&self.model, &self.stencils, x)?;
        phi += self.external_value(x, tg);
        Some(phi)
    }

    /// One substep of length h from the current state (not yet accepted). Errors a smaller h may cure
    /// (degenerate start or iterate, failed factorisation, non-finite values) and unconverged Newton iterations
    /// ask for a retry; others end the run.
    fn substep(&self, h: f64, step: usize) -> Result<Substep, ShellError> {
        let retry = |e: ShellError| match e {
            ShellError::DegenerateStart { .. }
            | ShellError::Degenerate { .. }
            | ShellError::Factorization { .. }
            | ShellError::NonFiniteState { .. } => Ok(Substep::Retry {
                error: Some(e),
                residual: f64::NAN,
                newton: 0,
            }),
            e => Err(e),
        };
        let t1 = self.time + h;
        let (tg, x) = match self.start_of_step(t1, h) {
            Ok(v) => v,
            Err(e) => return retry(e),
        };
        let phi = match self.potential(&x, &tg) {
            Some(phi) => phi,
            None => {
                return retry(
                    non_finite_material(&self.model, &self.stencils, &x, Some(step))
                        .unwrap_or(ShellError::DegenerateStart { step, time: t1 }),
                )
            }
        };
        let m = match self.settings.integrator {
            Integrator::ImplicitEuler | Integrator::Bdf2 => self.minimise(x, &tg, phi),
            Integrator::Linearized => self.linearized(x, &tg),
        };
        let m = match m {
            Ok(m) => m,
            Err(e) => return retry(e),
        };
        for (what, v) in [
            ("largest residual force", m.residual),
            ("elastic energy", m.asm.energy),
        ] {
            if let Err(e) = check_finite(step, t1, what, v) {
                return retry(e);
            }
        }
        if !m.converged {
            return Ok(Substep::Retry {
                error: None,
                residual: m.residual,
                newton: m.newton,
            });
        }
        Ok(Substep::Done(Box::new((m, tg))))
    }

    /// Take a substep's minimiser as the new state.
    fn accept(&mut self, m: &Minimum, tg: &Target) {
        let start = (self.settings.integrator == Integrator::Bdf2).then(|| History {
            x: self.x.clone(),
            v: self.v.clone(),
            h: tg.step,
            t: self.time,
        });
        for i in 0..m.x.len() {
            self.v[i] = if self.settings.quasi_static {
                0.0
            } else {
                (m.x[i] - tg.xn[i]) / tg.h
            };
        }
        self.x.clone_from(&m.x);
        self.time += tg.step;
        self.history = start;
        if let Some(tape) = self.tape.as_mut() {
            tape.steps.push(TapeStep {
                h: tg.step,
                time: self.time,
                x: self.x.clone(),
            });
        }
    }

    /// The prescribed position of every held vertex at time t (pins at x0, handles at x0 + offset).
    fn held_targets(&self, t: f64) -> Vec<(usize, [f64; 3])> {
        let at = |v: usize, o: [f64; 3]| (v, std::array::from_fn(|c| self.x0[3 * v + c] + o[c]));
        let mut out: Vec<(usize, [f64; 3])> =
            self.pinned.iter().map(|&v| at(v, [0.0; 3])).collect();
        for hd in &self.handles {
            let o = hd.offset(t);
            out.extend(hd.vertices.iter().map(|&v| at(v, o)));
        }
        out
    }

    /// The constants of the substep ending at `t1` (x̃ = xₙ + h vₙ, xₙ, spring targets, lagged terms) and the
    /// starting point of its minimisation: held vertices at their prescribed positions (hard constraints), the
    /// free ones at the inertial prediction x̃ when Φ is defined there, else at xₙ (always xₙ in quasi-static
    /// mode).
    fn start_of_step(&self, t1: f64, h: f64) -> Result<(Target, Vec<f64>), ShellError> {
        let s = &self.settings;
        let n = self.pattern.n;
        let xn = self.x.clone();
        let anchor = Anchor::new(
            s.integrator,
            s.quasi_static,
            &xn,
            &self.v,
            self.history.as_ref(),
            h,
        );
        // each obstacle's anchor: the same combination of its placements at tₙ and tₙ₋₁
        let (wn, wp) = anchor.weights;
        let t_prev = self.history.as_ref().map_or(self.time, |p| p.t);
        let obstacle_anchors: Vec<[f64; 3]> = self
            .obstacle_motions
            .iter()
            .map(|m| {
                let (a, b) = (m.position(self.time), m.position(t_prev));
                std::array::from_fn(|c| wn * a[c] + wp * b[c])
            })
            .collect();
        let xt = anchor.xt.clone();
        let held = self.held_targets(t1);
        let mut x = xn.clone();
        let springs = if s.handle_stiffness.is_some() {
            held
        } else {
            for &(v, p) in &held {
                x[3 * v..3 * v + 3].copy_from_slice(&p);
            }
            vec![]
        };
        let lagged = self.lagged(&xn, &anchor.xb, anchor.h, t1, &obstacle_anchors)?;
        let order = anchor.order();
        let tg = Target {
            h: anchor.h,
            step: h,
            time: t1,
            xt: anchor.xt,
            xn: anchor.xb,
            xp: anchor.xp,
            order,
            springs,
            lagged,
        };
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
        Ok((tg, x))
    }

    /// ARCSim's linearised implicit Euler (module documentation, "Integrators"): one Newton step on Φ from `x`
    /// (the inertial prediction x̃, held vertices at their targets) with the PSD option's Hessian and no line
    /// search; the result counts as converged, with the residual force it leaves.
    fn linearized(&self, mut x: Vec<f64>, tg: &Target) -> Result<Minimum, ShellError> {
        let (asm, g_full) = self.gradient_hessian(&x, tg)?;
        let (gf, _) = self.free_gradient(&g_full);
        let (d, max_shift) = if gf.is_empty() {
            (vec![], 0.0)
        } else {
            self.solve(&asm.values, &[], &gf)?
        };
        for v in 0..self.pattern.n {
            if let Some(k) = self.pattern.free[v] {
                for c in 0..3 {
                    x[3 * v + c] += d[3 * k + c];
                }
            }
        }
        let (asm, g_full) = self.gradient_hessian(&x, tg)?;
        let (_, residual) = self.free_gradient(&g_full);
        Ok(Minimum {
            x,
            newton: usize::from(!gf.is_empty()),
            residual,
            converged: true,
            max_shift,
            asm,
            g_full,
        })
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

    /// The names of the held sets in the order of [`StepReport::handle_forces`]: the handles, then `pinned`
    /// when there are pinned vertices.
    pub fn held_set_names(&self) -> impl Iterator<Item = &str> {
        self.handles
            .iter()
            .map(|h| h.name.as_str())
            .chain((!self.pinned.is_empty()).then_some("pinned"))
    }

    /// The force each held set exerts on the cloth, each handle under its name and the pinned vertices as
    /// `pinned` (when there are any): with hard constraints the sum of the full gradient of Φ over its
    /// vertices, with springs the sum of the spring forces k (p_v − x_v) at the current state.
    fn handle_forces(&self, g_full: &[f64]) -> Vec<(String, [f64; 3])> {
        let reaction = |vertices: &[usize], o: [f64; 3]| {
            let mut f = [0.0; 3];
            for &v in vertices {
                for c in 0..3 {
                    f[c] += match self.settings.handle_stiffness {
                        None => g_full[3 * v + c],
                        Some(k) => k * (self.x0[3 * v + c] + o[c] - self.x[3 * v + c]),
                    };
                }
            }
            f
        };
        let mut out: Vec<(String, [f64; 3])> = self
            .handles
            .iter()
            .map(|hd| {
                (
                    hd.name.clone(),
                    reaction(&hd.vertices, hd.offset(self.time)),
                )
            })
            .collect();
        if !self.pinned.is_empty() {
            out.push(("pinned".to_string(), reaction(&self.pinned, [0.0; 3])));
        }
        out
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
            eo += self.obstacle_terms(v, p, self.time).0;
        }
        (ek, eg, eo)
    }

    /// The first Newton direction of the next step at the current state (assembly, factorisation, solve): one
    /// Newton iteration without the line search, for benchmarks. Returns the direction and the shift used.
    pub fn newton_direction(&self) -> Result<(Vec<f64>, f64), ShellError> {
        let (asm, gf) = self.newton_system()?;
        self.solve_newton_system(&asm, &gf)
    }

    /// The Newton system of the next step's first iteration at the current state: the assembly (the PSD
    /// option's and, with `exact_first`, the exact Hessian values in the pattern's order) and the gradient over
    /// the free dofs, for benchmarks of [`solve_newton_system`](Self::solve_newton_system).
    pub fn newton_system(&self) -> Result<(Assembled, Vec<f64>), ShellError> {
        let h = self.settings.dt;
        let (tg, _) = self.start_of_step(self.time + h, h)?;
        let (asm, g) = self.gradient_hessian(&self.x, &tg)?;
        let (gf, _) = self.free_gradient(&g);
        Ok((asm, gf))
    }

    /// The direction d = −H⁻¹ g of a Newton system from [`newton_system`](Self::newton_system) (the
    /// factorisations and the solve of one Newton iteration) and the diagonal shift used.
    pub fn solve_newton_system(
        &self,
        asm: &Assembled,
        gf: &[f64],
    ) -> Result<(Vec<f64>, f64), ShellError> {
        self.solve(&asm.values, &asm.values_exact, gf)
    }
}
