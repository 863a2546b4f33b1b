//! PNG plots of a fitted material (`docs/fitting.md`, "Quality report"): each 1D term with its samples, the
//! MLS curve g and the spline f₀ + f_k; each 2D term as two heat maps, the fitted surface f and the residual term
//! the material stores, with the samples that failed marked. Drawn with plotters' bitmap backend.

use super::fit1d::Fit1D;
use super::fit2d::Fit2D;
use super::model::{MaterialFit, TermData};
use crate::strain::StrainComponent;
use plotters::backend::DrawingBackend;
use plotters::drawing::DrawingAreaErrorKind;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The error type of plotters' bitmap backend.
type DrawError = DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>;

/// What went wrong with one plot file or folder.
#[derive(Debug, thiserror::Error)]
pub enum PlotErrorKind {
    /// the plot folder could not be created
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// plotters could not draw the plot or write the PNG
    #[error("cannot draw the plot: {0}")]
    Draw(#[from] DrawError),
}

/// A plot that was not written: the file (or, for the folder, the folder) and why. Displayed as one line
/// `PATH: what is wrong`.
#[derive(Debug, thiserror::Error)]
#[error("{}: {kind}", path.display())]
pub struct PlotError {
    /// the file (or folder)
    pub path: PathBuf,
    /// what went wrong
    pub kind: PlotErrorKind,
}

impl PlotError {
    fn at(path: &Path) -> impl Fn(PlotErrorKind) -> PlotError + '_ {
        move |kind| PlotError {
            path: path.to_path_buf(),
            kind,
        }
    }
}

/// Plot one 1D term: samples (Ψ̄ against the strain), g + (f₀ − offset) and f₀ + f_k, over 10 % beyond the data.
pub fn plot_term1d(
    path: &Path,
    k: usize,
    fit: &Fit1D,
    data: &TermData,
    sigma: f64,
    constant: f64,
) -> Result<(), PlotError> {
    draw_term1d(path, k, fit, data, sigma, constant).map_err(PlotError::at(path))
}

fn draw_term1d(
    path: &Path,
    k: usize,
    fit: &Fit1D,
    data: &TermData,
    sigma: f64,
    constant: f64,
) -> Result<(), PlotErrorKind> {
    let pts: Vec<(f64, f64)> = data
        .x
        .iter()
        .zip(&data.psi)
        .filter(|(_, p)| p.is_finite())
        .map(|(&x, &p)| (x * sigma, p))
        .collect();
    let (lo, hi) = data
        .x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let (lo, hi) = (lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo));
    let spline: Vec<(f64, f64)> = (0..=400)
        .map(|i| {
            let x = lo + (hi - lo) * i as f64 / 400.0;
            (x * sigma, constant + fit.spline.eval2(x)[0])
        })
        .collect();
    let shift = constant - fit.offset;
    let curve: Vec<(f64, f64)> = fit
        .curve
        .iter()
        .map(|c| (c[0] * sigma, c[1] + shift))
        .collect();
    let ys = pts.iter().chain(&spline).map(|p| p.1);
    let (ymin, ymax) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    let pad = 0.05 * (ymax - ymin).max(1e-12);
    let failed = data.psi.iter().filter(|p| !p.is_finite()).count();

    let root = BitMapBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let title = format!(
        "f0 + f_{k} ({}): {} samples, {} failed, fit RMS {:.2e}",
        StrainComponent::NAMES[k],
        fit.report.n_samples,
        failed,
        fit.report.rms_rel
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(lo * sigma..hi * sigma, ymin - pad..ymax + pad)?;
    chart
        .configure_mesh()
        .x_desc(StrainComponent::NAMES[k])
        .y_desc("energy density [J/m2]")
        .draw()?;
    chart
        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, BLUE.filled())))?
        .label("micro samples")
        .legend(|(x, y)| Circle::new((x, y), 3, BLUE.filled()));
    chart
        .draw_series(LineSeries::new(curve, GREEN.stroke_width(2)))?
        .label("MLS curve g")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], GREEN.stroke_width(2)));
    chart
        .draw_series(LineSeries::new(spline, RED.stroke_width(2)))?
        .label("spline f0 + f_k")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
    chart
        .draw_series(fit.spline.t.iter().map(|&t| {
            let y = constant + fit.spline.eval2(t)[0];
            Cross::new((t * sigma, y), 5, BLACK.stroke_width(2))
        }))?
        .label("knots")
        .legend(|(x, y)| Cross::new((x, y), 5, BLACK.stroke_width(2)));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperMiddle)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// A colour for t ∈ [0, 1] on a dark-blue → teal → yellow ramp (viridis-like).
fn ramp(t: f64) -> RGBColor {
    const C: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let t = t.clamp(0.0, 1.0) * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    let c = |j: usize| (C[i][j] + f * (C[i + 1][j] - C[i][j])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// A diverging colour for t ∈ [−1, 1]: blue → white → red.
fn diverging(t: f64) -> RGBColor {
    let t = t.clamp(-1.0, 1.0);
    let a = (255.0 * (1.0 - t.abs())).round() as u8;
    if t >= 0.0 {
        RGBColor(255, a, a)
    } else {
        RGBColor(a, a, 255)
    }
}

/// Plot one 2D term: heat maps of the fitted surface f (left) and of the stored residual (right) over the
/// samples' range; failed samples are black crosses.
pub fn plot_term2d(
    path: &Path,
    k0: usize,
    k1: usize,
    fit: &Fit2D,
    data: &TermData,
    sigma: [f64; 2],
) -> Result<(), PlotError> {
    draw_term2d(path, k0, k1, fit, data, sigma).map_err(PlotError::at(path))
}

fn draw_term2d(
    path: &Path,
    k0: usize,
    k1: usize,
    fit: &Fit2D,
    data: &TermData,
    sigma: [f64; 2],
) -> Result<(), PlotErrorKind> {
    let range = |d: &[f64]| {
        d.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            })
    };
    let (u0, u1) = range(&data.x);
    let (v0, v1) = range(&data.y);
    let n = 120;
    let cell = |i: usize, a: f64, b: f64| a + (b - a) * i as f64 / n as f64;
    let mut full = vec![0.0; n * n];
    let mut res = vec![0.0; n * n];
    for j in 0..n {
        for i in 0..n {
            let (u, v) = (
                cell(i, u0, u1) + 0.5 * (u1 - u0) / n as f64,
                cell(j, v0, v1) + 0.5 * (v1 - v0) / n as f64,
            );
            full[j * n + i] = fit.full.eval2(u, v)[0];
            res[j * n + i] = fit.residual.eval2(u, v)[0];
        }
    }
    let (fmin, fmax) = range(&full);
    let rmax = res.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let root = BitMapBackend::new(path, (1400, 650)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(700);
    let failed: Vec<(f64, f64)> = (0..data.psi.len())
        .filter(|&i| !data.psi[i].is_finite())
        .map(|i| (data.x[i] * sigma[0], data.y[i] * sigma[1]))
        .collect();
    for (area, values, title, residual) in [
        (
            &left,
            &full,
            format!(
                "f({}, {}): {:.3e} to {:.3e} J/m² (log colours), fit RMS {:.2e}",
                StrainComponent::NAMES[k0],
                StrainComponent::NAMES[k1],
                fmin,
                fmax,
                fit.report.rms_rel
            ),
            false,
        ),
        (
            &right,
            &res,
            format!("residual f_{k0}{k1}: |r| ≤ {rmax:.3e} J/m² (red +, blue −)"),
            true,
        ),
    ] {
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 18))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(u0 * sigma[0]..u1 * sigma[0], v0 * sigma[1]..v1 * sigma[1])?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(StrainComponent::NAMES[k0])
            .y_desc(StrainComponent::NAMES[k1])
            .draw()?;
        chart.draw_series((0..n * n).map(|c| {
            let (i, j) = (c % n, c / n);
            let x = [cell(i, u0, u1) * sigma[0], cell(i + 1, u0, u1) * sigma[0]];
            let y = [cell(j, v0, v1) * sigma[1], cell(j + 1, v0, v1) * sigma[1]];
            let v = values[c];
            let colour = if residual {
                diverging(v / rmax)
            } else {
                // logarithmic colour scale over the value range (energies span decades)
                let e = 1e-3 * (fmax - fmin).max(1e-300);
                ramp(((v - fmin) / e).ln_1p() / ((fmax - fmin) / e).ln_1p())
            };
            Rectangle::new([(x[0], y[0]), (x[1], y[1])], colour.filled())
        }))?;
        chart.draw_series(
            failed
                .iter()
                .map(|&p| Cross::new(p, 4, BLACK.stroke_width(2))),
        )?;
    }
    root.present()?;
    Ok(())
}

/// Write every term's plot to `dir` (`1d_<strain>.png`, `2d_<strain>_<strain>.png`); returns the paths.
pub fn plot_material_fit(dir: &Path, fit: &MaterialFit) -> Result<Vec<PathBuf>, PlotError> {
    std::fs::create_dir_all(dir)
        .map_err(PlotErrorKind::from)
        .map_err(PlotError::at(dir))?;
    let sigma = fit.material.strain_scale;
    let mut out = Vec::new();
    for (k, f, d) in &fit.fits1d {
        let path = dir.join(format!("1d_{}.png", StrainComponent::NAMES[*k]));
        plot_term1d(&path, *k, f, d, sigma[*k], fit.material.constant)?;
        out.push(path);
    }
    for (k0, k1, f, d) in &fit.fits2d {
        let path = dir.join(format!(
            "2d_{}_{}.png",
            StrainComponent::NAMES[*k0],
            StrainComponent::NAMES[*k1]
        ));
        plot_term2d(&path, *k0, *k1, f, d, [sigma[*k0], sigma[*k1]])?;
        out.push(path);
    }
    Ok(out)
}
