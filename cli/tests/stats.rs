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
        "environment",
        "lobe samples",
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
    let lights = &json["light_samples"];
    let skipped = &lights["skipped"];
    assert_eq!(
        lights["area"].as_u64().unwrap() + lights["point"].as_u64().unwrap(),
        ["below_surface", "behind_light", "zero_brdf", "zero_density"]
            .iter()
            .map(|k| skipped[k].as_u64().unwrap())
            .sum::<u64>()
            + lights["shadow_rays"].as_u64().unwrap()
    );
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

/// The whole numbers of the `--stats` line that starts with `label`.
fn numbers_of_line(text: &str, label: &str) -> Vec<u64> {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with(label))
        .unwrap_or_else(|| panic!("no {label} line in\n{text}"));
    line.split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect()
}

#[test]
fn every_sample_is_a_ray_or_a_skip_and_the_lines_add_up() {
    // Area lights (cornell-set1), the environment with no light at all
    // (environment), and physical shading's lobe samples (physical-glossy).
    let dir = tempfile::tempdir().unwrap();
    for name in ["cornell-set1", "environment", "physical-glossy"] {
        let args = ["render", &scene(name), "-o", "a.png", "--stats"];
        let small = ["--environment-samples", "4"];
        let o = glint(&[&args[..], &SMALL[..], &small[..]].concat(), dir.path());
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let text = stdout(&o);
        // total (area, point): rays, then the skips.
        let lights = numbers_of_line(&text, "light samples");
        assert_eq!(lights[0], lights[1] + lights[2], "{name}: {lights:?}");
        assert_eq!(
            lights[0],
            lights[3..].iter().sum::<u64>(),
            "{name}: {lights:?}"
        );
        // samples: rays, then the skips.
        for label in ["environment", "lobe samples"] {
            let n = numbers_of_line(&text, label);
            assert_eq!(n[0], n[1..].iter().sum::<u64>(), "{name}, {label}: {n:?}");
        }
        let environment = numbers_of_line(&text, "environment");
        match name {
            "environment" => assert!(environment[0] > 0 && environment[2] > 0, "{text}"),
            _ => assert_eq!(environment[0], 0, "{name}"),
        }
        let lobes = numbers_of_line(&text, "lobe samples")[0];
        assert_eq!(lobes > 0, name == "physical-glossy", "{name}: {lobes}");
    }
}
