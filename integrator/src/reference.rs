//! The integrator one ray at a time: the reference the camera-sample lanes
//! ([`crate::direct`]) are tested against, bit for bit, radiance and
//! counts, in test builds only. A render, `glint explain` and
//! [`DirectIntegrator::li`] all take the lanes; this is the same integrator
//! written the plain way, sample after sample, each light and environment
//! sample through its own shadow ray, the course's report read line by line.

mod point;
#[cfg(test)]
mod tests;

use crate::context::SampleContext;
use crate::direct::wave::mirror_ray;
use crate::direct::PairAllocation;
use crate::mistakes::{
    invisible_light, mistaken_direction, mistaken_footprint, mistaken_hit, Mistake, Mistakes,
};
use crate::sampling::{DimensionPair, SamplePoints};
use crate::shading_point::ShadingPoint;
use crate::texture_lookup::texture_footprint;
use crate::{DirectIntegrator, Scene, SurfaceKind};
use glam::Vec3;
use glint_geometry::{spawn_ray, Hit, Occluders, Ray, RayDifferential, RayTarget};
use glint_lighting::{
    AreaLight, EnvironmentSampling, Light, PhongMaterial, ShadingModel, SphereLight,
};

impl DirectIntegrator {
    /// Radiance arriving along `ray` (a camera ray, or a reflection ray `depth`
    /// reflections deep), whose footprint is given by the ray differentials `diff`,
    /// one ray at a time: the scalar reference the lanes are tested against.
    /// Light and environment samples come from the camera sample `ctx` was
    /// started on ([`SampleContext::begin_sample`]).
    pub(crate) fn li_one_ray(
        &self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let hit = scene.shapes.closest_hit(ray, f32::INFINITY);
        self.li_at(scene, ray, diff, hit, depth, ctx)
    }

    /// [`Self::li_one_ray`] for a ray whose closest hit is already found:
    /// `hit`, or `None` for a miss.
    pub(crate) fn li_at(
        &self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        hit: Option<Hit>,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let Some(hit) = hit else {
            return self.environment_seen(scene, ray, diff, ctx);
        };
        if invisible_light(scene, &hit, ctx.mistakes) {
            let through = spawn_ray(&hit, ray.direction);
            return self.li_one_ray(scene, &through, diff, depth, ctx);
        }
        let material = match scene.surface_of(&hit) {
            SurfaceKind::Emitter(light) => return light.emitted(),
            SurfaceKind::Material(m) => m,
        };
        let r = material.reflectivity;
        let at = SurfaceHit {
            hit: &hit,
            material,
            ray,
            diff,
        };
        let local = if material.has_local_shading() {
            self.local_shading(scene, &at, depth, ctx)
        } else {
            Vec3::ZERO
        };
        let mirror = if r > 0.0 && depth < self.max_depth {
            self.mirror_reflection(scene, &at, depth, ctx)
        } else {
            Vec3::ZERO
        };
        (1.0 - r) * local + r * mirror
    }

    /// The shapes that may block `point`'s shadow rays to area light `index`:
    /// every shape but its own and the light's flat surfaces
    /// ([`ShapeList::occluders_but`](glint_geometry::ShapeList::occluders_but));
    /// its own too, with [`Mistake::NoShadowOffset`].
    fn occluders(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        mistakes: Mistakes,
    ) -> Occluders {
        let light = scene.light_objects[index];
        let own = match mistakes.has(Mistake::NoShadowOffset) {
            true => light,
            false => point.hit.shape,
        };
        (scene.shapes).occluders_but([own, light])
    }

    /// The environment's radiance along a ray that hits nothing (black without one).
    fn environment_seen(
        &self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let Some(env) = &scene.environment else {
            return Vec3::ZERO;
        };
        ctx.counters.environment_lookups += 1;
        // Physical shading reads the map unfiltered: the mean of a
        // pixel's samples is then an unbiased estimate of the
        // radiance over its footprint, where a map prefiltered over
        // each ray's footprint is blurred twice (measured against
        // Mitsuba 3: a chrome sphere's rim came out 16% too bright
        // under the studio map's small, bright lamps).
        let width = match scene.shading {
            ShadingModel::Phong => diff.angular_width(ray.direction),
            ShadingModel::Physical => 0.0,
        };
        let direction = mistaken_direction(env, ray.direction.normalize(), ctx.mistakes);
        env.radiance(direction, width)
    }

    /// The light reflected at `hit` by its material (ambient, lights and
    /// environment), its textures read over the ray's footprint.
    fn local_shading(
        &self,
        scene: &Scene,
        at: &SurfaceHit,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        if at.material.uses_footprint() {
            ctx.counters.footprints += 1;
        }
        let hit = mistaken_hit(scene, at.hit, at.ray, ctx.mistakes);
        let tc = texture_footprint(scene, at.material, (&hit, depth), at.ray, at.diff);
        let tc = mistaken_footprint(at.material, tc, ctx.mistakes);
        if ctx.detailed {
            ctx.textures.record(at.material, &tc);
        }
        let mut point = ShadingPoint::new(&hit, at.material, at.ray, &tc);
        point.mistaken(scene, ctx.mistakes);
        match scene.shading {
            ShadingModel::Phong => self.shade(scene, &point, depth, ctx),
            ShadingModel::Physical => self.shade_physical(scene, &point, depth, ctx),
        }
    }

    /// The radiance a mirror at `hit` reflects towards the ray, tinted: the
    /// reflected ray followed one level deeper, with its differentials.
    fn mirror_reflection(
        &self,
        scene: &Scene,
        at: &SurfaceHit,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let (reflected, reflected_diff) = mirror_ray(at.hit, at.ray, at.diff);
        ctx.counters.reflection_rays += 1;
        at.material.mirror_tint
            * self.li_one_ray(scene, &reflected, &reflected_diff, depth + 1, ctx)
    }

    /// The local shading of `point`, `depth` reflections deep: ambient, the
    /// lights and the environment.
    fn shade(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        self.shade_with(
            scene,
            point,
            depth,
            ctx,
            |index, light, pairs, ctx| match light {
                Light::Point(p) => {
                    ctx.counters.point_light_samples += 1;
                    let target = RayTarget::exact(p.position);
                    let reflected =
                        point.unoccluded_reflection(scene, &target, &Occluders::ALL, ctx);
                    p.color * reflected
                }
                Light::Area(area) => {
                    let pair = self.light_pair(pairs, index, depth);
                    self.area_light(scene, point, index, area, pair, ctx)
                }
                // The course's model has no sphere lights: the scene file
                // accepts them under physical shading only.
                Light::Sphere(_) => Vec3::ZERO,
            },
        )
    }

    /// What both shading models share: `ambient · kd`, plus what each light
    /// adds (`light_term(index, light, pairs, ctx)`, in scene order, taking
    /// its dimension pair from `pairs` if it samples), plus the environment.
    pub(crate) fn shade_with(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        depth: u32,
        ctx: &mut SampleContext,
        mut light_term: impl FnMut(usize, &Light, &mut PairAllocation, &mut SampleContext) -> Vec3,
    ) -> Vec3 {
        let mut radiance = match ctx.mistakes.has(Mistake::AmbientWithoutKd) {
            true => scene.ambient,
            false => scene.ambient * point.kd,
        };
        let mut pairs = PairAllocation::new(depth);
        for (index, light) in scene.lights.iter().enumerate() {
            radiance += light_term(index, light, &mut pairs, ctx);
        }
        radiance += self.environment_term(scene, point, &mut pairs, depth, ctx);
        radiance
    }

    /// Light `pair`'s points for this camera sample, in the buffer taken from
    /// `ctx.light_points` (the caller puts it back).
    #[inline]
    pub(crate) fn draw_light_points(
        &self,
        pair: DimensionPair,
        ctx: &mut SampleContext,
    ) -> SamplePoints {
        let mut samples = std::mem::take(&mut ctx.light_points);
        ctx.fill_points(self.light_pattern, pair, &mut samples);
        samples
    }

    /// The environment's light at `point` (zero without environment samples),
    /// its sample points taken from `pairs`.
    pub(crate) fn environment_term(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        pairs: &mut PairAllocation,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        if self.environment_samples == 0 || scene.environment.is_none() {
            return Vec3::ZERO;
        }
        let pair = pairs.take(
            DimensionPair::Environment { depth },
            self.environment_samples,
        );
        self.environment_light(scene, point, pair, ctx)
    }

    /// The average over the light's samples (the dimension pair `pair` of the
    /// Sobol pattern) of the Phong reflection of each visible sample, times the
    /// light's color.
    fn area_light(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        light: &AreaLight,
        pair: DimensionPair,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        if ctx.mistakes.has(Mistake::LightBlocksItself) {
            return Vec3::ZERO;
        }
        let samples = self.draw_light_points(pair, ctx);
        let occluders = self.occluders(scene, point, index, ctx.mistakes);
        ctx.counters.light_samples += samples.len() as u64;
        let sum = point.area_light_sum(scene, light, &samples, &occluders, ctx);
        ctx.light_points = samples;
        light.color * sum / self.light_samples as f32
    }

    /// Monte Carlo estimate of `∫ L_env(ω)·V(ω)·f(ω)·cos θ dω` with directions
    /// importance-sampled from the environment (the points of
    /// `environment_pattern` over [0, 1)² mapped to directions), for a shading
    /// point `depth` reflections deep.
    pub(crate) fn environment_light(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        pair: DimensionPair,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let Some(env) = &scene.environment else {
            return Vec3::ZERO;
        };
        ctx.counters.environment_samples += u64::from(self.environment_samples);
        let mut sum = Vec3::ZERO;
        let mut samples = std::mem::take(&mut ctx.environment_points);
        ctx.fill_points(self.environment_pattern, pair, &mut samples);
        for u in samples.iter() {
            let mut s = match self.environment_sampling {
                EnvironmentSampling::Luminance => env.sample(point.n, u),
                EnvironmentSampling::Cosine => env.sample_cosine(point.n, u),
            };
            if !ctx.mistakes.is_empty() {
                // A mistaken map's sample: the right map's, moved by the
                // mistake's involution, or the cosine sample's radiance
                // read where the mistaken tracer reads it.
                let moved = mistaken_direction(env, s.direction, ctx.mistakes);
                match self.environment_sampling {
                    EnvironmentSampling::Luminance => s.direction = moved,
                    EnvironmentSampling::Cosine => s.radiance = env.radiance(moved, 0.0),
                }
            }
            sum += point.environment_sample(scene, &s, ctx);
        }
        ctx.environment_points = samples;
        sum / self.environment_samples as f32
    }

    /// The local shading of `point` in physical units, `depth` reflections deep.
    pub(crate) fn shade_physical(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        self.shade_with(
            scene,
            point,
            depth,
            ctx,
            |index, light, pairs, ctx| match light {
                Light::Point(p) => point.point_light(scene, p, ctx),
                Light::Area(area) => {
                    let pair = self.light_pair(pairs, index, depth);
                    self.physical_area_light(scene, point, index, area, pair, depth, ctx)
                }
                Light::Sphere(sphere) => {
                    let pair = self.light_pair(pairs, index, depth);
                    self.physical_sphere_light(scene, point, index, sphere, pair, depth, ctx)
                }
            },
        )
    }

    /// The light `light` (at `index` of the scene's lights) reflects at
    /// `point`: light samples from `pair`, and on a glossy material as many
    /// specular-lobe samples, combined by the power heuristic.
    #[allow(clippy::too_many_arguments)]
    fn physical_area_light(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        light: &AreaLight,
        pair: DimensionPair,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let x = point.hit.point;
        let n = self.light_samples;
        ctx.counters.light_samples += u64::from(n);
        // The light is flat: a point behind it is behind every point of it.
        if !light.illuminates(light.surface().center(), x) {
            ctx.counters.light_skips.behind_light += u64::from(n);
            return Vec3::ZERO;
        }
        let sampler = light.sampler(x, self.area_sampling);
        let mis = self.mis && point.has_specular;
        let samples = self.draw_light_points(pair, ctx);
        let occluders = self.occluders(scene, point, index, ctx.mistakes);
        let mut sum = Vec3::ZERO;
        for u in samples.iter() {
            let s = sampler.sample(u);
            let target = light.shadow_target(s.point);
            sum += point.light_sample(scene, &target, s.pdf, mis, &occluders, ctx);
        }
        ctx.light_points = samples;
        if mis {
            sum += self.lobe_samples(scene, point, index, depth, |y| sampler.pdf(y), ctx);
        }
        light.color * sum / n as f32
    }

    /// The spherical light `light` (at `index` of the scene's lights) reflects
    /// at `point`: directions uniform over its cone, and on a glossy material
    /// as many specular-lobe samples, combined by the power heuristic.
    #[allow(clippy::too_many_arguments)]
    fn physical_sphere_light(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        light: &SphereLight,
        pair: DimensionPair,
        depth: u32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let x = point.hit.point;
        let n = self.light_samples;
        ctx.counters.light_samples += u64::from(n);
        let pdf = light.pdf(x);
        if pdf == 0.0 {
            // Inside the sphere: it lights nothing there.
            ctx.counters.light_skips.behind_light += u64::from(n);
            return Vec3::ZERO;
        }
        let mis = self.mis && point.has_specular;
        let samples = self.draw_light_points(pair, ctx);
        let mut sum = Vec3::ZERO;
        for u in samples.iter() {
            match light.sample(x, u) {
                Some(s) => {
                    sum += point.light_sample(scene, &s.target, s.pdf, mis, &Occluders::ALL, ctx)
                }
                None => ctx.counters.light_skips.zero_density += 1,
            }
        }
        ctx.light_points = samples;
        if mis {
            sum += self.lobe_samples(scene, point, index, depth, |_| pdf, ctx);
        }
        light.color * sum / n as f32
    }

    /// The sum over `light_samples` directions drawn from `point`'s specular
    /// lobe of [`ShadingPoint::lobe_sample`] towards the light at `index`,
    /// whose own sampling has density `light_pdf(y)` towards its point `y`.
    fn lobe_samples(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        depth: u32,
        light_pdf: impl Fn(Vec3) -> f32,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let pair = DimensionPair::Brdf {
            light: index as u32,
            depth,
        };
        let samples = self.draw_light_points(pair, ctx);
        ctx.counters.lobe_samples += samples.len() as u64;
        let object = scene.light_objects[index];
        let mut sum = Vec3::ZERO;
        for u in samples.iter() {
            match point.material.sample_specular(point.n, point.v, u) {
                Some(l) => sum += point.lobe_sample(scene, &light_pdf, object, l, ctx),
                None => ctx.counters.lobe_skips.zero_density += 1,
            }
        }
        ctx.light_points = samples;
        sum
    }
}

/// A ray's hit on a material, with what shading it reads: the ray and its
/// differentials.
#[derive(Clone, Copy)]
struct SurfaceHit<'a> {
    hit: &'a Hit,
    material: &'a PhongMaterial,
    ray: &'a Ray,
    diff: &'a RayDifferential,
}
