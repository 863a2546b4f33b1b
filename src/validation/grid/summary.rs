//! The summary of a grid run ([`summarize`]): position and θ errors against the original displacements, relative
//! to each side's z = 0 state (raw, translation removed, per-yarn translation removed, pinned like the original),
//! per axis and per point, the agreement of directions and magnitudes, and every solve that failed.

use super::*;

/// Compare a grid run with the original data.
pub fn summarize(problem: &MicroProblem, data: &GridData, run: &GridRun) -> GridSummary {
    let p = &problem.pattern;
    let n = p.len();
    let r = p.radius;
    let ours: Vec<Option<Vec<[f64; 4]>>> = {
        let mut v = vec![None; GRID_LEN];
        for pr in &run.points {
            v[pr.index] = pr.state.as_ref().and_then(|s| counterpart(p, s));
        }
        v
    };
    let yarn_of = {
        let mut y = vec![0; n];
        for (k, yarn) in p.yarns().iter().enumerate() {
            for &v in yarn {
                y[v] = k;
            }
        }
        y
    };
    let pins: Vec<(usize, usize)> = (0..n)
        .flat_map(|v| (0..2).map(move |c| (v, c)))
        .filter(|&(v, c)| (0..GRID_LEN).all(|g| data.row(g, v)[c].abs() < 1e-12))
        .collect();
    let mut e = Errors::new(n, r, yarn_of, &pins, neighbours(run.zero));
    if let Some(zero) = ours[run.zero].as_ref() {
        for pr in &run.points {
            if let Some(our) = ours[pr.index].as_ref() {
                e.add_point(data, run.zero, pr, our, zero);
            }
        }
    }
    let count = e.pos.count.max(1) as f64;
    e.per_point.sort_by(|a, b| b.1.total_cmp(&a.1));
    e.per_point.truncate(5);
    let mut worst_vertices: Vec<(usize, f64)> = e
        .per_vertex
        .iter()
        .enumerate()
        .map(|(v, s)| (v, (s / e.per_vertex_count.max(1) as f64).sqrt()))
        .collect();
    worst_vertices.sort_by(|a, b| b.1.total_cmp(&a.1));
    worst_vertices.truncate(5);

    let warm = StepStats::of(
        run.points
            .iter()
            .flat_map(|p| &p.attempts)
            .filter(|a| matches!(a.start, Start::Warm { .. })),
    );
    let cold = StepStats::of(
        run.points
            .iter()
            .flat_map(|p| &p.attempts)
            .filter(|a| a.start == Start::Cold)
            .chain(run.cold_samples.iter().map(|(_, a)| a)),
    );
    GridSummary {
        vertices: n,
        radius: r,
        periods: p.periods,
        slide_constraints: problem.options.slide_constraints,
        tolerance: problem.options.tolerance,
        points: run.points.len(),
        converged: run.points.iter().filter(|p| p.state.is_some()).count(),
        recovered_cold: run
            .points
            .iter()
            .filter(|p| p.state.is_some() && p.attempts.len() > 1)
            .count(),
        position_error: e.pos.stats(data),
        position_error_translation_removed: e.pos_t.stats(data),
        position_error_yarn_translation_removed: e.pos_y.stats(data),
        position_error_pinned_like_original: e.pos_pin.stats(data),
        original_pins: pins.clone(),
        position_error_rms_components: e.comp.map(|s| (s / count).sqrt()),
        position_error_rms_by_axis: e.by_axis.map(|row| {
            row.map(|(s, k)| {
                if k > 0 {
                    (s / k as f64).sqrt()
                } else {
                    f64::NAN
                }
            })
        }),
        original_displacement: e.orig.stats(data),
        theta_error: e.th.stats(data),
        cosine: e.dot_all / (e.ours_all * e.orig_all).sqrt(),
        magnitude_ratio: (e.ours_all / e.orig_all).sqrt(),
        first_neighbours: e.first_neighbours,
        original_theta: e.orig_th.stats(data),
        worst_points: e.per_point,
        worst_vertices,
        warm,
        cold,
        failures: failures(data, run),
        time: run.time,
    }
}

/// The error accumulators of [`summarize`] over the converged grid points.
struct Errors<'a> {
    n: usize,
    r: f64,
    yarn_of: Vec<usize>,
    n_yarns: usize,
    pins: &'a [(usize, usize)],
    near: Vec<usize>,
    pos_pin: Accum,
    pos: Accum,
    pos_t: Accum,
    pos_y: Accum,
    comp: [f64; 3],
    orig: Accum,
    th: Accum,
    orig_th: Accum,
    per_point: Vec<([f64; 3], f64)>,
    per_vertex: Vec<f64>,
    per_vertex_count: usize,
    dot_all: f64,
    ours_all: f64,
    orig_all: f64,
    first_neighbours: Vec<PointComparison>,
    by_axis: [[(f64, usize); AXIS_LEN]; 3],
}

impl<'a> Errors<'a> {
    fn new(
        n: usize,
        r: f64,
        yarn_of: Vec<usize>,
        pins: &'a [(usize, usize)],
        near: Vec<usize>,
    ) -> Self {
        let n_yarns = yarn_of.iter().max().map_or(0, |m| m + 1);
        Errors {
            n,
            r,
            yarn_of,
            n_yarns,
            pins,
            near,
            pos_pin: Accum::default(),
            pos: Accum::default(),
            pos_t: Accum::default(),
            pos_y: Accum::default(),
            comp: [0.0; 3],
            orig: Accum::default(),
            th: Accum::default(),
            orig_th: Accum::default(),
            per_point: Vec::new(),
            per_vertex: vec![0.0; n],
            per_vertex_count: 0,
            dot_all: 0.0,
            ours_all: 0.0,
            orig_all: 0.0,
            first_neighbours: Vec::new(),
            by_axis: [[(0.0, 0usize); AXIS_LEN]; 3],
        }
    }

    /// Add grid point `pr` (our displacements `our`, ours at z = 0 `zero`; the original's at `g0` = z = 0).
    fn add_point(
        &mut self,
        data: &GridData,
        g0: usize,
        pr: &PointResult,
        our: &[[f64; 4]],
        zero: &[[f64; 4]],
    ) {
        let (n, r, g) = (self.n, self.r, pr.index);
        let yarn_of = &self.yarn_of;
        let diff: Vec<[f64; 4]> = (0..n)
            .map(|v| {
                let o = data.row(g, v);
                let o0 = data.row(g0, v);
                std::array::from_fn(|c| (our[v][c] - zero[v][c]) - (o[c] - o0[c]))
            })
            .collect();
        let mut mean = [0.0; 3];
        let mut yarn_mean = vec![[0.0; 3]; self.n_yarns];
        let mut yarn_count = vec![0usize; self.n_yarns];
        for v in 0..n {
            for c in 0..3 {
                mean[c] += diff[v][c] / n as f64;
                yarn_mean[yarn_of[v]][c] += diff[v][c];
            }
            yarn_count[yarn_of[v]] += 1;
        }
        for (m, &k) in yarn_mean.iter_mut().zip(&yarn_count) {
            m.iter_mut().for_each(|x| *x /= k.max(1) as f64);
        }
        let norm = |d: [f64; 3]| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / r;
        let mut pinned = diff.clone();
        for &(vp, c) in self.pins {
            let shift = diff[vp][c];
            for v in (0..n).filter(|&v| yarn_of[v] == yarn_of[vp]) {
                pinned[v][c] -= shift;
            }
        }
        let mut point_sum2 = 0.0;
        let (mut dot, mut oo, mut tt) = (0.0, 0.0, 0.0);
        for v in 0..n {
            let o = data.row(g, v);
            let o0 = data.row(g0, v);
            for c in 0..3 {
                let a = our[v][c] - zero[v][c];
                let b = o[c] - o0[c];
                dot += a * b;
                oo += a * a;
                tt += b * b;
            }
        }
        self.dot_all += dot;
        self.ours_all += oo;
        self.orig_all += tt;
        if self.near.contains(&g) {
            let z = pr.strain.0;
            self.first_neighbours.push(PointComparison {
                strain: [z[0], z[1], z[2]],
                rms_error: f64::NAN,
                rms_original: (tt / n as f64).sqrt() / r,
                cosine: dot / (oo * tt).sqrt(),
                magnitude_ratio: (oo / tt).sqrt(),
            });
        }
        for v in 0..n {
            let d = [diff[v][0], diff[v][1], diff[v][2]];
            let e = norm(d);
            self.pos.add(e, g, v);
            point_sum2 += e * e;
            self.per_vertex[v] += e * e;
            for c in 0..3 {
                self.comp[c] += (d[c] / r).powi(2);
            }
            self.pos_t
                .add(norm(std::array::from_fn(|c| d[c] - mean[c])), g, v);
            self.pos_pin
                .add(norm(std::array::from_fn(|c| pinned[v][c])), g, v);
            let ym = yarn_mean[yarn_of[v]];
            self.pos_y
                .add(norm(std::array::from_fn(|c| d[c] - ym[c])), g, v);
            self.th.add(diff[v][3].abs(), g, v);
            let o = data.row(g, v);
            let o0 = data.row(g0, v);
            self.orig
                .add(norm(std::array::from_fn(|c| o[c] - o0[c])), g, v);
            self.orig_th.add((o[3] - o0[3]).abs(), g, v);
        }
        self.per_vertex_count += 1;
        let near = &self.near;
        if let Some(c) = self
            .first_neighbours
            .last_mut()
            .filter(|_| near.contains(&g))
        {
            c.rms_error = (point_sum2 / n as f64).sqrt();
        }
        for (k, &i) in grid_coords(g).iter().enumerate() {
            self.by_axis[k][i].0 += point_sum2;
            self.by_axis[k][i].1 += n;
        }
        let z = pr.strain.0;
        self.per_point
            .push(([z[0], z[1], z[2]], (point_sum2 / n as f64).sqrt()));
    }
}

/// Every attempt that did not converge (continuation and extra cold solves), with where it started.
fn failures(data: &GridData, run: &GridRun) -> Vec<Failure> {
    let mut failures = Vec::new();
    let describe = |a: &Attempt| match (&a.status, &a.error) {
        (_, Some(e)) => format!("error: {e}"),
        (Some(s), None) => s.to_string(),
        (None, None) => "unknown".into(),
    };
    for pr in &run.points {
        for a in pr.attempts.iter().filter(|a| !a.converged()) {
            let z = pr.strain.0;
            failures.push(Failure {
                strain: [z[0], z[1], z[2]],
                grid: grid_coords(pr.index),
                start: match a.start {
                    Start::Cold => "cold".into(),
                    Start::Warm { from } => format!("warm from {:?}", grid_coords(from)),
                },
                status: describe(a),
                steps: a.steps,
                gradient_norm: a.gradient_norm,
                recovered: pr.state.is_some(),
            });
        }
    }
    for (g, a) in run.cold_samples.iter().filter(|(_, a)| !a.converged()) {
        let z = data.strain(*g).0;
        failures.push(Failure {
            strain: [z[0], z[1], z[2]],
            grid: grid_coords(*g),
            start: "cold sample".into(),
            status: describe(a),
            steps: a.steps,
            gradient_norm: a.gradient_norm,
            recovered: false,
        });
    }
    failures
}
