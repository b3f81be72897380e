//! The light samples in lanes ([`LightSampleLanes`], the render's kernel
//! for a shading point's area-light samples) against the reference's sums
//! of one sample at a time.

use super::*;
use crate::light_samples::{count_lanes, LightSampleLanes};
use crate::{SceneBuilder, SurfaceKind};
use glam::{UVec2, Vec2};
use glint_camera::Camera;
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes};
use glint_geometry::{offset_ray_origin, Parallelogram, Ray, RayLanes, Sphere};
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

/// [`ShadingPoint::area_light_sum`] with [`LANES`](glint_geometry::lanes::LANES)
/// samples at a time in lanes, as the render shades them: each chunk's light
/// points, reflections and horizon tests in [`LightSampleLanes`], its
/// shadow rays traced together from the point offset to the side each
/// leaves on, each lane's value added in order.
fn area_light_sum_in_lanes(
    point: &ShadingPoint,
    scene: &Scene,
    light: &AreaLight,
    samples: &SamplePoints,
    (occluders, ctx): (&Occluders, &mut SampleContext),
) -> Vec3 {
    let (x, error, g) = (point.hit.point, point.hit.error, point.hit.geometric_normal);
    let front = Vec3Lanes::splat(offset_ray_origin(x, error, g));
    let back = Vec3Lanes::splat(offset_ray_origin(x, error, -g));
    let (receiver, ng) = (Vec3Lanes::splat(x), Vec3Lanes::splat(point.ng));
    let specular = if point.has_specular { u32::MAX } else { 0 };
    let reflect = |l: &Vec3Lanes| {
        let (kd, ks, n, v) = (point.kd, point.ks, point.n, point.v);
        point
            .material
            .reflect_lanes(kd, ks, n, l, v, point.has_specular)
    };
    let mut sum = Vec3::ZERO;
    for chunk in samples.chunks() {
        let used = chunk.used();
        let u = (chunk.lanes.x, chunk.lanes.y);
        let s = LightSampleLanes::new(light, u, &receiver, &ng, used, reflect);
        count_lanes(&mut ctx.counters, used, s.lit, s.shaded, s.traced, specular);
        let from_back = lanes::lt(s.towards.dot_splat(g), F32Lanes::ZERO);
        let origin = Vec3Lanes::select(from_back, &back, &front);
        let direction = light.shadow_ends(&s.position) - origin;
        let rays = RayLanes { origin, direction };
        let visible = s.traced & !scene.shapes.any_hits_among(occluders, &rays, 1.0, s.traced);
        for k in lanes::each_set(s.lit) {
            sum += match visible >> k & 1 {
                1 => s.reflected.lane(k),
                _ => Vec3::ZERO,
            };
        }
    }
    sum
}

#[test]
fn light_samples_in_lanes_give_the_one_by_one_sum_and_counts_bit_for_bit() {
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
                    let in_lanes = (&occluders, &mut lanes);
                    let a = area_light_sum_in_lanes(&point, &scene, light, &samples, in_lanes);
                    let b = point.area_light_sum(&scene, light, &samples, &occluders, &mut scalar);
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
