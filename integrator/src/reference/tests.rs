//! The reference's own lanes against its one-by-one sums.

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
                    let a = point.area_light_sum(&scene, light, &samples, &occluders, &mut lanes);
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
