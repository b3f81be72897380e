//! Settings given beside a scene file that replace its own: `glint render`'s
//! flags, and the Python package's keywords, through one code path.

use crate::SceneDescription;
use glam::UVec2;
use glint_integrator::{
    AreaSampling, EnvironmentSampling, RenderSettings, SamplePattern, TextureLevel,
};
use glint_texture::TextureFilter;

/// What replaces the scene file's settings; `None` keeps the file's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    /// Camera samples per pixel (`render.spp`).
    pub spp: Option<u32>,
    /// Samples per area light per camera sample (`render.light_samples`).
    pub light_samples: Option<u32>,
    /// Where the camera samples fall in the pixel (`render.pixel_sampler`).
    pub pixel_sampler: Option<SamplePattern>,
    /// Where the samples fall on each area light (`render.light_sampler`).
    pub light_sampler: Option<SamplePattern>,
    /// Most mirror reflections per camera ray (`render.max_depth`).
    pub max_depth: Option<u32>,
    /// Environment directions per shading point (`render.environment_samples`).
    pub environment_samples: Option<u32>,
    /// The environment samples' pattern (`render.environment_sampler`).
    pub environment_sampler: Option<SamplePattern>,
    /// How environment directions are drawn (`render.environment_sampling`).
    pub environment_sampling: Option<EnvironmentSampling>,
    /// How area lights are sampled under physical shading (`render.area_sampling`).
    pub area_sampling: Option<AreaSampling>,
    /// Multiple importance sampling of glossy lobes (`render.mis`).
    pub mis: Option<bool>,
    /// The seed of every random stream (`render.seed`).
    pub seed: Option<u64>,
    /// Film size in pixels (`render.resolution`).
    pub resolution: Option<UVec2>,
    /// The filter of every image texture (each texture's `filter`).
    pub texture_filter: Option<TextureFilter>,
    /// The MIP level image textures are read at.
    pub texture_level: Option<TextureLevel>,
}

/// Why overrides could not be applied.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OverrideError {
    /// The report's level is read trilinearly; another filter was asked for.
    #[error("the report's texture level is read trilinearly: leave out the texture filter, or give trilinear")]
    ReportLevelFilter,
    /// The resolution the camera cannot take.
    #[error("resolution: {0}")]
    Resolution(String),
    /// The settings, once replaced, are not a render's.
    #[error("render settings: {0}")]
    Settings(String),
}

impl Overrides {
    /// Applies these to a loaded scene: its settings replaced, its
    /// environment's sampling prepared for them, its textures' filter and
    /// level and its camera's resolution set; then its settings checked.
    pub fn apply(&self, description: &mut SceneDescription) -> Result<(), OverrideError> {
        self.apply_to_settings(&mut description.settings);
        let scene = &mut description.scene;
        // The map's distribution is part of loading it, not of the render.
        let start = std::time::Instant::now();
        scene.prepare(&description.settings);
        description.timings.assets += start.elapsed();
        if let Some(filter) = self.texture_filter {
            scene.override_texture_filter(filter);
        }
        if let Some(level) = self.texture_level {
            let other_filter = self
                .texture_filter
                .is_some_and(|f| f != TextureFilter::Trilinear);
            if level == TextureLevel::Report && other_filter {
                return Err(OverrideError::ReportLevelFilter);
            }
            scene.set_texture_level(level);
        }
        if let Some(resolution) = self.resolution {
            scene.camera = (scene.camera)
                .with_resolution(resolution)
                .map_err(|e| OverrideError::Resolution(e.to_string()))?;
        }
        (description.settings)
            .validate()
            .map_err(|e| OverrideError::Settings(e.to_string()))
    }

    /// The render settings these replace.
    pub fn apply_to_settings(&self, settings: &mut RenderSettings) {
        let keep = |value: &mut u32, new: Option<u32>| *value = new.unwrap_or(*value);
        keep(&mut settings.spp, self.spp);
        keep(&mut settings.light_samples, self.light_samples);
        keep(&mut settings.max_depth, self.max_depth);
        keep(&mut settings.environment_samples, self.environment_samples);
        settings.pixel_pattern = self.pixel_sampler.unwrap_or(settings.pixel_pattern);
        settings.light_pattern = self.light_sampler.unwrap_or(settings.light_pattern);
        settings.seed = self.seed.unwrap_or(settings.seed);
        settings.area_sampling = self.area_sampling.unwrap_or(settings.area_sampling);
        settings.mis = self.mis.unwrap_or(settings.mis);
        settings.environment_pattern =
            (self.environment_sampler).unwrap_or(settings.environment_pattern);
        settings.environment_sampling =
            (self.environment_sampling).unwrap_or(settings.environment_sampling);
    }
}
