//! The sweep's plots (plotters), each as SVG and PNG: frame time against the final
//! image's error, one series per kernel × chain; and the per-pass cost of every
//! point as stacked bars.

use super::{name, Point, Sweep};
use crate::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

const SIZE: (u32, u32) = (1200, 760);

fn plot_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Input(format!("{}: {e}", path.display()))
}

/// Writes `time_vs_error.{svg,png}` and `passes.{svg,png}` into `dir`.
pub fn write_plots(sweep: &Sweep, dir: &Path) -> Result<()> {
    // Registering twice is harmless; the bitmap backend looks fonts up by family.
    plotters::style::register_font("sans-serif", FontStyle::Normal, crate::text::FONT)
        .map_err(|_| plot_error(dir, "the embedded font does not load"))?;
    for stem in ["time_vs_error", "passes"] {
        let svg = dir.join(format!("{stem}.svg"));
        draw(sweep, stem, SVGBackend::new(&svg, SIZE).into_drawing_area())
            .map_err(|e| plot_error(&svg, e))?;
        let png = dir.join(format!("{stem}.png"));
        draw(
            sweep,
            stem,
            BitMapBackend::new(&png, SIZE).into_drawing_area(),
        )
        .map_err(|e| plot_error(&png, e))?;
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(sweep: &Sweep, stem: &str, area: DrawingArea<DB, Shift>) -> DrawResult
where
    DB::ErrorType: 'static,
{
    match stem {
        "passes" => passes(sweep, area),
        _ => time_vs_error(sweep, area),
    }
}

type DrawResult = std::result::Result<(), String>;

fn series_label(p: &Point) -> String {
    format!("{} / {}", name(&p.variant.kernel), name(&p.variant.chain))
}

/// x: frame time (ms, log), y: final-image RMSE relative to the mean (%, log).
fn time_vs_error<DB: DrawingBackend>(sweep: &Sweep, area: DrawingArea<DB, Shift>) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    // The reference's own point (zero error) has no place on a log axis.
    let shown: Vec<&Point> = sweep
        .points
        .iter()
        .filter(|p| p.final_error.rmse_rel > 0.0)
        .collect();
    let pts: Vec<(f64, f64)> = shown
        .iter()
        .map(|p| (p.total_ms.max(1e-3), 100.0 * p.final_error.rmse_rel))
        .collect();
    let range = |v: Vec<f64>| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        (lo / 1.5)..(hi * 1.5)
    };
    let xs = range(pts.iter().map(|p| p.0).collect());
    let ys = range(pts.iter().map(|p| p.1).collect());
    let mut chart = ChartBuilder::on(&area)
        .caption(
            format!(
                "{}: frame time against error ({}x{})",
                sweep.scene, sweep.width, sweep.height
            ),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(xs.log_scale(), ys.log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_labels(10)
        .y_labels(10)
        .y_label_formatter(&|y| format!("{y:.2}"))
        .x_label_formatter(&|x| format!("{x:.0}"))
        .x_desc("frame time, sum of pass medians without rulers (ms)")
        .y_desc("final image RMSE / mean (%)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(e)?;
    let mut labels: Vec<String> = shown.iter().map(|p| series_label(p)).collect();
    labels.sort();
    labels.dedup();
    for (i, label) in labels.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let series: Vec<(f64, f64, u32)> = shown
            .iter()
            .zip(&pts)
            .filter(|(p, _)| &series_label(p) == label)
            .map(|(p, &(x, y))| (x, y, p.variant.resolution))
            .collect();
        chart
            .draw_series(LineSeries::new(
                series.iter().map(|s| (s.0, s.1)),
                color.stroke_width(2),
            ))
            .map_err(e)?
            .label(label.clone())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
        chart
            .draw_series(series.iter().map(|&(x, y, r)| {
                EmptyElement::at((x, y))
                    + Circle::new((0, 0), 4, color.filled())
                    + Text::new(format!("{r}²"), (6, -14), ("sans-serif", 12))
            }))
            .map_err(e)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(e)?;
    area.present().map_err(e)
}

/// One horizontal bar per point, the medians of its passes stacked (rulers
/// excluded), points top to bottom in sweep order.
fn passes<DB: DrawingBackend>(sweep: &Sweep, area: DrawingArea<DB, Shift>) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    // Passes in first-seen order; the blur passes grouped per level.
    let group = |n: &str| n.trim_end_matches("_u").trim_end_matches("_v").to_string();
    let mut groups: Vec<String> = Vec::new();
    for p in sweep.points.iter().flat_map(|p| &p.passes) {
        let g = group(&p.name);
        if !p.name.starts_with("ruler_") && !groups.contains(&g) {
            groups.push(g);
        }
    }
    let top = sweep.points.iter().map(|p| p.total_ms).fold(0.0, f64::max) * 1.05;
    let n = sweep.points.len();
    // Row i from the top.
    let row = |i: usize| (n - 1 - i) as f64;
    let labels: Vec<String> = sweep
        .points
        .iter()
        .map(|p| {
            let v = p.variant;
            format!("{}² {} {}", v.resolution, name(&v.kernel), name(&v.chain))
        })
        .collect();
    let mut chart = ChartBuilder::on(&area)
        .caption(
            format!("{}: median per pass (ms)", sweep.scene),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(190)
        .build_cartesian_2d(0.0..top.max(1e-3), -0.5..n as f64 - 0.5)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(n + 1)
        .y_label_formatter(&|y| {
            let r = y.round();
            let i = n as f64 - 1.0 - r;
            match (y - r).abs() < 1e-3 && i >= 0.0 {
                true => labels.get(i as usize).cloned().unwrap_or_default(),
                false => String::new(),
            }
        })
        .x_desc("sum of pass medians (ms)")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    for (gi, g) in groups.iter().enumerate() {
        let color = Palette99::pick(gi).to_rgba();
        let bars: Vec<Rectangle<(f64, f64)>> = sweep
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let ms = |filter: &dyn Fn(&str) -> bool| {
                    p.passes
                        .iter()
                        .filter(|s| !s.name.starts_with("ruler_") && filter(&s.name))
                        .map(|s| s.time.map_or(0.0, |t| t.median_ns) / 1e6)
                        .sum::<f64>()
                };
                let left = ms(&|n| groups[..gi].contains(&group(n)));
                let own = ms(&|n| group(n) == *g);
                Rectangle::new(
                    [(left, row(i) - 0.35), (left + own, row(i) + 0.35)],
                    color.filled(),
                )
            })
            .collect();
        chart
            .draw_series(bars)
            .map_err(e)?
            .label(g.clone())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], color.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(e)?;
    area.present().map_err(e)
}
