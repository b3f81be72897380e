//! The direct-lighting integrator: the radiance of camera samples, shaded
//! [`LANES`] at once.
//!
//! The route from a camera sample to its radiance is seven calls, one file a
//! step (pbrt-v4's `Render` → `EvaluatePixelSample` → `Li` → `SampleLd`, in
//! lanes):
//!
//! 1. `render_rows` (`render.rs`, a tile's rows) →
//!    `PixelRenderer::pixel` (its pixel's chunks of [`LANES`] samples) →
//!    `chunk_values` (their camera rays and closest hits, the first [`Wave`]);
//! 2. → [`DirectIntegrator::li_wave`] (`wave.rs`): misses see the
//!    environment, emitters give their radiance, surfaces get their shading
//!    points (ambient included) and mirrors reflect into the next wave;
//! 3. → `with_direct_lighting` (`shade.rs`): each light's term and the
//!    environment's, in the order the one-ray integrator adds them;
//! 4. → `area_light_term`: a light's N samples, each lane's drawn where its
//!    camera sample alone draws them (`points.rs`) →
//!    `ShadedLanes::area_light` (`shaded_lanes.rs`, the points set up once
//!    for all samples, their reflectances from `surfaces.rs`): one sample's
//!    light point and Phong reflection in lanes →
//!    `ShadedLanes::unoccluded`: its shadow rays, traced as one batch.
//!
//! [`DirectIntegrator::li`] (one ray) enters the same route at step 2, in one
//! lane. `events.rs` shows each step to a tracer (`glint explain`);
//! `tests.rs` holds each lane to the integrator one ray at a time.
//!
//! The lanes are the camera samples: the [`LANES`] samples of a pixel (or,
//! for pixels of fewer samples, the runs of samples of consecutive pixels a
//! [`LaneSamples`] names) that
//! [`glint_geometry::ShapeList::closest_primitives_lanes`] found the hits of
//! together are shaded together too. Their surface points, reflectances and
//! shadow-ray origins are set up once; then, for each of a light's N samples in
//! turn, every lane's light point, direction, Phong reflection ([`PhongLanes`],
//! each lane with its own material) and horizon test run in SIMD lanes, the
//! shadow rays from as many origins are traced as one batch, and each lane adds
//! its own sample to its own sum. With one sample per light (`--light-samples
//! 1`, the way Mitsuba's `direct` integrator is usually run) a shading point has
//! no light samples for [`crate::light_samples`]' lanes to batch; with more,
//! this is the wavefront form of the same sums.
//!
//! Every scene whose closest hits are found in lanes is shaded so, in
//! either shading model, whatever its light and environment patterns:
//! each lane takes its points as its camera sample alone takes them
//! (`LanePoints`), the lanes whose points come from their own streams
//! drawing only where `li_at` draws. Lanes on mirrors reflect their rays as
//! the next wave of lanes, one reflection deeper
//! ([`DirectIntegrator::li_wave`]), with their differentials where the scene
//! reads footprints; lanes not in a wave are masked, not traced apart.
//! Physical shading draws
//! each lane's light samples with its own point's sampler (by area or solid
//! angle) and takes them through the diffuse kernel a point's light samples
//! share ([`crate::physical::DiffusePoints`]), or on glossy points through
//! the BRDF with its lobe in lanes ([`PhongLanes::brdf_cos`]), weighted by
//! multiple importance against as many directions drawn from each lane's
//! lobe, whose rays are traced together ([`DirectIntegrator::lobe_sum`]); its
//! environment samples are drawn together across the lanes
//! ([`glint_lighting::EnvironmentLight::sample_each`]), and the lanes that
//! miss read the map. Textures
//! filtered over a footprint are looked up lane by lane, from each lane's ray
//! differentials. Every lane
//! repeats the scalar path's operations in its order, and its random numbers
//! come from its own camera sample's stream or its own points of its pixel's
//! Sobol sequence, so each sample's radiance and the shading counts are those
//! of `li_at`, the integrator one ray at a time that the tests hold the
//! lanes to (`reference.rs`, in test builds), bit for bit.

mod events;
mod points;
mod shade;
mod shaded_lanes;
mod surfaces;
#[cfg(test)]
mod tests;
pub(crate) mod wave;

pub(crate) use points::PairAllocation;
pub(crate) use wave::Wave;

use crate::context::SampleContext;
use crate::sampling::LaneSamples;
use crate::trace::Tracer;
use glam::Vec3;
use glint_geometry::lanes::LANES;
use glint_geometry::RayLanes;

use crate::sampling::{DimensionPair, SamplePattern};
use crate::settings::RenderSettings;
use crate::Scene;
use glint_geometry::{Ray, RayDifferential};
use glint_lighting::{AreaSampling, EnvironmentLight, EnvironmentSampling, Light, ShadingModel};

/// The direct-lighting integrator of the course report (section 2.5), with the
/// environment and mirror reflections of section 2.7.
///
/// For a ray: a miss sees the environment (black without one); a first hit on a
/// light's front face is the light's color; otherwise the hit point reflects
/// `ambient · kd`, plus for each light the Phong reflection of every unoccluded light
/// sample (one shadow ray per sample, the N samples of an area light averaged), plus
/// the environment's light through shadow rays towards importance-sampled directions;
/// a material with reflectivity `r` blends in `r` times the mirror reflection, traced
/// recursively up to `max_depth` reflections (beyond that, black).
#[derive(Clone, Copy, Debug)]
pub struct DirectIntegrator {
    pub light_samples: u32,
    pub light_pattern: SamplePattern,
    pub environment_samples: u32,
    pub environment_pattern: SamplePattern,
    pub environment_sampling: EnvironmentSampling,
    pub max_depth: u32,
    /// Physical shading: how area lights are sampled.
    pub area_sampling: AreaSampling,
    /// Physical shading: multiple importance sampling of glossy lobes.
    pub mis: bool,
}

impl DirectIntegrator {
    /// given by the ray differentials `diff` (read where the scene filters
    /// textures over footprints), for the camera sample `ctx` was started on
    /// ([`SampleContext::begin_sample`]): the render's own route, in one lane.
    pub fn li<T: Tracer>(
        &self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        let rays = RayLanes::new([*ray; LANES]);
        let diffs = [*diff; LANES];
        let closest = scene.shapes.closest_lanes(&rays, 1);
        let samples = LaneSamples::of_pixel(ctx.sample);
        let footprints = scene.needs_differentials().then_some(&diffs);
        let wave = Wave::first(&rays, footprints, &closest, 1);
        (self.li_wave(scene, wave, &mut self.lane_streams(&samples), ctx)).lane(0)
    }

    /// The integrator `settings` describe (their sample counts, patterns and
    /// depth; the rest is the render loop's).
    pub fn new(settings: &RenderSettings) -> Self {
        Self {
            light_samples: settings.light_samples,
            light_pattern: settings.light_pattern,
            environment_samples: settings.environment_samples,
            environment_pattern: settings.environment_pattern,
            environment_sampling: settings.environment_sampling,
            max_depth: settings.max_depth,
            area_sampling: settings.area_sampling,
            mis: settings.mis,
        }
    }

    /// The dimension pair of light `index`'s samples at a point `depth`
    /// reflections deep.
    #[inline]
    pub(crate) fn light_pair(
        &self,
        pairs: &mut PairAllocation,
        index: usize,
        depth: u32,
    ) -> DimensionPair {
        let own = DimensionPair::Light {
            light: index as u32,
            depth,
        };
        pairs.take(own, self.light_samples)
    }

    /// Whether the scene's environment samples are drawn from its map, by
    /// luminance, so that they do not depend on the shading normal.
    pub(crate) fn samples_environment_by_map(&self, scene: &Scene) -> bool {
        self.environment_sampling == EnvironmentSampling::Luminance
            && (scene.environment.as_ref()).is_some_and(EnvironmentLight::is_sampled_by_map)
    }

    /// The dimension pair of the environment's samples at a point `depth`
    /// reflections deep: the one `shade_with` gives it after the lights that
    /// sample take theirs.
    pub(crate) fn environment_pair(&self, scene: &Scene, depth: u32) -> DimensionPair {
        let mut pairs = PairAllocation::new(depth);
        for (index, light) in scene.lights.iter().enumerate() {
            let samples = match light {
                Light::Area(_) => true,
                Light::Sphere(_) => scene.shading == ShadingModel::Physical,
                Light::Point(_) => false,
            };
            if samples {
                self.light_pair(&mut pairs, index, depth);
            }
        }
        let own = DimensionPair::Environment { depth };
        pairs.take(own, self.environment_samples)
    }
}
