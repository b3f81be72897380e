//! How to render: the settings a render is given, their limits, and the errors
//! of settings that cannot be rendered.

use crate::sampling::SamplePattern;
use crate::Aov;
use glam::UVec2;
use glint_lighting::{AreaSampling, EnvironmentSampling};

/// The most mirror reflections a render follows.
pub const MAX_DEPTH: u32 = 64;

/// The most worker threads a render accepts.
pub const MAX_THREADS: usize = 1024;

/// The most samples per pixel, and per light, a render accepts: each worker keeps
/// a buffer of that many sample positions, so the bound keeps memory bounded.
pub const MAX_SAMPLES: u32 = 1 << 20;

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
    /// Write this buffer instead of radiance.
    pub aov: Option<Aov>,
    /// Most mirror reflections followed along one camera ray.
    pub max_depth: u32,
    /// Environment directions sampled per shading point to light surfaces
    /// (0: the environment is only seen, directly and in mirrors).
    pub environment_samples: u32,
    /// Where in [0, 1)² the environment samples fall before they are mapped to
    /// directions.
    pub environment_pattern: SamplePattern,
    /// How those points are mapped to directions: by the map's luminance or
    /// by the cosine about the shading normal.
    pub environment_sampling: EnvironmentSampling,
    /// Gather the detailed counts of [`RenderStats`](crate::RenderStats) (intersection tests, BVH
    /// visits, texture lookups by level); the image is the same either way.
    pub stats: bool,
    /// Physical shading: how area lights are sampled.
    pub area_sampling: AreaSampling,
    /// Physical shading: combine light samples with as many samples of glossy
    /// materials' specular lobes by multiple importance sampling (Veach's
    /// power heuristic); off, area lights are sampled by light only.
    pub mis: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 16,
            pixel_pattern: SamplePattern::Sobol,
            light_samples: 16,
            light_pattern: SamplePattern::Sobol,
            seed: 0,
            threads: None,
            aov: None,
            max_depth: 4,
            environment_samples: 16,
            environment_pattern: SamplePattern::Sobol,
            environment_sampling: EnvironmentSampling::Luminance,
            stats: false,
            area_sampling: AreaSampling::Auto,
            mis: true,
        }
    }
}

/// Which sample count a [`SettingsError`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleCount {
    /// Camera samples per pixel (`spp`).
    PerPixel,
    /// Samples per area light per camera sample.
    PerLight,
    /// Environment directions per shading point.
    PerEnvironment,
}

impl std::fmt::Display for SampleCount {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            SampleCount::PerPixel => "spp",
            SampleCount::PerLight => "light samples",
            SampleCount::PerEnvironment => "environment samples",
        })
    }
}

/// Settings that cannot be rendered.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SettingsError {
    #[error("{what} must be at least 1")]
    Zero { what: SampleCount },
    #[error("max depth is {0}, more than the limit of {MAX_DEPTH}")]
    Depth(u32),
    #[error("{what} is {count}, more than the limit of {MAX_SAMPLES}")]
    TooMany { what: SampleCount, count: u32 },
    #[error("{what} is {count}, but the grid pattern needs a perfect square (1, 4, 9, 16, …)")]
    GridNotSquare { what: SampleCount, count: u32 },
    #[error("threads must be from 1 to {MAX_THREADS}, got {0}")]
    Threads(usize),
    #[error("could not start the worker threads: {0}")]
    ThreadPool(String),
    #[error("the partial render to resume is {}x{} pixels, the camera's film {}x{}", film.x, film.y, camera.x, camera.y)]
    ResumeResolution { film: UVec2, camera: UVec2 },
    #[error("the crop {},{},{},{} is not a non-empty window of the {}x{} image (x0 < x1 <= width, y0 < y1 <= height)", crop.x0, crop.y0, crop.x1, crop.y1, size.x, size.y)]
    Crop { crop: Crop, size: UVec2 },
}

impl RenderSettings {
    /// Checks that the counts are positive (the environment's may be 0) and fit
    /// their patterns.
    pub fn validate(&self) -> Result<(), SettingsError> {
        for (what, count, pattern) in [
            (SampleCount::PerPixel, self.spp, self.pixel_pattern),
            (
                SampleCount::PerLight,
                self.light_samples,
                self.light_pattern,
            ),
        ] {
            if count == 0 {
                return Err(SettingsError::Zero { what });
            }
            if count > MAX_SAMPLES {
                return Err(SettingsError::TooMany { what, count });
            }
            if !pattern.supports(count) {
                return Err(SettingsError::GridNotSquare { what, count });
            }
        }
        let (what, count) = (SampleCount::PerEnvironment, self.environment_samples);
        if count > MAX_SAMPLES {
            return Err(SettingsError::TooMany { what, count });
        }
        if count > 0 && !self.environment_pattern.supports(count) {
            return Err(SettingsError::GridNotSquare { what, count });
        }
        if self.max_depth > MAX_DEPTH {
            return Err(SettingsError::Depth(self.max_depth));
        }
        if let Some(n) = self.threads.filter(|n| !(1..=MAX_THREADS).contains(n)) {
            return Err(SettingsError::Threads(n));
        }
        Ok(())
    }
}

/// A window of pixels, half-open: columns `x0..x1`, rows `y0..y1` from the top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Crop {
    /// The window's width and height.
    pub fn size(&self) -> UVec2 {
        UVec2::new(self.x1 - self.x0, self.y1 - self.y0)
    }

    /// The window, if it is non-empty and lies inside an image of `size`.
    pub(crate) fn check(self, size: UVec2) -> Result<Crop, SettingsError> {
        if self.x0 < self.x1 && self.y0 < self.y1 && self.x1 <= size.x && self.y1 <= size.y {
            Ok(self)
        } else {
            Err(SettingsError::Crop { crop: self, size })
        }
    }
}
