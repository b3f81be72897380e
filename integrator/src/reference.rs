//! The integrator one ray at a time: the reference the camera-sample lanes
//! ([`crate::direct`]) are tested against, bit for bit, radiance and
//! counts, in test builds only. A render, `glint explain` and
//! [`DirectIntegrator::li`] all take the lanes; this is the same integrator
//! written the plain way, sample after sample, each light and environment
//! sample through its own shadow ray, the course's report read line by line.

use crate::context::SampleContext;
use crate::direct::wave::mirror_ray;
use crate::direct::PairAllocation;
use crate::light_samples::{count_lanes, LightSampleLanes};
use crate::physical::{power_heuristic, DiffusePoints};
use crate::sampling::{DimensionPair, PointChunk, SamplePoints};
use crate::shading_point::ShadingPoint;
use crate::texture_lookup::texture_footprint;
use crate::{DirectIntegrator, Scene, ShadingCounters, Skips, SurfaceKind};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes, LANES};
use glint_geometry::{
    offset_ray_origin, spawn_ray, spawn_ray_to, Hit, Occluders, Ray, RayDifferential, RayLanes,
    RayTarget,
};
use glint_lighting::{
    AreaLight, AreaLightSampler, EnvironmentLight, EnvironmentSample, EnvironmentSampling, Light,
    PhongMaterial, PointLight, ShadingModel, SphereLight,
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
    /// ([`ShapeList::occluders_but`](glint_geometry::ShapeList::occluders_but)).
    fn occluders(&self, scene: &Scene, point: &ShadingPoint, index: usize) -> Occluders {
        (scene.shapes).occluders_but([point.hit.shape, scene.light_objects[index]])
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
        env.radiance(ray.direction.normalize(), width)
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
        let tc = texture_footprint(scene, at.material, (at.hit, depth), at.ray, at.diff);
        if ctx.detailed {
            ctx.textures.record(at.material, &tc);
        }
        let point = ShadingPoint::new(at.hit, at.material, at.ray, &tc);
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
        let mut radiance = scene.ambient * point.kd;
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
        let samples = self.draw_light_points(pair, ctx);
        let occluders = self.occluders(scene, point, index);
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
        let n = self.environment_samples as usize;
        ctx.counters.environment_samples += n as u64;
        let one_by_one = n < LANES_FROM_SAMPLES;
        let mut sum = Vec3::ZERO;
        let mut samples = std::mem::take(&mut ctx.environment_points);
        ctx.fill_points(self.environment_pattern, pair, &mut samples);
        for chunk in samples.chunks() {
            let drawn = drawn_together(env, self.environment_sampling, point.n, &chunk);
            let drawn = &drawn[..chunk.len];
            point.add_environment_samples(scene, drawn, one_by_one, &mut sum, ctx);
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
        let occluders = self.occluders(scene, point, index);
        let mut sum = if samples.len() < LANES_FROM_SAMPLES {
            let mut sum = Vec3::ZERO;
            for u in samples.iter() {
                let s = sampler.sample(u);
                let target = light.shadow_target(s.point);
                sum += point.light_sample(scene, &target, s.pdf, mis, &occluders, ctx);
            }
            sum
        } else {
            point.light_samples_shadowed_in_lanes(
                scene, light, &sampler, &samples, mis, &occluders, ctx,
            )
        };
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

impl ShadingPoint<'_> {
    /// The origins of this point's shadow rays, for rays tested in lanes.
    /// Inlined: returned through memory, the lanes cost a store-forwarding stall.
    #[inline(always)]
    pub(crate) fn shadow_origins(&self) -> ShadowOrigins {
        let (point, error, normal) = (self.hit.point, self.hit.error, self.hit.geometric_normal);
        ShadowOrigins {
            front: Vec3Lanes::splat(offset_ray_origin(point, error, normal)),
            back: Vec3Lanes::splat(offset_ray_origin(point, error, -normal)),
            normal,
        }
    }

    /// An environment sample's value `L · f · cos θ / p` if unblocked, short
    /// of its shadow ray, or `None` (counted) where it needs no shadow ray.
    /// Counts the shadow ray it needs.
    fn environment_sample_unshadowed(
        &self,
        s: &EnvironmentSample,
        ctx: &mut SampleContext,
    ) -> Option<Vec3> {
        if s.pdf.is_nan() || s.pdf <= 0.0 || s.radiance == Vec3::ZERO {
            ctx.counters.environment_skips.zero_density += 1;
            return None;
        }
        if !self.above_surface(s.direction) {
            ctx.counters.environment_skips.below_surface += 1;
            return None;
        }
        let f = self.brdf_cos(s.direction, ctx);
        if f == Vec3::ZERO {
            ctx.counters.environment_skips.zero_brdf += 1;
            return None;
        }
        ctx.counters.environment_shadow_rays += 1;
        Some(s.radiance * f / s.pdf)
    }

    /// Adds to `sum` the values of the environment samples `drawn` (at most
    /// [`LANES`]) whose shadow rays are unblocked, in order: `one_by_one`,
    /// or each up to its shadow ray one by one and then their shadow rays
    /// tested together (the origins of `spawn_ray`, so the same answers and
    /// the same sum, bit for bit).
    fn add_environment_samples(
        &self,
        scene: &Scene,
        drawn: &[EnvironmentSample],
        one_by_one: bool,
        sum: &mut Vec3,
        ctx: &mut SampleContext,
    ) {
        if one_by_one {
            for s in drawn {
                let Some(value) = self.environment_sample_unshadowed(s, ctx) else {
                    continue;
                };
                let shadow_ray = spawn_ray(self.hit, s.direction);
                if !scene.shapes.any_hit(&shadow_ray, f32::INFINITY) {
                    *sum += value;
                }
            }
            return;
        }
        let mut values = [Vec3::ZERO; LANES];
        let mut directions = [self.hit.geometric_normal; LANES];
        let mut traced = 0u32;
        for (k, s) in drawn.iter().enumerate() {
            if let Some(value) = self.environment_sample_unshadowed(s, ctx) {
                (values[k], directions[k]) = (value, s.direction);
                traced |= 1 << k;
            }
        }
        let direction = Vec3Lanes::from_lanes(directions);
        let origin = self.shadow_origins().leaving_towards(&direction);
        let rays = RayLanes { origin, direction };
        let blocked = (scene.shapes).any_hits_among(&Occluders::ALL, &rays, f32::INFINITY, traced);
        for k in lanes::each_set(traced & !blocked) {
            *sum += values[k];
        }
    }

    /// The BRDF times the cosine for light from direction `l`: the specular
    /// lobe only where `ks` is nonzero.
    #[inline]
    pub(crate) fn brdf_cos(&self, l: Vec3, ctx: &mut SampleContext) -> Vec3 {
        if self.has_specular {
            ctx.counters.specular_lobes += 1;
        }
        self.f_cos(l)
    }

    /// Phong reflection towards `v` of a unit light at `target`, or zero if the
    /// light is behind the surface or a shadow ray finds it occluded (testing only
    /// `occluders`). The shadow ray is only traced when the light could contribute.
    pub(crate) fn unoccluded_reflection(
        &self,
        scene: &Scene,
        target: &RayTarget,
        occluders: &Occluders,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        // A direction of no length (the light's point is the shading point)
        // is not above the surface either: `ng · 0 > 0` is false.
        let l = (target.point - self.hit.point).normalize_or_zero();
        if !self.above_surface(l) {
            ctx.counters.light_skips.below_surface += 1;
            return Vec3::ZERO;
        }
        let reflected = if self.has_specular {
            ctx.counters.specular_lobes += 1;
            self.material.reflect(self.kd, self.ks, self.n, l, self.v)
        } else {
            self.material.reflect_diffuse(self.kd, self.n, l)
        };
        if reflected == Vec3::ZERO {
            ctx.counters.light_skips.zero_brdf += 1;
            return Vec3::ZERO;
        }
        let shadow = spawn_ray_to(self.hit, target);
        ctx.counters.light_shadow_rays += 1;
        if scene.shapes.any_hit_among(occluders, &shadow, 1.0) {
            Vec3::ZERO
        } else {
            reflected
        }
    }

    /// The sum over `samples` (coordinates on `light`) of the point's Phong
    /// reflection of each light point that shines on it and is not blocked
    /// (testing only `occluders`), before the light's colour and the average.
    pub(crate) fn area_light_sum(
        &self,
        scene: &Scene,
        light: &AreaLight,
        samples: &SamplePoints,
        occluders: &Occluders,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        if samples.len() < LANES_FROM_SAMPLES {
            return self.area_light_sum_one_by_one(scene, light, samples, occluders, ctx);
        }
        let point = self.hit.point;
        let origins = self.shadow_origins();
        let mut sum = Vec3::ZERO;
        let (receiver, ng) = (Vec3Lanes::splat(point), Vec3Lanes::splat(self.ng));
        for chunk in samples.chunks() {
            let used = chunk.used();
            let reflect = |l: &Vec3Lanes| {
                let (kd, ks, n, v) = (self.kd, self.ks, self.n, self.v);
                self.material
                    .reflect_lanes(kd, ks, n, l, v, self.has_specular)
            };
            let u = (chunk.lanes.x, chunk.lanes.y);
            let s = LightSampleLanes::new(light, u, &receiver, &ng, used, reflect);
            self.count(ctx, used, s.lit, s.shaded, s.traced);
            let origin = origins.leaving_towards(&s.towards);
            let shadow_rays = RayLanes {
                origin,
                direction: light.shadow_ends(&s.position) - origin,
            };
            let blocked = scene
                .shapes
                .any_hits_among(occluders, &shadow_rays, 1.0, s.traced);
            let visible = s.traced & !blocked;
            for k in 0..chunk.len {
                if s.lit >> k & 1 == 1 {
                    sum += if visible >> k & 1 == 1 {
                        s.reflected.lane(k)
                    } else {
                        Vec3::ZERO
                    };
                }
            }
        }
        sum
    }

    /// Adds one chunk's lanes to the counts ([`count_lanes`]).
    fn count(&self, ctx: &mut SampleContext, used: u32, lit: u32, shaded: u32, traced: u32) {
        let specular = if self.has_specular { u32::MAX } else { 0 };
        count_lanes(&mut ctx.counters, used, lit, shaded, traced, specular);
    }

    /// [`Self::area_light_sum`] one sample at a time.
    pub(crate) fn area_light_sum_one_by_one(
        &self,
        scene: &Scene,
        light: &AreaLight,
        samples: &SamplePoints,
        occluders: &Occluders,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for u in samples.iter() {
            let position = light.sample_point(u);
            if light.illuminates(position, self.hit.point) {
                let target = light.shadow_target(position);
                sum += self.unoccluded_reflection(scene, &target, occluders, ctx);
            } else {
                ctx.counters.light_skips.behind_light += 1;
            }
        }
        sum
    }

    /// `f · cos θ · I / r²` of a point light, or zero behind the surface or in
    /// shadow.
    fn point_light(&self, scene: &Scene, light: &PointLight, ctx: &mut SampleContext) -> Vec3 {
        ctx.counters.point_light_samples += 1;
        let d = light.position - self.hit.point;
        let distance2 = d.length_squared();
        let Some(l) = d.try_normalize() else {
            // The light is at the point: no direction, counted as below the surface.
            ctx.counters.light_skips.below_surface += 1;
            return Vec3::ZERO;
        };
        let Some(f) = self.reflection_towards(l, light_skips, ctx) else {
            return Vec3::ZERO;
        };
        ctx.counters.light_shadow_rays += 1;
        let shadow = spawn_ray_to(self.hit, &RayTarget::exact(light.position));
        if scene.shapes.any_hit_among(&Occluders::ALL, &shadow, 1.0) {
            return Vec3::ZERO;
        }
        light.color * f / distance2
    }

    /// One light sample's `f · cos θ · V · w / p` towards the point
    /// `target` on a light, drawn with solid-angle density `pdf` (the shadow
    /// ray testing only `occluders`), `w` its power-heuristic weight against
    /// the specular lobe's density (1 without `mis`).
    fn light_sample(
        &self,
        scene: &Scene,
        target: &RayTarget,
        pdf: f32,
        mis: bool,
        occluders: &Occluders,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let Some(value) = self.light_sample_unshadowed(target, pdf, mis, ctx) else {
            return Vec3::ZERO;
        };
        let shadow = spawn_ray_to(self.hit, target);
        match scene.shapes.any_hit_among(occluders, &shadow, 1.0) {
            true => Vec3::ZERO,
            false => value,
        }
    }

    /// The sum of [`Self::light_sample`] over `samples` (coordinates on
    /// `light`, drawn by `sampler`), in order: each sample up to its shadow ray
    /// one by one, then the shadow rays of [`LANES`] samples tested together,
    /// as [`ShadingPoint::area_light_sum`] does (the same origins and ends, so
    /// the same answers and the same sum, bit for bit).
    #[allow(clippy::too_many_arguments)]
    fn light_samples_shadowed_in_lanes(
        &self,
        scene: &Scene,
        light: &AreaLight,
        sampler: &AreaLightSampler,
        samples: &SamplePoints,
        mis: bool,
        occluders: &Occluders,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let origins = self.shadow_origins();
        let mut sum = Vec3::ZERO;
        for chunk in samples.chunks() {
            let (position, values, traced) = if self.has_specular {
                self.unshadowed_one_by_one(light, sampler, &chunk, mis, ctx)
            } else {
                self.unshadowed_diffuse_lanes(sampler, &chunk, ctx)
            };
            let origin = origins.leaving_towards(&position.sub_splat(self.hit.point));
            let rays = RayLanes {
                origin,
                direction: light.shadow_ends(&position) - origin,
            };
            let visible = traced & !scene.shapes.any_hits_among(occluders, &rays, 1.0, traced);
            for (k, value) in values.iter().enumerate().take(chunk.len) {
                sum += if visible >> k & 1 == 1 {
                    *value
                } else {
                    Vec3::ZERO
                };
            }
        }
        sum
    }

    /// Up to [`LANES`] light samples short of their shadow rays, one by one
    /// ([`Self::light_sample_unshadowed`]): each lane's light point, its value
    /// if unblocked, and the lanes that need a shadow ray.
    fn unshadowed_one_by_one(
        &self,
        light: &AreaLight,
        sampler: &AreaLightSampler,
        chunk: &PointChunk,
        mis: bool,
        ctx: &mut SampleContext,
    ) -> (Vec3Lanes, [Vec3; LANES], u32) {
        let mut values = [Vec3::ZERO; LANES];
        let mut positions = [self.hit.point; LANES];
        let mut traced = 0u32;
        for (k, u) in chunk.iter().enumerate() {
            let s = sampler.sample(u);
            let target = light.shadow_target(s.point);
            if let Some(value) = self.light_sample_unshadowed(&target, s.pdf, mis, ctx) {
                (values[k], positions[k]) = (value, s.point);
                traced |= 1 << k;
            }
        }
        (Vec3Lanes::from_lanes(positions), values, traced)
    }

    /// [`Self::unshadowed_one_by_one`] for a diffuse point (no lobe, so no
    /// MIS), the direction, horizon test and `kd/π · cos θ / p` in lanes: each
    /// lane [`Self::light_sample_unshadowed`]'s value and counts, bit for bit.
    fn unshadowed_diffuse_lanes(
        &self,
        sampler: &AreaLightSampler,
        chunk: &PointChunk,
        ctx: &mut SampleContext,
    ) -> (Vec3Lanes, [Vec3; LANES], u32) {
        let mut positions = [self.hit.point; LANES];
        let mut pdfs = [0.0; LANES];
        for (k, u) in chunk.iter().enumerate() {
            let s = sampler.sample(u);
            (positions[k], pdfs[k]) = (s.point, s.pdf);
        }
        let (position, pdf) = (Vec3Lanes::from_lanes(positions), F32Lanes::new(pdfs));
        let at = DiffusePoints {
            point: &Vec3Lanes::splat(self.hit.point),
            ng: &Vec3Lanes::splat(self.ng),
            n: &Vec3Lanes::splat(self.n),
            kd: &Vec3Lanes::splat(self.kd),
        };
        let (value, reflects) = at.light_samples(&position, pdf, chunk.used(), &mut ctx.counters);
        let values = std::array::from_fn(|k| value.lane(k));
        (position, values, reflects)
    }

    /// [`Self::light_sample`] short of its shadow ray: the sample's value
    /// `f · cos θ · w / p` if unblocked, or `None` (counted) where it needs no
    /// shadow ray. Counts the shadow ray it needs.
    fn light_sample_unshadowed(
        &self,
        target: &RayTarget,
        pdf: f32,
        mis: bool,
        ctx: &mut SampleContext,
    ) -> Option<Vec3> {
        if !(pdf > 0.0 && pdf.is_finite()) {
            ctx.counters.light_skips.zero_density += 1;
            return None;
        }
        let Some(l) = (target.point - self.hit.point).try_normalize() else {
            // The light's point is the shading point: counted as below the surface.
            ctx.counters.light_skips.below_surface += 1;
            return None;
        };
        let f = self.reflection_towards(l, light_skips, ctx)?;
        ctx.counters.light_shadow_rays += 1;
        let weight = if mis {
            power_heuristic(pdf, self.material.specular_pdf(self.n, l, self.v))
        } else {
            1.0
        };
        Some(f * (weight / pdf))
    }

    /// One specular-lobe sample's `f · cos θ · V · w / p` towards the light
    /// whose surface is scene object `object` and whose light sampling draws
    /// the direction towards its point `y` with density `light_pdf(y)`: zero
    /// unless the ray from the point along `l` reaches that light first.
    fn lobe_sample(
        &self,
        scene: &Scene,
        light_pdf: &impl Fn(Vec3) -> f32,
        object: u32,
        l: Vec3,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let pdf = self.material.specular_pdf(self.n, l, self.v);
        if !(pdf > 0.0 && pdf.is_finite()) {
            ctx.counters.lobe_skips.zero_density += 1;
            return Vec3::ZERO;
        }
        let Some(f) = self.reflection_towards(l, lobe_skips, ctx) else {
            return Vec3::ZERO;
        };
        ctx.counters.brdf_rays += 1;
        let ray = spawn_ray(self.hit, l);
        // The light's surface is one-sided: a hit on it is a hit on its front.
        match scene.shapes.closest_hit(&ray, f32::INFINITY) {
            Some(hit) if hit.shape == object => {
                f * (power_heuristic(pdf, light_pdf(hit.point)) / pdf)
            }
            _ => Vec3::ZERO,
        }
    }

    /// `f(l, v) · cos θ` towards the unit direction `l`, or `None` where no
    /// ray need be traced: `l` below the geometric surface, or a zero BRDF,
    /// counted in the skips `skips` picks (a light's or a lobe's).
    fn reflection_towards(&self, l: Vec3, skips: SkipsOf, ctx: &mut SampleContext) -> Option<Vec3> {
        if !self.above_surface(l) {
            skips(&mut ctx.counters).below_surface += 1;
            return None;
        }
        let f = self.brdf_cos(l, ctx);
        if f == Vec3::ZERO {
            skips(&mut ctx.counters).zero_brdf += 1;
            return None;
        }
        Some(f)
    }
}

/// The origins of a shading point's shadow rays in lanes: its point offset
/// to either side of its surface, made once for all its samples.
pub(crate) struct ShadowOrigins {
    front: Vec3Lanes,
    back: Vec3Lanes,
    normal: Vec3,
}

/// The environment's samples at a chunk of points, about `normal`: drawn
/// together ([`EnvironmentLight::sample_each`]), each as it is drawn alone.
#[inline]
fn drawn_together(
    env: &EnvironmentLight,
    sampling: EnvironmentSampling,
    normal: Vec3,
    chunk: &PointChunk,
) -> [EnvironmentSample; LANES] {
    let mut points = [Vec2::ZERO; LANES];
    for (point, u) in points.iter_mut().zip(chunk.iter()) {
        *point = u;
    }
    if sampling == EnvironmentSampling::Luminance {
        return env.sample_each(normal, &points, chunk.len);
    }
    let u = (
        lanes::from_fn(|k| points[k].x),
        lanes::from_fn(|k| points[k].y),
    );
    let used = (1 << chunk.len) - 1;
    let (d, radiance, pdf) = env.sample_cosine_each(&Vec3Lanes::splat(normal), u, used);
    let pdf = pdf.to_array();
    lanes::array_from_fn(|k| EnvironmentSample {
        direction: d.lane(k),
        radiance: radiance.lane(k),
        pdf: pdf[k],
    })
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

/// From this many samples per light on, the samples are shaded in lanes; below
/// it, one by one (the same result: the lanes only cost more for one sample).
pub(crate) const LANES_FROM_SAMPLES: usize = 2;

/// Which of the counters' skips a sample's skip is counted in.
type SkipsOf = fn(&mut ShadingCounters) -> &mut Skips;

fn light_skips(c: &mut ShadingCounters) -> &mut Skips {
    &mut c.light_skips
}

fn lobe_skips(c: &mut ShadingCounters) -> &mut Skips {
    &mut c.lobe_skips
}

impl ShadowOrigins {
    /// Each lane's origin on the side of the surface its direction `towards`
    /// leaves on, as `spawn_ray` and `spawn_ray_to` choose it.
    #[inline]
    pub(crate) fn leaving_towards(&self, towards: &Vec3Lanes) -> Vec3Lanes {
        let from_back = lanes::lt(towards.dot_splat(self.normal), F32Lanes::ZERO);
        Vec3Lanes::select(from_back, &self.back, &self.front)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SceneBuilder, SurfaceKind};
    use glam::{UVec2, Vec2};
    use glint_camera::Camera;
    use glint_geometry::{Parallelogram, Ray, Sphere};
    use glint_lighting::{Light, PhongMaterial, SpecularLobe};
    use glint_texture::{TexCoord, Texture};

    /// A floor, a ceiling above the light (behind its one emitting side), a
    /// sphere between them and a one-sided light, in materials `material`.
    fn scene(material: PhongMaterial) -> crate::Scene {
        let mut b = SceneBuilder::new();
        let m = b.material(material);
        let floor = Parallelogram::new(
            Vec3::new(-4.0, 0.0, -6.0),
            Vec3::Z * 8.0,
            Vec3::X * 8.0,
            false,
        )
        .unwrap()
        .facing(Vec3::Y);
        let ceiling = Parallelogram::new(
            Vec3::new(-4.0, 4.0, -6.0),
            Vec3::X * 8.0,
            Vec3::Z * 8.0,
            false,
        )
        .unwrap()
        .facing(-Vec3::Y);
        b.shape(floor, m)
            .shape(ceiling, m)
            .shape(Sphere::new(Vec3::new(0.3, 1.0, -2.0), 0.6).unwrap(), m);
        let light = AreaLight::new(Vec3::new(0.0, 3.0, -2.0), Vec3::X, Vec3::Z, Vec3::ONE).unwrap();
        b.area_light(light.facing(-Vec3::Y));
        let camera = Camera::new(
            Vec3::new(0.0, 2.0, 4.0),
            Vec3::new(0.0, 1.0, -2.0),
            Vec3::Y,
            60.0,
            1.0,
            UVec2::new(8, 8),
        )
        .unwrap();
        b.build(camera).unwrap()
    }

    #[test]
    fn eight_lanes_give_the_one_by_one_sum_and_counts_bit_for_bit() {
        let materials = [
            PhongMaterial::new(Vec3::new(0.7, 0.4, 0.2), 16.0),
            PhongMaterial::new(Vec3::new(0.7, 0.4, 0.2), 7.5),
            PhongMaterial {
                lobe: SpecularLobe::BlinnPhong,
                ..PhongMaterial::new(Vec3::new(0.2, 0.4, 0.9), 40.0)
            },
            PhongMaterial {
                specular: Some(Texture::Constant(Vec3::ZERO)),
                ..PhongMaterial::new(Vec3::splat(0.5), 1.0)
            },
            // Black: every lane's reflection is zero, and no shadow ray is traced.
            PhongMaterial {
                specular: Some(Texture::Constant(Vec3::ZERO)),
                ..PhongMaterial::new(Vec3::ZERO, 1.0)
            },
        ];
        let mut rng = crate::sampling::pixel_rng(7, 0, 0);
        let mut uniform = || (rng.next_u32() >> 8) as f32 / (1 << 24) as f32;
        let mut compared = 0;
        let mut total = crate::ShadingCounters::default();
        for material in materials {
            let scene = scene(material);
            let Light::Area(light) = &scene.lights[0] else {
                unreachable!()
            };
            for _ in 0..60 {
                // Rays from inside the room towards the floor, ceiling and sphere.
                let origin = Vec3::new(
                    uniform() * 4.0 - 2.0,
                    0.5 + uniform() * 3.0,
                    uniform() * 2.0 - 3.0,
                );
                let direction = Vec3::new(uniform() - 0.5, uniform() * 2.0 - 1.0, uniform() - 0.5);
                let ray = Ray::new(origin, direction);
                let Some(hit) = scene.shapes.closest_hit(&ray, f32::INFINITY) else {
                    continue;
                };
                let SurfaceKind::Material(material) = scene.surface_of(&hit) else {
                    continue;
                };
                let point = ShadingPoint::new(&hit, material, &ray, &TexCoord::point(hit.uv));
                for n in [1usize, 2, 7, 8, 9, 16, 19] {
                    let mut points: Vec<Vec2> =
                        (0..n).map(|_| Vec2::new(uniform(), uniform())).collect();
                    points[0] = Vec2::ZERO; // a corner, exactly
                    let samples = SamplePoints::from_points(&points);
                    let culled = scene.shapes.occluders_towards(
                        hit.point,
                        0.0,
                        &light.surface().corners(),
                        [hit.shape, scene.light_objects[0]],
                    );
                    for occluders in [Occluders::ALL, culled] {
                        let mut lanes = SampleContext::new(0, 0);
                        let mut scalar = SampleContext::new(0, 0);
                        let a =
                            point.area_light_sum(&scene, light, &samples, &occluders, &mut lanes);
                        let b = point.area_light_sum_one_by_one(
                            &scene,
                            light,
                            &samples,
                            &occluders,
                            &mut scalar,
                        );
                        assert_eq!(
                            a.to_array().map(f32::to_bits),
                            b.to_array().map(f32::to_bits),
                            "{n} samples at {}",
                            hit.point
                        );
                        assert_eq!(
                            lanes.counters, scalar.counters,
                            "{n} samples at {}",
                            hit.point
                        );
                        compared += 1;
                        total += scalar.counters;
                    }
                }
            }
        }
        // Every branch was taken: lanes behind the light, below the horizon, with
        // zero reflection, and traced.
        assert!(compared > 1000, "only {compared} comparisons");
        assert!(total.light_skips.behind_light > 0, "{total:?}");
        assert!(total.light_skips.below_surface > 0, "{total:?}");
        assert!(total.light_skips.zero_brdf > 0, "{total:?}");
        assert!(total.light_shadow_rays > 0, "{total:?}");
    }
}
