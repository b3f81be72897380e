//! Camera ray generation, per ray, on a 512 × 512 film (the course's Set1 camera).
//!
//! `cargo bench -p glint-camera --bench camera`
//!
//! Each iteration generates the rays through the 512 pixel centres of one row
//! (the next row each time), so the throughput is rays per second and the time
//! per ray is the iteration time / 512. See `docs/microbenchmarks.md`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::{UVec2, Vec3};
use glint_camera::Camera;
use std::hint::black_box;
use std::time::Duration;

const SIDE: u32 = 512;

fn set1_camera() -> Camera {
    Camera::new(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        45.0,
        1.0,
        UVec2::splat(SIDE),
    )
    .expect("a valid camera")
}

fn camera_rays(c: &mut Criterion) {
    let camera = set1_camera();
    let mut group = c.benchmark_group("camera");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(u64::from(SIDE)));

    group.bench_function("generate_ray", |b| {
        let mut row = 0u32;
        b.iter(|| {
            row = (row + 1) % SIDE;
            let y = row as f32 + 0.5;
            for x in 0..SIDE {
                black_box(camera.generate_ray(black_box(x as f32 + 0.5), y));
            }
        })
    });

    group.bench_function("generate_ray_differential", |b| {
        let mut row = 0u32;
        b.iter(|| {
            row = (row + 1) % SIDE;
            let y = row as f32 + 0.5;
            for x in 0..SIDE {
                black_box(camera.generate_ray_differential(black_box(x as f32 + 0.5), y));
            }
        })
    });
    group.finish();
}

criterion_group!(benches, camera_rays);
criterion_main!(benches);
