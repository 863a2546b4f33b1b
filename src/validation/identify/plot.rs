//! PNG plots of `hylc identify` (issue 22, item 3): line plots of several series (our 1D curves against the
//! original's, the displacement error per grid axis value before and after), drawn with plotters' bitmap backend.

use super::IdentifyError;
use plotters::prelude::*;
use std::path::Path;

/// One series of a line plot: label, points, colour (index into a fixed palette), dashed markers only.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
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
