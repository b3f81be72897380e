//! The environment as Mitsuba 3's `envmap`: a lat-long image on Mitsuba's own
//! texel grid, filled with Glint's radiance in each texel's direction.
//!
//! Mitsuba reads a lat-long map with `u = atan2(d.x, −d.z)/2π`,
//! `v = acos(d.y)/π` (in the emitter's frame), column `i` of `W` centred at
//! `u = (i + ½)/W`, and, unlike Glint, its first and last rows on the poles:
//! row `j` of `H` at `θ = j·π/(H − 1)` (Glint centres rows in their bands,
//! `θ = (j + ½)·π/H`). Glint's `u = ½` looks down −z where Mitsuba's `u = 0`
//! does. Rather than turning the map, each texel of the image written here is
//! Glint's radiance ([`EnvironmentLight::radiance`], level 0, bilinear) in the
//! direction Mitsuba gives that texel, with the identity `to_world`: the map's
//! rotation and intensity are in the image, and Mitsuba's bilinear
//! interpolation between texels reproduces Glint's radiance function (exactly
//! on the texels; columns fall on Glint's own texel centres when the rotation
//! is a whole number of texels and the width even). This is what
//! `tools/mitsuba/envmap.py` does for the diffuse-sphere comparison. A cube
//! map is sampled the same way onto a `4N × 2N` lat-long image (`N` its face
//! size).

use glam::{UVec2, Vec3};
use glint_camera::Film;
use glint_lighting::EnvironmentLight;
use glint_texture::Environment;
use std::f32::consts::{PI, TAU};

/// How far from the poles the first and last rows are read (radians): at the
/// pole itself every column's direction is the same, but Glint's radiance
/// near a pole depends on the meridian it is approached along.
const POLE_OFFSET: f32 = 1e-5;

/// How many texels of the image for Mitsuba a lat-long map's texel becomes,
/// along each axis. Mitsuba's bilinear interpolation of texels on its own grid
/// (rows on the poles) only approximates Glint's bilinear function between the
/// kinks of Glint's grid (rows centred in their bands), and the error shrinks
/// with a finer grid: at the map's own size, the background of
/// `physical-environment.toml` seen directly differed from Glint's, pixel by
/// pixel, by 3.5 times the two renderers' noise (the means agreeing to
/// 0.002%).
const LATLONG_UPSAMPLING: u32 = 4;

/// The size of the lat-long image for Mitsuba: [`LATLONG_UPSAMPLING`] times
/// the map's own for a lat-long map, `4N × 2N` for a cube map of face size
/// `N`; `None` for a constant.
pub(super) fn image_size(environment: &Environment) -> Option<UVec2> {
    match environment {
        Environment::Constant(_) => None,
        Environment::LatLong(map) => {
            Some(LATLONG_UPSAMPLING * UVec2::new(map.image().width(), map.image().height()))
        }
        Environment::CubeMap(cube) => Some(UVec2::new(4 * cube.size(), 2 * cube.size())),
    }
}

/// The direction of texel `(i, j)` of a `size` lat-long image as Mitsuba's
/// `envmap` reads it (identity `to_world`).
pub(super) fn mitsuba_direction(i: u32, j: u32, size: UVec2) -> Vec3 {
    let phi = TAU * (i as f32 + 0.5) / size.x as f32;
    let theta = if size.y > 1 {
        (PI * j as f32 / (size.y - 1) as f32).clamp(POLE_OFFSET, PI - POLE_OFFSET)
    } else {
        0.5 * PI
    };
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}

/// The environment's radiance on Mitsuba's lat-long grid of `size` texels.
pub(super) fn latlong_film(light: &EnvironmentLight, size: UVec2) -> Film {
    let mut film = Film::new(size);
    for j in 0..size.y {
        for i in 0..size.x {
            let d = mitsuba_direction(i, j, size);
            film.set_pixel(i, j, light.radiance(d, 0.0));
        }
    }
    film
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_texture::{latlong_uv, Image, LatLongMap};

    /// Mitsuba's reading of a lat-long image of `size` in direction `d`:
    /// bilinear between texels on its grid (columns wrap, rows clamp).
    fn mitsuba_lookup(film: &Film, d: Vec3) -> Vec3 {
        let size = film.resolution();
        let u = d.x.atan2(-d.z) / TAU;
        let v = d.y.clamp(-1.0, 1.0).acos() / PI;
        let x = u.rem_euclid(1.0) * size.x as f32 - 0.5;
        let y = v * (size.y - 1) as f32;
        let (x0, y0) = (x.floor(), y.floor().min((size.y - 2) as f32));
        let (fx, fy) = (x - x0, y - y0);
        let texel = |i: f32, j: f32| {
            film.pixel(
                (i as i64).rem_euclid(size.x as i64) as u32,
                (j as u32).min(size.y - 1),
            )
        };
        let top = texel(x0, y0).lerp(texel(x0 + 1.0, y0), fx);
        let bottom = texel(x0, y0 + 1.0).lerp(texel(x0 + 1.0, y0 + 1.0), fx);
        top.lerp(bottom, fy)
    }

    #[test]
    fn texels_hold_glints_radiance_where_mitsuba_puts_them() {
        // A map whose radiance is a smooth function of direction: Mitsuba's
        // bilinear reading of the written image must agree with Glint's own
        // lookups (on texel centres exactly, between them to interpolation error,
        // within 1e-3 at the 4x finer grid the export writes).
        let (w, h) = (64, 32);
        let image = Image::from_fn(w, h, |x, y| {
            let d = glint_texture::latlong_direction(glam::Vec2::new(
                (x as f32 + 0.5) / w as f32,
                (y as f32 + 0.5) / h as f32,
            ));
            Vec3::new(1.0 + d.x, 1.5 + d.y, 2.0 + 0.5 * d.z)
        });
        for rotation_degrees in [0.0f32, 90.0, 37.0] {
            let light = EnvironmentLight::new(
                Environment::LatLong(LatLongMap::new(image.clone())),
                rotation_degrees.to_radians(),
                0.5,
            );
            let size = image_size(light.environment()).unwrap();
            assert_eq!(size, LATLONG_UPSAMPLING * UVec2::new(w, h));
            let film = latlong_film(&light, size);
            for k in 0..500 {
                let (a, b) = (k as f32 * 0.618_034, k as f32 * 0.414_214);
                let z = 1.0 - 2.0 * b.fract();
                let r = (1.0 - z * z).max(0.0).sqrt();
                let d = Vec3::new(r * (TAU * a).cos(), z, r * (TAU * a).sin());
                let glint = light.radiance(d, 0.0);
                let mitsuba = mitsuba_lookup(&film, d);
                assert!(
                    (glint - mitsuba).abs().max_element() < 1e-3,
                    "rotation {rotation_degrees}: {d} (uv {}): Glint {glint}, Mitsuba {mitsuba}",
                    latlong_uv(d)
                );
            }
        }
    }

    #[test]
    fn rows_sit_on_the_poles_and_columns_at_their_centres() {
        // Glint's u = ½ looks down −z; Mitsuba's u = 0 does.
        let size = UVec2::new(8, 5);
        let d = mitsuba_direction(0, 2, size);
        let uv = latlong_uv(d);
        assert!((uv.x - (0.5 + 0.5 / 8.0)).abs() < 1e-6, "{uv}");
        assert!((uv.y - 0.5).abs() < 1e-6, "{uv}");
        assert!(mitsuba_direction(3, 0, size).y > 0.999_999);
        assert!(mitsuba_direction(3, 4, size).y < -0.999_999);
    }

    #[test]
    fn a_cube_map_becomes_a_4n_by_2n_image_of_its_radiance() {
        let faces: [Image; 6] =
            std::array::from_fn(|f| Image::from_fn(4, 4, |_, _| Vec3::splat(f as f32 + 1.0)));
        let light = EnvironmentLight::new(
            Environment::CubeMap(glint_texture::CubeMap::new(faces).unwrap()),
            0.0,
            2.0,
        );
        let size = image_size(light.environment()).unwrap();
        assert_eq!(size, UVec2::new(16, 8));
        let film = latlong_film(&light, size);
        // The top row looks up +y (face py, 3), the bottom row down −y (ny, 4),
        // each times the intensity 2.
        assert_eq!(film.pixel(5, 0), Vec3::splat(6.0));
        assert_eq!(film.pixel(5, 7), Vec3::splat(8.0));
    }
}
