//! Conventions first (docs/yarn-parameters.md): before fitting, every convention that could move the compared
//! displacements without any yarn parameter, each switched on its own, with the error at the six grid points
//! nearest z = 0 (the start point's neighbours), compared as `micro-grid` compares them.
//!
//! The conventions:
//! - `as implemented`: our rows (F₂⁻¹ ũ_xy, ũ_z, θ − θ_ref), F = [[a, b c], [0, b √(1−c²)]] (the shear turns e₂);
//! - `world frame`: our world displacement ũ_xy without mapping it back to reference coordinates (as if the
//!   original stored world displacements);
//! - `shear turns e₁`: the world displacement in the frame where F' = [[a √(1−c²), 0], [a c, b]] (the shear
//!   turns e₁; F' = Q F with Q a rotation); mapped back to reference coordinates the two agree exactly, so this
//!   differs from `as implemented` only if the original stored world displacements in its frame;
//! - `rigid rotation removed`: per grid point, the best in-plane rotation (and translation) of our field onto the
//!   original's removed (a rotation of the tile that the original's constraints fix differently);
//! - `s_a mirrored`: ours at −s_a against the original at s_a (the sign of the shear);
//! - `s_x ↔ s_y`: ours at (s_y, s_a, s_x) against the original at (s_x, s_a, s_y) (the axes of the tile);
//! - `file periods`: the periods stored in the `.pyp` file instead of those implied by the rest lengths;
//! - `θ sign flipped`: the θ error with our dθ negated (θ only; the position error is that of `as implemented`).

use super::IdentifyError;
use crate::micro::{MacroStrain, MicroProblem, MicroState, SolverOptions, Status};
use crate::pattern::Pattern;
use crate::rod::YarnMaterial;
use crate::validation::grid::{counterpart, neighbours, GridData};
use serde::Serialize;

/// One convention's errors at the six nearest grid points.
#[derive(Clone, Debug, Serialize)]
pub struct ConventionRow {
    /// The convention's name.
    pub name: &'static str,
    /// RMS position error over the six points and the vertices (r).
    pub position_rms: f64,
    /// RMS θ error (rad).
    pub theta_rms: f64,
    /// Per point: (s_x, s_a, s_y) and the RMS position error there (r).
    pub points: Vec<([f64; 3], f64)>,
}

/// A converged solve or an error naming the strain.
fn solve(
    problem: &MicroProblem,
    z: &MacroStrain,
    start: Option<&MicroState>,
) -> Result<MicroState, IdentifyError> {
    let sol = problem.solve(z, start)?;
    if sol.status != Status::Converged {
        return Err(IdentifyError::NotConverged {
            what: "conventions check".into(),
            strain: *z,
            status: sol.status,
        });
    }
    Ok(sol.state)
}

/// The rows of our state relative to our start point, per vertex.
type Rows = Vec<[f64; 4]>;

/// Our rows at `z` relative to those at z₀ (both solved with `problem`).
fn relative_rows(
    problem: &MicroProblem,
    z0: &MacroStrain,
    z: &MacroStrain,
) -> Result<(Rows, MicroState), IdentifyError> {
    let s0 = solve(problem, z0, None)?;
    let s = solve(problem, z, Some(&s0))?;
    let p = &problem.pattern;
    let (a, b) = (
        counterpart(p, &s).expect("in-plane"),
        counterpart(p, &s0).expect("in-plane"),
    );
    Ok((
        a.iter()
            .zip(&b)
            .map(|(x, y)| std::array::from_fn(|c| x[c] - y[c]))
            .collect(),
        s,
    ))
}

/// Position error (sum of squares in r², count) and θ error sum of squares of our relative rows against the
/// original's at grid point g.
fn compare(
    ours: &Rows,
    data: &GridData,
    g: usize,
    g0: usize,
    r: f64,
    theta_sign: f64,
) -> (f64, f64) {
    let mut pos = 0.0;
    let mut th = 0.0;
    for (v, o) in ours.iter().enumerate() {
        let (t, t0) = (data.row(g, v), data.row(g0, v));
        for c in 0..3 {
            pos += ((o[c] - (t[c] - t0[c])) / r).powi(2);
        }
        th += (theta_sign * o[3] - (t[3] - t0[3])).powi(2);
    }
    (pos, th)
}

/// F₂ of an in-plane strain (the shear turns e₂) and the rotation Q with F' = Q F (the shear turns e₁).
fn frames(z: &MacroStrain) -> ([[f64; 2]; 2], [[f64; 2]; 2]) {
    let (a, b, c) = (1.0 + z.0[0], 1.0 + z.0[2], z.0[1]);
    let s = (1.0 - c * c).sqrt();
    let f = [[a, b * c], [0.0, b * s]];
    let fp = [[a * s, 0.0], [a * c, b]];
    // Q = F' F⁻¹, F⁻¹ = [[1/a, −c/(a s)], [0, 1/(b s)]]
    let fi = [[1.0 / a, -c / (a * s)], [0.0, 1.0 / (b * s)]];
    let q =
        std::array::from_fn(|i| std::array::from_fn(|j| fp[i][0] * fi[0][j] + fp[i][1] * fi[1][j]));
    (f, q)
}

/// The table of item 4 for one pattern. `file_pattern` is the pattern with the periods stored in its file (when
/// they differ from the implied ones).
pub fn check_conventions(
    pattern: &Pattern,
    file_pattern: Option<&Pattern>,
    material: &YarnMaterial,
    solver: &SolverOptions,
    data: &GridData,
) -> Result<Vec<ConventionRow>, IdentifyError> {
    data.check_pattern(pattern)?;
    let problem = MicroProblem::new(pattern.clone(), material, solver.clone());
    let r = pattern.radius;
    let n = pattern.len();
    let g0 = data.zero_point();
    let z0 = data.strain(g0);
    let points = neighbours(g0);
    let mut rows: Vec<ConventionRow> = Vec::new();
    let mut push = |name, per: Vec<([f64; 3], f64, f64)>| {
        let count = (per.len() * n) as f64;
        rows.push(ConventionRow {
            name,
            position_rms: (per.iter().map(|p| p.1).sum::<f64>() / count).sqrt(),
            theta_rms: (per.iter().map(|p| p.2).sum::<f64>() / count).sqrt(),
            points: per.iter().map(|p| (p.0, (p.1 / n as f64).sqrt())).collect(),
        });
    };
    let triple = |z: &MacroStrain| [z.0[0], z.0[1], z.0[2]];
    // as implemented, its world-frame variants, the rigid rotation and the θ sign: one solve per point
    let mut base = Vec::new();
    let (mut world, mut turned, mut rigid, mut flipped) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &g in &points {
        let z = data.strain(g);
        let (ours, _) = relative_rows(&problem, &z0, &z)?;
        let (pos, th) = compare(&ours, data, g, g0, r, 1.0);
        base.push((triple(&z), pos, th));
        let (_, thf) = compare(&ours, data, g, g0, r, -1.0);
        flipped.push((triple(&z), pos, thf));
        let (f, q) = frames(&z);
        let map = |m: &[[f64; 2]; 2], o: &[f64; 4]| -> [f64; 4] {
            [
                m[0][0] * o[0] + m[0][1] * o[1],
                m[1][0] * o[0] + m[1][1] * o[1],
                o[2],
                o[3],
            ]
        };
        // world displacement u_xy = F₂ (dξ₁, dξ₂) (z₀ is the identity map)
        let w: Rows = ours.iter().map(|o| map(&f, o)).collect();
        let wq: Rows = w.iter().map(|o| map(&q, o)).collect();
        let (pw, _) = compare(&w, data, g, g0, r, 1.0);
        let (pq, _) = compare(&wq, data, g, g0, r, 1.0);
        world.push((triple(&z), pw, th));
        turned.push((triple(&z), pq, th));
        rigid.push((triple(&z), rigid_removed(&ours, data, g, g0, r), th));
    }
    push("as implemented", base);
    push("world frame", world);
    push("shear turns e1 (world frame)", turned);
    push("rigid rotation removed", rigid);
    // mirrored shear and swapped axes: ours at another strain against the original at z
    let mut mirrored = Vec::new();
    let mut swapped = Vec::new();
    for &g in &points {
        let z = data.strain(g);
        let zm = MacroStrain::in_plane(z.0[0], -z.0[1], z.0[2]);
        let (ours, _) = relative_rows(&problem, &z0, &zm)?;
        let (pos, th) = compare(&ours, data, g, g0, r, 1.0);
        mirrored.push((triple(&z), pos, th));
        let zs = MacroStrain::in_plane(z.0[2], z.0[1], z.0[0]);
        let (ours, _) = relative_rows(&problem, &z0, &zs)?;
        let (pos, th) = compare(&ours, data, g, g0, r, 1.0);
        swapped.push((triple(&z), pos, th));
    }
    push("s_a mirrored", mirrored);
    push("s_x and s_y swapped", swapped);
    if let Some(fp) = file_pattern {
        let fproblem = MicroProblem::new(fp.clone(), material, solver.clone());
        let mut per = Vec::new();
        for &g in &points {
            let z = data.strain(g);
            let (ours, _) = relative_rows(&fproblem, &z0, &z)?;
            let (pos, th) = compare(&ours, data, g, g0, r, 1.0);
            per.push((triple(&z), pos, th));
        }
        push("file periods", per);
    }
    push_theta_row(&mut rows, flipped, n);
    Ok(rows)
}

fn push_theta_row(rows: &mut Vec<ConventionRow>, per: Vec<([f64; 3], f64, f64)>, n: usize) {
    let count = (per.len() * n) as f64;
    rows.push(ConventionRow {
        name: "theta sign flipped",
        position_rms: (per.iter().map(|p| p.1).sum::<f64>() / count).sqrt(),
        theta_rms: (per.iter().map(|p| p.2).sum::<f64>() / count).sqrt(),
        points: per.iter().map(|p| (p.0, (p.1 / n as f64).sqrt())).collect(),
    });
}

/// Sum of squared position errors (r²) after removing the best in-plane rotation about e₃ and translation of our
/// field onto the original's (both about their centroids; the normal component keeps only its translation).
fn rigid_removed(ours: &Rows, data: &GridData, g: usize, g0: usize, r: f64) -> f64 {
    let n = ours.len() as f64;
    let theirs: Rows = (0..ours.len())
        .map(|v| {
            let (t, t0) = (data.row(g, v), data.row(g0, v));
            std::array::from_fn(|c| t[c] - t0[c])
        })
        .collect();
    let mean = |rows: &Rows, c: usize| rows.iter().map(|o| o[c]).sum::<f64>() / n;
    let (mo, mt): ([f64; 3], [f64; 3]) = (
        std::array::from_fn(|c| mean(ours, c)),
        std::array::from_fn(|c| mean(&theirs, c)),
    );
    let (mut dot, mut cross) = (0.0, 0.0);
    for (o, t) in ours.iter().zip(&theirs) {
        let (ox, oy) = (o[0] - mo[0], o[1] - mo[1]);
        let (tx, ty) = (t[0] - mt[0], t[1] - mt[1]);
        dot += ox * tx + oy * ty;
        cross += ox * ty - oy * tx;
    }
    let phi = cross.atan2(dot);
    let (c, s) = (phi.cos(), phi.sin());
    let mut sum = 0.0;
    for (o, t) in ours.iter().zip(&theirs) {
        let (ox, oy) = (o[0] - mo[0], o[1] - mo[1]);
        let rx = c * ox - s * oy;
        let ry = s * ox + c * oy;
        sum += ((rx - (t[0] - mt[0])) / r).powi(2)
            + ((ry - (t[1] - mt[1])) / r).powi(2)
            + ((o[2] - mo[2] - (t[2] - mt[2])) / r).powi(2);
    }
    sum
}
