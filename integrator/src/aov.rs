//! Arbitrary output variables: per-pixel buffers other than radiance, for
//! studying a stage (texture coordinates, MIP level, normals, depth, albedo).

use crate::report_level::report_level;
use crate::texture_lookup::texture_footprint;
use crate::{Scene, SurfaceKind};
use glam::Vec3;
use glint_camera::Film;
use glint_geometry::{reflect, Hit, Ray, RayDifferential};
use glint_lighting::Light;
use glint_texture::srgb_to_linear;

/// What a render writes instead of radiance. Misses write 0 in every AOV.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aov {
    /// `(u, v, 0)`: the surface's own uv at the first hit.
    Uv,
    /// `(l, l, l)`: the continuous MIP level the diffuse texture is read at
    /// (0 for textures without a pyramid): Glint's level, from the ray
    /// differentials shrunk to each sample's share of the pixel.
    MipLevel,
    /// `(l, l, l)`: the level the course report chooses for the diffuse texture,
    /// `log2(L/W)` ([`crate::report_level()`]), from a whole pixel's footprint
    /// (0 where the diffuse texture is not an image, or the level is not
    /// finite). It may be negative: a texel wider than the pixel.
    ReportMipLevel,
    /// The shading normal at the first hit, components in [−1, 1].
    Normal,
    /// `(d, d, d)`: the distance from the camera to the first hit.
    Depth,
    /// The filtered diffuse reflectance `kd` (a light's color where a light is hit).
    Albedo,
    /// `(n, n, n)`: how many mirror reflections the camera ray's path took (0 when
    /// it stops at its first hit or misses), up to the render's max depth.
    ReflectionDepth,
    /// `(i + 1, i + 1, i + 1)`: the object the camera ray hits first, by its
    /// index in the scene's shape list (0 for a miss). Samples are averaged
    /// like every AOV's, so a pixel whose samples see two objects holds no
    /// index: render it with one sample at the pixel's centre (`--spp 1
    /// --sampler grid`) to read the object at each pixel.
    Object,
}

impl Aov {
    pub const NAMES: [&'static str; 8] = [
        "uv",
        "mip-level",
        "report-mip-level",
        "normal",
        "depth",
        "albedo",
        "reflection-depth",
        "object",
    ];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "uv" => Some(Self::Uv),
            "mip-level" => Some(Self::MipLevel),
            "report-mip-level" => Some(Self::ReportMipLevel),
            "normal" => Some(Self::Normal),
            "depth" => Some(Self::Depth),
            "albedo" => Some(Self::Albedo),
            "reflection-depth" => Some(Self::ReflectionDepth),
            "object" => Some(Self::Object),
            _ => None,
        }
    }

    /// The value of this AOV along a camera ray, following at most `max_depth`
    /// mirror reflections.
    pub fn evaluate(
        self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        max_depth: u32,
    ) -> Vec3 {
        let Some(hit) = scene.shapes.closest_hit(ray, f32::INFINITY) else {
            return Vec3::ZERO;
        };
        let surface = scene.surface_of(&hit);
        let material = match surface {
            SurfaceKind::Material(m) => Some(m),
            SurfaceKind::Emitter(_) => None,
        };

        match self {
            Aov::Uv => hit.uv.extend(0.0),
            Aov::Normal => hit.shading_normal,
            Aov::Depth => Vec3::splat(hit.t * ray.direction.length()),
            Aov::MipLevel => Vec3::splat(material.map_or(0.0, |m| {
                m.diffuse_mip_level(&texture_footprint(scene, m, (&hit, 0), ray, diff))
            })),
            Aov::ReportMipLevel => Vec3::splat(material.map_or(0.0, |m| {
                report_level(&scene.camera, ray, &hit, m, &m.diffuse).map_or(0.0, |r| r.level)
            })),
            Aov::ReflectionDepth => {
                Vec3::splat(reflection_depth(scene, *ray, hit, max_depth) as f32)
            }
            Aov::Object => Vec3::splat((hit.shape + 1) as f32),
            Aov::Albedo => match surface {
                SurfaceKind::Material(m) => {
                    m.reflectances(&texture_footprint(scene, m, (&hit, 0), ray, diff))
                        .0
                }
                SurfaceKind::Emitter(Light::Area(a)) => a.color,
                SurfaceKind::Emitter(Light::Point(p)) => p.color,
                SurfaceKind::Emitter(Light::Sphere(s)) => s.color,
            },
        }
    }

    /// The buffer mapped to displayable colors, for 8-bit output: normals to
    /// `0.5·n + 0.5`, uv to its fractional part, depth to gray (near bright, far
    /// dark, 0 for misses), MIP levels and reflection depths to a blue → green → red
    /// ramp over 0 … the highest value seen; objects to colours of their own
    /// (misses black); albedo unchanged. These are display
    /// values: they are stored decoded from sRGB, so that an sRGB writer (the PNG
    /// output) stores exactly them (0.5 as 128). Albedo is a linear color, kept as is.
    pub fn false_color(self, film: &Film) -> Film {
        let max = film.pixels().iter().fold(0.0f32, |m, p| m.max(p.x));
        let mut out = film.clone();
        for p in out.pixels_mut() {
            *p = match self {
                Aov::Normal => 0.5 * *p + 0.5,
                Aov::Uv => Vec3::new(p.x.rem_euclid(1.0), p.y.rem_euclid(1.0), 0.0),
                Aov::Depth if p.x > 0.0 && max > 0.0 => Vec3::splat(1.0 - 0.9 * p.x / max),
                Aov::Depth => Vec3::ZERO,
                Aov::MipLevel | Aov::ReportMipLevel | Aov::ReflectionDepth => {
                    ramp(if max > 0.0 { p.x / max } else { 0.0 })
                }
                Aov::Object => object_colour(p.x),
                Aov::Albedo => *p,
            };
            if self != Aov::Albedo {
                *p = Vec3::from_array(p.to_array().map(srgb_to_linear));
            }
        }
        out
    }
}

/// The number of mirror reflections along the path of `ray`, whose first hit is
/// `first`.
fn reflection_depth(scene: &Scene, mut ray: Ray, first: Hit, max_depth: u32) -> u32 {
    let mut hit = first;
    let mut depth = 0;
    while depth < max_depth {
        let reflective = match scene.surface_of(&hit) {
            SurfaceKind::Material(m) => m.reflectivity > 0.0,
            SurfaceKind::Emitter(_) => false,
        };
        if !reflective {
            break;
        }
        let wo = -ray.direction.normalize();
        ray = glint_geometry::spawn_ray(&hit, reflect(wo, hit.facing_normal(ray.direction)));
        depth += 1;
        match scene.shapes.closest_hit(&ray, f32::INFINITY) {
            Some(next) => hit = next,
            None => break,
        }
    }
    depth
}

/// A colour for object id `id` (0, a miss, is black): hues a golden angle
/// apart, so that neighbouring indices differ.
fn object_colour(id: f32) -> Vec3 {
    if id < 0.5 {
        return Vec3::ZERO;
    }
    let hue = (id * 0.618_034).fract() * 6.0;
    let x = 1.0 - (hue % 2.0 - 1.0).abs();
    let (r, g, b) = match hue as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    0.25 + 0.75 * Vec3::new(r, g, b)
}

/// Blue (0) → green (0.5) → red (1).
fn ramp(x: f32) -> Vec3 {
    let x = x.clamp(0.0, 1.0);
    if x < 0.5 {
        Vec3::new(0.0, 2.0 * x, 1.0 - 2.0 * x)
    } else {
        Vec3::new(2.0 * x - 1.0, 2.0 - 2.0 * x, 0.0)
    }
}
