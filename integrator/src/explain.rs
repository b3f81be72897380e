//! One pixel explained: [`explain_pixel`] renders a pixel as a render does,
//! and again with a [`PixelTrace`] recording every step of the samples asked
//! for, and checks that the two agree bit for bit.

use crate::render::{accumulate, PixelRenderer};
use crate::trace::{Event, PixelTrace, SampleSelection, SampleTrace, Tracer};
use crate::{DirectIntegrator, RenderSettings, SampleContext, Scene, SettingsError};
use glam::{UVec2, Vec2, Vec3};
use glint_geometry::lanes;

/// A pixel's radiance and the recorded steps of its selected samples.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelExplanation {
    pub pixel: UVec2,
    /// Camera samples per pixel.
    pub spp: u32,
    /// The pixel's radiance: what a render writes for it (linear).
    pub radiance: Vec3,
    /// The selected samples' steps, in sample order.
    pub samples: Vec<SampleTrace>,
}

/// Why a pixel cannot be explained.
#[derive(Debug, thiserror::Error)]
pub enum ExplainError {
    #[error(transparent)]
    Settings(#[from] SettingsError),
    #[error("pixel ({x}, {y}) is outside the {}x{} image", size.x, size.y)]
    Outside { x: u32, y: u32, size: UVec2 },
    #[error("sample {sample} does not exist: the pixel has {spp} samples (0 to {})", spp - 1)]
    NoSuchSample { sample: u64, spp: u32 },
    /// The traced pixel differs from the rendered one: a bug in Glint (a
    /// tracer's hooks must not change what the lanes compute).
    #[error(
        "internal error: the traced pixel ({traced}) differs from the rendered one ({rendered})"
    )]
    Diverged { rendered: Vec3, traced: Vec3 },
}

/// Pixel `(x, y)` of `scene` rendered with `settings`, with the steps of the
/// samples `selection` names. Its radiance is what [`crate::render`] writes
/// for that pixel (the same code, on one pixel; a render may shade several
/// pixels' samples in one chunk's lanes, to the same bits): the trace is taken
/// on the render's own route, in lanes, and checked against the untraced
/// pixel bit for bit ([`ExplainError::Diverged`] otherwise).
pub fn explain_pixel(
    scene: &Scene,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    selection: SampleSelection,
) -> Result<PixelExplanation, ExplainError> {
    settings.validate()?;
    let size = scene.camera.resolution();
    if x >= size.x || y >= size.y {
        return Err(ExplainError::Outside { x, y, size });
    }
    if let SampleSelection::One(sample) = selection {
        if sample >= settings.spp as u64 {
            return Err(ExplainError::NoSuchSample {
                sample,
                spp: settings.spp,
            });
        }
    }
    let settings = RenderSettings {
        aov: None,
        stats: false,
        ..settings.clone()
    };
    let integrator = DirectIntegrator::new(&settings);
    let renderer = PixelRenderer::new(scene, &settings, &integrator);
    let mut pixel_samples = vec![Vec2::ZERO; settings.spp as usize];
    let mut ctx = SampleContext::new(settings.light_samples, settings.environment_samples);
    let rendered = renderer.pixel(x, y, &mut pixel_samples, &mut ctx);
    let mut traced_ctx = SampleContext::with_tracer(
        settings.light_samples,
        settings.environment_samples,
        PixelTrace::new(selection),
    );
    let traced = traced_pixel(&renderer, (x, y), &mut pixel_samples, &mut traced_ctx);
    if rendered.to_array().map(f32::to_bits) != traced.to_array().map(f32::to_bits) {
        return Err(ExplainError::Diverged { rendered, traced });
    }
    Ok(PixelExplanation {
        pixel: UVec2::new(x, y),
        spp: settings.spp,
        radiance: rendered,
        samples: traced_ctx.tracer.samples,
    })
}

/// Pixel `(x, y)` as [`PixelRenderer::pixel`] computes it, its chunks'
/// camera samples seen by `ctx`'s tracer: the render's own `chunk_values`
/// (whose stages record their steps), with the chunk's start, its camera
/// stage and each sample's radiance recorded around it.
fn traced_pixel<T: Tracer>(
    renderer: &PixelRenderer,
    (x, y): (u32, u32),
    pixel_samples: &mut [Vec2],
    ctx: &mut SampleContext<T>,
) -> Vec3 {
    let spp = pixel_samples.len();
    let candidates = renderer.candidates(x, 1, y);
    let mut sum = Vec3::ZERO;
    for chunk in renderer.pixel_chunks(x, y, pixel_samples) {
        let lanes = lanes::bits(lanes::first_lanes(chunk.jitters.len()));
        (ctx.tracer).start_chunk(chunk.jitters.len(), |k| chunk.samples.lane(k).sample);
        (ctx.tracer).record(lanes, renderer.camera_events(&chunk));
        let values = renderer.chunk_values(&chunk, candidates, ctx);
        let radiance = |k| Event::SampleRadiance {
            value: values.lane(k),
        };
        (ctx.tracer).record(lanes, radiance);
        accumulate(&mut sum, &values, 0..chunk.jitters.len(), &mut ctx.counters);
    }
    sum / spp as f32
}
