//! The waves of camera-sample lanes: the first hits of a chunk's camera
//! samples, what each lane sees (the environment, a light, a surface to
//! shade), and the lanes on mirrors reflected as the next wave.

use super::points::LaneStreams;
use super::shaded_lanes::ShadedLanes;
use crate::context::SampleContext;
use crate::trace::{Event, Tracer};
use crate::{DirectIntegrator, Scene, SurfaceKind};
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes, LANES};
use glint_geometry::{
    offset_ray_origins, reflect, reflect_differential, spawn_ray, ClosestLanes, Hit, ObjectRef,
    Ray, RayDifferential, RayLanes, Shape,
};
use glint_lighting::{AreaLight, Light, PhongMaterial, ShadingModel};

impl DirectIntegrator {
    /// `li_at` for every lane of `wave`, `wave.depth` reflections deep, for
    /// the lanes' camera samples (`streams`): misses read the environment, emitters give their
    /// radiance, and surfaces their local shading and, on a mirror, the
    /// radiance of the next wave ([`Self::mirror_wave`]), in `li_at`'s
    /// order and operations. The other lanes are zero.
    // Inlined into the first hits and into `mirror_wave`, which alone
    // recurses: the first wave is then one function, its lanes passed in
    // registers, not memory.
    #[inline(always)]
    pub(crate) fn li_wave<T: Tracer>(
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
        // Of the lanes that draw no points for a term, only these go on
        // to draw later (for another term, or a next wave).
        streams.live = hit_lanes;
        let shaded = match hits {
            _ if local == 0 => 0,
            FirstHits::OnOneEmitter(area) => {
                ctx.tracer.record(local, |_| Event::Emitter {
                    radiance: area.color,
                });
                let color = Vec3Lanes::splat(area.color);
                radiance = Vec3Lanes::select(lanes::from_bits(local), &color, &radiance);
                0
            }
            hits => {
                let shaded = surface_lanes(scene, &wave, (local, hits), &mut radiance, ctx);
                if T::ON {
                    wave.trace_surfaces(scene, &shaded, &radiance, ctx);
                }
                if shaded.lanes != 0 {
                    radiance = self.with_direct_lighting(scene, &shaded, streams, radiance, ctx);
                }
                shaded.lanes
            }
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
    pub(crate) fn environment_seen_lanes<T: Tracer>(
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

    /// The radiance along the rays the lanes `traced` of `wave` reflect
    /// into, on mirrors, found as the next wave one reflection deeper: the
    /// rays made in their own lanes ([`reflected_rays`]), their closest hits
    /// found together, and their radiance by [`Self::li_wave`].
    #[inline(never)]
    pub(crate) fn mirror_wave<T: Tracer>(
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
}

/// The shading points of the lanes `local` of `wave`, on surfaces (`hits`,
/// one object's all at once, else one by one), each lane's ambient term (or
/// an emitter's radiance, set one by one) put in `radiance`.
#[inline(always)]
fn surface_lanes<'s, T: Tracer>(
    scene: &'s Scene,
    wave: &Wave,
    (local, hits): (u32, FirstHits<'s>),
    radiance: &mut Vec3Lanes,
    ctx: &mut SampleContext<T>,
) -> ShadedLanes<'s> {
    let (rays, closest, depth) = (wave.rays, wave.closest, wave.depth);
    // Each arm builds the lanes in place, as the value returned: made over a
    // default, moved out of an `Option` or out of a local, their kilobytes
    // cost a zeroing or a copy a chunk.
    match hits {
        FirstHits::OnOneObject(object, shape, material) => {
            let on = (object, shape, material);
            ShadedLanes::on_one_object(scene, (rays, closest), (local, depth), on, radiance, ctx)
        }
        FirstHits::OnOneEmitter(_) | FirstHits::Several => {
            let hits = (rays, wave.diffs, closest);
            ShadedLanes::one_by_one(scene, hits, (local, depth), radiance, ctx)
        }
    }
}

/// The reflected rays of the lanes `wave`, all on one sphere or
/// parallelogram, made in their own lanes: `reflect_differential`'s
/// direction and `spawn_ray`'s origin, from the surface points of
/// [`ShadedLanes::on_one_object`] (no texture coordinates, so no `acos` and
/// `atan2` a lane). None where the lanes lie on several objects or others.
pub(crate) fn reflected_in_place(
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
pub(crate) fn reflected_rays(
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
pub(crate) struct Wave<'a> {
    pub(crate) rays: &'a RayLanes,
    pub(crate) diffs: Option<&'a [RayDifferential; LANES]>,
    pub(crate) closest: &'a ClosestLanes,
    pub(crate) lanes: u32,
    pub(crate) depth: u32,
}

impl<'a> Wave<'a> {
    /// The first wave: camera rays `rays` in the first `used` lanes, with
    /// their differentials `diffs` where the scene reads footprints, and
    /// their closest hits `closest`.
    pub(crate) fn first(
        rays: &'a RayLanes,
        diffs: Option<&'a [RayDifferential; LANES]>,
        closest: &'a ClosestLanes,
        used: usize,
    ) -> Self {
        Self {
            rays,
            diffs,
            closest,
            lanes: (1 << used) - 1,
            depth: 0,
        }
    }
}

/// The hit lanes of a wave on mirrors: each one's reflectivity `r` (zero
/// elsewhere) and tint, and those that reflect all (`r = 1`, with no local
/// shading).
pub(crate) struct Mirrors {
    pub(crate) reflectivity: F32Lanes,
    pub(crate) tint: Vec3Lanes,
    pub(crate) lanes: u32,
    pub(crate) perfect: u32,
}

impl Mirrors {
    /// The mirrors among the lanes `hit_lanes`, which landed on `hits`.
    #[inline(always)]
    pub(crate) fn of(
        scene: &Scene,
        closest: &ClosestLanes,
        hit_lanes: u32,
        hits: &FirstHits,
    ) -> Self {
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
pub(crate) enum FirstHits<'a> {
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
    pub(crate) fn of(scene: &'a Scene, closest: &ClosestLanes, hit_lanes: u32) -> Self {
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

/// The ray `ray` reflects into at `hit` by a perfect mirror, and its
/// differentials ([`reflect_differential`]), leaving from an origin offset
/// to its side ([`spawn_ray`]).
pub(crate) fn mirror_ray(hit: &Hit, ray: &Ray, diff: &RayDifferential) -> (Ray, RayDifferential) {
    let surface = hit.differentials(diff);
    let (wi, reflected_diff) = reflect_differential(hit, ray.direction, diff, &surface);
    (spawn_ray(hit, wi), reflected_diff)
}
