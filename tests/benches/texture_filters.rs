//! Texture filtering, measured: run time against error.
//!
//! Renders `scenes/ground-mipmap.toml` at 1 sample per pixel (pixel centres) with
//! each image filter, and once more with the ground's checkerboard as the
//! analytically box-filtered procedural texture; compares each with a ground truth
//! rendered at 1024 stratified samples per pixel with bilinear lookups at full
//! resolution; prints relative MSE and the median render time of each as a table.
//!
//! `cargo bench -p glint-tests --bench texture_filters`
//!
//! Relative MSE is pbrt's imgtool definition: the mean over pixels and channels of
//! `(x − ref)² / (ref² + 0.01)`.

use glint_camera::Film;
use glint_integrator::{render, RenderSettings, SamplePattern};
use glint_scene::{parse_in, SceneDescription};
use glint_texture::TextureFilter;
use std::time::Duration;

const GROUND_TRUTH_SPP: u32 = 1024;
const TIMING_RUNS: usize = 5;

fn main() {
    let path = glint_tests::scene_path("ground-mipmap");
    let source = std::fs::read_to_string(&path).expect("scene readable");
    let base = path.parent().expect("scene directory");
    let load = |text: &str| parse_in(text, &path.display().to_string(), base).expect("scene valid");

    let truth = {
        let mut d = load(&source);
        d.scene.override_texture_filter(TextureFilter::Bilinear);
        let settings = RenderSettings {
            spp: GROUND_TRUTH_SPP,
            pixel_pattern: SamplePattern::Stratified,
            ..d.settings.clone()
        };
        eprintln!("rendering the ground truth ({GROUND_TRUTH_SPP} spp, bilinear)…");
        render(&d.scene, &settings, &|_, _| {})
            .expect("renders")
            .film
    };

    let mut rows = Vec::new();
    for filter in [
        TextureFilter::Nearest,
        TextureFilter::Bilinear,
        TextureFilter::Trilinear,
        TextureFilter::Ewa,
    ] {
        let mut d = load(&source);
        d.scene.override_texture_filter(filter);
        rows.push((format!("{filter:?}").to_lowercase(), measure(&d, &truth)));
    }
    // The ground as the procedural checker, box-filtered exactly; photos with EWA.
    let analytic_source = with_analytic_ground(&source);
    let mut d = load(&analytic_source);
    d.scene.override_texture_filter(TextureFilter::Ewa);
    rows.push(("analytic checker (photos: ewa)".into(), measure(&d, &truth)));

    let resolution = truth.resolution();
    println!(
        "\nground-mipmap, {}x{}, 1 spp at pixel centres; ground truth {GROUND_TRUTH_SPP} spp bilinear; median of {TIMING_RUNS} runs\n",
        resolution.x, resolution.y
    );
    println!("| filter | relative MSE | render time | first render |");
    println!("|---|---|---|---|");
    for (name, (rel_mse, time, first)) in rows {
        println!(
            "| {name} | {rel_mse:.5} | {:.1} ms | {:.1} ms |",
            time.as_secs_f64() * 1e3,
            first.as_secs_f64() * 1e3
        );
    }
}

/// Relative MSE against `truth`, the median render time, and the time of the
/// first render (which also builds the MIP pyramids the filter reads), at 1 spp.
fn measure(d: &SceneDescription, truth: &Film) -> (f64, Duration, Duration) {
    let settings = RenderSettings {
        spp: 1,
        pixel_pattern: SamplePattern::Grid,
        ..d.settings.clone()
    };
    let mut times = Vec::new();
    let mut film = None;
    for _ in 0..TIMING_RUNS {
        let out = render(&d.scene, &settings, &|_, _| {}).expect("renders");
        times.push(out.stats.elapsed);
        film = Some(out.film);
    }
    let first = times[0];
    times.sort();
    (
        relative_mse(&film.expect("rendered"), truth),
        times[TIMING_RUNS / 2],
        first,
    )
}

fn relative_mse(image: &Film, truth: &Film) -> f64 {
    let sum: f64 = image
        .pixels()
        .iter()
        .zip(truth.pixels())
        .flat_map(|(x, r)| (0..3).map(move |c| (x[c] as f64, r[c] as f64)))
        .map(|(x, r)| (x - r).powi(2) / (r * r + 0.01))
        .sum();
    sum / (3 * image.pixels().len()) as f64
}

/// The scene text with the ground's checkerboard image replaced by the procedural
/// checkerboard (same colors and checks) filtered analytically.
fn with_analytic_ground(source: &str) -> String {
    let image_table = "[textures.ground-checks.checker_image]";
    let start = source
        .find(image_table)
        .expect("ground-mipmap has its checker image");
    let end = start
        + source[start..]
            .find("\n\n")
            .expect("table ends with a blank line");
    let table = &source[start..end];
    let keep: Vec<&str> = table
        .lines()
        .skip(1)
        .filter(|l| l.starts_with("colors") || l.starts_with("checks"))
        .collect();
    assert_eq!(keep.len(), 2, "ground checker table changed: {table}");
    let replacement = format!(
        "[textures.ground-checks.checkerboard]\n{}\nfilter = \"analytic\"",
        keep.join("\n")
    );
    format!("{}{}{}", &source[..start], replacement, &source[end..])
}
