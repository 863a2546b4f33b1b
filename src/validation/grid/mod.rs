//! Validation item c (`docs/results.md`, "Validation against the original"): our micro solver against the original
//! solver's equilibrium displacements on the 9×9×9 in-plane strain grid of `../shared/data/hylc2020/displacements/`.
//!
//! Data ([`GridData`]): `axes.txt` lists the nine s_x, s_a and s_y values (one line each); `data.npy` is float32 of
//! shape (n·729, 4) and row isx + 9·isa + 81·isy + 729·v holds, for vertex v, the original displacement
//! (dξ₁, dξ₂, dh) mapped back to reference coordinates and dθ.
//!
//! Our counterpart ([`counterpart`]) at an in-plane strain is (F₂⁻¹ ũ_xy, ũ_z, θ − θ_ref), with F₂ the upper 2×2
//! block of F = [[a, bc], [0, b√(1−c²)]] (`docs/micro-solver.md`, section 1) and ũ the world displacement from
//! φ(ξ_v) + h_v n. Both sides are compared relative to their own z = 0 state.
//!
//! The grid is solved by warm-started continuation ([`run_grid`]): a cold solve at the grid point nearest z = 0,
//! then breadth-first by layers of index distance from it; each point is warm-started from a converged neighbour
//! of the previous layer (the first in the fixed order −s_x, +s_x, −s_a, +s_a, −s_y, +s_y), and retried cold when
//! the warm solve fails (both attempts recorded). The points of one layer are independent, so they run in
//! parallel (rayon) without changing any result: each solve depends only on its strain and its start state.

use crate::micro::solver::{local, world_positions, MicroProblem, MicroState, Status};
use crate::micro::strain::{Family, MacroStrain};
use crate::pattern::Pattern;
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Values per strain axis.
pub const AXIS_LEN: usize = 9;
/// Grid points (9³).
pub const GRID_LEN: usize = AXIS_LEN * AXIS_LEN * AXIS_LEN;

/// The five original grids: (folder under `displacements/`, pattern file under `patterns/`).
pub const ORIGINAL_GRIDS: [(&str, &str); 5] = [
    ("basket", "basket.pyp"),
    ("satin", "satin.pyp"),
    ("honey", "slip_stitch_honeycomb.pyp"),
    ("stock", "stockinette.pyp"),
    ("rib", "cartridge_belt_rib.pyp"),
];

/// Reading the grid data or matching it to a pattern failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GridError {
    /// A file could not be read.
    #[error("{}: {message}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A file was read but its content is not what the format requires.
    #[error("{}: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The data does not fit the pattern (vertex count).
    #[error("{0}")]
    Mismatch(String),
    /// The cold solve at the start point (nearest z = 0) did not converge: nothing to compare against.
    #[error("{0}")]
    StartFailed(String),
}

/// Flat index of grid point (isx, isa, isy).
pub fn grid_index(isx: usize, isa: usize, isy: usize) -> usize {
    isx + AXIS_LEN * isa + AXIS_LEN * AXIS_LEN * isy
}

/// (isx, isa, isy) of a flat grid index.
pub fn grid_coords(g: usize) -> [usize; 3] {
    [
        g % AXIS_LEN,
        (g / AXIS_LEN) % AXIS_LEN,
        g / (AXIS_LEN * AXIS_LEN),
    ]
}

/// Read a float32 `.npy` file holding a C-ordered 2D array with `cols` columns; returns the values (row-major)
/// and the number of rows. Any other dtype, order or shape is an error naming the file.
pub fn read_npy_f32(path: &Path, cols: usize) -> Result<(Vec<f32>, usize), GridError> {
    let io = |m: String| GridError::Io {
        path: path.to_path_buf(),
        message: m,
    };
    let fmt_err = |m: String| GridError::Format {
        path: path.to_path_buf(),
        message: m,
    };
    let file = std::fs::File::open(path).map_err(|e| io(e.to_string()))?;
    let npy = npyz::NpyFile::new(std::io::BufReader::new(file))
        .map_err(|e| fmt_err(format!("not a readable .npy file ({e})")))?;
    let dtype = npy.dtype();
    let is_f32 = matches!(&dtype, npyz::DType::Plain(t) if {
        let s = t.to_string();
        s == "<f4" || s == ">f4"
    });
    if !is_f32 {
        return Err(fmt_err(format!(
            "dtype {} where float32 ('<f4') is expected",
            dtype.descr()
        )));
    }
    if npy.order() != npyz::Order::C {
        return Err(fmt_err(
            "Fortran-ordered array where C order is expected".into(),
        ));
    }
    let shape = npy.shape().to_vec();
    if shape.len() != 2 || shape[1] != cols as u64 {
        return Err(fmt_err(format!(
            "shape {shape:?} where (rows, {cols}) is expected"
        )));
    }
    let rows = usize::try_from(shape[0]).map_err(|_| fmt_err(format!("{} rows", shape[0])))?;
    let values: Vec<f32> = npy
        .into_vec()
        .map_err(|e| fmt_err(format!("reading the data failed ({e})")))?;
    if values.len() != rows * cols {
        return Err(fmt_err(format!(
            "{} values where the shape {shape:?} needs {}",
            values.len(),
            rows * cols
        )));
    }
    Ok((values, rows))
}

/// Read `axes.txt`: three lines of nine numbers (s_x, s_a, s_y), strictly increasing and admissible.
pub fn read_axes(path: &Path) -> Result<[[f64; AXIS_LEN]; 3], GridError> {
    let text = std::fs::read_to_string(path).map_err(|e| GridError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let fmt_err = |m: String| GridError::Format {
        path: path.to_path_buf(),
        message: m,
    };
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    if lines.len() != 3 {
        return Err(fmt_err(format!(
            "{} non-empty lines where 3 (s_x, s_a, s_y) are expected",
            lines.len()
        )));
    }
    let mut axes = [[0.0; AXIS_LEN]; 3];
    for (k, line) in lines.iter().enumerate() {
        let values: Vec<f64> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse::<f64>()
                    .map_err(|_| fmt_err(format!("line {}: cannot parse {s:?}", k + 1)))
            })
            .collect::<Result<_, _>>()?;
        if values.len() != AXIS_LEN {
            return Err(fmt_err(format!(
                "line {}: {} values where {AXIS_LEN} are expected",
                k + 1,
                values.len()
            )));
        }
        if values.iter().any(|v| !v.is_finite()) || values.windows(2).any(|w| w[1] <= w[0]) {
            return Err(fmt_err(format!(
                "line {}: values must be finite and strictly increasing",
                k + 1
            )));
        }
        axes[k].copy_from_slice(&values);
    }
    for g in [
        grid_index(0, 0, 0),
        grid_index(AXIS_LEN - 1, AXIS_LEN - 1, AXIS_LEN - 1),
    ] {
        let [i, j, l] = grid_coords(g);
        let z = MacroStrain::in_plane(axes[0][i], axes[1][j], axes[2][l]);
        z.validate()
            .map_err(|e| fmt_err(format!("grid corner outside the admissible set: {e}")))?;
    }
    Ok(axes)
}

/// The original solver's displacements on one grid.
#[derive(Clone, Debug)]
pub struct GridData {
    /// The nine values of s_x, s_a, s_y.
    pub axes: [[f64; AXIS_LEN]; 3],
    /// Vertices n of the pattern the data belongs to.
    pub n_vertices: usize,
    /// Row-major (n·729, 4).
    values: Vec<f32>,
}

impl GridData {
    /// Load `dir/axes.txt` and `dir/data.npy`.
    pub fn load(dir: &Path) -> Result<Self, GridError> {
        let axes = read_axes(&dir.join("axes.txt"))?;
        let path = dir.join("data.npy");
        let (values, rows) = read_npy_f32(&path, 4)?;
        if rows == 0 || rows % GRID_LEN != 0 {
            return Err(GridError::Format {
                path,
                message: format!(
                    "{rows} rows is not a positive multiple of {GRID_LEN} (vertices × grid points)"
                ),
            });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(GridError::Format {
                path,
                message: format!("non-finite value in row {}", i / 4),
            });
        }
        Ok(GridData {
            axes,
            n_vertices: rows / GRID_LEN,
            values,
        })
    }

    /// Grid data from values in the layout of `data.npy` (row g + 729 v holds vertex v at grid point g), e.g. a
    /// synthetic field for tests; the same shape and finiteness checks as [`GridData::load`], `name` in errors.
    pub fn from_values(
        axes: [[f64; AXIS_LEN]; 3],
        values: Vec<f32>,
        name: &Path,
    ) -> Result<Self, GridError> {
        let rows = values.len() / 4;
        if !values.len().is_multiple_of(4) || rows == 0 || !rows.is_multiple_of(GRID_LEN) {
            return Err(GridError::Format {
                path: name.to_path_buf(),
                message: format!(
                    "{} values is not 4 columns of a positive multiple of {GRID_LEN} rows",
                    values.len()
                ),
            });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(GridError::Format {
                path: name.to_path_buf(),
                message: format!("non-finite value in row {}", i / 4),
            });
        }
        Ok(GridData {
            axes,
            n_vertices: rows / GRID_LEN,
            values,
        })
    }

    /// (dξ₁, dξ₂, dh, dθ) of vertex `v` at grid point `g`.
    pub fn row(&self, g: usize, v: usize) -> [f64; 4] {
        let i = 4 * (g + GRID_LEN * v);
        std::array::from_fn(|c| self.values[i + c] as f64)
    }

    /// The in-plane strain of grid point `g`.
    pub fn strain(&self, g: usize) -> MacroStrain {
        let [i, j, l] = grid_coords(g);
        MacroStrain::in_plane(self.axes[0][i], self.axes[1][j], self.axes[2][l])
    }

    /// The grid point nearest z = 0 (Euclidean in (s_x, s_a, s_y)); the first on ties.
    pub fn zero_point(&self) -> usize {
        let norm = |g: usize| {
            let z = self.strain(g).0;
            z[0] * z[0] + z[1] * z[1] + z[2] * z[2]
        };
        (0..GRID_LEN).fold(0, |best, g| if norm(g) < norm(best) { g } else { best })
    }

    /// Check that the data fits a pattern.
    pub fn check_pattern(&self, pattern: &Pattern) -> Result<(), GridError> {
        if self.n_vertices != pattern.len() {
            return Err(GridError::Mismatch(format!(
                "the grid data has {} vertices, the pattern {}",
                self.n_vertices,
                pattern.len()
            )));
        }
        Ok(())
    }
}

/// Our counterpart of the original displacement rows for a state at an in-plane strain: per vertex
/// (F₂⁻¹ ũ_xy, ũ_z, θ − θ_ref) (`docs/results.md`, item c), with ũ the world displacement from φ(ξ_v) + h_v n.
/// `None` for a bending strain (the original grid is in-plane only).
pub fn counterpart(pattern: &Pattern, state: &MicroState) -> Option<Vec<[f64; 4]>> {
    let z = state.strain.0;
    if z[3] != 0.0 || z[4] != 0.0 {
        return None;
    }
    let (a, b, c) = (1.0 + z[0], 1.0 + z[2], z[1]);
    let s = (1.0 - c * c).sqrt();
    let n = pattern.len();
    // world displacement: the home position minus φ(ξ) + h n (in the BendX family the plane is rotated, so
    // measure from the positions rather than reading ũ)
    let x = world_positions(pattern, state);
    let zero: Vec<f64> = {
        let mut y = state.y.clone();
        y[..3 * n].iter_mut().for_each(|v| *v = 0.0);
        y
    };
    let base_state = MicroState {
        y: zero,
        ..state.clone()
    };
    let x0 = world_positions(pattern, &base_state);
    let mut rows = Vec::with_capacity(n);
    for v in 0..n {
        let mut u = x[v] - x0[v];
        if state.family == Family::BendX {
            // rotate the plane of the BendX family back onto F (Q F₂ = G₂, Q e₁ = (√(1−c²), c))
            u = nalgebra::Vector3::new(s * u.x + c * u.y, -c * u.x + s * u.y, u.z);
        }
        debug_assert!(state.family == Family::BendX || (u - local(&state.y, v)).norm() < 1e-9);
        // F₂⁻¹ = [[1/a, −c/(a s)], [0, 1/(b s)]]
        let d1 = u.x / a - c * u.y / (a * s);
        let d2 = u.y / (b * s);
        rows.push([d1, d2, u.z, state.y[3 * n + v] - pattern.theta[v]]);
    }
    Some(rows)
}

/// How an attempt started.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Start {
    /// From the reference state.
    Cold,
    /// From the converged state of this grid point.
    Warm {
        /// The grid index of the converged point it started from.
        from: usize,
    },
}

/// One solve at one grid point.
#[derive(Clone, Debug, Serialize)]
pub struct Attempt {
    /// How the attempt started.
    pub start: Start,
    /// The solver's status, or `None` when it stopped with an error.
    pub status: Option<Status>,
    /// The error message when the solve stopped with an error.
    pub error: Option<String>,
    /// Newton steps taken.
    pub steps: usize,
    /// Final ‖g‖_∞ of the projected reduced gradient (N).
    pub gradient_norm: f64,
    /// Wall time (s).
    pub time: f64,
}

impl Attempt {
    /// Whether the solve converged.
    pub fn converged(&self) -> bool {
        self.status == Some(Status::Converged)
    }
}

/// The result at one grid point.
#[derive(Clone, Debug)]
pub struct PointResult {
    /// Grid index isx + 9·isa + 81·isy.
    pub index: usize,
    /// The macro strain of the point.
    pub strain: MacroStrain,
    /// The continuation attempts in order (warm, then cold when the warm one failed).
    pub attempts: Vec<Attempt>,
    /// The converged state (none when every attempt failed).
    pub state: Option<MicroState>,
}

/// Settings of a grid run.
#[derive(Clone, Debug, Default)]
pub struct GridOptions {
    /// Solve only the first `limit` points of the continuation order (a quick partial run).
    pub limit: Option<usize>,
    /// Additionally solve every `cold_every`-th grid point cold (0: none), for the warm-vs-cold statistics; these
    /// do not enter the error metrics or the convergence rate.
    pub cold_every: usize,
}

/// All results of a grid run.
#[derive(Clone, Debug)]
pub struct GridRun {
    /// The start point (nearest z = 0), solved cold.
    pub zero: usize,
    /// The continuation results in visiting order.
    pub points: Vec<PointResult>,
    /// The extra cold solves: (grid point, attempt).
    pub cold_samples: Vec<(usize, Attempt)>,
    /// Wall time of the whole run (s).
    pub time: f64,
}

/// The continuation order: grid points by layers of index (Manhattan) distance from `zero`, each layer in index
/// order.
pub fn continuation_layers(zero: usize) -> Vec<Vec<usize>> {
    let z = grid_coords(zero);
    let dist = |g: usize| {
        let c = grid_coords(g);
        (0..3).map(|k| c[k].abs_diff(z[k])).sum::<usize>()
    };
    let max = (0..GRID_LEN).map(dist).max().unwrap_or(0);
    (0..=max)
        .map(|d| (0..GRID_LEN).filter(|&g| dist(g) == d).collect())
        .collect()
}

/// The six grid neighbours of `g`, in the order −s_x, +s_x, −s_a, +s_a, −s_y, +s_y.
pub fn neighbours(g: usize) -> Vec<usize> {
    let c = grid_coords(g);
    let mut out = Vec::with_capacity(6);
    for k in 0..3 {
        for up in [false, true] {
            let mut d = c;
            if up {
                if d[k] + 1 >= AXIS_LEN {
                    continue;
                }
                d[k] += 1;
            } else {
                if d[k] == 0 {
                    continue;
                }
                d[k] -= 1;
            }
            out.push(grid_index(d[0], d[1], d[2]));
        }
    }
    out
}

fn attempt(
    problem: &MicroProblem,
    strain: &MacroStrain,
    start: Start,
    from: Option<&MicroState>,
) -> (Attempt, Option<MicroState>) {
    let t0 = Instant::now();
    match problem.solve(strain, from) {
        Ok(sol) => {
            let a = Attempt {
                start,
                status: Some(sol.status),
                error: None,
                steps: sol.steps,
                gradient_norm: sol.gradient_norm,
                time: sol.time,
            };
            let state = a.converged().then_some(sol.state);
            (a, state)
        }
        Err(e) => (
            Attempt {
                start,
                status: None,
                error: Some(e.to_string()),
                steps: 0,
                gradient_norm: f64::NAN,
                time: t0.elapsed().as_secs_f64(),
            },
            None,
        ),
    }
}

/// Solve the grid by warm-started continuation (see the module documentation). `progress` is called once per
/// finished solve (continuation points and cold samples). An error only when the cold solve at the start point
/// cannot run; any later failure is recorded in the results.
pub fn run_grid(
    problem: &MicroProblem,
    data: &GridData,
    options: &GridOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<GridRun, GridError> {
    data.check_pattern(&problem.pattern)?;
    let t0 = Instant::now();
    let zero = data.zero_point();
    let limit = options.limit.unwrap_or(GRID_LEN).min(GRID_LEN);
    let mut results: Vec<Option<PointResult>> = vec![None; GRID_LEN];
    let mut order = Vec::new();
    let mut done = 0;
    for layer in continuation_layers(zero) {
        if done >= limit {
            break;
        }
        let layer: Vec<usize> = layer.into_iter().take(limit - done).collect();
        done += layer.len();
        let solved: Vec<PointResult> = layer
            .par_iter()
            .map(|&g| {
                let strain = data.strain(g);
                let parent = if g == zero {
                    None
                } else {
                    neighbours(g)
                        .into_iter()
                        .find(|&p| results[p].as_ref().is_some_and(|r| r.state.is_some()))
                };
                let mut attempts = Vec::new();
                let mut state = None;
                if let Some(p) = parent {
                    let from = results[p].as_ref().and_then(|r| r.state.as_ref());
                    let (a, s) = attempt(problem, &strain, Start::Warm { from: p }, from);
                    attempts.push(a);
                    state = s;
                }
                if state.is_none() {
                    let (a, s) = attempt(problem, &strain, Start::Cold, None);
                    attempts.push(a);
                    state = s;
                }
                progress();
                PointResult {
                    index: g,
                    strain,
                    attempts,
                    state,
                }
            })
            .collect();
        for r in solved {
            order.push(r.index);
            let g = r.index;
            results[g] = Some(r);
        }
        if let Some(r) = results[zero].as_ref().filter(|r| r.state.is_none()) {
            let why = r
                .attempts
                .iter()
                .map(|a| match (&a.error, a.status) {
                    (Some(e), _) => e.clone(),
                    (None, Some(s)) => format!("{s} after {} steps", a.steps),
                    (None, None) => "no result".into(),
                })
                .collect::<Vec<_>>()
                .join("; ");
            return Err(GridError::StartFailed(format!(
                "the cold solve at the start point {} did not converge: {why}",
                r.strain
            )));
        }
    }
    let cold_points: Vec<usize> = if options.cold_every == 0 {
        Vec::new()
    } else {
        (0..GRID_LEN)
            .step_by(options.cold_every)
            .filter(|&g| g != zero)
            .collect()
    };
    let cold_samples: Vec<(usize, Attempt)> = cold_points
        .par_iter()
        .map(|&g| {
            let (a, _) = attempt(problem, &data.strain(g), Start::Cold, None);
            progress();
            (g, a)
        })
        .collect();
    let points = order
        .into_iter()
        .map(|g| results[g].take().expect("solved above"))
        .collect();
    Ok(GridRun {
        zero,
        points,
        cold_samples,
        time: t0.elapsed().as_secs_f64(),
    })
}

/// RMS and maximum of an error over (grid point, vertex) pairs, with where the maximum occurs.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ErrorStats {
    /// Root mean square of the error.
    pub rms: f64,
    /// Largest error.
    pub max: f64,
    /// (s_x, s_a, s_y) of the maximum.
    pub max_strain: [f64; 3],
    /// The vertex of the maximum.
    pub max_vertex: usize,
    /// Number of (grid point, vertex) pairs.
    pub count: usize,
}

#[derive(Default)]
struct Accum {
    sum2: f64,
    max: f64,
    at: (usize, usize),
    count: usize,
}

impl Accum {
    fn add(&mut self, e: f64, g: usize, v: usize) {
        self.sum2 += e * e;
        self.count += 1;
        if e > self.max || self.count == 1 {
            self.max = e;
            self.at = (g, v);
        }
    }

    fn stats(&self, data: &GridData) -> ErrorStats {
        let z = data.strain(self.at.0).0;
        ErrorStats {
            rms: if self.count > 0 {
                (self.sum2 / self.count as f64).sqrt()
            } else {
                f64::NAN
            },
            max: self.max,
            max_strain: [z[0], z[1], z[2]],
            max_vertex: self.at.1,
            count: self.count,
        }
    }
}

/// Newton steps and wall time of a set of solves.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StepStats {
    /// Number of solves.
    pub solves: usize,
    /// Solves that converged.
    pub converged: usize,
    /// Median Newton steps per solve.
    pub median_steps: f64,
    /// Most Newton steps of a solve.
    pub max_steps: usize,
    /// Mean Newton steps per solve.
    pub mean_steps: f64,
    /// Mean wall time per solve (s).
    pub mean_time: f64,
    /// Median wall time per solve (s).
    pub median_time: f64,
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

impl StepStats {
    fn of<'a>(attempts: impl Iterator<Item = &'a Attempt>) -> Self {
        let a: Vec<&Attempt> = attempts.collect();
        if a.is_empty() {
            return StepStats::default();
        }
        let steps: Vec<f64> = a.iter().map(|x| x.steps as f64).collect();
        let times: Vec<f64> = a.iter().map(|x| x.time).collect();
        StepStats {
            solves: a.len(),
            converged: a.iter().filter(|x| x.converged()).count(),
            median_steps: median(steps.clone()),
            max_steps: a.iter().map(|x| x.steps).max().unwrap_or(0),
            mean_steps: steps.iter().sum::<f64>() / a.len() as f64,
            mean_time: times.iter().sum::<f64>() / a.len() as f64,
            median_time: median(times),
        }
    }
}

/// Our displacement field against the original's at one grid point (both relative to their z = 0 state, the
/// position components (dξ₁, dξ₂, dh) of all vertices as one vector).
#[derive(Clone, Debug, Serialize)]
pub struct PointComparison {
    /// (s_x, s_a, s_y).
    pub strain: [f64; 3],
    /// RMS position error over the vertices (r).
    pub rms_error: f64,
    /// RMS of the original displacement (r).
    pub rms_original: f64,
    /// cos ∠(ours, original): 1 when the fields have the same shape.
    pub cosine: f64,
    /// ‖ours‖ / ‖original‖: 1 when they have the same size.
    pub magnitude_ratio: f64,
}

/// A failed attempt.
#[derive(Clone, Debug, Serialize)]
pub struct Failure {
    /// (s_x, s_a, s_y).
    pub strain: [f64; 3],
    /// (isx, isa, isy).
    pub grid: [usize; 3],
    /// "warm from (isx, isa, isy)", "cold", or "cold sample" (the extra cold solves).
    pub start: String,
    /// The status, or "error: …".
    pub status: String,
    /// Newton steps taken.
    pub steps: usize,
    /// Final ‖g‖_∞ of the projected reduced gradient (N).
    pub gradient_norm: f64,
    /// Whether the point converged in the end (a cold retry after a failed warm solve).
    pub recovered: bool,
}

/// Per-pattern summary of a grid run (the content of `validation/micro_grid.json`).
#[derive(Clone, Debug, Serialize)]
pub struct GridSummary {
    /// Vertices of the pattern.
    pub vertices: usize,
    /// Yarn radius r (m).
    pub radius: f64,
    /// The pattern's periods (m).
    pub periods: [f64; 2],
    /// Whether each yarn's slide along itself was constrained.
    pub slide_constraints: bool,
    /// The solver's dimensionless force tolerance.
    pub tolerance: f64,
    /// Grid points solved by the continuation (729 for a full run).
    pub points: usize,
    /// Points with a converged solution (warm or cold retry).
    pub converged: usize,
    /// Points whose warm solve failed and whose cold retry converged.
    pub recovered_cold: usize,
    /// ‖our − original‖ of (dξ₁, dξ₂, dh) relative to each side's z = 0 state, in units of r.
    pub position_error: ErrorStats,
    /// The same after removing, per grid point, the mean difference over the vertices (a rigid translation).
    pub position_error_translation_removed: ErrorStats,
    /// The same after removing, per grid point, each yarn's mean difference (per-yarn translations, a
    /// diagnostic for sliding modes; it also removes genuine relative yarn motion).
    pub position_error_yarn_translation_removed: ErrorStats,
    /// The same after sliding each of our yarns rigidly along the axis the original pins: the original data holds
    /// one vertex per yarn whose displacement along ξ₁ (or ξ₂) is zero at every grid point (its no-slide
    /// constraint); we shift that component of the yarn's vertices so that ours is zero there too.
    pub position_error_pinned_like_original: ErrorStats,
    /// The pinned (vertex, component) pairs found in the original data (component 0: ξ₁, 1: ξ₂).
    pub original_pins: Vec<(usize, usize)>,
    /// RMS of the error per component (dξ₁, dξ₂, dh), units of r.
    pub position_error_rms_components: [f64; 3],
    /// RMS position error (r) per axis value: over the grid points with s_x (row 0), s_a (row 1), s_y (row 2)
    /// equal to the axis' k-th value.
    pub position_error_rms_by_axis: [[f64; AXIS_LEN]; 3],
    /// RMS and max of the original displacement relative to its z = 0 state (units of r): the scale of the
    /// quantity compared.
    pub original_displacement: ErrorStats,
    /// |our − original| of θ − θ_ref relative to each side's z = 0 state (rad).
    pub theta_error: ErrorStats,
    /// RMS and max of the original dθ relative to its z = 0 state (rad).
    pub original_theta: ErrorStats,
    /// cos ∠(ours, original) of the displacement fields over all compared grid points and vertices.
    pub cosine: f64,
    /// ‖ours‖ / ‖original‖ of the displacement fields over all compared grid points and vertices.
    pub magnitude_ratio: f64,
    /// The comparison at the grid points one index step from the start point (the smallest strains).
    pub first_neighbours: Vec<PointComparison>,
    /// The grid points with the largest RMS position error: ((s_x, s_a, s_y), RMS in r).
    pub worst_points: Vec<([f64; 3], f64)>,
    /// The vertices with the largest RMS position error over the grid: (vertex, RMS in r).
    pub worst_vertices: Vec<(usize, f64)>,
    /// Warm-started continuation solves.
    pub warm: StepStats,
    /// Cold solves: the start point, cold retries and the extra cold samples.
    pub cold: StepStats,
    /// Every failed attempt.
    pub failures: Vec<Failure>,
    /// Wall time of the run (s).
    pub time: f64,
}

mod summary;

pub use summary::summarize;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_indexing_round_trips() {
        for g in 0..GRID_LEN {
            let [i, j, l] = grid_coords(g);
            assert_eq!(grid_index(i, j, l), g);
        }
        assert_eq!(grid_index(1, 2, 3), 1 + 18 + 243);
    }

    #[test]
    fn continuation_layers_cover_the_grid_once() {
        let zero = grid_index(2, 4, 2);
        let layers = continuation_layers(zero);
        assert_eq!(layers[0], vec![zero]);
        let mut seen = vec![false; GRID_LEN];
        for (d, layer) in layers.iter().enumerate() {
            for &g in layer {
                assert!(!seen[g]);
                seen[g] = true;
                if d > 0 {
                    // every point has a neighbour in the previous layer to start from
                    assert!(neighbours(g).iter().any(|p| layers[d - 1].contains(p)));
                }
            }
        }
        assert!(seen.iter().all(|&s| s));
        assert_eq!(neighbours(grid_index(0, 0, 0)).len(), 3);
        assert_eq!(neighbours(zero).len(), 6);
    }

    fn temp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("hylc-grid-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn npy_bytes(descr: &str, shape: &str, payload: &[u8]) -> Vec<u8> {
        let mut header =
            format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(payload);
        out
    }

    #[test]
    fn npy_reader_checks_dtype_and_shape() {
        let d = temp("npy");
        let good = d.join("good.npy");
        let payload: Vec<u8> = (0..8).flat_map(|i| (i as f32).to_le_bytes()).collect();
        std::fs::write(&good, npy_bytes("<f4", "(2, 4)", &payload)).unwrap();
        let (v, rows) = read_npy_f32(&good, 4).unwrap();
        assert_eq!(rows, 2);
        assert_eq!(v, (0..8).map(|i| i as f32).collect::<Vec<_>>());

        let wrong_shape = read_npy_f32(&good, 3).unwrap_err();
        assert!(
            wrong_shape.to_string().contains("good.npy"),
            "{wrong_shape}"
        );
        assert!(wrong_shape.to_string().contains("shape"), "{wrong_shape}");

        let f8 = d.join("f8.npy");
        let payload: Vec<u8> = (0..8).flat_map(|i| (i as f64).to_le_bytes()).collect();
        std::fs::write(&f8, npy_bytes("<f8", "(2, 4)", &payload)).unwrap();
        let e = read_npy_f32(&f8, 4).unwrap_err();
        assert!(
            e.to_string().contains("f8.npy") && e.to_string().contains("float32"),
            "{e}"
        );

        let junk = d.join("junk.npy");
        std::fs::write(&junk, b"not numpy").unwrap();
        let e = read_npy_f32(&junk, 4).unwrap_err();
        assert!(e.to_string().contains("junk.npy"), "{e}");

        let missing = read_npy_f32(&d.join("missing.npy"), 4).unwrap_err();
        assert!(matches!(missing, GridError::Io { .. }), "{missing}");
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn axes_reader_rejects_bad_files() {
        let d = temp("axes");
        let good = d.join("axes.txt");
        let line = "-0.2 -0.1 0 0.1 0.2 0.3 0.4 0.5 0.6";
        std::fs::write(&good, format!("{line}\n{line}\n{line}\n")).unwrap();
        let axes = read_axes(&good).unwrap();
        assert_eq!(axes[1][2], 0.0);
        for (name, text) in [
            ("two_lines", format!("{line}\n{line}\n")),
            ("short", format!("{line}\n{line}\n-0.2 0\n")),
            (
                "text",
                format!("{line}\n{line}\n{}\n", line.replace("0.6", "x")),
            ),
            (
                "unsorted",
                format!("{line}\n{line}\n{}\n", line.replace("0.6", "0.05")),
            ),
            (
                "inadmissible",
                format!("{line}\n{}\n{line}\n", line.replace("0.6", "1.5")),
            ),
        ] {
            let p = d.join(format!("{name}.txt"));
            std::fs::write(&p, text).unwrap();
            let e = read_axes(&p).unwrap_err();
            assert!(e.to_string().contains(&format!("{name}.txt")), "{e}");
        }
        std::fs::remove_dir_all(&d).ok();
    }
}
