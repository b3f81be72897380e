//! Physical shading (`shading = "physical"`): radiometric lights and
//! energy-conserving BRDFs, estimated with multiple importance sampling.
//!
//! At a surface point `x` seen from direction `v`, the reflected radiance is
//!
//! `L(x, v) = ambient·kd + Σ_point f(l, v)·cos θ·I/r² · V + Σ_area ∫_Ω f·L_e·cos θ·V dω + L_env`
//!
//! with `f = kd/π + ks·(normalised lobe)` ([`glint_lighting::PhongMaterial::brdf_cos`]), `I`
//! a point light's intensity, `L_e` an area light's radiance (front side only)
//! and `V` the visibility. The environment term is the same as in Phong
//! shading (it is physical already).
//!
//! Each area light takes N light samples, drawn by area or solid angle
//! ([`AreaSampling`](glint_lighting::AreaSampling)). On a glossy material
//! (`ks ≠ 0`) it also takes N directions drawn from the specular lobe
//! ([`glint_lighting::PhongMaterial::sample_specular`]), each traced to see whether it reaches
//! the light, and the two are combined by multiple importance sampling with
//! the power heuristic (Veach and Guibas 1995; Veach's thesis 1997, §9.2):
//! a sample drawn by technique `a` with density `p_a`, where the other gives
//! `p_b`, is weighted `p_a² / (p_a² + p_b²)` (equal sample counts). The weights
//! of the two techniques sum to 1 for every direction, so the estimate is
//! unbiased (for randomised point sets: the `grid` pattern's fixed cell
//! centres make it a fixed quadrature, as for light samples alone); light samples carry the diffuse term and broad lobes, lobe samples
//! the sharp highlight of a large light, where light samples alone are noisy.
//! On a purely diffuse material only the light is sampled (weight 1).

use crate::direct::{SampleContext, ShadingPoint};
use crate::light_samples::LANES_FROM_SAMPLES;
use crate::sampling::{DimensionPair, PointChunk, SamplePoints};
use crate::trace::{Shadow, Skip, Tracer};
use crate::{DirectIntegrator, Scene, ShadingCounters, Skips};
use glam::Vec3;
use glint_geometry::lanes::{self, F32Lanes, Float, Vec3Lanes, LANES};
use glint_geometry::{spawn_ray, spawn_ray_to, Occluders, RayLanes, RayTarget};
use glint_lighting::{AreaLight, AreaLightSampler, Light, PointLight, SphereLight};

impl DirectIntegrator {
    /// The local shading of `point` in physical units, `depth` reflections deep.
    pub(crate) fn shade_physical<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        depth: u32,
        ctx: &mut SampleContext<T>,
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
    fn physical_area_light<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        light: &AreaLight,
        pair: DimensionPair,
        depth: u32,
        ctx: &mut SampleContext<T>,
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
        let occluders = self.occluders(scene, point, index, light, ctx);
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
}

impl DirectIntegrator {
    /// The spherical light `light` (at `index` of the scene's lights) reflects
    /// at `point`: directions uniform over its cone, and on a glossy material
    /// as many specular-lobe samples, combined by the power heuristic.
    #[allow(clippy::too_many_arguments)]
    fn physical_sphere_light<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        light: &SphereLight,
        pair: DimensionPair,
        depth: u32,
        ctx: &mut SampleContext<T>,
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
}

impl DirectIntegrator {
    /// The sum over `light_samples` directions drawn from `point`'s specular
    /// lobe of [`ShadingPoint::lobe_sample`] towards the light at `index`,
    /// whose own sampling has density `light_pdf(y)` towards its point `y`.
    fn lobe_samples<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        depth: u32,
        light_pdf: impl Fn(Vec3) -> f32,
        ctx: &mut SampleContext<T>,
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

/// Diffuse points in lanes (one point in every lane, or a point per lane):
/// their positions, geometric normals and unit shading normals on the
/// viewer's side, and diffuse reflectances.
pub(crate) struct DiffusePoints<'a> {
    pub(crate) point: &'a Vec3Lanes,
    pub(crate) ng: &'a Vec3Lanes,
    pub(crate) n: &'a Vec3Lanes,
    pub(crate) kd: &'a Vec3Lanes,
}

impl DiffusePoints<'_> {
    /// The light samples at `position` with solid-angle densities `pdf`, one
    /// a lane, in the lanes `used`, short of their shadow rays: each lane's
    /// `kd/π · cos θ / p` ([`ShadingPoint::light_sample_unshadowed`] at a
    /// diffuse point, bit for bit) and the lanes that need a shadow ray,
    /// the others counted as skipped.
    #[inline(always)]
    pub(crate) fn light_samples(
        &self,
        position: &Vec3Lanes,
        pdf: F32Lanes,
        used: u32,
        counters: &mut ShadingCounters,
    ) -> (Vec3Lanes, u32) {
        let s = self.unshadowed_by(position, pdf, used, counters, |l| {
            // `brdf_cos_diffuse`: kd/π · n·l, zero where n·l ≤ 0.
            let n_dot_l = l.dot(self.n);
            let f = (self.kd)
                .scale(F32Lanes::splat(std::f32::consts::FRAC_1_PI))
                .scale(n_dot_l);
            let zero = Vec3Lanes::default();
            Vec3Lanes::select(lanes::le(n_dot_l, F32Lanes::ZERO), &zero, &f)
        });
        (s.f_cos.scale(F32Lanes::ONE / pdf), s.reflects)
    }

    /// The part of [`Self::light_samples`] every BRDF shares: each lane's
    /// unit direction `l` towards `position` and its `f · cos θ` by
    /// `brdf_cos`, the lanes with a density and above the surface, and of
    /// those the lanes that reflect something and need a shadow ray; the
    /// others counted as skipped, the rays counted.
    #[inline(always)]
    pub(crate) fn unshadowed_by(
        &self,
        position: &Vec3Lanes,
        pdf: F32Lanes,
        used: u32,
        counters: &mut ShadingCounters,
        brdf_cos: impl FnOnce(&Vec3Lanes) -> Vec3Lanes,
    ) -> UnshadowedLanes {
        let dense = used & lanes::bits(lanes::gt(pdf, F32Lanes::ZERO) & pdf.is_finite());
        let (l, normalized) = (*position - *self.point).try_normalize();
        let above = lanes::bits(normalized & lanes::gt(l.dot(self.ng), F32Lanes::ZERO));
        let f_cos = brdf_cos(&l);
        let reflects = dense & above & !lanes::bits(f_cos.is_zero());
        let skips = &mut counters.light_skips;
        skips.zero_density += u64::from((used & !dense).count_ones());
        skips.below_surface += u64::from((dense & !above).count_ones());
        skips.zero_brdf += u64::from((dense & above & !reflects).count_ones());
        counters.light_shadow_rays += u64::from(reflects.count_ones());
        UnshadowedLanes {
            l,
            f_cos,
            evaluated: dense & above,
            reflects,
        }
    }
}

/// Light samples in lanes short of their shadow rays
/// ([`DiffusePoints::unshadowed_by`]).
pub(crate) struct UnshadowedLanes {
    /// Each lane's unit direction towards its light point.
    pub(crate) l: Vec3Lanes,
    /// Each lane's `f · cos θ`.
    pub(crate) f_cos: Vec3Lanes,
    /// The lanes whose BRDF was evaluated: with a density, above the surface.
    pub(crate) evaluated: u32,
    /// The lanes that need a shadow ray.
    pub(crate) reflects: u32,
}

/// Veach's power heuristic (β = 2) for a sample drawn with density `a` where
/// the other technique has density `b`: `a² / (a² + b²)`, written so that
/// neither square overflows.
/// In one lane or in many.
#[inline(always)]
pub(crate) fn power_heuristic<F: Float>(a: F, b: F) -> F {
    let ratio = b / a;
    F::select(a.le(F::ZERO), F::ZERO, F::ONE / (F::ONE + ratio * ratio))
}

impl ShadingPoint<'_> {
    /// `f · cos θ · I / r²` of a point light, or zero behind the surface or in
    /// shadow.
    fn point_light<T: Tracer>(
        &self,
        scene: &Scene,
        light: &PointLight,
        ctx: &mut SampleContext<T>,
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
    fn light_sample<T: Tracer>(
        &self,
        scene: &Scene,
        target: &RayTarget,
        pdf: f32,
        mis: bool,
        occluders: &Occluders,
        ctx: &mut SampleContext<T>,
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
    fn light_samples_shadowed_in_lanes<T: Tracer>(
        &self,
        scene: &Scene,
        light: &AreaLight,
        sampler: &AreaLightSampler,
        samples: &SamplePoints,
        mis: bool,
        occluders: &Occluders,
        ctx: &mut SampleContext<T>,
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
    fn unshadowed_one_by_one<T: Tracer>(
        &self,
        light: &AreaLight,
        sampler: &AreaLightSampler,
        chunk: &PointChunk,
        mis: bool,
        ctx: &mut SampleContext<T>,
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
    fn unshadowed_diffuse_lanes<T: Tracer>(
        &self,
        sampler: &AreaLightSampler,
        chunk: &PointChunk,
        ctx: &mut SampleContext<T>,
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
    fn light_sample_unshadowed<T: Tracer>(
        &self,
        target: &RayTarget,
        pdf: f32,
        mis: bool,
        ctx: &mut SampleContext<T>,
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
    fn lobe_sample<T: Tracer>(
        &self,
        scene: &Scene,
        light_pdf: &impl Fn(Vec3) -> f32,
        object: u32,
        l: Vec3,
        ctx: &mut SampleContext<T>,
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

    /// Why [`Self::reflection_towards`] gave `None` for `l`.
    pub(crate) fn skip_reason(&self, l: Vec3) -> Shadow {
        Shadow::Skipped(if self.above_surface(l) {
            Skip::ZeroBrdf
        } else {
            Skip::BehindSurface
        })
    }

    /// `f(l, v) · cos θ` towards the unit direction `l`, or `None` where no
    /// ray need be traced: `l` below the geometric surface, or a zero BRDF,
    /// counted in the skips `skips` picks (a light's or a lobe's).
    fn reflection_towards<T: Tracer>(
        &self,
        l: Vec3,
        skips: SkipsOf,
        ctx: &mut SampleContext<T>,
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
type SkipsOf = fn(&mut ShadingCounters) -> &mut Skips;

fn light_skips(c: &mut ShadingCounters) -> &mut Skips {
    &mut c.light_skips
}

fn lobe_skips(c: &mut ShadingCounters) -> &mut Skips {
    &mut c.lobe_skips
}
