//! Glint's lat-long environment lighting against Mitsuba 3's, through
//! `measure/mitsuba/envmap.py`: a diffuse sphere under the shipped map, with the
//! map resampled onto Mitsuba's rows (docs/environment-lighting.md). Needs a
//! Python with the `mitsuba` package (`GLINT_MITSUBA_VENV`, or
//! `target/mitsuba-venv` as `.ci/run` makes it); elsewhere it says so and
//! skips, and under `CI=true` fails.

mod common;
use common::{python_with_mitsuba, repo};

use std::process::Command;

/// The three ratios of a table cell such as `0.9995, 0.9995, 0.9994`.
fn ratios(cell: &str) -> Vec<f64> {
    cell.split(',').map(|r| r.trim().parse().unwrap()).collect()
}

#[test]
fn a_diffuse_sphere_under_the_shipped_map_agrees_with_mitsuba() {
    let Some(python) = python_with_mitsuba() else {
        return;
    };
    let out = Command::new(python)
        .arg(repo().join("measure/mitsuba/envmap.py"))
        .arg(repo().join("scenes/environments/studio-latlong.hdr"))
        .args(["--spp", "16", "--glint", env!("CARGO_BIN_EXE_glint")])
        .output()
        .expect("python runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let row = text
        .lines()
        .find(|l| l.starts_with("| studio-latlong.hdr"))
        .unwrap_or_else(|| panic!("no row for the map in:\n{text}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    // One radiance function: the means must agree within 0.3% (the bound the
    // accuracy issue sets); over seeds 0 to 3 they were 0.9997 to 1.0007.
    for r in ratios(cells[3]) {
        assert!((r - 1.0).abs() < 3e-3, "Glint / Mitsuba = {r}: {row}");
    }
}
