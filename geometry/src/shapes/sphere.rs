//! Spheres: the ray–sphere test in its precision-improved form, and the
//! spherical uv mapping with its derivatives.

use crate::error_bounds::gamma;
use crate::{Hit, Ray};
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// A sphere given by centre and radius.
///
/// uv: `u = φ / 2π` with `φ = atan2(−z, x)` about the y axis (u grows left to right
/// seen from +z), `v = 1 − θ / π` with `θ` the polar angle from +y (v = 0 at the
/// bottom pole, 1 at the top).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub(super) center: Vec3,
    pub(super) radius: f32,
}

impl Sphere {
    /// Returns `None` unless `radius` is positive and finite.
    pub fn new(center: Vec3, radius: f32) -> Option<Self> {
        (radius > 0.0 && radius.is_finite()).then_some(Self { center, radius })
    }

    pub fn center(&self) -> Vec3 {
        self.center
    }
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The smallest root of |o + t·d − c|² = r² in (0, t_max).
    ///
    /// The report's geometric method in the numerically careful form of Haines et
    /// al., "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems
    /// (2019), ch. 7: with `f = o − c`, `b = f·d`, `a = d·d`, the discriminant is
    /// `a·(r² − |f − (b/a)·d|²)` — the squared distance from the centre to the line
    /// is computed directly rather than as a difference of large squares — and the
    /// roots come from the stable pair `q = −(b + sign(b)·√disc)`, `t = c/q`, `t = q/a`.
    pub fn hit_distance(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let f = ray.origin - self.center;
        let d = ray.direction;
        let b = f.dot(d);
        let r2 = self.radius * self.radius;
        let c = f.length_squared() - r2;
        // Outside the sphere (c > 0) and moving away (b > 0): both roots are
        // negative. Most rays against most spheres end here, before any division.
        if c > 0.0 && b > 0.0 {
            return None;
        }
        let a = d.length_squared();
        let perpendicular = f - (b / a) * d;
        let disc = a * (r2 - perpendicular.length_squared());
        if disc < 0.0 {
            return None;
        }
        let q = -(b + b.signum() * disc.sqrt());
        let (t0, t1) = if q == 0.0 {
            let h = (-c / a).max(0.0).sqrt();
            (-h, h)
        } else {
            let (x, y) = (c / q, q / a);
            (x.min(y), x.max(y))
        };
        [t0, t1].into_iter().find(|&t| t > 0.0 && t < t_max)
    }

    /// The surface record at ray parameter `t`, found by [`Self::hit_distance`].
    /// The hit point is projected back onto the sphere to remove the error of `o + t·d`.
    pub fn surface_at(&self, ray: &Ray, t: f32) -> Hit {
        let (hit, theta, phi) = self.surface_frame(ray, t);
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (sin_theta, cos_theta) = theta.sin_cos();
        let r = self.radius;
        // p = c + r (sinθ cosφ, cosθ, −sinθ sinφ), u = φ/2π, v = 1 − θ/π.
        let dpdu = TAU * r * Vec3::new(-sin_theta * sin_phi, 0.0, -sin_theta * cos_phi);
        let dpdv = -PI * r * Vec3::new(cos_theta * cos_phi, -sin_theta, -cos_theta * sin_phi);
        Hit {
            dpdu,
            dpdv,
            // n = (p − c)/r, so ∂n/∂u = (∂p/∂u)/r (Weingarten, for a sphere).
            dndu: dpdu / r,
            dndv: dpdv / r,
            ..hit
        }
    }

    /// [`Self::surface_at`] without the derivatives `dpdu`, `dpdv`, `dndu` and
    /// `dndv` (left zero), for shading that reads no texture footprint: the
    /// other fields bit for bit, without the two `sin_cos` the derivatives take.
    #[inline]
    pub fn surface_point(&self, ray: &Ray, t: f32) -> Hit {
        self.surface_frame(ray, t).0
    }

    /// The point `c + r·n` of the unit normal `n` as a ray's target: with its
    /// error bound and its outward normal, so that a ray from outside ends
    /// just short of the surface ([`crate::RayTarget::end`]).
    #[inline]
    pub fn target_at(&self, n: Vec3) -> crate::RayTarget {
        crate::RayTarget {
            point: self.center + self.radius * n,
            error: self.point_error(n),
            normal: n,
        }
    }

    /// The error bound of the point `c + r·n` ([`crate::error_bounds`]):
    /// `γ₂|c| + γ₆·r·|n|`.
    #[inline]
    pub(crate) fn point_error(&self, n: Vec3) -> Vec3 {
        gamma(2) * self.center.abs() + n.abs() * (gamma(6) * self.radius)
    }

    /// The uv of the point with unit normal `n`, with its polar angle θ (from
    /// +y) and azimuth φ (from +x towards −z, in [0, 2π)).
    #[inline]
    pub(crate) fn uv_of_normal(n: Vec3) -> (Vec2, f32, f32) {
        let theta = n.y.clamp(-1.0, 1.0).acos();
        let mut phi = (-n.z).atan2(n.x);
        if phi < 0.0 {
            phi += TAU;
        }
        (Vec2::new(phi / TAU, 1.0 - theta / PI), theta, phi)
    }

    /// The surface record at `t` without derivatives, and the hit's polar angle
    /// θ (from +y) and azimuth φ (from +x towards −z, in [0, 2π)).
    #[inline]
    fn surface_frame(&self, ray: &Ray, t: f32) -> (Hit, f32, f32) {
        let n = (ray.at(t) - self.center).normalize();
        let point = self.center + self.radius * n;
        let (uv, theta, phi) = Self::uv_of_normal(n);
        let hit = Hit {
            t,
            point,
            error: self.point_error(n),
            geometric_normal: n,
            shading_normal: n,
            uv,
            dpdu: Vec3::ZERO,
            dpdv: Vec3::ZERO,
            dndu: Vec3::ZERO,
            dndv: Vec3::ZERO,
            front_face: n.dot(ray.direction) < 0.0,
            shape: 0,
            primitive: 0,
        };
        (hit, theta, phi)
    }
}
