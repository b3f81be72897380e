//! Spheres: the ray–sphere test in its precision-improved form, and the
//! spherical uv mapping with its derivatives.

use crate::error_bounds::gamma;
use crate::{Hit, Ray};
use glam::{Vec2, Vec3};
use glint_lanes::{Float, Mask, Vector3};
use std::f32::consts::{PI, TAU};

/// [`Sphere::hit_distance`] over any [`Float`]: for one ray and one sphere
/// (`f32`), many rays and one sphere, or one ray and many spheres (lanes, the
/// other operands splat). The mask of the lanes whose ray hits in `(0, t_max)`,
/// and there the nearer such root.
///
/// Haines et al., "Precision Improvements for Ray/Sphere Intersection", Ray
/// Tracing Gems (2019), ch. 7: `f = o − c`, `b = f·d`, `a = d·d`,
/// `disc = a·(r² − |f − (b/a)·d|²)`, and the roots `c/q` and `q/a` with
/// `q = −(b + sign(b)·√disc)` (`±√(−c/a)` where `q = 0`).
#[inline(always)]
pub(crate) fn sphere_hits<F: Float>(
    center: &Vector3<F>,
    radius2: F,
    origin: &Vector3<F>,
    direction: &Vector3<F>,
    t_max: F,
) -> (F::Mask, F) {
    let f = *origin - *center;
    let d = direction;
    let b = f.dot(d);
    let c = f.dot(&f) - radius2;
    // Outside the sphere (c > 0) and moving away (b > 0): both roots are
    // negative. Most rays against most spheres end here, before any division.
    let receding = c.gt(F::ZERO) & b.gt(F::ZERO);
    if receding.all() {
        return (F::Mask::FALSE, F::ZERO);
    }
    let a = d.dot(d);
    let perpendicular = f - d.scale(b / a);
    let disc = a * (radius2 - perpendicular.dot(&perpendicular));
    let missed = receding | disc.lt(F::ZERO);
    if missed.all() {
        return (F::Mask::FALSE, F::ZERO);
    }
    let q = -(b + b.signum() * disc.sqrt());
    let (x, y) = (c / q, q / a);
    let (mut t0, mut t1) = (x.min(y), x.max(y));
    let q_zero = q.eq(F::ZERO);
    if q_zero.any() {
        let h = (-c / a).max(F::ZERO).sqrt();
        t0 = F::select(q_zero, -h, t0);
        t1 = F::select(q_zero, h, t1);
    }
    let near = t0.in_ray_range(t_max);
    let hit = (near | t1.in_ray_range(t_max)) & !missed;
    (hit, F::select(near, t0, t1))
}

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
        let (hit, t) = sphere_hits(
            &self.center.into(),
            self.radius * self.radius,
            &ray.origin.into(),
            &ray.direction.into(),
            t_max,
        );
        hit.then_some(t)
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
    pub fn uv_of_normal(n: Vec3) -> (Vec2, f32, f32) {
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
