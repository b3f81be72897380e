//! The light a wave's shaded lanes reflect: ambient, each light's samples
//! (the course's Phong model or the physical one, with multiple importance
//! sampling of glossy lobes) and the environment's.

use super::points::{LaneStreams, PairAllocation, PointsOf};
use super::shaded_lanes::{count_light_samples, ShadedLanes};
use crate::context::SampleContext;
use crate::physical::power_heuristic;
use crate::sampling::DimensionPair;
use crate::trace::{Event, Tracer};
use crate::{DirectIntegrator, Scene};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes, LANES};
use glint_geometry::{offset_ray_origins, Occluders, RayLanes};
use glint_lighting::{AreaLight, EnvironmentLight, Light, ShadingModel, SphereLight};

impl DirectIntegrator {
    /// `radiance` plus, in the lanes of `shaded`, each light's term and the
    /// environment's, added in `li_at`'s order, for the camera samples
    /// `streams`.
    #[inline(always)]
    pub(crate) fn with_direct_lighting<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        streams: &mut LaneStreams,
        mut radiance: Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let shaded_mask = lanes::from_bits(shaded.lanes);
        let mut pairs = PairAllocation::new(shaded.depth);
        let physical = scene.shading == ShadingModel::Physical;
        for (index, light) in scene.lights.iter().enumerate() {
            // The dimensions `light_pair` gives a light that samples.
            let own = DimensionPair::Light {
                light: index as u32,
                depth: shaded.depth,
            };
            ctx.tracer
                .record(shaded.lanes, |_| Event::Light { light: index });
            let term = match light {
                Light::Area(area) => {
                    let pair = pairs.take(own, self.light_samples);
                    let points = (pair, &mut *streams);
                    if physical {
                        self.physical_area_light_term(scene, shaded, (index, area), points, ctx)
                    } else {
                        self.area_light_term(scene, shaded, (index, area), points, ctx)
                    }
                }
                Light::Point(point) => {
                    ctx.counters.point_light_samples += u64::from(shaded.lanes.count_ones());
                    if physical {
                        shaded.physical_point_light(scene, point, ctx)
                    } else {
                        let reflected = shaded.point_light(scene, point, ctx);
                        Vec3Lanes::scaled_splat_lanes(point.color, &reflected)
                    }
                }
                // The course's model has no sphere lights (`shade`).
                Light::Sphere(_) if !physical => Vec3Lanes::default(),
                Light::Sphere(sphere) => {
                    let pair = pairs.take(own, self.light_samples);
                    let sphere = (index, sphere);
                    self.physical_sphere_light_term(scene, shaded, sphere, (pair, streams), ctx)
                }
            };
            let total = |k| Event::LightTotal {
                light: index,
                value: term.lane(k),
            };
            ctx.tracer.record(shaded.lanes, total);
            radiance = Vec3Lanes::select(shaded_mask, &(radiance + term), &radiance);
        }
        if let Some(env) = scene
            .environment
            .as_ref()
            .filter(|_| self.environment_samples > 0)
        {
            let term = self.environment_term_lanes(scene, env, shaded, streams, ctx);
            let total = |k| Event::EnvironmentTotal {
                value: term.lane(k),
            };
            ctx.tracer.record(shaded.lanes, total);
            radiance = Vec3Lanes::select(shaded_mask, &(radiance + term), &radiance);
        }
        radiance
    }

    /// `environment_light` at every lane's point: each lane's `n` samples
    /// drawn together across the lanes at its camera sample's points, from
    /// the map ([`EnvironmentLight::sample_each`]) or about each lane's normal
    /// ([`EnvironmentLight::sample_cosine_each`]), then `L · f · cos θ / p`
    /// (the lobe too on glossy lanes) and the shadow rays in lanes, each lane
    /// summing its own samples in order: bit for bit the one-ray reference's
    /// `environment_light`.
    pub(crate) fn environment_term_lanes<T: Tracer>(
        &self,
        scene: &Scene,
        env: &EnvironmentLight,
        shaded: &ShadedLanes,
        streams: &mut LaneStreams,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let n = self.environment_samples;
        let count = u64::from(shaded.lanes.count_ones());
        ctx.counters.environment_samples += u64::from(n) * count;
        let pair = self.environment_pair(scene, shaded.depth);
        let of = (PointsOf::Environment, pair, shaded.lanes);
        let mut points = self.lane_points(of, streams, ctx);
        let len = (u32::BITS - shaded.lanes.leading_zeros()) as usize;
        let by_map = self.samples_environment_by_map(scene);
        let mut sum = Vec3Lanes::default();
        for j in 0..n {
            let u = points.get(j);
            let (direction, radiance, pdf) = if by_map {
                let (ux, uy) = (u.0.to_array(), u.1.to_array());
                let points: [Vec2; LANES] = lanes::array_from_fn(|k| Vec2::new(ux[k], uy[k]));
                let drawn = env.sample_each(Vec3::Y, &points, len);
                (
                    Vec3Lanes::from_lanes(lanes::array_from_fn(|k| drawn[k].direction)),
                    Vec3Lanes::from_lanes(lanes::array_from_fn(|k| drawn[k].radiance)),
                    F32Lanes::new(lanes::array_from_fn(|k| drawn[k].pdf)),
                )
            } else {
                env.sample_cosine_each(shaded.phong.normals(), u, shaded.lanes)
            };
            let dense = shaded.lanes
                & lanes::bits(lanes::gt(pdf, F32Lanes::ZERO))
                & !lanes::bits(radiance.is_zero());
            let above = lanes::bits(lanes::gt(direction.dot(&shaded.ng), F32Lanes::ZERO));
            let f = shaded.phong.brdf_cos(&direction);
            let traced = dense & above & !lanes::bits(f.is_zero());
            let glossy = dense & above & shaded.phong.specular_lanes();
            ctx.counters.specular_lobes += u64::from(glossy.count_ones());
            let skips = &mut ctx.counters.environment_skips;
            skips.zero_density += u64::from((shaded.lanes & !dense).count_ones());
            skips.below_surface += u64::from((dense & !above).count_ones());
            skips.zero_brdf += u64::from((dense & above & !traced).count_ones());
            ctx.counters.environment_shadow_rays += u64::from(traced.count_ones());
            let lit = radiance * f;
            let value = Vec3Lanes::new(lit.x / pdf, lit.y / pdf, lit.z / pdf);
            let origin = shaded.origins_towards(&direction, traced);
            let rays = RayLanes { origin, direction };
            let blocked =
                (scene.shapes).any_hits_among(&Occluders::ALL, &rays, f32::INFINITY, traced);
            if T::ON {
                let verdicts = [dense, above, traced, traced & !blocked];
                let drawn = (&direction, &radiance, pdf);
                shaded.trace_environment_samples(scene, drawn, verdicts, (&f, &value), ctx);
            }
            let visible = lanes::from_bits(traced & !blocked);
            sum = sum + Vec3Lanes::select(visible, &value, &Vec3Lanes::default());
        }
        points.finish(ctx);
        sum.div_splat(n as f32)
    }

    /// `li_at`'s `L · (0 + Σ reflected) / n` for area light `index`, each lane
    /// summing its own `n` samples in order, their points those of `pair` for
    /// the lanes' camera samples (drawn from their streams where the pattern
    /// draws). A sample a lane's point does not see adds +0 where `li_at` adds
    /// nothing: the same, as the sum is never −0.
    pub(crate) fn area_light_term<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        (index, area): (usize, &AreaLight),
        (pair, streams): (DimensionPair, &mut LaneStreams),
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        // `area_light` draws its points at every point, seen or not.
        let mut points = self.lane_points((PointsOf::Lights, pair, shaded.lanes), streams, ctx);
        let occluders = shaded.occluders(scene, index, area, ctx);
        let mut sum = Vec3Lanes::default();
        for j in 0..self.light_samples {
            let u = points.get(j);
            ctx.counters.light_samples += u64::from(shaded.lanes.count_ones());
            sum = sum + shaded.area_light(scene, area, &occluders, u, ctx);
        }
        points.finish(ctx);
        Vec3Lanes::scaled_splat_lanes(area.color, &sum).div_splat(self.light_samples as f32)
    }

    /// `physical_area_light`'s `L · Σ (f · cos θ / p · V · w) / n` for area
    /// light `index` at every lane's point, each lane summing its own `n`
    /// samples in order, drawn by its own point's sampler (by area or solid
    /// angle, as `light.sampler` chooses for it) at the points of `pair` for
    /// the lanes' camera samples; on a glossy point, plus as many samples of
    /// its lobe ([`Self::lobe_sum`]), the two combined by the power
    /// heuristic. A lane behind the light takes no sample: its term is +0, as
    /// `li_at` adds `Vec3::ZERO`.
    pub(crate) fn physical_area_light_term<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        (index, area): (usize, &AreaLight),
        (pair, streams): (DimensionPair, &mut LaneStreams),
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let n = self.light_samples;
        let center = area.surface().center();
        let lit = area.illuminates_lanes(&Vec3Lanes::splat(center), &shaded.point);
        let lit = shaded.lanes & lanes::bits(lit);
        count_light_samples(&mut ctx.counters, n, shaded.lanes, lit);
        if lit == 0 {
            return Vec3Lanes::default();
        }
        let lit_lanes = lanes::from_bits(lit);
        let sampler = area.sampler_from(&shaded.point, self.area_sampling, lit_lanes);
        let occluders = shaded.occluders(scene, index, area, ctx);
        let draw = |(ux, uy): (F32Lanes, F32Lanes)| {
            let (position, pdf) = sampler.sample_at(ux, uy);
            let position = Vec3Lanes::select(lit_lanes, &position, &shaded.point);
            let pdf = F32Lanes::select(lit_lanes, pdf, F32Lanes::ZERO);
            (position, pdf, area.shadow_ends(&position))
        };
        let light_pdf = |k: usize, y: Vec3| sampler.pdf_in_lane(k, y);
        let sampled = (draw, light_pdf);
        let light = (index, area.color);
        self.sampled_light_term(
            scene,
            shaded,
            light,
            (lit, &occluders),
            sampled,
            (pair, streams),
            ctx,
        )
    }

    /// `L · Σ (f · cos θ / p · V · w) / n` at the lanes `lit` for light
    /// `index` of radiance `L`: its `n` samples drawn by `draw`
    /// ([`Self::light_sum`], their shadow rays tested against `occluders`)
    /// and, on glossy points, as many of the lobe's ([`Self::lobe_sum`]),
    /// weighted by the power heuristic against `light_pdf`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn sampled_light_term<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        (index, color): (usize, Vec3),
        (lit, occluders): (u32, &Occluders),
        (draw, light_pdf): (
            impl FnMut((F32Lanes, F32Lanes)) -> (Vec3Lanes, F32Lanes, Vec3Lanes),
            impl Fn(usize, Vec3) -> f32,
        ),
        (pair, streams): (DimensionPair, &mut LaneStreams),
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let mis = self.mis_lanes(shaded, lit);
        let shadowed = (lit, mis, occluders);
        let mut sum = self.light_sum(scene, shaded, shadowed, (pair, streams), draw, ctx);
        if mis != 0 {
            sum = sum + self.lobe_sum(scene, shaded, (mis, index), light_pdf, streams, ctx);
        }
        Vec3Lanes::scaled_splat_lanes(color, &sum).div_splat(self.light_samples as f32)
    }

    /// `physical_sphere_light`'s `L · Σ (f · cos θ / p · V · w) / n` for
    /// sphere light `index` at every lane's point, each lane summing its own
    /// `n` directions uniform over its cone ([`SphereLight::sample_lanes`]) at
    /// the points of `pair` for the lanes' camera samples; on a glossy point,
    /// plus as many samples of its lobe ([`Self::lobe_sum`]). A lane inside
    /// the sphere takes no sample: its term is +0, as `li_at` adds
    /// `Vec3::ZERO`.
    #[inline(never)]
    pub(crate) fn physical_sphere_light_term<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        (index, light): (usize, &SphereLight),
        (pair, streams): (DimensionPair, &mut LaneStreams),
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let n = self.light_samples;
        let lit = shaded.lanes & light.outside_lanes(&shaded.point);
        count_light_samples(&mut ctx.counters, n, shaded.lanes, lit);
        if lit == 0 {
            return Vec3Lanes::default();
        }
        let draw = |u: (F32Lanes, F32Lanes)| {
            let (_, [point, error, normal], pdf) = light.sample_lanes(&shaded.point, u);
            (point, pdf, offset_ray_origins(&point, &error, &normal))
        };
        let light_pdf = |k: usize, _: Vec3| light.pdf(shaded.point.lane(k));
        let (sampled, all) = ((draw, light_pdf), (lit, &Occluders::ALL));
        let light = (index, light.color);
        self.sampled_light_term(scene, shaded, light, all, sampled, (pair, streams), ctx)
    }

    /// `Σ_j f · cos θ / p · V · w` over a light's `light_samples` samples at
    /// every lane of `lit`, each lane summing its own in order: sample `j`'s
    /// points (each lane's of `pair`, [`LanePoints`]; only `lit` draws) drawn by
    /// `draw` into light points, their densities and their shadow rays' ends,
    /// tested against `occluders`; `w` the power heuristic's weight against
    /// the lobe in the lanes `mis`, else 1. A blocked sample adds +0 where
    /// `li_at` adds nothing: the same, as the sum is never −0.
    pub(crate) fn light_sum<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        (lit, mis, occluders): (u32, u32, &Occluders),
        (pair, streams): (DimensionPair, &mut LaneStreams),
        mut draw: impl FnMut((F32Lanes, F32Lanes)) -> (Vec3Lanes, F32Lanes, Vec3Lanes),
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let mut points = self.lane_points((PointsOf::Lights, pair, lit), streams, ctx);
        let mut sum = Vec3Lanes::default();
        for j in 0..self.light_samples {
            let (position, pdf, ends) = draw(points.get(j));
            let (values, traced) = shaded.light_samples(&position, pdf, (lit, mis), ctx);
            let towards = position - shaded.point;
            let visible = traced & !shaded.blocked(scene, occluders, &ends, &towards, traced);
            if T::ON {
                let verdicts = [lit, mis, traced, visible];
                let drawn = (&position, pdf, &ends);
                shaded.trace_physical_samples(scene, drawn, verdicts, &values, ctx);
            }
            let zero = Vec3Lanes::default();
            sum = sum + Vec3Lanes::select(lanes::from_bits(visible), &values, &zero);
        }
        points.finish(ctx);
        sum
    }

    /// The lanes of `lit` whose light samples are weighted against their
    /// lobe's: glossy points, when the integrator combines the two.
    pub(crate) fn mis_lanes(&self, shaded: &ShadedLanes, lit: u32) -> u32 {
        match self.mis {
            true => lit & shaded.phong.specular_lanes(),
            false => 0,
        }
    }

    /// `lobe_samples`' `Σ_j f · cos θ / p · w` at the glossy points of the
    /// lanes `mis` towards light `index`: each lane's `light_samples`
    /// directions drawn from its own lobe at the points of the light's BRDF
    /// pair, in order, the rays along them traced together, and a direction
    /// counted where its ray meets the light's surface first, weighted by
    /// the power heuristic against `light_pdf(k, y)`, lane k's density of
    /// drawing the light's point `y`. Each lane's sum and counts are
    /// `lobe_samples`' bit for bit; the other lanes' sums are +0.
    #[inline(never)]
    pub(crate) fn lobe_sum<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        (mis, index): (u32, usize),
        light_pdf: impl Fn(usize, Vec3) -> f32,
        streams: &mut LaneStreams,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let n = self.light_samples;
        let pair = DimensionPair::Brdf {
            light: index as u32,
            depth: shaded.depth,
        };
        let mut points = self.lane_points((PointsOf::Lights, pair, mis), streams, ctx);
        ctx.counters.lobe_samples += u64::from(n) * u64::from(mis.count_ones());
        let object = scene.light_objects[index];
        let mut sum = Vec3Lanes::default();
        for j in 0..n {
            let u = points.get(j);
            let (l, pdf, drawn) = shaded.lobe_directions(u, mis, &mut ctx.counters);
            let (f, traced) = shaded.lobe_reflections(&l, drawn, &mut ctx.counters);
            if traced == 0 {
                if T::ON {
                    let none = (0, None, 0);
                    let zero = Vec3Lanes::default();
                    shaded.trace_lobe_samples(scene, (mis, u), none, &light_pdf, &zero, ctx);
                }
                continue;
            }
            let pdf = pdf.to_array();
            let rays = RayLanes {
                origin: shaded.origins_towards(&l, traced),
                direction: l,
            };
            let closest = scene.shapes.closest_lanes(&rays, LANES);
            let mut weights = [0.0; LANES];
            let mut reached = 0;
            for k in lanes::each_set(traced) {
                let ray = rays.lane(k);
                let found = closest.hit(k);
                // The light's surface is one-sided: a hit on it is a hit on its front.
                let on_light = found.filter(|found| found.object == object);
                if let Some(hit) =
                    on_light.and_then(|found| scene.shapes.surface_point(&ray, found))
                {
                    weights[k] = power_heuristic(pdf[k], light_pdf(k, hit.point)) / pdf[k];
                    reached |= 1 << k;
                }
            }
            let value = f.scale(F32Lanes::new(weights));
            if T::ON {
                let found = (traced, Some((&rays, &closest)), reached);
                shaded.trace_lobe_samples(scene, (mis, u), found, &light_pdf, &value, ctx);
            }
            sum = sum + Vec3Lanes::select(lanes::from_bits(reached), &value, &Vec3Lanes::default());
        }
        points.finish(ctx);
        sum
    }
}
