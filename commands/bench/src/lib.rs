//! `glint bench`: run time against error. Renders a scene with each strategy
//! (sample patterns, texture filters) over a ladder of sample or time budgets,
//! measures each image against a reference, and reports time, rays, RMSE,
//! relative MSE, FLIP and efficiency, the convergence slope of each strategy and
//! its equal-error speed-up over `random`, with a plot and error heat maps.
//!
//! # Conventions
//! - Images are linear RGB; errors are measured over a region (the whole image by
//!   default) with the definitions of `glint-metrics`: relative MSE is pbrt-v4's
//!   imgtool MRSE, `mean((x − r)²/(r + 0.01)²)`, FLIP is LDR-FLIP on the 8-bit sRGB images.
//! - Time is the renderer's own wall-clock time for the render (scene loading and
//!   image writing excluded), the median of `repeat` runs; efficiency is
//!   `1 / (relMSE · seconds)`.
//! - "Samples" are light-sample paths per pixel, `spp · light_samples`: the
//!   x-axis of the fitted slopes.
//! - The reference is rendered (and cached) unless given; see [`reference`](mod@reference).
//!
//! # Entry points
//! [`run`] does a bench described by a [`BenchConfig`] and returns a [`Bench`]:
//! its [`Report`] (table, CSV, JSON) and the heat maps; [`Bench::write`] writes
//! every file. Strategies and ladders are parsed by [`strategy`] and [`budget`].

pub mod budget;
pub mod fit;
pub mod machine;
mod merge;
mod output;
pub mod plot;
pub mod reference;
pub mod report;
pub mod strategy;
mod sweep;

pub use budget::{Ladder, SampleBudget};
pub use machine::Machine;
pub use merge::merge;
pub use reference::Reference;
pub use report::Report;
pub use strategy::{Strategy, TextureChoice};

use glam::{UVec2, Vec3};
use glint_integrator::{RenderOutput, RenderSettings, SamplePattern, Scene};
use glint_metrics::{ImageView, Region};
use glint_scene::SceneDescription;
use glint_texture::TextureFilter;
use reference::{CachePaths, Origin, RoundSums};
use report::{Baseline, HeatmapSummary, ReferenceSummary, RegionSummary, Row, StrategySummary};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use sweep::{Counter, Measurement};

/// Why a bench failed: bad input (exit status 2 on the command line) or
/// anything else (1).
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("{0}")]
    Input(String),
    #[error("{0}")]
    Other(String),
}

/// Measurements of images the bench itself made: sizes that do not fit are
/// its own fault, not the user's.
impl From<glint_metrics::MetricsError> for BenchError {
    fn from(e: glint_metrics::MetricsError) -> Self {
        BenchError::Other(e.to_string())
    }
}

/// The region errors are measured over.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RegionChoice {
    Whole,
    /// Pixels of the rendered image, `[x0, x1) × [y0, y1)`.
    Pixels(Region),
    /// A region the scene file names (`[regions]`), in pixels of the scene's own
    /// resolution, scaled to the bench's.
    Named(String),
}

/// Where the reference comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceChoice {
    /// An image file (EXR, PFM or PNG) of the bench's resolution.
    File(PathBuf),
    /// Rendered by the bench: `spp` samples per pixel in all (two rounds), or,
    /// without it, as many as the noise goal needs. `texture_filter` overrides
    /// every image texture's filter in the reference (the bench uses `bilinear`,
    /// the full-resolution image, when it compares texture filters).
    /// `pixel_centre`: the reference samples each pixel at its centre only, and
    /// its rounds' samples go to the lights and the environment; for benches
    /// whose strategies all do the same (one sample per pixel on the grid
    /// pattern), to measure light sampling alone.
    Render {
        spp: Option<u32>,
        texture_filter: Option<TextureFilter>,
        pixel_centre: bool,
    },
}

/// Everything a bench needs to know.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    pub scene: PathBuf,
    pub strategies: Vec<Strategy>,
    pub ladder: Ladder,
    pub repeat: usize,
    pub region: RegionChoice,
    pub reference: ReferenceChoice,
    /// The ladder step whose heat maps are drawn (default: the last).
    pub heatmap_step: Option<usize>,
    pub resolution: Option<UVec2>,
    pub seed: Option<u64>,
    pub threads: Option<usize>,
    pub max_depth: Option<u32>,
    /// Where the results go; the reference cache is kept there too.
    pub output_dir: PathBuf,
    /// Names this build of Glint in the reference cache's key.
    pub version: String,
}

/// Progress, reported as the bench goes.
#[derive(Clone, Copy, Debug)]
pub enum Progress<'a> {
    /// Render `number` of (about) `planned` is starting.
    Render {
        number: usize,
        planned: usize,
        what: &'a str,
    },
    /// Of the current render's tiles, `done` of `total` are finished.
    Tiles { done: usize, total: usize },
    /// A step other than rendering (measuring FLIP, say).
    Step(&'a str),
}

/// A finished bench: its report, the heat maps, and the plot.
pub struct Bench {
    pub report: Report,
    pub heatmaps: Vec<Heatmap>,
}

/// One strategy's error heat map: its file name and RGB pixels (the bench's
/// resolution, row-major from the top-left pixel).
pub struct Heatmap {
    pub file: String,
    pub pixels: Vec<[u8; 3]>,
}

/// How every render of the bench is set up: the scene re-read for each strategy
/// (so one-off work such as MIP pyramids is paid by each), with the bench's
/// resolution, seed, thread count and depth.
pub(crate) struct Setup<'a> {
    config: &'a BenchConfig,
    resolution: UVec2,
}

impl Setup<'_> {
    fn load(&self) -> Result<SceneDescription, BenchError> {
        let mut d =
            glint_scene::load(&self.config.scene).map_err(|e| BenchError::Input(e.to_string()))?;
        if d.scene.camera.resolution() != self.resolution {
            d.scene.camera = d
                .scene
                .camera
                .with_resolution(self.resolution)
                .map_err(|e| BenchError::Input(format!("--resolution: {e}")))?;
        }
        if let Some(seed) = self.config.seed {
            d.settings.seed = seed;
        }
        if self.config.threads.is_some() {
            d.settings.threads = self.config.threads;
        }
        if let Some(depth) = self.config.max_depth {
            d.settings.max_depth = depth;
        }
        d.settings.aov = None;
        Ok(d)
    }

    /// The scene and settings of one strategy (its own copy of the scene, so
    /// that one-off work such as MIP pyramids is paid by each strategy).
    fn prepare(&self, strategy: &Strategy) -> Result<(Scene, RenderSettings), BenchError> {
        let SceneDescription {
            mut scene,
            mut settings,
            ..
        } = self.load()?;
        strategy.apply(&mut scene, &mut settings);
        Ok((scene, settings))
    }

    fn render(
        &self,
        scene: &Scene,
        settings: &RenderSettings,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<RenderOutput, BenchError> {
        let on_tile = |done: usize, total: usize| progress(Progress::Tiles { done, total });
        glint_integrator::render(scene, settings, &on_tile)
            .map_err(|e| BenchError::Other(e.to_string()))
    }
}

/// Runs the bench: the sweep, then the reference (rendered, cached or read),
/// then the measurements, fits and heat maps.
pub fn run(
    config: &BenchConfig,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Bench, BenchError> {
    let first = glint_scene::load(&config.scene).map_err(|e| BenchError::Input(e.to_string()))?;
    let scene_resolution = first.scene.camera.resolution();
    let resolution = config
        .resolution
        .unwrap_or_else(|| default_resolution(scene_resolution));
    let setup = Setup { config, resolution };
    let region = resolve_region(&config.region, &first, scene_resolution, resolution)?;
    check_budgets(config, &first.settings)?;
    check_pixel_centre(config)?;
    if config.strategies.is_empty() {
        return Err(BenchError::Input("no strategy to measure".into()));
    }
    let file_reference = match &config.reference {
        ReferenceChoice::File(path) => Some(read_reference(path, resolution)?),
        ReferenceChoice::Render { .. } => None,
    };
    // Fail on an unreadable asset before rendering, not after.
    let inputs = input_files(config, &first)?;
    drop(first);

    let measurements = sweep::run(
        &setup,
        &config.strategies,
        &config.ladder,
        config.repeat,
        progress,
    )?;
    let reference = match file_reference {
        Some(r) => r,
        None => rendered_reference(&setup, config, &inputs, &measurements, region, progress)?,
    };
    progress(Progress::Step(
        "measuring errors (RMSE, relative MSE, FLIP)",
    ));
    let rows = rows(config, &measurements, &reference, region)?;
    let strategies = summaries(&names(config), &rows);
    let baseline = baseline(&names(config), &rows);
    let heatmap_step = config
        .heatmap_step
        .unwrap_or(usize::MAX)
        .min(steps(&measurements).saturating_sub(1));
    let (heatmaps, heatmap_summary) = heatmaps(config, &measurements, &reference, heatmap_step)?;
    let smallest = rows.iter().map(|r| r.rel_mse).fold(f64::INFINITY, f64::min);
    let noise = reference.noise_rel_mse(region);
    let report = Report {
        scene: config.scene.display().to_string(),
        scene_name: scene_name(&config.scene),
        glint_version: config.version.clone(),
        machine: Machine::this_one(),
        resolution: [resolution.x, resolution.y],
        region: RegionSummary {
            name: match &config.region {
                RegionChoice::Named(name) => Some(name.clone()),
                _ => None,
            },
            pixels: [region.x0, region.y0, region.x1, region.y1],
            whole_image: region == Region::full(resolution.x, resolution.y),
        },
        reference: ReferenceSummary {
            origin: reference.origin.clone(),
            rounds: reference.rounds,
            spp_per_round: reference.spp_per_round,
            total_spp: reference.total_spp(),
            pixel_centre: matches!(
                config.reference,
                ReferenceChoice::Render {
                    pixel_centre: true,
                    ..
                }
            ),
            noise_rel_mse: noise,
            smallest_rel_mse: smallest,
            noise_goal_met: noise.map(|n| n * reference::NOISE_MARGIN <= smallest),
            render_seconds: reference.render_time.as_secs_f64(),
        },
        repeat: config.repeat.max(1),
        rows,
        strategies,
        baseline,
        heatmaps: Some(heatmap_summary),
    };
    Ok(Bench { report, heatmaps })
}

impl Bench {
    /// Writes `results.csv`, `results.json`, `relmse-vs-time.png` and `.svg`,
    /// and the heat maps into `dir`, each file atomically.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, String> {
        let mut written = Vec::new();
        let mut put = |name: &str, bytes: &[u8]| -> Result<(), String> {
            let path = dir.join(name);
            output::write_atomically(&path, bytes)?;
            written.push(path);
            Ok(())
        };
        put("results.csv", self.report.csv().as_bytes())?;
        let json = serde_json::to_string_pretty(&self.report).map_err(|e| e.to_string())?;
        put("results.json", json.as_bytes())?;
        put("relmse-vs-time.svg", plot::svg(&self.report)?.as_bytes())?;
        let (w, h, pixels) = plot::rgb(&self.report)?;
        let png = dir.join("relmse-vs-time.png");
        glint_metrics::save_heatmap(&png, w, h, &pixels)?;
        written.push(png);
        let [width, height] = self.report.resolution;
        for heatmap in &self.heatmaps {
            let path = dir.join(&heatmap.file);
            glint_metrics::save_heatmap(&path, width, height, &heatmap.pixels)?;
            written.push(path);
        }
        Ok(written)
    }
}

/// The most pixels a bench renders unless told otherwise: 256 × 256.
pub const DEFAULT_MAX_PIXELS: u64 = 256 * 256;

/// The resolution a bench renders at without `--resolution`: the scene's, or,
/// if it has more than [`DEFAULT_MAX_PIXELS`], the scene's scaled down (aspect
/// ratio kept) to about that many. Errors per pixel hardly depend on the pixel
/// count, while the bench's time grows with it: a 512 × 512 scene is benched at
/// 256 × 256 in about a quarter of the time.
pub fn default_resolution(scene: UVec2) -> UVec2 {
    let pixels = scene.x as u64 * scene.y as u64;
    if pixels <= DEFAULT_MAX_PIXELS {
        return scene;
    }
    let scale = (DEFAULT_MAX_PIXELS as f64 / pixels as f64).sqrt();
    let side = |s: u32| ((s as f64 * scale).round() as u32).max(1);
    UVec2::new(side(scene.x), side(scene.y))
}

/// The scene file's name without its extension.
pub fn scene_name(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
}

fn resolve_region(
    choice: &RegionChoice,
    description: &SceneDescription,
    scene_resolution: UVec2,
    resolution: UVec2,
) -> Result<Region, BenchError> {
    let region = match choice {
        RegionChoice::Whole => return Ok(Region::full(resolution.x, resolution.y)),
        RegionChoice::Pixels(r) => *r,
        RegionChoice::Named(name) => {
            let [x0, y0, x1, y1] = description
                .regions
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, r)| *r)
                .ok_or_else(|| {
                    let known: Vec<&str> = description
                        .regions
                        .iter()
                        .map(|(n, _)| n.as_str())
                        .collect();
                    BenchError::Input(format!(
                        "--region: the scene names no region \"{name}\" (it names: {})",
                        if known.is_empty() {
                            "none".into()
                        } else {
                            known.join(", ")
                        }
                    ))
                })?;
            Region { x0, y0, x1, y1 }.scaled(
                (scene_resolution.x, scene_resolution.y),
                (resolution.x, resolution.y),
            )
        }
    };
    region
        .check(resolution.x, resolution.y)
        .map_err(|e| BenchError::Input(format!("--region: {e}")))?;
    Ok(region)
}

/// Every budget must suit every strategy (the grid pattern needs squares, counts
/// have limits), checked before any render; and the environment must be sampled
/// at every step or at none (else the steps would compute different images).
fn check_budgets(config: &BenchConfig, scene_settings: &RenderSettings) -> Result<(), BenchError> {
    let budgets: Vec<SampleBudget> = match &config.ladder {
        Ladder::Samples(b) => b.clone(),
        Ladder::Time {
            light_samples,
            environment_samples,
            ..
        } => vec![SampleBudget {
            spp: 1,
            light_samples: *light_samples,
            environment_samples: *environment_samples,
        }],
    };
    if budgets.is_empty() {
        return Err(BenchError::Input("the ladder has no budget".into()));
    }
    let sampled = budgets.iter().filter(|b| b.environment_samples > 0).count();
    if sampled != 0 && sampled != budgets.len() {
        return Err(BenchError::Input(
            "--environment-samples: give 0 at every step or at none (the environment either lights surfaces or not)".into(),
        ));
    }
    for s in &config.strategies {
        for b in &budgets {
            if !s.supports(b.spp, b.light_samples, b.environment_samples) {
                return Err(BenchError::Input(format!(
                    "{}: the grid pattern needs perfect squares (1, 4, 9, 16, …), got {} spp, {} light samples, {} environment samples",
                    s.name(),
                    b.spp,
                    b.light_samples,
                    b.environment_samples
                )));
            }
            let settings = RenderSettings {
                spp: b.spp,
                light_samples: b.light_samples,
                environment_samples: b.environment_samples,
                pixel_pattern: s.pixel,
                light_pattern: s.light,
                environment_pattern: s.environment,
                threads: config.threads.or(scene_settings.threads),
                max_depth: config.max_depth.unwrap_or(scene_settings.max_depth),
                ..scene_settings.clone()
            };
            settings
                .validate()
                .map_err(|e| BenchError::Input(format!("{}: {e}", s.name())))?;
        }
    }
    Ok(())
}

fn read_reference(path: &Path, resolution: UVec2) -> Result<Reference, BenchError> {
    let film = glint_camera::Film::load(path).map_err(|e| BenchError::Input(e.to_string()))?;
    if film.resolution() != resolution {
        return Err(BenchError::Input(format!(
            "{}: the reference is {}x{}, the bench renders {}x{} (give --resolution {}x{})",
            path.display(),
            film.resolution().x,
            film.resolution().y,
            resolution.x,
            resolution.y,
            film.resolution().x,
            film.resolution().y
        )));
    }
    Ok(Reference::from_film(film, path))
}

/// The files a rendered reference depends on: the scene and its assets.
fn input_files(
    config: &BenchConfig,
    description: &SceneDescription,
) -> Result<Vec<PathBuf>, BenchError> {
    let mut files = vec![config.scene.clone()];
    files.extend(description.assets.iter().cloned());
    for f in &files {
        std::fs::metadata(f).map_err(|e| BenchError::Input(format!("{}: {e}", f.display())))?;
    }
    Ok(files)
}

/// The settings of one reference round: Owen-scrambled Sobol samples, `samples`
/// camera samples with one light and one environment sample each, or, at pixel
/// centres, one camera sample with `samples` light and environment samples.
fn reference_round_settings(
    base: &RenderSettings,
    samples: u32,
    sampled_environment: bool,
    pixel_centre: bool,
) -> RenderSettings {
    let (spp, per_sample) = if pixel_centre {
        (1, samples)
    } else {
        (samples, 1)
    };
    RenderSettings {
        spp,
        pixel_pattern: if pixel_centre {
            SamplePattern::Grid
        } else {
            SamplePattern::Sobol
        },
        light_samples: per_sample,
        light_pattern: SamplePattern::Sobol,
        environment_samples: if sampled_environment { per_sample } else { 0 },
        environment_pattern: SamplePattern::Sobol,
        aov: None,
        ..base.clone()
    }
}

/// A pixel-centre reference suits only strategies that sample pixels at their
/// centres too: the grid pattern at one sample per pixel.
fn check_pixel_centre(config: &BenchConfig) -> Result<(), BenchError> {
    let ReferenceChoice::Render {
        pixel_centre: true, ..
    } = config.reference
    else {
        return Ok(());
    };
    let one_spp = matches!(&config.ladder, Ladder::Samples(b) if b.iter().all(|b| b.spp == 1));
    let grid = config
        .strategies
        .iter()
        .all(|s| s.pixel == SamplePattern::Grid);
    if one_spp && grid {
        Ok(())
    } else {
        Err(BenchError::Input(
            "--reference-pixel centre: every strategy must sample pixels at their centres too (the grid pixel pattern, e.g. --samplers grid/sobol, with --spp 1 and the budget in --light-samples)".into(),
        ))
    }
}

/// Camera samples per reference round when the user gives no count: four times
/// the sweep's largest budget (as light-sample paths), as a power of two between
/// 64 and 16 384. Two rounds then leave noise 8–16× below an estimator
/// converging as `N⁻¹·⁵`–`N⁻¹` at the largest budget; more rounds are added if
/// the measured errors need it.
fn default_round_spp(measurements: &[Measurement]) -> u32 {
    let largest = measurements
        .iter()
        .map(|m| m.budget.total_samples())
        .max()
        .unwrap_or(1);
    (4 * largest).clamp(64, 16_384).next_power_of_two() as u32
}

fn rendered_reference(
    setup: &Setup,
    config: &BenchConfig,
    inputs: &[PathBuf],
    measurements: &[Measurement],
    region: Region,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Reference, BenchError> {
    let ReferenceChoice::Render {
        spp,
        texture_filter,
        pixel_centre,
    } = config.reference
    else {
        unreachable!("a file reference is read, not rendered");
    };
    let round_spp = match spp {
        Some(total) => total.div_ceil(reference::FIRST_ROUNDS).max(1),
        None => default_round_spp(measurements),
    };
    let d = setup.load()?;
    let sampled_environment = measurements
        .iter()
        .any(|m| m.budget.environment_samples > 0);
    let mut settings =
        reference_round_settings(&d.settings, round_spp, sampled_environment, pixel_centre);
    let mut scene = d.scene;
    if let Some(filter) = texture_filter {
        scene.override_texture_filter(filter);
    }
    settings
        .validate()
        .map_err(|e| BenchError::Input(format!("reference: {e}")))?;
    let (width, height) = (setup.resolution.x, setup.resolution.y);
    let fingerprint = format!(
        "{} texture_filter={}",
        reference::settings_fingerprint(&settings, width, height),
        texture_filter.map_or("scene", TextureFilter::name)
    );
    let key = reference::cache_key(&config.version, &fingerprint, inputs)
        .map_err(|e| BenchError::Input(format!("reading the scene's files: {e}")))?;
    let cache = CachePaths::new(&config.output_dir, &key);
    let cached = cache.load(&key, width, height);
    let mut sums = cached
        .as_ref()
        .and_then(RoundSums::from_reference)
        .unwrap_or_else(|| RoundSums::new(width, height, round_spp));
    let mut wanted = reference::FIRST_ROUNDS;
    let mut rendered = Duration::ZERO;
    let mut counter = Counter::new(wanted as usize);
    let origin = |cached: bool| Origin::Rendered {
        cached,
        key: key.clone(),
    };
    loop {
        while sums.rounds < wanted {
            settings.seed = reference::round_seed(d.settings.seed, sums.rounds);
            let what = format!("reference round {} ({} spp)", sums.rounds + 1, round_spp);
            counter.next(&what, progress);
            let start = Instant::now();
            let output = setup.render(&scene, &settings, progress)?;
            rendered += start.elapsed();
            sums.add(output.film.pixels());
        }
        let reference = sums.reference(origin(rendered.is_zero()), rendered);
        if spp.is_some() || sums.rounds >= reference::MAX_ROUNDS {
            return finish_reference(&cache, &key, &fingerprint, reference, rendered);
        }
        let noise = reference.noise_rel_mse(region).unwrap_or(f64::INFINITY);
        let smallest = measurements
            .iter()
            .map(|m| {
                glint_metrics::rel_mse(
                    view(&m.image, width, height),
                    view(&reference.mean, width, height),
                    region,
                )
            })
            .try_fold(f64::INFINITY, |a, b| b.map(|b| a.min(b)))?;
        // The measured error is on average the true error plus the noise.
        if noise * (reference::NOISE_MARGIN + 1.0) <= smallest {
            return finish_reference(&cache, &key, &fingerprint, reference, rendered);
        }
        wanted = (sums.rounds * 2).min(reference::MAX_ROUNDS);
        counter.total += (wanted - sums.rounds) as usize;
    }
}

/// Stores a reference that gained rounds in this bench, and returns it.
fn finish_reference(
    cache: &CachePaths,
    key: &str,
    fingerprint: &str,
    reference: Reference,
    rendered: Duration,
) -> Result<Reference, BenchError> {
    if !rendered.is_zero() {
        cache
            .store(key, fingerprint, &reference)
            .map_err(BenchError::Other)?;
    }
    Ok(reference)
}

fn view(pixels: &[Vec3], width: u32, height: u32) -> ImageView<'_> {
    ImageView {
        width,
        height,
        pixels,
    }
}

fn rows(
    config: &BenchConfig,
    measurements: &[Measurement],
    reference: &Reference,
    region: Region,
) -> Result<Vec<Row>, BenchError> {
    let (w, h) = (reference.width, reference.height);
    let reference_view = view(&reference.mean, w, h);
    measurements
        .iter()
        .map(|m| {
            let test = view(&m.image, w, h);
            let rel_mse = glint_metrics::rel_mse(test, reference_view, region)?;
            let seconds = m.median_time().as_secs_f64();
            Ok(Row {
                strategy: config.strategies[m.strategy].name(),
                spp: m.budget.spp,
                light_samples: m.budget.light_samples,
                environment_samples: m.budget.environment_samples,
                total_samples: m.budget.total_samples(),
                time_median_s: seconds,
                time_min_s: m.min_time().as_secs_f64(),
                time_max_s: m.max_time().as_secs_f64(),
                time_first_s: m.times[0].as_secs_f64(),
                runs: m.times.len(),
                camera_rays: m.stats.camera_rays,
                shadow_rays: m.stats.shadow_rays,
                reflection_rays: m.stats.reflection_rays,
                rmse: glint_metrics::rmse(test, reference_view, region)?,
                rel_mse,
                flip: glint_metrics::flip(test, reference_view)?.mean(region)?,
                efficiency: 1.0 / (rel_mse * seconds),
            })
        })
        .collect()
}

/// The strategies' names, in the order they were given.
fn names(config: &BenchConfig) -> Vec<String> {
    config.strategies.iter().map(Strategy::name).collect()
}

/// The strategy speed-ups are measured against: the first strategy whose
/// patterns are all `random` (whatever its texture filter), else the first.
/// By name: its patterns' part (before any `+`) is `random` alone, as
/// [`Strategy::name`] writes three equal patterns.
fn baseline_name(names: &[String]) -> String {
    names
        .iter()
        .find(|name| name.split('+').next() == Some(SamplePattern::Random.name()))
        .unwrap_or(&names[0])
        .clone()
}

/// The baseline's target: its largest budget, by samples and then by time.
/// Samples come first because the times of a small scene's cheapest budgets
/// can swap places on a busy machine, and the target must not move with them.
fn baseline(names: &[String], rows: &[Row]) -> Option<Baseline> {
    let name = baseline_name(names);
    let last = rows.iter().filter(|r| r.strategy == name).max_by(|a, b| {
        a.total_samples
            .cmp(&b.total_samples)
            .then(a.time_median_s.total_cmp(&b.time_median_s))
    })?;
    Some(Baseline {
        strategy: name,
        target_rel_mse: last.rel_mse,
        target_total_samples: last.total_samples,
        time_s: last.time_median_s,
    })
}

fn summaries(names: &[String], rows: &[Row]) -> Vec<StrategySummary> {
    let base = baseline(names, rows);
    names
        .iter()
        .map(|name| {
            let name = name.clone();
            let mine: Vec<&Row> = rows.iter().filter(|r| r.strategy == name).collect();
            let against_samples = |error: fn(&Row) -> f64| {
                let points: Vec<(f64, f64)> = mine
                    .iter()
                    .map(|r| (r.total_samples as f64, error(r)))
                    .collect();
                fit::log_log_slope(&points)
            };
            let crossing = base.as_ref().and_then(|b| {
                let curve: Vec<(f64, f64)> =
                    mine.iter().map(|r| (r.time_median_s, r.rel_mse)).collect();
                fit::cost_to_reach(&curve, b.target_rel_mse)
                    .filter(|c| !c.extrapolated || within_reach(&curve, c.cost))
                    .map(|c| (b.time_s / c.cost, c.extrapolated))
            });
            StrategySummary {
                name,
                rel_mse_slope: against_samples(|r| r.rel_mse),
                rmse_slope: against_samples(|r| r.rmse),
                equal_error_speedup: crossing.map(|c| c.0),
                speedup_extrapolated: crossing.is_some_and(|c| c.1),
            }
        })
        .collect()
}

/// How far a curve may be extended to reach the target error: to a time no
/// more than four times beyond the range it was measured over. Further out (a
/// biased strategy whose error levels off, say) a speed-up is not reported.
fn within_reach(curve: &[(f64, f64)], time: f64) -> bool {
    let (lo, hi) = curve.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.0), hi.max(p.0))
    });
    time >= lo / 4.0 && time <= hi * 4.0
}

/// The number of ladder steps each strategy was measured at (the fewest, for
/// time ladders where budgets can merge).
fn steps(measurements: &[Measurement]) -> usize {
    let strategies = measurements
        .iter()
        .map(|m| m.strategy)
        .max()
        .map_or(0, |s| s + 1);
    (0..strategies)
        .map(|s| measurements.iter().filter(|m| m.strategy == s).count())
        .min()
        .unwrap_or(0)
}

/// Per-pixel relative MSE at one ladder step, one map per strategy, coloured on
/// one scale: the 99th percentile of all their values, so that they compare.
fn heatmaps(
    config: &BenchConfig,
    measurements: &[Measurement],
    reference: &Reference,
    step: usize,
) -> Result<(Vec<Heatmap>, HeatmapSummary), BenchError> {
    let (w, h) = (reference.width, reference.height);
    let maps: Vec<(usize, glint_metrics::ErrorMap)> = (0..config.strategies.len())
        .filter_map(|s| {
            let m = measurements.iter().filter(|m| m.strategy == s).nth(step)?;
            let map = glint_metrics::rel_mse_map(view(&m.image, w, h), view(&reference.mean, w, h));
            Some(map.map(|map| (s, map)))
        })
        .collect::<Result<_, _>>()?;
    let scale =
        glint_metrics::heatmap_scale(maps.iter().flat_map(|(_, m)| m.values.iter().copied()));
    let files: Vec<Heatmap> = maps
        .iter()
        .map(|(s, map)| {
            Ok(Heatmap {
                file: format!("heatmap-{}.png", config.strategies[*s].file_stem()),
                pixels: glint_metrics::heatmap(map, scale)?,
            })
        })
        .collect::<Result<_, BenchError>>()?;
    let summary = HeatmapSummary {
        step,
        scale,
        files: files.iter().map(|h| h.file.clone()).collect(),
    };
    Ok((files, summary))
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

#[cfg(test)]
mod tests {
    use super::*;

    fn measurement(strategy: usize, spp: u32) -> Measurement {
        Measurement {
            strategy,
            budget: SampleBudget {
                spp,
                light_samples: 1,
                environment_samples: 0,
            },
            times: vec![Duration::from_millis(10)],
            stats: Default::default(),
            image: Vec::new(),
        }
    }

    #[test]
    fn the_reference_takes_four_times_the_largest_budget_as_a_power_of_two() {
        assert_eq!(default_round_spp(&[measurement(0, 1)]), 64);
        assert_eq!(
            default_round_spp(&[measurement(0, 16), measurement(0, 256)]),
            1024
        );
        assert_eq!(default_round_spp(&[measurement(0, 100)]), 512);
        assert_eq!(default_round_spp(&[measurement(0, 1 << 20)]), 16_384);
        assert_eq!(
            steps(&[measurement(0, 1), measurement(0, 4), measurement(1, 1)]),
            1
        );
    }

    #[test]
    fn large_scenes_are_benched_at_about_256_by_256() {
        assert_eq!(
            default_resolution(UVec2::new(512, 512)),
            UVec2::new(256, 256)
        );
        assert_eq!(
            default_resolution(UVec2::new(640, 360)),
            UVec2::new(341, 192)
        );
        assert_eq!(
            default_resolution(UVec2::new(200, 100)),
            UVec2::new(200, 100)
        );
        assert!(within_reach(&[(1.0, 0.1), (2.0, 0.05)], 7.9));
        assert!(!within_reach(&[(1.0, 0.1), (2.0, 0.05)], 8.1));
        assert!(!within_reach(&[(1.0, 0.1), (2.0, 0.05)], 0.2));
    }
}
