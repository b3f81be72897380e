//! `glint diff`: two images compared by the metrics of glint-metrics, printed as
//! a table, with an optional heat map and an exit status that gates a script.

use crate::output::check_heatmap_path;
use crate::Failure;
use clap::{Args, ValueEnum};
use glint_camera::Film;
use glint_metrics::{
    compare_with_flip_map, flip, heatmap, non_finite_count, rel_mse_map, save_heatmap, Comparison,
    ErrorMap, ImageView, Region,
};
use std::path::PathBuf;

#[derive(Args)]
#[command(
    after_help = "Compares TEST with REFERENCE (PNG, JPEG, BMP, TGA, PPM/PGM, Radiance HDR, \
                  OpenEXR or PFM, told by content; the same size): per-channel means, RMSE, \
                  relative MSE, mean FLIP and the largest difference, printed as a table, \
                  then whether the difference is within the tolerance. Metrics are computed \
                  on linear RGB (integer formats decoded from sRGB); \
                  docs/comparing-images.md defines them.\n\n\
                  Exit status: 0 within the tolerance, 1 beyond it, 2 for bad input \
                  (unreadable or invalid files, different sizes, a bad region, tolerance \
                  or heat map path), 3 for a failure of Glint's own (a failed write)."
)]
pub(crate) struct DiffArgs {
    /// The image to judge (.png, .jpg, .exr or .pfm)
    test: PathBuf,

    /// The reference it is judged against: relative MSE divides by it and FLIP
    /// judges the test against it (same size as TEST)
    reference: PathBuf,

    /// The metric --tolerance applies to: relmse (relative MSE), rmse, flip
    /// (mean FLIP), max (the largest difference of one channel)
    #[arg(long, value_name = "METRIC", value_enum, default_value_t = Metric::Relmse)]
    metric: Metric,

    /// The largest value of --metric that passes; above it the exit status is 1
    /// [default: a match to float precision: relmse 1e-8, rmse 1e-4, flip 1e-3,
    /// max 1e-3; 0 fails on any difference]
    #[arg(long, value_name = "T", value_parser = parse_tolerance)]
    tolerance: Option<f64>,

    /// Measure only this rectangle of pixels: columns x0 to x1 and rows y0 to y1
    /// (from the top), x1 and y1 excluded, e.g. 0,0,64,32 [default: the whole image]
    #[arg(long, value_name = "x0,y0,x1,y1", value_parser = Region::parse)]
    region: Option<Region>,

    /// Write a heat map of the per-pixel error to this PNG file (the whole image,
    /// magma colors from black for no error to light yellow); written atomically
    #[arg(long, value_name = "FILE.png")]
    heatmap: Option<PathBuf>,

    /// The error the heat map shows: flip (per-pixel FLIP, 0 to 1) or relmse
    /// (per-pixel relative squared error)
    #[arg(long, value_name = "METRIC", value_enum, default_value_t = HeatmapMetric::Flip)]
    heatmap_metric: HeatmapMetric,

    /// Print the comparison as JSON (schema glint-diff/1: the same numbers as
    /// the table, the verdict as within_tolerance) instead of the table
    #[arg(long)]
    json: bool,

    /// The error drawn as the top color of the heat map [default: 1 for flip; for
    /// relmse the 99th percentile of the region's per-pixel values]
    #[arg(long, value_name = "S", value_parser = parse_scale)]
    heatmap_scale: Option<f32>,
}

/// The metric the tolerance applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Metric {
    Relmse,
    Rmse,
    Flip,
    Max,
}

impl Metric {
    /// The default tolerance: two renders that agree to float precision
    /// (a student's 64-bit tracer against Glint's 32-bit one, on the
    /// deterministic recipe) pass, anything visible does not. Rounding in
    /// 32 bits moves a value by about 1e-7 of itself: a relative MSE of
    /// 1e-14, far below 1e-8 (an rms relative difference of 1e-4).
    fn default_tolerance(self) -> f64 {
        match self {
            Metric::Relmse => 1e-8,
            Metric::Rmse => 1e-4,
            Metric::Flip | Metric::Max => 1e-3,
        }
    }

    fn label(self) -> &'static str {
        match self {
            Metric::Relmse => "relMSE",
            Metric::Rmse => "RMSE",
            Metric::Flip => "mean FLIP",
            Metric::Max => "max difference",
        }
    }

    fn value(self, c: &Comparison) -> f64 {
        match self {
            Metric::Relmse => c.rel_mse,
            Metric::Rmse => c.rmse,
            Metric::Flip => c.flip,
            Metric::Max => c.max_difference.value as f64,
        }
    }
}

/// The per-pixel error a heat map shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum HeatmapMetric {
    Flip,
    Relmse,
}

fn parse_tolerance(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(t) if t.is_finite() && t >= 0.0 => Ok(t),
        _ => Err("expected a number, 0 or more".into()),
    }
}

fn parse_scale(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(s) if s.is_finite() && s > 0.0 => Ok(s),
        _ => Err("expected a number greater than 0".into()),
    }
}

pub(crate) fn diff(args: &DiffArgs) -> Result<(), Failure> {
    if let Some(path) = &args.heatmap {
        check_heatmap_path(path, &[&args.test, &args.reference])?;
    }
    let test = Film::load(&args.test).map_err(|e| Failure::Input(e.to_string()))?;
    let reference = Film::load(&args.reference).map_err(|e| Failure::Input(e.to_string()))?;
    let (size, reference_size) = (test.resolution(), reference.resolution());
    if size != reference_size {
        return Err(Failure::Input(format!(
            "{}: the image is {}x{}, but {} is {}x{}; glint diff compares images of the same size",
            args.reference.display(),
            reference_size.x,
            reference_size.y,
            args.test.display(),
            size.x,
            size.y
        )));
    }
    let region = args.region.unwrap_or(Region::full(size.x, size.y));
    region
        .check(size.x, size.y)
        .map_err(|e| Failure::Input(format!("{}: --region: {e}", args.test.display())))?;

    let (t, r) = (ImageView::from(&test), ImageView::from(&reference));
    let unmeasurable = |e| Failure::Input(format!("{}: {e}", args.test.display()));
    let flip_map = flip(t, r).map_err(unmeasurable)?;
    let c = compare_with_flip_map(t, r, region, &flip_map).map_err(unmeasurable)?;
    let non_finite = [
        non_finite_count(t, region).map_err(unmeasurable)?,
        non_finite_count(r, region).map_err(unmeasurable)?,
    ];

    let heat = match &args.heatmap {
        Some(path) => Some(write_heatmap(path, args, (t, r), flip_map, region)?),
        None => None,
    };
    let value = args.metric.value(&c);
    let tolerance = args
        .tolerance
        .unwrap_or_else(|| args.metric.default_tolerance());
    // NaN (a NaN or infinity in one image only) is never within tolerance.
    let within = value <= tolerance;
    let label = args.metric.label();
    let out = match args.json {
        true => {
            let verdict = (tolerance, within);
            let document = json_document(
                args,
                (&test, &reference),
                region,
                (&c, non_finite),
                &heat,
                verdict,
            );
            serde_json::to_string_pretty(&document).expect("JSON of numbers and strings") + "\n"
        }
        false => {
            let mut text = table(args, (&test, &reference), region, (&c, non_finite), &heat);
            let (value, tolerance) = (number(value), tolerance_text(args, tolerance));
            text += &match within {
                true => format!("within tolerance: {label} {value} <= {tolerance}\n"),
                false => format!("beyond tolerance: {label} {value} > {tolerance}\n"),
            };
            text
        }
    };
    crate::output::say(&out);
    if within {
        Ok(())
    } else {
        Err(Failure::Verdict(Some(format!(
            "{} differs from {} beyond the tolerance: {label} {} > {}",
            args.test.display(),
            args.reference.display(),
            number(value),
            tolerance_text(args, tolerance)
        ))))
    }
}

/// The tolerance as the verdict prints it, saying when it is the default.
fn tolerance_text(args: &DiffArgs, tolerance: f64) -> String {
    match args.tolerance {
        Some(_) => number(tolerance),
        None => format!(
            "{} (the default: a match to float precision)",
            number(tolerance)
        ),
    }
}

/// A measurement refused after [`diff`] checked its sizes and region.
fn other(e: glint_metrics::MetricsError) -> Failure {
    Failure::Other(e.to_string())
}

/// The heat map written: its file, the error it shows and its scale.
struct Heat {
    path: PathBuf,
    name: &'static str,
    scale: f32,
}

fn write_heatmap(
    path: &std::path::Path,
    args: &DiffArgs,
    (t, r): (ImageView, ImageView),
    flip_map: ErrorMap,
    region: Region,
) -> Result<Heat, Failure> {
    let (map, name) = match args.heatmap_metric {
        HeatmapMetric::Flip => (flip_map, "FLIP"),
        HeatmapMetric::Relmse => (rel_mse_map(t, r).map_err(other)?, "relMSE per pixel"),
    };
    let scale = args
        .heatmap_scale
        .unwrap_or_else(|| match args.heatmap_metric {
            HeatmapMetric::Flip => 1.0,
            HeatmapMetric::Relmse => percentile_99(&map, region),
        });
    let colors = heatmap(&map, scale).map_err(other)?;
    save_heatmap(path, map.width, map.height, &colors).map_err(Failure::Other)?;
    Ok(Heat {
        path: path.to_owned(),
        name,
        scale,
    })
}

/// The comparison as the table `glint diff` prints.
fn table(
    args: &DiffArgs,
    (test, reference): (&Film, &Film),
    region: Region,
    (c, non_finite): (&Comparison, [u64; 2]),
    heat: &Option<Heat>,
) -> String {
    let size = test.resolution();
    let mut table = Table::default();
    table.row("A (test)", [args.test.display().to_string()]);
    table.row("B (reference)", [args.reference.display().to_string()]);
    table.row("size", [format!("{}x{}", size.x, size.y)]);
    let region_text = if region == Region::full(size.x, size.y) {
        format!("whole image ({} pixels)", region.pixel_count())
    } else {
        format!("{region} ({} pixels)", region.pixel_count())
    };
    table.row("region", [region_text]);
    table.row("", ["A".to_string(), "B".to_string()]);
    for (i, name) in ["mean R", "mean G", "mean B"].into_iter().enumerate() {
        table.row(
            name,
            [number(c.means_test[i]), number(c.means_reference[i])],
        );
    }
    table.row("non-finite", non_finite.map(|n| n.to_string()));
    table.row("RMSE", [number(c.rmse)]);
    table.row("relMSE", [number(c.rel_mse)]);
    table.row("mean FLIP", [number(c.flip)]);
    let m = c.max_difference;
    let max_text = if m.value == 0.0 {
        "0 (identical)".to_string()
    } else {
        let channel = |film: &Film| film.pixel(m.x, m.y)[m.channel] as f64;
        format!(
            "{} at pixel ({}, {}), channel {} (A {}, B {})",
            number(m.value as f64),
            m.x,
            m.y,
            m.channel_name(),
            number(channel(test)),
            number(channel(reference))
        )
    };
    table.row("max difference", [max_text]);
    if let Some(h) = heat {
        table.row(
            "heat map",
            [format!(
                "{} ({}, scale {})",
                h.path.display(),
                h.name,
                number(h.scale as f64)
            )],
        );
    }
    table.render()
}

/// The comparison as JSON (schema `glint-diff/1`); non-finite numbers are
/// `null`.
fn json_document(
    args: &DiffArgs,
    (test, reference): (&Film, &Film),
    region: Region,
    (c, non_finite): (&Comparison, [u64; 2]),
    heat: &Option<Heat>,
    (tolerance, within): (f64, bool),
) -> serde_json::Value {
    use serde_json::json;
    let finite = |v: f64| v.is_finite().then_some(v);
    let m = c.max_difference;
    let size = test.resolution();
    json!({
        "schema": "glint-diff/1",
        "test": args.test.display().to_string(),
        "reference": args.reference.display().to_string(),
        "size": [size.x, size.y],
        "region": [region.x0, region.y0, region.x1, region.y1],
        "means": {
            "test": c.means_test.to_array().map(finite),
            "reference": c.means_reference.to_array().map(finite),
        },
        "non_finite": {"test": non_finite[0], "reference": non_finite[1]},
        "rmse": finite(c.rmse),
        "rel_mse": finite(c.rel_mse),
        "flip": finite(c.flip),
        "max_difference": {
            "value": finite(m.value as f64),
            "pixel": [m.x, m.y],
            "channel": m.channel_name(),
            "test": finite(test.pixel(m.x, m.y)[m.channel] as f64),
            "reference": finite(reference.pixel(m.x, m.y)[m.channel] as f64),
        },
        "heatmap": heat.as_ref().map(|h| json!({
            "file": h.path.display().to_string(),
            "error": h.name,
            "scale": h.scale,
        })),
        "metric": args.metric.label(),
        "value": finite(args.metric.value(c)),
        "tolerance": tolerance,
        "within_tolerance": within,
    })
}

/// The 99th percentile of the finite values of `map` in `region`, or 1 if it is
/// not positive (no error at all): a scale that fireflies do not flatten.
fn percentile_99(map: &ErrorMap, region: Region) -> f32 {
    glint_metrics::heatmap_scale((region.y0..region.y1).flat_map(|y| {
        let start = y as usize * map.width as usize;
        map.values[start + region.x0 as usize..start + region.x1 as usize]
            .iter()
            .copied()
    }))
}

/// A number for the table: about six significant digits, plain between 1e-4 and
/// 1e6, scientific outside; NaN and infinities by name.
fn number(v: f64) -> String {
    if v.is_nan() {
        return "NaN".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf" } else { "-inf" }.into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs();
    if !(1e-4..1e6).contains(&magnitude) {
        return format!("{v:.5e}");
    }
    let decimals = (5 - magnitude.log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// Rows of a label and one or two values, aligned in columns.
#[derive(Default)]
struct Table {
    rows: Vec<(String, Vec<String>)>,
}

impl Table {
    fn row<const N: usize>(&mut self, label: &str, values: [String; N]) {
        self.rows.push((label.to_string(), values.to_vec()));
    }

    fn render(&self) -> String {
        const LABEL_WIDTH: usize = 16;
        // The first column is as wide as its widest entry among two-value rows.
        let first = self
            .rows
            .iter()
            .filter(|(_, v)| v.len() > 1)
            .map(|(_, v)| v[0].chars().count())
            .max()
            .unwrap_or(0);
        let mut out = String::new();
        for (label, values) in &self.rows {
            let mut line = format!("{label:<LABEL_WIDTH$}");
            match values.as_slice() {
                [a, b] => line += &format!("{a:<first$}  {b}"),
                [a] => line += a,
                _ => {}
            }
            out += line.trim_end();
            out.push('\n');
        }
        out
    }
}
