//! Texture filters, per lookup, on a 512 × 512 texture.
//!
//! `cargo bench -p glint-texture --bench filters`
//!
//! The texture is the course's 8 × 8 checkerboard rasterised at 64 texels per
//! check (512 × 512, repeat wrap), looked up through `Texture::evaluate` as the
//! integrator does: `nearest`, `bilinear`, `trilinear` and `ewa` image textures,
//! and the same checkerboard evaluated analytically (`checker_analytic`, box
//! filtered over the footprint). Footprints, in texels of level 0 per pixel:
//!
//! - `magnified`: ¼ texel (each texel covers 4 × 4 pixels);
//! - `1to1`: 1 texel;
//! - `minified8`: 8 texels;
//! - `aniso8to1`: 8 texels along one axis and 1 across, turned 30°.
//!
//! Each iteration looks up 4 tiles of 8 × 8 pixels (256 lookups), neighbouring
//! pixels stepping by the footprint as in a render; the tiles sit at fixed places
//! spread over the texture. The pyramid is built before timing. Throughput is in
//! lookups. `pyramid/2048` times building the MIP pyramid of a 2048 × 2048
//! checkerboard (12 levels). See `docs/microbenchmarks.md`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::{Vec2, Vec3};
use glint_texture::{
    Checkerboard, ImageTexture, MipMap, TexCoord, Texture, TextureFilter, TextureImage, WrapMode,
};
use std::hint::black_box;
use std::time::Duration;

const SIDE: f32 = 512.0;
const TILE: usize = 8;
const TILE_ORIGINS: [Vec2; 4] = [
    Vec2::new(0.13, 0.71),
    Vec2::new(0.62, 0.28),
    Vec2::new(0.37, 0.04),
    Vec2::new(0.88, 0.93),
];

/// `(name, ∂uv/∂x, ∂uv/∂y)`.
fn footprints() -> [(&'static str, Vec2, Vec2); 4] {
    let texel = 1.0 / SIDE;
    let (sin, cos) = 30f32.to_radians().sin_cos();
    [
        (
            "magnified",
            Vec2::new(0.25 * texel, 0.0),
            Vec2::new(0.0, 0.25 * texel),
        ),
        ("1to1", Vec2::new(texel, 0.0), Vec2::new(0.0, texel)),
        (
            "minified8",
            Vec2::new(8.0 * texel, 0.0),
            Vec2::new(0.0, 8.0 * texel),
        ),
        (
            "aniso8to1",
            8.0 * texel * Vec2::new(cos, sin),
            texel * Vec2::new(-sin, cos),
        ),
    ]
}

/// The 256 lookups of one iteration.
fn lookups(duvdx: Vec2, duvdy: Vec2) -> Vec<TexCoord> {
    TILE_ORIGINS
        .iter()
        .flat_map(|&origin| {
            (0..TILE * TILE).map(move |k| TexCoord {
                uv: origin + (k % TILE) as f32 * duvdx + (k / TILE) as f32 * duvdy,
                duvdx,
                duvdy,
            })
        })
        .collect()
}

fn filters(c: &mut Criterion) {
    let pattern = Checkerboard::new(Vec3::ONE, Vec3::new(0.1, 0.2, 0.8), 8);
    let image = TextureImage::from_checkerboard(pattern.clone(), 64);
    assert_eq!(image.image().width(), SIDE as u32);
    image.pyramid();
    let mut textures: Vec<(&str, Texture)> = [
        TextureFilter::Nearest,
        TextureFilter::Bilinear,
        TextureFilter::Trilinear,
        TextureFilter::Ewa,
    ]
    .into_iter()
    .map(|filter| {
        let texture = ImageTexture::new(image.clone(), WrapMode::Repeat, filter);
        (filter.name(), Texture::Image(texture))
    })
    .collect();
    textures.push((
        "checker_analytic",
        Texture::Checkerboard(Checkerboard {
            analytic: true,
            ..pattern
        }),
    ));

    let footprints = footprints();
    for (name, texture) in &textures {
        let mut group = c.benchmark_group(format!("filter/{name}"));
        group
            .sample_size(20)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2))
            .throughput(Throughput::Elements(
                (TILE_ORIGINS.len() * TILE * TILE) as u64,
            ));
        for (footprint, duvdx, duvdy) in footprints {
            let tcs = lookups(duvdx, duvdy);
            group.bench_function(footprint, |b| {
                b.iter(|| {
                    for tc in &tcs {
                        black_box(texture.evaluate(black_box(tc)));
                    }
                })
            });
        }
        group.finish();
    }
}

fn pyramid(c: &mut Criterion) {
    let side = 2048;
    let checks = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 8);
    let image = glint_texture::Image::from_fn(side, side, |x, y| {
        checks.evaluate((Vec2::new(x as f32, y as f32) + 0.5) / side as f32)
    });
    let mut group = c.benchmark_group("pyramid");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5));
    group.bench_function("2048", |b| {
        b.iter(|| black_box(MipMap::new(black_box(image.clone()))))
    });
    group.finish();
}

criterion_group!(benches, filters, pyramid);
criterion_main!(benches);
