//! How big a pixel is on a surface: ray differentials carried to a hit point.
//!
//! pbrt-v4 section 10.1 (after Igehy, "Tracing Ray Differentials", SIGGRAPH 1999):
//! the offset rays are intersected with the tangent plane at the hit, giving
//! ∂p/∂x and ∂p/∂y; ∂(u,v)/∂x and ∂(u,v)/∂y then follow from
//! `∂p/∂x = ∂p/∂u · ∂u/∂x + ∂p/∂v · ∂v/∂x`, solved in the least-squares sense.

use crate::{Hit, Ray};
use glam::{Vec2, Vec3};

/// The rays one pixel step away from a main ray, in x and in y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayDifferential {
    pub rx_origin: Vec3,
    pub rx_direction: Vec3,
    pub ry_origin: Vec3,
    pub ry_direction: Vec3,
}

impl RayDifferential {
    /// No footprint: both offset rays are `ray` itself. For scenes where nothing
    /// reads differentials, so they are never computed.
    pub fn none(ray: &Ray) -> Self {
        Self {
            rx_origin: ray.origin,
            rx_direction: ray.direction,
            ry_origin: ray.origin,
            ry_direction: ray.direction,
        }
    }
}

/// The change of surface position and uv per pixel step in x and y.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceDifferentials {
    pub dpdx: Vec3,
    pub dpdy: Vec3,
    /// (∂u/∂x, ∂v/∂x)
    pub duvdx: Vec2,
    /// (∂u/∂y, ∂v/∂y)
    pub duvdy: Vec2,
}

/// Larger uv derivatives are clamped: they arise only at grazing angles, where
/// they would otherwise overflow the filters downstream.
const MAX_UV_DERIVATIVE: f32 = 1e8;

/// The mirror reflection of the unit direction `wo` (pointing away from the
/// surface) about the unit normal `n`: `2(wo·n)n − wo`.
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

/// The mirror reflection of a ray with differentials at a hit, and its
/// differentials: pbrt-v4's `SurfaceInteraction::SpawnRay` for perfect specular
/// reflection (after Igehy 1999). With `wo = −d`, `n` the normal on `wo`'s side and
/// `wi = 2(wo·n)n − wo`, the offset rays leave from `p + ∂p/∂x` along
/// `wi − ∂wo/∂x + 2((wo·n)·∂n/∂x + (∂wo/∂x·n + wo·∂n/∂x)·n)`, where
/// `∂n/∂x = ∂n/∂u·∂u/∂x + ∂n/∂v·∂v/∂x`: curved mirrors widen the footprint.
pub fn reflect_differential(
    hit: &Hit,
    direction: Vec3,
    diff: &RayDifferential,
    surface: &SurfaceDifferentials,
) -> (Vec3, RayDifferential) {
    let wo = -direction.normalize();
    let n = hit.facing_normal(direction);
    let wi = reflect(wo, n);
    let flip = if n.dot(hit.shading_normal) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let dndx = flip * (hit.dndu * surface.duvdx.x + hit.dndv * surface.duvdx.y);
    let dndy = flip * (hit.dndu * surface.duvdy.x + hit.dndv * surface.duvdy.y);
    let offset = |d_dir: Vec3, dndx: Vec3| {
        let dwo = -d_dir.normalize() - wo;
        let d_dn = dwo.dot(n) + wo.dot(dndx);
        wi - dwo + 2.0 * (wo.dot(n) * dndx + d_dn * n)
    };
    let differential = RayDifferential {
        rx_origin: hit.point + surface.dpdx,
        rx_direction: offset(diff.rx_direction, dndx),
        ry_origin: hit.point + surface.dpdy,
        ry_direction: offset(diff.ry_direction, dndy),
    };
    (wi, differential)
}

impl RayDifferential {
    /// The angle (radians) between a ray of direction `d` and the wider of its two
    /// offset rays: the angular footprint an environment lookup filters over,
    /// `max(∠(d, rx), ∠(d, ry))`. Each angle is `2·atan2(|a − b|, |a + b|)` of
    /// the unit directions (Kahan), accurate to a few float steps at any
    /// angle, where `acos(a·b)` of a dot product rounded near 1 moves in steps
    /// of 2⁻²⁴ of `1 − cos`: about 5% apart at a pixel's footprint.
    pub fn angular_width(&self, d: Vec3) -> f32 {
        let angle = |o: Vec3| {
            let (a, b) = (d.normalize(), o.normalize());
            let angle = 2.0 * (a - b).length().atan2((a + b).length());
            if angle.is_finite() {
                angle
            } else {
                0.0
            }
        };
        angle(self.rx_direction).max(angle(self.ry_direction))
    }
}

impl Hit {
    /// The footprint of the pixel whose ray differentials are `diff` at this hit.
    pub fn differentials(&self, diff: &RayDifferential) -> SurfaceDifferentials {
        let n = self.geometric_normal;
        let on_tangent_plane = |origin: Vec3, direction: Vec3| {
            let t = n.dot(self.point - origin) / n.dot(direction);
            let p = origin + t * direction;
            if p.is_finite() {
                p - self.point
            } else {
                Vec3::ZERO
            }
        };
        let dpdx = on_tangent_plane(diff.rx_origin, diff.rx_direction);
        let dpdy = on_tangent_plane(diff.ry_origin, diff.ry_direction);
        SurfaceDifferentials {
            dpdx,
            dpdy,
            duvdx: self.uv_change(dpdx),
            duvdy: self.uv_change(dpdy),
        }
    }

    /// The (du, dv) whose `du·dpdu + dv·dpdv` best approximates `dp` (normal equations).
    fn uv_change(&self, dp: Vec3) -> Vec2 {
        let (a00, a01, a11) = (
            self.dpdu.length_squared(),
            self.dpdu.dot(self.dpdv),
            self.dpdv.length_squared(),
        );
        let det = a00 * a11 - a01 * a01;
        let inv_det = if det.abs() > 0.0 && (1.0 / det).is_finite() {
            1.0 / det
        } else {
            return Vec2::ZERO;
        };
        let (b0, b1) = (self.dpdu.dot(dp), self.dpdv.dot(dp));
        let duv = Vec2::new(a11 * b0 - a01 * b1, a00 * b1 - a01 * b0) * inv_det;
        if duv.is_finite() {
            duv.clamp(
                Vec2::splat(-MAX_UV_DERIVATIVE),
                Vec2::splat(MAX_UV_DERIVATIVE),
            )
        } else {
            Vec2::ZERO
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Plane, Ray, RayDifferential, Shape};
    use glam::{Vec2, Vec3};

    #[test]
    fn the_angular_width_is_accurate_at_a_pixels_footprint() {
        // Angles of a pixel's size and below, between directions off every
        // axis: within a few float steps (3e-7 rad) of the angle computed in
        // 64 bits, where acos of a 32-bit dot product near 1 is off by up to
        // 1e-4 rad.
        for (k, angle) in [2.2e-3f64, 1e-3, 3e-4, 0.5].into_iter().enumerate() {
            let d = glam::DVec3::new(0.3, -0.8 + 0.1 * k as f64, 0.52).normalize();
            let side = d.cross(glam::DVec3::Y).normalize();
            let o = d * angle.cos() + side * angle.sin();
            let diff = RayDifferential {
                rx_origin: Vec3::ZERO,
                rx_direction: o.as_vec3() * 3.0,
                ry_origin: Vec3::ZERO,
                ry_direction: d.as_vec3(),
            };
            let width = f64::from(diff.angular_width(d.as_vec3() * 0.5));
            // The exact angle between the 32-bit directions given.
            let exact = d.as_vec3().as_dvec3().angle_between(o.as_vec3().as_dvec3());
            assert!(
                (width - exact).abs() < 3e-7,
                "{angle}: {width} against {exact}"
            );
        }
    }

    fn ground_hit_from(height: f32, tilt: f32) -> (crate::Hit, RayDifferential) {
        let plane = Shape::from(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap());
        let origin = Vec3::new(0.0, height, 0.0);
        let d = Vec3::new(0.0, -1.0, -tilt).normalize();
        // Offsets on a film plane perpendicular to d, as a camera makes them.
        let (right, up) = (Vec3::X, Vec3::X.cross(d));
        let step = 0.01;
        let diff = RayDifferential {
            rx_origin: origin,
            rx_direction: (d + step * right).normalize(),
            ry_origin: origin,
            ry_direction: (d + step * up).normalize(),
        };
        (
            plane
                .intersect(&Ray::new(origin, d), f32::INFINITY)
                .unwrap(),
            diff,
        )
    }

    #[test]
    fn footprint_grows_with_distance_and_obliquity() {
        let (near, dn) = ground_hit_from(1.0, 0.0);
        let (far, df) = ground_hit_from(4.0, 0.0);
        let fx_near = near.differentials(&dn).dpdx.length();
        let fx_far = far.differentials(&df).dpdx.length();
        // Straight down: the footprint scales with height.
        assert!((fx_far / fx_near - 4.0).abs() < 1e-3, "{fx_near} {fx_far}");
        let (oblique, d_obl) = ground_hit_from(1.0, 2.0);
        let s = oblique.differentials(&d_obl);
        // Seen at incidence θ (cos θ = 1/√5 here), the footprint stretches by
        // about 1/cos θ along the tilt.
        let stretch = s.dpdy.length() / s.dpdx.length();
        assert!((stretch / 5f32.sqrt() - 1.0).abs() < 0.05, "{stretch}");
    }

    #[test]
    fn uv_derivatives_solve_the_tangent_plane_system() {
        let (hit, diff) = ground_hit_from(2.0, 0.5);
        let s = hit.differentials(&diff);
        for (dp, duv) in [(s.dpdx, s.duvdx), (s.dpdy, s.duvdy)] {
            let rebuilt = duv.x * hit.dpdu + duv.y * hit.dpdv;
            assert!((rebuilt - dp).length() < 1e-5 * dp.length().max(1e-3));
        }
    }

    #[test]
    fn grazing_rays_give_finite_footprints() {
        let (mut hit, mut diff) = ground_hit_from(1.0, 1e6);
        diff.ry_direction = Vec3::new(0.0, 0.0, -1.0);
        let s = hit.differentials(&diff);
        assert!(s.dpdy.is_finite() && s.duvdy.is_finite());
        hit.dpdv = hit.dpdu; // degenerate parameterisation
        assert_eq!(hit.differentials(&diff).duvdx, Vec2::ZERO);
    }
}

#[cfg(test)]
mod reflection_tests {
    use super::*;
    use crate::{Plane, Ray, Shape, Sphere};

    fn camera_like(origin: Vec3, d: Vec3, spread: f32) -> RayDifferential {
        let (right, up) = d.normalize().any_orthonormal_pair();
        RayDifferential {
            rx_origin: origin,
            rx_direction: (d.normalize() + spread * right).normalize(),
            ry_origin: origin,
            ry_direction: (d.normalize() + spread * up).normalize(),
        }
    }

    #[test]
    fn a_flat_mirror_keeps_the_angular_spread_and_a_curved_one_widens_it() {
        let origin = Vec3::new(0.0, 0.0, 5.0);
        let d = -Vec3::Z;
        let diff = camera_like(origin, d, 0.001);
        let spread_in = diff.angular_width(d);
        let flat = Shape::from(Plane::new(Vec3::ZERO, Vec3::Z, false).unwrap());
        let ball = Shape::from(Sphere::new(Vec3::new(0.0, 0.0, -1.0), 1.0).unwrap());
        let ray = Ray::new(origin, d);
        let widths: Vec<f32> = [flat, ball]
            .iter()
            .map(|shape| {
                let hit = shape.intersect(&ray, f32::INFINITY).unwrap();
                let (wi, reflected) =
                    reflect_differential(&hit, d, &diff, &hit.differentials(&diff));
                assert!((wi - Vec3::Z).length() < 1e-5);
                reflected.angular_width(wi)
            })
            .collect();
        assert!(
            (widths[0] - spread_in).abs() < 1e-4,
            "{widths:?} {spread_in}"
        );
        // A convex mirror of radius 1 seen from distance 5 spreads the beam by
        // about 1 + 2·5/1 = 11 times.
        assert!(widths[1] > 8.0 * spread_in, "{widths:?} {spread_in}");
    }
}
