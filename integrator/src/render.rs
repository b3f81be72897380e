use crate::context::SampleContext;
use crate::counters::{ShadingCounters, TextureCounters};
use crate::direct::Wave;
use crate::sampling::{pixel_rng, LaneSamples, PixelSample, SobolPoints, PIXEL_STREAM};
use crate::settings::{Crop, RenderSettings, SettingsError};
use crate::trace::{Event, Tracer};
use crate::{DirectIntegrator, Scene};
use glam::{UVec2, Vec2, Vec3};
use glint_camera::{Camera, Film, PartialFilm};
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes, LANES};
use glint_geometry::{take_counters, CountingGuard, QueryCounters, Ray, RayDifferential, RayLanes};
use rayon::prelude::*;
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use std::time::{Duration, Instant};

/// Height in rows of the tiles (full-width bands) the image is split into for
/// parallel rendering.
pub const TILE_SIZE: u32 = 16;

/// Counts of the work a render did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    pub camera_rays: u64,
    /// Shadow rays of every kind (to lights and to environment samples).
    pub shadow_rays: u64,
    pub reflection_rays: u64,
    /// The integrator's counts by kind, skips and drops.
    pub shading: ShadingCounters,
    /// Intersection work: BVH visits and tests by shape (with `stats` only).
    pub queries: QueryCounters,
    /// Texture lookups by kind and MIP level (with `stats` only).
    pub textures: TextureCounters,
    pub elapsed: Duration,
}

/// What one tile's worker counted.
#[derive(Clone, Copy, Debug, Default)]
struct TileCounts {
    /// The pixels it rendered (not those a resumed render kept).
    pixels: u64,
    shading: ShadingCounters,
    queries: QueryCounters,
    textures: TextureCounters,
}

impl TileCounts {
    fn add(mut self, other: TileCounts) -> TileCounts {
        self.pixels += other.pixels;
        self.shading += other.shading;
        self.queries += other.queries;
        self.textures += other.textures;
        self
    }
}

impl RenderStats {
    /// Every ray traced: camera, shadow, reflection, and the rays towards
    /// directions drawn from specular lobes.
    pub fn rays(&self) -> u64 {
        self.camera_rays + self.shadow_rays + self.reflection_rays + self.shading.brdf_rays
    }

    pub fn rays_per_second(&self) -> f64 {
        self.rays() as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// How a render may be cut short, or continue an earlier one ([`render_with`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderControl<'a> {
    /// Once set (say by a signal handler), each worker stops after the pixel it
    /// is on (or the run of pixels sharing its chunk) and starts no other: the
    /// pixels not reached stay unfinished.
    pub stop: Option<&'a AtomicBool>,
    /// A partial render to continue: its finished pixels are kept as they are
    /// and only the others rendered. Every pixel depends only on the scene, the
    /// settings and its own index, so with the same scene and settings the
    /// result is the uninterrupted render's, bit for bit.
    pub resume: Option<&'a PartialFilm>,
    /// Render only this window of the camera's image: the film is the
    /// window's size, and each of its pixels is the same pixel of the whole
    /// render, bit for bit (a pixel depends only on its place in the whole
    /// image).
    pub crop: Option<Crop>,
}

/// A rendered image and what it cost.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub film: Film,
    /// Per pixel (row-major from the top left), whether it is finished: all of
    /// them unless [`RenderControl::stop`] was set.
    pub finished: Vec<bool>,
    pub stats: RenderStats,
}

/// Renders `scene` with the direct integrator, in parallel over tiles.
///
/// Tiles are bands of [`TILE_SIZE`] full rows, rendered straight into the film
/// (no second copy of the image). `on_tile_done(done, total)` is called after each
/// tile (from worker threads), for progress reporting. The result does not depend
/// on the thread count or on the order tiles finish in.
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    on_tile_done: &(dyn Fn(usize, usize) + Sync),
) -> Result<RenderOutput, SettingsError> {
    render_with(scene, settings, on_tile_done, RenderControl::default())
}

/// [`render`], which `control` may stop early or set to continue a partial
/// render.
pub fn render_with(
    scene: &Scene,
    settings: &RenderSettings,
    on_tile_done: &(dyn Fn(usize, usize) + Sync),
    control: RenderControl,
) -> Result<RenderOutput, SettingsError> {
    settings.validate()?;
    let window = match control.crop {
        Some(crop) => crop.check(scene.camera.resolution())?,
        None => full_image(scene.camera.resolution()),
    };
    if let Some(partial) = control.resume {
        let (film, camera) = (partial.film.resolution(), window.size());
        if film != camera {
            return Err(SettingsError::ResumeResolution { film, camera });
        }
    }
    scene.prepare(settings);
    let run = || render_on_current_pool(scene, settings, on_tile_done, control, window);
    match settings.threads {
        None => Ok(run()),
        Some(threads) => rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| SettingsError::ThreadPool(e.to_string()))
            .map(|pool| pool.install(run)),
    }
}

fn render_on_current_pool(
    scene: &Scene,
    settings: &RenderSettings,
    on_tile_done: &(dyn Fn(usize, usize) + Sync),
    control: RenderControl,
    window: Crop,
) -> RenderOutput {
    let start = Instant::now();
    let resolution = window.size();
    let integrator = DirectIntegrator::new(settings);
    let (mut film, mut finished) = match control.resume {
        Some(partial) => (partial.film.clone(), partial.finished.clone()),
        None => (
            Film::new(resolution),
            vec![false; resolution.x as usize * resolution.y as usize],
        ),
    };
    let band = (TILE_SIZE * resolution.x) as usize;
    let total = film.pixels().len().div_ceil(band);
    let done = AtomicUsize::new(0);
    let _counting = settings.stats.then(CountingGuard::start);
    let counts = film
        .pixels_mut()
        .par_chunks_mut(band)
        .zip(finished.par_chunks_mut(band))
        .enumerate()
        .map(|(i, (pixels, finished))| {
            let rows = Rows {
                first_row: window.y0 + i as u32 * TILE_SIZE,
                x0: window.x0,
                width: resolution.x,
                pixels,
                finished,
            };
            let counts = render_rows(scene, settings, &integrator, rows, control.stop);
            on_tile_done(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            counts
        })
        .reduce(TileCounts::default, TileCounts::add);
    let shading = counts.shading;
    let stats = RenderStats {
        camera_rays: counts.pixels * settings.spp as u64,
        shadow_rays: shading.light_shadow_rays + shading.environment_shadow_rays,
        reflection_rays: shading.reflection_rays,
        shading,
        queries: counts.queries,
        textures: counts.textures,
        elapsed: start.elapsed(),
    };
    RenderOutput {
        film,
        finished,
        stats,
    }
}

/// One tile: whole rows of the film from image row `first_row`, row-major,
/// with which of their pixels are finished; the film's columns are the
/// image's from `x0`, `width` of them.
struct Rows<'a> {
    first_row: u32,
    x0: u32,
    width: u32,
    pixels: &'a mut [Vec3],
    finished: &'a mut [bool],
}

/// Renders the unfinished pixels of `rows`, in order, until `stop` is set;
/// returns what it counted. A camera sample whose radiance is NaN or infinite
/// is left out of its pixel (counted in `nonfinite_samples`): one bad sample
/// would otherwise blot out the pixel.
fn render_rows(
    scene: &Scene,
    settings: &RenderSettings,
    integrator: &DirectIntegrator,
    rows: Rows,
    stop: Option<&AtomicBool>,
) -> TileCounts {
    let Rows {
        first_row,
        x0,
        width,
        pixels,
        finished,
    } = rows;
    let mut rendered = 0;
    if settings.stats {
        // Drop what other work on this thread counted: the tile's counts are its own.
        let _ = take_counters();
    }
    let mut pixel_samples = vec![Vec2::ZERO; settings.spp as usize];
    let mut ctx = SampleContext::new(settings.light_samples, settings.environment_samples);
    ctx.detailed = settings.stats;
    let pixels_of = PixelRenderer::new(scene, settings, integrator);
    let run = pixels_of.run_length();
    let mut run_samples = [Vec2::ZERO; LANES];
    let mut offset = 0;
    while offset < pixels.len() {
        if finished[offset] {
            offset += 1;
            continue;
        }
        if stop.is_some_and(|stop| stop.load(Ordering::Relaxed)) {
            break;
        }
        let column = offset as u32 % width;
        let (x, y) = (x0 + column, first_row + offset as u32 / width);
        // A run of pixels shares one chunk's lanes where it fits in the row
        // and none of it is finished; else the pixel goes alone.
        let whole_run = offset..offset + run;
        if run > 1
            && column as usize + run <= width as usize
            && !finished[whole_run.clone()].contains(&true)
        {
            let values = pixels_of.pixel_run(x, y, &mut run_samples, &mut ctx);
            pixels[whole_run.clone()].copy_from_slice(&values[..run]);
            finished[whole_run].fill(true);
            (offset, rendered) = (offset + run, rendered + run as u64);
        } else {
            pixels[offset] = pixels_of.pixel(x, y, &mut pixel_samples, &mut ctx);
            finished[offset] = true;
            (offset, rendered) = (offset + 1, rendered + 1);
        }
    }
    TileCounts {
        pixels: rendered,
        shading: ctx.counters,
        queries: if settings.stats {
            take_counters()
        } else {
            QueryCounters::default()
        },
        textures: ctx.textures,
    }
}

/// What every pixel of a render shares: the scene, the settings, and the
/// paths their samples may take.
pub(crate) struct PixelRenderer<'a> {
    scene: &'a Scene,
    settings: &'a RenderSettings,
    integrator: &'a DirectIntegrator,
    /// [`footprint_scale`] at the settings' spp.
    footprint_scale: f32,
    differentials: bool,
    /// The whole of a camera sample in lanes, from its ray to its radiance.
    all_in_lanes: bool,
    /// The objects the last span of pixels may see, for its next pixels.
    span: Cell<Option<CandidateSpan>>,
}

/// The objects the camera rays through pixels `x0..x1` of row `y` may hit.
#[derive(Clone, Copy, Debug)]
struct CandidateSpan {
    y: u32,
    x0: u32,
    x1: u32,
    objects: u64,
}

/// The pixels of a row whose camera rays' candidates are found together:
/// one frustum test instead of eight. The span's objects are a superset of
/// each pixel's, so every closest hit is the same.
const CANDIDATE_SPAN: u32 = 8;

impl<'a> PixelRenderer<'a> {
    pub(crate) fn new(
        scene: &'a Scene,
        settings: &'a RenderSettings,
        integrator: &'a DirectIntegrator,
    ) -> Self {
        let differentials = scene.needs_differentials();
        Self {
            scene,
            settings,
            integrator,
            footprint_scale: footprint_scale(settings.spp),
            differentials,
            all_in_lanes: settings.aov.is_none() && !differentials,
            span: Cell::new(None),
        }
    }

    /// The radiance of pixel `(x, y)`: the sum of its finite camera samples
    /// over `spp` (a sample that is not finite counts as zero).
    /// It depends only on the scene, the settings and `(x, y)`.
    pub(crate) fn pixel(
        &self,
        x: u32,
        y: u32,
        pixel_samples: &mut [Vec2],
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let candidates = self.candidates(x, 1, y);
        let mut sum = Vec3::ZERO;
        for chunk in self.pixel_chunks(x, y, pixel_samples) {
            let values = self.chunk_values(&chunk, candidates, ctx);
            accumulate(&mut sum, &values, 0..chunk.jitters.len(), &mut ctx.counters);
        }
        sum / self.settings.spp as f32
    }

    /// The chunks of [`LANES`] camera samples of pixel `(x, y)`, their
    /// positions drawn into `pixel_samples` (`spp` of them).
    pub(crate) fn pixel_chunks<'s>(
        &self,
        x: u32,
        y: u32,
        pixel_samples: &'s mut [Vec2],
    ) -> impl Iterator<Item = SampleChunk<'s>> + use<'s, '_> {
        let pixel = self.pixel_index(x, y);
        self.fill_jitters(pixel, pixel_samples);
        let seed = self.settings.seed;
        let samples: &'s [Vec2] = pixel_samples;
        samples
            .chunks(LANES)
            .enumerate()
            .map(move |(chunk, jitters)| SampleChunk {
                x0: x,
                y,
                jitters,
                samples: LaneSamples::of_pixel(PixelSample {
                    seed,
                    pixel,
                    sample: (chunk * LANES) as u64,
                }),
            })
    }

    /// Pixels rendered together, each the same as [`Self::pixel`]: where a
    /// pixel has fewer samples than a chunk has lanes, this many pixels of a
    /// row fill the lanes (1 where they do not divide evenly).
    pub(crate) fn run_length(&self) -> usize {
        let spp = self.settings.spp as usize;
        if spp < LANES && LANES.is_multiple_of(spp) {
            LANES / spp
        } else {
            1
        }
    }

    /// Pixels `(x0 + i, y)` for `i < run_length()`, [`Self::pixel`] each,
    /// bit for bit, their camera samples in the lanes of one chunk (`jitters`
    /// is a buffer of [`LANES`] positions).
    pub(crate) fn pixel_run(
        &self,
        x0: u32,
        y: u32,
        jitters: &mut [Vec2; LANES],
        ctx: &mut SampleContext,
    ) -> [Vec3; LANES] {
        let (run, spp) = (self.run_length(), self.settings.spp as usize);
        let mut samples = LaneSamples {
            seed: self.settings.seed,
            first: 0,
            per_pixel: spp,
            pixels: [0; LANES],
        };
        for (i, own) in jitters.chunks_mut(spp).take(run).enumerate() {
            samples.pixels[i] = self.pixel_index(x0 + i as u32, y);
            self.fill_jitters(samples.pixels[i], own);
        }
        let chunk = SampleChunk {
            x0,
            y,
            jitters: &jitters[..run * spp],
            samples,
        };
        let values = self.chunk_values(&chunk, self.candidates(x0, run, y), ctx);
        let mut sums = [Vec3::ZERO; LANES];
        for (i, sum) in sums.iter_mut().enumerate().take(run) {
            accumulate(sum, &values, i * spp..(i + 1) * spp, &mut ctx.counters);
            *sum /= spp as f32;
        }
        sums
    }

    /// The index `y · width + x` that names pixel (x, y)'s samples.
    fn pixel_index(&self, x: u32, y: u32) -> u64 {
        y as u64 * self.scene.camera.resolution().x as u64 + x as u64
    }

    /// The positions in pixel `pixel` of its camera samples, from its pattern.
    fn fill_jitters(&self, pixel: u64, out: &mut [Vec2]) {
        pixel_positions(self.settings, pixel, out);
    }

    /// The objects the camera rays through pixels `(x0..x0 + count, y)` may
    /// hit, where the whole sample is taken in lanes (else all): those of the
    /// span of [`CANDIDATE_SPAN`] pixels or more that holds them.
    pub(crate) fn candidates(&self, x0: u32, count: usize, y: u32) -> u64 {
        if !self.all_in_lanes {
            return u64::MAX;
        }
        let x1 = x0 + count as u32;
        if let Some(span) = self.span.get() {
            if span.y == y && span.x0 <= x0 && x1 <= span.x1 {
                return span.objects;
            }
        }
        let width = self.scene.camera.resolution().x;
        let end = x1.max(x0 + CANDIDATE_SPAN).min(width).max(x1);
        let objects = objects_seen_by_pixels(self.scene, x0, (end - x0) as usize, y);
        self.span.set(Some(CandidateSpan {
            y,
            x0,
            x1: end,
            objects,
        }));
        objects
    }

    /// The radiance of a chunk's camera samples: camera rays (with their
    /// differentials where the scene reads footprints), closest hits (among
    /// the objects `candidates` names where the whole sample is taken in
    /// lanes) and shading, all in lanes; one by one only for an AOV. With a
    /// tracer on (`T::ON`), it sees each step of the samples in their lanes
    /// (`glint explain`, around this call).
    pub(crate) fn chunk_values<T: Tracer>(
        &self,
        chunk: &SampleChunk,
        candidates: u64,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let (scene, integrator, used) = (self.scene, self.integrator, chunk.jitters.len());
        let (rays, diffs) = self.camera_rays(chunk);
        let closest = match &diffs {
            None => scene.shapes.closest_lanes_among(&rays, used, candidates),
            Some(diffs) if self.settings.aov.is_some() => {
                return self.samples_one_by_one(chunk, (&rays, diffs));
            }
            Some(_) => scene.shapes.closest_lanes(&rays, used),
        };
        let footprints = diffs.as_ref().filter(|_| self.differentials);
        let wave = Wave::first(&rays, footprints, &closest, used);
        integrator.li_wave(
            scene,
            wave,
            &mut integrator.lane_streams(&chunk.samples),
            ctx,
        )
    }

    /// Each of a chunk's camera samples' AOV, from its ray and
    /// differentials (`rays`).
    fn samples_one_by_one(
        &self,
        chunk: &SampleChunk,
        (ray_lanes, diffs): (&RayLanes, &[RayDifferential; LANES]),
    ) -> Vec3Lanes {
        let (scene, settings, used) = (self.scene, self.settings, chunk.jitters.len());
        let aov = settings.aov.expect("one by one for an AOV");
        Vec3Lanes::from_lanes(std::array::from_fn(|k| match k < used {
            true => aov.evaluate(scene, &ray_lanes.lane(k), &diffs[k], settings.max_depth),
            false => Vec3::ZERO,
        }))
    }

    /// The camera rays of a chunk's lanes: without differentials where its
    /// samples are taken in lanes whole, else with them (unit ones where the
    /// scene reads no footprint).
    fn camera_rays(&self, chunk: &SampleChunk) -> (RayLanes, Option<[RayDifferential; LANES]>) {
        let camera = &self.scene.camera;
        let (px, py) = chunk.raster_lanes();
        if self.all_in_lanes {
            return (centre_rays(camera, px, py), None);
        }
        let (rays, diffs) = match self.differentials {
            true => camera_rays_lanes(camera, px, py, self.footprint_scale),
            false => {
                let rays = centre_rays(camera, px, py);
                let diffs = lanes::array_from_fn(|k| RayDifferential::none(&rays.lane(k)));
                (rays, diffs)
            }
        };
        (rays, Some(diffs))
    }

    /// The camera stage of the lanes of `chunk` as a tracer sees it: each
    /// lane's raster position, film point and ray (its own, recomputed),
    /// with its differentials where the scene reads footprints.
    pub(crate) fn camera_events<'c>(
        &'c self,
        chunk: &'c SampleChunk,
    ) -> impl Fn(usize) -> Event + 'c {
        let (rays, diffs) = self.camera_rays(chunk);
        let diffs = diffs.filter(|_| self.differentials);
        move |k: usize| {
            let raster = Vec2::new(chunk.x(k) as f32, chunk.y as f32) + chunk.jitters[k];
            let (ndc, film_point) = self.scene.camera.film_point(raster.x, raster.y);
            Event::Camera {
                raster,
                ndc,
                film_point,
                ray: rays.lane(k),
                differential: diffs.map(|d| d[k]),
            }
        }
    }
}

/// The positions in pixel `pixel` (index `y · width + x`) of its camera
/// samples, from the settings' pixel pattern and seed.
pub(crate) fn pixel_positions(settings: &RenderSettings, pixel: u64, out: &mut [Vec2]) {
    let mut rng = pixel_rng(settings.seed, pixel, PIXEL_STREAM);
    let sobol = SobolPoints::pixel_positions(settings.seed, pixel);
    settings.pixel_pattern.fill(&mut rng, sobol, out);
}

/// The width of a camera sample's footprint in pixels at `spp` samples:
/// each stands for `1/√spp` of the pixel (pbrt-v4 scales differentials the
/// same way), never below 1/8.
pub(crate) fn footprint_scale(spp: u32) -> f32 {
    (1.0 / (spp as f32).sqrt()).max(0.125)
}

/// The whole image of `size` as a window.
fn full_image(size: UVec2) -> Crop {
    Crop {
        x0: 0,
        y0: 0,
        x1: size.x,
        y1: size.y,
    }
}

/// The objects a camera ray through pixels `(x0..x0 + count, y)` may hit
/// ([`ShapeList::objects_in_frustum`](glint_geometry::ShapeList::objects_in_frustum)):
/// those meeting the frustum of the rays through the run's four corners.
fn objects_seen_by_pixels(scene: &Scene, x0: u32, count: usize, y: u32) -> u64 {
    let camera = &scene.camera;
    let (x, y, w) = (x0 as f32, y as f32, count as f32);
    let corner = |dx: f32, dy: f32| camera.generate_ray(x + dx, y + dy);
    let corners = [
        corner(0.0, 0.0),
        corner(w, 0.0),
        corner(w, 1.0),
        corner(0.0, 1.0),
    ];
    scene
        .shapes
        .objects_in_frustum(corners[0].origin, corners.map(|c| c.direction))
}

/// Adds a chunk's radiance `values` in `lanes` to `sum`, in order, leaving
/// out (and counting in `counters`) those that are NaN or infinite.
#[inline]
pub(crate) fn accumulate(
    sum: &mut Vec3,
    values: &Vec3Lanes,
    lanes: std::ops::Range<usize>,
    counters: &mut ShadingCounters,
) {
    let finite = lanes::bits(values.x.is_finite() & values.y.is_finite() & values.z.is_finite());
    let (x, y, z) = (
        values.x.to_array(),
        values.y.to_array(),
        values.z.to_array(),
    );
    for k in lanes {
        if finite >> k & 1 == 1 {
            *sum += Vec3::new(x[k], y[k], z[k]);
        } else {
            counters.nonfinite_samples += 1;
        }
    }
}

/// A chunk of camera samples in lanes: runs of `samples.per_pixel` samples
/// of pixels `(x0, y), (x0 + 1, y), …`, lane k at `jitters[k]` in its pixel
/// (the lanes past `jitters` repeat the last).
pub(crate) struct SampleChunk<'j> {
    x0: u32,
    y: u32,
    pub(crate) jitters: &'j [Vec2],
    pub(crate) samples: LaneSamples,
}

impl SampleChunk<'_> {
    /// Lane k's pixel column (a run's length divides [`LANES`]: a shift).
    #[inline]
    fn x(&self, k: usize) -> u32 {
        debug_assert!(self.samples.per_pixel.is_power_of_two());
        self.x0 + (k >> self.samples.per_pixel.trailing_zeros()) as u32
    }

    /// Every lane's raster position.
    #[inline]
    fn raster_lanes(&self) -> (F32Lanes, F32Lanes) {
        let last = self.jitters.len() - 1;
        let (mut x, mut y) = ([0.0; LANES], [0.0; LANES]);
        for k in 0..LANES {
            let jitter = self.jitters[k.min(last)];
            x[k] = self.x(k.min(last)) as f32 + jitter.x;
            y[k] = self.y as f32 + jitter.y;
        }
        (F32Lanes::new(x), F32Lanes::new(y))
    }
}

fn vec3_lanes([x, y, z]: [F32Lanes; 3]) -> Vec3Lanes {
    Vec3Lanes { x, y, z }
}

/// The camera rays through raster positions `(x[k], y[k])`, without
/// differentials.
#[inline]
fn centre_rays(camera: &Camera, x: F32Lanes, y: F32Lanes) -> RayLanes {
    let c = camera.generate_rays_lanes(x, y);
    RayLanes {
        origin: Vec3Lanes::splat(c.origin),
        direction: vec3_lanes(c.direction),
    }
}

/// [`camera_ray`] in every lane, at raster positions `(x[k], y[k])`: each
/// lane's ray and differentials bit for bit the scalar ones.
pub fn camera_rays_lanes(
    camera: &Camera,
    x: F32Lanes,
    y: F32Lanes,
    scale: f32,
) -> (RayLanes, [RayDifferential; LANES]) {
    let rays = centre_rays(camera, x, y);
    let (origin, d) = (camera.position(), rays.direction);
    let shrunk = |offset: [F32Lanes; 3]| d + (vec3_lanes(offset) - d).scale(F32Lanes::splat(scale));
    let rx = shrunk(camera.generate_rays_lanes(x + F32Lanes::ONE, y).direction);
    let ry = shrunk(camera.generate_rays_lanes(x, y + F32Lanes::ONE).direction);
    let diffs = lanes::array_from_fn(|k| RayDifferential {
        rx_origin: origin,
        rx_direction: rx.lane(k),
        ry_origin: origin,
        ry_direction: ry.lane(k),
    });
    (rays, diffs)
}

/// The camera ray through `raster`, with its differentials shrunk to `scale`
/// pixels (a render uses `max(1/8, 1/√spp)`).
pub fn camera_ray(camera: &Camera, raster: Vec2, scale: f32) -> (Ray, RayDifferential) {
    let c = camera.generate_ray_differential(raster.x, raster.y);
    let d = c.ray.direction;
    let diff = RayDifferential {
        rx_origin: c.ray.origin,
        rx_direction: d + scale * (c.dx_direction - d),
        ry_origin: c.ray.origin,
        ry_direction: d + scale * (c.dy_direction - d),
    };
    (Ray::new(c.ray.origin, d), diff)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lane's ray and differentials are the scalar `camera_ray`'s, bit
    /// for bit, for cameras looking along and across the axes.
    #[test]
    fn camera_rays_in_lanes_are_the_scalar_ones() {
        let cameras = [
            (Vec3::new(0.0, 1.0, 6.0), Vec3::new(0.0, 0.55, -10.0), 45.0),
            (Vec3::new(-2.5, 3.1, 0.7), Vec3::new(1.0, -0.2, -3.0), 71.0),
            (Vec3::ZERO, -Vec3::Z, 12.0),
        ];
        for (position, look_at, fov) in cameras {
            let resolution = UVec2::new(640, 360);
            let camera = Camera::new(position, look_at, Vec3::Y, fov, 1.0, resolution).unwrap();
            let raster = |k: usize| Vec2::new(17.0 + 39.3 * k as f32, 3.0 + 22.1 * k as f32);
            let (x, y) = (
                lanes::from_fn(|k| raster(k).x),
                lanes::from_fn(|k| raster(k).y),
            );
            for scale in [1.0, 0.25, 0.125] {
                let (rays, diffs) = camera_rays_lanes(&camera, x, y, scale);
                for (k, diff) in diffs.iter().enumerate() {
                    let (ray, expected) = camera_ray(&camera, raster(k), scale);
                    assert_eq!(rays.lane(k).origin, ray.origin);
                    assert_eq!(rays.lane(k).direction, ray.direction, "lane {k}");
                    assert_eq!(*diff, expected, "lane {k} at scale {scale}");
                }
            }
        }
    }
}
