//! A whole bench on a tiny scene: the sweep, the reference and its cache, the
//! measurements, the fits and the files.

use glint_bench::budget::{sample_ladder, Ladder};
use glint_bench::reference::Origin;
use glint_bench::strategy::parse_samplers;
use glint_bench::{run, BenchConfig, BenchError, ReferenceChoice, RegionChoice};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A floor under a sphere and a square light: soft shadows, 24 × 24 pixels.
const SCENE: &str = r#"
ambient = [0.05, 0.05, 0.05]

[camera]
position = [0, 2, 6]
look_at = [0, 0.5, 0]
fov = 40

[render]
resolution = [24, 24]

[regions]
shadow = [4, 12, 20, 24]

[materials.white]
diffuse = [0.8, 0.8, 0.8]
specular = [0, 0, 0]

[[plane]]
point = [0, 0, 0]
normal = [0, 1, 0]
material = "white"

[[sphere]]
center = [0, 0.8, 0]
radius = 0.6
material = "white"

[[area_light]]
center = [0, 3, 0]
edge1 = [1.5, 0, 0]
edge2 = [0, 0, 1.5]
"#;

fn scene_in(dir: &Path) -> PathBuf {
    let path = dir.join("tiny.toml");
    std::fs::write(&path, SCENE).unwrap();
    path
}

fn config(scene: PathBuf, out: &Path) -> BenchConfig {
    BenchConfig {
        scene,
        strategies: parse_samplers("random,sobol").unwrap(),
        ladder: Ladder::Samples(sample_ladder(&[1, 4, 16], &[1], &[0]).unwrap()),
        repeat: 2,
        region: RegionChoice::Whole,
        reference: ReferenceChoice::Render {
            spp: None,
            texture_filter: None,
            pixel_centre: false,
        },
        heatmap_step: None,
        resolution: None,
        seed: None,
        threads: Some(2),
        max_depth: None,
        output_dir: out.to_owned(),
        version: "test".into(),
    }
}

#[test]
fn a_bench_measures_fits_writes_and_caches_its_reference() {
    let dir = tempfile::tempdir().unwrap();
    let config = config(scene_in(dir.path()), dir.path());
    let renders = std::sync::Mutex::new(Vec::new());
    let record = |p: glint_bench::Progress| {
        if let glint_bench::Progress::Render { what, .. } = p {
            renders.lock().unwrap().push(what.to_owned());
        }
    };
    let bench = run(&config, &record).unwrap();
    // Strategies take turns, budget by budget and run by run.
    let renders = renders.into_inner().unwrap();
    assert_eq!(
        renders[..4],
        [
            "random at 1 spp × 1 light samples (run 1 of 2)",
            "sobol at 1 spp × 1 light samples (run 1 of 2)",
            "random at 1 spp × 1 light samples (run 2 of 2)",
            "sobol at 1 spp × 1 light samples (run 2 of 2)",
        ]
    );
    assert!(renders[4].starts_with("random at 4 spp"), "{renders:?}");
    assert!(renders.iter().any(|r| r.starts_with("reference round 1")));
    let r = &bench.report;
    assert_eq!(r.rows.len(), 6);
    assert!(r
        .rows
        .iter()
        .all(|row| row.runs == 2 && row.time_median_s > 0.0));
    assert!(r
        .rows
        .iter()
        .all(|row| row.rel_mse > 0.0 && row.flip >= 0.0));
    // Errors fall with samples, for both strategies.
    for name in ["random", "sobol"] {
        let errors: Vec<f64> = r
            .rows
            .iter()
            .filter(|row| row.strategy == name)
            .map(|row| row.rel_mse)
            .collect();
        assert!(errors[2] < errors[0], "{name}: {errors:?}");
    }
    assert!(r.strategies.iter().all(|s| s.rel_mse_slope.is_some()));
    let base = r.baseline.as_ref().unwrap();
    assert_eq!(base.strategy, "random");
    assert_eq!(base.target_total_samples, 16);
    let random = &r.strategies[0];
    assert!((random.equal_error_speedup.unwrap() - 1.0).abs() < 1e-9);
    // The reference: rendered, its noise estimated and below the goal (or capped).
    assert!(matches!(
        r.reference.origin,
        Origin::Rendered { cached: false, .. }
    ));
    assert!(r.reference.rounds >= 2);
    assert_eq!(r.reference.spp_per_round, 64);
    let noise = r.reference.noise_rel_mse.unwrap();
    assert!(
        r.reference.noise_goal_met == Some(true) || r.reference.rounds == 64,
        "{:?}",
        r.reference
    );
    assert!(noise > 0.0);
    // Files.
    let written = bench.write(dir.path()).unwrap();
    for name in [
        "results.csv",
        "results.json",
        "relmse-vs-time.png",
        "relmse-vs-time.svg",
        "heatmap-random.png",
        "heatmap-sobol.png",
    ] {
        assert!(dir.path().join(name).is_file(), "{name}");
    }
    assert_eq!(written.len(), 6);
    let csv = std::fs::read_to_string(dir.path().join("results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 7);
    assert!(csv.starts_with("strategy,spp,"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("results.json")).unwrap())
            .unwrap();
    assert_eq!(json["rows"].as_array().unwrap().len(), 6);
    let svg = std::fs::read_to_string(dir.path().join("relmse-vs-time.svg")).unwrap();
    assert!(svg.contains("tiny: relative MSE against render time"));
    assert!(r.table().contains("equal-error speed-up"));

    // A second bench of the same inputs reads the cached reference.
    let again = run(&config, &|_| {}).unwrap();
    assert!(matches!(
        again.report.reference.origin,
        Origin::Rendered { cached: true, .. }
    ));
    assert_eq!(again.report.reference.render_seconds, 0.0);
    assert_eq!(again.report.reference.rounds, r.reference.rounds);
    assert_eq!(again.report.rows[5].rel_mse, r.rows[5].rel_mse);

    // Any change to the scene file makes a new reference.
    std::fs::write(
        &config.scene,
        SCENE.replace("0.8, 0.8, 0.8", "0.7, 0.7, 0.7"),
    )
    .unwrap();
    let changed = run(&config, &|_| {}).unwrap();
    assert!(matches!(
        changed.report.reference.origin,
        Origin::Rendered { cached: false, .. }
    ));
}

#[test]
fn named_regions_scale_with_the_resolution_and_unknown_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut config = config(scene_in(dir.path()), dir.path());
    config.strategies = parse_samplers("stratified").unwrap();
    config.region = RegionChoice::Named("shadow".into());
    config.resolution = Some(glam::UVec2::new(48, 48));
    config.repeat = 1;
    let bench = run(&config, &|_| {}).unwrap();
    assert_eq!(bench.report.region.pixels, [8, 24, 40, 48]);
    assert_eq!(bench.report.region.name.as_deref(), Some("shadow"));
    config.region = RegionChoice::Named("nowhere".into());
    match run(&config, &|_| {}) {
        Err(BenchError::Input(m)) => {
            assert!(m.contains("\"nowhere\"") && m.contains("shadow"), "{m}")
        }
        other => panic!("{:?}", other.err()),
    }
}

#[test]
fn bad_budgets_and_references_are_input_errors_before_any_render() {
    let dir = tempfile::tempdir().unwrap();
    let mut config = config(scene_in(dir.path()), dir.path());
    config.strategies = parse_samplers("grid").unwrap();
    config.ladder = Ladder::Samples(sample_ladder(&[1, 2], &[1], &[0]).unwrap());
    let rendered = std::sync::atomic::AtomicUsize::new(0);
    let count = |_: glint_bench::Progress| {
        rendered.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    };
    match run(&config, &count) {
        Err(BenchError::Input(m)) => assert!(m.contains("perfect squares"), "{m}"),
        other => panic!("{:?}", other.err()),
    }
    config.strategies = parse_samplers("random").unwrap();
    config.ladder = Ladder::Samples(sample_ladder(&[1, 4], &[1], &[0]).unwrap());
    // A reference of another size.
    let small = dir.path().join("small.pfm");
    glint_camera::Film::new(glam::UVec2::new(8, 8))
        .save(&small)
        .unwrap();
    config.reference = ReferenceChoice::File(small);
    match run(&config, &count) {
        Err(BenchError::Input(m)) => assert!(m.contains("8x8") && m.contains("24x24"), "{m}"),
        other => panic!("{:?}", other.err()),
    }
    assert_eq!(
        rendered.into_inner(),
        0,
        "nothing rendered before the checks"
    );
}

#[test]
fn a_reference_file_is_used_as_given_and_time_budgets_pick_sample_counts() {
    let dir = tempfile::tempdir().unwrap();
    let mut config = config(scene_in(dir.path()), dir.path());
    config.strategies = parse_samplers("sobol").unwrap();
    config.repeat = 1;
    let first = run(&config, &|_| {}).unwrap();
    // Keep the rendered reference as a file, and bench against it.
    let file = dir.path().join("given.pfm");
    let pfm = dir.path().join(format!(
        "reference-{}.pfm",
        match &first.report.reference.origin {
            Origin::Rendered { key, .. } => key.clone(),
            other => panic!("{other:?}"),
        }
    ));
    std::fs::copy(pfm, &file).unwrap();
    config.reference = ReferenceChoice::File(file.clone());
    config.ladder = Ladder::Time {
        budgets: vec![Duration::from_millis(5), Duration::from_millis(40)],
        light_samples: 1,
        environment_samples: 0,
    };
    let timed = run(&config, &|_| {}).unwrap();
    assert!(matches!(&timed.report.reference.origin, Origin::File { path } if *path == file));
    assert_eq!(timed.report.reference.noise_rel_mse, None);
    let spp: Vec<u32> = timed.report.rows.iter().map(|r| r.spp).collect();
    assert!(
        !spp.is_empty() && spp.windows(2).all(|w| w[0] < w[1]),
        "{spp:?}"
    );
    assert!(spp.iter().all(|&s| s >= 1));
}
