//! `glint diff` as a user runs it: the table and its JSON, the exit statuses (0
//! within the tolerance, 1 beyond it, 2 for bad input), heat maps, PPM input,
//! and one-line errors.

use glam::{UVec2, Vec3};
use glint_camera::Film;
use std::path::Path;
use std::process::Output;

mod common;

use common::{assert_input_error, glint, stderr, stdout};

/// A 4 × 2 film of mid grays.
fn base() -> Film {
    let mut film = Film::new(UVec2::new(4, 2));
    for y in 0..2 {
        for x in 0..4 {
            film.set_pixel(x, y, Vec3::new(0.5, 0.25, 0.125) * (1.0 + x as f32 / 4.0));
        }
    }
    film
}

/// `base()` with pixel (3, 1) brighter by 0.5 in green.
fn changed() -> Film {
    let mut film = base();
    let p = film.pixel(3, 1);
    film.set_pixel(3, 1, p + Vec3::new(0.0, 0.5, 0.0));
    film
}

fn write(dir: &Path, name: &str, film: &Film) {
    film.save(&dir.join(name)).unwrap();
}

#[test]
fn a_match_to_float_precision_passes_by_default_and_tolerance_0_asks_for_equal() {
    let dir = images();
    let mut nudged = base();
    let p = nudged.pixel(2, 0);
    nudged.set_pixel(2, 0, p * (1.0 + 3.0 * f32::EPSILON));
    write(dir.path(), "nudged.pfm", &nudged);
    let o = glint(&["diff", "nudged.pfm", "b.pfm"], dir.path());
    assert_exit(&o, 0);
    let out = stdout(&o);
    let verdict = out.lines().last().unwrap();
    assert!(verdict.starts_with("within tolerance: relMSE "), "{out}");
    assert!(
        verdict.contains("e-1"),
        "scientific, as in the table: {out}"
    );
    assert!(
        verdict.ends_with("<= 1.00000e-8 (the default: a match to float precision)"),
        "{out}"
    );
    let o = glint(
        &["diff", "nudged.pfm", "b.pfm", "--tolerance", "0"],
        dir.path(),
    );
    assert_exit(&o, 1);
}

/// A directory with `a.pfm` (changed) and `b.pfm` (base), and `same.pfm` (base).
fn images() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "a.pfm", &changed());
    write(dir.path(), "b.pfm", &base());
    write(dir.path(), "same.pfm", &base());
    dir
}

fn assert_exit(o: &Output, code: i32) {
    assert_eq!(
        o.status.code(),
        Some(code),
        "stdout:\n{}stderr:\n{}",
        stdout(o),
        stderr(o)
    );
}

#[test]
fn identical_images_exit_0_with_every_metric_0() {
    let dir = images();
    let o = glint(&["diff", "same.pfm", "b.pfm"], dir.path());
    assert_exit(&o, 0);
    let out = stdout(&o);
    for line in [
        "A (test)        same.pfm",
        "B (reference)   b.pfm",
        "size            4x2",
        "region          whole image (8 pixels)",
        "non-finite      0",
        "RMSE            0\n",
        "relMSE          0\n",
        "mean FLIP       0\n",
        "max difference  0 (identical)",
    ] {
        assert!(out.contains(line), "{line:?} in\n{out}");
    }
    assert!(
        out.ends_with(
            "within tolerance: relMSE 0 <= 1.00000e-8 (the default: a match to float precision)\n"
        ),
        "{out}"
    );
    assert_eq!(stderr(&o), "");
}

#[test]
fn the_table_shows_the_means_and_where_the_largest_difference_is() {
    let dir = images();
    let o = glint(&["diff", "a.pfm", "b.pfm"], dir.path());
    let out = stdout(&o);
    // Green at (3, 1): 0.25 · 1.75 = 0.4375 in B, 0.9375 in A.
    assert!(
        out.contains("max difference  0.5 at pixel (3, 1), channel G (A 0.9375, B 0.4375)"),
        "{out}"
    );
    // RMSE = √(0.25 / 24); relMSE = 0.25 / (0.4375 + 0.01)² / 24.
    assert!(
        out.contains(&format!("RMSE            {:.6}", (0.25f64 / 24.0).sqrt())),
        "{out}"
    );
    // 0.25 / (0.4375 + 0.01)² / 24 = 0.05201669, printed with six significant digits.
    assert!(out.contains("relMSE          0.0520167\n"), "{out}");
    // Mean of R over both rows: 0.5 · (1 + 1.25 + 1.5 + 1.75) / 4 = 0.6875, same in both.
    assert!(out.contains("mean R          0.6875    0.6875"), "{out}");
}

#[test]
fn different_images_exit_1_beyond_the_tolerance_and_0_within() {
    let dir = images();
    let o = glint(&["diff", "a.pfm", "b.pfm"], dir.path());
    assert_exit(&o, 1);
    assert!(
        stdout(&o).contains("beyond tolerance: relMSE 0.0"),
        "{}",
        stdout(&o)
    );
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    // A verdict, not an error; its number printed as the table prints it.
    assert!(
        err.starts_with("glint: a.pfm differs from b.pfm beyond the tolerance: relMSE 0.0"),
        "{err}"
    );
    assert!(
        err.ends_with("> 1.00000e-8 (the default: a match to float precision)\n"),
        "{err}"
    );

    for (args, code) in [
        (&["--tolerance", "1"][..], 0),
        (&["--metric", "max", "--tolerance", "0.4"][..], 1),
        (&["--metric", "max", "--tolerance", "0.5"][..], 0),
        (&["--metric", "rmse", "--tolerance", "0.1"][..], 1),
        (&["--metric", "rmse", "--tolerance", "0.11"][..], 0),
        (&["--metric", "flip", "--tolerance", "1"][..], 0),
        (&["--metric", "flip", "--tolerance", "0.0001"][..], 1),
        // The region leaves out the changed pixel.
        (&["--region", "0,0,3,2"][..], 0),
        (
            &[
                "--region",
                "3,1,4,2",
                "--metric",
                "max",
                "--tolerance",
                "0.49",
            ][..],
            1,
        ),
    ] {
        let o = glint(&[&["diff", "a.pfm", "b.pfm"], args].concat(), dir.path());
        assert_exit(&o, code);
        let verdict = if code == 0 {
            "within tolerance"
        } else {
            "beyond tolerance"
        };
        assert!(
            stdout(&o).lines().last().unwrap().starts_with(verdict),
            "{args:?}: {}",
            stdout(&o)
        );
    }
    let o = glint(
        &["diff", "a.pfm", "b.pfm", "--region", "1,0,3,2"],
        dir.path(),
    );
    assert!(
        stdout(&o).contains("region          1,0,3,2 (4 pixels)"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn png_and_exr_inputs_compare_like_their_pixels() {
    let dir = images();
    write(dir.path(), "a.exr", &changed());
    write(dir.path(), "b.png", &base());
    write(dir.path(), "c.png", &base());
    assert_exit(&glint(&["diff", "b.png", "c.png"], dir.path()), 0);
    // Float against 8-bit: quantisation differs, FLIP of the sRGB encodings too.
    let o = glint(
        &[
            "diff",
            "a.exr",
            "b.png",
            "--metric",
            "max",
            "--tolerance",
            "0.51",
        ],
        dir.path(),
    );
    assert_exit(&o, 0);
    assert!(
        stdout(&o).contains("at pixel (3, 1), channel G"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn non_finite_values_are_counted_and_never_within_tolerance() {
    let dir = images();
    let mut film = base();
    film.set_pixel(1, 0, Vec3::new(f32::NAN, 0.0, 0.0));
    write(dir.path(), "nan.pfm", &film);
    let o = glint(
        &["diff", "nan.pfm", "b.pfm", "--tolerance", "1000"],
        dir.path(),
    );
    assert_exit(&o, 1);
    let out = stdout(&o);
    assert!(out.contains("non-finite      1         0"), "{out}");
    assert!(out.contains("relMSE          NaN"), "{out}");
    assert!(
        out.contains("max difference  NaN at pixel (1, 0), channel R (A NaN, B"),
        "{out}"
    );
    assert!(out.contains("beyond tolerance: relMSE NaN > 1000"), "{out}");
    // The same file against itself is identical, NaN included.
    assert_exit(&glint(&["diff", "nan.pfm", "nan.pfm"], dir.path()), 0);
}

#[test]
fn different_sizes_are_bad_input() {
    let dir = images();
    write(dir.path(), "big.pfm", &Film::new(UVec2::new(5, 2)));
    let o = glint(&["diff", "a.pfm", "big.pfm"], dir.path());
    assert_input_error(
        &o,
        "big.pfm: the image is 5x2, but a.pfm is 4x2; glint diff compares images of the same size",
    );
}

#[test]
fn unreadable_and_bad_files_and_values_are_bad_input() {
    let dir = images();
    std::fs::write(dir.path().join("corrupt.png"), b"not a png").unwrap();
    std::fs::write(dir.path().join("short.pfm"), b"PF\n4 2\n-1.0\n\0\0\0\0").unwrap();
    std::fs::write(dir.path().join("image.bmp"), b"BM").unwrap();
    std::fs::write(dir.path().join("image.gif"), b"GIF89a\x01\x00").unwrap();
    for (args, expected) in [
        (
            &["diff", "missing.pfm", "b.pfm"][..],
            "missing.pfm: cannot read the image: ",
        ),
        (
            &["diff", "a.pfm", "missing.png"][..],
            "missing.png: cannot read the image: ",
        ),
        (
            &["diff", "corrupt.png", "b.pfm"][..],
            "corrupt.png: cannot read the image: ",
        ),
        (
            &["diff", "short.pfm", "b.pfm"][..],
            "short.pfm: cannot read the image: the file is truncated",
        ),
        (
            &["diff", "image.bmp", "b.pfm"][..],
            "image.bmp: cannot read the image: the file is truncated",
        ),
        (
            &["diff", "image.gif", "b.pfm"][..],
            "image.gif: cannot read the image: a GIF image; Glint reads PNG, JPEG, BMP, TGA, PPM/PGM, Radiance HDR, OpenEXR and PFM",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--region", "0,0,5,2"][..],
            "a.pfm: --region: the region 0,0,5,2 reaches outside the 4x2 image",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--region", "0,0,4"][..],
            "expected x0,y0,x1,y1",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--region", "2,0,1,1"][..],
            "x1 (1) must be greater than x0 (2)",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--tolerance=-1"][..],
            "expected a number, 0 or more",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--tolerance", "lots"][..],
            "expected a number, 0 or more",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--metric", "psnr"][..],
            "invalid value 'psnr' for '--metric <METRIC>'",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--heatmap-scale", "0"][..],
            "expected a number greater than 0",
        ),
        (&["diff", "a.pfm"][..], "required"),
    ] {
        assert_input_error(&glint(args, dir.path()), expected);
    }
}

#[test]
fn heat_maps_are_written_as_png_of_the_image_size() {
    let dir = images();
    for (extra, name) in [
        (&[][..], "flip.png"),
        (&["--heatmap-metric", "relmse"][..], "relmse.png"),
        (
            &["--heatmap-metric", "relmse", "--heatmap-scale", "0.5"][..],
            "scaled.png",
        ),
    ] {
        let o = glint(
            &[&["diff", "a.pfm", "b.pfm", "--heatmap", name], extra].concat(),
            dir.path(),
        );
        assert_exit(&o, 1); // the images differ; the heat map is written all the same
        let out = stdout(&o);
        assert!(out.contains(&format!("heat map        {name} (")), "{out}");
        let map = Film::load(&dir.path().join(name)).unwrap();
        assert_eq!(map.resolution(), UVec2::new(4, 2));
        // The changed pixel is the brightest; with relMSE, unchanged pixels are
        // magma's black (FLIP's filters spread the error to its neighbours).
        let srgb = map.to_srgb8();
        let brightness = |i: usize| {
            srgb[3 * i..3 * i + 3]
                .iter()
                .map(|&c| c as u32)
                .sum::<u32>()
        };
        assert!(
            (0..7).all(|i| brightness(i) < brightness(7)),
            "{name}: {srgb:?}"
        );
        if name != "flip.png" {
            assert!(srgb[..21].iter().all(|&c| c < 10), "{name}: {srgb:?}");
        }
    }
    let o = glint(
        &[
            "diff",
            "a.pfm",
            "b.pfm",
            "--heatmap",
            "relmse.png",
            "--heatmap-metric",
            "relmse",
        ],
        dir.path(),
    );
    assert!(
        stdout(&o).contains("(relMSE per pixel, scale "),
        "{}",
        stdout(&o)
    );
    let o = glint(
        &["diff", "a.pfm", "b.pfm", "--heatmap", "flip.png"],
        dir.path(),
    );
    assert!(
        stdout(&o).contains("heat map        flip.png (FLIP, scale 1)"),
        "{}",
        stdout(&o)
    );
    // Only the requested files, no temporary ones.
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "a.pfm",
            "b.pfm",
            "flip.png",
            "relmse.png",
            "same.pfm",
            "scaled.png"
        ]
    );
}

#[test]
fn a_bad_heat_map_path_fails_before_any_work_and_a_failed_run_keeps_the_old_map() {
    let dir = images();
    std::fs::create_dir(dir.path().join("folder.png")).unwrap();
    for (path, expected) in [
        (
            "no-such-dir/map.png",
            "no-such-dir/map.png: the output directory no-such-dir does not exist",
        ),
        ("folder.png", "folder.png: is a directory"),
        (
            "map.jpg",
            "map.jpg: a heat map is written as PNG; expected a .png extension",
        ),
        ("b.pfm", "b.pfm: a heat map is written as PNG"),
    ] {
        // Even with an unreadable input, the heat map path is checked first.
        let o = glint(
            &["diff", "missing.pfm", "b.pfm", "--heatmap", path],
            dir.path(),
        );
        assert_input_error(&o, expected);
    }
    write(dir.path(), "a.png", &changed());
    let o = glint(
        &["diff", "b.pfm", "a.png", "--heatmap", "a.png"],
        dir.path(),
    );
    assert_input_error(&o, "a.png: is one of the images being compared");

    std::fs::write(dir.path().join("old.png"), b"precious").unwrap();
    write(dir.path(), "big.pfm", &Film::new(UVec2::new(5, 2)));
    let o = glint(
        &["diff", "a.pfm", "big.pfm", "--heatmap", "old.png"],
        dir.path(),
    );
    assert_exit(&o, 2);
    assert_eq!(
        std::fs::read(dir.path().join("old.png")).unwrap(),
        b"precious"
    );
    assert!(!dir.path().join("no-such-dir").exists());
    assert!(!dir.path().join("map.jpg").exists());
}

#[test]
fn json_gives_the_table_s_numbers_and_a_ppm_reads_like_its_png() {
    let dir = images();
    let o = glint(
        &["diff", "a.pfm", "b.pfm", "--json", "--tolerance", "1"],
        dir.path(),
    );
    assert_exit(&o, 0);
    let doc: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(doc["schema"], "glint-diff/1");
    assert_eq!(doc["size"], serde_json::json!([4, 2]));
    assert_eq!(doc["max_difference"]["pixel"], serde_json::json!([3, 1]));
    assert_eq!(doc["max_difference"]["channel"], "G");
    assert_eq!(doc["within_tolerance"], true);
    assert!(doc["rel_mse"].as_f64().unwrap() > 0.0);
    let o = glint(&["diff", "a.pfm", "b.pfm", "--json"], dir.path());
    assert_exit(&o, 1);
    let doc: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(doc["within_tolerance"], false);
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));

    // A P3 PPM of the PNG's codes is the same image.
    write(dir.path(), "a.png", &changed());
    let png = image::open(dir.path().join("a.png")).unwrap().to_rgb8();
    let mut ppm = String::from("P3\n4 2\n255\n");
    for p in png.pixels() {
        ppm += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    std::fs::write(dir.path().join("a.ppm"), ppm).unwrap();
    let o = glint(&["diff", "a.ppm", "a.png"], dir.path());
    assert_exit(&o, 0);
    assert!(stdout(&o).contains("0 (identical)"), "{}", stdout(&o));
}

#[test]
fn help_documents_every_flag() {
    let dir = tempfile::tempdir().unwrap();
    let o = glint(&["diff", "--help"], dir.path());
    assert_exit(&o, 0);
    let help = stdout(&o);
    for flag in [
        "<TEST>",
        "<REFERENCE>",
        "--metric <METRIC>",
        "relmse",
        "rmse",
        "flip",
        "max",
        "--tolerance <T>",
        "--region <x0,y0,x1,y1>",
        "--heatmap <FILE.png>",
        "--heatmap-metric <METRIC>",
        "--heatmap-scale <S>",
        "Exit status: 0 within the tolerance, 1 beyond it",
        "docs/comparing-images.md",
    ] {
        assert!(help.contains(flag), "{flag:?} missing from\n{help}");
    }
    let top = stdout(&glint(&["--help"], dir.path()));
    assert!(
        top.contains("diff") && top.contains("Compare two images"),
        "{top}"
    );
}
