//! The pixel footprint, from camera ray differentials to the MIP level a texture
//! lookup reads: camera → geometry → texture, with no integrator in between.

use glam::Vec2;
use glam::{UVec2, Vec3};
use glint_camera::Camera;
use glint_geometry::{Plane, Shape};
use glint_integrator::camera_ray;
use glint_snapfmt::sig5;
use glint_texture::{Checkerboard, ImageTexture, TexCoord, TextureFilter, TextureImage, WrapMode};
use std::fmt::Write;

/// The course's ground: 8 checks of 32 texels (a 256² image), one uv unit per
/// 4 world units, seen by a 512² camera with a 45° field of view.
fn mip_levels(eye_height: f32, distance: f32) -> (f32, f32, f32) {
    mip_levels_at_scale(eye_height, distance, 1.0)
}

/// As [`mip_levels`], with the differentials shrunk to `scale` pixels.
fn mip_levels_at_scale(eye_height: f32, distance: f32, scale: f32) -> (f32, f32, f32) {
    let ground = Shape::from(
        Plane::new(Vec3::ZERO, Vec3::Y, false)
            .unwrap()
            .with_tile_size(4.0)
            .unwrap(),
    );
    let eye = Vec3::new(0.0, eye_height, 0.0);
    let target = Vec3::new(0.0, 0.0, -distance);
    // This reference up is parallel to none of the views, straight down included.
    let up = Vec3::new(0.0, 1.0, -1.0);
    let camera = Camera::new(eye, target, up, 45.0, 1.0, UVec2::new(512, 512)).unwrap();
    let (ray, diff) = camera_ray(&camera, Vec2::new(256.0, 256.0), scale);
    let hit = ground.intersect(&ray, f32::INFINITY).unwrap();
    let d = hit.differentials(&diff);
    let tc = TexCoord {
        uv: hit.uv,
        duvdx: d.duvdx,
        duvdy: d.duvdy,
    };
    let checker = Checkerboard::new(Vec3::ONE, Vec3::ZERO, 8);
    let image = TextureImage::new(checker.to_image(32));
    let level = |filter| ImageTexture::new(image.clone(), WrapMode::Repeat, filter).mip_level(&tc);
    let incidence = ray.direction.angle_between(-Vec3::Y).to_degrees();
    (
        incidence,
        level(TextureFilter::Trilinear),
        level(TextureFilter::Ewa),
    )
}

#[test]
fn mip_level_for_fixed_rays_at_several_distances_and_angles() {
    let mut s = String::from("height distance | incidence° | trilinear level | ewa level\n");
    let mut previous = (f32::NEG_INFINITY, f32::NEG_INFINITY);
    // At one height, ever farther and more grazing; then more grazing still.
    for (height, distance) in [
        (1.0, 0.001),
        (1.0, 1.0),
        (1.0, 4.0),
        (1.0, 16.0),
        (1.0, 64.0),
        (0.25, 64.0),
    ] {
        let (incidence, trilinear, ewa) = mip_levels(height, distance);
        writeln!(
            s,
            "{height:>6} {distance:>8} | {:>10} | {:>15} | {:>9}",
            sig5(incidence),
            sig5(trilinear),
            sig5(ewa)
        )
        .unwrap();
        // Farther or more grazing: never a finer level. EWA picks its level from the
        // footprint's minor axis, so it is never coarser than trilinear.
        assert!(trilinear >= previous.0 && ewa >= previous.1, "{s}");
        assert!(ewa <= trilinear + 1e-6, "{s}");
        previous = (trilinear, ewa);
    }
    insta::assert_snapshot!(s);
}

#[test]
fn straight_down_the_level_follows_the_texel_to_pixel_ratio() {
    // From height h straight down, one pixel spans 2·h·tan(22.5°)/512 world units,
    // i.e. that × 256 / 4 texels of level 0; the level is log2 of it.
    for h in [32.0f32, 128.0, 512.0, 2048.0] {
        let (_, trilinear, ewa) = mip_levels(h, 0.0001);
        let texels = 2.0 * h * 22.5f32.to_radians().tan() / 512.0 * 256.0 / 4.0;
        let expected = texels.log2().clamp(0.0, 8.0);
        assert!(expected > 0.0);
        assert!(
            (trilinear - expected).abs() < 1e-2,
            "h {h}: {trilinear} vs {expected}"
        );
        assert!((ewa - expected).abs() < 1e-2, "h {h}: {ewa} vs {expected}");
    }
}

#[test]
fn four_samples_per_pixel_read_one_level_finer() {
    // Each of 4 samples stands for a quarter of the pixel, half its width: one level.
    let (_, one, _) = mip_levels_at_scale(128.0, 0.0001, 1.0);
    let (_, four, _) = mip_levels_at_scale(128.0, 0.0001, 1.0 / 4f32.sqrt());
    assert!((one - four - 1.0).abs() < 1e-3, "{one} {four}");
}
