//! A shading point's samples in the reference: each light sample, lobe
//! sample and environment sample drawn alone, through its own shadow ray,
//! in scalar code of its own (no lanes), for every sample count.

use crate::context::SampleContext;
use crate::mistakes::Mistake;
use crate::physical::power_heuristic;
use crate::sampling::SamplePoints;
use crate::shading_point::ShadingPoint;
use crate::{Scene, ShadingCounters, Skips};
use glam::Vec3;
use glint_geometry::{spawn_ray, spawn_ray_to, Occluders, Ray, RayTarget};
use glint_lighting::{AreaLight, EnvironmentSample, PointLight};

impl ShadingPoint<'_> {
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

    /// The environment sample `s`'s value `L · f · cos θ / p` where its
    /// shadow ray is unblocked, else zero.
    pub(super) fn environment_sample(
        &self,
        scene: &Scene,
        s: &EnvironmentSample,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let Some(value) = self.environment_sample_unshadowed(s, ctx) else {
            return Vec3::ZERO;
        };
        if ctx.mistakes.has(Mistake::NoShadows) {
            return value;
        }
        let shadow_ray = match ctx.mistakes.has(Mistake::NoShadowOffset) {
            true => Ray::new(self.hit.point, s.direction),
            false => spawn_ray(self.hit, s.direction),
        };
        match scene.shapes.any_hit(&shadow_ray, f32::INFINITY) {
            true => Vec3::ZERO,
            false => value,
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
        let reflected = if let Some(mistaken) = self.mistaken_reflection(l, ctx.mistakes) {
            mistaken
        } else if self.has_specular {
            ctx.counters.specular_lobes += 1;
            self.material.reflect(self.kd, self.ks, self.n, l, self.v)
        } else {
            self.material.reflect_diffuse(self.kd, self.n, l)
        };
        if reflected == Vec3::ZERO {
            ctx.counters.light_skips.zero_brdf += 1;
            return Vec3::ZERO;
        }
        if ctx.mistakes.has(Mistake::NoShadows) {
            return reflected;
        }
        let shadow = match ctx.mistakes.has(Mistake::NoShadowOffset) {
            true => Ray::new(self.hit.point, target.point - self.hit.point),
            false => spawn_ray_to(self.hit, target),
        };
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

/// Which of the counters' skips a sample's skip is counted in.
pub(super) type SkipsOf = fn(&mut ShadingCounters) -> &mut Skips;

pub(super) fn light_skips(c: &mut ShadingCounters) -> &mut Skips {
    &mut c.light_skips
}

pub(super) fn lobe_skips(c: &mut ShadingCounters) -> &mut Skips {
    &mut c.lobe_skips
}
