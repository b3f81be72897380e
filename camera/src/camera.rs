//! The pinhole camera of the course report (sections 2.1 and 2.2).

use glam::{UVec2, Vec2, Vec3};
pub use glint_lanes::{F32Lanes, LANES};

/// A ray leaving the camera: origin at the pinhole, unit-length direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRay {
    pub origin: Vec3,
    pub direction: Vec3,
}

/// [`LANES`] camera rays in SIMD lanes: the pinhole they share, and each lane's
/// unit direction by component (`direction[0]` the x components, and so on).
#[derive(Clone, Copy, Debug)]
pub struct CameraRayLanes {
    pub origin: Vec3,
    pub direction: [F32Lanes; 3],
}

/// A camera ray with the directions of the rays one pixel to the right (`dx`) and
/// one pixel down (`dy`): the ray differentials of Igehy (1999) and pbrt-v4
/// section 10.1.1. A pinhole camera's three rays share one origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRayDifferential {
    pub ray: CameraRay,
    pub dx_direction: Vec3,
    pub dy_direction: Vec3,
}

/// Why a camera could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CameraError {
    #[error("the vertical field of view must lie strictly between 0 and 180 degrees, got {0}")]
    FieldOfView(f32),
    #[error("the focal length must be positive, got {0}")]
    FocalLength(f32),
    #[error("the film resolution must be at least 1x1, got {0}x{1}")]
    Resolution(u32, u32),
    #[error("the camera position and the look-at point coincide")]
    NoForward,
    #[error("the reference up vector is zero or parallel to the viewing direction")]
    UpParallelToForward,
}

/// A pinhole camera with an orthonormal basis and a film plane at `focal_length`.
///
/// With `forward = normalize(look_at − position)`, `right = normalize(forward × up_ref)`
/// and `up = right × forward`, the film spans `±half_width · right` and
/// `±half_height · up` around `position + focal_length · forward`, where
/// `half_height = focal_length · tan(fov_y / 2)` and `half_width = aspect · half_height`.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    focal_length: f32,
    fov_y: f32,
    half_width: f32,
    half_height: f32,
    resolution: UVec2,
}

impl Camera {
    /// Builds a camera looking from `position` towards `look_at`.
    ///
    /// `fov_y_degrees` is the vertical field of view in degrees, in the open
    /// interval (0, 180). `resolution` is the film size in pixels (width, height);
    /// any aspect ratio is allowed.
    pub fn new(
        position: Vec3,
        look_at: Vec3,
        up_ref: Vec3,
        fov_y_degrees: f32,
        focal_length: f32,
        resolution: UVec2,
    ) -> Result<Self, CameraError> {
        if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) {
            return Err(CameraError::FieldOfView(fov_y_degrees));
        }
        if !(focal_length > 0.0 && focal_length.is_finite()) {
            return Err(CameraError::FocalLength(focal_length));
        }
        if resolution.x == 0 || resolution.y == 0 {
            return Err(CameraError::Resolution(resolution.x, resolution.y));
        }
        let forward = (look_at - position)
            .try_normalize()
            .ok_or(CameraError::NoForward)?;
        // |forward × up| is the sine of the angle between them; below ~0.06° the
        // roll of the camera would be decided by rounding noise.
        let right = up_ref
            .try_normalize()
            .map(|up| forward.cross(up))
            .filter(|r| r.length() > 1e-3)
            .ok_or(CameraError::UpParallelToForward)?
            .normalize();
        let up = right.cross(forward);
        let fov_y = fov_y_degrees.to_radians();
        let half_height = focal_length * (0.5 * fov_y).tan();
        let aspect = resolution.x as f32 / resolution.y as f32;
        Ok(Self {
            position,
            forward,
            right,
            up,
            focal_length,
            fov_y,
            half_width: aspect * half_height,
            half_height,
            resolution,
        })
    }

    /// The ray through continuous raster position `(x, y)`.
    ///
    /// Raster → NDC: `(x / width, y / height)` in `[0, 1]²`, then to `[−1, 1]²` with
    /// y flipped so that raster-down is world-down. The film point is
    /// `position + f·forward + ndc.x·half_width·right + ndc.y·half_height·up`.
    pub fn generate_ray(&self, x: f32, y: f32) -> CameraRay {
        let (_, on_film) = self.film_point(x, y);
        CameraRay {
            origin: self.position,
            direction: on_film.normalize(),
        }
    }

    /// Raster position `(x, y)` (pixels from the top left) in normalised device
    /// coordinates (`[−1, 1]`, y up), and the point on the film it names,
    /// relative to the eye in world space (report sections 2.1–2.2):
    /// `f·forward + ndc_x·(w/2)·right + ndc_y·(h/2)·up`. The camera ray's
    /// direction is that point normalised.
    #[inline]
    pub fn film_point(&self, x: f32, y: f32) -> (Vec2, Vec3) {
        let ndc_x = 2.0 * x / self.resolution.x as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * y / self.resolution.y as f32;
        let on_film = self.focal_length * self.forward
            + (ndc_x * self.half_width) * self.right
            + (ndc_y * self.half_height) * self.up;
        (Vec2::new(ndc_x, ndc_y), on_film)
    }

    /// [`Self::generate_ray`] for [`LANES`] raster positions `(x[k], y[k])` at
    /// once, each lane's direction bit for bit the scalar one: the same
    /// operations in the same order, nothing fused.
    #[inline]
    pub fn generate_rays_lanes(&self, x: F32Lanes, y: F32Lanes) -> CameraRayLanes {
        let two = F32Lanes::splat(2.0);
        let ndc_x = two * x / F32Lanes::splat(self.resolution.x as f32) - F32Lanes::ONE;
        let ndc_y = F32Lanes::ONE - two * y / F32Lanes::splat(self.resolution.y as f32);
        let (a, b) = (
            ndc_x * F32Lanes::splat(self.half_width),
            ndc_y * F32Lanes::splat(self.half_height),
        );
        let on_film = |axis: usize| {
            let f = self.focal_length * self.forward[axis];
            F32Lanes::splat(f)
                + a * F32Lanes::splat(self.right[axis])
                + b * F32Lanes::splat(self.up[axis])
        };
        let (dx, dy, dz) = (on_film(0), on_film(1), on_film(2));
        // Vec3::normalize: times 1/length, the length of (x·x + y·y) + z·z.
        let rcp = F32Lanes::ONE / (dx * dx + dy * dy + dz * dz).sqrt();
        CameraRayLanes {
            origin: self.position,
            direction: [dx * rcp, dy * rcp, dz * rcp],
        }
    }

    /// The ray through raster position `(x, y)` with its differentials: the rays
    /// through `(x + 1, y)` and `(x, y + 1)`.
    pub fn generate_ray_differential(&self, x: f32, y: f32) -> CameraRayDifferential {
        CameraRayDifferential {
            ray: self.generate_ray(x, y),
            dx_direction: self.generate_ray(x + 1.0, y).direction,
            dy_direction: self.generate_ray(x, y + 1.0).direction,
        }
    }

    pub fn position(&self) -> Vec3 {
        self.position
    }
    pub fn forward(&self) -> Vec3 {
        self.forward
    }
    pub fn right(&self) -> Vec3 {
        self.right
    }
    pub fn up(&self) -> Vec3 {
        self.up
    }
    pub fn focal_length(&self) -> f32 {
        self.focal_length
    }
    /// The vertical field of view in radians.
    pub fn fov_y(&self) -> f32 {
        self.fov_y
    }
    /// Film half extents in world units at the focal distance: (width, height).
    pub fn film_half_extent(&self) -> (f32, f32) {
        (self.half_width, self.half_height)
    }
    /// Film resolution in pixels (width, height).
    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    /// The same camera with a different film resolution: the basis and the
    /// vertical field of view are kept, the horizontal extent follows the aspect ratio.
    pub fn with_resolution(&self, resolution: UVec2) -> Result<Self, CameraError> {
        if resolution.x == 0 || resolution.y == 0 {
            return Err(CameraError::Resolution(resolution.x, resolution.y));
        }
        let aspect = resolution.x as f32 / resolution.y as f32;
        Ok(Self {
            resolution,
            half_width: aspect * self.half_height,
            ..self.clone()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_snapfmt::vec3 as v3;
    use std::fmt::Write;

    fn course_set2(res: UVec2) -> Camera {
        Camera::new(
            Vec3::new(5.0, 3.0, 12.0),
            Vec3::ZERO,
            Vec3::Y,
            45.0,
            1.0,
            res,
        )
        .unwrap()
    }

    #[test]
    fn basis_and_corner_rays_of_a_4x3_film() {
        let cam = course_set2(UVec2::new(4, 3));
        let mut s = String::new();
        writeln!(s, "forward {}", v3(cam.forward())).unwrap();
        writeln!(s, "right   {}", v3(cam.right())).unwrap();
        writeln!(s, "up      {}", v3(cam.up())).unwrap();
        for (name, x, y) in [
            ("top-left", 0.0, 0.0),
            ("top-right", 4.0, 0.0),
            ("bottom-left", 0.0, 3.0),
            ("bottom-right", 4.0, 3.0),
            ("centre", 2.0, 1.5),
        ] {
            let r = cam.generate_ray(x, y);
            writeln!(s, "{name:<12} {} -> {}", v3(r.origin), v3(r.direction)).unwrap();
        }
        insta::assert_snapshot!(s);
    }

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        let cam = course_set2(UVec2::new(640, 480));
        for v in [cam.forward(), cam.right(), cam.up()] {
            assert!((v.length() - 1.0).abs() < 1e-6);
        }
        assert!(cam.forward().dot(cam.right()).abs() < 1e-6);
        assert!(cam.forward().dot(cam.up()).abs() < 1e-6);
        assert!((cam.right().cross(cam.up()) + cam.forward()).length() < 1e-6);
    }

    #[test]
    fn corner_rays_span_the_field_of_view() {
        let cam = course_set2(UVec2::new(300, 200));
        let top = cam.generate_ray(150.0, 0.0).direction;
        let bottom = cam.generate_ray(150.0, 200.0).direction;
        let angle = top.angle_between(bottom).to_degrees();
        assert!((angle - 45.0).abs() < 1e-3, "vertical fov was {angle}");
        let left = cam.generate_ray(0.0, 100.0).direction;
        let right = cam.generate_ray(300.0, 100.0).direction;
        let expected = 2.0 * (1.5 * (22.5f32).to_radians().tan()).atan().to_degrees();
        let got = left.angle_between(right).to_degrees();
        assert!((got - expected).abs() < 1e-3);
        assert!(top.dot(cam.up()) > 0.0 && left.dot(cam.right()) < 0.0);
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let ok = |fov, f, res: UVec2, up: Vec3| {
            Camera::new(Vec3::ZERO, -Vec3::Z, up, fov, f, res).map(|_| ())
        };
        let res = UVec2::new(4, 4);
        assert_eq!(
            ok(0.0, 1.0, res, Vec3::Y),
            Err(CameraError::FieldOfView(0.0))
        );
        assert_eq!(
            ok(180.0, 1.0, res, Vec3::Y),
            Err(CameraError::FieldOfView(180.0))
        );
        assert_eq!(
            ok(45.0, 0.0, res, Vec3::Y),
            Err(CameraError::FocalLength(0.0))
        );
        assert_eq!(
            ok(45.0, 1.0, UVec2::new(0, 4), Vec3::Y),
            Err(CameraError::Resolution(0, 4))
        );
        assert_eq!(
            ok(45.0, 1.0, res, Vec3::Z),
            Err(CameraError::UpParallelToForward)
        );
        assert_eq!(ok(45.0, 1.0, res, Vec3::Y), Ok(()));
        // Nearly parallel up vectors (here off by rounding noise) are refused too.
        let dir = Vec3::new(0.3, 0.7, 1.1);
        let near = Camera::new(Vec3::ZERO, dir, dir + Vec3::splat(1e-7), 45.0, 1.0, res);
        assert_eq!(near.map(|_| ()), Err(CameraError::UpParallelToForward));
    }

    #[test]
    fn a_new_resolution_keeps_the_view_even_far_from_the_origin() {
        let far = Vec3::new(3.0e7, -2.0e7, 1.0e7);
        let cam = Camera::new(
            far,
            far + Vec3::new(0.3, 0.1, -1.0),
            Vec3::Y,
            40.0,
            1.0,
            UVec2::new(8, 8),
        )
        .unwrap();
        let wide = cam.with_resolution(UVec2::new(16, 8)).unwrap();
        assert_eq!(
            (wide.forward(), wide.right(), wide.up()),
            (cam.forward(), cam.right(), cam.up())
        );
        assert_eq!(wide.film_half_extent().0, 2.0 * cam.film_half_extent().0);
        assert_eq!(wide.film_half_extent().1, cam.film_half_extent().1);
        assert_eq!(wide.generate_ray(8.0, 4.0), cam.generate_ray(4.0, 4.0));
        assert!(cam.with_resolution(UVec2::new(0, 3)).is_err());
    }

    #[test]
    fn rays_in_lanes_are_the_scalar_rays_bit_for_bit() {
        let camera = Camera::new(
            Vec3::new(1.5, -2.0, 7.0),
            Vec3::new(0.2, 0.1, -3.0),
            Vec3::new(0.1, 1.0, 0.0),
            47.0,
            1.3,
            UVec2::new(640, 360),
        )
        .unwrap();
        let mut seed = 0x2545_f491_u32;
        let mut next = move |scale: f32| {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            (seed >> 8) as f32 / (1 << 24) as f32 * scale
        };
        for _ in 0..500 {
            let x: [f32; LANES] = std::array::from_fn(|_| next(640.0));
            let y: [f32; LANES] = std::array::from_fn(|_| next(360.0));
            let lanes = camera.generate_rays_lanes(F32Lanes::new(x), F32Lanes::new(y));
            for k in 0..LANES {
                let scalar = camera.generate_ray(x[k], y[k]);
                assert_eq!(lanes.origin, scalar.origin);
                let d = lanes.direction.map(|c| c.to_array()[k].to_bits());
                assert_eq!(
                    d,
                    scalar.direction.to_array().map(f32::to_bits),
                    "({}, {})",
                    x[k],
                    y[k]
                );
            }
        }
    }
}
