//! The `[render]` table as render settings, and the `[regions]` table.

use crate::error::Problem;
use crate::format::{RenderTable, SceneFile};
use crate::values::Pattern;
use glint_integrator::{RenderSettings, SampleCount, SettingsError};
use toml::Spanned;

pub(super) fn settings(render: &RenderTable) -> Result<RenderSettings, Problem> {
    let settings = RenderSettings {
        spp: render.spp.get_ref().0,
        pixel_pattern: render.pixel_sampler.get_ref().0,
        light_samples: render.light_samples.get_ref().0,
        light_pattern: render.light_sampler.get_ref().0,
        seed: render.seed,
        threads: None,
        aov: None,
        max_depth: *render.max_depth.get_ref(),
        environment_samples: *render.environment_samples.get_ref(),
        environment_pattern: render.environment_sampler.get_ref().0,
        environment_sampling: render.environment_sampling.0,
        stats: false,
        area_sampling: render.area_sampling.0,
        mis: render.mis,
    };
    settings.validate().map_err(|e| {
        // Point at the count if the file set it, else at its sampler.
        fn at<T>(count: &Spanned<T>, sampler: &Spanned<Pattern>) -> std::ops::Range<usize> {
            if count.span().is_empty() {
                sampler.span()
            } else {
                count.span()
            }
        }
        let (field, span) = match &e {
            SettingsError::Zero { what }
            | SettingsError::TooMany { what, .. }
            | SettingsError::GridNotSquare { what, .. } => match what {
                SampleCount::PerPixel => ("render.spp", at(&render.spp, &render.pixel_sampler)),
                SampleCount::PerLight => (
                    "render.light_samples",
                    at(&render.light_samples, &render.light_sampler),
                ),
                SampleCount::PerEnvironment => (
                    "render.environment_samples",
                    at(&render.environment_samples, &render.environment_sampler),
                ),
            },
            SettingsError::Depth(_) => ("render.max_depth", render.max_depth.span()),
            // The file sets no thread count, partial render or crop, so these
            // cannot come from it.
            SettingsError::Threads(_)
            | SettingsError::ThreadPool(_)
            | SettingsError::ResumeResolution { .. }
            | SettingsError::Crop { .. } => ("render", 0..0),
        };
        Problem::new(span, field, e.to_string())
    })?;
    Ok(settings)
}

/// The `[regions]` table: each a non-empty rectangle inside the render resolution.
pub(super) fn regions(file: &SceneFile) -> Result<Vec<(String, [u32; 4])>, Problem> {
    let size = file.render.resolution.0;
    file.regions
        .iter()
        .map(|(name, spanned)| {
            let [x0, y0, x1, y1] = spanned.get_ref().0;
            if x0 >= x1 || y0 >= y1 || x1 > size.x || y1 > size.y {
                return Err(Problem::new(
                    spanned.span(),
                    format!("regions.{name}"),
                    format!(
                        "expected [x0, y0, x1, y1] with x0 < x1 <= {} and y0 < y1 <= {} (pixels of the {}x{} render, x1 and y1 excluded), got [{x0}, {y0}, {x1}, {y1}]",
                        size.x, size.y, size.x, size.y
                    ),
                ));
            }
            Ok((name.clone(), [x0, y0, x1, y1]))
        })
        .collect()
}
