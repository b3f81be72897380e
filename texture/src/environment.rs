//! Environment maps: radiance as a function of direction, from six cube-map faces
//! or one equirectangular (lat-long) image.
//!
//! # Conventions (as in the assets README)
//! - Cube faces are `px nx py ny pz nz` (+x −x +y −y +z −z), each square, in the
//!   OpenGL/RenderMan orientation: face texel `(i, j)` (i rightwards, j downwards) of
//!   an `N × N` face has `s = 2(i + ½)/N − 1`, `t = 2(j + ½)/N − 1` and looks along
//!   `px: (1, −t, −s)`, `nx: (−1, −t, s)`, `py: (s, 1, t)`, `ny: (s, −1, −t)`,
//!   `pz: (s, −t, 1)`, `nz: (−s, −t, −1)`.
//! - Lat-long: for a unit direction `d`, `u = ½ + atan2(d.x, −d.z)/2π`,
//!   `v = acos(d.y)/π`, with `v = 0` the top row: the image centre looks down −z.
//! - Footprints are angular widths in radians; a lookup reads the MIP level whose
//!   texels subtend that angle.

use crate::{Image, TextureImage, WrapMode};
use glam::{Vec2, Vec3};
use glint_lanes::{acos_approx, atan2_approx, sin_cos_approx, F32Lanes, Float, Vec3Lanes};
use std::f32::consts::{PI, TAU};
use std::sync::Arc;

/// Index of a cube face in `px nx py ny pz nz` order.
pub type CubeFace = usize;

/// The face a direction points into and its face coordinates in [0, 1]²
/// (`((s + 1)/2, (t + 1)/2)`, image orientation: the second grows downwards).
#[inline]
pub fn cube_face_st(d: Vec3) -> (CubeFace, Vec2) {
    let a = d.abs();
    let (face, s, t, major) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z, -d.y, a.x)
        } else {
            (1, d.z, -d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    if major.is_nan() || major <= 0.0 {
        return (4, Vec2::splat(0.5)); // zero or NaN direction
    }
    (face, 0.5 * (Vec2::new(s, t) / major + Vec2::ONE))
}

/// The (unnormalised) direction through face coordinates `st` of `face`;
/// the inverse of [`cube_face_st`]. `st` may lie outside [0, 1]² (past the edge).
#[inline]
pub fn cube_direction(face: CubeFace, st: Vec2) -> Vec3 {
    let (s, t) = (2.0 * st.x - 1.0, 2.0 * st.y - 1.0);
    match face {
        0 => Vec3::new(1.0, -t, -s),
        1 => Vec3::new(-1.0, -t, s),
        2 => Vec3::new(s, 1.0, t),
        3 => Vec3::new(s, -1.0, -t),
        4 => Vec3::new(s, -t, 1.0),
        _ => Vec3::new(-s, -t, -1.0),
    }
}

/// Lat-long coordinates `(u, v)` ∈ [0, 1]² of a unit direction.
#[inline]
pub fn latlong_uv(d: Vec3) -> Vec2 {
    let (u, v) = latlong_coordinates(d.x, d.y, d.z);
    Vec2::new(u, v)
}

/// [`latlong_uv`] of unit direction `(x, y, z)`, in one lane or in many, the
/// same bits in each: `u = ½ + atan2(x, −z)/2π` (1 wrapping to 0) and
/// `v = acos(y)/π`, the angles by polynomials within a few units in the last
/// place of libm's ([`atan2_approx`], [`acos_approx`]), which would take the
/// lanes one at a time.
#[inline(always)]
pub fn latlong_coordinates<F: Float>(x: F, y: F, z: F) -> (F, F) {
    let u = F::splat(0.5) + atan2_approx(x, -z) / F::splat(TAU);
    let u = F::select(u.ge(F::ONE), u - F::ONE, u);
    let v = acos_approx(y.max(F::splat(-1.0)).min(F::ONE)) / F::splat(PI);
    (u, v)
}

/// The unit direction at lat-long coordinates `(u, v)`; inverse of [`latlong_uv`].
#[inline]
pub fn latlong_direction(uv: Vec2) -> Vec3 {
    latlong_direction_and_sin_theta(uv).0
}

/// [`latlong_direction`] and `sin θ`, θ = v·π its angle from +y (the
/// Jacobian of the map's coordinates has it), from the one sine.
#[inline]
pub fn latlong_direction_and_sin_theta(uv: Vec2) -> (Vec3, f32) {
    let ([x, y, z], sin_t) = latlong_direction_of(uv.x, uv.y);
    (Vec3::new(x, y, z), sin_t)
}

/// [`latlong_direction_and_sin_theta`] at `(u, v)` ∈ [0, 1]², in one lane
/// or in many, the same bits in each: `θ = v·π`, `φ = (u − ½)·2π`, their
/// sines and cosines by polynomials within a unit in the last place of
/// libm's ([`sin_cos_approx`]).
#[inline(always)]
pub fn latlong_direction_of<F: Float>(u: F, v: F) -> ([F; 3], F) {
    let phi = (u - F::splat(0.5)) * F::splat(TAU);
    let theta = v * F::splat(PI);
    let (sin_t, cos_t) = sin_cos_approx(theta);
    let (sin_p, cos_p) = sin_cos_approx(phi);
    ([sin_t * sin_p, cos_t, -sin_t * cos_p], sin_t)
}

/// Six square faces of one size, each with its own lazily built pyramid.
#[derive(Clone, Debug)]
pub struct CubeMap {
    faces: [Arc<TextureImage>; 6],
}

impl CubeMap {
    /// Faces in `px nx py ny pz nz` order; all must be square and of one size.
    pub fn new(faces: [Image; 6]) -> Result<Self, String> {
        let n = faces[0].width();
        if n == 0 {
            return Err("the cube map's faces have no texels".into());
        }
        for (name, face) in ["px", "nx", "py", "ny", "pz", "nz"].iter().zip(&faces) {
            if face.width() != face.height() || face.width() != n {
                return Err(format!(
                    "face {name} is {}x{}, but every face must be {n}x{n} (square, one size)",
                    face.width(),
                    face.height()
                ));
            }
        }
        Ok(Self {
            faces: faces.map(TextureImage::new),
        })
    }

    /// Texels along a face side at level 0.
    pub fn size(&self) -> u32 {
        self.faces[0].image().width()
    }

    pub fn face(&self, face: CubeFace) -> &Image {
        self.faces[face].image()
    }

    fn level_count(&self) -> usize {
        (32 - self.size().leading_zeros()) as usize
    }

    fn level(&self, face: CubeFace, level: usize) -> &Image {
        if level == 0 {
            self.faces[face].image()
        } else {
            let levels = self.faces[face].pyramid().levels();
            &levels[level.min(levels.len() - 1)]
        }
    }

    /// Radiance towards `d`, filtered over a cone of angular width `width`
    /// (radians): trilinear between the levels whose texels subtend about that
    /// angle. A level-0 texel at face coordinates (s, t) subtends about
    /// `(2/N)/(1 + s² + t²)^{3/4}` (its solid angle is `(2/N)²/(1 + s² + t²)^{3/2}`),
    /// so the level is `log2(width·N/2) + ¾·log2(1 + s² + t²)`.
    pub fn radiance(&self, d: Vec3, width: f32) -> Vec3 {
        let (face, st) = cube_face_st(d);
        // A cone of no width (or NaN) reads level 0: the level below would
        // come out −∞ (or NaN), which the clamp turns into 0 anyway.
        if width.is_nan() || width <= 0.0 {
            return self.bilinear(face, 0, st);
        }
        let (s, t) = (2.0 * st.x - 1.0, 2.0 * st.y - 1.0);
        let level = (width * self.size() as f32 / 2.0).log2() + 0.75 * (1.0 + s * s + t * t).log2();
        let last = (self.level_count() - 1) as f32;
        let level = if level > 0.0 { level.min(last) } else { 0.0 };
        let lower = level as usize;
        let fine = self.bilinear(face, lower, st);
        let frac = level - lower as f32;
        if frac == 0.0 {
            return fine;
        }
        fine + (self.bilinear(face, lower + 1, st) - fine) * frac
    }

    /// Bilinear filtering on one level that reads across face edges: a texel past
    /// the edge is fetched from the face its centre's direction points into, so the
    /// result is continuous across edges and corners (no seams).
    pub fn bilinear(&self, face: CubeFace, level: usize, st: Vec2) -> Vec3 {
        let image = self.level(face, level);
        let n = image.width() as i64;
        let inside = |i: i64| (0..n).contains(&i);
        image.bilinear_with(st, |x, y| {
            if inside(x) || inside(y) {
                return self.texel(face, level, x, y);
            }
            // Diagonally past a corner, where only three faces meet, there is no
            // texel: take the mean of the other three of the 2 × 2 footprint, which
            // makes all three faces agree at the corner.
            let (xi, yi) = (x.clamp(0, n - 1), y.clamp(0, n - 1));
            (self.texel(face, level, xi, y)
                + self.texel(face, level, x, yi)
                + self.texel(face, level, xi, yi))
                / 3.0
        })
    }

    /// Texel `(i, j)` of `face` at `level`, following the cube past the face's edges.
    pub fn texel(&self, face: CubeFace, level: usize, i: i64, j: i64) -> Vec3 {
        let image = self.level(face, level);
        let n = image.width() as i64;
        if (0..n).contains(&i) && (0..n).contains(&j) {
            return image.texel(i as u32, j as u32);
        }
        let st = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
        let (other, st) = cube_face_st(cube_direction(face, st));
        let other_image = self.level(other, level);
        let p = (st * n as f32).floor();
        other_image.texel_wrapped(p.x as i64, p.y as i64, WrapMode::Clamp)
    }
}

/// One equirectangular image covering the sphere of directions.
#[derive(Clone, Debug)]
pub struct LatLongMap {
    image: Arc<TextureImage>,
}

impl LatLongMap {
    pub fn new(image: Image) -> Self {
        Self {
            image: TextureImage::new(image),
        }
    }

    pub fn image(&self) -> &Image {
        self.image.image()
    }

    /// Level 0 read bilinearly at lat-long coordinates `uv` (longitude wraps,
    /// and past a pole the filter continues on the other side of it): the
    /// radiance of [`LatLongMap::radiance`] with width 0.
    #[inline]
    pub fn bilinear(&self, uv: Vec2) -> Vec3 {
        latlong_bilinear(self.image.image(), uv)
    }

    /// [`Self::bilinear`] at `(u, v)` in the lanes of `lanes` (zero in the
    /// others), each lane's bits the scalar one's: the texels of lanes inside
    /// the image read in lanes, those of lanes across the seam or a pole one
    /// by one.
    #[inline]
    pub fn bilinear_each(&self, u: F32Lanes, v: F32Lanes, lanes: u32) -> Vec3Lanes {
        let image = self.image.image();
        let (mut value, edges) = image.bilinear_inside_lanes(u, v, lanes);
        if edges != 0 {
            let (u, v) = (u.to_array(), v.to_array());
            for k in glint_lanes::each_set(edges) {
                value.set_lane(k, latlong_bilinear(image, Vec2::new(u[k], v[k])));
            }
        }
        value
    }

    /// Radiance towards `d`, filtered over a cone of angular width `width`: the
    /// level whose texels span `width` along the meridian (`π/H` at level 0), so
    /// `log2(width·H/π)`. Towards the poles a texel narrows across (`2π·sin θ/W`)
    /// while keeping its height; an isotropic pyramid cannot follow that, and
    /// choosing the level by the narrow side would blur away several levels of
    /// detail along the meridian, so there the filter is finer than the footprint
    /// across longitude.
    pub fn radiance(&self, d: Vec3, width: f32) -> Vec3 {
        let uv = latlong_uv(d);
        let image = self.image.image();
        if width.is_nan() || width <= 0.0 {
            return latlong_bilinear(image, uv);
        }
        let level = (width * image.height() as f32 / PI).log2();
        if level.is_nan() || level <= 0.0 {
            return latlong_bilinear(self.image.image(), uv);
        }
        let levels = self.image.pyramid().levels();
        let level = level.min((levels.len() - 1) as f32);
        let lower = level as usize;
        let fine = latlong_bilinear(&levels[lower], uv);
        let frac = level - lower as f32;
        if frac == 0.0 {
            return fine;
        }
        let coarse = latlong_bilinear(&levels[(lower + 1).min(levels.len() - 1)], uv);
        fine + (coarse - fine) * frac
    }
}

/// Bilinear on a lat-long image: longitude wraps around, and past a pole the
/// filter continues on the other side of it (half a turn away), so the value at
/// the pole does not depend on the longitude it is approached from.
fn latlong_bilinear(image: &Image, uv: Vec2) -> Vec3 {
    image.bilinear_with(uv, |x, y| latlong_texel(image, x, y))
}

/// Texel `(x, y)` of a lat-long image, for any integer coordinates: longitude
/// wraps, and a row past a pole is the mirrored row half a turn away.
pub fn latlong_texel(image: &Image, x: i64, y: i64) -> Vec3 {
    let (w, h) = (image.width() as i64, image.height() as i64);
    let (x, y) = if y < 0 {
        (x + w / 2, -1 - y)
    } else if y >= h {
        (x + w / 2, 2 * h - 1 - y)
    } else {
        (x, y)
    };
    // Most reads are inside: skip the division there.
    let x = if (0..w).contains(&x) {
        x
    } else {
        x.rem_euclid(w)
    };
    image.texel(x as u32, y.clamp(0, h - 1) as u32)
}

/// Radiance arriving from every direction: a constant, a cube map or a lat-long map.
#[derive(Clone, Debug)]
pub enum Environment {
    Constant(Vec3),
    CubeMap(CubeMap),
    LatLong(LatLongMap),
}

impl Environment {
    /// Radiance arriving from direction `d` (unit, world space), filtered over a
    /// cone of angular width `width` radians.
    #[inline]
    pub fn radiance(&self, d: Vec3, width: f32) -> Vec3 {
        match self {
            Environment::Constant(c) => *c,
            Environment::CubeMap(c) => c.radiance(d, width),
            Environment::LatLong(l) => l.radiance(d, width),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_lanes::LANES;

    /// Every lane of `bilinear_each` is `bilinear`'s bits: inside the image,
    /// across the seam, at and past the poles, on texel centres and edges,
    /// and NaN; lanes not asked for are zero.
    #[test]
    fn bilinear_in_lanes_is_each_lanes_bilinear() {
        let (w, h) = (24, 12);
        let map = LatLongMap::new(Image::from_fn(w, h, |x, y| {
            Vec3::new(
                x as f32 * 0.37 + 1.0,
                y as f32 * 1.3,
                ((x * 7 + y * 3) % 5) as f32,
            )
        }));
        let mut points: Vec<Vec2> = (0..400)
            .map(|i| {
                Vec2::new(
                    (i as f32 * 0.618_034).fract(),
                    (i as f32 * 0.414_214).fract(),
                )
            })
            .collect();
        for edge in [
            0.0,
            0.5 / 24.0,
            1.0 / 24.0,
            1.0 - 0.5 / 24.0,
            1.0,
            0.5 / 12.0,
            f32::NAN,
        ] {
            points.extend([
                Vec2::new(edge, 0.4),
                Vec2::new(0.3, edge),
                Vec2::splat(edge),
            ]);
        }
        for (chunk, points) in points.chunks(LANES).enumerate() {
            let lane = |k: usize| points[k.min(points.len() - 1)];
            let u = glint_lanes::from_fn(|k| lane(k).x);
            let v = glint_lanes::from_fn(|k| lane(k).y);
            let asked = ((1u32 << points.len()) - 1) & !(1 << (chunk % 3));
            let each = map.bilinear_each(u, v, asked);
            for (k, &uv) in points.iter().enumerate() {
                let want = if asked >> k & 1 == 1 {
                    map.bilinear(uv)
                } else {
                    Vec3::ZERO
                };
                assert_eq!(
                    each.lane(k).to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "{uv}"
                );
            }
        }
    }

    fn directions() -> impl Iterator<Item = Vec3> {
        (0..2000).map(|i| {
            let (a, b) = (i as f32 * 0.618_034, i as f32 * 0.414_214);
            let z = 1.0 - 2.0 * b.fract();
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * (TAU * a).cos(), r * (TAU * a).sin(), z)
        })
    }

    #[test]
    fn face_texels_follow_the_documented_orientation() {
        // Texel (i, j) = (0, 0), top-left: s = t = −1 + 1/N.
        let n = 4.0;
        let c = -1.0 + 1.0 / n;
        let expected = [
            Vec3::new(1.0, -c, -c),
            Vec3::new(-1.0, -c, c),
            Vec3::new(c, 1.0, c),
            Vec3::new(c, -1.0, -c),
            Vec3::new(c, -c, 1.0),
            Vec3::new(-c, -c, -1.0),
        ];
        for (face, e) in expected.iter().enumerate() {
            let st = Vec2::splat(0.5 / n);
            assert_eq!(cube_direction(face, st), *e, "face {face}");
            let (f, back) = cube_face_st(*e);
            assert_eq!(f, face);
            assert!((back - st).length() < 1e-6);
        }
    }

    #[test]
    fn direction_face_round_trips_on_faces_edges_and_corners() {
        for d in directions() {
            let (face, st) = cube_face_st(d);
            assert!((0.0..=1.0).contains(&st.x) && (0.0..=1.0).contains(&st.y));
            let back = cube_direction(face, st).normalize();
            assert!((back - d).length() < 1e-5, "{d} -> {face} {st} -> {back}");
        }
        // Edges and corners: on the boundary the face is ambiguous, but the
        // direction must come back.
        for face in 0..6 {
            for st in [
                Vec2::ZERO,
                Vec2::ONE,
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 0.5),
                Vec2::new(0.5, 0.0),
            ] {
                let d = cube_direction(face, st).normalize();
                let (f2, st2) = cube_face_st(d);
                let back = cube_direction(f2, st2).normalize();
                assert!((back - d).length() < 1e-6, "face {face} {st}");
            }
        }
    }

    #[test]
    fn latlong_round_trips_and_matches_the_assets_convention() {
        assert!((latlong_uv(-Vec3::Z) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((latlong_uv(Vec3::X) - Vec2::new(0.75, 0.5)).length() < 1e-6);
        assert!(latlong_uv(Vec3::Y).y < 1e-6);
        for d in directions() {
            let back = latlong_direction(latlong_uv(d));
            assert!((back - d).length() < 1e-4, "{d} -> {back}");
        }
    }

    fn constant_cube(n: u32, c: Vec3) -> CubeMap {
        CubeMap::new(std::array::from_fn(|_| Image::from_fn(n, n, |_, _| c))).unwrap()
    }

    #[test]
    fn a_constant_cube_map_is_constant_everywhere_at_every_level() {
        let c = Vec3::new(0.3, 0.6, 0.9);
        let cube = constant_cube(8, c);
        for d in directions() {
            for width in [0.0, 0.05, 0.3, 2.0, f32::INFINITY, f32::NAN] {
                let got = cube.radiance(d, width);
                assert!((got - c).abs().max_element() < 1e-6, "{d} {width}: {got}");
            }
        }
    }

    #[test]
    fn filtering_is_continuous_across_face_edges() {
        // Each face a different constant: across an edge, bilinear blends the two
        // faces, so directions just either side of the edge read (nearly) the same.
        let colors = [
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            Vec3::ONE,
            Vec3::ZERO,
            Vec3::splat(0.5),
        ];
        let cube = CubeMap::new(colors.map(|c| Image::from_fn(16, 16, |_, _| c))).unwrap();
        for face in 0..6 {
            for st in [
                Vec2::new(1.0, 0.3),
                Vec2::new(0.0, 0.7),
                Vec2::new(0.4, 0.0),
                Vec2::new(0.6, 1.0),
                Vec2::ONE,
            ] {
                let on_edge = cube_direction(face, st).normalize();
                let inside = cube_direction(face, st * 0.9999 + 0.00005).normalize();
                let outside = cube_direction(face, (st - 0.5) * 1.0001 + 0.5).normalize();
                for width in [0.0, 0.1, 0.5] {
                    let (a, b) = (cube.radiance(inside, width), cube.radiance(outside, width));
                    let gap = (a - b).abs().max_element();
                    assert!(gap < 2e-3, "face {face} {st} width {width}: {a} vs {b}");
                    assert!(cube.radiance(on_edge, width).is_finite());
                }
            }
        }
    }

    #[test]
    fn latlong_filtering_is_continuous_over_the_poles() {
        // A function continuous on the sphere: 3 + d.x + 2·d.z, which is 3 at both
        // poles. Its top row still varies with longitude (the row's centre is
        // π/2H from the pole); bilinear filtering that reads across the pole
        // averages opposite longitudes and so gives 3 there from every side,
        // where clamping at the top row would leave about ±0.2.
        let (w, h) = (32, 16);
        let map = LatLongMap::new(Image::from_fn(w, h, |x, y| {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let d = latlong_direction(uv);
            Vec3::splat(3.0 + d.x + 2.0 * d.z)
        }));
        for pole in [1.0f32, -1.0] {
            for i in 0..16 {
                let phi = i as f32 * 0.4;
                let d = Vec3::new(1e-5 * phi.cos(), pole, 1e-5 * phi.sin()).normalize();
                let v = map.radiance(d, 0.0).x;
                assert!((v - 3.0).abs() < 0.02, "pole {pole}, longitude {phi}: {v}");
            }
        }
    }

    #[test]
    fn wrong_face_sizes_are_refused() {
        let mut faces: [Image; 6] = std::array::from_fn(|_| Image::from_fn(4, 4, |_, _| Vec3::ONE));
        faces[3] = Image::from_fn(4, 5, |_, _| Vec3::ONE);
        let e = CubeMap::new(faces).unwrap_err();
        assert!(e.contains("face ny is 4x5"), "{e}");
    }
}
