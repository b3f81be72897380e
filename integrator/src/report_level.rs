//! The MIP level the course report chooses (section 2.8), for `glint explain`
//! and the `report-mip-level` AOV, beside the level Glint's filters read.
//!
//! The report reads level `log2(L/W)` at a camera ray's hit:
//! - `L = 2·t·tan(fov/2) / (r·|N·D|)`, a pixel's height at the hit's distance
//!   `t` along the ray (`D` its unit direction, `r` the vertical resolution,
//!   `fov` the vertical field of view), stretched by the surface's slant (`N`
//!   the geometric normal; the report writes `−N·D` with `N` facing the
//!   camera).
//! - `W = |J_T|/m`, a texel's width on the surface: `m` is the texture's
//!   resolution (its larger side, in texels) and `|J_T|` the length that one
//!   unit of uv covers on the surface. The report calls `|J_T|` the
//!   determinant of the Jacobian `(∂p/∂u ∂p/∂v)`; for a 3 × 2 matrix that is
//!   the area factor `|∂p/∂u × ∂p/∂v|`, so Glint takes its square root, a
//!   length, divided by `√|s_u·s_v|` for the material's `uv_scale` `s`.
//!
//! `L` is a whole pixel's footprint, so the level does not depend on the
//! samples per pixel. Glint's own level ([`glint_texture::Texture::mip_level`])
//! comes from the ray differentials, shrunk to each sample's share of the
//! pixel, and differs (`docs/checking-your-ray-tracer.md` compares the two).

use glint_camera::Camera;
use glint_geometry::{Hit, Ray};
use glint_lighting::PhongMaterial;
use glint_texture::Texture;

/// The report's MIP level of one texture lookup, with its parts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReportLevel {
    /// `log2(L/W)`.
    pub level: f32,
    /// `L`: the pixel's height on the surface, in world units.
    pub l: f32,
    /// `W = |J_T|/m`: a texel's width on the surface, in world units.
    pub w: f32,
    /// `m`: the texture's resolution, its larger side in texels.
    pub m: u32,
}

/// The report's level for `texture`, read through `material` at `hit`, the
/// first hit of the camera ray `ray`. `None` unless the texture is an image,
/// or where the level is not finite (a ray grazing the surface, a surface
/// without uv derivatives).
pub fn report_level(
    camera: &Camera,
    ray: &Ray,
    hit: &Hit,
    material: &PhongMaterial,
    texture: &Texture,
) -> Option<ReportLevel> {
    let Texture::Image(texture) = texture else {
        return None;
    };
    let image = texture.image.image();
    let m = image.width().max(image.height());
    let l = pixel_height_on_surface(camera, ray, hit);
    let w = uv_unit_length(hit, material) / m as f32;
    let level = (l / w).log2();
    level.is_finite().then_some(ReportLevel { level, l, w, m })
}

/// The report's `L = 2·t·tan(fov/2) / (r·|N·D|)` at `hit` of `ray`.
pub fn pixel_height_on_surface(camera: &Camera, ray: &Ray, hit: &Hit) -> f32 {
    let length = ray.direction.length();
    // `hit.t` counts multiples of the direction, which need not be a unit vector.
    let t = hit.t * length;
    let cos = (hit.geometric_normal.dot(ray.direction) / length).abs();
    let rows = camera.resolution().y as f32;
    2.0 * t * (0.5 * camera.fov_y()).tan() / (rows * cos)
}

/// The report's `|J_T|`: the world length one unit of the material's uv
/// covers at `hit`, `√|∂p/∂u × ∂p/∂v| / √|s_u·s_v|`.
pub fn uv_unit_length(hit: &Hit, material: &PhongMaterial) -> f32 {
    let area = hit.dpdu.cross(hit.dpdv).length();
    let scale = material.uv_transform.scale;
    (area / (scale.x * scale.y).abs()).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{UVec2, Vec3};
    use glint_geometry::Plane;
    use glint_lighting::UvTransform;
    use glint_texture::{Checkerboard, ImageTexture, TextureFilter, TextureImage, WrapMode};

    /// 3 units above the origin, looking straight down, 60° over 100 pixels.
    fn top_down_camera() -> Camera {
        Camera::new(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::ZERO,
            Vec3::Z,
            60.0,
            1.0,
            UVec2::new(100, 100),
        )
        .unwrap()
    }

    /// Straight down onto a plane of 2 world units per uv unit, 3 above it:
    /// `L = 2·3·tan(30°)/100`, `W = 2/256`, whatever the samples per pixel.
    #[test]
    fn straight_down_the_level_is_the_pixel_over_the_texel() {
        let camera = top_down_camera();
        let plane = Plane::new(Vec3::ZERO, Vec3::Y, false)
            .and_then(|p| p.with_tile_size(2.0))
            .unwrap();
        let c = camera.generate_ray(50.0, 50.0);
        let ray = Ray::new(c.origin, c.direction);
        let t = plane.hit_distance(&ray, f32::INFINITY).unwrap();
        let hit = plane.surface_at(&ray, t);
        let checks = Checkerboard::new(Vec3::ONE, Vec3::ZERO, 8);
        let image = TextureImage::from_checkerboard(checks, 32);
        let texture = Texture::Image(ImageTexture::new(
            image,
            WrapMode::Repeat,
            TextureFilter::Trilinear,
        ));
        let material = PhongMaterial::new(Vec3::ONE, 1.0);
        let r = report_level(&camera, &ray, &hit, &material, &texture).unwrap();
        let l = 6.0 * 30f32.to_radians().tan() / 100.0;
        assert!((r.l - l).abs() < 1e-6 * l, "{r:?}");
        assert_eq!(r.m, 256);
        assert!((r.w - 2.0 / 256.0).abs() < 1e-7, "{r:?}");
        assert!((r.level - (l / (2.0 / 256.0)).log2()).abs() < 1e-5, "{r:?}");
        // A uv_scale of 4 repeats the texture four times: texels 4 times narrower.
        let scaled = PhongMaterial {
            uv_transform: UvTransform {
                scale: glam::Vec2::splat(4.0),
                ..UvTransform::default()
            },
            ..material.clone()
        };
        let s = report_level(&camera, &ray, &hit, &scaled, &texture).unwrap();
        assert!(
            (s.level - r.level - 2.0).abs() < 1e-5,
            "{s:?} against {r:?}"
        );
        // No level for what is not an image.
        let constant = Texture::Constant(Vec3::ONE);
        assert_eq!(
            report_level(&camera, &ray, &hit, &material, &constant),
            None
        );
    }

    /// The `report-mip-level` AOV, straight down as above: the closed form at
    /// the centre pixel with 1 sample or 4, and 0 on a constant material.
    #[test]
    fn the_aov_is_the_reports_level_whatever_the_samples_per_pixel() {
        use crate::{render, Aov, RenderSettings, SamplePattern, SceneBuilder};
        use glint_geometry::Sphere;
        let checks = Checkerboard::new(Vec3::ONE, Vec3::ZERO, 8);
        let texture = Texture::Image(ImageTexture::new(
            TextureImage::from_checkerboard(checks, 32),
            WrapMode::Repeat,
            TextureFilter::Trilinear,
        ));
        let mut b = SceneBuilder::new();
        let ground = b.material(PhongMaterial {
            diffuse: texture,
            ..PhongMaterial::new(Vec3::ONE, 1.0)
        });
        let plain = b.material(PhongMaterial::new(Vec3::ONE, 1.0));
        let plane = Plane::new(Vec3::ZERO, Vec3::Y, false)
            .and_then(|p| p.with_tile_size(2.0))
            .unwrap();
        b.shape(plane, ground)
            .shape(Sphere::new(Vec3::new(1.2, 0.2, 1.2), 0.2).unwrap(), plain);
        let camera = top_down_camera();
        let scene = b.build(camera).unwrap();
        let level = (6.0 * 30f32.to_radians().tan() / 100.0 / (2.0 / 256.0)).log2();
        for spp in [1, 4] {
            let settings = RenderSettings {
                spp,
                pixel_pattern: SamplePattern::Grid,
                aov: Some(Aov::ReportMipLevel),
                ..RenderSettings::default()
            };
            let film = render(&scene, &settings, &|_, _| {}).unwrap().film;
            let centre = film.pixel(50, 50).x;
            assert!(
                (centre - level).abs() < 1e-3,
                "{spp} spp: {centre} against {level}"
            );
            if spp > 1 {
                continue;
            }
            // The sphere is not textured: 0 at every pixel whose ray hits it.
            let mut on_sphere = 0;
            for (x, y) in (0..100).flat_map(|y| (0..100).map(move |x| (x, y))) {
                let c = scene.camera.generate_ray(x as f32 + 0.5, y as f32 + 0.5);
                let ray = Ray::new(c.origin, c.direction);
                if scene.shapes.closest_hit(&ray, f32::INFINITY).unwrap().shape == 1 {
                    assert_eq!(film.pixel(x, y), Vec3::ZERO, "({x}, {y})");
                    on_sphere += 1;
                }
            }
            assert!(on_sphere > 10, "{on_sphere} pixels on the sphere");
        }
    }
}
