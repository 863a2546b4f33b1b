//! PNG plots of `hylc identify` (docs/yarn-parameters.md): line plots of several series (our 1D curves against the
//! original's, the displacement error per grid axis value before and after), drawn with plotters' bitmap backend.
//! [`write_plots`] and [`plot_study`] write the files of an identification.

use super::held_out::{HeldOut, StudyCurve, STUDY_PARAMETERS};
use super::{Identification, IdentifyError};
use crate::validation::grid::AXIS_LEN;
use plotters::prelude::*;
use std::path::Path;

/// One series of a line plot: label, points, colour (index into a fixed palette), dashed markers only.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// The points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Colour: an index into the palette.
    pub colour: usize,
    /// Draw markers only (no line).
    pub markers: bool,
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 0, 0),
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];

/// Several panels side by side, each a line plot with its title and x label; one y label for all.
pub fn plot_panels(
    path: &Path,
    title: &str,
    y_desc: &str,
    panels: &[(String, String, Vec<Series>)],
) -> Result<(), IdentifyError> {
    draw(path, title, y_desc, panels).map_err(|e| IdentifyError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn draw(
    path: &Path,
    title: &str,
    y_desc: &str,
    panels: &[(String, String, Vec<Series>)],
) -> Result<(), Box<dyn std::error::Error>> {
    let w = 520 * panels.len().max(1) as u32;
    let root = BitMapBackend::new(path, (w, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let areas = root.split_evenly((1, panels.len().max(1)));
    for ((name, x_desc, series), area) in panels.iter().zip(areas) {
        let pts = series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| p.0.is_finite() && p.1.is_finite());
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for p in pts {
            x0 = x0.min(p.0);
            x1 = x1.max(p.0);
            y0 = y0.min(p.1);
            y1 = y1.max(p.1);
        }
        if !(x0.is_finite() && y0.is_finite()) {
            continue;
        }
        let px = 0.05 * (x1 - x0).max(1e-12);
        let py = 0.05 * (y1 - y0).max(1e-12 * y1.abs().max(1e-300));
        let mut chart = ChartBuilder::on(&area)
            .caption(name, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x0 - px..x1 + px, y0 - py..y1 + py)?;
        chart
            .configure_mesh()
            .x_desc(x_desc.as_str())
            .y_desc(y_desc)
            .draw()?;
        for s in series {
            let c = PALETTE[s.colour % PALETTE.len()];
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            if s.markers {
                chart
                    .draw_series(points.iter().map(|&p| Circle::new(p, 4, c.filled())))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| Circle::new((x, y), 4, c.filled()));
            } else {
                chart
                    .draw_series(LineSeries::new(points, c.stroke_width(2)))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                    });
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

/// The names of the grid's three axes (the in-plane strains).
const AXIS_NAMES: [&str; 3] = ["s_x", "s_a", "s_y"];

/// The plots of an identification in `out` (titles start with `stem`): the RMS position error of the fitted grid
/// points by axis value before and after (`fit_grid_error.png`, when residual b was on), and with the held-out
/// numbers before and after ([start, identified]) the full grid's error by axis (`grid_error_by_axis.png`) and
/// the 1D curves (`curves.png`).
pub fn write_plots(
    out: &Path,
    stem: &str,
    r: &Identification,
    validation: Option<&[HeldOut]>,
) -> Result<(), IdentifyError> {
    if !r.before.grid_points.is_empty() {
        plot_fit_grid_error(out, stem, r)?;
    }
    if let Some([before, after]) = validation {
        if let (Some(bx), Some(ax), Some(axes)) =
            (before.grid_rms_by_axis, after.grid_rms_by_axis, after.axes)
        {
            plot_grid_error_by_axis(out, stem, &bx, &ax, &axes)?;
        }
        plot_curves(out, stem, before, after)?;
    }
    Ok(())
}

/// RMS per axis value of the fitted grid points: (axis value, RMS) per axis.
fn by_axis(points: &[([f64; 3], f64)]) -> [Vec<(f64, f64)>; 3] {
    std::array::from_fn(|k| {
        let mut vals: Vec<f64> = points.iter().map(|p| p.0[k]).collect();
        vals.sort_by(f64::total_cmp);
        vals.dedup();
        vals.iter()
            .map(|&v| {
                let sel: Vec<f64> = points
                    .iter()
                    .filter(|p| p.0[k] == v)
                    .map(|p| p.1 * p.1)
                    .collect();
                (v, (sel.iter().sum::<f64>() / sel.len() as f64).sqrt())
            })
            .collect()
    })
}

/// Two series, "before" and "after", in the colours 1 and 2.
fn before_after(before: Vec<(f64, f64)>, after: Vec<(f64, f64)>, markers: bool) -> Vec<Series> {
    vec![
        Series {
            label: "before".into(),
            points: before,
            colour: 1,
            markers,
        },
        Series {
            label: "after".into(),
            points: after,
            colour: 2,
            markers,
        },
    ]
}

/// fit_grid_error.png: the fitted grid points' RMS error by the value of each axis, before and after.
fn plot_fit_grid_error(out: &Path, stem: &str, r: &Identification) -> Result<(), IdentifyError> {
    let (b, a) = (
        by_axis(&r.before.grid_points),
        by_axis(&r.after.grid_points),
    );
    let panels: Vec<(String, String, Vec<Series>)> = (0..3)
        .map(|k| {
            (
                format!("error by {} (fitted points)", AXIS_NAMES[k]),
                AXIS_NAMES[k].to_string(),
                before_after(b[k].clone(), a[k].clone(), true),
            )
        })
        .collect();
    plot_panels(
        &out.join("fit_grid_error.png"),
        &format!("{stem}: RMS position error [r]"),
        "RMS error [r]",
        &panels,
    )
}

/// grid_error_by_axis.png: the full grid's RMS error by the value of each axis (`axes`), before and after.
fn plot_grid_error_by_axis(
    out: &Path,
    stem: &str,
    bx: &[[f64; AXIS_LEN]; 3],
    ax: &[[f64; AXIS_LEN]; 3],
    axes: &[[f64; AXIS_LEN]; 3],
) -> Result<(), IdentifyError> {
    let line = |v: &[f64; AXIS_LEN], k: usize| -> Vec<(f64, f64)> {
        (0..AXIS_LEN).map(|i| (axes[k][i], v[i])).collect()
    };
    let panels: Vec<(String, String, Vec<Series>)> = (0..3)
        .map(|k| {
            (
                format!("full grid, by {}", AXIS_NAMES[k]),
                AXIS_NAMES[k].to_string(),
                before_after(line(&bx[k], k), line(&ax[k], k), false),
            )
        })
        .collect();
    plot_panels(
        &out.join("grid_error_by_axis.png"),
        &format!("{stem}: full-grid RMS position error [r]"),
        "RMS error [r]",
        &panels,
    )
}

/// curves.png: each 1D curve of the original material against ours at the start and identified parameters
/// (nothing when there are no curves).
fn plot_curves(
    out: &Path,
    stem: &str,
    before: &HeldOut,
    after: &HeldOut,
) -> Result<(), IdentifyError> {
    let panels: Vec<(String, String, Vec<Series>)> = after
        .curves
        .iter()
        .zip(&before.curves)
        .map(|(a, b)| {
            let pts =
                |c: &[f64], s: &[f64]| s.iter().copied().zip(c.iter().copied()).collect::<Vec<_>>();
            (
                format!("f0 + f_{}: after {:.1} %", a.component, 100.0 * a.rel_rms),
                a.component.to_string(),
                vec![
                    Series {
                        label: "original".into(),
                        points: pts(&a.original, &a.strains),
                        colour: 0,
                        markers: false,
                    },
                    Series {
                        label: "ours, start".into(),
                        points: pts(&b.ours, &b.strains),
                        colour: 1,
                        markers: true,
                    },
                    Series {
                        label: "ours, identified".into(),
                        points: pts(&a.ours, &a.strains),
                        colour: 2,
                        markers: true,
                    },
                ],
            )
        })
        .collect();
    if panels.is_empty() {
        return Ok(());
    }
    plot_panels(
        &out.join("curves.png"),
        &format!("{stem}: 1D curves [J/m2]"),
        "energy density [J/m2]",
        &panels,
    )
}

/// study.png: θ ∂Ψ̄/∂θ along each 1D range, one panel per range, one series per parameter.
pub fn plot_study(out: &Path, stem: &str, curves: &[StudyCurve]) -> Result<(), IdentifyError> {
    let panels: Vec<(String, String, Vec<Series>)> = curves
        .iter()
        .map(|c| {
            let series = (0..5)
                .map(|j| Series {
                    label: format!("d psi / d ln {}", STUDY_PARAMETERS[j]),
                    points: c
                        .strains
                        .iter()
                        .copied()
                        .zip(c.dpsi_dlog[j].iter().copied())
                        .collect(),
                    colour: j + 1,
                    markers: false,
                })
                .collect();
            (
                format!("f0 + f_{}", c.component),
                c.component.to_string(),
                series,
            )
        })
        .collect();
    plot_panels(
        &out.join("study.png"),
        &format!(
            "{stem}: sensitivity of the energy density to the yarn parameters [J/m2 per ln θ]"
        ),
        "J/m2",
        &panels,
    )
}
