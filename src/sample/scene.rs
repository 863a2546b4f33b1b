//! Scene-driven sampling plans ("model only what a scene requires", `docs/cloth-simulator.md` and
//! `docs/sampling.md`, "Sampling plan (C4)"): from the strain extremes a macro run visited, a plan that
//! covers only those ranges plus a margin, at the sample spacing of a base plan.
//!
//! The macro strain z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁) has three curvature components; the plan samples the
//! curvatures along the fabric axes only (II₀₀, II₁₁), and the material's bending terms see the principal
//! curvatures. Every eigenvalue λ of II satisfies |λ| ≤ max(|II₀₀|, |II₁₁|) + |II₀₁| (Gershgorin), so both bending
//! ranges get the symmetric interval of that bound.

use super::plan::{Plan, Ranges};
use super::SampleError;
use std::path::Path;

/// The extremes of each macro strain component over a run (min, max per component of z).
#[derive(Clone, Debug, PartialEq)]
pub struct StrainExtent {
    /// componentwise minimum of z = (s_x, s_a, s_y, II₀₀, II₀₁, II₁₁)
    pub min: [f64; 6],
    /// componentwise maximum of z
    pub max: [f64; 6],
    /// steps read
    pub steps: usize,
}

impl StrainExtent {
    /// Nothing visited yet.
    pub fn empty() -> Self {
        StrainExtent {
            min: [f64::INFINITY; 6],
            max: [f64::NEG_INFINITY; 6],
            steps: 0,
        }
    }

    /// Widen by one step's extremes.
    pub fn add(&mut self, min: &[f64; 6], max: &[f64; 6]) {
        for k in 0..6 {
            self.min[k] = self.min[k].min(min[k]);
            self.max[k] = self.max[k].max(max[k]);
        }
        self.steps += 1;
    }

    /// The visited interval of each plan strain (s_x, s_a, s_y, II₀₀, II₁₁), the bending ones by the
    /// eigenvalue bound of the module docs.
    pub fn plan_intervals(&self) -> [[f64; 2]; 5] {
        let amax = |k: usize| self.min[k].abs().max(self.max[k].abs());
        let b = amax(3).max(amax(5)) + amax(4);
        [
            [self.min[0], self.max[0]],
            [self.min[1], self.max[1]],
            [self.min[2], self.max[2]],
            [-b, b],
            [-b, b],
        ]
    }

    /// Read the extremes of every line of a `hylc simulate` log (`log.jsonl`): `strain_min`/`strain_max`
    /// (`outliers` true: every triangle) or the 1st/99th percentiles `strain_p01`/`strain_p99` (false: what 98 % of
    /// the triangles visit in each step, without the few of a mesh-scale crease); errors name the file and line.
    pub fn read_log(
        path: &Path,
        into: &mut StrainExtent,
        outliers: bool,
    ) -> Result<(), SampleError> {
        let (kmin, kmax) = if outliers {
            ("strain_min", "strain_max")
        } else {
            ("strain_p01", "strain_p99")
        };
        let text = std::fs::read_to_string(path).map_err(|e| SampleError::Io {
            path: path.to_path_buf(),
            action: "cannot read",
            source: e,
        })?;
        let mut n = 0;
        for (i, line) in text.lines().enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let bad = |message: String| SampleError::Line {
                path: path.to_path_buf(),
                line: i + 1,
                message,
            };
            let v: serde_json::Value =
                serde_json::from_str(line).map_err(|e| bad(format!("not JSON: {e}")))?;
            let get = |key: &str| -> Result<[f64; 6], SampleError> {
                let a = v.get(key).and_then(|a| a.as_array()).ok_or_else(|| {
                    bad(format!(
                        "no `{key}` array (is this a `hylc simulate` log.jsonl?)"
                    ))
                })?;
                let mut out = [0.0; 6];
                if a.len() != 6 {
                    return Err(bad(format!("`{key}` has {} entries, expected 6", a.len())));
                }
                for (o, x) in out.iter_mut().zip(a) {
                    *o = x
                        .as_f64()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| bad(format!("`{key}`: {x} is not a finite number")))?;
                }
                Ok(out)
            };
            into.add(&get(kmin)?, &get(kmax)?);
            n += 1;
        }
        if n == 0 {
            return Err(SampleError::File {
                path: path.to_path_buf(),
                message: "no steps".into(),
            });
        }
        Ok(())
    }
}

/// SAMPLERANGE's spacing coordinate of strain `k` (`plan::sample_range`): (z + 1)^(1/10) for the stretches,
/// sgn(z) √|z| for the others; samples are equally spaced in it.
fn spacing_coordinate(k: usize, z: f64) -> f64 {
    if k == 0 || k == 2 {
        (z + 1.0).max(0.0).powf(0.1)
    } else {
        z.signum() * z.abs().sqrt()
    }
}

/// How a scene plan was derived, per plan strain.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ScenePlanReport {
    /// visited interval of each plan strain
    pub visited: [[f64; 2]; 5],
    /// the plan's range (visited plus margin, containing 0, clipped to the base plan's range)
    pub ranges: [[f64; 2]; 5],
    /// each range's share of the base range in the spacing coordinate
    pub fraction: [f64; 5],
    /// samples of the base plan
    pub base_samples: usize,
    /// samples of the derived plan
    pub samples: usize,
}

/// A plan covering `extent` plus `margin` (a fraction of each visited interval's length, and at least
/// `margin` × 5 % of the base range on each side of 0, so that every range keeps a neighbourhood of the rest
/// state), clipped to the base ranges, with per-range counts (`counts_1d`, `counts_2d`) scaled so that every
/// range and every grid axis keeps the base plan's sample spacing. Counts never fall below 7 (1D) and 5 (2D),
/// which the fits need.
pub fn scene_plan(base: &Plan, extent: &StrainExtent, margin: f64) -> (Plan, ScenePlanReport) {
    let visited = extent.plan_intervals();
    let mut ranges = [[0.0; 2]; 5];
    let mut fraction = [0.0; 5];
    for k in 0..5 {
        let [blo, bhi] = base.ranges.get(k);
        let [lo, hi] = visited[k];
        let pad = margin * (hi - lo).max(0.0);
        let floor = margin * 0.05 * (bhi - blo);
        let lo = (lo - pad).min(-floor).max(blo);
        let hi = (hi + pad).max(floor).min(bhi);
        ranges[k] = [lo, hi];
        fraction[k] = (spacing_coordinate(k, hi) - spacing_coordinate(k, lo))
            / (spacing_coordinate(k, bhi) - spacing_coordinate(k, blo));
    }
    // n samples over a share f of the spacing axis keep the base spacing when n − 1 ≥ f (N − 1)
    let count = |n: usize, f: f64, min: usize| {
        ((f * n.saturating_sub(1) as f64 - 1e-9).ceil().max(0.0) as usize + 1).clamp(min.min(n), n)
    };
    let plan = Plan {
        ranges: Ranges {
            s_x: ranges[0],
            s_a: ranges[1],
            s_y: ranges[2],
            ii00: ranges[3],
            ii11: ranges[4],
        },
        count_1d: base.count_1d,
        count_2d: base.count_2d,
        pairs: base.pairs.clone(),
        ranges_2d: None,
        grid: None,
        counts_1d: Some(std::array::from_fn(|k| count(base.n_1d(k), fraction[k], 7))),
        counts_2d: Some(
            base.pairs
                .iter()
                .enumerate()
                .map(|(p, [a, b])| {
                    let [na, nb] = base.n_2d(p);
                    [
                        count(na, fraction[a.index()], 5),
                        count(nb, fraction[b.index()], 5),
                    ]
                })
                .collect(),
        ),
    };
    let report = ScenePlanReport {
        visited,
        ranges,
        fraction,
        base_samples: base.len(),
        samples: plan.len(),
    };
    (plan, report)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn extent(min: [f64; 6], max: [f64; 6]) -> StrainExtent {
        let mut e = StrainExtent::empty();
        e.add(&min, &max);
        e
    }

    /// A scene that visits the whole base range gets the base plan's counts; a narrow one gets fewer samples,
    /// ranges that contain the visited interval and 0, and the base spacing on every range.
    #[test]
    fn narrow_scene_saves_samples_and_covers_what_it_visited() {
        let base = Plan::default();
        let wide = extent(
            [-0.6, -0.7, -0.6, -160.0, 0.0, -160.0],
            [0.96, 0.7, 0.96, 160.0, 0.0, 160.0],
        );
        let (p, r) = scene_plan(&base, &wide, 0.1);
        assert_eq!(p.counts_1d, Some([150; 5]));
        assert_eq!(p.counts_2d, Some(vec![[50, 50]; 9]));
        assert_eq!(r.samples, base.len());
        let narrow = extent(
            [-0.02, -0.05, -0.01, -20.0, -3.0, -10.0],
            [0.05, 0.04, 0.03, 30.0, 2.0, 5.0],
        );
        let (p, r) = scene_plan(&base, &narrow, 0.1);
        assert!(
            r.samples < base.len() / 2,
            "{} of {}",
            r.samples,
            base.len()
        );
        p.validate().expect("a valid plan");
        for k in 0..5 {
            let [lo, hi] = p.ranges.get(k);
            assert!(lo < 0.0 && hi > 0.0, "range {k} contains 0: {lo} {hi}");
            assert!(
                lo <= r.visited[k][0] && hi >= r.visited[k][1],
                "range {k} covers the visit"
            );
        }
        // bending: Gershgorin bound max(|II00|, |II11|) + |II01| = 30 + 3, plus 10 % of its 66 span
        assert!((p.ranges.ii00[1] - 33.0 * 1.0 - 6.6).abs() < 1e-12);
        // every range and grid axis keeps at most the base spacing (unless at the minimum count), and the
        // narrow s_y range gets fewer samples than the bending ranges, which the bound keeps wide
        let step = |n: usize, f: f64| f / (n - 1) as f64;
        for k in 0..5 {
            let n = p.n_1d(k);
            assert!(
                n == 7 || step(n, r.fraction[k]) <= step(base.count_1d, 1.0) + 1e-12,
                "range {k}"
            );
        }
        for (q, [a, b]) in p.pairs.iter().enumerate() {
            for (side, c) in [a, b].into_iter().enumerate() {
                let k = c.index();
                let n = p.n_2d(q)[side];
                assert!(n == 5 || step(n, r.fraction[k]) <= step(base.count_2d, 1.0) + 1e-12);
            }
        }
        assert!(p.n_1d(2) < p.n_1d(3));
    }

    /// Bad logs get one line naming the file and the line.
    #[test]
    fn bad_logs_name_file_and_line() {
        let dir = std::env::temp_dir().join(format!("hylc_scene_plan_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("log.jsonl");
        std::fs::write(
            &f,
            "{\"strain_min\":[0,0,0,0,0,0],\"strain_max\":[0,0,0,0,0,0]}\n{\"step\":2}\n",
        )
        .unwrap();
        let e = StrainExtent::read_log(&f, &mut StrainExtent::empty(), true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("log.jsonl:2: no `strain_min`"), "{e}");
        std::fs::write(
            &f,
            "{\"strain_min\":[0,0,0,0,0],\"strain_max\":[0,0,0,0,0,0]}\n",
        )
        .unwrap();
        let e = StrainExtent::read_log(&f, &mut StrainExtent::empty(), true)
            .unwrap_err()
            .to_string();
        assert!(e.contains(":1: `strain_min` has 5 entries"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
