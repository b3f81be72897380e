//! The first hits of a chunk of camera samples shaded [`LANES`] at once.
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
//! ([`LanePoints`]), the lanes whose points come from their own streams
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

use crate::context::{LaneOccluders, SampleContext};
use crate::direct::{mirror_ray, PairAllocation, CULL_REACH};
use crate::light_samples::{count_lanes, LightSampleLanes};
use crate::physical::{power_heuristic, DiffusePoints};
use crate::sampling::{
    DimensionPair, LaneSamples, Pcg32Lanes, PointLanes, RunLanes, SamplePattern, SamplePoints,
    SobolSequence,
};
use crate::shading_point::ShadingPoint;
use crate::texture_lookup::texture_footprint;
use crate::trace::{Event, Tracer};
use crate::{DirectIntegrator, Scene, ShadingCounters, SurfaceKind};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, F32Lanes, Float, I32Lanes, Vec3Lanes, LANES};
use glint_geometry::{
    offset_ray_origins, reflect, spawn_ray, ClosestLanes, ObjectRef, Occluders, Ray,
    RayDifferential, RayLanes, Shape, Sphere, SurfaceLanes, SPHERE_UV_APPROX_ERROR,
};
use glint_lighting::{
    sample_specular_at, specular_pdf_at, AreaLight, EnvironmentLight, Light, PhongLanes,
    PhongMaterial, PointLight, ShadingModel, SphereLight, UvTransform,
};
use glint_texture::{Checkerboard, TexCoord, Texture};
use std::cell::OnceCell;

impl DirectIntegrator {
    /// The radiance arriving along the camera ray `ray`, whose footprint is
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
        self.li_first_hits(scene, &rays, footprints, &closest, 1, &samples, ctx)
            .lane(0)
    }

    /// The radiance of the first `used` of [`LANES`] camera samples, lane k
    /// sample `samples.lane(k)`, whose camera rays `rays` (with their
    /// differentials `diffs` where the scene reads footprints) have the
    /// closest hits `closest`: for each, what `li_at` gives it alone (with
    /// [`SampleContext::begin_sample`] for that sample), bit for bit.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn li_first_hits<T: Tracer>(
        &self,
        scene: &Scene,
        rays: &RayLanes,
        diffs: Option<&[RayDifferential; LANES]>,
        closest: &ClosestLanes,
        used: usize,
        samples: &LaneSamples,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        // Each lane's own stream, as `SampleContext::begin_sample` makes it,
        // where a pattern draws from it (grid and Sobol points draw nothing).
        let draws = |pattern| matches!(pattern, SamplePattern::Random | SamplePattern::Stratified);
        let mut streams = LaneStreams {
            samples,
            live: 0,
            rngs: (draws(self.light_pattern) || draws(self.environment_pattern))
                .then(|| Pcg32Lanes::new(samples.stream_seeds())),
        };
        let wave = Wave {
            rays,
            diffs,
            closest,
            lanes: (1 << used) - 1,
            depth: 0,
        };
        self.li_wave(scene, wave, &mut streams, ctx)
    }

    /// `li_at` for every lane of `wave`, `wave.depth` reflections deep, for
    /// the lanes' camera samples (`streams`): misses read the environment, emitters give their
    /// radiance, and surfaces their local shading and, on a mirror, the
    /// radiance of the next wave ([`Self::mirror_wave`]), in `li_at`'s
    /// order and operations. The other lanes are zero.
    // Inlined into the first hits and into `mirror_wave`, which alone
    // recurses: the first wave is then one function, as it was before
    // mirrors took the lanes (its lanes passed in registers, not memory).
    #[inline(always)]
    fn li_wave<T: Tracer>(
        &self,
        scene: &Scene,
        wave: Wave,
        streams: &mut LaneStreams,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        if T::ON {
            wave.trace_rays(scene, ctx);
        }
        let hit_lanes = wave.closest.hits & wave.lanes;
        let mut radiance = self.environment_seen_lanes(scene, &wave, wave.lanes & !hit_lanes, ctx);
        if hit_lanes == 0 {
            return radiance;
        }
        let hits = FirstHits::of(scene, wave.closest, hit_lanes);
        let mirrors = Mirrors::of(scene, wave.closest, hit_lanes, &hits);
        // Perfect mirrors have no local shading.
        let local = hit_lanes & !mirrors.perfect;
        let hits = match local == hit_lanes {
            true => hits,
            false => FirstHits::of(scene, wave.closest, local),
        };
        let on = (local, hits);
        // Of the lanes that draw no points for a term, only these go on
        // to draw later (for another term, or a next wave).
        streams.live = hit_lanes;
        let shaded = match local {
            0 => 0,
            _ => self.local_shading_lanes(scene, &wave, on, streams, &mut radiance, ctx),
        };
        // `li_at`'s `(1 − r)·local + r·mirror` on every surface: a zero
        // mirror term on all but mirrors (which turns a −0 to +0 there too),
        // and no local term on a perfect mirror.
        if mirrors.lanes == 0 {
            let plus_zero = radiance + Vec3Lanes::default();
            if T::ON {
                let values = (&radiance, &Vec3Lanes::default(), &plus_zero);
                wave.trace_radiance(shaded, values, ctx);
            }
            return Vec3Lanes::select(lanes::from_bits(shaded), &plus_zero, &radiance);
        }
        let traced = match wave.depth < self.max_depth {
            true => mirrors.lanes,
            false => 0,
        };
        let mirror = match traced {
            0 => Vec3Lanes::default(),
            _ => self.mirror_wave(scene, &wave, traced, streams, ctx) * mirrors.tint,
        };
        let r = mirrors.reflectivity;
        let value = radiance.scale(F32Lanes::splat(1.0) - r) + mirror.scale(r);
        let surfaces = shaded | mirrors.perfect;
        if T::ON {
            wave.trace_radiance(surfaces, (&radiance, &mirror, &value), ctx);
        }
        Vec3Lanes::select(lanes::from_bits(surfaces), &value, &radiance)
    }

    /// The environment's radiance along the rays of `wave` in the lanes
    /// `misses`, which hit nothing (zero elsewhere, and without one): the map
    /// unfiltered under physical shading, filtered over each ray's footprint
    /// in the course's model, as `li_at`'s `environment_seen` reads it.
    #[inline(always)]
    fn environment_seen_lanes<T: Tracer>(
        &self,
        scene: &Scene,
        wave: &Wave,
        misses: u32,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let mut radiance = Vec3Lanes::default();
        let Some(env) = scene.environment.as_ref().filter(|_| misses != 0) else {
            return radiance;
        };
        ctx.counters.environment_lookups += u64::from(misses.count_ones());
        match scene.shading {
            ShadingModel::Physical => {
                let seen = env.radiance_each(&wave.rays.direction.normalize(), misses);
                radiance = Vec3Lanes::select(lanes::from_bits(misses), &seen, &radiance);
            }
            ShadingModel::Phong => {
                for k in lanes::each_set(misses) {
                    let ray = wave.rays.lane(k);
                    let diff = wave
                        .diffs
                        .map_or_else(|| RayDifferential::none(&ray), |d| d[k]);
                    let width = diff.angular_width(ray.direction);
                    radiance.set_lane(k, env.radiance(ray.direction.normalize(), width));
                }
            }
        }
        if T::ON {
            wave.trace_misses(scene, misses, &radiance, ctx);
        }
        radiance
    }

    /// The lanes of `local`, on surfaces (`hits`), shaded: an emitter's
    /// radiance, or a material's ambient term, lights and environment
    /// (`li_at`'s local shading), put in `radiance`. The lanes shaded on a
    /// material are returned.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn local_shading_lanes<T: Tracer>(
        &self,
        scene: &Scene,
        wave: &Wave,
        (local, hits): (u32, FirstHits),
        streams: &mut LaneStreams,
        radiance: &mut Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) -> u32 {
        let (rays, closest) = (wave.rays, wave.closest);
        // Each arm builds the lanes in place: made over a default, or moved
        // out of an `Option`, their kilobytes cost a zeroing or a copy a chunk.
        let mut shaded = match hits {
            FirstHits::OnOneObject(object, shape, material) => {
                let on = (object, shape, material);
                ShadedLanes::on_one_object(scene, rays, closest, local, on, radiance, ctx)
            }
            FirstHits::OnOneEmitter(area) => {
                ctx.tracer.record(local, |_| Event::Emitter {
                    radiance: area.color,
                });
                let color = Vec3Lanes::splat(area.color);
                *radiance = Vec3Lanes::select(lanes::from_bits(local), &color, radiance);
                return 0;
            }
            FirstHits::Several => {
                let hits = (rays, wave.diffs, closest);
                ShadedLanes::one_by_one(scene, hits, (local, wave.depth), radiance, ctx)
            }
        };
        shaded.depth = wave.depth;
        if T::ON {
            wave.trace_surfaces(scene, &shaded, radiance, ctx);
        }
        if shaded.lanes != 0 {
            *radiance = self.with_direct_lighting(scene, &shaded, streams, *radiance, ctx);
        }
        shaded.lanes
    }

    /// `radiance` plus, in the lanes of `shaded`, each light's term and the
    /// environment's, added in `li_at`'s order, for the camera samples
    /// `streams`.
    #[inline(always)]
    fn with_direct_lighting<T: Tracer>(
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

    /// The radiance along the rays the lanes `traced` of `wave` reflect
    /// into, on mirrors, found as the next wave one reflection deeper: the
    /// rays made in their own lanes ([`reflected_rays`]), their closest hits
    /// found together, and their radiance by [`Self::li_wave`].
    #[inline(never)]
    fn mirror_wave<T: Tracer>(
        &self,
        scene: &Scene,
        wave: &Wave,
        traced: u32,
        streams: &mut LaneStreams,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let (rays, diffs, traced) = reflected_rays(scene, wave, traced);
        if T::ON {
            wave.trace_mirrors(scene, &rays, traced, ctx);
        }
        ctx.counters.reflection_rays += u64::from(traced.count_ones());
        let used = (u32::BITS - traced.leading_zeros()) as usize;
        let closest = scene.shapes.closest_lanes(&rays, used);
        let next = Wave {
            rays: &rays,
            diffs: diffs.as_ref(),
            closest: &closest,
            lanes: traced,
            depth: wave.depth + 1,
        };
        self.li_wave(scene, next, streams, ctx)
    }

    /// `environment_light` at every lane's point: each lane's `n` samples
    /// drawn together across the lanes at its camera sample's points, from
    /// the map ([`EnvironmentLight::sample_each`]) or about each lane's normal
    /// ([`EnvironmentLight::sample_cosine_each`]), then `L · f · cos θ / p`
    /// (the lobe too on glossy lanes) and the shadow rays in lanes, each lane summing
    /// its own samples in order, bit for bit `add_environment_samples`.
    fn environment_term_lanes<T: Tracer>(
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
    fn area_light_term<T: Tracer>(
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
    fn physical_area_light_term<T: Tracer>(
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
    fn sampled_light_term<T: Tracer>(
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
    fn physical_sphere_light_term<T: Tracer>(
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
    fn light_sum<T: Tracer>(
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
    fn mis_lanes(&self, shaded: &ShadedLanes, lit: u32) -> u32 {
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
    fn lobe_sum<T: Tracer>(
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

    /// Each lane's points of `pair` for the lights or the environment, as
    /// its camera sample takes them alone, the lanes `drawing` drawing from
    /// their streams where the pattern draws ([`LanePoints`]).
    #[inline(always)]
    fn lane_points<'s, T: Tracer>(
        &self,
        (of, pair, drawing): (PointsOf, DimensionPair, u32),
        streams: &'s mut LaneStreams,
        ctx: &mut SampleContext<T>,
    ) -> LanePoints<'s> {
        let (pattern, n) = match of {
            PointsOf::Lights => (self.light_pattern, self.light_samples),
            PointsOf::Environment => (self.environment_pattern, self.environment_samples),
        };
        let samples = streams.samples;
        match pattern {
            SamplePattern::Sobol => {
                let sequences = RunSequences::new(samples, drawing, pair, n, ctx);
                let stride = u64::from(n);
                match RunLanes::new(&sequences.runs[..sequences.count], stride, stride) {
                    // All the points hashed together and up front: the
                    // hashes of different points overlap, where one point's
                    // waits on its own long chain of products.
                    Some(together) => {
                        let mut points = std::mem::take(&mut ctx.sobol_lanes);
                        points.clear();
                        points.extend((0..n).map(|j| together.points(j)));
                        LanePoints::Hashed(points)
                    }
                    None => LanePoints::Sobol(sequences, n),
                }
            }
            SamplePattern::Grid => {
                let mut points = std::mem::take(of.buffer(ctx));
                ctx.fill_points(pattern, pair, &mut points);
                LanePoints::Grid(points, of)
            }
            SamplePattern::Random | SamplePattern::Stratified => {
                let rngs = streams
                    .rngs
                    .as_mut()
                    .expect("streams where the pattern draws");
                // Two uniforms a point: random points, and a stratified one
                // (its one cell is the whole square, and `(0 + u)·1` is `u`).
                if pattern == SamplePattern::Random || n == 1 {
                    let (before, kept) = (*rngs, streams.live & !drawing);
                    return LanePoints::Uniform(rngs, before, kept);
                }
                let n = n as usize;
                let mut points = std::mem::take(&mut ctx.lane_points);
                points.resize(LANES * n, Vec2::ZERO);
                for k in lanes::each_set(drawing) {
                    let mut rng = rngs.lane(k);
                    let sobol = samples.lane(k).sobol_points(pair, n as u32);
                    pattern.fill(&mut rng, sobol, &mut points[k * n..(k + 1) * n]);
                    rngs.set_lane(k, rng);
                }
                LanePoints::Filled(points, n)
            }
        }
    }
}

/// The camera samples of a chunk's lanes, and their streams where a pattern
/// draws from them.
pub(crate) struct LaneStreams<'a> {
    samples: &'a LaneSamples,
    /// The lanes whose streams are read after the term being drawn.
    live: u32,
    rngs: Option<Pcg32Lanes>,
}

/// Whose points: the lights' (and their lobes'), or the environment's.
#[derive(Clone, Copy)]
enum PointsOf {
    Lights,
    Environment,
}

impl PointsOf {
    /// The context's buffer for a camera sample's points.
    fn buffer<T: Tracer>(self, ctx: &mut SampleContext<T>) -> &mut SamplePoints {
        match self {
            Self::Lights => &mut ctx.light_points,
            Self::Environment => &mut ctx.environment_points,
        }
    }
}

/// Each lane's points of one dimension pair, as its camera sample alone
/// takes them from its pattern: the grid's (the same in every lane); its
/// own points of its pixel's Sobol sequence; its stream's next two uniforms
/// a point, drawn in lanes (random, and stratified for one point); or the
/// pattern's points drawn lane by lane up front from each lane's stream
/// (stratified). Only the lanes named on making them draw:
/// [`LanePoints::finish`] leaves the other lanes' streams as they were, as
/// `li_at` draws nothing there, and puts the buffers back.
// On the stack for one light's samples: boxing the sequences would
// allocate per light and chunk.
#[allow(clippy::large_enum_variant)]
enum LanePoints<'s> {
    Grid(SamplePoints, PointsOf),
    /// Each run's points hashed from its own sequence, where some lane's
    /// points leave its sequence's first 2^16 ([`RunLanes::new`]).
    Sobol(RunSequences, u32),
    /// Every lane's points of its run's sequence, point `j` at `j`.
    Hashed(Vec<PointLanes>),
    /// The streams, where they were, and the lanes read later that do not
    /// draw.
    Uniform(&'s mut Pcg32Lanes, Pcg32Lanes, u32),
    /// Lane k's `n` points at `k·n`.
    Filled(Vec<Vec2>, usize),
}

impl LanePoints<'_> {
    /// Every lane's point `j`.
    #[inline(always)]
    fn get(&mut self, j: u32) -> (F32Lanes, F32Lanes) {
        match self {
            Self::Grid(points, _) => {
                let p = points.get(j as usize);
                (F32Lanes::splat(p.x), F32Lanes::splat(p.y))
            }
            Self::Sobol(sequences, n) => sequences.points(j, *n),
            Self::Hashed(points) => {
                let p = points[j as usize];
                (p.x, p.y)
            }
            Self::Uniform(rngs, _, _) => rngs.uniform2(),
            Self::Filled(points, n) => {
                let p = |k: usize| points[k * *n + j as usize];
                (lanes::from_fn(|k| p(k).x), lanes::from_fn(|k| p(k).y))
            }
        }
    }

    /// The lanes that did not draw keep their streams; the buffers go back
    /// to `ctx`.
    #[inline(always)]
    fn finish<T: Tracer>(self, ctx: &mut SampleContext<T>) {
        match self {
            Self::Grid(points, of) => *of.buffer(ctx) = points,
            Self::Sobol(..) => {}
            Self::Hashed(points) => ctx.sobol_lanes = points,
            Self::Uniform(rngs, before, kept) if kept != 0 => {
                *rngs = Pcg32Lanes::select(kept, &before, rngs);
            }
            Self::Uniform(..) => {}
            Self::Filled(points, _) => ctx.lane_points = points,
        }
    }
}

/// The Sobol sequences of a chunk's runs of camera samples for one pair:
/// lane k's sample j is point `(sample + k')·n + j` of its pixel's sequence,
/// `k'` its place in its run, the points each sample alone takes of it.
struct RunSequences {
    /// Each run's sequence, its first point, and its first lane.
    runs: [(SobolSequence, u64, usize); LANES],
    count: usize,
}

impl RunSequences {
    /// The sequences of the runs holding a lane of `lanes`.
    fn new<T: Tracer>(
        samples: &LaneSamples,
        lanes: u32,
        pair: DimensionPair,
        n: u32,
        ctx: &mut SampleContext<T>,
    ) -> Self {
        let used = (u32::BITS - lanes.leading_zeros()) as usize;
        let count = samples.runs(used);
        let mut start = |run: usize| {
            let sobol = samples.run_start(run).sobol_points(pair, n);
            let sequence = ctx.sequences.sequence(sobol);
            (sequence, sobol.first, run * samples.per_pixel)
        };
        let mut runs = [start(0); LANES];
        for (run, entry) in runs.iter_mut().enumerate().take(count).skip(1) {
            *entry = start(run);
        }
        Self { runs, count }
    }

    /// Every lane's light point `j` of `n`.
    #[inline]
    fn points(&self, j: u32, n: u32) -> (F32Lanes, F32Lanes) {
        let (sequence, first, _) = self.runs[0];
        let mut u = sequence.lanes_strided(first + u64::from(j), u64::from(n));
        for &(sequence, first, lane) in &self.runs[1..self.count] {
            let run = sequence.lanes_strided_from(first + u64::from(j), u64::from(n), lane);
            let from_run = lanes::from_bits(u32::MAX << lane);
            u.x = Float::select(from_run, run.x, u.x);
            u.y = Float::select(from_run, run.y, u.y);
        }
        (u.x, u.y)
    }
}

/// The reflected rays of the lanes `wave`, all on one sphere or
/// parallelogram, made in their own lanes: `reflect_differential`'s
/// direction and `spawn_ray`'s origin, from the surface points of
/// [`ShadedLanes::on_one_object`] (no texture coordinates, so no `acos` and
/// `atan2` a lane). None where the lanes lie on several objects or others.
fn reflected_in_place(
    scene: &Scene,
    rays: &RayLanes,
    closest: &ClosestLanes,
    wave: u32,
) -> Option<RayLanes> {
    let object = closest.common_object(wave)?;
    let surface = match scene.shapes.object(object) {
        ObjectRef::Shape(Shape::Sphere(s)) => s.surface_points_lanes(rays, closest.t, 0),
        ObjectRef::Shape(Shape::Parallelogram(p)) => p.surface_points_lanes(rays, closest.t),
        _ => return None,
    };
    let (d, g) = (&rays.direction, &surface.normal);
    let n = Vec3Lanes::select(lanes::gt(g.dot(d), F32Lanes::ZERO), &-*g, g);
    let wo = -d.normalize();
    let wi = n.scale(F32Lanes::splat(2.0) * wo.dot(&n)) - wo;
    let from_back = lanes::lt(wi.dot(g), F32Lanes::ZERO);
    let outgoing = Vec3Lanes::select(from_back, &-*g, g);
    Some(RayLanes {
        origin: offset_ray_origins(&surface.point, &surface.error, &outgoing),
        direction: wi,
    })
}

/// The rays the lanes `traced` of `wave` reflect into, each in its own lane
/// as `li_at` makes it ([`mirror_ray`]), and the lanes that hold one. With
/// differentials where the wave carries them (the scene reads footprints);
/// without, all at once where the lanes lie on one sphere or wall
/// ([`reflected_in_place`]), else lane by lane. The other lanes hold the
/// wave's own rays, whose answers are not read.
fn reflected_rays(
    scene: &Scene,
    wave: &Wave,
    traced: u32,
) -> (RayLanes, Option<[RayDifferential; LANES]>, u32) {
    if wave.diffs.is_none() {
        if let Some(rays) = reflected_in_place(scene, wave.rays, wave.closest, traced) {
            return (rays, None, traced);
        }
    }
    let (mut rays, mut diffs, mut reflected) = (*wave.rays, wave.diffs.copied(), 0);
    for k in lanes::each_set(traced) {
        let ray = wave.rays.lane(k);
        let found = wave.closest.hit(k).expect("a hit lane");
        let made = match &mut diffs {
            Some(diffs) => scene.shapes.surface_record(&ray, found).map(|hit| {
                let (reflected, diff) = mirror_ray(&hit, &ray, &diffs[k]);
                diffs[k] = diff;
                reflected
            }),
            // `mirror_ray`'s ray, without the derivatives a sphere's full
            // record costs.
            None => scene.shapes.surface_point(&ray, found).map(|hit| {
                let wi = reflect(-ray.direction.normalize(), hit.facing_normal(ray.direction));
                spawn_ray(&hit, wi)
            }),
        };
        if let Some(made) = made {
            rays.origin.set_lane(k, made.origin);
            rays.direction.set_lane(k, made.direction);
            reflected |= 1 << k;
        }
    }
    (rays, diffs, reflected)
}

/// A wave of rays in [`LANES`], `depth` reflections deep: the lanes
/// `lanes` hold one, with its differentials where the scene reads
/// footprints, and its closest hit.
struct Wave<'a> {
    rays: &'a RayLanes,
    diffs: Option<&'a [RayDifferential; LANES]>,
    closest: &'a ClosestLanes,
    lanes: u32,
    depth: u32,
}

/// The hit lanes of a wave on mirrors: each one's reflectivity `r` (zero
/// elsewhere) and tint, and those that reflect all (`r = 1`, with no local
/// shading).
struct Mirrors {
    reflectivity: F32Lanes,
    tint: Vec3Lanes,
    lanes: u32,
    perfect: u32,
}

impl Mirrors {
    /// The mirrors among the lanes `hit_lanes`, which landed on `hits`.
    #[inline(always)]
    fn of(scene: &Scene, closest: &ClosestLanes, hit_lanes: u32, hits: &FirstHits) -> Self {
        let mut mirrors = Self {
            reflectivity: F32Lanes::ZERO,
            tint: Vec3Lanes::default(),
            lanes: 0,
            perfect: 0,
        };
        match hits {
            FirstHits::OnOneObject(_, _, m) if m.reflectivity > 0.0 => {
                mirrors.reflectivity = F32Lanes::splat(m.reflectivity);
                mirrors.tint = Vec3Lanes::splat(m.mirror_tint);
                mirrors.lanes = hit_lanes;
                if !m.has_local_shading() {
                    mirrors.perfect = hit_lanes;
                }
                return mirrors;
            }
            FirstHits::OnOneObject(..) | FirstHits::OnOneEmitter(_) => return mirrors,
            FirstHits::Several => {}
        }
        if !scene.materials.iter().any(|m| m.reflectivity > 0.0) {
            return mirrors;
        }
        let mut r = [0.0; LANES];
        for k in lanes::each_set(hit_lanes) {
            let SurfaceKind::Material(m) =
                scene.surface_of_primitive(closest.object[k], closest.primitive[k])
            else {
                continue;
            };
            if m.reflectivity > 0.0 {
                r[k] = m.reflectivity;
                mirrors.tint.set_lane(k, m.mirror_tint);
                mirrors.lanes |= 1 << k;
                if !m.has_local_shading() {
                    mirrors.perfect |= 1 << k;
                }
            }
        }
        mirrors.reflectivity = F32Lanes::new(r);
        mirrors
    }
}

/// What a chunk's hit lanes landed on, as far as shading them together goes.
enum FirstHits<'a> {
    /// All on one sphere, parallelogram or plane (its object index) of a
    /// material whose textures need no footprint.
    OnOneObject(u32, &'a Shape, &'a PhongMaterial),
    /// All on one emitter: an area light's colour, or nothing.
    OnOneEmitter(&'a AreaLight),
    /// On several objects, other shapes, a footprint's material, or none.
    Several,
}

impl<'a> FirstHits<'a> {
    #[inline(always)]
    fn of(scene: &'a Scene, closest: &ClosestLanes, hit_lanes: u32) -> Self {
        let Some(object) = closest.common_object(hit_lanes) else {
            return Self::Several;
        };
        let shape = match scene.shapes.object(object) {
            ObjectRef::Shape(
                shape @ (Shape::Sphere(_) | Shape::Parallelogram(_) | Shape::Plane(_)),
            ) => shape,
            _ => return Self::Several,
        };
        match scene.surface_of_primitive(object, 0) {
            // Its footprints need each lane's surface record: one by one.
            SurfaceKind::Material(material) if material.uses_footprint() => Self::Several,
            SurfaceKind::Material(material) => Self::OnOneObject(object, shape, material),
            SurfaceKind::Emitter(Light::Area(area)) => Self::OnOneEmitter(area),
            SurfaceKind::Emitter(_) => Self::Several,
        }
    }
}

/// Counts `n` samples of one light at each lane of `shaded`, those of the
/// lanes outside `lit` as skipped behind the light, as `li_at` counts them.
fn count_light_samples(counters: &mut ShadingCounters, n: u32, shaded: u32, lit: u32) {
    counters.light_samples += u64::from(n) * u64::from(shaded.count_ones());
    counters.light_skips.behind_light += u64::from(n) * u64::from((shaded & !lit).count_ones());
}

/// The shading points of up to [`LANES`] lanes: all at once where the lanes hit
/// one shape ([`ShadedLanes::on_one_object`]), else one by one ([`ShadedLanes::set`]).
#[derive(Default)]
struct ShadedLanes<'a> {
    /// The lanes holding a point (bit k for lane k).
    lanes: u32,
    point: Vec3Lanes,
    /// The error bound of `point` ([`glint_geometry::Hit::error`]).
    error: Vec3Lanes,
    geometric_normal: Vec3Lanes,
    /// The geometric normals on the viewer's side.
    ng: Vec3Lanes,
    phong: PhongLanes<'a>,
    /// The shadow rays' origins, once the lanes are set.
    origins: ShadowOrigins,
    /// The one object every lane is on, where set together.
    object: Option<u32>,
    /// Each lane's object, where set one by one.
    objects: [u32; LANES],
    /// The reflections the camera rays took to the points.
    depth: u32,
}

/// The points of [`ShadedLanes`] offset to either side of their surfaces, the
/// origins of their shadow rays: each side made when a shadow ray first
/// leaves on it, once for all the light samples. Most points' shadow rays
/// all leave on the viewer's side.
#[derive(Default)]
struct ShadowOrigins {
    front: OnceCell<Vec3Lanes>,
    back: OnceCell<Vec3Lanes>,
}

impl<'a> ShadedLanes<'a> {
    /// The shading points of the lanes `hit_lanes`, set one by one
    /// ([`Self::set_one_by_one`]), with their shadow rays' origins.
    fn one_by_one<T: Tracer>(
        scene: &'a Scene,
        hits: (&RayLanes, Option<&[RayDifferential; LANES]>, &ClosestLanes),
        (hit_lanes, depth): (u32, u32),
        radiance: &mut Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) -> Self {
        let mut shaded = Self {
            depth,
            ..Self::default()
        };
        shaded.set_one_by_one(scene, hits, hit_lanes, radiance, ctx);
        shaded
    }

    /// The lanes of `hit_lanes` set one by one: each lane's surface point,
    /// its emitted light or ambient term in `radiance`, and its shading point.
    /// A material that filters its textures over a footprint is looked up
    /// over the lane's ray differentials (`diffs`; none without), from the
    /// hit's full surface record, as `li_at` looks it up.
    fn set_one_by_one<T: Tracer>(
        &mut self,
        scene: &'a Scene,
        (rays, diffs, closest): (&RayLanes, Option<&[RayDifferential; LANES]>, &ClosestLanes),
        hit_lanes: u32,
        radiance: &mut Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) {
        for k in lanes::each_set(hit_lanes) {
            let ray = rays.lane(k);
            let found = closest.hit(k).expect("a hit lane");
            let Some(hit) = scene.shapes.surface_point(&ray, found) else {
                continue;
            };
            match scene.surface_of(&hit) {
                SurfaceKind::Emitter(light) => {
                    let emitted = light.emitted();
                    ctx.tracer
                        .record(1 << k, |_| Event::Emitter { radiance: emitted });
                    radiance.set_lane(k, emitted);
                }
                SurfaceKind::Material(material) if material.uses_footprint() => {
                    let Some(hit) = scene.shapes.surface_record(&ray, found) else {
                        continue;
                    };
                    ctx.counters.footprints += 1;
                    let diff = diffs.map_or_else(|| RayDifferential::none(&ray), |d| d[k]);
                    let tc = texture_footprint(scene, material, (&hit, self.depth), &ray, &diff);
                    if ctx.detailed {
                        ctx.textures.record(material, &tc);
                    }
                    let point = ShadingPoint::new(&hit, material, &ray, &tc);
                    radiance.set_lane(k, scene.ambient * point.kd);
                    self.set(k, &point, material);
                }
                SurfaceKind::Material(material) => {
                    if ctx.detailed {
                        ctx.textures.record(material, &TexCoord::point(hit.uv));
                    }
                    let reflectances = material.reflectances_at(hit.uv);
                    let point = ShadingPoint::with_reflectances(&hit, material, &ray, reflectances);
                    radiance.set_lane(k, scene.ambient * point.kd);
                    self.set(k, &point, material);
                }
            }
        }
        // Lanes shaded on one object share one culling of occluders.
        self.object = closest.common_object(self.lanes);
    }

    /// Puts `p`, of `material`, in lane `k`.
    fn set(&mut self, k: usize, p: &ShadingPoint, material: &'a PhongMaterial) {
        self.phong
            .set(k, material, p.kd, p.ks, p.n, p.v, p.has_specular);
        self.lanes |= 1 << k;
        self.objects[k] = p.hit.shape;
        self.point.set_lane(k, p.hit.point);
        self.error.set_lane(k, p.hit.error);
        self.geometric_normal.set_lane(k, p.hit.geometric_normal);
        self.ng.set_lane(k, p.ng);
    }

    /// The shading points of the lanes `hit_lanes`, all on `object`, a sphere
    /// or parallelogram of `material` (most of a pixel's samples), made all at
    /// once: each lane what [`Self::set`] gives it from its [`ShadingPoint`],
    /// and `radiance` its ambient part.
    fn on_one_object<T: Tracer>(
        scene: &'a Scene,
        rays: &RayLanes,
        closest: &ClosestLanes,
        hit_lanes: u32,
        (object, shape, material): (u32, &Shape, &'a PhongMaterial),
        radiance: &mut Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) -> Self {
        // A sphere's texture coordinates cost an `acos` and an `atan2` a lane:
        // only where the material reads them, and not for checks.
        let checks = match shape {
            Shape::Sphere(_) if !ctx.detailed => SphereChecks::of(material),
            _ => None,
        };
        let uv_lanes = match material.reads_uv() && checks.is_none() {
            true => hit_lanes,
            false => 0,
        };
        let surface = match shape {
            Shape::Sphere(s) => s.surface_points_lanes(rays, closest.t, uv_lanes),
            Shape::Parallelogram(p) => p.surface_points_lanes(rays, closest.t),
            Shape::Plane(p) => p.surface_points_lanes(rays, closest.t),
            _ => unreachable!("FirstHits::of admits spheres, parallelograms and planes"),
        };
        let (kd, ks) = match &checks {
            Some(checks) => checks.reflectances_lanes(material, &surface.normal, hit_lanes),
            None => reflectances_lanes(material, &surface, hit_lanes, ctx),
        };
        // `ShadingPoint::with_reflectances`: the normal turned to the viewer, the
        // geometric normal to its side, and the unit direction to the viewer.
        let d = &rays.direction;
        let g = &surface.normal;
        let n = Vec3Lanes::select(lanes::gt(g.dot(d), F32Lanes::ZERO), &-*g, g);
        let ng = Vec3Lanes::select(lanes::lt(g.dot(&n), F32Lanes::ZERO), &-*g, g);
        let v = -d.normalize();
        let specular = hit_lanes & !lanes::bits(ks.is_zero());
        let ambient = Vec3Lanes::scaled_splat_lanes(scene.ambient, &kd);
        *radiance = Vec3Lanes::select(lanes::from_bits(hit_lanes), &ambient, radiance);
        Self {
            lanes: hit_lanes,
            origins: ShadowOrigins::default(),
            point: surface.point,
            error: surface.error,
            geometric_normal: surface.normal,
            ng,
            phong: PhongLanes::of_lanes(hit_lanes, material, &kd, &ks, &n, &v, specular),
            object: Some(object),
            objects: [object; LANES],
            depth: 0,
        }
    }

    /// The shapes that may block the lanes' shadow rays to area light `index`,
    /// as [`DirectIntegrator::occluders`] culls them for one point: from a
    /// centre, widened by a reach that holds every lane's point, where the
    /// lanes lie on one object; every shape but the light's otherwise.
    fn occluders<T: Tracer>(
        &self,
        scene: &Scene,
        index: usize,
        light: &AreaLight,
        ctx: &mut SampleContext<T>,
    ) -> Occluders {
        let light_object = scene.light_objects[index];
        let Some(object) = self.object else {
            // Lanes on several surfaces: the light's own is left out here,
            // each lane's own by its shadow rays (`blocked`).
            return scene.shapes.occluders_but([light_object, light_object]);
        };
        let farthest_from = |center: Vec3| {
            let offsets = self.point.sub_splat(center);
            lanes::max_lane(offsets.dot(&offsets).sqrt(), lanes::from_bits(self.lanes))
        };
        if let Some(cached) = ctx.lane_occluders {
            let same = (cached.light, cached.object) == (index, object);
            if same && farthest_from(cached.center) <= cached.reach {
                return cached.occluders;
            }
        }
        let center = self.point.lane(self.lanes.trailing_zeros() as usize);
        // A tenth wider than the farthest lane (far past the rounding of the
        // distances, which the reach must not fall short of), and at least
        // the one-point culling's reach, so that the chunks of the pixels
        // around reuse it.
        let reach = (farthest_from(center) * 1.1)
            .max(CULL_REACH * center.distance(light.surface().center()));
        let occluders = scene.shapes.occluders_towards(
            center,
            reach,
            &light.surface().corners(),
            [object, light_object],
        );
        ctx.lane_occluders = Some(LaneOccluders {
            light: index,
            object,
            center,
            reach,
            occluders,
        });
        occluders
    }

    /// Per lane, the Phong reflection of the light point at `(ux, uy)` on `light`, or
    /// zero where it is behind the light, below the surface, reflects nothing or
    /// is blocked: `unoccluded_reflection` of the scalar path, with its counts.
    fn area_light<T: Tracer>(
        &self,
        scene: &Scene,
        light: &AreaLight,
        occluders: &Occluders,
        (ux, uy): (F32Lanes, F32Lanes),
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let reflect = |l: &Vec3Lanes| self.phong.reflect(l);
        let s = LightSampleLanes::new(light, (ux, uy), &self.point, &self.ng, self.lanes, reflect);
        self.unoccluded(scene, &s, &light.shadow_ends(&s.position), occluders, ctx)
    }

    /// Per lane, the Phong reflection of point light `light`, or zero where it
    /// is below the surface, reflects nothing or is blocked: the scalar path's
    /// `unoccluded_reflection` towards the exact point, with its counts.
    fn point_light<T: Tracer>(
        &self,
        scene: &Scene,
        light: &PointLight,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let reflect = |l: &Vec3Lanes| self.phong.reflect(l);
        let position = Vec3Lanes::splat(light.position);
        let s = LightSampleLanes::at(position, &self.point, &self.ng, self.lanes, reflect);
        self.unoccluded(scene, &s, &position, &Occluders::ALL, ctx)
    }

    /// Per lane, physical shading's `I · kd/π · cos θ / r²` of point light
    /// `light` at a diffuse point, or zero where it is below the surface or
    /// blocked: the scalar path's `point_light`, bit for bit, with its counts
    /// (but the samples', which the caller counts).
    #[inline(never)]
    fn physical_point_light<T: Tracer>(
        &self,
        scene: &Scene,
        light: &PointLight,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let position = Vec3Lanes::splat(light.position);
        // A density of 1 leaves each lane's `f · cos θ` as it is.
        let (f, traced) = self.light_samples(&position, F32Lanes::ONE, (self.lanes, 0), ctx);
        let towards = position - self.point;
        let visible = traced & !self.blocked(scene, &Occluders::ALL, &position, &towards, traced);
        if T::ON {
            self.trace_point_light(scene, &position, [traced, visible], ctx);
        }
        let distance2 = towards.dot(&towards);
        let lit = Vec3Lanes::scaled_splat_lanes(light.color, &f);
        let value = Vec3Lanes::new(lit.x / distance2, lit.y / distance2, lit.z / distance2);
        Vec3Lanes::select(lanes::from_bits(visible), &value, &Vec3Lanes::default())
    }

    /// The light samples at `position` with solid-angle densities `pdf`, one
    /// a lane, in the lanes `used`, short of their shadow rays: each lane's
    /// `f · cos θ · w / p` (`ShadingPoint::light_sample_unshadowed` bit for
    /// bit, `w` the power heuristic's weight in the lanes `mis`, else 1) and
    /// the lanes that need a shadow ray, the others counted as skipped.
    #[inline(always)]
    fn light_samples<T: Tracer>(
        &self,
        position: &Vec3Lanes,
        pdf: F32Lanes,
        (used, mis): (u32, u32),
        ctx: &mut SampleContext<T>,
    ) -> (Vec3Lanes, u32) {
        if used & self.phong.specular_lanes() != 0 {
            return self.glossy_light_samples(position, pdf, (used, mis), &mut ctx.counters);
        }
        (self.diffuse_points()).light_samples(position, pdf, used, &mut ctx.counters)
    }

    /// The lanes' points as diffuse ones, for their kernel.
    #[inline(always)]
    fn diffuse_points(&self) -> DiffusePoints<'_> {
        DiffusePoints {
            point: &self.point,
            ng: &self.ng,
            n: self.phong.normals(),
            kd: self.phong.kd(),
        }
    }

    /// [`Self::light_samples`] where some lanes of `used` are glossy.
    #[inline(never)]
    fn glossy_light_samples(
        &self,
        position: &Vec3Lanes,
        pdf: F32Lanes,
        (used, mis): (u32, u32),
        counters: &mut ShadingCounters,
    ) -> (Vec3Lanes, u32) {
        let at = self.diffuse_points();
        let s = at.unshadowed_by(position, pdf, used, counters, |l| self.phong.brdf_cos(l));
        let glossy = s.evaluated & self.phong.specular_lanes();
        counters.specular_lobes += u64::from(glossy.count_ones());
        let (n, v) = (self.phong.normals(), self.phong.viewers());
        let lobe_pdf = specular_pdf_at(self.phong.lobes(), n, &s.l, v);
        let weighted = lanes::from_bits(s.reflects & mis);
        let weights = F32Lanes::select(weighted, power_heuristic(pdf, lobe_pdf), F32Lanes::ONE);
        (s.f_cos.scale(weights / pdf), s.reflects)
    }

    /// One direction drawn from each lane's lobe, of the glossy lanes `mis`,
    /// at its point of `u`: the unit directions, their densities and the
    /// lanes that drew one with a positive, finite density (the others
    /// counted as the lobe's zero-density skips).
    fn lobe_directions(
        &self,
        u: (F32Lanes, F32Lanes),
        mis: u32,
        counters: &mut ShadingCounters,
    ) -> (Vec3Lanes, F32Lanes, u32) {
        let (lobes, n, v) = (
            self.phong.lobes(),
            self.phong.normals(),
            self.phong.viewers(),
        );
        let (l, sampled) = sample_specular_at(lobes, n, v, u);
        let pdf = specular_pdf_at(lobes, n, &l, v);
        let positive = pdf.gt(F32Lanes::ZERO) & pdf.is_finite();
        let drawn = mis & lanes::bits(sampled & positive);
        counters.lobe_skips.zero_density += u64::from((mis & !drawn).count_ones());
        let drawn_lanes = lanes::from_bits(drawn);
        (
            Vec3Lanes::select(drawn_lanes, &l, &Vec3Lanes::default()),
            F32Lanes::select(drawn_lanes, pdf, F32Lanes::ZERO),
            drawn,
        )
    }

    /// Each lane's `f · cos θ` towards its lobe direction `l`, and the
    /// lanes of `drawn` that need a ray along it: above the geometric
    /// surface, with a reflection (the others counted as the lobe's skips),
    /// counted.
    fn lobe_reflections(
        &self,
        l: &Vec3Lanes,
        drawn: u32,
        counters: &mut ShadingCounters,
    ) -> (Vec3Lanes, u32) {
        let above = drawn & lanes::bits(lanes::gt(l.dot(&self.ng), F32Lanes::ZERO));
        let f = self.phong.brdf_cos(l);
        let traced = above & !lanes::bits(f.is_zero());
        counters.lobe_skips.below_surface += u64::from((drawn & !above).count_ones());
        counters.lobe_skips.zero_brdf += u64::from((above & !traced).count_ones());
        counters.specular_lobes += u64::from(above.count_ones());
        counters.brdf_rays += u64::from(traced.count_ones());
        (f, traced)
    }

    /// The reflections of light samples `s` where their shadow rays, ending at
    /// `ends`, are not blocked by `occluders` (zero elsewhere), counted.
    #[inline(always)]
    fn unoccluded<T: Tracer>(
        &self,
        scene: &Scene,
        s: &LightSampleLanes,
        ends: &Vec3Lanes,
        occluders: &Occluders,
        ctx: &mut SampleContext<T>,
    ) -> Vec3Lanes {
        let specular = self.phong.specular_lanes();
        count_lanes(
            &mut ctx.counters,
            self.lanes,
            s.lit,
            s.shaded,
            s.traced,
            specular,
        );
        let visible = s.traced & !self.blocked(scene, occluders, ends, &s.towards, s.traced);
        if T::ON {
            let verdicts = [s.lit, s.shaded, s.traced, visible];
            self.trace_light_samples(scene, (&s.position, ends), verdicts, &s.reflected, ctx);
        }
        Vec3Lanes::select(
            lanes::from_bits(visible),
            &s.reflected,
            &Vec3Lanes::default(),
        )
    }

    /// The `traced` lanes whose shadow ray, from the point (offset to the side
    /// `towards` leaves on) to `end` (a light point off its surface), is
    /// blocked; lanes on several objects each leave their own flat surface
    /// out, as the one point's culling does.
    // Inlined: out of line, the light samples' lanes go through memory, and
    // reloading them costs a store-forwarding stall (measured: 1.1× the
    // time of `cornell-set1`, AMD EPYC).
    #[inline(always)]
    fn blocked(
        &self,
        scene: &Scene,
        occluders: &Occluders,
        end: &Vec3Lanes,
        towards: &Vec3Lanes,
        traced: u32,
    ) -> u32 {
        let origin = self.origins_towards(towards, traced);
        let rays = RayLanes {
            origin,
            direction: *end - origin,
        };
        match self.object {
            Some(_) => scene.shapes.any_hits_among(occluders, &rays, 1.0, traced),
            None => {
                (scene.shapes).any_hits_among_leaving(occluders, &rays, 1.0, traced, &self.objects)
            }
        }
    }

    /// Each lane's shadow-ray origin (of the lanes `traced`; the others'
    /// are any): its point offset to the side of its surface that `towards`
    /// leaves on, as `spawn_ray` and `spawn_ray_to` choose it.
    #[inline]
    fn origins_towards(&self, towards: &Vec3Lanes, traced: u32) -> Vec3Lanes {
        let g = &self.geometric_normal;
        let from_back = lanes::lt(towards.dot(g), F32Lanes::ZERO);
        let offset = |side: &OnceCell<Vec3Lanes>, normal: &Vec3Lanes| {
            *side.get_or_init(|| offset_ray_origins(&self.point, &self.error, normal))
        };
        let (front, back) = (&self.origins.front, &self.origins.back);
        match lanes::bits(from_back) & traced {
            0 => offset(front, g),
            leave_back if leave_back == traced => offset(back, &-*g),
            _ => Vec3Lanes::select(from_back, &offset(back, &-*g), &offset(front, g)),
        }
    }
}

/// `material`'s reflectances `(kd, ks)` at each lane's uv (the lanes of
/// `hit_lanes`; the others zero), as [`PhongMaterial::reflectances_at`] gives
/// them: constants in every lane at once, textures lane by lane.
fn reflectances_lanes<T: Tracer>(
    material: &PhongMaterial,
    surface: &SurfaceLanes,
    hit_lanes: u32,
    ctx: &mut SampleContext<T>,
) -> (Vec3Lanes, Vec3Lanes) {
    let (u, v) = (surface.u.to_array(), surface.v.to_array());
    let uv = |k: usize| Vec2::new(u[k], v[k]);
    if ctx.detailed {
        for k in lanes::each_set(hit_lanes) {
            ctx.textures.record(material, &TexCoord::point(uv(k)));
        }
    }
    let specular = material.specular.as_ref().map(Texture::as_constant);
    match (material.diffuse.as_constant(), specular) {
        (Some(kd), None) => (Vec3Lanes::splat(kd), Vec3Lanes::splat(kd)),
        (Some(kd), Some(Some(ks))) => (Vec3Lanes::splat(kd), Vec3Lanes::splat(ks)),
        _ => {
            let (mut kd, mut ks) = (Vec3Lanes::default(), Vec3Lanes::default());
            for k in lanes::each_set(hit_lanes) {
                let (d, s) = material.reflectances_at(uv(k));
                kd.set_lane(k, d);
                ks.set_lane(k, s);
            }
            (kd, ks)
        }
    }
}

/// A sphere's point-sampled checkerboard, read from each lane's normal: its
/// check found from polar angles in lanes ([`Sphere::uv_of_normals_approx`]),
/// and from libm's (the scalar path's texture coordinates) only in lanes
/// within the approximation's error of a check's edge. The check is then
/// the scalar path's, and so are the reflectances, bit for bit.
struct SphereChecks<'a> {
    board: &'a Checkerboard,
    /// The constant specular color, `None` where it is the diffuse one.
    ks: Option<Vec3>,
    /// The checks per unit of the sphere's u and v, at most.
    density: f32,
}

impl<'a> SphereChecks<'a> {
    /// The checks of `material`, if its diffuse color is a point-sampled
    /// checkerboard, its specular color none or a constant, and its checks
    /// few enough per unit of uv (at most [`Self::MAX_DENSITY`]) that the
    /// approximation's error stays far below a check.
    fn of(material: &'a PhongMaterial) -> Option<Self> {
        let Texture::Checkerboard(board) = &material.diffuse else {
            return None;
        };
        let ks = match &material.specular {
            None => None,
            Some(texture) => Some(texture.as_constant()?),
        };
        let density = board.checks as f32 * material.uv_transform.scale.abs().max_element();
        (!board.analytic && density <= Self::MAX_DENSITY).then_some(Self { board, ks, density })
    }

    const MAX_DENSITY: f32 = 64.0;

    /// `material.reflectances_at` each lane's uv on a sphere whose unit
    /// normals are `normal` (lanes of `hit_lanes`; the others' are any).
    fn reflectances_lanes(
        &self,
        material: &PhongMaterial,
        normal: &Vec3Lanes,
        hit_lanes: u32,
    ) -> (Vec3Lanes, Vec3Lanes) {
        let (u, v) = Sphere::uv_of_normals_approx(normal);
        let UvTransform { scale, offset } = material.uv_transform;
        let n = F32Lanes::splat(self.board.checks as f32);
        let cells = |c: F32Lanes, s: f32, o: f32| (c * F32Lanes::splat(s) + F32Lanes::splat(o)) * n;
        let (x, y) = (cells(u, scale.x, offset.x), cells(v, scale.y, offset.y));
        let error = F32Lanes::splat(2.0 * self.density * SPHERE_UV_APPROX_ERROR);
        // Away from every edge by more than the error (and the rounding of
        // `c`, a few of its ulps): the exact coordinate is in the same check.
        // A clear `c` has a fraction, so its floor is an exact `i32`.
        let clear = |c: F32Lanes| {
            let margin = error + c.abs() * F32Lanes::splat(1e-6);
            let f = c - c.floor();
            lanes::bits(lanes::gt(f, margin) & lanes::lt(f, F32Lanes::ONE - margin))
        };
        let parity = (x.floor().trunc_int() ^ y.floor().trunc_int()) & I32Lanes::splat(1);
        let odd = lanes::gt(parity.round_float(), F32Lanes::ZERO);
        let [even_color, odd_color] = self.board.colors.map(Vec3Lanes::splat);
        let mut kd = Vec3Lanes::select(odd, &odd_color, &even_color);
        let mut ks = self.ks.map_or(kd, Vec3Lanes::splat);
        for k in lanes::each_set(hit_lanes & !(clear(x) & clear(y))) {
            let (uv, _, _) = Sphere::uv_of_normal(normal.lane(k));
            let (d, s) = material.reflectances_at(uv);
            kd.set_lane(k, d);
            ks.set_lane(k, s);
        }
        (kd, ks)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SceneBuilder, ShadingCounters};
    use glam::UVec2;
    use glam::Vec3;
    use glint_camera::Camera;
    use glint_geometry::{Parallelogram, Ray, RayDifferential, Sphere};
    use glint_lighting::SpecularLobe;
    use glint_texture::{Checkerboard, Texture};

    /// A room (floor, back wall, one-sided ceiling) with four spheres in
    /// materials that take every path of the Phong lanes, lit by two area
    /// lights: one facing down into the room, one facing the back wall from
    /// in front of the camera's view, so that each is behind some points.
    fn room() -> Scene {
        room_with(|_| {})
    }

    /// A lat-long map with a bright patch, sampled by luminance.
    fn sky() -> EnvironmentLight {
        sky_of(1)
    }

    /// [`sky`] at `scale` times its 32 × 16 texels, the patch striped across
    /// its texels so that a lookup filtered over a footprint differs from
    /// the texel's own.
    fn sky_of(scale: u32) -> EnvironmentLight {
        let image = glint_texture::Image::from_fn(32 * scale, 16 * scale, |x, y| {
            let (x, stripe) = (x / scale, (x + y) % 2 == 0);
            let bright = (10..14).contains(&x) && (3..6).contains(&(y / scale));
            let shade = if stripe { 1.0 } else { 0.25 };
            Vec3::new(0.2 + 0.01 * x as f32, 0.3, 0.4 * shade) * if bright { 40.0 } else { 1.0 }
        });
        let map = glint_texture::Environment::LatLong(glint_texture::LatLongMap::new(image));
        EnvironmentLight::new(map, 0.3, 1.5)
    }

    /// [`room`] with what `more` adds to it.
    fn room_with(more: impl FnOnce(&mut SceneBuilder)) -> Scene {
        let mut b = SceneBuilder::new();
        let checks = b.material(PhongMaterial::new(
            Checkerboard::new(Vec3::new(0.9, 0.2, 0.1), Vec3::new(0.1, 0.3, 0.8), 4),
            22.0,
        ));
        let gray = b.material(PhongMaterial::new(Vec3::splat(0.7), 16.0));
        let blinn = b.material(PhongMaterial {
            lobe: SpecularLobe::BlinnPhong,
            ..PhongMaterial::new(Vec3::new(0.2, 0.4, 0.9), 40.0)
        });
        let fractional = b.material(PhongMaterial::new(Vec3::new(0.6, 0.6, 0.1), 7.5));
        let matte = b.material(PhongMaterial {
            specular: Some(Texture::Constant(Vec3::ZERO)),
            ..PhongMaterial::new(Vec3::new(0.3, 0.8, 0.3), 1.0)
        });
        // Reflects nothing: no shadow ray is traced.
        let black = b.material(PhongMaterial {
            specular: Some(Texture::Constant(Vec3::ZERO)),
            ..PhongMaterial::new(Vec3::ZERO, 1.0)
        });
        let wall = |origin: Vec3, e1: Vec3, e2: Vec3, facing: Vec3| {
            Parallelogram::new(origin, e1, e2, false)
                .unwrap()
                .facing(facing)
        };
        b.shape(
            wall(
                Vec3::new(-5.0, -2.0, -9.0),
                Vec3::X * 10.0,
                Vec3::Z * 12.0,
                Vec3::Y,
            ),
            gray,
        )
        .shape(
            wall(
                Vec3::new(-5.0, -2.0, -9.0),
                Vec3::X * 10.0,
                Vec3::Y * 8.0,
                Vec3::Z,
            ),
            checks,
        )
        .shape(
            wall(
                Vec3::new(-5.0, 4.0, -9.0),
                Vec3::X * 10.0,
                Vec3::Z * 12.0,
                -Vec3::Y,
            ),
            matte,
        )
        .shape(
            Sphere::new(Vec3::new(-2.0, -1.0, -5.0), 1.0).unwrap(),
            checks,
        )
        .shape(Sphere::new(Vec3::new(0.5, 0.0, -6.0), 1.2).unwrap(), blinn)
        .shape(
            Sphere::new(Vec3::new(2.5, -1.2, -4.0), 0.8).unwrap(),
            fractional,
        )
        .shape(Sphere::new(Vec3::new(0.0, 2.5, -7.0), 0.6).unwrap(), black);
        // Large enough that some pixels see nothing else.
        let down = AreaLight::new(
            Vec3::new(0.0, 3.9, -5.0),
            Vec3::X * 3.0,
            Vec3::Z * 3.0,
            Vec3::ONE,
        )
        .unwrap()
        .facing(-Vec3::Y);
        let back = AreaLight::new(
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::X * 0.5,
            Vec3::Y * 0.5,
            Vec3::new(0.8, 0.6, 0.3),
        )
        .unwrap()
        .facing(-Vec3::Z);
        b.area_light(down).area_light(back);
        b.ambient(Vec3::splat(0.05));
        more(&mut b);
        let camera = Camera::new(
            Vec3::new(0.0, 1.0, 3.0),
            Vec3::new(0.0, 0.0, -5.0),
            Vec3::Y,
            70.0,
            1.0,
            UVec2::new(12, 10),
        )
        .unwrap();
        b.build(camera).unwrap()
    }

    /// Every camera sample of every pixel, in chunks of [`LANES`] (and of three
    /// and one, partly filled): the lanes give each sample's `li_at` radiance
    /// and the shading counts bit for bit, for every light pattern.
    /// The room's checkered material filtered over each ray's footprint.
    fn checks_over_footprints(scene: &mut Scene) {
        scene.materials[0].diffuse = Texture::Checkerboard(Checkerboard {
            analytic: true,
            ..Checkerboard::new(Vec3::new(0.9, 0.2, 0.1), Vec3::new(0.1, 0.3, 0.8), 4)
        });
    }

    /// Every lane of [`DirectIntegrator::li_first_hits`] against `li_at` for
    /// its sample alone, bit for bit, radiance and counts, over every pixel
    /// of `scene` and several shapes of chunk; the samples compared, with
    /// the counts added to `total` and the chunks' kinds to `common`.
    fn compare_lanes_with_scalar(
        scene: &Scene,
        integrator: &DirectIntegrator,
        footprints: bool,
        total: &mut ShadingCounters,
        common: &mut [usize; 3],
    ) -> usize {
        let (pattern, light_samples) = (integrator.light_pattern, integrator.light_samples);
        let resolution = scene.camera.resolution();
        let mut compared = 0;
        // One context for every chunk, as a render's thread keeps it: the
        // lanes' culling of occluders serves the chunks near it.
        let mut lanes = SampleContext::new(light_samples, integrator.environment_samples);
        for pixel in 0..(resolution.x * resolution.y) as u64 {
            let (x, y) = (pixel % resolution.x as u64, pixel / resolution.x as u64);
            // One pixel's chunks (full, three lanes, one), then runs of
            // several pixels' samples: four of four, a lane's worth of one,
            // and runs of four partly used (eleven lanes of sixteen).
            for (chunk, used, per_pixel) in [
                (0u64, LANES, LANES),
                (1, 3, LANES),
                (2, 1, LANES),
                (0, LANES, 4),
                (0, LANES, 1),
                (1, LANES - 5, 4),
            ] {
                let cameras: [(Ray, RayDifferential); LANES] = std::array::from_fn(|k| {
                    let n = LANES as f32;
                    let jitter = ((k as f32 + 0.5) / n, ((k * 5 % LANES) as f32 + 0.5) / n);
                    let raster = glam::Vec2::new(x as f32 + jitter.0, y as f32 + jitter.1);
                    if footprints {
                        crate::camera_ray(&scene.camera, raster, 0.25)
                    } else {
                        let c = scene.camera.generate_ray(raster.x, raster.y);
                        let ray = Ray::new(c.origin, c.direction);
                        (ray, RayDifferential::none(&ray))
                    }
                });
                let rays = cameras.map(|(ray, _)| ray);
                let diffs = cameras.map(|(_, diff)| diff);
                let ray_lanes = RayLanes::new(rays);
                let closest = scene.shapes.closest_lanes(&ray_lanes, used);
                let hit_lanes = closest.hits & ((1 << used) - 1);
                match closest.common_object(hit_lanes) {
                    Some(object) if scene.light_objects.contains(&object) => common[2] += 1,
                    Some(_) => common[1] += 1,
                    None => common[0] += 1,
                }
                let samples = LaneSamples {
                    seed: 11,
                    first: chunk * per_pixel as u64,
                    per_pixel,
                    pixels: std::array::from_fn(|run| pixel + 1000 * run as u64),
                };
                lanes.counters = ShadingCounters::default();
                let values = integrator.li_first_hits(
                    scene,
                    &ray_lanes,
                    footprints.then_some(&diffs),
                    &closest,
                    used,
                    &samples,
                    &mut lanes,
                );
                let mut scalar = SampleContext::new(light_samples, integrator.environment_samples);
                for (k, ray) in rays.iter().enumerate().take(used) {
                    let sample = samples.lane(k);
                    scalar.begin_sample(sample.seed, sample.pixel, sample.sample);
                    let hit = scene.shapes.closest_hit(ray, f32::INFINITY);
                    let expected = integrator.li_at(scene, ray, &diffs[k], hit, 0, &mut scalar);
                    assert_eq!(
                        values.lane(k).to_array().map(f32::to_bits),
                        expected.to_array().map(f32::to_bits),
                        "{pattern:?} × {light_samples}, pixel ({x}, {y}), {sample:?}: {} against {expected}",
                        values.lane(k)
                    );
                    compared += 1;
                }
                assert_eq!(
                    lanes.counters, scalar.counters,
                    "{pattern:?} × {light_samples}, pixel ({x}, {y})"
                );
                *total += scalar.counters;
            }
        }
        compared
    }

    #[test]
    fn lanes_give_each_samples_radiance_and_counts_bit_for_bit() {
        let mut total = ShadingCounters::default();
        // Chunks whose lanes hit several objects, one shape, one light.
        let mut common = [0; 3];
        // The last cases put the room under the sky, with a mirror, a half
        // mirror and a box: each miss's lookup filtered over its footprint,
        // each mirror's reflections, with their differentials, the next wave.
        // With mirrors, reflections are followed four deep, or one (a
        // mirror seen in a mirror is then black).
        for (pattern, light_samples, footprints, sky_and_mirrors, max_depth) in [
            (SamplePattern::Random, 1, false, false, 4),
            (SamplePattern::Stratified, 1, false, false, 4),
            (SamplePattern::Sobol, 1, false, false, 4),
            (SamplePattern::Grid, 1, false, false, 4),
            (SamplePattern::Random, 3, false, false, 4),
            (SamplePattern::Sobol, 5, false, false, 4),
            (SamplePattern::Grid, 4, false, false, 4),
            (SamplePattern::Sobol, 1, true, false, 4),
            (SamplePattern::Random, 4, true, false, 4),
            (SamplePattern::Random, 1, false, true, 4),
            (SamplePattern::Sobol, 4, true, true, 4),
            (SamplePattern::Random, 3, false, true, 1),
            // Stratified points of a square count, and of another (a Latin
            // hypercube), drawn lane by lane; the grid's under the sky.
            (SamplePattern::Stratified, 4, false, false, 4),
            (SamplePattern::Stratified, 3, true, true, 4),
            (SamplePattern::Grid, 4, false, true, 4),
        ] {
            let mut scene = match sky_and_mirrors {
                false => room(),
                true => room_with(|b| {
                    let material = b.material(PhongMaterial::new(Vec3::new(0.5, 0.4, 0.7), 8.0));
                    let aabox = glint_geometry::AaBox::new(
                        Vec3::new(1.0, -2.0, -8.5),
                        Vec3::new(3.5, 0.5, -7.0),
                    );
                    b.shape(aabox.unwrap(), material);
                }),
            };
            if sky_and_mirrors {
                scene.environment = Some(sky_of(8));
                scene.materials[2].reflectivity = 1.0;
                scene.materials[3].reflectivity = 0.5;
            }
            if light_samples > 1 {
                // Two point lights too, after the area light.
                let point = |position| {
                    Light::Point(glint_lighting::PointLight {
                        position,
                        color: Vec3::new(0.5, 0.4, 0.3),
                    })
                };
                scene.lights.push(point(Vec3::new(-2.0, 3.0, -3.0)));
                scene.lights.push(point(Vec3::new(2.5, 0.0, -1.0)));
            }
            if footprints {
                checks_over_footprints(&mut scene);
            }
            // Under the sky, its points in the lights' pattern.
            let integrator = DirectIntegrator {
                light_samples,
                light_pattern: pattern,
                environment_samples: 4,
                environment_pattern: match sky_and_mirrors {
                    true => pattern,
                    false => SamplePattern::Sobol,
                },
                environment_sampling: glint_lighting::EnvironmentSampling::Luminance,
                max_depth,
                area_sampling: glint_lighting::AreaSampling::Auto,
                mis: true,
            };
            let differentials = footprints || sky_and_mirrors;
            let compared = compare_lanes_with_scalar(
                &scene,
                &integrator,
                differentials,
                &mut total,
                &mut common,
            );
            assert_eq!(compared, 12 * 10 * (4 * LANES - 1));
        }
        assert!(
            total.environment_lookups > 0 && total.reflection_rays > 0,
            "{total:?}"
        );
        assert!(total.environment_shadow_rays > 0, "{total:?}");
        // Both ways of gathering the points were taken, and lanes that all see a light.
        assert!(common.iter().all(|&n| n > 0), "{common:?}");
        // Every branch was taken: lanes behind a light, below the horizon, with
        // zero reflection, traced, and the specular lobe evaluated.
        assert!(total.light_samples > 0, "{total:?}");
        assert!(total.light_skips.behind_light > 0, "{total:?}");
        assert!(total.light_skips.below_surface > 0, "{total:?}");
        assert!(total.light_skips.zero_brdf > 0, "{total:?}");
        assert!(total.light_shadow_rays > 0, "{total:?}");
        assert!(total.specular_lobes > 0, "{total:?}");
        assert!(total.footprints > 0, "{total:?}");
        assert!(total.point_light_samples > 0, "{total:?}");
    }

    /// The reflected rays made in place for lanes on one sphere or wall, and
    /// those made lane by lane without differentials, are `mirror_ray`'s,
    /// origins and directions bit for bit (the origin only decides which
    /// lanes meet a surface, so the radiance test cannot see it).
    #[test]
    fn reflected_rays_are_mirror_rays() {
        let scene = room();
        let mut checked = [0usize; 3];
        for i in 0..64u32 {
            let rays = RayLanes {
                origin: Vec3Lanes::splat(Vec3::new(0.3, 0.5, 1.0)),
                direction: Vec3Lanes::from_lanes(std::array::from_fn(|k| {
                    let a = (i * 16 + k as u32) as f32;
                    Vec3::new(
                        (a * 0.618_034).sin(),
                        (a * 0.414_214).cos(),
                        -(a * 0.3).cos(),
                    )
                })),
            };
            let closest = scene.shapes.closest_lanes(&rays, LANES);
            if closest.hits == 0 {
                continue;
            }
            let object = closest.object[closest.hits.trailing_zeros() as usize];
            let on_one = lanes::each_set(closest.hits)
                .filter(|&k| closest.object[k] == object)
                .fold(0, |wave, k| wave | 1 << k);
            for traced in [closest.hits, on_one] {
                let wave = Wave {
                    rays: &rays,
                    diffs: None,
                    closest: &closest,
                    lanes: traced,
                    depth: 0,
                };
                let (reflected, diffs, made) = reflected_rays(&scene, &wave, traced);
                assert_eq!((made, diffs), (traced, None));
                let in_place = reflected_in_place(&scene, &rays, &closest, traced).is_some();
                for k in lanes::each_set(traced) {
                    let ray = rays.lane(k);
                    let hit = closest
                        .hit(k)
                        .and_then(|f| scene.shapes.surface_record(&ray, f));
                    let (expected, _) =
                        mirror_ray(&hit.unwrap(), &ray, &RayDifferential::none(&ray));
                    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                    assert_eq!(bits(reflected.origin.lane(k)), bits(expected.origin));
                    assert_eq!(bits(reflected.direction.lane(k)), bits(expected.direction));
                }
                let sphere = matches!(
                    scene.shapes.object(object),
                    ObjectRef::Shape(Shape::Sphere(_))
                );
                let kind = if in_place { usize::from(sphere) } else { 2 };
                checked[kind] += traced.count_ones() as usize;
            }
        }
        // On a wall, on a sphere, and lane by lane.
        assert!(checked.iter().all(|&n| n > 0), "{checked:?}");
    }

    /// The same under physical shading: the room's materials made diffuse
    /// (no specular color), its area light sampled by area, by solid angle,
    /// or as each point's distance decides, with Sobol and grid points.
    #[test]
    fn physical_lanes_give_each_samples_radiance_and_counts_bit_for_bit() {
        use glint_lighting::AreaSampling;
        let (mut total, mut common) = (ShadingCounters::default(), [0; 3]);
        // Glossy rooms also hold a point light and a sphere light; their
        // materials take every kind of lobe (Phong's with integral and
        // fractional exponents, Blinn–Phong's) against every kind of light.
        let glossy_room = || {
            room_with(|b| {
                b.point_light(glint_lighting::PointLight {
                    position: Vec3::new(-2.0, 3.0, -3.0),
                    color: Vec3::new(0.5, 0.4, 0.3),
                });
                let sphere = SphereLight::new(Vec3::new(2.0, 2.5, -3.0), 0.5, Vec3::splat(2.0));
                b.sphere_light(sphere.unwrap());
            })
        };
        // (light pattern, light samples, footprints, area sampling,
        // environment samples, mirrors, glossy)
        #[rustfmt::skip]
        let cases = [
            (SamplePattern::Sobol, 1, false, AreaSampling::Auto, 0, false, false),
            (SamplePattern::Sobol, 5, false, AreaSampling::Auto, 0, false, false),
            (SamplePattern::Grid, 4, false, AreaSampling::Area, 0, false, false),
            (SamplePattern::Sobol, 4, true, AreaSampling::SolidAngle, 0, false, false),
            (SamplePattern::Sobol, 1, false, AreaSampling::Auto, 1, false, false),
            (SamplePattern::Sobol, 4, true, AreaSampling::Auto, 3, false, false),
            (SamplePattern::Grid, 1, false, AreaSampling::Area, 17, false, false),
            (SamplePattern::Sobol, 1, false, AreaSampling::Auto, 4, true, false),
            (SamplePattern::Sobol, 4, true, AreaSampling::Auto, 1, true, false),
            (SamplePattern::Sobol, 1, false, AreaSampling::Auto, 0, false, true),
            (SamplePattern::Sobol, 5, false, AreaSampling::SolidAngle, 0, false, true),
            (SamplePattern::Grid, 4, true, AreaSampling::Area, 0, false, true),
            (SamplePattern::Sobol, 3, false, AreaSampling::Auto, 0, true, true),
            (SamplePattern::Sobol, 1, false, AreaSampling::Auto, 4, false, true),
            (SamplePattern::Grid, 4, true, AreaSampling::Auto, 3, true, true),
            // Points from each sample's stream, which a lane behind a light
            // or inside one, or not glossy, does not draw from.
            (SamplePattern::Random, 4, false, AreaSampling::Auto, 3, true, true),
            (SamplePattern::Random, 1, false, AreaSampling::Area, 1, false, false),
            (SamplePattern::Stratified, 4, true, AreaSampling::SolidAngle, 4, false, true),
            (SamplePattern::Stratified, 3, false, AreaSampling::Auto, 0, true, true),
            (SamplePattern::Stratified, 1, false, AreaSampling::Auto, 2, true, true),
        ];
        for (
            pattern,
            light_samples,
            footprints,
            area_sampling,
            environment_samples,
            mirrors,
            glossy,
        ) in cases
        {
            let mut scene = if glossy { glossy_room() } else { room() };
            scene.shading = ShadingModel::Physical;
            if environment_samples > 0 {
                scene.environment = Some(sky());
            }
            for material in scene.materials.iter_mut().filter(|_| !glossy) {
                material.specular = Some(Texture::Constant(Vec3::ZERO));
            }
            if mirrors {
                // A mirror and a half mirror (with local shading), both
                // reflected as the next wave of lanes.
                scene.materials[2].reflectivity = 1.0;
                scene.materials[3].reflectivity = 0.5;
            }
            if footprints {
                checks_over_footprints(&mut scene);
            }
            let integrator = DirectIntegrator {
                light_samples,
                light_pattern: pattern,
                environment_samples,
                // The lights' pattern where it places that many points.
                environment_pattern: match pattern.supports(environment_samples) {
                    true => pattern,
                    false => SamplePattern::Sobol,
                },
                environment_sampling: glint_lighting::EnvironmentSampling::Luminance,
                max_depth: 4,
                area_sampling,
                mis: true,
            };
            let compared =
                compare_lanes_with_scalar(&scene, &integrator, footprints, &mut total, &mut common);
            assert_eq!(compared, 12 * 10 * (4 * LANES - 1));
        }
        assert!(total.environment_shadow_rays > 0, "{total:?}");
        assert!(total.environment_lookups > 0, "{total:?}");
        assert!(total.reflection_rays > 0, "{total:?}");
        assert!(total.environment_skips.below_surface > 0, "{total:?}");
        assert!(common.iter().all(|&n| n > 0), "{common:?}");
        assert!(total.light_skips.behind_light > 0, "{total:?}");
        assert!(total.light_skips.below_surface > 0, "{total:?}");
        assert!(total.light_skips.zero_brdf > 0, "{total:?}");
        assert!(total.light_shadow_rays > 0, "{total:?}");
        assert!(total.footprints > 0, "{total:?}");
        assert!(total.lobe_samples > 0 && total.brdf_rays > 0, "{total:?}");
        assert!(total.lobe_skips.below_surface > 0, "{total:?}");
        assert!(total.specular_lobes > 0, "{total:?}");
    }

    /// Lights flush with the walls they light, a hair in front: shadow rays
    /// from the walls to the lights graze the walls' own planes, where a
    /// lane's own surface could block it by rounding. The lanes give each
    /// sample's `li_at` bit for bit, in both shading models. (Lanes on
    /// several objects leave each one's own wall out, as the one-by-one
    /// route does, `any_hits_among_leaving`; no ray here happens to need it,
    /// at offsets from 10⁻⁵ down to 0, so the geometry's own test checks it.)
    #[test]
    fn lights_flush_with_a_wall_are_shaded_in_lanes_as_one_by_one() {
        let (mut total, mut common) = (ShadingCounters::default(), [0; 3]);
        for shading in [ShadingModel::Phong, ShadingModel::Physical] {
            let mut scene = room_with(|b| {
                // On the back wall (z = −9), facing into the room, and on the
                // floor (y = −2), facing up.
                let back = AreaLight::new(
                    Vec3::new(-4.0, -1.0, -9.0 + 1e-5),
                    Vec3::X * 3.0,
                    Vec3::Y * 4.0,
                    Vec3::splat(0.8),
                );
                b.area_light(back.unwrap().facing(Vec3::Z));
                let floor = AreaLight::new(
                    Vec3::new(1.0, -2.0 + 1e-5, -8.0),
                    Vec3::X * 3.0,
                    Vec3::Z * 2.0,
                    Vec3::splat(0.5),
                );
                b.area_light(floor.unwrap().facing(Vec3::Y));
            });
            scene.shading = shading;
            let integrator = DirectIntegrator {
                light_samples: 16,
                light_pattern: SamplePattern::Sobol,
                environment_samples: 0,
                environment_pattern: SamplePattern::Sobol,
                environment_sampling: glint_lighting::EnvironmentSampling::Luminance,
                max_depth: 4,
                area_sampling: glint_lighting::AreaSampling::Area,
                mis: true,
            };
            compare_lanes_with_scalar(&scene, &integrator, false, &mut total, &mut common);
        }
        assert!(common[0] > 0 && total.light_shadow_rays > 0, "{common:?}");
    }

    /// Checks read from the normals in lanes are the scalar path's, bit for
    /// bit: on a dense sweep of directions, including every check's edges
    /// and their neighbours, the poles and the seam, with the material's uv
    /// scaled and offset; both ways of finding the check are taken.
    #[test]
    fn sphere_checks_from_normals_are_the_scalar_paths() {
        let mut material = PhongMaterial::new(Vec3::ZERO, 20.0);
        let board = Checkerboard::new(Vec3::new(0.9, 0.1, 0.2), Vec3::new(0.1, 0.3, 0.8), 8);
        material.diffuse = Texture::Checkerboard(board);
        material.specular = Some(Texture::Constant(Vec3::splat(0.25)));
        material.uv_transform = UvTransform {
            scale: Vec2::new(3.0, -2.0),
            offset: Vec2::new(0.125, 0.3),
        };
        let checks = SphereChecks::of(&material).expect("point-sampled checks");
        let direction = |theta: f32, phi: f32| {
            let (st, ct) = theta.sin_cos();
            Vec3::new(st * phi.cos(), ct, -st * phi.sin())
        };
        let mut normals = vec![Vec3::Y, -Vec3::Y, Vec3::X, -Vec3::Z];
        let edges = 8 * 3 * 2;
        for i in 0..=edges {
            let at = i as f32 / edges as f32;
            for nudge in [-2e-6f32, -1e-7, 0.0, 1e-7, 2e-6, 0.013] {
                let a = (at + nudge) * std::f32::consts::PI;
                for j in 0..7 {
                    let b = j as f32 * 0.9;
                    normals.push(direction(a, b));
                    normals.push(direction(b * 0.5, 2.0 * a));
                }
            }
        }
        // Normals whose exact check coordinates lie within 1e-4 of an edge
        // (inside the margin, so read through libm), and the others.
        let (mut near, mut clear) = (0, 0);
        for chunk in normals.chunks(LANES) {
            let mut normal = Vec3Lanes::default();
            for (k, n) in chunk.iter().enumerate() {
                normal.set_lane(k, n.normalize());
            }
            let used = (1u32 << chunk.len()) - 1;
            let (kd, ks) = checks.reflectances_lanes(&material, &normal, used);
            for k in 0..chunk.len() {
                let (uv, _, _) = Sphere::uv_of_normal(normal.lane(k));
                let (d, s) = material.reflectances_at(uv);
                assert_eq!(kd.lane(k), d, "normal {}", normal.lane(k));
                assert_eq!(ks.lane(k), s, "normal {}", normal.lane(k));
                let UvTransform { scale, offset } = material.uv_transform;
                let c = (uv * scale + offset) * 8.0;
                let edge = |c: f32| (c - c.round()).abs() < 1e-4;
                if edge(c.x) || edge(c.y) {
                    near += 1;
                } else {
                    clear += 1;
                }
            }
        }
        assert!(
            near > 200 && clear > 2000,
            "{near} near an edge, {clear} clear"
        );
    }
}
