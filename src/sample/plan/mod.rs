//! Sampling plans (`docs/sampling.md`, section "Sampling plan (C4)").
//!
//! A [`Plan`] lists per-strain ranges, the sample counts of the 1D ranges and of the 2D grids, and the strain
//! pairs of the grids. Its samples are enumerated in a fixed order (the five 1D ranges, then the grids row-major),
//! each with a stable id: the FNV-1a 64 hash of the plan's canonical JSON and the sample's index. For
//! warm-started continuation the samples are grouped into [`Chain`]s: each 1D range is two rays solved outward
//! from the sample nearest z = 0; each 2D grid first solves its axis (the column nearest zero in the second
//! strain) as two rays from the point nearest the origin, then continues every row as two rays from that axis.

mod check;

pub use check::{
    inadmissible, PlanError, MAX_PLAN_CURVATURE, MAX_PLAN_SAMPLES, MAX_PLAN_SHEAR,
    MAX_PLAN_STRETCH, MIN_PLAN_STRETCH,
};

use crate::strain::StrainComponent;
use serde::{Deserialize, Serialize};

/// SAMPLERANGE(z, z_min, z_max, N) (`docs/sampling.md`): for the stretches s_x, s_y (`k` = 0, 2)
/// Z = linspace((z_min+1)^(1/10), (z_max+1)^(1/10), N)^10 − 1 (denser towards compression); for s_a, Π₀₀, Π₁₁
/// (`k` = 1, 3, 4) Z = linspace(−√|z_min|, √|z_max|, N), then Z = sgn(Z) Z² (denser near 0).
/// `n` = 1 gives the lower end (as `linspace` does).
pub fn sample_range(k: usize, z_min: f64, z_max: f64, n: usize) -> Vec<f64> {
    let linspace = |a: f64, b: f64| -> Vec<f64> {
        match n {
            0 => vec![],
            1 => vec![a],
            _ => (0..n)
                .map(|i| {
                    if i == n - 1 {
                        b
                    } else {
                        a + (b - a) * i as f64 / (n - 1) as f64
                    }
                })
                .collect(),
        }
    };
    if k == 0 || k == 2 {
        linspace((z_min + 1.0).powf(0.1), (z_max + 1.0).powf(0.1))
            .into_iter()
            .map(|v| v.powi(10) - 1.0)
            .collect()
    } else {
        linspace(-z_min.abs().sqrt(), z_max.abs().sqrt())
            .into_iter()
            .map(|v| v.signum() * v * v)
            .collect()
    }
}

/// Per-strain ranges [min, max] (defaults: s_x, s_y ∈ [−0.6, 0.96], s_a ∈ [−0.7, 0.7], Π ∈ [−160, 160]
/// m⁻¹).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ranges {
    /// range of s_x
    pub s_x: [f64; 2],
    /// range of s_a
    pub s_a: [f64; 2],
    /// range of s_y
    pub s_y: [f64; 2],
    /// range of Π₀₀ (1/m)
    #[serde(rename = "II00")]
    pub ii00: [f64; 2],
    /// range of Π₁₁ (1/m)
    #[serde(rename = "II11")]
    pub ii11: [f64; 2],
}

impl Ranges {
    /// The range of strain `k` (0..5: s_x, s_a, s_y, Π₀₀, Π₁₁).
    pub fn get(&self, k: usize) -> [f64; 2] {
        [self.s_x, self.s_a, self.s_y, self.ii00, self.ii11][k]
    }
}

impl Default for Ranges {
    fn default() -> Self {
        Ranges {
            s_x: [-0.6, 0.96],
            s_a: [-0.7, 0.7],
            s_y: [-0.6, 0.96],
            ii00: [-160.0, 160.0],
            ii11: [-160.0, 160.0],
        }
    }
}

/// A sampling plan (`docs/sampling.md`, "Sampling plan (C4)"), stored as JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// Per-strain ranges.
    pub ranges: Ranges,
    /// Samples of each 1D range (default 150).
    pub count_1d: usize,
    /// Samples per axis of each 2D grid (default 50, i.e. 50×50).
    pub count_2d: usize,
    /// The strain pairs of the 2D grids (written by name: `s_x`, `s_a`, `s_y`, `II00`, `II11`).
    pub pairs: Vec<[StrainComponent; 2]>,
    /// Optional ranges of the 2D grids, one [[min, max], [min, max]] per pair (Algorithm C4 takes 2D ranges
    /// separately from the 1D ones; the original materials' grids span e.g. s_x ∈ [−0.1, 0.84] where their 1D
    /// range reaches −0.64). Absent (the default): the grids use `ranges`. Each must contain 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ranges_2d: Option<Vec<[[f64; 2]; 2]>>,
    /// An optional tensor grid of in-plane strains (s_x, s_a, s_y all varying, no bending): held-out samples
    /// off the sampled planes, which the additive model must predict (`docs/sampling.md`, "Quality
    /// report"). Absent from the JSON (and from the hash) when `None`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<InPlaneGrid>,
    /// Optional samples per 1D range, one count per strain (s_x, s_a, s_y, II00, II11), overriding `count_1d`
    /// (a scene plan keeps the default spacing on each range it narrows). Absent: `count_1d` for every range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counts_1d: Option<[usize; 5]>,
    /// Optional samples per axis of each 2D grid, one [first, second] per pair, overriding `count_2d`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counts_2d: Option<Vec<[usize; 2]>>,
}

/// The explicit axis values of an in-plane tensor grid (samples (s_x, s_a, s_y, 0, 0), s_x index outermost).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InPlaneGrid {
    /// values of s_x
    pub s_x: Vec<f64>,
    /// values of s_a
    pub s_a: Vec<f64>,
    /// values of s_y
    pub s_y: Vec<f64>,
}

impl InPlaneGrid {
    /// The 9×9×9 grid of the original displacement data (`docs/derivative-harness.md`, item 3c): s_x, s_y ∈ {−0.2, −0.1,
    /// 0, 1/6, …, 1}, s_a ∈ {−0.7, −0.525, …, 0.7}.
    pub fn original() -> Self {
        let stretch: Vec<f64> = [-0.2, -0.1]
            .into_iter()
            .chain((0..7).map(|i| i as f64 / 6.0))
            .collect();
        InPlaneGrid {
            s_x: stretch.clone(),
            s_a: (0..9).map(|i| 0.175 * (i as f64 - 4.0)).collect(),
            s_y: stretch,
        }
    }

    /// Number of grid points.
    pub fn len(&self) -> usize {
        self.checked_len().unwrap_or(usize::MAX)
    }

    /// Number of grid points, `None` when it overflows `usize`.
    pub fn checked_len(&self) -> Option<usize> {
        self.s_x
            .len()
            .checked_mul(self.s_a.len())?
            .checked_mul(self.s_y.len())
    }

    /// Whether the grid has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The default plan's nine pairs: {s_x,s_a,s_y}² unordered distinct, then {s_x,s_a,s_y}×{Π₀₀,Π₁₁}.
pub fn default_pairs() -> Vec<[StrainComponent; 2]> {
    use StrainComponent::*;
    vec![
        [Sx, Sa],
        [Sx, Sy],
        [Sa, Sy],
        [Sx, II00],
        [Sx, II11],
        [Sa, II00],
        [Sa, II11],
        [Sy, II00],
        [Sy, II11],
    ]
}

/// The smallest stretch of the quick plan's grids that pair s_x or s_y with a bending strain ([`Plan::quick`]).
pub const QUICK_BENT_COMPRESSION: f64 = -0.44;

impl Default for Plan {
    /// The default plan: 5 × 150 + 9 × 50² = 23 250 samples.
    fn default() -> Self {
        Plan {
            ranges: Ranges::default(),
            count_1d: 150,
            count_2d: 50,
            pairs: default_pairs(),
            ranges_2d: None,
            grid: None,
            counts_1d: None,
            counts_2d: None,
        }
    }
}

/// One sample of a plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Position in the plan's enumeration.
    pub index: usize,
    /// Stable id: `<plan hash, 16 hex digits>-<index>`.
    pub id: String,
    /// The strain z = (s_x, s_a, s_y, Π₀₀, Π₁₁).
    pub z: [f64; 5],
}

/// One step of a continuation chain: solve sample `sample`, starting from the state of step `from` of the same
/// chain (the reference state when `None`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    /// the sample to solve (its index in the plan)
    pub sample: usize,
    /// the earlier step of the chain it starts from (`None`: the reference state)
    pub from: Option<usize>,
}

/// A continuation chain: steps in solve order; every step's `from` is an earlier step, so a chain is solved
/// sequentially and its results depend only on the chain.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chain {
    /// the steps in solve order
    pub steps: Vec<Step>,
}

/// FNV-1a 64 of bytes.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// Indices of `values` ordered as two rays outward from the value nearest 0: the nearest index first, then
/// upwards, then downwards. Returns (origin, up, down).
fn rays(values: &[f64]) -> (usize, Vec<usize>, Vec<usize>) {
    let mut origin = 0;
    for (i, v) in values.iter().enumerate() {
        if v.abs() < values[origin].abs() {
            origin = i;
        }
    }
    let up = (origin + 1..values.len()).collect();
    let down = (0..origin).rev().collect();
    (origin, up, down)
}

/// Append a ray (steps continuing from `start`) to `steps`, returning the step index of each element.
fn push_ray(steps: &mut Vec<Step>, start: usize, samples: impl IntoIterator<Item = usize>) {
    let mut from = start;
    for s in samples {
        steps.push(Step {
            sample: s,
            from: Some(from),
        });
        from = steps.len() - 1;
    }
}

/// A continuation chain over a 2D tensor grid (`at(i, j)` = sample index; `first`, `second` = [`rays`] of the two
/// axes, `n_first` values along the first): the line j = j0 as two rays from (i0, j0), which starts from the
/// reference state, then every line i, in index order, as two rays in j from its point on that line.
fn grid_chain(
    first: &(usize, Vec<usize>, Vec<usize>),
    second: &(usize, Vec<usize>, Vec<usize>),
    n_first: usize,
    at: impl Fn(usize, usize) -> usize,
) -> Vec<Step> {
    let (i0, iup, idown) = first;
    let (j0, jup, jdown) = second;
    let mut steps = vec![Step {
        sample: at(*i0, *j0),
        from: None,
    }];
    let mut line_step = vec![0usize; n_first];
    for ray in [iup, idown] {
        let mut from = 0;
        for &i in ray {
            steps.push(Step {
                sample: at(i, *j0),
                from: Some(from),
            });
            from = steps.len() - 1;
            line_step[i] = from;
        }
    }
    for i in 0..n_first {
        push_ray(&mut steps, line_step[i], jup.iter().map(|&j| at(i, j)));
        push_ray(&mut steps, line_step[i], jdown.iter().map(|&j| at(i, j)));
    }
    steps
}

impl Plan {
    /// A reduced plan for quick runs and tests: 30 samples per 1D range, 10×10 grids, default ranges and pairs.
    pub fn reduced() -> Self {
        Plan {
            count_1d: 30,
            count_2d: 10,
            ..Plan::default()
        }
    }

    /// The plan of `hylc run`, the end-to-end job: 30 samples per 1D range and 6×6 grids (150 + 9 · 36 = 474
    /// samples), default ranges and pairs, so that the whole job stays within minutes on 2 cores. The grids that
    /// pair a stretch (s_x, s_y) with a bending strain stop the stretch at [`QUICK_BENT_COMPRESSION`]: beyond it
    /// the generated stockinette, bent by 58–160 /m, has no equilibrium that keeps its yarns apart (the guarded
    /// solves stall) or a jamming wall a 6 × 6 grid cannot resolve, and drapes stay far inside (README, "Set-up").
    pub fn quick() -> Self {
        let base = Plan::default();
        let ranges_2d = base
            .pairs
            .iter()
            .map(|&[a, b]| {
                let bent = [a, b].iter().any(|c| c.index() >= 3);
                let range = |c: StrainComponent| {
                    let mut r = base.ranges.get(c.index());
                    if bent && matches!(c, StrainComponent::Sx | StrainComponent::Sy) {
                        r[0] = r[0].max(QUICK_BENT_COMPRESSION);
                    }
                    r
                };
                [range(a), range(b)]
            })
            .collect();
        Plan {
            count_1d: 30,
            count_2d: 6,
            ranges_2d: Some(ranges_2d),
            ..base
        }
    }

    /// The held-out plan: only the in-plane grid of [`InPlaneGrid::original`] (729 samples, no 1D ranges or
    /// 2D grids).
    pub fn holdout() -> Self {
        Plan {
            count_1d: 0,
            count_2d: 0,
            pairs: vec![],
            grid: Some(InPlaneGrid::original()),
            ..Plan::default()
        }
    }

    /// Index of the first in-plane grid sample (after the 1D ranges and the 2D grids).
    pub fn grid_start(&self) -> usize {
        self.range_2d(self.pairs.len()).start
    }

    /// Samples of the 1D range of strain `k`.
    pub fn n_1d(&self, k: usize) -> usize {
        self.counts_1d.map_or(self.count_1d, |c| c[k])
    }

    /// Samples per axis [first, second] of pair `p`'s grid.
    pub fn n_2d(&self, p: usize) -> [usize; 2] {
        self.counts_2d
            .as_ref()
            .and_then(|c| c.get(p).copied())
            .unwrap_or([self.count_2d; 2])
    }

    /// Sample indices of the 1D range of strain `k` (`k` = 5: the empty range after the last).
    pub fn range_1d(&self, k: usize) -> std::ops::Range<usize> {
        let start = (0..k).fold(0usize, |n, j| n.saturating_add(self.n_1d(j)));
        start..start.saturating_add(if k < 5 { self.n_1d(k) } else { 0 })
    }

    /// Sample indices of pair `p`'s grid, row-major (`p` = number of pairs: the empty range after the last).
    pub fn range_2d(&self, p: usize) -> std::ops::Range<usize> {
        let start = (0..p).fold(self.range_1d(5).start, |n, q| {
            let [a, b] = self.n_2d(q);
            n.saturating_add(a.saturating_mul(b))
        });
        let [a, b] = if p < self.pairs.len() {
            self.n_2d(p)
        } else {
            [0, 0]
        };
        start..start.saturating_add(a.saturating_mul(b))
    }

    /// The canonical JSON (compact, fields in declaration order); the plan hash is taken over it.
    pub fn canonical_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// The plan hash: FNV-1a 64 of the canonical JSON.
    pub fn hash(&self) -> u64 {
        fnv1a64(self.canonical_json().as_bytes())
    }

    /// The values of strain `k` on its 1D range.
    pub fn axis_1d(&self, k: usize) -> Vec<f64> {
        let [lo, hi] = self.ranges.get(k);
        sample_range(k, lo, hi, self.n_1d(k))
    }

    /// The values of side `side` (0: the first strain, 1: the second) of pair `p`'s grid axis: SAMPLERANGE over
    /// the pair's own range when the plan has `ranges_2d`, else over the strain's range.
    pub fn axis_2d(&self, p: usize, side: usize) -> Vec<f64> {
        let k = self.pair_indices()[p][side];
        let [lo, hi] = match &self.ranges_2d {
            Some(r) => r[p][side],
            None => self.ranges.get(k),
        };
        sample_range(k, lo, hi, self.n_2d(p)[side])
    }

    /// Number of samples: the 1D ranges, the 2D grids and the in-plane grid's points (`usize::MAX` when that
    /// overflows, which [`Plan::validate`] rejects).
    pub fn len(&self) -> usize {
        self.checked_len().unwrap_or(usize::MAX)
    }

    /// Whether the plan has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn pair_indices(&self) -> Vec<[usize; 2]> {
        self.pairs
            .iter()
            .map(|[a, b]| [a.index(), b.index()])
            .collect()
    }

    /// All samples in plan order: the 1D ranges of s_x, s_a, s_y, Π₀₀, Π₁₁ (others 0), then each pair's grid,
    /// row-major (index i of the first strain, j of the second: i · (second axis count) + j).
    pub fn samples(&self) -> Vec<Sample> {
        let hash = self.hash();
        let mut zs: Vec<[f64; 5]> = Vec::with_capacity(self.len().min(MAX_PLAN_SAMPLES));
        for k in 0..5 {
            for v in self.axis_1d(k) {
                let mut z = [0.0; 5];
                z[k] = v;
                zs.push(z);
            }
        }
        for (p, [a, b]) in self.pair_indices().into_iter().enumerate() {
            let va = self.axis_2d(p, 0);
            let vb = self.axis_2d(p, 1);
            for x in &va {
                for y in &vb {
                    let mut z = [0.0; 5];
                    z[a] = *x;
                    z[b] = *y;
                    zs.push(z);
                }
            }
        }
        if let Some(g) = &self.grid {
            for &a in &g.s_x {
                for &b in &g.s_a {
                    for &c in &g.s_y {
                        zs.push([a, b, c, 0.0, 0.0]);
                    }
                }
            }
        }
        zs.into_iter()
            .enumerate()
            .map(|(index, z)| Sample {
                index,
                id: format!("{hash:016x}-{index}"),
                z,
            })
            .collect()
    }

    /// The continuation chains (module docs): one per 1D range, then one per 2D grid. Every sample appears in
    /// exactly one chain, once.
    pub fn chains(&self) -> Vec<Chain> {
        let mut chains = Vec::new();
        for k in 0..5 {
            let base = self.range_1d(k).start;
            let values = self.axis_1d(k);
            if values.is_empty() {
                continue;
            }
            let (origin, up, down) = rays(&values);
            let mut steps = vec![Step {
                sample: base + origin,
                from: None,
            }];
            push_ray(&mut steps, 0, up.into_iter().map(|i| base + i));
            push_ray(&mut steps, 0, down.into_iter().map(|i| base + i));
            chains.push(Chain { steps });
        }
        for p in 0..self.pairs.len() {
            let [na, nb] = self.n_2d(p);
            if na == 0 || nb == 0 {
                continue;
            }
            let base = self.range_2d(p).start;
            let at = |i: usize, j: usize| base + i * nb + j;
            let steps = grid_chain(
                &rays(&self.axis_2d(p, 0)),
                &rays(&self.axis_2d(p, 1)),
                na,
                at,
            );
            chains.push(Chain { steps });
        }
        // the in-plane grid: one chain per s_x value, cold at (s_x, s_a ≈ 0, s_y ≈ 0), then the s_a line as two
        // rays, then every s_y line as two rays from it
        if let Some(g) = &self.grid {
            let base = self.grid_start();
            let (na, ny) = (g.s_a.len(), g.s_y.len());
            let (sa, sy) = (rays(&g.s_a), rays(&g.s_y));
            for i in 0..g.s_x.len() {
                let at = |a: usize, y: usize| base + (i * na + a) * ny + y;
                let steps = grid_chain(&sa, &sy, na, at);
                chains.push(Chain { steps });
            }
        }
        chains
    }
}

#[cfg(test)]
mod tests;
