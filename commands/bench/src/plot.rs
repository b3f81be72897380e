//! The plot of relative MSE against render time, log–log, one curve per
//! strategy, as PNG and SVG (plotters). Text is set in DejaVu Sans, bundled (a
//! Latin subset; see `assets/README.md`) so that no system font is needed.

use crate::report::Report;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::OnceLock;

const SIZE: (u32, u32) = (960, 640);
const FONT: &[u8] = include_bytes!("../assets/DejaVuSans-subset.ttf");

/// Colours for the curves, distinguishable and readable on white.
const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// Makes the bundled font the plot's `sans-serif`, once per process.
fn register_font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
                .map_err(|_| "the bundled plot font is unreadable".to_owned())
        })
        .clone()
}

/// The plot as SVG text.
pub fn svg(report: &Report) -> Result<String, String> {
    register_font()?;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
        draw(&root, report).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(text)
}

/// The plot as 8-bit RGB pixels, row-major, `SIZE` large.
pub fn rgb(report: &Report) -> Result<(u32, u32, Vec<[u8; 3]>), String> {
    register_font()?;
    let mut buffer = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, SIZE).into_drawing_area();
        draw(&root, report).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    let pixels = buffer.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Ok((SIZE.0, SIZE.1, pixels))
}

type DrawResult<T, DB> = Result<T, DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, report: &Report) -> DrawResult<(), DB> {
    root.fill(&WHITE)?;
    let (footer, body) = (
        root.clone().shrink((0, SIZE.1 - 28), (SIZE.0, 28)),
        root.clone().shrink((0, 0), (SIZE.0, SIZE.1 - 28)),
    );
    let points: Vec<(f64, f64)> = report
        .rows
        .iter()
        .map(|r| (r.time_median_s, r.rel_mse))
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && t.is_finite() && e.is_finite())
        .collect();
    let (x_range, y_range) = log_ranges(&points);
    let mut title = format!("{}: relative MSE against render time", report.scene_name);
    if let Some(name) = &report.region.name {
        title = format!("{title} ({name})");
    } else if !report.region.whole_image {
        title = format!("{title} (region)");
    }
    let mut chart = ChartBuilder::on(&body)
        .caption(title, ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())?;
    chart
        .configure_mesh()
        .x_desc("render time (s)")
        .y_desc("relative MSE")
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .x_label_formatter(&|x| short(*x))
        .y_label_formatter(&|y| short(*y))
        .draw()?;
    for (k, strategy) in report.strategies.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let curve: Vec<(f64, f64)> = report
            .rows
            .iter()
            .filter(|r| r.strategy == strategy.name)
            .map(|r| (r.time_median_s, r.rel_mse))
            .filter(|(t, e)| *t > 0.0 && *e > 0.0 && t.is_finite() && e.is_finite())
            .collect();
        let label = match strategy.rel_mse_slope {
            Some(s) => format!("{} (slope {s:+.2})", strategy.name),
            None => strategy.name.clone(),
        };
        chart
            .draw_series(LineSeries::new(curve.clone(), color.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(2))
            });
        chart.draw_series(curve.into_iter().map(|p| Circle::new(p, 4, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 16))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    let caption = format!(
        "{}x{}, reference {} spp; {}",
        report.resolution[0],
        report.resolution[1],
        report.reference.total_spp,
        report.machine.label()
    );
    footer.draw(&Text::new(
        caption,
        (16, 4),
        ("sans-serif", 14).into_font().color(&RGBColor(80, 80, 80)),
    ))?;
    Ok(())
}

/// Axis ranges that hold every point with a margin, on log axes.
fn log_ranges(points: &[(f64, f64)]) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let range = |values: Vec<f64>| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi.is_finite() {
            (lo / 1.6)..(hi * 1.6)
        } else {
            0.01..1.0
        }
    };
    (
        range(points.iter().map(|p| p.0).collect()),
        range(points.iter().map(|p| p.1).collect()),
    )
}

/// Tick labels: `0.01`, `3`, `1e-5`.
fn short(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&x.abs()) {
        let s = format!("{x:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        format!("{x:.0e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(short(0.01), "0.01");
        assert_eq!(short(3.0), "3");
        assert_eq!(short(1e-5), "1e-5");
        assert_eq!(short(250.0), "250");
    }

    #[test]
    fn ranges_hold_every_point() {
        let (x, y) = log_ranges(&[(0.1, 1e-3), (2.0, 5e-5)]);
        assert!(x.start < 0.1 && x.end > 2.0);
        assert!(y.start < 5e-5 && y.end > 1e-3);
        let (x, _) = log_ranges(&[]);
        assert!(x.start > 0.0 && x.end > x.start);
    }
}
