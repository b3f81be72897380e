//! The surface points of a wave's lanes, set up once for all their light
//! samples: their reflectances, the occluders culled for a light, the
//! shadow-ray origins, and the shadow test.

use super::surfaces::{reflectances_lanes, SphereChecks};
use crate::context::{LaneOccluders, SampleContext};
use crate::light_samples::{count_lanes, LightSampleLanes};
use crate::physical::{power_heuristic, DiffusePoints};
use crate::shading_point::ShadingPoint;
use crate::texture_lookup::texture_footprint;
use crate::trace::{Event, Tracer};
use crate::{Scene, ShadingCounters, SurfaceKind};
use glam::Vec3;
use glint_geometry::lanes::{self, F32Lanes, Float, Vec3Lanes, LANES};
use glint_geometry::{
    offset_ray_origins, ClosestLanes, Occluders, RayDifferential, RayLanes, Shape,
};
use glint_lighting::{
    sample_specular_at, specular_pdf_at, AreaLight, PhongLanes, PhongMaterial, PointLight,
};
use glint_texture::TexCoord;
use std::cell::OnceCell;

/// Counts `n` samples of one light at each lane of `shaded`, those of the
/// lanes outside `lit` as skipped behind the light, as `li_at` counts them.
pub(crate) fn count_light_samples(counters: &mut ShadingCounters, n: u32, shaded: u32, lit: u32) {
    counters.light_samples += u64::from(n) * u64::from(shaded.count_ones());
    counters.light_skips.behind_light += u64::from(n) * u64::from((shaded & !lit).count_ones());
}

/// The shading points of up to [`LANES`] lanes: all at once where the lanes hit
/// one shape ([`ShadedLanes::on_one_object`]), else one by one ([`ShadedLanes::set`]).
#[derive(Default)]
pub(crate) struct ShadedLanes<'a> {
    /// The lanes holding a point (bit k for lane k).
    pub(crate) lanes: u32,
    pub(crate) point: Vec3Lanes,
    /// The error bound of `point` ([`glint_geometry::Hit::error`]).
    pub(crate) error: Vec3Lanes,
    pub(crate) geometric_normal: Vec3Lanes,
    /// The geometric normals on the viewer's side.
    pub(crate) ng: Vec3Lanes,
    pub(crate) phong: PhongLanes<'a>,
    /// The shadow rays' origins, once the lanes are set.
    pub(crate) origins: ShadowOrigins,
    /// The one object every lane is on, where set together.
    pub(crate) object: Option<u32>,
    /// Each lane's object, where set one by one.
    pub(crate) objects: [u32; LANES],
    /// The reflections the camera rays took to the points.
    pub(crate) depth: u32,
}

/// The points of [`ShadedLanes`] offset to either side of their surfaces, the
/// origins of their shadow rays: each side made when a shadow ray first
/// leaves on it, once for all the light samples. Most points' shadow rays
/// all leave on the viewer's side.
#[derive(Default)]
pub(crate) struct ShadowOrigins {
    pub(crate) front: OnceCell<Vec3Lanes>,
    pub(crate) back: OnceCell<Vec3Lanes>,
}

impl<'a> ShadedLanes<'a> {
    /// The shading points of the lanes `hit_lanes`, set one by one
    /// ([`Self::set_one_by_one`]), with their shadow rays' origins.
    pub(crate) fn one_by_one<T: Tracer>(
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
    pub(crate) fn set_one_by_one<T: Tracer>(
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
    pub(crate) fn set(&mut self, k: usize, p: &ShadingPoint, material: &'a PhongMaterial) {
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
    pub(crate) fn on_one_object<T: Tracer>(
        scene: &'a Scene,
        (rays, closest): (&RayLanes, &ClosestLanes),
        (hit_lanes, depth): (u32, u32),
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
            depth,
        }
    }

    /// The shapes that may block the lanes' shadow rays to area light `index`,
    /// as [`DirectIntegrator::occluders`] culls them for one point: from a
    /// centre, widened by a reach that holds every lane's point, where the
    /// lanes lie on one object; every shape but the light's otherwise.
    pub(crate) fn occluders<T: Tracer>(
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
    pub(crate) fn area_light<T: Tracer>(
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
    pub(crate) fn point_light<T: Tracer>(
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
    pub(crate) fn physical_point_light<T: Tracer>(
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
    pub(crate) fn light_samples<T: Tracer>(
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
    pub(crate) fn diffuse_points(&self) -> DiffusePoints<'_> {
        DiffusePoints {
            point: &self.point,
            ng: &self.ng,
            n: self.phong.normals(),
            kd: self.phong.kd(),
        }
    }

    /// [`Self::light_samples`] where some lanes of `used` are glossy.
    #[inline(never)]
    pub(crate) fn glossy_light_samples(
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
    pub(crate) fn lobe_directions(
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
    pub(crate) fn lobe_reflections(
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
    pub(crate) fn unoccluded<T: Tracer>(
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
    pub(crate) fn blocked(
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
    pub(crate) fn origins_towards(&self, towards: &Vec3Lanes, traced: u32) -> Vec3Lanes {
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

/// How far from the point it was found for a culling serves, as a fraction of
/// the point's distance to the light: a pixel's samples on one surface then
/// share one (a pixel spans about a thousandth of its distance from the camera
/// at 512², so a hundredth covers it with room), at the price of faces
/// widened by that much.
pub(crate) const CULL_REACH: f32 = 0.01;
