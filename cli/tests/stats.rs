//! `glint render --stats` and `--stats-json`: what the render did, printed and
//! written as JSON, with the image unchanged.

mod common;

use common::{glint, scene, stderr, stdout, SMALL};

#[test]
fn stats_print_every_section_write_json_and_change_no_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let plain = glint(
        &[&["render", &set1, "-o", "a.png"], &SMALL[..]].concat(),
        dir.path(),
    );
    assert!(plain.status.success(), "{}", stderr(&plain));
    assert!(!stdout(&plain).contains("render statistics"));
    let args = [
        "render",
        &set1,
        "-o",
        "b.png",
        "--stats",
        "--stats-json",
        "stats.json",
    ];
    let counted = glint(&[&args[..], &SMALL[..]].concat(), dir.path());
    assert!(counted.status.success(), "{}", stderr(&counted));
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert_eq!(read("a.png"), read("b.png"), "the image does not change");
    let text = stdout(&counted);
    for section in [
        "rays",
        "light samples",
        "shading",
        "tests",
        "BVH",
        "textures",
        "time",
        "peak memory",
    ] {
        assert!(
            text.contains(&format!("\n  {section}")),
            "{section} in\n{text}"
        );
    }
    let json: serde_json::Value = serde_json::from_slice(&read("stats.json")).unwrap();
    // 24 × 24 pixels × 4 samples; the course's box has no environment, mirror or BVH.
    assert_eq!(json["rays"]["camera"], 2304);
    assert_eq!(json["rays"]["shadow_to_environment"], 0);
    assert_eq!(json["rays"]["reflection"], 0);
    assert_eq!(json["bvh"]["built"], false);
    assert_eq!(json["bvh"]["nodes_visited"], 0);
    assert!(json["intersection_tests"]["sphere"].as_u64().unwrap() > 0);
    assert!(json["rays"]["shadow_to_lights"].as_u64().unwrap() > 0);
    assert!(json["seconds"]["render"].as_f64().unwrap() > 0.0);
    assert!(
        json["texture_lookups_by_level"]["checkerboard"][0]
            .as_u64()
            .unwrap()
            > 0
    );
}

#[test]
fn a_stats_file_in_a_missing_directory_fails_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "render",
        &scene("cornell-set1"),
        "-o",
        "a.png",
        "--stats-json",
        "no/such/dir/s.json",
    ];
    let o = glint(&[&args[..], &SMALL[..]].concat(), dir.path());
    common::assert_input_error(
        &o,
        "no/such/dir/s.json: the output directory no/such/dir does not exist",
    );
    assert!(!dir.path().join("a.png").exists());
}
