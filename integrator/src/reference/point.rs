//! A shading point's samples in the reference: each light sample, lobe
//! sample and environment sample through its own shadow ray (in lanes from
//! [`LANES_FROM_SAMPLES`] samples on, to the same sums).

use crate::context::SampleContext;
use crate::light_samples::{count_lanes, LightSampleLanes};
use crate::physical::{power_heuristic, DiffusePoints};
use crate::sampling::{PointChunk, SamplePoints};
use crate::shading_point::ShadingPoint;
use crate::{Scene, ShadingCounters, Skips};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes, LANES};
use glint_geometry::{offset_ray_origin, spawn_ray, spawn_ray_to, Occluders, RayLanes, RayTarget};
use glint_lighting::{
    AreaLight, AreaLightSampler, EnvironmentLight, EnvironmentSample, EnvironmentSampling,
    PointLight,
};

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
    pub(super) fn environment_sample_unshadowed(
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
    pub(super) fn add_environment_samples(
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
    pub(super) fn count(
        &self,
        ctx: &mut SampleContext,
        used: u32,
        lit: u32,
        shaded: u32,
        traced: u32,
    ) {
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
    pub(super) fn point_light(
        &self,
        scene: &Scene,
        light: &PointLight,
        ctx: &mut SampleContext,
    ) -> Vec3 {
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
    pub(super) fn light_sample(
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
    pub(super) fn light_samples_shadowed_in_lanes(
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
    pub(super) fn unshadowed_one_by_one(
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
    pub(super) fn unshadowed_diffuse_lanes(
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
    pub(super) fn light_sample_unshadowed(
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
    pub(super) fn lobe_sample(
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
    pub(super) fn reflection_towards(
        &self,
        l: Vec3,
        skips: SkipsOf,
        ctx: &mut SampleContext,
    ) -> Option<Vec3> {
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
pub(super) fn drawn_together(
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

/// Which of the counters' skips a sample's skip is counted in.
pub(super) type SkipsOf = fn(&mut ShadingCounters) -> &mut Skips;

pub(super) fn light_skips(c: &mut ShadingCounters) -> &mut Skips {
    &mut c.light_skips
}

pub(super) fn lobe_skips(c: &mut ShadingCounters) -> &mut Skips {
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

/// From this many samples per light on, the samples are shaded in lanes; below
/// it, one by one (the same result: the lanes only cost more for one sample).
pub(crate) const LANES_FROM_SAMPLES: usize = 2;
