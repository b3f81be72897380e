//! The direct integrator against closed forms and the report's rules.

mod common;

use common::{camera, diffuse};
use glam::{UVec2, Vec3};
use glint_camera::Camera;
use glint_geometry::{Parallelogram, Plane, Sphere};
use glint_integrator::{render, RenderSettings, SamplePattern, Scene, SceneBuilder};
use glint_lighting::{AreaLight, PhongMaterial, PointLight};

const KD: Vec3 = Vec3::new(0.8, 0.6, 0.4);
const LIGHT_POS: Vec3 = Vec3::new(1.0, 3.0, -2.0);
const LIGHT_COLOR: Vec3 = Vec3::new(1.0, 0.9, 0.8);
const AMBIENT: Vec3 = Vec3::new(0.05, 0.04, 0.03);

fn one_sample_at_pixel_centres() -> RenderSettings {
    RenderSettings {
        spp: 1,
        pixel_pattern: SamplePattern::Grid,
        light_samples: 1,
        light_pattern: SamplePattern::Grid,
        ..RenderSettings::default()
    }
}

fn plane_under_point_light(resolution: UVec2) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(diffuse(KD));
    b.shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), m)
        .point_light(PointLight {
            position: LIGHT_POS,
            color: LIGHT_COLOR,
        })
        .ambient(AMBIENT);
    b.build(camera(resolution)).unwrap()
}

/// The expected radiance of pixel (x, y), worked out from first principles: the
/// pinhole ray through the pixel centre, its hit on y = 0, and Lambert's cosine.
fn closed_form(resolution: UVec2, x: u32, y: u32) -> Vec3 {
    let eye = Vec3::new(0.0, 2.0, 4.0);
    let forward = (Vec3::new(0.0, 0.0, -2.0) - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half_h = (25f32).to_radians().tan();
    let half_w = half_h * resolution.x as f32 / resolution.y as f32;
    let sx = 2.0 * (x as f32 + 0.5) / resolution.x as f32 - 1.0;
    let sy = 1.0 - 2.0 * (y as f32 + 0.5) / resolution.y as f32;
    let d = (forward + sx * half_w * right + sy * half_h * up).normalize();
    if d.y >= 0.0 {
        return Vec3::ZERO;
    }
    let p = eye + (-eye.y / d.y) * d;
    let cosine = (LIGHT_POS - p).normalize().y;
    LIGHT_COLOR * KD * cosine.max(0.0) + AMBIENT * KD
}

#[test]
fn point_light_over_a_diffuse_plane_matches_the_closed_form() {
    let resolution = UVec2::new(24, 16);
    let scene = plane_under_point_light(resolution);
    let out = render(&scene, &one_sample_at_pixel_centres(), &|_, _| {}).unwrap();
    let mut worst = 0.0f32;
    for y in 0..resolution.y {
        for x in 0..resolution.x {
            let expected = closed_form(resolution, x, y);
            let got = out.film.pixel(x, y);
            for c in 0..3 {
                let err = (got[c] - expected[c]).abs() / expected[c].max(1e-3);
                worst = worst.max(err);
            }
        }
    }
    assert!(worst < 1e-5, "worst relative error {worst}");
    // The view straddles the horizon: sky (black) at the top, lit plane at the bottom.
    assert!((0..resolution.x).all(|x| out.film.pixel(x, 0) == Vec3::ZERO));
    assert!((0..resolution.x).all(|x| out.film.pixel(x, resolution.y - 1).x > 0.1));
}

#[test]
fn shadowed_points_get_ambient_only_and_misses_are_black() {
    let mut b = SceneBuilder::new();
    let m = b.material(diffuse(KD));
    b.shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), m)
        // A large sphere between the light and the plane's centre of view.
        .shape(Sphere::new(Vec3::new(0.0, 1.5, -2.0), 0.5).unwrap(), m)
        .point_light(PointLight {
            position: Vec3::new(0.0, 5.0, -2.0),
            color: Vec3::ONE,
        })
        .ambient(AMBIENT);
    let cam = Camera::new(
        Vec3::new(0.0, 0.3, 0.0),
        Vec3::new(0.0, 0.0, -2.0),
        Vec3::Y,
        30.0,
        1.0,
        UVec2::new(9, 9),
    )
    .unwrap();
    let scene = b.build(cam).unwrap();
    let camera_ray = scene.camera.generate_ray(4.5, 4.5);
    let ray = glint_geometry::Ray::new(camera_ray.origin, camera_ray.direction);
    let hit = scene.shapes.closest_hit(&ray, f32::INFINITY).unwrap();
    assert!(
        hit.point.distance(Vec3::new(0.0, 0.0, -2.0)) < 0.1,
        "{hit:?}"
    );
    let out = render(&scene, &one_sample_at_pixel_centres(), &|_, _| {}).unwrap();
    let centre = out.film.pixel(4, 4);
    assert!(
        (centre - AMBIENT * KD).abs().max_element() < 1e-7,
        "{centre}"
    );
    // The top row looks above the horizon: nothing there.
    assert_eq!(out.film.pixel(4, 0), Vec3::ZERO);
}

fn box_with_area_light(resolution: UVec2) -> Scene {
    let mut b = SceneBuilder::new();
    let gray = b.material(PhongMaterial::new(Vec3::splat(0.7), 16.0));
    let floor = Parallelogram::new(
        Vec3::new(-5.0, -2.0, -10.0),
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 0.0),
        false,
    )
    .unwrap();
    b.shape(floor, gray)
        .shape(Sphere::new(Vec3::new(0.0, -1.0, -5.0), 1.0).unwrap(), gray)
        .area_light(
            AreaLight::new(
                Vec3::new(0.0, 2.0, -5.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::new(0.9, 0.8, 0.0),
            )
            .unwrap(),
        )
        .ambient(Vec3::splat(0.1));
    let cam = Camera::new(
        Vec3::new(0.0, -1.0, 3.0),
        Vec3::new(0.0, 0.5, -5.0),
        Vec3::Y,
        60.0,
        1.0,
        resolution,
    )
    .unwrap();
    b.build(cam).unwrap()
}

#[test]
fn a_camera_ray_that_hits_the_light_sees_its_color() {
    let scene = box_with_area_light(UVec2::new(32, 32));
    // Find a pixel whose centre ray hits the light and check its exact color.
    let out = render(&scene, &one_sample_at_pixel_centres(), &|_, _| {}).unwrap();
    let light_pixels = out
        .film
        .pixels()
        .iter()
        .filter(|p| **p == Vec3::new(0.9, 0.8, 0.0))
        .count();
    assert!(light_pixels > 4, "the light covers {light_pixels} pixels");
}

#[test]
fn output_is_bit_identical_for_any_thread_count() {
    let scene = box_with_area_light(UVec2::new(40, 23));
    let settings = |threads| RenderSettings {
        spp: 3,
        pixel_pattern: SamplePattern::Stratified,
        light_samples: 5,
        light_pattern: SamplePattern::Random,
        seed: 42,
        threads: Some(threads),
        ..RenderSettings::default()
    };
    let one = render(&scene, &settings(1), &|_, _| {}).unwrap();
    let four = render(&scene, &settings(4), &|_, _| {}).unwrap();
    let bits = |f: &glint_camera::Film| -> Vec<u32> {
        f.pixels()
            .iter()
            .flat_map(|p| p.to_array())
            .map(f32::to_bits)
            .collect()
    };
    assert_eq!(bits(&one.film), bits(&four.film));
    assert_eq!(one.stats.shadow_rays, four.stats.shadow_rays);
    let other_seed = render(
        &scene,
        &RenderSettings {
            seed: 7,
            ..settings(2)
        },
        &|_, _| {},
    )
    .unwrap();
    assert_ne!(bits(&one.film), bits(&other_seed.film));
}

#[test]
fn sobol_renders_are_bit_identical_for_any_thread_count() {
    // Sobol alone and mixed with the PCG patterns, at counts that are not powers
    // of two (so camera samples share blocks of the light sequences).
    let scene = box_with_area_light(UVec2::new(40, 23));
    let settings = |threads, pixel_pattern, light_pattern| RenderSettings {
        spp: 3,
        pixel_pattern,
        light_samples: 5,
        light_pattern,
        seed: 42,
        threads: Some(threads),
        ..RenderSettings::default()
    };
    let bits = |f: &glint_camera::Film| -> Vec<u32> {
        f.pixels()
            .iter()
            .flat_map(|p| p.to_array())
            .map(f32::to_bits)
            .collect()
    };
    let mut images = Vec::new();
    for (pixel, light) in [
        (SamplePattern::Sobol, SamplePattern::Sobol),
        (SamplePattern::Sobol, SamplePattern::Random),
        (SamplePattern::Stratified, SamplePattern::Sobol),
    ] {
        let one = render(&scene, &settings(1, pixel, light), &|_, _| {}).unwrap();
        let four = render(&scene, &settings(4, pixel, light), &|_, _| {}).unwrap();
        assert_eq!(bits(&one.film), bits(&four.film), "{pixel:?}/{light:?}");
        assert_eq!(one.stats.shadow_rays, four.stats.shadow_rays);
        images.push(bits(&one.film));
    }
    assert_ne!(images[0], images[1]);
    assert_ne!(images[0], images[2]);
    let other_seed = RenderSettings {
        seed: 7,
        ..settings(2, SamplePattern::Sobol, SamplePattern::Sobol)
    };
    assert_ne!(
        images[0],
        bits(&render(&scene, &other_seed, &|_, _| {}).unwrap().film)
    );
}

#[test]
fn sobol_light_samples_have_less_error_than_random_ones() {
    // Soft shadows and the area light's falloff, against 1024 stratified light
    // samples at the pixel centres: with 16 samples per pixel, Sobol's error is
    // well below random's (the same number of shadow rays).
    let scene = box_with_area_light(UVec2::new(32, 24));
    let settings = |light_samples, light_pattern| RenderSettings {
        light_samples,
        light_pattern,
        ..one_sample_at_pixel_centres()
    };
    let film = |s: &RenderSettings| render(&scene, s, &|_, _| {}).unwrap().film;
    let reference = film(&settings(1024, SamplePattern::Stratified));
    let mse = |pattern| {
        let f = film(&settings(16, pattern));
        f.pixels()
            .iter()
            .zip(reference.pixels())
            .map(|(a, b)| (*a - *b).length_squared() as f64)
            .sum::<f64>()
            / f.pixels().len() as f64
    };
    let (sobol, random) = (mse(SamplePattern::Sobol), mse(SamplePattern::Random));
    assert!(
        sobol < 0.5 * random,
        "MSE sobol {sobol:.3e}, random {random:.3e}"
    );
}

#[test]
fn soft_shadow_fraction_matches_the_sample_average() {
    // A point under the light's centre with half the light hidden: with a 2x2 grid
    // of light samples exactly 2 of 4 samples are visible.
    let mut b = SceneBuilder::new();
    let m = b.material(diffuse(Vec3::ONE));
    b.shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), m)
        // Blocker covering x < 0 just under the light.
        .shape(
            Parallelogram::new(
                Vec3::new(-3.0, 1.9, -3.0),
                Vec3::new(0.0, 0.0, 6.0),
                Vec3::new(3.0, 0.0, 0.0),
                true,
            )
            .unwrap(),
            m,
        )
        .area_light(AreaLight::new(Vec3::new(0.0, 2.0, 0.0), Vec3::X, Vec3::Z, Vec3::ONE).unwrap());
    let cam = Camera::new(
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::ZERO,
        Vec3::Y,
        1.0,
        1.0,
        UVec2::ONE,
    )
    .unwrap();
    let scene = b.build(cam).unwrap();
    let settings = RenderSettings {
        light_samples: 4,
        ..one_sample_at_pixel_centres()
    };
    let out = render(&scene, &settings, &|_, _| {}).unwrap();
    // Visible samples at x = +0.25, z = ±0.25 from the origin at height 2.
    let expected: f32 = [-0.25f32, 0.25]
        .iter()
        .map(|z| {
            let l = Vec3::new(0.25, 2.0, *z) - Vec3::ZERO;
            l.normalize().y
        })
        .sum::<f32>()
        / 4.0;
    let got = out.film.pixel(0, 0);
    assert!(
        (got.x - expected).abs() < 2e-3,
        "got {got}, expected {expected}"
    );
}

#[test]
fn invalid_settings_are_refused() {
    let scene = plane_under_point_light(UVec2::new(2, 2));
    for bad in [
        RenderSettings {
            spp: 0,
            ..Default::default()
        },
        RenderSettings {
            spp: 8,
            pixel_pattern: SamplePattern::Grid,
            ..Default::default()
        },
        RenderSettings {
            light_samples: 2,
            light_pattern: SamplePattern::Grid,
            ..Default::default()
        },
        RenderSettings {
            threads: Some(0),
            ..Default::default()
        },
        RenderSettings {
            spp: u32::MAX,
            ..Default::default()
        },
        RenderSettings {
            light_samples: glint_integrator::MAX_SAMPLES + 1,
            ..Default::default()
        },
        RenderSettings {
            environment_samples: 8,
            environment_pattern: SamplePattern::Grid,
            ..Default::default()
        },
    ] {
        assert!(render(&scene, &bad, &|_, _| {}).is_err(), "{bad:?}");
    }
    // Without environment samples the environment's pattern places nothing.
    let none = RenderSettings {
        environment_samples: 0,
        environment_pattern: SamplePattern::Grid,
        ..Default::default()
    };
    assert!(render(&scene, &none, &|_, _| {}).is_ok());
}
