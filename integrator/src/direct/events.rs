//! The steps of the camera-sample lanes as a [`Tracer`] sees them, for
//! `glint explain`: each hook names the lanes its step happens in, and makes
//! each recorded lane's [`Event`] from that lane's numbers. What the lanes
//! computed (rays, hits, reflectances, values, shadow verdicts) is read from
//! them; what they do not keep is recomputed for display from the lane's
//! scalar [`ShadingPoint`]: why a sample needs no shadow ray, `n·l`, the
//! diffuse and specular parts, and the nearest blocker of a blocked shadow
//! ray. Every hook is called under `if T::ON`, so a render compiles none of
//! it.

use super::shaded_lanes::ShadedLanes;
use super::wave::Wave;
use crate::physical::power_heuristic;
use crate::shading_point::ShadingPoint;
use crate::texture_lookup::texture_footprint;
use crate::trace::{Event, Shadow, Skip, Technique, TracedSurface, Tracer};
use crate::{SampleContext, Scene, SurfaceKind};
use glam::Vec3;
use glint_geometry::lanes::{F32Lanes, Vec3Lanes};
use glint_geometry::{ClosestLanes, Ray, RayDifferential, RayLanes};
use glint_lighting::{EnvironmentSample, ShadingModel};

/// Whether bit `k` of `lanes` is set.
fn has(lanes: u32, k: usize) -> bool {
    lanes >> k & 1 == 1
}

/// The shading point of a lane's kept surface, as the scalar path makes it.
fn shading_point<'a>(scene: &'a Scene, surface: &'a TracedSurface) -> Option<ShadingPoint<'a>> {
    match scene.surface_of(&surface.hit) {
        SurfaceKind::Material(m) => Some(ShadingPoint::new(
            &surface.hit,
            m,
            &surface.ray,
            &surface.tc,
        )),
        SurfaceKind::Emitter(_) => None,
    }
}

impl Wave<'_> {
    /// Lane k's ray and its differentials (none where the scene reads no
    /// footprints).
    fn ray(&self, k: usize) -> (Ray, RayDifferential) {
        let ray = self.rays.lane(k);
        let diff = self
            .diffs
            .map_or_else(|| RayDifferential::none(&ray), |d| d[k]);
        (ray, diff)
    }

    /// Each lane's ray and its closest hit's full record.
    pub(super) fn trace_rays<T: Tracer>(&self, scene: &Scene, ctx: &mut SampleContext<T>) {
        ctx.tracer.record(self.lanes, |k| {
            let ray = self.rays.lane(k);
            let hit =
                (self.closest.hit(k)).and_then(|found| scene.shapes.surface_record(&ray, found));
            Event::Ray {
                depth: self.depth,
                ray,
                hit: hit.map(Box::new),
            }
        });
    }

    /// The environment seen by the lanes `misses`, `radiance` in them.
    pub(super) fn trace_misses<T: Tracer>(
        &self,
        scene: &Scene,
        misses: u32,
        radiance: &Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) {
        ctx.tracer.record(misses, |k| {
            let (ray, diff) = self.ray(k);
            let width = match scene.shading {
                ShadingModel::Phong => diff.angular_width(ray.direction),
                ShadingModel::Physical => 0.0,
            };
            Event::Environment {
                direction: ray.direction.normalize(),
                width,
                radiance: radiance.lane(k),
            }
        });
    }

    /// The surfaces of `shaded`, kept for their shading's events, with their
    /// reflectances and frames, and their ambient terms `radiance`.
    pub(super) fn trace_surfaces<T: Tracer>(
        &self,
        scene: &Scene,
        shaded: &ShadedLanes,
        radiance: &Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) {
        ctx.tracer.keep_surfaces(shaded.lanes, |k| {
            let (ray, diff) = self.ray(k);
            let hit = scene.shapes.surface_record(&ray, self.closest.hit(k)?)?;
            let SurfaceKind::Material(material) = scene.surface_of(&hit) else {
                return None;
            };
            let tc = texture_footprint(scene, material, (&hit, shaded.depth), &ray, &diff);
            Some(TracedSurface { hit, ray, tc })
        });
        let phong = &shaded.phong;
        ctx.tracer.record_on(shaded.lanes, |k, surface| {
            Some(Event::Surface {
                tc: surface.tc,
                kd: phong.kd().lane(k),
                ks: phong.ks().lane(k),
                n: phong.normals().lane(k),
                ng: shaded.ng.lane(k),
                v: phong.viewers().lane(k),
            })
        });
        ctx.tracer.record(shaded.lanes, |k| Event::Ambient {
            value: radiance.lane(k),
        });
    }

    /// The mirror rays `rays` of the lanes `traced`.
    pub(super) fn trace_mirrors<T: Tracer>(
        &self,
        scene: &Scene,
        rays: &RayLanes,
        traced: u32,
        ctx: &mut SampleContext<T>,
    ) {
        ctx.tracer.record(traced, |k| {
            let closest = self.closest;
            let surface = scene.surface_of_primitive(closest.object[k], closest.primitive[k]);
            let (reflectivity, tint) = match surface {
                SurfaceKind::Material(m) => (m.reflectivity, m.mirror_tint),
                SurfaceKind::Emitter(_) => (0.0, Vec3::ZERO),
            };
            Event::Mirror {
                reflectivity,
                tint,
                direction: rays.direction.lane(k),
            }
        });
    }

    /// The radiance of the lanes `surfaces`: `local`, the tinted mirror term
    /// `mirror`, and `value`.
    pub(super) fn trace_radiance<T: Tracer>(
        &self,
        surfaces: u32,
        (local, mirror, value): (&Vec3Lanes, &Vec3Lanes, &Vec3Lanes),
        ctx: &mut SampleContext<T>,
    ) {
        ctx.tracer.record(surfaces, |k| Event::Radiance {
            depth: self.depth,
            local: local.lane(k),
            mirror: mirror.lane(k),
            value: value.lane(k),
        });
    }
}

impl ShadedLanes<'_> {
    /// Lane k's shadow ray towards `end` (leaving on the side `towards`
    /// leaves on), as the lanes traced it.
    fn shadow_ray(&self, k: usize, (towards, end): (&Vec3Lanes, &Vec3Lanes), traced: u32) -> Ray {
        let origin = self.origins_towards(towards, traced).lane(k);
        Ray::new(origin, end.lane(k) - origin)
    }

    /// Lane k's shadow-ray verdict: unoccluded where `visible`, else its
    /// nearest blocker before `t_max`.
    fn verdict(&self, scene: &Scene, k: usize, visible: u32, ray: impl FnOnce() -> Ray) -> Shadow {
        match has(visible, k) {
            true => Shadow::Unoccluded,
            false => blocker(scene, &ray(), 1.0),
        }
    }

    /// The course's model: each lane's light sample at `position` (on an
    /// area light, else a point light), of the lanes lit `lit`, shaded
    /// `shaded` and traced `traced`, towards `ends`, adding `reflected` where
    /// `visible`.
    pub(super) fn trace_light_samples<T: Tracer>(
        &self,
        scene: &Scene,
        (position, ends): (&Vec3Lanes, &Vec3Lanes),
        [lit, shaded, traced, visible]: [u32; 4],
        reflected: &Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) {
        let towards = *position - self.point;
        ctx.tracer.record_on(self.lanes, |k, surface| {
            let point = shading_point(scene, surface)?;
            let p = position.lane(k);
            let l = (p - point.hit.point).normalize_or_zero();
            let shadow = match () {
                _ if !has(lit, k) => Shadow::Skipped(Skip::BehindLight),
                _ if !has(shaded, k) => Shadow::Skipped(Skip::BehindSurface),
                _ if !has(traced, k) => Shadow::Skipped(Skip::ZeroBrdf),
                _ => self.verdict(scene, k, visible, || {
                    self.shadow_ray(k, (&towards, ends), traced)
                }),
            };
            let value = match shadow {
                Shadow::Unoccluded => reflected.lane(k),
                _ => Vec3::ZERO,
            };
            Some(point.light_sample_event((p, l), shadow, value))
        });
    }

    /// Physical shading: each lane of `lit`'s light sample at `position`,
    /// drawn with density `pdf` (weighted against its lobe in the lanes
    /// `mis`), towards `ends`, adding `values` where `visible` (of the lanes
    /// `traced`).
    pub(super) fn trace_physical_samples<T: Tracer>(
        &self,
        scene: &Scene,
        (position, pdf, ends): (&Vec3Lanes, F32Lanes, &Vec3Lanes),
        [lit, mis, traced, visible]: [u32; 4],
        values: &Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) {
        let towards = *position - self.point;
        let pdfs = pdf.to_array();
        ctx.tracer.record_on(lit, |k, surface| {
            let point = shading_point(scene, surface)?;
            let (y, pdf, mis) = (position.lane(k), pdfs[k], has(mis, k));
            let event = |l: Vec3, (f_cos, shadow, value)| {
                let lobe_pdf = match mis {
                    true => point.material.specular_pdf(point.n, l, point.v),
                    false => 0.0,
                };
                Event::PhysicalSample {
                    technique: Technique::Light,
                    l,
                    f_cos,
                    light_pdf: pdf,
                    lobe_pdf,
                    weight: if mis {
                        power_heuristic(pdf, lobe_pdf)
                    } else {
                        1.0
                    },
                    shadow,
                    value,
                }
            };
            let l_or_zero = (y - point.hit.point).normalize_or_zero();
            if !(pdf > 0.0 && pdf.is_finite()) {
                let skipped = Shadow::Skipped(Skip::ZeroPdf);
                return Some(event(l_or_zero, (Vec3::ZERO, skipped, Vec3::ZERO)));
            }
            let l = (y - point.hit.point).try_normalize()?;
            if !has(traced, k) {
                return Some(event(l, (Vec3::ZERO, point.skip_reason(l), Vec3::ZERO)));
            }
            let ray = || self.shadow_ray(k, (&towards, ends), traced);
            let shadow = self.verdict(scene, k, visible, ray);
            let value = match has(visible, k) {
                true => values.lane(k),
                false => Vec3::ZERO,
            };
            Some(event(l, (point.f_cos(l), shadow, value)))
        });
    }

    /// Physical shading: point light at `position` from each lane, blocked
    /// but where `visible` (of the lanes `traced`).
    pub(super) fn trace_point_light<T: Tracer>(
        &self,
        scene: &Scene,
        position: &Vec3Lanes,
        [traced, visible]: [u32; 2],
        ctx: &mut SampleContext<T>,
    ) {
        let towards = *position - self.point;
        ctx.tracer.record_on(self.lanes, |k, surface| {
            let point = shading_point(scene, surface)?;
            let d = position.lane(k) - point.hit.point;
            let l = d.try_normalize()?;
            let (f_cos, shadow, value) = match has(traced, k) {
                false => (Vec3::ZERO, point.skip_reason(l), Vec3::ZERO),
                true => {
                    let f = point.f_cos(l);
                    let ray = || self.shadow_ray(k, (&towards, position), traced);
                    match self.verdict(scene, k, visible, ray) {
                        Shadow::Unoccluded => (f, Shadow::Unoccluded, f / d.length_squared()),
                        blocked => (f, blocked, Vec3::ZERO),
                    }
                }
            };
            Some(Event::PhysicalSample {
                technique: Technique::PointLight,
                l,
                f_cos,
                light_pdf: 1.0,
                lobe_pdf: 0.0,
                weight: 1.0,
                shadow,
                value,
            })
        });
    }

    /// Physical shading: the lanes of `mis`' directions drawn from their
    /// lobes at `u` towards a light; the lanes `traced` found `found` along
    /// their rays, the lanes `reached` the light, adding `values`;
    /// `light_pdf(k, y)` is lane k's density of drawing the light's point `y`.
    pub(super) fn trace_lobe_samples<T: Tracer>(
        &self,
        scene: &Scene,
        (mis, u): (u32, (F32Lanes, F32Lanes)),
        (traced, found, reached): (u32, Option<(&RayLanes, &ClosestLanes)>, u32),
        light_pdf: &dyn Fn(usize, Vec3) -> f32,
        values: &Vec3Lanes,
        ctx: &mut SampleContext<T>,
    ) {
        let (ux, uy) = (u.0.to_array(), u.1.to_array());
        ctx.tracer.record_on(mis, |k, surface| {
            let point = shading_point(scene, surface)?;
            let u = glam::Vec2::new(ux[k], uy[k]);
            let l = point.material.sample_specular(point.n, point.v, u)?;
            let pdf = point.material.specular_pdf(point.n, l, point.v);
            let (f_cos, light, shadow, value) = if !(pdf > 0.0 && pdf.is_finite()) {
                (Vec3::ZERO, 0.0, Shadow::Skipped(Skip::ZeroPdf), Vec3::ZERO)
            } else if !has(traced, k) {
                (Vec3::ZERO, 0.0, point.skip_reason(l), Vec3::ZERO)
            } else {
                let (rays, closest) = found?;
                let hit = closest.hit(k);
                let f = point.f_cos(l);
                match has(reached, k) {
                    true => {
                        let y = hit.and_then(|h| scene.shapes.surface_point(&rays.lane(k), h));
                        let light = y.map_or(0.0, |y| light_pdf(k, y.point));
                        (f, light, Shadow::Unoccluded, values.lane(k))
                    }
                    false => {
                        let missed = Shadow::MissedLight {
                            object: hit.map(|h| h.object),
                            t: hit.map_or(f32::INFINITY, |h| h.t),
                        };
                        (f, 0.0, missed, Vec3::ZERO)
                    }
                }
            };
            Some(Event::PhysicalSample {
                technique: Technique::Lobe,
                l,
                f_cos,
                light_pdf: light,
                lobe_pdf: pdf,
                weight: power_heuristic(pdf, light),
                shadow,
                value,
            })
        });
    }

    /// Each lane's environment sample (`drawn`, from its map or about its
    /// normal), of the lanes `dense` with a density, `above` the surface
    /// and `traced`, with `f` its `f · cos θ`, adding `values` where
    /// `visible`.
    pub(super) fn trace_environment_samples<T: Tracer>(
        &self,
        scene: &Scene,
        drawn: (&Vec3Lanes, &Vec3Lanes, F32Lanes),
        [dense, above, traced, visible]: [u32; 4],
        (f, values): (&Vec3Lanes, &Vec3Lanes),
        ctx: &mut SampleContext<T>,
    ) {
        let (direction, radiance, pdf) = drawn;
        let pdfs = pdf.to_array();
        ctx.tracer.record(self.lanes, |k| {
            let s = EnvironmentSample {
                direction: direction.lane(k),
                radiance: radiance.lane(k),
                pdf: pdfs[k],
            };
            let (f_cos, shadow, value) = match () {
                _ if !has(dense, k) => (Vec3::ZERO, Shadow::Skipped(Skip::ZeroPdf), Vec3::ZERO),
                _ if !has(above, k) => {
                    (Vec3::ZERO, Shadow::Skipped(Skip::BehindSurface), Vec3::ZERO)
                }
                _ if !has(traced, k) => (f.lane(k), Shadow::Skipped(Skip::ZeroBrdf), Vec3::ZERO),
                _ if has(visible, k) => (f.lane(k), Shadow::Unoccluded, values.lane(k)),
                _ => {
                    let origin = self.origins_towards(direction, traced).lane(k);
                    let ray = Ray::new(origin, s.direction);
                    (f.lane(k), blocker(scene, &ray, f32::INFINITY), Vec3::ZERO)
                }
            };
            Event::EnvironmentSample {
                direction: s.direction,
                pdf: s.pdf,
                radiance: s.radiance,
                f_cos,
                shadow,
                value,
            }
        });
    }
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
