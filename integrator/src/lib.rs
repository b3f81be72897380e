//! The integrator stage of Glint: the scene as the integrator sees it, the
//! course's direct-lighting integrator, sample patterns, and the parallel,
//! deterministic render loop.
//!
//! # Conventions
//! - Radiance is **linear** RGB `f32`; the film is written by the camera crate.
//! - Determinism: every random number a pixel uses comes from a generator seeded by
//!   `(seed, pixel index, sample index)` ([`sampling::pixel_rng`]), or from a Sobol
//!   sequence seeded by `(seed, pixel index, dimension pair)`
//!   ([`sampling::SobolSequence`]), never from a shared generator, so the image is
//!   bit-identical for any thread count or tile order.
//! - Work is split into tiles of [`TILE_SIZE`] full rows, rendered in parallel with
//!   rayon straight into the film; scratch buffers are allocated once per tile,
//!   never per ray.
//!
//! # Entry points
//! - [`SceneBuilder`] assembles a [`Scene`] (materials, shapes, meshes, lights,
//!   ambient, environment) and builds its BVH; [`SceneBuilder::build`] fails with a
//!   [`SceneError`] if a shape names a missing material.
//! - [`render`] renders a scene with [`RenderSettings`] (checked by
//!   [`RenderSettings::validate`], failing with a [`SettingsError`]) into a
//!   [`RenderOutput`]: the film and its [`RenderStats`].
//! - [`DirectIntegrator::li`] is the radiance along one ray, for callers that drive
//!   their own loop ([`camera_ray`] makes the camera ray with its differentials).
//! - [`explain_pixel`] is one pixel as [`render`] computes it, with every step of
//!   its samples recorded ([`trace`]: the integrator's events, seen by a
//!   [`trace::Tracer`] type parameter that costs nothing when it is `()`);
//!   [`RenderControl::crop`] renders a window of the image with the whole
//!   render's pixels.
//! - [`SamplePattern`] and [`sampling`]: the sample patterns (grid, random,
//!   stratified, Owen-scrambled Sobol) and per-pixel streams;
//!   [`Aov`]: buffers other than radiance.
//! - With the `mistakes` feature, `mistakes::render_with_mistakes`: the
//!   one-ray reference integrator with classic student mistakes switched on
//!   (`glint grade` names a failing image's mistake with it).
//! - [`report_level()`]: the MIP level the course report chooses (section 2.8),
//!   `log2(L/W)`, with its `L` and `W`.

mod aov;
mod context;
pub mod counters;
mod direct;
mod explain;
mod light_samples;
#[cfg(any(test, feature = "mistakes"))]
pub mod mistakes;
mod physical;
#[cfg(any(test, feature = "mistakes"))]
mod reference;
mod render;
mod report_level;
pub mod sampling;
mod scene;
mod settings;
mod shading_point;
mod texture_lookup;
pub mod trace;

pub use aov::Aov;
pub use context::SampleContext;
pub use counters::{LookupKind, ShadingCounters, Skips, TextureCounters};
pub use direct::DirectIntegrator;
pub use explain::{explain_pixel, ExplainError, PixelExplanation};
pub use glint_lighting::{AreaSampling, EnvironmentSampling, ShadingModel};
pub use render::{
    camera_ray, render, render_with, RenderControl, RenderOutput, RenderStats, TILE_SIZE,
};
pub use report_level::{pixel_height_on_surface, report_level, uv_unit_length, ReportLevel};
pub use sampling::SamplePattern;
pub use scene::{Scene, SceneBuilder, SceneError, Surface, SurfaceKind, TextureLevel};
pub use settings::{Crop, RenderSettings, SampleCount, SettingsError, MAX_SAMPLES, MAX_THREADS};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
