//! `glint bench` as a user runs it: the table, the files, the cached reference,
//! and one error line with exit status 2 for bad input, before any work.

mod common;

use common::{assert_input_error, glint, scene};
use std::path::Path;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

const SMALL: [&str; 6] = [
    "--resolution",
    "16x16",
    "--spp",
    "1,4,16",
    "--samplers",
    "random,sobol",
];

#[test]
fn a_bench_prints_its_table_and_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let args = [&["bench", set1.as_str(), "-o", "out"], &SMALL[..]].concat();
    let o = glint(&args, dir.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(out.starts_with("strategy"), "{out}");
    assert!(out.contains("sobol: relMSE slope"), "{out}");
    assert!(out.contains("equal-error speed-up"), "{out}");
    assert!(
        out.contains("reference: 2 rounds") || out.contains("reference: 4 rounds"),
        "{out}"
    );
    for file in [
        "results.csv",
        "results.json",
        "relmse-vs-time.png",
        "relmse-vs-time.svg",
        "heatmap-random.png",
        "heatmap-sobol.png",
    ] {
        assert!(dir.path().join("out").join(file).is_file(), "{file}");
    }
    // The second bench starts from the cached reference.
    let again = glint(&args, dir.path());
    assert!(again.status.success(), "{}", text(&again.stderr));
    assert!(
        text(&again.stdout).contains("spp, cached"),
        "{}",
        text(&again.stdout)
    );
    // No temporary file is left behind.
    let leftovers = std::fs::read_dir(dir.path().join("out"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with('.')
        })
        .count();
    assert_eq!(leftovers, 0);
}

#[test]
fn a_named_region_is_measured_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let args = [
        &[
            "bench",
            set1.as_str(),
            "--region",
            "floor-shadows",
            "--repeat",
            "2",
        ],
        &SMALL[..],
    ]
    .concat();
    let o = glint(&args, dir.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    // 16 × 16 is 1/32 of the scene's 512 × 512: [72, 480, 440, 512] becomes this.
    assert!(
        text(&o.stdout).contains("errors over the region floor-shadows: x 2..14, y 15..16"),
        "{}",
        text(&o.stdout)
    );
    assert!(dir.path().join("cornell-set1-bench/results.json").is_file());
}

#[test]
fn bad_input_gives_one_line_and_exit_2_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let bench = |extra: &[&str]| {
        let args = [&["bench", set1.as_str(), "--resolution", "8x8"], extra].concat();
        glint(&args, dir.path())
    };
    assert_input_error(&bench(&["--samplers", "sobol,halton"]), "\"halton\"");
    assert_input_error(
        &bench(&["--samplers", "grid", "--spp", "1,2"]),
        "perfect squares",
    );
    assert_input_error(&bench(&["--spp", "4,1"]), "grow");
    // A count past the limit at a later step is refused before the first render.
    assert_input_error(&bench(&["--spp", "1,2000000"]), "more than the limit");
    assert_input_error(&bench(&["--spp", "1,x"]), "--spp");
    assert_input_error(&bench(&["--region", "nowhere"]), "\"nowhere\"");
    assert_input_error(&bench(&["--region", "0,0,9,9"]), "--region");
    assert_input_error(&bench(&["--time", "1h"]), "--time");
    assert_input_error(&bench(&["--texture-filters", "box"]), "--texture-filters");
    assert_input_error(&bench(&["--reference", "missing.exr"]), "missing.exr");
    std::fs::write(dir.path().join("a-file"), "x").unwrap();
    assert_input_error(&bench(&["-o", "a-file"]), "a-file");
    let o = glint(&["bench", "no-such-scene.toml"], dir.path());
    assert_input_error(&o, "no-such-scene.toml");
    // Nothing was written for any of them.
    let entries: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(entries, ["a-file"], "{entries:?}");
}

#[test]
fn help_documents_every_flag() {
    let o = glint(&["bench", "--help"], Path::new("."));
    assert!(o.status.success());
    let help = text(&o.stdout);
    for flag in [
        "--output",
        "--samplers",
        "--texture-filters",
        "--spp",
        "--light-samples",
        "--environment-samples",
        "--time",
        "--repeat",
        "--region",
        "--reference",
        "--reference-spp",
        "--reference-texture-filter",
        "--reference-pixel",
        "--heatmap-step",
        "--resolution",
        "--seed",
        "--threads",
        "--max-depth",
        "--merge",
    ] {
        assert!(help.contains(flag), "{flag} undocumented");
    }
}

/// The deterministic columns of a results.json's rows (not the times), keyed
/// by strategy and budget.
fn rows(dir: &Path) -> Vec<(String, u64, Vec<f64>)> {
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    let mut rows: Vec<(String, u64, Vec<f64>)> = json["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let values = ["rmse", "rel_mse", "flip", "camera_rays", "shadow_rays"]
                .map(|k| r[k].as_f64().unwrap())
                .to_vec();
            (
                r["strategy"].as_str().unwrap().to_owned(),
                r["total_samples"].as_u64().unwrap(),
                values,
            )
        })
        .collect();
    rows.sort_by(|a, b| (&a.0, a.1).cmp(&(&b.0, b.1)));
    rows
}

/// Runs glint in `d`, which must succeed; returns its stdout.
fn succeeds(args: &[&str], d: &Path) -> String {
    let o = glint(args, d);
    assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
    text(&o.stdout)
}

/// A 16 × 16 reference for `scene` in `d`: 256 samples with `seed`.
fn reference(scene: &str, seed: &str, name: &str, d: &Path) {
    let args = ["render", scene, "--resolution", "16x16", "--spp", "256"];
    succeeds(&[&args[..], &["--seed", seed, "-o", name]].concat(), d);
}

/// The same rows (strategies, budgets, errors and rays), the metrics to the
/// last bits their parallel sums may round apart.
fn assert_same_rows(whole: &Path, merged: &Path, count: usize) {
    let (whole, merged) = (rows(whole), rows(merged));
    assert_eq!((whole.len(), merged.len()), (count, count));
    for (a, b) in whole.iter().zip(&merged) {
        assert_eq!((&a.0, a.1), (&b.0, b.1));
        for (x, y) in a.2.iter().zip(&b.2) {
            assert!((x - y).abs() <= 1e-12 * x.abs(), "{a:?} against {b:?}");
        }
    }
}

/// Benches run apart (a strategy's budgets split between two tasks) and put
/// together with `--merge` give the single bench's rows and fits; tasks of
/// another reference, or one measured twice, are refused.
#[test]
fn merged_tasks_give_the_single_bench_s_rows_and_fits() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let set1 = scene("cornell-set1");
    let run = |args: &[&str]| succeeds(args, d);
    for (seed, name) in [("777", "ref.exr"), ("778", "other-ref.exr")] {
        reference(&set1, seed, name, d);
    }
    let bench = |samplers: &str, spp: &str, reference: &str, out: &str| {
        let args = [
            "bench",
            &set1,
            "--resolution",
            "16x16",
            "--samplers",
            samplers,
            "--spp",
            spp,
        ];
        run(&[&args[..], &["--reference", reference, "-o", out]].concat());
    };
    bench("random,sobol", "1,4,16", "ref.exr", "whole");
    bench("random", "1,4", "ref.exr", "t0");
    bench("random", "16", "ref.exr", "t1");
    bench("sobol", "1,4,16", "ref.exr", "t2");
    let table = run(&["bench", &set1, "--merge", "t2", "t0", "t1", "-o", "merged"]);
    assert!(
        table.contains("sobol: relMSE slope") && table.contains("from 3 tasks"),
        "{table}"
    );
    assert_same_rows(&d.join("whole"), &d.join("merged"), 6);
    let slopes = |dir: &str| -> Vec<(String, f64)> {
        let json: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(d.join(dir).join("results.json")).unwrap(),
        )
        .unwrap();
        let mut s: Vec<(String, f64)> = json["strategies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| {
                (
                    s["name"].as_str().unwrap().to_owned(),
                    s["rel_mse_slope"].as_f64().unwrap(),
                )
            })
            .collect();
        s.sort_by(|a, b| a.0.cmp(&b.0));
        s
    };
    for ((a, x), (b, y)) in slopes("whole").iter().zip(&slopes("merged")) {
        assert_eq!(a, b);
        assert!((x - y).abs() < 1e-9, "{a}: {x} against {y}");
    }
    assert!(d.join("merged/relmse-vs-time.png").exists());
    bench("sobol", "1,4,16", "other-ref.exr", "t3");
    let o = glint(&["bench", &set1, "--merge", "t0", "t3", "-o", "bad"], d);
    assert_input_error(&o, "t3: another reference than t0's");
    let o = glint(&["bench", &set1, "--merge", "t0", "t0", "-o", "bad"], d);
    assert_input_error(
        &o,
        "random at 1 spp × 1 light samples is measured by two tasks",
    );
    let o = glint(&["bench", &set1, "--merge", "nowhere", "-o", "bad"], d);
    assert_input_error(&o, "--merge: nowhere/results.json");
    assert!(!d.join("bad").exists());
}

/// `glint farm parallel bench` splits a sweep into one task per strategy
/// and budget; its scripts, run by hand in any order, then merged, give the
/// single bench's rows and slopes. Its options are checked first.
#[test]
fn a_farmed_sweep_gives_the_single_bench_s_rows_and_fits() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let set1 = scene("cornell-set1");
    let run = |args: &[&str]| succeeds(args, d);
    reference(&set1, "777", "ref.exr", d);
    let measure = [
        "--resolution",
        "16x16",
        "--samplers",
        "random,sobol",
        "--spp",
        "1,4,16",
    ];
    let reference = ["--reference", "ref.exr"];
    run(&[
        &["bench", &set1, "-o", "whole"],
        &measure[..],
        &reference[..],
    ]
    .concat());
    let said = run(&[
        &[
            "farm", "parallel", "bench", &set1, "--dir", "farm", "-o", "merged", "--",
        ],
        &measure[..],
        &reference[..],
    ]
    .concat());
    assert!(
        said.contains("6 tasks (2 strategies × 3 budgets)"),
        "{said}"
    );
    let farm = d.join("farm");
    for task in [5, 0, 3, 1, 4, 2] {
        let o = std::process::Command::new(farm.join("bench-task.sh"))
            .arg(task.to_string())
            .output()
            .unwrap();
        assert!(o.status.success(), "task {task}: {}", text(&o.stderr));
    }
    let o = std::process::Command::new(farm.join("merge-bench.sh"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_same_rows(&d.join("whole"), &d.join("merged"), 6);
    for (args, expected) in [
        (vec!["--spp", "1,4"], "give --reference FILE"),
        (
            vec!["--reference", "gone.exr"],
            "--reference gone.exr: no such file",
        ),
        (
            vec!["--reference", "ref.exr", "--threads", "2"],
            "--threads is set by glint farm",
        ),
        (
            vec!["--reference", "ref.exr", "--spp", "x"],
            "--spp: expected whole numbers",
        ),
    ] {
        let mut all = vec![
            "farm",
            "parallel",
            "bench",
            set1.as_str(),
            "--dir",
            "bad",
            "--",
        ];
        all.extend(args);
        assert_input_error(&glint(&all, d), expected);
        assert!(!d.join("bad").exists());
    }
}
