//! Warnings that an input is suspect: the run goes on, and the binary prints each as one line on stderr
//! (`docs/command-line.md`, "Warnings").
//!
//! - [`StrainVisits`] / [`StrainsOutsideKnots`]: a cloth run's strains left the fitted knots of its material, where
//!   ψ extrapolates;
//! - [`coarse_mesh`] / [`CoarseMesh`]: a mesh edge longer than a quarter of the cloth's bounding-box diagonal;
//! - [`radius_overridden`] / [`RadiusOverridden`]: a yarn file's radius that the pattern's own radius replaces.

use crate::shell::solver::StepReport;
use crate::shell::ElementModel;
use crate::strain::Strain6;
use std::fmt;
use std::path::{Path, PathBuf};

/// The strains a cloth run visited, step by step, against the knot range of each strain component of its material
/// (the material as the scene reduced it: without bending terms when bending is off, without 2D terms with
/// `only_1d`).
///
/// The knot range of s_x, s_a, s_y is [`crate::material::Material::knot_range`]. The bending terms see the
/// eigenvalues of β II (β the scene's bending scale); a diagonal entry II₀₀ or II₁₁ lies between them, so one
/// outside the knots of the bending terms (both, when the material has both) means a bending term extrapolates.
/// II₀₁ has no knots of its own and is not checked.
#[derive(Clone, Debug)]
pub struct StrainVisits {
    /// the knot range of each component of z in z's units, `None` where the material has no knots
    pub knots: [Option<(f64, f64)>; 6],
    /// componentwise minimum of z over every triangle and step
    pub min: [f64; 6],
    /// componentwise maximum of z over every triangle and step
    pub max: [f64; 6],
    /// steps seen
    pub steps: usize,
    /// steps with some triangle outside the knots (by the step's `strain_min`/`strain_max`)
    pub steps_outside: usize,
    /// steps whose 1st or 99th percentile lay outside the knots (at least 1 % of the triangles outside)
    pub steps_bulk_outside: usize,
}

fn valid(r: (f64, f64)) -> Option<(f64, f64)> {
    (r.0.is_finite() && r.1.is_finite() && r.0 <= r.1).then_some(r)
}

impl StrainVisits {
    /// Nothing visited yet, against the knots of `model`'s material.
    pub fn new(model: &ElementModel) -> Self {
        let m = &model.material;
        let mut knots = [None; 6];
        for (k, slot) in knots.iter_mut().enumerate().take(3) {
            *slot = valid(m.knot_range(k));
        }
        if model.bending && model.bending_scale > 0.0 {
            let both = match (valid(m.knot_range(3)), valid(m.knot_range(4))) {
                (Some(a), Some(b)) => valid((a.0.max(b.0), a.1.min(b.1))),
                (a, b) => a.or(b),
            };
            let b = model.bending_scale;
            knots[3] = both.map(|(lo, hi)| (lo / b, hi / b));
            knots[5] = knots[3];
        }
        StrainVisits {
            knots,
            min: [f64::INFINITY; 6],
            max: [f64::NEG_INFINITY; 6],
            steps: 0,
            steps_outside: 0,
            steps_bulk_outside: 0,
        }
    }

    fn outside(&self, lo: &[f64; 6], hi: &[f64; 6]) -> bool {
        self.knots.iter().enumerate().any(|(k, r)| match r {
            Some((a, b)) => lo[k] < *a || hi[k] > *b,
            None => false,
        })
    }

    /// Add one step's report (its extremes and percentiles).
    pub fn add(&mut self, r: &StepReport) {
        for k in 0..6 {
            self.min[k] = self.min[k].min(r.strain_min[k]);
            self.max[k] = self.max[k].max(r.strain_max[k]);
        }
        self.steps += 1;
        self.steps_outside += usize::from(self.outside(&r.strain_min, &r.strain_max));
        self.steps_bulk_outside += usize::from(self.outside(&r.strain_p01, &r.strain_p99));
    }

    /// The warning when some component left its knots; `log` is the run's `log.jsonl`, named in the advice.
    pub fn warning(&self, log: Option<&Path>) -> Option<StrainsOutsideKnots> {
        let components: Vec<ComponentOutside> = (0..6)
            .filter_map(|k| {
                let (lo, hi) = self.knots[k]?;
                (self.min[k] < lo || self.max[k] > hi).then(|| ComponentOutside {
                    name: Strain6::NAMES[k],
                    visited: (self.min[k], self.max[k]),
                    knots: (lo, hi),
                })
            })
            .collect();
        (!components.is_empty()).then(|| StrainsOutsideKnots {
            components,
            steps: self.steps,
            steps_outside: self.steps_outside,
            steps_bulk_outside: self.steps_bulk_outside,
            log: log.map(Path::to_path_buf),
        })
    }
}

/// One strain component a run took outside its knots.
#[derive(Clone, Debug, PartialEq)]
pub struct ComponentOutside {
    /// the component's name (`s_x`, `s_a`, `s_y`, `II00`, `II11`)
    pub name: &'static str,
    /// the run's minimum and maximum of it
    pub visited: (f64, f64),
    /// the knots' range
    pub knots: (f64, f64),
}

/// A cloth run's strains outside the fitted knots of its material ([`StrainVisits::warning`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StrainsOutsideKnots {
    /// the components outside, in the order of z
    pub components: Vec<ComponentOutside>,
    /// steps of the run
    pub steps: usize,
    /// steps with some triangle outside
    pub steps_outside: usize,
    /// steps with at least 1 % of the triangles outside (a percentile outside)
    pub steps_bulk_outside: usize,
    /// the run's `log.jsonl`, for `hylc scene-plan`
    pub log: Option<PathBuf>,
}

impl fmt::Display for StrainsOutsideKnots {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "warning: strains outside the material's fitted knots, where ψ extrapolates:"
        )?;
        for (i, c) in self.components.iter().enumerate() {
            write!(
                f,
                "{} {} visited [{}, {}], knots [{}, {}]",
                if i == 0 { "" } else { ";" },
                c.name,
                num(c.visited.0),
                num(c.visited.1),
                num(c.knots.0),
                num(c.knots.1)
            )?;
        }
        let log = self
            .log
            .as_ref()
            .map_or("LOG.jsonl".into(), |p| p.display().to_string());
        write!(
            f,
            " (some triangle outside in {} of {} steps, at least 1 % of the triangles in {}); \
             `hylc scene-plan {log}` samples where the scene went",
            self.steps_outside, self.steps, self.steps_bulk_outside
        )
    }
}

/// `x` to four significant digits: fixed between 1e-3 and 1e5 (and 0), scientific otherwise.
fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        let digits = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.3e}")
    }
}

/// A mesh too coarse to bend: its longest edge is longer than a quarter of the diagonal of the cloth's bounding
/// box ([`coarse_mesh`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CoarseMesh {
    /// the longest edge (m)
    pub longest_edge: f64,
    /// the diagonal of the cloth's bounding box (m)
    pub diagonal: f64,
}

impl fmt::Display for CoarseMesh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "warning: the longest mesh edge, {:.4} m, is longer than a quarter of the cloth's bounding-box \
             diagonal ({:.4} m / 4 = {:.4} m): the cloth is too coarse to bend; use a finer mesh (a rectangle's \
             `edge`, `--edge`)",
            self.longest_edge,
            self.diagonal,
            0.25 * self.diagonal
        )
    }
}

/// The warning when the longest edge of the triangles `tris` over `positions` is longer than a quarter of the
/// diagonal of the vertices' bounding box.
pub fn coarse_mesh(positions: &[[f64; 3]], tris: &[[usize; 3]]) -> Option<CoarseMesh> {
    let dist = |a: &[f64; 3], b: &[f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let longest_edge = tris
        .iter()
        .flat_map(|t| (0..3).map(move |i| (t[i], t[(i + 1) % 3])))
        .map(|(a, b)| dist(&positions[a], &positions[b]))
        .fold(0.0, f64::max);
    let diagonal = if positions.is_empty() {
        0.0
    } else {
        dist(&lo, &hi)
    };
    (longest_edge > 0.25 * diagonal && !tris.is_empty()).then_some(CoarseMesh {
        longest_edge,
        diagonal,
    })
}

/// A yarn file's radius that the pattern replaces ([`radius_overridden`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RadiusOverridden {
    /// the yarn file
    pub file: PathBuf,
    /// its radius (m)
    pub file_radius: f64,
    /// the pattern (as given on the command line)
    pub pattern: String,
    /// the pattern's radius (m), the one every solve takes
    pub pattern_radius: f64,
}

impl fmt::Display for RadiusOverridden {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "warning: {}: radius {} m is not used: the pattern {} carries its own radius, {} m, which every \
             solve takes",
            self.file.display(),
            self.file_radius,
            self.pattern,
            self.pattern_radius
        )
    }
}

/// The warning when the radius `file_radius` of the yarn file `file` differs from the radius of the pattern
/// `pattern` by more than 1e-6 relative (a micro problem or tile takes its pattern's radius).
pub fn radius_overridden(
    file: &Path,
    file_radius: f64,
    pattern: &str,
    pattern_radius: f64,
) -> Option<RadiusOverridden> {
    let scale = file_radius.abs().max(pattern_radius.abs());
    ((file_radius - pattern_radius).abs() > 1e-6 * scale).then(|| RadiusOverridden {
        file: file.to_path_buf(),
        file_radius,
        pattern: pattern.to_string(),
        pattern_radius,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::synthetic::default_material;
    use crate::shell::{ModelFlags, Psd};

    /// Two triangles of a unit square: the diagonal √2 is longer than a quarter of the square's diagonal; a 4 × 4
    /// grid of such squares is fine.
    #[test]
    fn coarse_mesh_compares_the_longest_edge_with_a_quarter_diagonal() {
        let square = |n: usize| {
            let p: Vec<[f64; 3]> = (0..=n)
                .flat_map(|j| (0..=n).map(move |i| [i as f64, j as f64, 0.0]))
                .collect();
            let v = |i: usize, j: usize| j * (n + 1) + i;
            let t: Vec<[usize; 3]> = (0..n)
                .flat_map(|j| {
                    (0..n).flat_map(move |i| {
                        [
                            [v(i, j), v(i + 1, j), v(i + 1, j + 1)],
                            [v(i, j), v(i + 1, j + 1), v(i, j + 1)],
                        ]
                    })
                })
                .collect();
            (p, t)
        };
        let (p, t) = square(1);
        let w = coarse_mesh(&p, &t).unwrap();
        assert!(
            (w.longest_edge - 2f64.sqrt()).abs() < 1e-15
                && (w.diagonal - 2f64.sqrt()).abs() < 1e-15
        );
        let (p, t) = square(5);
        assert_eq!(coarse_mesh(&p, &t), None);
        assert_eq!(coarse_mesh(&[], &[]), None);
    }

    #[test]
    fn radius_overridden_beyond_one_part_in_a_million() {
        let f = Path::new("y.json");
        assert!(radius_overridden(f, 2e-3, "plain", 1e-3).is_some());
        assert!(radius_overridden(f, 1e-3 * (1.0 + 2e-6), "plain", 1e-3).is_some());
        assert_eq!(
            radius_overridden(f, 1e-3 * (1.0 + 5e-7), "plain", 1e-3),
            None
        );
    }

    /// The knots per component: the in-plane ones as the material's, the bending diagonal ones divided by β,
    /// none for II₀₁, and none for bending without bending terms.
    #[test]
    fn strain_visits_take_the_knots_of_the_reduced_material() {
        let m = default_material();
        let flags = ModelFlags {
            bending_scale: 2.0,
            ..ModelFlags::default()
        };
        let v = StrainVisits::new(&ElementModel::new(&m, &flags, Psd::Full));
        assert_eq!(v.knots[0], Some(m.knot_range(0)));
        let (a, b) = (m.knot_range(3), m.knot_range(4));
        let (lo, hi) = (a.0.max(b.0), a.1.min(b.1));
        assert_eq!(v.knots[3], Some((lo / 2.0, hi / 2.0)));
        assert_eq!(v.knots[5], v.knots[3]);
        assert_eq!(v.knots[4], None);
        let flat = ModelFlags {
            bending: false,
            ..ModelFlags::default()
        };
        let v = StrainVisits::new(&ElementModel::new(&m, &flat, Psd::Full));
        assert_eq!((v.knots[3], v.knots[5]), (None, None));
        assert_eq!(v.warning(None), None);
    }

    #[test]
    fn numbers_have_four_significant_digits() {
        assert_eq!(num(183.7954), "183.8");
        assert_eq!(num(-0.12944), "-0.1294");
        assert_eq!(num(9e-4), "9.000e-4");
        assert_eq!(num(0.0), "0");
    }
}
