//! Benches run apart, put together: the results of tasks that each measured
//! some strategies at some budgets of one scene against one reference (on as
//! many machines, `glint farm … bench`), as the one report a single bench
//! would have written, their rows together and the fits, the baseline and the
//! speed-ups computed over all of them.

use crate::reference::{self, Origin};
use crate::report::Report;
use crate::Bench;

/// One report of `reports` (each a task's `results.json`, named by `names`
/// in errors): the rows of all, in the order of the strategies' first
/// appearance, then by budget. Refused: reports of other scenes,
/// resolutions, regions, references, repeat counts or Glint versions, and a
/// strategy measured twice at one budget. The heat maps are left out: each
/// task's are coloured on its own scale, so they would not compare.
pub fn merge(reports: Vec<Report>, names: &[String]) -> Result<Bench, String> {
    let first = reports.first().ok_or("no results to merge")?;
    for (report, name) in reports.iter().zip(names).skip(1) {
        same_bench(first, report).map_err(|what| {
            format!(
                "{name}: another {what} than {}'s; merge the tasks of one bench",
                names[0]
            )
        })?;
    }
    let mut strategies: Vec<String> = Vec::new();
    let mut rows = Vec::new();
    for report in &reports {
        for row in &report.rows {
            if !strategies.contains(&row.strategy) {
                strategies.push(row.strategy.clone());
            }
            let budget = |r: &crate::report::Row| {
                (
                    r.strategy.clone(),
                    r.spp,
                    r.light_samples,
                    r.environment_samples,
                )
            };
            if rows.iter().any(|r| budget(r) == budget(row)) {
                return Err(format!(
                    "{} at {} spp × {} light samples is measured by two tasks; merge each once",
                    row.strategy, row.spp, row.light_samples
                ));
            }
            rows.push(row.clone());
        }
    }
    let order = |name: &str| strategies.iter().position(|s| s == name);
    rows.sort_by(|a, b| {
        (order(&a.strategy), a.total_samples)
            .cmp(&(order(&b.strategy), b.total_samples))
            .then(a.time_median_s.total_cmp(&b.time_median_s))
    });
    let smallest = rows.iter().map(|r| r.rel_mse).fold(f64::INFINITY, f64::min);
    let mut reference = first.reference.clone();
    reference.smallest_rel_mse = smallest;
    reference.noise_goal_met = reference
        .noise_rel_mse
        .map(|n| n * reference::NOISE_MARGIN <= smallest);
    let report = Report {
        strategies: crate::summaries(&strategies, &rows),
        baseline: crate::baseline(&strategies, &rows),
        rows,
        reference,
        heatmaps: None,
        ..first.clone()
    };
    Ok(Bench {
        report,
        heatmaps: Vec::new(),
    })
}

/// What differs between two reports that must be of one bench, if anything.
fn same_bench(a: &Report, b: &Report) -> Result<(), &'static str> {
    let reference_of = |r: &Report| match &r.reference.origin {
        Origin::File { path } => Some(path.clone()),
        Origin::Rendered { .. } => None,
    };
    let checks = [
        (a.scene_name == b.scene_name, "scene"),
        (a.resolution == b.resolution, "resolution"),
        (a.region.pixels == b.region.pixels, "region"),
        (a.repeat == b.repeat, "repeat count"),
        (a.glint_version == b.glint_version, "Glint version"),
        (reference_of(a) == reference_of(b), "reference"),
    ];
    match checks.iter().find(|(same, _)| !same) {
        Some((_, what)) => Err(what),
        None => Ok(()),
    }
}
