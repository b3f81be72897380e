use crate::sampling::{DimensionPair, SamplePattern, MAX_JOINT};
use crate::settings::RenderSettings;
use crate::trace::Shadow;
use crate::Scene;
use glint_geometry::{reflect_differential, spawn_ray, Hit, Ray, RayDifferential};
use glint_lighting::{AreaSampling, EnvironmentLight, EnvironmentSampling, Light, ShadingModel};

/// How far from the point it was found for a culling serves, as a fraction of
/// the point's distance to the light: a pixel's samples on one surface then
/// share one (a pixel spans about a thousandth of its distance from the camera
/// at 512², so a hundredth covers it with room), at the price of faces
/// widened by that much.
pub(crate) const CULL_REACH: f32 = 0.01;

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

/// Which Sobol dimension pair each of a shading point's 2D samples reads. At the
/// camera ray's hit, the first light-like sample (area lights in scene order,
/// then the environment) that takes one sample per camera sample reads the
/// pixel's own sequence, dimensions 2 and 3 ([`DimensionPair::Joint`]):
/// stratified together with the pixel position,
/// which lowers the error of a pixel's soft shadows (measured on the Cornell
/// box's floor: about half the relative MSE at 256 samples, and a steeper
/// convergence slope, than independent pairs). Every other sample keeps its own
/// sequence.
pub(crate) struct PairAllocation {
    depth: u32,
    next_joint: u32,
}

impl PairAllocation {
    pub(crate) fn new(depth: u32) -> Self {
        Self {
            depth,
            next_joint: 1,
        }
    }

    /// The pair for a sample that would otherwise read `own`, taking
    /// `per_sample` points per camera sample.
    #[inline]
    pub(crate) fn take(&mut self, own: DimensionPair, per_sample: u32) -> DimensionPair {
        if self.depth == 0 && per_sample == 1 && self.next_joint <= MAX_JOINT {
            self.next_joint += 1;
            DimensionPair::Joint {
                k: self.next_joint - 1,
            }
        } else {
            own
        }
    }
}

/// The ray `ray` reflects into at `hit` by a perfect mirror, and its
/// differentials ([`reflect_differential`]), leaving from an origin offset
/// to its side ([`spawn_ray`]).
pub(crate) fn mirror_ray(hit: &Hit, ray: &Ray, diff: &RayDifferential) -> (Ray, RayDifferential) {
    let surface = hit.differentials(diff);
    let (wi, reflected_diff) = reflect_differential(hit, ray.direction, diff, &surface);
    (spawn_ray(hit, wi), reflected_diff)
}

/// The nearest object blocking `shadow` before `t_max`, as a tracer reports
/// it (the integrator itself only asks whether anything does). A closest-hit
/// query: call it in a tracer's hook only.
pub(crate) fn blocker(scene: &Scene, shadow: &Ray, t_max: f32) -> Shadow {
    match scene.shapes.closest_hit(shadow, t_max) {
        Some(hit) => Shadow::Blocked {
            object: hit.shape,
            t: hit.t,
        },
        // Counted as blocked by a test the closest-hit query rounds differently.
        None => Shadow::Blocked {
            object: u32::MAX,
            t: f32::NAN,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_single_sample_at_the_camera_hit_reads_the_joint_pair() {
        let light = |light| DimensionPair::Light { light, depth: 0 };
        let environment = DimensionPair::Environment { depth: 0 };
        // One sample each at the camera ray's hit: the first light-like one is joint.
        let mut pairs = PairAllocation::new(0);
        assert_eq!(pairs.take(light(1), 1), DimensionPair::Joint { k: 1 });
        assert_eq!(pairs.take(light(2), 1), light(2));
        assert_eq!(pairs.take(environment, 1), environment);
        // Without area lights, the environment takes it.
        assert_eq!(
            PairAllocation::new(0).take(environment, 1),
            DimensionPair::Joint { k: 1 }
        );
        // Several samples per camera sample, or a reflection's hit: their own.
        assert_eq!(PairAllocation::new(0).take(light(0), 4), light(0));
        let deeper = DimensionPair::Light { light: 0, depth: 1 };
        assert_eq!(PairAllocation::new(1).take(deeper, 1), deeper);
    }
}
