//! What a bench found, as data (serialised to JSON), as a table for the terminal
//! and as CSV.

use crate::machine::Machine;
use crate::reference::Origin;
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// The whole result of a bench.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    /// The scene file, as given.
    pub scene: String,
    /// Its file name without extension (used in file names and the plot's title).
    pub scene_name: String,
    pub glint_version: String,
    pub machine: Machine,
    pub resolution: [u32; 2],
    /// The pixels errors are measured over, `[x0, y0, x1, y1)`, and their name.
    pub region: RegionSummary,
    pub reference: ReferenceSummary,
    /// Runs per budget; times are their median.
    pub repeat: usize,
    pub rows: Vec<Row>,
    pub strategies: Vec<StrategySummary>,
    /// The strategy speed-ups are measured against, and the error they are
    /// measured at (its relative MSE at its largest budget).
    pub baseline: Option<Baseline>,
    pub heatmaps: Option<HeatmapSummary>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RegionSummary {
    pub name: Option<String>,
    pub pixels: [u32; 4],
    pub whole_image: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ReferenceSummary {
    pub origin: Origin,
    pub rounds: u32,
    /// Samples per pixel of each round: camera samples, or at pixel centres
    /// (`pixel_centre`) light and environment samples of one camera sample.
    pub spp_per_round: u32,
    pub total_spp: u64,
    pub pixel_centre: bool,
    /// The reference's expected contribution to a measured relative MSE.
    pub noise_rel_mse: Option<f64>,
    /// The smallest relative MSE the sweep measured, and whether the reference's
    /// noise is at least ten times below it.
    pub smallest_rel_mse: f64,
    pub noise_goal_met: Option<bool>,
    pub render_seconds: f64,
}

/// One strategy at one budget.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    pub strategy: String,
    pub spp: u32,
    pub light_samples: u32,
    pub environment_samples: u32,
    /// `spp · light_samples`.
    pub total_samples: u64,
    pub time_median_s: f64,
    pub time_min_s: f64,
    pub time_max_s: f64,
    /// The first run's time, which includes one-off work (MIP pyramids).
    pub time_first_s: f64,
    pub runs: usize,
    pub camera_rays: u64,
    pub shadow_rays: u64,
    pub reflection_rays: u64,
    pub rmse: f64,
    pub rel_mse: f64,
    pub flip: f64,
    /// `1 / (relMSE · seconds)`: higher is better.
    pub efficiency: f64,
}

/// A strategy's convergence and speed-up.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StrategySummary {
    pub name: String,
    /// Fitted log–log slopes of relative MSE and of RMSE against total samples.
    pub rel_mse_slope: Option<f64>,
    pub rmse_slope: Option<f64>,
    /// Render time of the baseline at the target error over this strategy's
    /// (interpolated on its log–log curve of relMSE against time).
    pub equal_error_speedup: Option<f64>,
    /// Whether reaching the target error lay outside this strategy's measured
    /// range, so that its curve was extended.
    pub speedup_extrapolated: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Baseline {
    pub strategy: String,
    pub target_rel_mse: f64,
    pub target_total_samples: u64,
    pub time_s: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HeatmapSummary {
    /// The budget the heat maps show (its index on the ladder, and its spp).
    pub step: usize,
    /// Per-pixel relative MSE mapped to the colour scale's top (magma): the same
    /// for every strategy, so that their maps compare.
    pub scale: f32,
    pub files: Vec<String>,
}

impl Report {
    /// The rows as an aligned table, then each strategy's slope and speed-up.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let header = [
            "strategy",
            "spp",
            "light",
            "time",
            "rays",
            "RMSE",
            "relMSE",
            "FLIP",
            "efficiency",
        ];
        let mut cells: Vec<[String; 9]> = vec![header.map(String::from)];
        for r in &self.rows {
            cells.push([
                r.strategy.clone(),
                r.spp.to_string(),
                r.light_samples.to_string(),
                format_seconds(r.time_median_s),
                format_count(r.camera_rays + r.shadow_rays + r.reflection_rays),
                format_sig(r.rmse),
                format_sig(r.rel_mse),
                format_sig(r.flip),
                format_sig(r.efficiency),
            ]);
        }
        let widths: Vec<usize> = (0..9)
            .map(|c| {
                cells
                    .iter()
                    .map(|row| row[c].chars().count())
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        for (i, row) in cells.iter().enumerate() {
            let line: Vec<String> = row
                .iter()
                .zip(&widths)
                .enumerate()
                .map(|(c, (cell, &w))| {
                    if c == 0 {
                        format!("{cell:<w$}")
                    } else {
                        format!("{cell:>w$}")
                    }
                })
                .collect();
            writeln!(out, "{}", line.join("  ").trim_end()).unwrap();
            if i == 0 {
                let rule: Vec<String> = widths.iter().map(|&w| "-".repeat(w)).collect();
                writeln!(out, "{}", rule.join("  ")).unwrap();
            }
        }
        writeln!(out).unwrap();
        let (by_error, by_efficiency) = self.rankings();
        writeln!(out, "ranked by relMSE at the largest budget: {by_error}").unwrap();
        writeln!(out, "ranked by efficiency there: {by_efficiency}").unwrap();
        let one_budget = self
            .strategies
            .iter()
            .all(|s| self.rows.iter().filter(|r| r.strategy == s.name).count() < 2);
        if let (Some(b), false) = (&self.baseline, one_budget) {
            writeln!(
                out,
                "speed-up: render time of {} to reach its relMSE at {} samples ({}), over each strategy's",
                b.strategy,
                b.target_total_samples,
                format_sig(b.target_rel_mse)
            )
            .unwrap();
        }
        for s in self.strategies.iter().filter(|_| !one_budget) {
            let slope = |x: Option<f64>| x.map_or("—".into(), |v| format!("{v:+.2}"));
            let speedup = match s.equal_error_speedup {
                Some(v) if s.speedup_extrapolated => format!("{v:.2}× (extrapolated)"),
                Some(v) => format!("{v:.2}×"),
                None => "—".into(),
            };
            writeln!(
                out,
                "{}: relMSE slope {}, RMSE slope {}, equal-error speed-up {}",
                s.name,
                slope(s.rel_mse_slope),
                slope(s.rmse_slope),
                speedup
            )
            .unwrap();
        }
        let r = &self.reference;
        let noise = match (r.noise_rel_mse, r.noise_goal_met) {
            (Some(n), Some(true)) => format!(
                "noise {} (≥{:.0}× below the smallest error, {})",
                format_sig(n),
                r.smallest_rel_mse / n.max(f64::MIN_POSITIVE),
                format_sig(r.smallest_rel_mse)
            ),
            (Some(n), _) => format!(
                "noise {} — only {:.1}× below the smallest error, {}: raise --reference-spp",
                format_sig(n),
                r.smallest_rel_mse / n.max(f64::MIN_POSITIVE),
                format_sig(r.smallest_rel_mse)
            ),
            (None, _) => "noise unknown (a file)".into(),
        };
        let unit = if r.pixel_centre {
            "light samples at pixel centres"
        } else {
            "spp"
        };
        let source = match &r.origin {
            Origin::File { path } => format!("{}", path.display()),
            Origin::Rendered { cached, .. } => format!(
                "{} rounds × {} {unit}{}",
                r.rounds,
                r.spp_per_round,
                if *cached { ", cached" } else { "" }
            ),
        };
        writeln!(out, "reference: {source}; {noise}").unwrap();
        let region = &self.region;
        if !region.whole_image {
            let [x0, y0, x1, y1] = region.pixels;
            let name = region
                .name
                .as_ref()
                .map_or(String::new(), |n| format!("{n}: "));
            writeln!(
                out,
                "errors over the region {name}x {x0}..{x1}, y {y0}..{y1}"
            )
            .unwrap();
        }
        writeln!(out, "machine: {}", self.machine.label()).unwrap();
        out
    }

    /// The strategies at their largest budget (the last row of each), best first:
    /// by relative MSE, and by efficiency.
    fn rankings(&self) -> (String, String) {
        let last: Vec<&Row> = self
            .strategies
            .iter()
            .filter_map(|s| self.rows.iter().rev().find(|r| r.strategy == s.name))
            .collect();
        let mut by_error = last.clone();
        by_error.sort_by(|a, b| a.rel_mse.total_cmp(&b.rel_mse));
        let mut by_efficiency = last;
        by_efficiency.sort_by(|a, b| b.efficiency.total_cmp(&a.efficiency));
        let list = |rows: &[&Row], value: fn(&Row) -> f64| {
            rows.iter()
                .map(|r| format!("{} {}", r.strategy, format_sig(value(r))))
                .collect::<Vec<_>>()
                .join(", ")
        };
        (
            list(&by_error, |r| r.rel_mse),
            list(&by_efficiency, |r| r.efficiency),
        )
    }

    /// One line per row, with a header; fields needing it are quoted.
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "strategy,spp,light_samples,environment_samples,total_samples,time_median_s,time_min_s,time_max_s,time_first_s,runs,camera_rays,shadow_rays,reflection_rays,rmse,rel_mse,flip,efficiency\n",
        );
        for r in &self.rows {
            writeln!(
                out,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                csv_field(&r.strategy),
                r.spp,
                r.light_samples,
                r.environment_samples,
                r.total_samples,
                r.time_median_s,
                r.time_min_s,
                r.time_max_s,
                r.time_first_s,
                r.runs,
                r.camera_rays,
                r.shadow_rays,
                r.reflection_rays,
                r.rmse,
                r.rel_mse,
                r.flip,
                r.efficiency
            )
            .unwrap();
        }
        out
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// Four significant digits, in scientific notation outside [0.001, 10 000).
pub fn format_sig(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".into();
    }
    if (1e-3..1e4).contains(&x.abs()) {
        let decimals = (3 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Seconds as `812 ms` or `3.41 s`.
pub fn format_seconds(s: f64) -> String {
    if s < 1.0 {
        format!("{:.0} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

/// A count as `12.3 M` or `845 k`.
fn format_count(n: u64) -> String {
    let x = n as f64;
    if x >= 1e9 {
        format!("{:.2} G", x / 1e9)
    } else if x >= 1e6 {
        format!("{:.1} M", x / 1e6)
    } else if x >= 1e3 {
        format!("{:.0} k", x / 1e3)
    } else {
        n.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_four_significant_digits() {
        assert_eq!(format_sig(0.012345), "0.01235");
        assert_eq!(format_sig(123.456), "123.5");
        assert_eq!(format_sig(1.5e-6), "1.500e-6");
        assert_eq!(format_sig(0.0), "0");
        assert_eq!(format_sig(f64::INFINITY), "inf");
        assert_eq!(format_seconds(0.0123), "12 ms");
        assert_eq!(format_seconds(3.456), "3.46 s");
        assert_eq!(format_count(12_345_678), "12.3 M");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("sobol/random"), "sobol/random");
    }
}
