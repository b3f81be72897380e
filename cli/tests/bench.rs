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
    ] {
        assert!(help.contains(flag), "{flag} undocumented");
    }
}
