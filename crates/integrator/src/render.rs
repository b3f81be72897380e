use crate::direct::SampleContext;
use crate::sampling::{pixel_rng, SamplePattern, PIXEL_STREAM};
use crate::{DirectIntegrator, Scene};
use glam::{UVec2, Vec2, Vec3};
use glint_camera::Film;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Side of the square tiles the image is split into for parallel rendering.
pub const TILE_SIZE: u32 = 16;

/// How to render: samples per pixel and per light, their patterns, the seed of
/// every random stream, and the number of threads.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Camera samples per pixel, averaged with a box filter.
    pub spp: u32,
    pub pixel_pattern: SamplePattern,
    /// Samples per area light per camera sample.
    pub light_samples: u32,
    pub light_pattern: SamplePattern,
    pub seed: u64,
    /// Worker threads; `None` uses one per core.
    pub threads: Option<usize>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 16,
            pixel_pattern: SamplePattern::Stratified,
            light_samples: 16,
            light_pattern: SamplePattern::Stratified,
            seed: 0,
            threads: None,
        }
    }
}

/// Settings that cannot be rendered.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    #[error("{what} must be at least 1")]
    Zero { what: &'static str },
    #[error("{what} is {count}, but the grid pattern needs a perfect square (1, 4, 9, 16, …)")]
    GridNotSquare { what: &'static str, count: u32 },
    #[error("threads must be at least 1")]
    ZeroThreads,
    #[error("could not start the worker threads: {0}")]
    ThreadPool(String),
}

impl RenderSettings {
    /// Checks that the counts are positive and fit their patterns.
    pub fn validate(&self) -> Result<(), SettingsError> {
        for (what, count, pattern) in [
            ("spp", self.spp, self.pixel_pattern),
            ("light samples", self.light_samples, self.light_pattern),
        ] {
            if count == 0 {
                return Err(SettingsError::Zero { what });
            }
            if !pattern.supports(count) {
                return Err(SettingsError::GridNotSquare { what, count });
            }
        }
        if self.threads == Some(0) {
            return Err(SettingsError::ZeroThreads);
        }
        Ok(())
    }
}

/// Counts of the work a render did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    pub camera_rays: u64,
    pub shadow_rays: u64,
    pub elapsed: Duration,
}

impl RenderStats {
    pub fn rays(&self) -> u64 {
        self.camera_rays + self.shadow_rays
    }

    pub fn rays_per_second(&self) -> f64 {
        self.rays() as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// A rendered image and what it cost.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub film: Film,
    pub stats: RenderStats,
}

/// A rectangle of pixels `[min, max)`.
#[derive(Clone, Copy, Debug)]
struct Tile {
    min: UVec2,
    max: UVec2,
}

fn tiles(resolution: UVec2) -> Vec<Tile> {
    let mut tiles = Vec::new();
    for y in (0..resolution.y).step_by(TILE_SIZE as usize) {
        for x in (0..resolution.x).step_by(TILE_SIZE as usize) {
            let min = UVec2::new(x, y);
            tiles.push(Tile {
                min,
                max: (min + TILE_SIZE).min(resolution),
            });
        }
    }
    tiles
}

/// Renders `scene` with the direct integrator, in parallel over tiles.
///
/// `on_tile_done(done, total)` is called after each tile (from worker threads), for
/// progress reporting. The result does not depend on the thread count or on the
/// order tiles finish in.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    on_tile_done: &(dyn Fn(usize, usize) + Sync),
) -> Result<RenderOutput, SettingsError> {
    settings.validate()?;
    match settings.threads {
        None => Ok(render_on_current_pool(scene, settings, on_tile_done)),
        Some(threads) => rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| SettingsError::ThreadPool(e.to_string()))
            .map(|pool| pool.install(|| render_on_current_pool(scene, settings, on_tile_done))),
    }
}

fn render_on_current_pool(
    scene: &Scene,
    settings: &RenderSettings,
    on_tile_done: &(dyn Fn(usize, usize) + Sync),
) -> RenderOutput {
    let start = Instant::now();
    let resolution = scene.camera.resolution();
    let integrator = DirectIntegrator {
        light_samples: settings.light_samples,
        light_pattern: settings.light_pattern,
    };
    let tiles = tiles(resolution);
    let done = std::sync::atomic::AtomicUsize::new(0);
    let rendered: Vec<(Vec<Vec3>, u64)> = tiles
        .par_iter()
        .map(|tile| {
            let result = render_tile(scene, settings, &integrator, *tile);
            let finished = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            on_tile_done(finished, tiles.len());
            result
        })
        .collect();

    let mut film = Film::new(resolution);
    let mut stats = RenderStats::default();
    for (tile, (pixels, shadow_rays)) in tiles.iter().zip(rendered) {
        let width = tile.max.x - tile.min.x;
        for (i, radiance) in pixels.into_iter().enumerate() {
            let x = tile.min.x + i as u32 % width;
            let y = tile.min.y + i as u32 / width;
            film.set_pixel(x, y, radiance);
        }
        stats.shadow_rays += shadow_rays;
    }
    stats.camera_rays = resolution.x as u64 * resolution.y as u64 * settings.spp as u64;
    stats.elapsed = start.elapsed();
    RenderOutput { film, stats }
}

/// The tile's pixels in row-major order, and the shadow rays it traced.
fn render_tile(
    scene: &Scene,
    settings: &RenderSettings,
    integrator: &DirectIntegrator,
    tile: Tile,
) -> (Vec<Vec3>, u64) {
    let width = scene.camera.resolution().x as u64;
    let size = tile.max - tile.min;
    let mut pixels = Vec::with_capacity((size.x * size.y) as usize);
    let mut pixel_samples = vec![Vec2::ZERO; settings.spp as usize];
    let mut ctx = SampleContext::new(settings.light_samples);
    for y in tile.min.y..tile.max.y {
        for x in tile.min.x..tile.max.x {
            let pixel = y as u64 * width + x as u64;
            let mut rng = pixel_rng(settings.seed, pixel, PIXEL_STREAM);
            settings.pixel_pattern.fill(&mut rng, &mut pixel_samples);
            let mut sum = Vec3::ZERO;
            for (sample, offset) in pixel_samples.iter().enumerate() {
                ctx.rng = pixel_rng(settings.seed, pixel, sample as u64);
                let raster = Vec2::new(x as f32, y as f32) + *offset;
                let camera_ray = scene.camera.generate_ray(raster.x, raster.y);
                let ray = glint_geometry::Ray::new(camera_ray.origin, camera_ray.direction);
                sum += integrator.li(scene, &ray, &mut ctx);
            }
            pixels.push(sum / settings.spp as f32);
        }
    }
    (pixels, ctx.shadow_rays)
}
