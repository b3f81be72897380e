//! The environment as Mitsuba 3's `envmap`: a lat-long image on Mitsuba's own
//! texel grid whose bilinear interpolation is exactly Glint's radiance.
//!
//! Mitsuba reads a lat-long map with `u = atan2(d.x, −d.z)/2π`,
//! `v = acos(d.y)/π` in the emitter's frame, column `i` of `W` centred at
//! `u = (i + ½)/W` and, unlike Glint, its first and last rows on the poles:
//! row `j` of `H′` at `v = j/(H′ − 1)` (Glint centres rows in their bands,
//! `v = (k + ½)/H`). Glint's own lookup is bilinear between texel centres, so
//! its radiance is bilinear in `(u, v)` inside each cell of its texel centres
//! and has kinks on their lines. Mitsuba's interpolation of values taken on
//! its grid reproduces that function exactly when every kink lies on a grid
//! line: then each of Mitsuba's cells lies inside one of Glint's, where a
//! bilinear function is its own bilinear interpolant. Hence
//!
//! - the emitter's `to_world` turns by the map's rotation plus half a turn,
//!   so that Mitsuba's `u` is Glint's (Glint's `u = ½` looks down −z, where
//!   Mitsuba's `u = 0` does), and the columns are the map's own `W`;
//! - the image has `2H + 1` rows: row `2k + 1` at `v = (k + ½)/H` is Glint's
//!   row `k`, row `2k` on the line between rows `k − 1` and `k`, and rows `0`
//!   and `2H` on the poles, where Glint's filter continues across the pole;
//! - the map's intensity is in the image (Mitsuba's `scale` stays 1).
//!
//! Each texel is Glint's radiance (level 0, bilinear) at its `(u, v)`. An
//! earlier export sampled Glint's radiance in the directions of a 4× finer
//! grid with the rows on Mitsuba's positions; its interpolation error left the
//! background of `physical-environment.toml` seen directly at 2.4 times the two
//! renderers' noise. A cube map has no such alignment: it is sampled in the
//! directions of a `4N × 2N` lat-long grid (`N` its face size), an
//! approximation that grows finer with `N`.

use glam::{UVec2, Vec2, Vec3};
use glint_camera::Film;
use glint_lighting::EnvironmentLight;
use glint_texture::Environment;
use std::f32::consts::{PI, TAU};

/// How far from the poles a cube map's first and last rows are read
/// (radians): at the pole itself every column's direction is the same.
const POLE_OFFSET: f32 = 1e-5;

/// The size of the lat-long image for Mitsuba: `W × (2H + 1)` for a `W × H`
/// lat-long map, `4N × 2N` for a cube map of face size `N`; `None` for a
/// constant.
pub(super) fn image_size(environment: &Environment) -> Option<UVec2> {
    match environment {
        Environment::Constant(_) => None,
        Environment::LatLong(map) => Some(UVec2::new(
            map.image().width(),
            2 * map.image().height() + 1,
        )),
        Environment::CubeMap(cube) => Some(UVec2::new(4 * cube.size(), 2 * cube.size())),
    }
}

/// Mitsuba's `(u, v)` of texel `(i, j)` of a `size` lat-long image.
fn mitsuba_uv(i: u32, j: u32, size: UVec2) -> Vec2 {
    let v = if size.y > 1 {
        j as f32 / (size.y - 1) as f32
    } else {
        0.5
    };
    Vec2::new((i as f32 + 0.5) / size.x as f32, v)
}

/// The direction of texel `(i, j)` of a `size` lat-long image in the emitter's
/// frame, as Mitsuba's `envmap` reads it (rows on the poles kept
/// [`POLE_OFFSET`] off them).
pub(super) fn mitsuba_direction(i: u32, j: u32, size: UVec2) -> Vec3 {
    let uv = mitsuba_uv(i, j, size);
    let phi = TAU * uv.x;
    let theta = (PI * uv.y).clamp(POLE_OFFSET, PI - POLE_OFFSET);
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}

/// The emitter's `to_world` (a 4×4 matrix, row by row): a turn about +y by the
/// map's rotation plus half a turn, which puts Mitsuba's `u` on Glint's.
pub(super) fn to_world(light: &EnvironmentLight) -> [[f32; 4]; 4] {
    // R_y(rotation + π) = −R_y(rotation) in the xz plane.
    let (s, c) = light.rotation().sin_cos();
    [
        [-c, 0.0, -s, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [s, 0.0, -c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// The environment's radiance (times its intensity) on Mitsuba's lat-long grid
/// of `size` texels, in the frame [`to_world`] turns into the world.
pub(super) fn latlong_film(light: &EnvironmentLight, size: UVec2) -> Film {
    let mut film = Film::new(size);
    for j in 0..size.y {
        for i in 0..size.x {
            let radiance = match light.environment() {
                Environment::LatLong(map) => map.bilinear(mitsuba_uv(i, j, size)),
                // Glint's map frame is Mitsuba's emitter frame turned by π.
                other => {
                    let d = mitsuba_direction(i, j, size);
                    other.radiance(Vec3::new(-d.x, d.y, -d.z), 0.0)
                }
            };
            film.set_pixel(i, j, light.scale() * radiance);
        }
    }
    film
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_texture::{latlong_uv, Image, LatLongMap};

    /// Mitsuba's reading of a lat-long image in world direction `d`: into the
    /// emitter's frame by the inverse of `to_world`, then bilinear between
    /// texels on its grid (columns wrap, rows clamp).
    fn mitsuba_lookup(film: &Film, to_world: [[f32; 4]; 4], d: Vec3) -> Vec3 {
        // A rotation's inverse is its transpose.
        let column = |c: usize| Vec3::new(to_world[0][c], to_world[1][c], to_world[2][c]);
        let d = Vec3::new(column(0).dot(d), column(1).dot(d), column(2).dot(d));
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

    /// Directions spread over the sphere (a Fibonacci lattice), poles included.
    fn directions() -> impl Iterator<Item = Vec3> {
        (0..2000)
            .map(|k| {
                let (a, b) = (k as f32 * 0.618_034, k as f32 * 0.414_214);
                let z = 1.0 - 2.0 * b.fract();
                let r = (1.0 - z * z).max(0.0).sqrt();
                Vec3::new(r * (TAU * a).cos(), z, r * (TAU * a).sin())
            })
            .chain([
                Vec3::Y,
                -Vec3::Y,
                Vec3::new(0.0, 0.999_9, 0.014_1).normalize(),
            ])
    }

    #[test]
    fn mitsubas_interpolation_of_the_image_is_glints_radiance() {
        // Texels of unrelated values (the worst case for interpolation): with
        // Glint's kinks on Mitsuba's grid lines the two agree to rounding. The
        // earlier 4x grid with rows on Mitsuba's own positions differed by up
        // to a third of the texels' range here.
        let (w, h) = (64, 32);
        let image = Image::from_fn(w, h, |x, y| {
            let hash = (x * 7919 + y * 104_729) % 1009;
            Vec3::new(hash as f32 / 1009.0, 1.0 - hash as f32 / 2018.0, 0.25)
        });
        for rotation_degrees in [0.0f32, 90.0, 37.0, -123.4] {
            let light = EnvironmentLight::new(
                Environment::LatLong(LatLongMap::new(image.clone())),
                rotation_degrees.to_radians(),
                0.5,
            );
            let size = image_size(light.environment()).unwrap();
            assert_eq!(size, UVec2::new(w, 2 * h + 1));
            let film = latlong_film(&light, size);
            for d in directions() {
                let glint = light.radiance(d, 0.0);
                let mitsuba = mitsuba_lookup(&film, to_world(&light), d);
                assert!(
                    (glint - mitsuba).abs().max_element() < 2e-4,
                    "rotation {rotation_degrees}: {d} (uv {}): Glint {glint}, Mitsuba {mitsuba}",
                    latlong_uv(d)
                );
            }
        }
    }

    #[test]
    fn odd_rows_are_the_maps_rows_and_columns_its_columns() {
        let image = Image::from_fn(8, 4, |x, y| Vec3::splat((10 * y + x) as f32));
        let light = EnvironmentLight::new(Environment::LatLong(LatLongMap::new(image)), 0.3, 2.0);
        let film = latlong_film(&light, image_size(light.environment()).unwrap());
        for (i, k) in [(0, 0), (5, 1), (7, 3)] {
            let texel = film.pixel(i, 2 * k + 1);
            assert!(
                (texel - Vec3::splat(2.0 * (10 * k + i) as f32))
                    .abs()
                    .max_element()
                    < 1e-4
            );
        }
        // Between rows 1 and 2, the mean of the two.
        assert!(
            (film.pixel(3, 4) - Vec3::splat(2.0 * 18.0))
                .abs()
                .max_element()
                < 1e-4
        );
    }

    #[test]
    fn rows_sit_on_the_poles_and_mitsubas_u_is_glints_after_half_a_turn() {
        let size = UVec2::new(8, 5);
        let d = mitsuba_direction(0, 2, size);
        let uv = latlong_uv(Vec3::new(-d.x, d.y, -d.z));
        assert!((uv.x - 0.5 / 8.0).abs() < 1e-6, "{uv}");
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
        // Mitsuba's u = 0 column looks down +z in the map's frame (face pz, 5)
        // once to_world has turned it by half a turn.
        assert_eq!(film.pixel(0, 4), Vec3::splat(10.0));
    }
}
