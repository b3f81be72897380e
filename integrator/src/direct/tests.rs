//! Each lane against the integrator one ray at a time (`reference.rs`),
//! bit for bit, in both shading models, and the lanes' own pieces.

use super::points::PairAllocation;
use super::surfaces::SphereChecks;
use super::wave::{mirror_ray, reflected_in_place, reflected_rays, Wave};
use crate::sampling::{DimensionPair, LaneSamples, SamplePattern};
use crate::{DirectIntegrator, SampleContext, Scene};
use crate::{SceneBuilder, ShadingCounters};
use glam::UVec2;
use glam::Vec2;
use glam::Vec3;
use glint_camera::Camera;
use glint_geometry::lanes::{self, Vec3Lanes, LANES};
use glint_geometry::{ObjectRef, RayLanes, Shape};
use glint_geometry::{Parallelogram, Ray, RayDifferential, Sphere};
use glint_lighting::SpecularLobe;
use glint_lighting::{
    AreaLight, EnvironmentLight, Light, PhongMaterial, ShadingModel, SphereLight, UvTransform,
};
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

/// Every lane of the first [`DirectIntegrator::li_wave`] against `li_at` for
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
            let wave = Wave::first(&ray_lanes, footprints.then_some(&diffs), &closest, used);
            let mut streams = integrator.lane_streams(&samples);
            let values = integrator.li_wave(scene, wave, &mut streams, &mut lanes);
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
    use glint_lighting::EnvironmentSampling::{Cosine, Luminance};
    // (light pattern, light samples, footprints, sky and mirrors, depth,
    // environment sampling)
    for (pattern, light_samples, footprints, sky_and_mirrors, max_depth, sampling) in [
        (SamplePattern::Random, 1, false, false, 4, Luminance),
        (SamplePattern::Stratified, 1, false, false, 4, Luminance),
        (SamplePattern::Sobol, 1, false, false, 4, Luminance),
        (SamplePattern::Grid, 1, false, false, 4, Luminance),
        (SamplePattern::Random, 3, false, false, 4, Luminance),
        (SamplePattern::Sobol, 5, false, false, 4, Luminance),
        (SamplePattern::Grid, 4, false, false, 4, Luminance),
        (SamplePattern::Sobol, 1, true, false, 4, Luminance),
        (SamplePattern::Random, 4, true, false, 4, Luminance),
        (SamplePattern::Random, 1, false, true, 4, Luminance),
        (SamplePattern::Sobol, 4, true, true, 4, Luminance),
        (SamplePattern::Random, 3, false, true, 1, Luminance),
        // Stratified points of a square count, and of another (a Latin
        // hypercube), drawn lane by lane; the grid's under the sky.
        (SamplePattern::Stratified, 4, false, false, 4, Luminance),
        (SamplePattern::Stratified, 3, true, true, 4, Luminance),
        (SamplePattern::Grid, 4, false, true, 4, Luminance),
        // Directions cosine-weighted about each normal, one and several.
        (SamplePattern::Sobol, 1, false, true, 4, Cosine),
        (SamplePattern::Random, 3, true, true, 4, Cosine),
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
            environment_sampling: sampling,
            max_depth,
            area_sampling: glint_lighting::AreaSampling::Auto,
            mis: true,
        };
        let differentials = footprints || sky_and_mirrors;
        let compared =
            compare_lanes_with_scalar(&scene, &integrator, differentials, &mut total, &mut common);
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
                let (expected, _) = mirror_ray(&hit.unwrap(), &ray, &RayDifferential::none(&ray));
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
    use glint_lighting::EnvironmentSampling::{Cosine, Luminance};
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
    // environment samples, mirrors, glossy); the environment sampled by
    // luminance, or where the cosine is named, by the cosine about each normal.
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
    let cosine_cases = [
        (
            SamplePattern::Sobol,
            1,
            false,
            AreaSampling::Auto,
            1,
            false,
            false,
        ),
        (
            SamplePattern::Sobol,
            4,
            true,
            AreaSampling::Auto,
            5,
            true,
            true,
        ),
        (
            SamplePattern::Random,
            2,
            false,
            AreaSampling::Area,
            3,
            true,
            false,
        ),
    ];
    let cases =
        (cases.iter().map(|&c| (c, Luminance))).chain(cosine_cases.iter().map(|&c| (c, Cosine)));
    for (case, sampling) in cases {
        let (
            pattern,
            light_samples,
            footprints,
            area_sampling,
            environment_samples,
            mirrors,
            glossy,
        ) = case;
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
            environment_sampling: sampling,
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

#[test]
fn the_first_single_sample_at_the_camera_hit_reads_the_joint_pair() {
    let light = |light| DimensionPair::Light { light, depth: 0 };
    let environment = DimensionPair::Environment { depth: 0 };
    // One sample each at the camera ray's hit: the first light-like one is joint.
    let mut pairs = PairAllocation::new(0);
    assert_eq!(pairs.take(light(1), 1), DimensionPair::Joint { k: 1 });
    assert_eq!(pairs.take(light(2), 1), light(2));
    assert_eq!(pairs.take(environment, 1), environment);
    // Without area lights, the environment takes it.
    assert_eq!(
        PairAllocation::new(0).take(environment, 1),
        DimensionPair::Joint { k: 1 }
    );
    // Several samples per camera sample, or a reflection's hit: their own.
    assert_eq!(PairAllocation::new(0).take(light(0), 4), light(0));
    let deeper = DimensionPair::Light { light: 0, depth: 1 };
    assert_eq!(PairAllocation::new(1).take(deeper, 1), deeper);
}
