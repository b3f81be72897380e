//! Starting secondary rays without self-intersection.
//!
//! Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
//! Ray Tracing Gems (2019), chapter 6: the origin is pushed along the normal by a
//! fixed number of ULPs of each coordinate, so the offset grows with the magnitude
//! of the point (its floating-point error grows the same way). Near the world origin,
//! where ULPs become tiny, a small absolute offset takes over.

use crate::{Hit, Ray};
use glam::Vec3;

const ORIGIN: f32 = 1.0 / 32.0;
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
const INT_SCALE: f32 = 256.0;

/// Fraction of a shadow ray's length left unexamined at its far end, so that the
/// surface the ray aims at (a light sample) does not occlude itself.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// `point` moved off its surface to the side that `normal` points to.
pub fn offset_ray_origin(point: Vec3, normal: Vec3) -> Vec3 {
    let offset_int = (INT_SCALE * normal).as_ivec3();
    let nudge = |p: f32, o: i32| {
        let o = if p < 0.0 { -o } else { o };
        f32::from_bits((p.to_bits() as i32).wrapping_add(o) as u32)
    };
    let p_int = Vec3::new(
        nudge(point.x, offset_int.x),
        nudge(point.y, offset_int.y),
        nudge(point.z, offset_int.z),
    );
    let near_origin = point.abs().cmplt(Vec3::splat(ORIGIN));
    Vec3::select(near_origin, point + FLOAT_SCALE * normal, p_int)
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
    let origin = offset_ray_origin(hit.point, outgoing_normal(hit, direction));
    Ray::new(origin, direction)
}

/// A ray from `hit` towards `target`, with the `t_max` to pass to occlusion
/// queries: the direction is `target − origin`, so `t = 1` is the target itself,
/// and `t_max = 1 − SHADOW_EPSILON` stops just short of it.
pub fn spawn_ray_to(hit: &Hit, target: Vec3) -> (Ray, f32) {
    let origin = offset_ray_origin(hit.point, outgoing_normal(hit, target - hit.point));
    (Ray::new(origin, target - origin), 1.0 - SHADOW_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_normal_side_and_scales_with_magnitude() {
        for p in [
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(-1000.0, 5000.0, -20000.0),
        ] {
            let n = Vec3::new(0.0, 1.0, 0.0);
            let o = offset_ray_origin(p, n);
            assert!(o.y > p.y);
            assert_eq!((o.x, o.z), (p.x, p.z));
            // 256 ULPs: relative offset about 256 * 2^-23 of the coordinate.
            let rel = (o.y - p.y) / p.y.abs();
            assert!(rel > 1e-5 && rel < 1e-4, "relative offset {rel}");
        }
        let tiny = offset_ray_origin(Vec3::ZERO, -Vec3::Z);
        assert_eq!(tiny, Vec3::new(0.0, 0.0, -FLOAT_SCALE));
    }
}
