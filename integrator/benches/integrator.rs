//! The direct integrator and the sample patterns, per call.
//!
//! `cargo bench -p glint-integrator --bench integrator`
//!
//! - `li/light_samples_{1,16}`: [`DirectIntegrator::li`] for camera rays into the
//!   course's Cornell box (Set1: five walls, four point-sampled checkered spheres,
//!   one 2 × 2 area light, ambient 0.1), built with [`SceneBuilder`], Sobol light
//!   samples. Each iteration traces 64 camera rays through the centres of an
//!   8 × 8 grid of pixels spread over the 512 × 512 image (walls, floor, ceiling,
//!   spheres and the light itself), each as camera sample 0 of its pixel; the
//!   throughput is in camera rays, so the time per ray is the iteration / 64.
//! - `fill/{random,stratified,sobol,grid}/{16,256}`: [`SamplePattern::fill`] of
//!   16 and 256 points (one area light's samples for one camera sample);
//!   throughput in points.
//!
//! See `docs/microbenchmarks.md`.

use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use glam::{UVec2, Vec2, Vec3};
use glint_camera::Camera;
use glint_geometry::{Parallelogram, Sphere};
use glint_integrator::sampling::{DimensionPair, PixelSample};
use glint_integrator::Scene;
use glint_integrator::{camera_ray, DirectIntegrator, SampleContext, SamplePattern, SceneBuilder};
use glint_lighting::{AreaLight, PhongMaterial};
use glint_texture::Checkerboard;
use std::hint::black_box;
use std::time::Duration;

const SIDE: u32 = 512;
/// Camera rays per iteration: an 8 × 8 grid of pixels.
const GRID: u32 = 8;

fn configure(group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>, elements: u64) {
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(elements));
}

/// `scenes/cornell-set1.toml`, built in code.
fn cornell() -> Scene {
    let mut builder = SceneBuilder::new();
    let plain = |c: [f32; 3]| PhongMaterial::new(Vec3::from(c), 16.0);
    let gray = builder.material(plain([0.7, 0.7, 0.7]));
    let red = builder.material(plain([1.0, 0.0, 0.0]));
    let green = builder.material(plain([0.0, 1.0, 0.0]));
    let wall = |o: [f32; 3], e1: [f32; 3], e2: [f32; 3], n: [f32; 3]| {
        Parallelogram::new(o.into(), e1.into(), e2.into(), false)
            .unwrap()
            .facing(n.into())
    };
    builder
        .shape(
            wall(
                [-10., -10., -10.],
                [20., 0., 0.],
                [0., 20., 0.],
                [0., 0., 1.],
            ),
            gray,
        )
        .shape(
            wall([-6., -7., -11.], [0., 0., 20.], [0., 20., 0.], [1., 0., 0.]),
            red,
        )
        .shape(
            wall([6., -7., -11.], [0., 0., 20.], [0., 20., 0.], [-1., 0., 0.]),
            green,
        )
        .shape(
            wall([-7., -6., -11.], [20., 0., 0.], [0., 0., 20.], [0., 1., 0.]),
            gray,
        )
        .shape(
            wall([-7., 6., -11.], [20., 0., 0.], [0., 0., 20.], [0., -1., 0.]),
            gray,
        );
    let spheres = [
        ([3., 1., -7.], 1.5, [[0., 0., 1.], [1., 1., 1.]], 4, 22.0),
        (
            [2., -3.2, -5.],
            1.0,
            [[0.2, 0.5, 0.], [0.9, 0., 0.4]],
            4,
            40.0,
        ),
        ([-4., 2., -5.], 1.8, [[1., 1., 1.], [0., 0., 0.]], 8, 120.0),
        (
            [-2., -4.5, -8.],
            2.0,
            [[0.3, 1., 0.4], [0.3, 0.7, 0.2]],
            4,
            16.0,
        ),
    ];
    for (centre, radius, [even, odd], checks, shininess) in spheres {
        let texture = Checkerboard::new(even.into(), odd.into(), checks);
        let material = builder.material(PhongMaterial::new(texture, shininess));
        builder.shape(Sphere::new(centre.into(), radius).unwrap(), material);
    }
    builder
        .area_light(
            AreaLight::new(
                Vec3::new(0.0, 5.9, -6.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::ONE,
            )
            .unwrap(),
        )
        .ambient(Vec3::splat(0.1));
    let camera = Camera::new(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        45.0,
        1.0,
        UVec2::splat(SIDE),
    )
    .unwrap();
    builder.build(camera).expect("a valid scene")
}

fn li(c: &mut Criterion) {
    let scene = cornell();
    let step = SIDE / GRID;
    // (pixel index, raster position)
    let pixels: Vec<(u64, Vec2)> = (0..GRID * GRID)
        .map(|k| {
            let (x, y) = ((k % GRID) * step + step / 2, (k / GRID) * step + step / 2);
            (
                u64::from(y * SIDE + x),
                Vec2::new(x as f32 + 0.5, y as f32 + 0.5),
            )
        })
        .collect();
    let mut group = c.benchmark_group("li");
    configure(&mut group, pixels.len() as u64);
    for light_samples in [1, 16] {
        let integrator = DirectIntegrator {
            light_samples,
            light_pattern: SamplePattern::Sobol,
            environment_samples: 0,
            environment_pattern: SamplePattern::Sobol,
            environment_sampling: glint_lighting::EnvironmentSampling::Luminance,
            max_depth: 4,
            area_sampling: glint_lighting::AreaSampling::Auto,
            mis: true,
        };
        let mut ctx = SampleContext::new(light_samples, 0);
        group.bench_function(format!("light_samples_{light_samples}"), |b| {
            b.iter(|| {
                for &(pixel, raster) in &pixels {
                    ctx.begin_sample(0, pixel, 0);
                    // A render of 16 samples per pixel shrinks differentials to ¼.
                    let (ray, diff) = camera_ray(&scene.camera, raster, 0.25);
                    black_box(integrator.li(&scene, black_box(&ray), &diff, &mut ctx));
                }
            })
        });
    }
    group.finish();
}

fn fill(c: &mut Criterion) {
    for n in [16u32, 256] {
        let mut group = c.benchmark_group(format!("fill/{n}"));
        configure(&mut group, u64::from(n));
        let mut points = vec![Vec2::ZERO; n as usize];
        for pattern in [
            SamplePattern::Random,
            SamplePattern::Stratified,
            SamplePattern::Sobol,
            SamplePattern::Grid,
        ] {
            let sample = PixelSample {
                seed: 0,
                pixel: 1234,
                sample: 0,
            };
            let mut rng = sample.rng();
            let sobol = sample.sobol_points(DimensionPair::Light { light: 0, depth: 0 }, n);
            group.bench_function(pattern.name(), |b| {
                b.iter(|| {
                    pattern.fill(&mut rng, black_box(sobol), &mut points);
                    black_box(&points);
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, li, fill);
criterion_main!(benches);
