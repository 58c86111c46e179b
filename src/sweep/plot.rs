//! The sweep's plots (plotters), each as SVG and PNG: frame time against the final
//! image's error, one series per kernel × chain; and the per-pass cost of every
//! point as stacked bars.

use super::{name, Point, Sweep};
use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::render::output::write_rgba8_png;
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
    // Each drawn in memory and written whole (crate::atomic).
    for stem in ["time_vs_error", "passes"] {
        let svg = dir.join(format!("{stem}.svg"));
        let mut text = String::new();
        draw(
            sweep,
            stem,
            SVGBackend::with_string(&mut text, SIZE).into_drawing_area(),
        )
        .map_err(|e| plot_error(&svg, e))?;
        write_atomic(&svg, text)?;
        let png = dir.join(format!("{stem}.png"));
        let mut rgb = vec![0u8; 3 * (SIZE.0 * SIZE.1) as usize];
        draw(
            sweep,
            stem,
            BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area(),
        )
        .map_err(|e| plot_error(&png, e))?;
        let rgba: Vec<u8> = rgb
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect();
        write_rgba8_png(&png, SIZE.0, SIZE.1, &rgba)?;
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

/// A titled, otherwise empty plot, for a sweep with nothing to show on it (an
/// empty range on a log axis would not draw, and can allocate without bound).
fn nothing<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, title: &str, why: &str) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    area.fill(&WHITE).map_err(e)?;
    let style = ("sans-serif", 20).into_font().color(&BLACK);
    area.draw(&Text::new(title.to_string(), (40, 40), style.clone()))
        .map_err(e)?;
    area.draw(&Text::new(why.to_string(), (40, 80), style))
        .map_err(e)?;
    area.present().map_err(e)
}

/// `lo..hi` around finite positive values for a log axis: the values' span
/// widened by 1.5× each way, or a decade around a single value.
fn log_range(values: &[f64]) -> std::ops::Range<f64> {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(0.0, f64::max);
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0) {
        return 0.1..10.0;
    }
    if hi / lo < 1.0 + 1e-9 {
        return (lo / 10f64.sqrt())..(hi * 10f64.sqrt());
    }
    (lo / 1.5)..(hi * 1.5)
}

fn series_label(p: &Point) -> String {
    format!("{} / {}", name(&p.variant.kernel), name(&p.variant.chain))
}

/// x: frame time (ms, log), y: final-image RMSE relative to the mean (%, log).
fn time_vs_error<DB: DrawingBackend>(sweep: &Sweep, area: DrawingArea<DB, Shift>) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    // The reference's own point (zero error) has no place on a log axis, nor
    // has a non-finite one.
    let shown: Vec<&Point> = sweep
        .points
        .iter()
        .filter(|p| p.final_error.rmse_rel > 0.0 && p.final_error.rmse_rel.is_finite())
        .filter(|p| p.total_ms.is_finite())
        .collect();
    let title = format!(
        "{}: frame time against error ({}x{})",
        sweep.scene, sweep.width, sweep.height
    );
    if shown.is_empty() {
        return nothing(
            &area,
            &title,
            "no point with a positive, finite error to plot",
        );
    }
    area.fill(&WHITE).map_err(e)?;
    let pts: Vec<(f64, f64)> = shown
        .iter()
        .map(|p| (p.total_ms.max(1e-3), 100.0 * p.final_error.rmse_rel))
        .collect();
    let xs = log_range(&pts.iter().map(|p| p.0).collect::<Vec<_>>());
    let ys = log_range(&pts.iter().map(|p| p.1).collect::<Vec<_>>());
    let mut chart = ChartBuilder::on(&area)
        .caption(title, ("sans-serif", 20))
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
    if sweep.points.is_empty() {
        return nothing(
            &area,
            &format!("{}: median per pass (ms)", sweep.scene),
            "no points",
        );
    }
    area.fill(&WHITE).map_err(e)?;
    // Passes in first-seen order; the blur passes grouped per level.
    let group = |n: &str| n.trim_end_matches("_u").trim_end_matches("_v").to_string();
    let mut groups: Vec<String> = Vec::new();
    for p in sweep.points.iter().flat_map(|p| &p.passes) {
        let g = group(&p.name);
        if !crate::timing::is_ruler(&p.name) && !groups.contains(&g) {
            groups.push(g);
        }
    }
    let top = sweep
        .points
        .iter()
        .map(|p| p.total_ms)
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max)
        * 1.05;
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
                        .filter(|s| !crate::timing::is_ruler(&s.name) && filter(&s.name))
                        .map(|s| s.time.map_or(0.0, |t| t.median_ns) / 1e6)
                        .filter(|ms| ms.is_finite())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::file::{Chain, Kernel};
    use crate::sweep::metric::ImageError;
    use crate::sweep::Variant;
    use crate::timing::{PassStats, Stats};

    fn sweep(points: Vec<(f64, f64)>) -> Sweep {
        let variant = |i: usize| Variant {
            resolution: 256 << (i % 6),
            kernel: Kernel::Deon7,
            chain: Chain::Full,
        };
        let err = |rmse: f64| ImageError {
            rmse_rel: rmse,
            max_rel: rmse,
            p99_rel: rmse,
            psnr_db: None,
            pixels: 0,
        };
        let pass = |ms: f64| PassStats {
            name: "irradiance".into(),
            frames: 1,
            time: Some(Stats {
                median_ns: ms * 1e6,
                min_ns: ms * 1e6,
                max_ns: ms * 1e6,
                p90_ns: ms * 1e6,
                mean_ns: ms * 1e6,
                std_ns: 0.0,
            }),
            ..Default::default()
        };
        Sweep {
            schema_version: 1,
            sweep_hash: String::new(),
            run_id: String::new(),
            timestamp: String::new(),
            dermis_version: String::new(),
            git_commit: String::new(),
            device: String::new(),
            driver: String::new(),
            fingerprint: Default::default(),
            scene: "test".into(),
            environment: String::new(),
            width: 1,
            height: 1,
            frames: 2,
            reference: variant(0),
            reference_checksum: String::new(),
            points: points
                .into_iter()
                .enumerate()
                .map(|(i, (ms, rmse))| Point {
                    id: variant(i).id(),
                    variant: variant(i),
                    passes: vec![pass(ms)],
                    total_ms: ms,
                    chain_ms: 0.0,
                    frame_span: pass(ms),
                    transient_bytes: 0,
                    final_error: err(rmse),
                    diffuse_error: err(rmse),
                })
                .collect(),
            shards: Vec::new(),
        }
    }

    #[test]
    fn empty_constant_and_zero_series_plot_without_panicking() {
        let dir = std::env::temp_dir().join(format!("dermis-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cases = [
            ("empty", vec![]),
            ("zero errors", vec![(5.0, 0.0), (7.0, 0.0)]),
            ("zero times", vec![(0.0, 0.1), (0.0, 0.2)]),
            ("constant", vec![(5.0, 0.1), (5.0, 0.1), (5.0, 0.1)]),
            ("one point", vec![(5.0, 0.1)]),
            (
                "not finite",
                vec![(f64::NAN, f64::INFINITY), (f64::INFINITY, 0.1)],
            ),
        ];
        for (what, points) in cases {
            write_plots(&sweep(points), &dir).unwrap_or_else(|e| panic!("{what}: {e}"));
            for f in [
                "time_vs_error.svg",
                "time_vs_error.png",
                "passes.svg",
                "passes.png",
            ] {
                assert!(dir.join(f).is_file(), "{what}: {f}");
            }
        }
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(left.is_empty(), "temporary files left: {left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn log_ranges_are_never_empty() {
        for v in [vec![], vec![0.0], vec![3.0], vec![3.0, 3.0], vec![f64::NAN]] {
            let r = log_range(&v);
            assert!(
                r.start > 0.0 && r.end > r.start && r.end.is_finite(),
                "{v:?}: {r:?}"
            );
        }
    }
}
