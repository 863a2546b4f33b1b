//! Checking a sampling plan (`docs/sampling.md`, "Sampling plan (C4)"; docs/robustness.md): the
//! admissible strains and sizes of a plan, [`Plan::validate`], and reading plan JSON with errors that name the
//! file and field ([`Plan::from_json`], [`Plan::load`]).

use super::{Plan, Ranges};
use crate::strain::StrainComponent;
use std::path::Path;

/// The most samples a plan may have (1D ranges, 2D grids and in-plane grid together), and so the largest any one
/// count (`count_1d`, `count_2d`, an entry of `counts_1d` / `counts_2d`, an axis of `grid`) may be. The
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

/// A bad plan: the file (if any), the field and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}plan field {field}: {message}", file.as_ref().map_or(String::new(), |f| format!("{f}: ")))]
pub struct PlanError {
    /// the plan file, if the plan came from one
    pub file: Option<String>,
    /// the field at fault
    pub field: String,
    /// what is wrong
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

impl Plan {
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
    /// total at most [`MAX_PLAN_SAMPLES`] (`docs/sampling.md`, "Sampling plan (C4)"). Every runner and
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
}
