//! Environment lighting: what misses see, mirrors, and the environment as a light.

use glam::{UVec2, Vec3};
use glint_camera::Camera;
use glint_geometry::{Parallelogram, Sphere};
use glint_integrator::{render, Aov, RenderSettings, SamplePattern, Scene, SceneBuilder};
use glint_lighting::{EnvironmentLight, EnvironmentSampling, PhongMaterial};
use glint_texture::{CubeMap, Environment, Image, LatLongMap, Texture};

fn camera(resolution: u32) -> Camera {
    Camera::new(
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        40.0,
        1.0,
        UVec2::splat(resolution),
    )
    .unwrap()
}

fn settings(spp: u32, environment_samples: u32) -> RenderSettings {
    RenderSettings {
        spp,
        pixel_pattern: SamplePattern::Stratified,
        environment_samples,
        ..RenderSettings::default()
    }
}

fn white_diffuse() -> PhongMaterial {
    PhongMaterial {
        specular: Some(Texture::Constant(Vec3::ZERO)),
        ..PhongMaterial::new(Vec3::ONE, 1.0)
    }
}

fn sphere_in(environment: Environment, material: PhongMaterial) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.material(material);
    b.shape(Sphere::new(Vec3::ZERO, 1.0).unwrap(), m)
        .environment(EnvironmentLight::new(environment, 0.3, 1.0));
    b.build(camera(24)).unwrap()
}

#[test]
fn a_mirror_in_a_one_color_cube_map_shows_no_seam() {
    let c = Vec3::new(0.25, 0.5, 0.75);
    let faces = std::array::from_fn(|_| Image::from_fn(8, 8, |_, _| c));
    let env = Environment::CubeMap(CubeMap::new(faces).unwrap());
    let scene = sphere_in(env, PhongMaterial::mirror(Vec3::ONE));
    let film = render(&scene, &settings(4, 0), &|_, _| {}).unwrap().film;
    // Every pixel, on the sphere (reflections across every face edge and corner, at
    // every MIP level the widening footprints reach) or off it, is exactly c.
    for p in film.pixels() {
        assert!((*p - c).abs().max_element() < 1e-6, "{p}");
    }
}

#[test]
fn furnace_constant_white_environment_gives_exactly_one() {
    let scene = sphere_in(Environment::Constant(Vec3::ONE), white_diffuse());
    let film = render(&scene, &settings(4, 8), &|_, _| {}).unwrap().film;
    for p in film.pixels() {
        assert!((*p - Vec3::ONE).abs().max_element() < 1e-5, "{p}");
    }
}

#[test]
fn furnace_constant_white_maps_give_exactly_one() {
    // A map whose texels are all equal is a constant environment, importance-sampled
    // exactly (by the cosine): every pixel is 1 to float precision.
    let latlong = Environment::LatLong(LatLongMap::new(Image::from_fn(64, 32, |_, _| Vec3::ONE)));
    let faces = std::array::from_fn(|_| Image::from_fn(8, 8, |_, _| Vec3::ONE));
    let cube = Environment::CubeMap(CubeMap::new(faces).unwrap());
    for map in [latlong, cube] {
        let film = render(
            &sphere_in(map, white_diffuse()),
            &settings(4, 8),
            &|_, _| {},
        )
        .unwrap()
        .film;
        for p in film.pixels() {
            assert!((*p - Vec3::ONE).abs().max_element() < 1e-5, "{p}");
        }
    }
}

#[test]
fn furnace_nearly_white_map_gives_one_within_monte_carlo_tolerance() {
    // Not quite constant, so sampled by luminance: 1 within Monte Carlo tolerance.
    let map = Environment::LatLong(LatLongMap::new(Image::from_fn(64, 32, |x, _| {
        Vec3::splat(if x % 2 == 0 { 0.999 } else { 1.001 })
    })));
    let film = render(
        &sphere_in(map, white_diffuse()),
        &settings(16, 64),
        &|_, _| {},
    )
    .unwrap()
    .film;
    // Pixels are independent estimates of 1 (the map's ±0.001 aside): their
    // mean lies within 4 standard errors, and a 1% bias would not.
    let values: Vec<f64> = film.pixels().iter().map(|p| p.x as f64).collect();
    let (mean, se) = mean_and_standard_error(&values);
    let within = |bias: f64| (bias * mean - 1.0).abs() <= 4.0 * bias * se + 0.001;
    assert!(within(1.0), "mean {mean} ± {se}");
    assert!(!within(1.01), "a 1% bias would pass: ± {se}");
    let sd = se * (values.len() as f64).sqrt();
    for p in film.pixels() {
        assert!((p.x as f64 - 1.0).abs() < 6.0 * sd, "{p} (pixel sd {sd})");
    }
}

/// The mean of independent draws and its standard error.
fn mean_and_standard_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

#[test]
fn the_environment_pattern_places_the_environment_samples() {
    // A diffuse sphere under a smooth environment, against 1024 stratified
    // directions per shading point: every pattern converges to it, and with 16
    // directions Sobol's error is well below random's.
    let (latlong, _) = gradient_maps();
    let scene = sphere_in(latlong, white_diffuse());
    let film = |environment_samples, environment_pattern| {
        let s = RenderSettings {
            environment_pattern,
            ..settings(1, environment_samples)
        };
        render(&scene, &s, &|_, _| {}).unwrap().film
    };
    let reference = film(1024, SamplePattern::Stratified);
    let errors: Vec<f32> = [
        SamplePattern::Random,
        SamplePattern::Stratified,
        SamplePattern::Grid,
        SamplePattern::Sobol,
    ]
    .into_iter()
    .map(|pattern| relative_mse(&film(16, pattern), &reference))
    .collect();
    let [random, stratified, grid, sobol] = errors[..] else {
        unreachable!()
    };
    assert!(stratified < random && grid < random, "{errors:?}");
    assert!(sobol < 0.5 * random, "{errors:?}");
}

/// A smooth environment, as a lat-long image and as the cube map resampled from it.
fn gradient_maps() -> (Environment, Environment) {
    let radiance =
        |d: Vec3| Vec3::new(0.5 + 0.5 * d.y, 0.4 + 0.3 * d.x, 0.6 - 0.4 * d.z).max(Vec3::ZERO);
    let latlong = Image::from_fn(256, 128, |x, y| {
        let uv = glam::Vec2::new((x as f32 + 0.5) / 256.0, (y as f32 + 0.5) / 128.0);
        radiance(glint_texture::latlong_direction(uv))
    });
    let faces = std::array::from_fn(|face| {
        Image::from_fn(64, 64, |x, y| {
            let st = glam::Vec2::new((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 64.0);
            radiance(glint_texture::cube_direction(face, st).normalize())
        })
    });
    (
        Environment::LatLong(LatLongMap::new(latlong)),
        Environment::CubeMap(CubeMap::new(faces).unwrap()),
    )
}

/// pbrt-v4's relative MSE (`imgtool diff --metric MRSE`), as `glint diff` computes
/// it: the mean over pixels and channels of `(a − b)²/(b + 0.01)²`.
fn relative_mse(a: &glint_camera::Film, b: &glint_camera::Film) -> f32 {
    a.pixels()
        .iter()
        .zip(b.pixels())
        .map(|(a, b)| {
            let d = *b + Vec3::splat(0.01);
            ((*a - *b) * (*a - *b) / (d * d)).element_sum() / 3.0
        })
        .sum::<f32>()
        / a.pixels().len() as f32
}

#[test]
fn cube_map_and_latlong_renders_of_one_environment_agree() {
    let (latlong, cube) = gradient_maps();
    let both = |material: PhongMaterial, environment_samples| {
        let films: Vec<_> = [latlong.clone(), cube.clone()]
            .into_iter()
            .map(|env| {
                let s = settings(4, environment_samples);
                render(&sphere_in(env, material.clone()), &s, &|_, _| {})
                    .unwrap()
                    .film
            })
            .collect();
        relative_mse(&films[0], &films[1])
    };
    // Seen in a mirror (no Monte Carlo noise): the two mappings agree to filtering.
    let mirror = both(PhongMaterial::mirror(Vec3::ONE), 0);
    assert!(mirror < 1e-4, "mirror: relative MSE {mirror}");
    // Lighting a diffuse surface: equal up to the noise of 4 × 256 samples.
    let diffuse = both(white_diffuse(), 256);
    assert!(diffuse < 2e-3, "diffuse: relative MSE {diffuse}");
}

#[test]
fn reflections_stop_at_max_depth() {
    // Two facing mirrors: a ray between them bounces until max_depth, then sees black.
    let mut b = SceneBuilder::new();
    let m = b.material(PhongMaterial::mirror(Vec3::ONE));
    let wall = |z: f32, facing: f32| {
        Parallelogram::new(
            Vec3::new(-5.0, -5.0, z),
            Vec3::X * 10.0,
            Vec3::Y * 10.0,
            true,
        )
        .unwrap()
        .facing(Vec3::new(0.0, 0.0, facing))
    };
    b.shape(wall(-1.0, 1.0), m)
        .shape(wall(6.0, -1.0), m)
        .environment(EnvironmentLight::new(
            Environment::Constant(Vec3::ONE),
            0.0,
            1.0,
        ));
    let scene = b.build(camera(3)).unwrap();
    for max_depth in [0, 1, 3] {
        let s = RenderSettings {
            max_depth,
            aov: Some(Aov::ReflectionDepth),
            ..settings(1, 0)
        };
        let depth = render(&scene, &s, &|_, _| {}).unwrap().film.pixel(1, 1);
        assert_eq!(depth.x, max_depth as f32);
        let radiance = render(&scene, &RenderSettings { aov: None, ..s }, &|_, _| {})
            .unwrap()
            .film;
        assert_eq!(
            radiance.pixel(1, 1),
            Vec3::ZERO,
            "trapped between mirrors: black"
        );
    }
}

/// Environment samples by luminance and by the cosine estimate one image:
/// over 16 seeds each, the means of the image of a diffuse sphere under a
/// coloured gradient agree within 4 standard errors of their difference (a
/// cosine density 3% too high moves them 7 apart).
#[test]
fn luminance_and_cosine_sampling_agree_within_their_standard_errors() {
    let (latlong, _) = gradient_maps();
    let scene = sphere_in(latlong, white_diffuse());
    let means = |sampling| -> Vec<f64> {
        (0..16)
            .map(|seed| {
                let s = RenderSettings {
                    seed,
                    pixel_pattern: SamplePattern::Random,
                    environment_pattern: SamplePattern::Random,
                    environment_sampling: sampling,
                    ..settings(4, 8)
                };
                let film = render(&scene, &s, &|_, _| {}).unwrap().film;
                let sum: f64 = film.pixels().iter().map(|p| p.element_sum() as f64).sum();
                sum / film.pixels().len() as f64
            })
            .collect()
    };
    let (lum, lum_se) = mean_and_standard_error(&means(EnvironmentSampling::Luminance));
    let (cos, cos_se) = mean_and_standard_error(&means(EnvironmentSampling::Cosine));
    let standard_error = lum_se.hypot(cos_se);
    assert!(standard_error > 0.0 && standard_error < 1e-2 * lum);
    assert!(
        (lum - cos).abs() < 4.0 * standard_error,
        "by luminance {lum}, by the cosine {cos}: {:.1} standard errors apart",
        (lum - cos).abs() / standard_error
    );
}
