//! Sampling plans (`../shared/design/04-sampling-fitting.md`, section "Sampling plan (C4)").
//!
//! A [`Plan`] lists per-strain ranges, the sample counts of the 1D ranges and of the 2D grids, and the strain
//! pairs of the grids. Its samples are enumerated in a fixed order (the five 1D ranges, then the grids row-major),
//! each with a stable id: the FNV-1a 64 hash of the plan's canonical JSON and the sample's index. For
//! warm-started continuation the samples are grouped into [`Chain`]s: each 1D range is two rays solved outward
//! from the sample nearest z = 0; each 2D grid first solves its axis (the column nearest zero in the second
//! strain) as two rays from the point nearest the origin, then continues every row as two rays from that axis.

use crate::strain::StrainComponent;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// SAMPLERANGE(z, z_min, z_max, N) of the design: for the stretches s_x, s_y (`k` = 0, 2)
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

/// The most samples a plan may have (1D ranges, 2D grids and in-plane grid together), and so the largest any one
/// count (`count_1d`, `count_2d`, an entry of `counts_1d` / `counts_2d`, an axis of `grid`) may be. The design's
/// default plan has 23 250 samples; 10⁶ is 43 times that, weeks of solves on a workstation, while the enumeration
/// ([`Plan::samples`], about 100 bytes a sample) stays near 100 MB. Checked (with overflow-free arithmetic) by
/// [`Plan::validate`] before anything is allocated.
pub const MAX_PLAN_SAMPLES: usize = 1_000_000;

/// The largest stretch s_x, s_y a plan may sample (a stretch ratio of 4). The built-in plans reach 0.96, the
/// in-plane grid 1.0 and the plans under `validation/plans/` 0.99; beyond a ratio of about 2 a yarn-level pattern
/// has straightened its yarns and only stretches the yarns themselves (orders of magnitude stiffer), so larger
/// values only make the solves long or fail. The lower limit is [`MIN_PLAN_STRETCH`].
pub const MAX_PLAN_STRETCH: f64 = 3.0;

/// The smallest s_x, s_y a plan may sample (up to rounding: the test is 1 + s ≥ the micro solver's smallest
/// stretch [`crate::micro::strain::MIN_STRETCH`]), so that every strain a plan passes is one the solver accepts.
pub const MIN_PLAN_STRETCH: f64 = crate::micro::strain::MIN_STRETCH - 1.0;

/// |s_a| must stay below this (exclusive): s_a is the cosine of the angle between the deformed warp and weft
/// directions, so |s_a| = 1 folds them onto one line. The built-in plans reach 0.7, `validation/plans/` 0.75.
pub const MAX_PLAN_SHEAR: f64 = 1.0;

/// The largest |Π₀₀|, |Π₁₁| (1/m) a plan may sample: a radius of curvature of 1 mm, about a period of the
/// patterns (a cloth bent tighter folds onto itself). The built-in plans reach 160 m⁻¹, `validation/plans/` 230.
pub const MAX_PLAN_CURVATURE: f64 = 1000.0;

/// Why value `v` of strain `k` (0..5: s_x, s_a, s_y, Π₀₀, Π₁₁) is not admissible in a plan, if it is not: finite,
/// stretches in [[`MIN_PLAN_STRETCH`], [`MAX_PLAN_STRETCH`]], |s_a| < [`MAX_PLAN_SHEAR`], |Π| ≤
/// [`MAX_PLAN_CURVATURE`].
pub fn inadmissible(k: usize, v: f64) -> Option<String> {
    let name = StrainComponent::NAMES[k];
    if !v.is_finite() {
        return Some(format!("{name} = {v} is not finite"));
    }
    match k {
        // the solver's own test on 1 + s, so that a plan never passes a strain the solver refuses
        0 | 2 if !(1.0 + v >= crate::micro::strain::MIN_STRETCH && v <= MAX_PLAN_STRETCH) => Some(format!(
            "{name} = {v} is outside the admissible stretches [{MIN_PLAN_STRETCH}, {MAX_PLAN_STRETCH}]"
        )),
        1 if v.abs() >= MAX_PLAN_SHEAR => Some(format!(
            "{name} = {v} is outside the admissible shears (−{MAX_PLAN_SHEAR}, {MAX_PLAN_SHEAR})"
        )),
        3 | 4 if v.abs() > MAX_PLAN_CURVATURE => Some(format!(
            "{name} = {v} is outside the admissible curvatures [−{MAX_PLAN_CURVATURE}, {MAX_PLAN_CURVATURE}] 1/m"
        )),
        _ => None,
    }
}

/// Per-strain ranges [min, max] (design defaults: s_x, s_y ∈ [−0.6, 0.96], s_a ∈ [−0.7, 0.7], Π ∈ [−160, 160]
/// m⁻¹).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ranges {
    pub s_x: [f64; 2],
    pub s_a: [f64; 2],
    pub s_y: [f64; 2],
    #[serde(rename = "II00")]
    pub ii00: [f64; 2],
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

/// A sampling plan (`04-sampling-fitting.md`, "Sampling plan (C4)"), stored as JSON.
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
    /// off the sampled planes, which the additive model must predict (`04-sampling-fitting.md`, "Quality
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
    pub s_x: Vec<f64>,
    pub s_a: Vec<f64>,
    pub s_y: Vec<f64>,
}

impl InPlaneGrid {
    /// The 9×9×9 grid of the original displacement data (`06-verification.md`, item 3c): s_x, s_y ∈ {−0.2, −0.1,
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

/// The design's nine pairs: {s_x,s_a,s_y}² unordered distinct, then {s_x,s_a,s_y}×{Π₀₀,Π₁₁}.
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

/// The message for a pair that does not name two different strains.
fn different_strains(a: &str, b: &str) -> String {
    format!(
        "[{a:?}, {b:?}] must name two different strains of {}",
        StrainComponent::NAMES.join(", ")
    )
}

/// The pairs of a plan file by name, or the field at fault (`pairs[i]`) with the message.
fn parse_pairs(names: Vec<[String; 2]>) -> Result<Vec<[StrainComponent; 2]>, (String, String)> {
    names
        .iter()
        .enumerate()
        .map(|(i, [a, b])| match (a.parse(), b.parse()) {
            (Ok(ka), Ok(kb)) => Ok([ka, kb]),
            _ => Err((format!("pairs[{i}]"), different_strains(a, b))),
        })
        .collect()
}

impl Default for Plan {
    /// The design's default plan: 5 × 150 + 9 × 50² = 23 250 samples.
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

/// A bad plan: the file (if any), the field and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}plan field {field}: {message}", file.as_ref().map_or(String::new(), |f| format!("{f}: ")))]
pub struct PlanError {
    pub file: Option<String>,
    pub field: String,
    pub message: String,
}

/// Why a field of a plan file could not be read (before the field's name is attached).
#[derive(Debug, thiserror::Error)]
enum FieldError {
    #[error("missing")]
    Missing,
    #[error(transparent)]
    Invalid(#[from] serde_json::Error),
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
    pub sample: usize,
    pub from: Option<usize>,
}

/// A continuation chain: steps in solve order; every step's `from` is an earlier step, so a chain is solved
/// sequentially and its results depend only on the chain.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chain {
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
    /// samples), default ranges and pairs, so that the whole job stays within minutes on 2 cores.
    pub fn quick() -> Self {
        Plan {
            count_1d: 30,
            count_2d: 6,
            ..Plan::default()
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

    /// The parts of the plan's enumeration with the field that sets each one's size: the 1D ranges (`count_1d` or
    /// `counts_1d[k]`), the 2D grids (`count_2d` or `counts_2d[p]`) and the in-plane grid (`grid`); a size that
    /// overflows `usize` is `None`.
    fn parts(&self) -> Vec<(String, Option<usize>)> {
        let mut parts: Vec<(String, Option<usize>)> = (0..5)
            .map(|k| match self.counts_1d {
                Some(_) => (format!("counts_1d[{k}]"), Some(self.n_1d(k))),
                None => ("count_1d".to_string(), Some(self.count_1d)),
            })
            .collect();
        for p in 0..self.pairs.len() {
            let [a, b] = self.n_2d(p);
            let field = match self.counts_2d {
                Some(_) => format!("counts_2d[{p}]"),
                None => "count_2d".to_string(),
            };
            parts.push((field, a.checked_mul(b)));
        }
        if let Some(g) = &self.grid {
            parts.push(("grid".to_string(), g.checked_len()));
        }
        parts
    }

    /// Number of samples, `None` when it overflows `usize`.
    pub fn checked_len(&self) -> Option<usize> {
        self.parts()
            .into_iter()
            .try_fold(0usize, |n, (_, part)| n.checked_add(part?))
    }

    /// Check the counts against [`MAX_PLAN_SAMPLES`] (each count, then the total, in checked arithmetic): the
    /// field at fault and the message.
    fn validate_counts(&self) -> Result<(), (String, String)> {
        let too_many = |n: String| {
            format!("{n} samples: more than the limit of {MAX_PLAN_SAMPLES} samples per plan")
        };
        let mut counts: Vec<(String, usize)> = vec![("count_1d".into(), self.count_1d)];
        counts.push(("count_2d".into(), self.count_2d));
        if let Some(c) = &self.counts_1d {
            counts.extend(
                c.iter()
                    .enumerate()
                    .map(|(k, &n)| (format!("counts_1d[{k}]"), n)),
            );
        }
        if let Some(c) = &self.counts_2d {
            for (p, pair) in c.iter().enumerate() {
                counts.extend(
                    pair.iter()
                        .enumerate()
                        .map(|(s, &n)| (format!("counts_2d[{p}][{s}]"), n)),
                );
            }
        }
        if let Some(g) = &self.grid {
            for (name, axis) in [("s_x", &g.s_x), ("s_a", &g.s_a), ("s_y", &g.s_y)] {
                counts.push((format!("grid.{name}"), axis.len()));
            }
        }
        if let Some((field, n)) = counts.into_iter().find(|(_, n)| *n > MAX_PLAN_SAMPLES) {
            return Err((field, too_many(n.to_string())));
        }
        let mut total = 0usize;
        for (field, part) in self.parts() {
            match part.and_then(|n| total.checked_add(n)) {
                Some(n) if n <= MAX_PLAN_SAMPLES => total = n,
                Some(n) => return Err((field, too_many(format!("with this part, {n}")))),
                None => return Err((field, too_many("with this part, more than 2⁶⁴".into()))),
            }
        }
        Ok(())
    }

    /// Check ranges, counts and pairs: every range value and grid value admissible ([`inadmissible`]: stretches in
    /// [[`MIN_PLAN_STRETCH`], [`MAX_PLAN_STRETCH`]], |s_a| < [`MAX_PLAN_SHEAR`], |Π| ≤ [`MAX_PLAN_CURVATURE`]), every count and the
    /// total at most [`MAX_PLAN_SAMPLES`] (`04-sampling-fitting.md`, "Sampling plan (C4)"). Every runner and
    /// [`Plan::from_json`] call this before enumerating a sample.
    pub fn validate(&self) -> Result<(), PlanError> {
        let err = |field: String, message: String| PlanError {
            file: None,
            field,
            message,
        };
        for (k, name) in StrainComponent::NAMES.iter().enumerate() {
            let [lo, hi] = self.ranges.get(k);
            if !lo.is_finite() || !hi.is_finite() || lo > hi {
                return Err(err(
                    format!("ranges.{name}"),
                    format!("[{lo}, {hi}] is not a finite range with min ≤ max"),
                ));
            }
            if let Some(m) = inadmissible(k, lo).or_else(|| inadmissible(k, hi)) {
                return Err(err(format!("ranges.{name}"), m));
            }
            if (k == 1 || k >= 3) && (lo > 0.0 || hi < 0.0) {
                return Err(err(
                    format!("ranges.{name}"),
                    format!("[{lo}, {hi}] must contain 0 (SAMPLERANGE mirrors √|z| about 0)"),
                ));
            }
        }
        if let Some(c2) = &self.counts_2d {
            if c2.len() != self.pairs.len() {
                return Err(err(
                    "counts_2d".into(),
                    format!("{} entries for {} pairs", c2.len(), self.pairs.len()),
                ));
            }
        }
        self.validate_counts().map_err(|(f, m)| err(f, m))?;
        if let Some(r2) = &self.ranges_2d {
            if r2.len() != self.pairs.len() {
                return Err(err(
                    "ranges_2d".into(),
                    format!("{} entries for {} pairs", r2.len(), self.pairs.len()),
                ));
            }
            for (p, sides) in r2.iter().enumerate() {
                for (side, &[lo, hi]) in sides.iter().enumerate() {
                    let k = self.pairs[p][side].index();
                    if !(lo.is_finite() && hi.is_finite() && lo <= 0.0 && 0.0 <= hi)
                        || ((k == 0 || k == 2) && lo <= -1.0)
                    {
                        return Err(err(
                            format!("ranges_2d[{p}][{side}]"),
                            format!(
                                "[{lo}, {hi}] must be a finite range containing 0 (and above −1 for a stretch)"
                            ),
                        ));
                    }
                    if let Some(m) = inadmissible(k, lo).or_else(|| inadmissible(k, hi)) {
                        return Err(err(format!("ranges_2d[{p}][{side}]"), m));
                    }
                }
            }
        }
        if let Some(g) = &self.grid {
            for (name, values) in [("s_x", &g.s_x), ("s_a", &g.s_a), ("s_y", &g.s_y)] {
                if values.is_empty() {
                    return Err(err(format!("grid.{name}"), "empty".into()));
                }
                let k = StrainComponent::NAMES
                    .iter()
                    .position(|n| *n == name)
                    .unwrap_or(0);
                if let Some(m) = values.iter().find_map(|&v| inadmissible(k, v)) {
                    return Err(err(format!("grid.{name}"), m));
                }
            }
        }
        for (i, [a, b]) in self.pairs.iter().enumerate() {
            if a == b {
                return Err(err(
                    format!("pairs[{i}]"),
                    different_strains(a.name(), b.name()),
                ));
            }
            if self.pairs[..i]
                .iter()
                .any(|[c, d]| (c == a && d == b) || (c == b && d == a))
            {
                return Err(err(
                    format!("pairs[{i}]"),
                    format!("[{:?}, {:?}] is listed twice", a.name(), b.name()),
                ));
            }
            if !a.is_in_plane() && !b.is_in_plane() {
                return Err(err(
                    format!("pairs[{i}]"),
                    "two bending strains at once are not a supported strain direction".into(),
                ));
            }
        }
        Ok(())
    }

    /// Parse and validate a plan from JSON text; `file` names the source in errors, and every error names the
    /// field (`count_1d`, `ranges.s_x`, `pairs[2]`, …).
    pub fn from_json(text: &str, file: Option<&str>) -> Result<Self, PlanError> {
        let err = |field: &str, message: String| PlanError {
            file: file.map(str::to_string),
            field: field.to_string(),
            message,
        };
        // a UTF-8 byte-order mark is accepted, as in `.pyp` files
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| err("-", format!("not JSON: {e}")))?;
        let obj = value
            .as_object()
            .ok_or_else(|| err("-", "a plan is a JSON object".into()))?;
        const FIELDS: [&str; 8] = [
            "ranges",
            "count_1d",
            "count_2d",
            "pairs",
            "ranges_2d",
            "grid",
            "counts_1d",
            "counts_2d",
        ];
        for key in obj.keys() {
            if !FIELDS.contains(&key.as_str()) {
                return Err(err(
                    key,
                    format!("unknown field (expected one of {})", FIELDS.join(", ")),
                ));
            }
        }
        fn field<T: serde::de::DeserializeOwned>(
            obj: &serde_json::Map<String, serde_json::Value>,
            key: &str,
        ) -> Result<T, FieldError> {
            let v = obj.get(key).ok_or(FieldError::Missing)?;
            Ok(serde_json::from_value(v.clone())?)
        }
        // an absent or null optional field is None
        fn optional<T: serde::de::DeserializeOwned>(
            obj: &serde_json::Map<String, serde_json::Value>,
            key: &str,
        ) -> Result<Option<T>, FieldError> {
            match obj.get(key) {
                None | Some(serde_json::Value::Null) => Ok(None),
                Some(_) => field(obj, key).map(Some),
            }
        }
        let ranges_obj = obj
            .get("ranges")
            .ok_or_else(|| err("ranges", "missing".into()))?
            .as_object()
            .ok_or_else(|| err("ranges", "expected an object of [min, max] pairs".into()))?;
        for key in ranges_obj.keys() {
            if key.parse::<StrainComponent>().is_err() {
                return Err(err(
                    &format!("ranges.{key}"),
                    format!(
                        "unknown strain (expected {})",
                        StrainComponent::NAMES.join(", ")
                    ),
                ));
            }
        }
        let mut r = [[0.0; 2]; 5];
        for (k, name) in StrainComponent::NAMES.iter().enumerate() {
            r[k] = field(ranges_obj, name)
                .map_err(|m| err(&format!("ranges.{name}"), m.to_string()))?;
        }
        let plan = Plan {
            ranges: Ranges {
                s_x: r[0],
                s_a: r[1],
                s_y: r[2],
                ii00: r[3],
                ii11: r[4],
            },
            count_1d: field(obj, "count_1d").map_err(|m| err("count_1d", m.to_string()))?,
            count_2d: field(obj, "count_2d").map_err(|m| err("count_2d", m.to_string()))?,
            pairs: parse_pairs(field(obj, "pairs").map_err(|m| err("pairs", m.to_string()))?)
                .map_err(|(f, m)| err(&f, m))?,
            ranges_2d: optional(obj, "ranges_2d").map_err(|m| err("ranges_2d", m.to_string()))?,
            grid: optional(obj, "grid").map_err(|m| err("grid", m.to_string()))?,
            counts_1d: optional(obj, "counts_1d").map_err(|m| err("counts_1d", m.to_string()))?,
            counts_2d: optional(obj, "counts_2d").map_err(|m| err("counts_2d", m.to_string()))?,
        };
        plan.validate().map_err(|mut e| {
            e.file = file.map(str::to_string);
            e
        })?;
        Ok(plan)
    }

    /// Load a plan file.
    pub fn load(path: &Path) -> Result<Self, PlanError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| PlanError {
            file: Some(name.clone()),
            field: "-".into(),
            message: format!("cannot read: {e}"),
        })?;
        Plan::from_json(&text, Some(&name))
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
mod tests {
    use super::*;

    #[test]
    fn plan_stretch_limits_agree_with_the_solver() {
        // up to the plan's own upper limit, a plan accepts exactly the stretches the micro solver accepts
        for v in [
            -1.0,
            -0.95,
            -0.9,
            MIN_PLAN_STRETCH,
            -0.899_999_999,
            -0.85,
            0.0,
            2.5,
            3.0,
        ] {
            let plan = inadmissible(0, v).is_none();
            let solver = crate::micro::MacroStrain::in_plane(v, 0.0, 0.0)
                .validate()
                .is_ok();
            assert_eq!(plan, solver, "s_x = {v}");
        }
        assert!(inadmissible(2, 3.01).is_some());
    }

    #[test]
    fn holdout_grid_samples_and_chains() {
        let p = Plan::holdout();
        assert_eq!(p.len(), 729);
        let s = p.samples();
        assert_eq!(s[0].z, [-0.2, -0.7, -0.2, 0.0, 0.0]);
        assert_eq!(s[728].z, [1.0, 0.7, 1.0, 0.0, 0.0]);
        let chains = p.chains();
        assert_eq!(chains.len(), 9);
        let mut seen = vec![0; 729];
        for c in &chains {
            assert!(c.steps[0].from.is_none());
            assert_eq!(s[c.steps[0].sample].z[1], 0.0);
            for (k, st) in c.steps.iter().enumerate() {
                seen[st.sample] += 1;
                if k > 0 {
                    assert!(st.from.unwrap() < k);
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
        // round trip, and plans without a grid keep their JSON (and hash)
        assert_eq!(Plan::from_json(&p.canonical_json(), None).unwrap(), p);
        assert!(!Plan::default().canonical_json().contains("grid"));
        let mut bad = p.clone();
        bad.grid.as_mut().unwrap().s_a[0] = 1.0;
        assert!(bad.validate().unwrap_err().field == "grid.s_a");
    }

    #[test]
    fn per_pair_2d_ranges() {
        let mut p = Plan::reduced();
        let base_hash = p.hash();
        let mut r: Vec<[[f64; 2]; 2]> = p
            .pairs
            .iter()
            .map(|[a, b]| {
                let (ka, kb) = (a.index(), b.index());
                [p.ranges.get(ka), p.ranges.get(kb)]
            })
            .collect();
        r[0] = [[-0.1, 0.84], [-0.6, 0.6]];
        p.ranges_2d = Some(r);
        p.validate().unwrap();
        assert_ne!(p.hash(), base_hash);
        let s = p.samples();
        let g0: Vec<&Sample> = s[150..250].iter().collect();
        let min_sx = g0.iter().map(|s| s.z[0]).fold(f64::INFINITY, f64::min);
        let max_sa = g0.iter().map(|s| s.z[1]).fold(f64::NEG_INFINITY, f64::max);
        assert!((min_sx + 0.1).abs() < 1e-12 && (max_sa - 0.6).abs() < 1e-12);
        // the other grids keep the strain ranges
        assert_eq!(s[250].z[0], -0.6000000000000001);
        assert_eq!(Plan::from_json(&p.canonical_json(), None).unwrap(), p);
        // one entry per pair, each containing 0
        let mut bad = p.clone();
        bad.ranges_2d.as_mut().unwrap().pop();
        assert_eq!(bad.validate().unwrap_err().field, "ranges_2d");
        let mut bad = p.clone();
        bad.ranges_2d.as_mut().unwrap()[3][1] = [10.0, 20.0];
        assert_eq!(bad.validate().unwrap_err().field, "ranges_2d[3][1]");
    }

    #[test]
    fn counts() {
        let p = Plan::default();
        assert_eq!(p.len(), 5 * 150 + 9 * 2500);
        assert_eq!(p.len(), 23_250);
        assert_eq!(p.samples().len(), 23_250);
        assert_eq!(Plan::reduced().samples().len(), 5 * 30 + 9 * 100);
        assert_eq!(p.pairs.len(), 9);
    }

    #[test]
    fn sample_range_endpoints_and_densification() {
        let s = sample_range(0, -0.6, 0.96, 150);
        assert_eq!(s.len(), 150);
        assert!((s[0] + 0.6).abs() < 1e-12 && (s[149] - 0.96).abs() < 1e-12);
        // denser towards compression: steps grow
        let d: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(d.iter().all(|v| *v > 0.0));
        assert!(d.windows(2).all(|w| w[1] > w[0]));
        let a = sample_range(1, -0.7, 0.7, 51);
        assert!((a[0] + 0.7).abs() < 1e-12 && (a[50] - 0.7).abs() < 1e-12);
        assert_eq!(a[25], 0.0);
        // denser near 0: steps shrink towards the middle
        let d: Vec<f64> = a.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(d[0] > d[20] && d[49] > d[30]);
        let b = sample_range(3, -160.0, 160.0, 50);
        assert!((b[0] + 160.0).abs() < 1e-9 && (b[49] - 160.0).abs() < 1e-9);
        assert!(b.windows(2).all(|w| w[1] > w[0]));
        // exact formula at one interior point
        let lo = 0.4f64.powf(0.1);
        let hi = 1.96f64.powf(0.1);
        let v = lo + (hi - lo) * 7.0 / 149.0;
        assert_eq!(s[7], v.powi(10) - 1.0);
    }

    #[test]
    fn ids_are_stable() {
        // the hash of the default plan is fixed across runs and builds (canonical JSON, FNV-1a 64)
        let p = Plan::default();
        assert_eq!(p.hash(), fnv1a64(p.canonical_json().as_bytes()));
        assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
        let s = p.samples();
        assert_eq!(s[17].id, format!("{:016x}-17", p.hash()));
        assert_eq!(Plan::default().samples()[17].id, s[17].id);
        assert_ne!(Plan::reduced().hash(), p.hash());
        assert_eq!(
            p.hash(),
            PINNED_DEFAULT_HASH,
            "the default plan's hash changed"
        );
    }

    const PINNED_DEFAULT_HASH: u64 = 3_641_870_492_531_437_183;

    #[test]
    fn json_round_trip() {
        for p in [Plan::default(), Plan::reduced()] {
            let text = serde_json::to_string_pretty(&p).unwrap();
            let q = Plan::from_json(&text, Some("x.json")).unwrap();
            assert_eq!(p, q);
            assert_eq!(p.hash(), q.hash());
        }
    }

    #[test]
    fn bad_json_errors_name_file_and_field() {
        let good = serde_json::to_value(Plan::reduced()).unwrap();
        let cases: Vec<(serde_json::Value, &str)> = vec![
            (
                {
                    let mut v = good.clone();
                    v["count_1d"] = "ten".into();
                    v
                },
                "count_1d",
            ),
            (
                {
                    let mut v = good.clone();
                    v["extra"] = 1.into();
                    v
                },
                "extra",
            ),
            (
                {
                    let mut v = good.clone();
                    v.as_object_mut().unwrap().remove("count_2d");
                    v
                },
                "count_2d",
            ),
            (
                {
                    let mut v = good.clone();
                    v["ranges"]["s_a"] = serde_json::json!([0.5, 0.7]);
                    v
                },
                "ranges.s_a",
            ),
            (
                {
                    let mut v = good.clone();
                    v["ranges"]["s_x"] = serde_json::json!([-1.5, 0.7]);
                    v
                },
                "ranges.s_x",
            ),
            (
                {
                    let mut v = good.clone();
                    v["ranges"]["s_q"] = serde_json::json!([0, 1]);
                    v
                },
                "ranges.s_q",
            ),
            (
                {
                    let mut v = good.clone();
                    v["pairs"][1] = serde_json::json!(["s_x", "s_z"]);
                    v
                },
                "pairs[1]",
            ),
            (
                {
                    let mut v = good.clone();
                    v["pairs"][1] = serde_json::json!(["s_a", "s_x"]);
                    v
                },
                "pairs[1]",
            ),
            (
                {
                    let mut v = good.clone();
                    v["pairs"][1] = serde_json::json!(["II00", "II11"]);
                    v
                },
                "pairs[1]",
            ),
        ];
        for (v, field) in cases {
            let e = Plan::from_json(&v.to_string(), Some("plan.json")).unwrap_err();
            assert_eq!(e.field, field, "{e}");
            let msg = e.to_string();
            assert!(msg.contains("plan.json") && msg.contains(field), "{msg}");
        }
        let e = Plan::from_json("{", Some("p.json")).unwrap_err();
        assert!(e.to_string().starts_with("p.json: "));
    }

    #[test]
    fn chains_cover_every_sample_once_and_start_near_zero() {
        let uniform = Plan {
            count_1d: 7,
            count_2d: 5,
            ..Plan::reduced()
        };
        // per-range counts: different on every range and both axes of every grid
        let per_range = Plan {
            counts_1d: Some([7, 4, 9, 5, 6]),
            counts_2d: Some((0..9).map(|p| [3 + p % 4, 5 + p % 3]).collect()),
            ..uniform.clone()
        };
        assert_eq!(
            per_range.len(),
            31 + (0..9).map(|p| (3 + p % 4) * (5 + p % 3)).sum::<usize>()
        );
        let text = serde_json::to_string(&per_range).unwrap();
        assert_eq!(Plan::from_json(&text, None).unwrap(), per_range);
        assert!(!serde_json::to_string(&uniform).unwrap().contains("counts_"));
        for p in [uniform, per_range] {
            check_chains(&p);
        }
    }

    #[test]
    fn huge_counts_are_rejected_before_any_allocation() {
        let good = serde_json::to_value(Plan::reduced()).unwrap();
        let big = serde_json::json!(u64::MAX);
        let cases: Vec<(&str, serde_json::Value, &str)> = vec![
            ("count_1d", big.clone(), "count_1d"),
            ("count_1d", 1_000_000_000u64.into(), "count_1d"),
            ("count_1d", (1u64 << 32).into(), "count_1d"),
            // 5 × 200 001 > 10⁶: each count is within the limit, the total is not
            ("count_1d", 200_001u64.into(), "count_1d"),
            ("count_2d", 100_000u64.into(), "count_2d"),
            ("count_2d", 1_000_000_000u64.into(), "count_2d"),
            // 9 × 400² = 1 440 000
            ("count_2d", 400u64.into(), "count_2d"),
            (
                "counts_1d",
                serde_json::json!([3, 3, u64::MAX, 3, 3]),
                "counts_1d[2]",
            ),
            (
                "counts_2d",
                {
                    let mut c = vec![serde_json::json!([3, 3]); 9];
                    c[4] = serde_json::json!([1u64 << 32, 1u64 << 32]);
                    c.into()
                },
                "counts_2d[4][0]",
            ),
            (
                "counts_2d",
                {
                    let mut c = vec![serde_json::json!([3, 3]); 9];
                    c[7] = serde_json::json!([1000, 1001]);
                    c.into()
                },
                "counts_2d[7]",
            ),
            (
                "grid",
                serde_json::json!({"s_x": vec![0.0; 101], "s_a": vec![0.0; 100], "s_y": vec![0.0; 100]}),
                "grid",
            ),
        ];
        for (key, value, field) in cases {
            let mut v = good.clone();
            v[key] = value;
            let e = Plan::from_json(&v.to_string(), Some("big.json")).unwrap_err();
            assert_eq!(e.field, field, "{e}");
            assert!(e.to_string().contains("1000000 samples per plan"), "{e}");
        }
        // checked arithmetic: a plan built in code with overflowing counts has no length, and len() saturates
        let p = Plan {
            count_2d: usize::MAX,
            ..Plan::reduced()
        };
        assert_eq!(p.checked_len(), None);
        assert_eq!(p.len(), usize::MAX);
        assert_eq!(p.validate().unwrap_err().field, "count_2d");
        // the limit itself is admissible
        let p = Plan {
            count_1d: 200_000,
            count_2d: 0,
            pairs: vec![],
            ..Plan::reduced()
        };
        assert_eq!(p.checked_len(), Some(MAX_PLAN_SAMPLES));
        p.validate().unwrap();
    }

    #[test]
    fn ranges_beyond_the_admissible_strains_are_rejected() {
        let good = serde_json::to_value(Plan::reduced()).unwrap();
        let cases: Vec<(&str, serde_json::Value, &str)> = vec![
            ("/ranges/s_x", serde_json::json!([-0.5, 1e23]), "ranges.s_x"),
            (
                "/ranges/s_y",
                serde_json::json!([-0.5, 1e300]),
                "ranges.s_y",
            ),
            ("/ranges/s_y", serde_json::json!([-0.5, 3.5]), "ranges.s_y"),
            (
                "/ranges/II00",
                serde_json::json!([-1e12, 1e12]),
                "ranges.II00",
            ),
            (
                "/ranges/II11",
                serde_json::json!([-0.0, 1000.5]),
                "ranges.II11",
            ),
            ("/ranges/s_a", serde_json::json!([-1e6, 1e6]), "ranges.s_a"),
            ("/ranges/s_a", serde_json::json!([-1.0, 0.5]), "ranges.s_a"),
            (
                "/grid",
                serde_json::json!({"s_x": [0.0, 5.0], "s_a": [0.0], "s_y": [0.0]}),
                "grid.s_x",
            ),
        ];
        for (pointer, value, field) in cases {
            let mut v = good.clone();
            if pointer == "/grid" {
                v["grid"] = value;
            } else {
                *v.pointer_mut(pointer).unwrap() = value;
            }
            let e = Plan::from_json(&v.to_string(), Some("r.json")).unwrap_err();
            assert_eq!(e.field, field, "{e}");
            assert!(e.to_string().starts_with("r.json: plan field "), "{e}");
        }
        let mut p = Plan::reduced();
        p.ranges_2d = Some(vec![[[-0.5, 0.5], [-0.5, 0.5]]; 9]);
        p.validate().unwrap();
        p.ranges_2d.as_mut().unwrap()[5][1] = [-2000.0, 0.0];
        assert_eq!(p.validate().unwrap_err().field, "ranges_2d[5][1]");
        // the limits themselves are admissible; every built-in plan is valid
        p.ranges_2d = None;
        p.ranges.s_x = [-0.85, MAX_PLAN_STRETCH];
        p.ranges.ii00 = [-MAX_PLAN_CURVATURE, MAX_PLAN_CURVATURE];
        p.ranges.s_a = [-0.999, 0.999];
        p.validate().unwrap();
        for p in [
            Plan::default(),
            Plan::reduced(),
            Plan::quick(),
            Plan::holdout(),
        ] {
            p.validate().unwrap();
        }
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/plans");
        let mut n = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "json") {
                Plan::load(&path).unwrap();
                n += 1;
            }
        }
        assert!(n >= 10);
    }

    #[test]
    fn a_byte_order_mark_is_accepted() {
        let text = format!("\u{feff}{}", Plan::reduced().canonical_json());
        assert_eq!(Plan::from_json(&text, None).unwrap(), Plan::reduced());
    }

    fn check_chains(p: &Plan) {
        for k in 0..5 {
            let r = p.range_1d(k);
            for (i, v) in p.axis_1d(k).into_iter().enumerate() {
                assert_eq!(p.samples()[r.start + i].z[k], v);
            }
        }
        let samples = p.samples();
        assert_eq!(samples.len(), p.len());
        let chains = p.chains();
        assert_eq!(chains.len(), 5 + 9);
        let mut seen = vec![0; p.len()];
        for c in &chains {
            assert_eq!(c.steps[0].from, None);
            let z0 = samples[c.steps[0].sample].z;
            for (i, s) in c.steps.iter().enumerate() {
                seen[s.sample] += 1;
                if i > 0 {
                    let f = s.from.unwrap();
                    assert!(f < i);
                    // each step moves one grid index along one strain, away from the origin
                    let a = samples[c.steps[f].sample].z;
                    let b = samples[s.sample].z;
                    let changed: Vec<usize> = (0..5).filter(|&k| a[k] != b[k]).collect();
                    assert_eq!(changed.len(), 1);
                    let k = changed[0];
                    assert!((b[k] - z0[k]).abs() > (a[k] - z0[k]).abs());
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
    }
}
