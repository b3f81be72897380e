//! A shading point's samples of one area light, shaded [`LANES`] at a time.
//!
//! For N samples of an area light, the integrator sums, over the samples that
//! face the point, the Phong reflection of each unoccluded one (report section
//! 2.5). Sample by sample the work is a chain of dependent steps (the light
//! point, the direction and its square root, the Phong lobe, the shadow ray's
//! origin), each waiting on the last. [`ShadingPoint::area_light_sum`] runs the
//! chain on [`LANES`] samples at once in SIMD lanes ([`Vec3Lanes`]) and traces the
//! shadow rays of the lanes that need one. Every lane does the scalar path's
//! operations in its order, and the sum is taken sample by sample in the same
//! order, so the result and the shading counts ([`crate::ShadingCounters`]) are
//! those of [`ShadingPoint::area_light_sum_one_by_one`], bit for bit (the tests
//! compare them). The intersection counts of `--stats` are not: tested in
//! lanes, a shape counts one test per ray in the batch.

use crate::direct::{SampleContext, ShadingPoint};
use crate::sampling::SamplePoints;
use crate::trace::Tracer;
use crate::{Scene, ShadingCounters};
use glam::Vec3;
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes};
use glint_geometry::{Occluders, RayLanes};
use glint_lighting::AreaLight;

/// One sample of an area light per lane, seen from each lane's receiving point,
/// before its shadow ray: the light point, the (unnormalised) direction to it,
/// the reflection of a unit light from it, and the lanes (bit k for lane k) it
/// lights, shades (normalisable and above the surface) and needs a shadow ray
/// for (a non-zero reflection). The one kernel of a point's light samples in
/// lanes and of a pixel's camera samples' first hits in lanes.
pub(crate) struct LightSampleLanes {
    pub(crate) position: Vec3Lanes,
    pub(crate) towards: Vec3Lanes,
    pub(crate) reflected: Vec3Lanes,
    pub(crate) lit: u32,
    pub(crate) shaded: u32,
    pub(crate) traced: u32,
}

impl LightSampleLanes {
    /// Lane k: the point `(ux, uy)_k` of `light` seen from `receiver_k`, whose
    /// geometric normal on the viewer's side is `ng_k`; `reflect` gives the
    /// reflection of a unit light from unit directions. Only the lanes `used`.
    #[inline(always)]
    pub(crate) fn new(
        light: &AreaLight,
        (ux, uy): (F32Lanes, F32Lanes),
        receiver: &Vec3Lanes,
        ng: &Vec3Lanes,
        used: u32,
        reflect: impl FnOnce(&Vec3Lanes) -> Vec3Lanes,
    ) -> Self {
        let position = light.sample_points(ux, uy);
        let lit = used & lanes::bits(light.illuminates_lanes(&position, receiver));
        Self::at(position, receiver, ng, lit, reflect)
    }

    /// Lane k: the light point `position_k`, which shines on `receiver_k` in
    /// the lanes `lit` (a point light's position, on all it is asked about).
    #[inline(always)]
    pub(crate) fn at(
        position: Vec3Lanes,
        receiver: &Vec3Lanes,
        ng: &Vec3Lanes,
        lit: u32,
        reflect: impl FnOnce(&Vec3Lanes) -> Vec3Lanes,
    ) -> Self {
        let towards = position - *receiver;
        let (l, normalized) = towards.try_normalize();
        let reflected = reflect(&l);
        let above = lanes::bits(lanes::gt(l.dot(ng), F32Lanes::ZERO));
        let shaded = lit & lanes::bits(normalized) & above;
        let traced = shaded & !lanes::bits(reflected.is_zero());
        Self {
            position,
            towards,
            reflected,
            lit,
            shaded,
            traced,
        }
    }
}

/// From this many samples per light on, the samples are shaded in lanes; below
/// it, one by one (the same result: the lanes only cost more for one sample).
pub(crate) const LANES_FROM_SAMPLES: usize = 2;

impl ShadingPoint<'_> {
    /// The sum over `samples` (coordinates on `light`) of the point's Phong
    /// reflection of each light point that shines on it and is not blocked
    /// (testing only `occluders`), before the light's colour and the average.
    pub(crate) fn area_light_sum<T: Tracer>(
        &self,
        scene: &Scene,
        light: &AreaLight,
        samples: &SamplePoints,
        occluders: &Occluders,
        ctx: &mut SampleContext<T>,
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
    fn count<T: Tracer>(
        &self,
        ctx: &mut SampleContext<T>,
        used: u32,
        lit: u32,
        shaded: u32,
        traced: u32,
    ) {
        let specular = if self.has_specular { u32::MAX } else { 0 };
        count_lanes(&mut ctx.counters, used, lit, shaded, traced, specular);
    }

    /// [`Self::area_light_sum`] one sample at a time.
    pub(crate) fn area_light_sum_one_by_one<T: Tracer>(
        &self,
        scene: &Scene,
        light: &AreaLight,
        samples: &SamplePoints,
        occluders: &Occluders,
        ctx: &mut SampleContext<T>,
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
}

/// Adds one chunk of light samples in lanes to the counts, as the scalar path
/// counts them one by one. Each argument is a set of lanes (bit k for lane k):
/// the lanes `used`, those whose light point shines on the point (`lit`),
/// which are shaded (`shaded`: their direction could be normalised and is
/// above the horizon; a lit lane that is not is counted below the surface, as
/// the scalar path counts a direction of no length), whose shadow ray is
/// traced, and those that evaluate a specular lobe when shaded.
pub(crate) fn count_lanes(
    counters: &mut ShadingCounters,
    used: u32,
    lit: u32,
    shaded: u32,
    traced: u32,
    specular: u32,
) {
    let ones = |bits: u32| u64::from(bits.count_ones());
    counters.light_skips.behind_light += ones(used & !lit);
    counters.light_skips.below_surface += ones(lit & !shaded);
    counters.specular_lobes += ones(shaded & specular);
    counters.light_skips.zero_brdf += ones(shaded & !traced);
    counters.light_shadow_rays += ones(traced);
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
