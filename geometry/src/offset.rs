//! Starting secondary rays without self-intersection.
//!
//! A computed hit point is only known to lie within its error bound
//! ([`Hit::error`], see [`crate::error_bounds`]) of the surface. A new ray starts
//! outside that box of uncertainty: moved along the normal by the bound's extent
//! in that direction, `d = |n|·error`, then each coordinate one float further the
//! way it moved, so that the rounding of the sum cannot leave it on the surface
//! (Pharr, Jakob and Humphreys, *pbrt-v4*, §6.8.6). The offset scales with the
//! magnitude of the point, as its error does, and with nothing else: there is no
//! fixed epsilon.

use crate::lanes::{Float, Vec3Lanes, Vector3};
use crate::{Hit, Ray};
use glam::Vec3;

/// `point`, known within `error` (per axis) of its surface, moved off the surface
/// to the side that the unit `normal` points to.
#[inline(always)]
pub fn offset_ray_origin(point: Vec3, error: Vec3, normal: Vec3) -> Vec3 {
    offset_origin(&point.into(), &error.into(), &normal.into()).into()
}

/// [`offset_ray_origin`] for [`LANES`](crate::lanes::LANES) points at once, each
/// lane bit for bit the scalar origin.
#[inline]
pub fn offset_ray_origins(point: &Vec3Lanes, error: &Vec3Lanes, normal: &Vec3Lanes) -> Vec3Lanes {
    offset_origin(point, error, normal)
}

/// The one kernel of both: `point + (|n|·error)·n`, then each coordinate one
/// float further the way it moved. Selects rather than branches on the
/// offset's sign, which varies unpredictably from point to point.
#[inline(always)]
fn offset_origin<F: Float>(
    point: &Vector3<F>,
    error: &Vector3<F>,
    normal: &Vector3<F>,
) -> Vector3<F> {
    let d = normal.abs().dot(error);
    let offset = normal.scale(d);
    let moved = *point + offset;
    Vector3 {
        x: moved.x.next_away(offset.x),
        y: moved.y.next_away(offset.y),
        z: moved.z.next_away(offset.z),
    }
}

/// The side of `hit`'s surface that `direction` leaves towards, as a unit normal.
fn outgoing_normal(hit: &Hit, direction: Vec3) -> Vec3 {
    if hit.geometric_normal.dot(direction) < 0.0 {
        -hit.geometric_normal
    } else {
        hit.geometric_normal
    }
}

/// A ray leaving `hit` along `direction`.
pub fn spawn_ray(hit: &Hit, direction: Vec3) -> Ray {
    let origin = offset_ray_origin(hit.point, hit.error, outgoing_normal(hit, direction));
    Ray::new(origin, direction)
}

/// A point a shadow ray aims at: a light's sample point, with the error bound of
/// its computed position and the unit normal of the light's side the rays
/// arrive on, or an exactly known point (a point light).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayTarget {
    pub point: Vec3,
    pub error: Vec3,
    pub normal: Vec3,
}

impl RayTarget {
    /// A point known exactly and on no surface: the ray ends at it.
    pub fn exact(point: Vec3) -> Self {
        Self {
            point,
            error: Vec3::ZERO,
            normal: Vec3::ZERO,
        }
    }

    /// Where a ray towards the target ends: the point moved off its surface
    /// towards `normal` by its error bound (the point itself when exact).
    #[inline]
    pub fn end(&self) -> Vec3 {
        offset_ray_origin(self.point, self.error, self.normal)
    }
}

/// A shadow ray from `hit` towards `target`: from the offset origin to the
/// target's offset [`end`](RayTarget::end), so that occlusion queries with
/// `t_max = 1` test the open segment between the two surfaces and neither
/// surface itself. The origin leaves on the side of `hit` that the target is on.
pub fn spawn_ray_to(hit: &Hit, target: &RayTarget) -> Ray {
    let normal = outgoing_normal(hit, target.point - hit.point);
    let origin = offset_ray_origin(hit.point, hit.error, normal);
    Ray::new(origin, target.end() - origin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error_bounds::gamma;
    use crate::lanes::LANES;

    #[test]
    fn origins_in_lanes_are_the_scalar_origins_bit_for_bit() {
        // Coordinates of every size and sign, zeros of both signs, errors from
        // zero up, and normals along and across the axes.
        let values = [
            0.0,
            -0.0,
            1e-30,
            -1e-30,
            0.03124,
            -0.03126,
            0.5,
            -2.0,
            3.7,
            -1e4,
            1e7,
            f32::MIN_POSITIVE,
            -123.456,
        ];
        let normals = [
            Vec3::X,
            -Vec3::Y,
            Vec3::new(0.6, -0.8, 0.0),
            Vec3::new(-0.267, 0.534, 0.801),
            Vec3::new(1e-8, -1.0, 1e-8),
        ];
        let mut compared = 0;
        for (i, _) in values.iter().enumerate() {
            let v = |j: usize, k: usize| values[(i + j * 3 + k) % values.len()];
            let points: [Vec3; LANES] =
                std::array::from_fn(|k| Vec3::new(v(0, k), v(1, k), v(2, k)));
            let errors: [Vec3; LANES] = std::array::from_fn(|k| gamma(k as u32) * points[k].abs());
            let ns: [Vec3; LANES] = std::array::from_fn(|k| normals[(i + k) % normals.len()]);
            let lanes = offset_ray_origins(
                &Vec3Lanes::from_lanes(points),
                &Vec3Lanes::from_lanes(errors),
                &Vec3Lanes::from_lanes(ns),
            );
            for k in 0..LANES {
                let scalar = offset_ray_origin(points[k], errors[k], ns[k]);
                assert_eq!(
                    lanes.lane(k).to_array().map(f32::to_bits),
                    scalar.to_array().map(f32::to_bits),
                    "{} ± {} along {}",
                    points[k],
                    errors[k],
                    ns[k]
                );
                compared += 1;
            }
        }
        assert_eq!(compared, LANES * values.len());
    }

    /// The origin leaves the error box: along the normal by more than the
    /// bound's extent `d`, and by not much more (one float per axis).
    #[test]
    fn the_offset_clears_the_error_bound_and_no_more() {
        for p in [
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(-1000.0, 5000.0, -20000.0),
            Vec3::new(1e-6, -3e-7, 0.0),
        ] {
            let error = gamma(7) * p.abs();
            for n in [Vec3::Y, Vec3::new(0.6, 0.0, -0.8), -Vec3::X] {
                let o = offset_ray_origin(p, error, n);
                let d = n.abs().dot(error);
                let along = (o.as_dvec3() - p.as_dvec3()).dot(n.as_dvec3());
                assert!(along > d as f64, "{p} along {n}: {along} <= {d}");
                let ulp = p.abs().max_element().next_up() - p.abs().max_element();
                assert!(along <= (d + 2.0 * ulp) as f64, "{p} along {n}: {along}");
            }
        }
        // Even with no error, the origin moves by one float (not at all along an
        // axis the normal has no component on).
        let o = offset_ray_origin(Vec3::new(1.0, 0.0, 2.0), Vec3::splat(1e-30), -Vec3::Z);
        assert_eq!(o, Vec3::new(1.0, 0.0, 2f32.next_down()));
    }

    #[test]
    fn an_exact_target_is_the_end_of_its_ray_and_a_surface_one_stops_short() {
        let hit = Hit {
            t: 1.0,
            point: Vec3::new(0.0, 0.0, 0.0),
            error: Vec3::splat(1e-7),
            geometric_normal: Vec3::Y,
            shading_normal: Vec3::Y,
            uv: glam::Vec2::ZERO,
            dpdu: Vec3::X,
            dpdv: Vec3::Z,
            dndu: Vec3::ZERO,
            dndv: Vec3::ZERO,
            front_face: true,
            shape: 0,
            primitive: 0,
        };
        let light = Vec3::new(0.3, 5.0, -0.2);
        let ray = spawn_ray_to(&hit, &RayTarget::exact(light));
        assert_eq!(ray.origin + ray.direction, light);
        assert!(ray.origin.y > 0.0);
        let on_light = RayTarget {
            point: light,
            error: gamma(7) * Vec3::splat(5.0),
            normal: -Vec3::Y,
        };
        let short = spawn_ray_to(&hit, &on_light);
        assert!((short.origin + short.direction).y < light.y);
    }
}
