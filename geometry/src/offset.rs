//! Starting secondary rays without self-intersection.
//!
//! Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
//! Ray Tracing Gems (2019), chapter 6: the origin is pushed along the normal by a
//! fixed number of ULPs of each coordinate, so the offset grows with the magnitude
//! of the point (its floating-point error grows the same way). Near the world origin,
//! where ULPs become tiny, a small absolute offset takes over.

use crate::lanes::I32Lanes;
use crate::lanes::{self, F32Lanes, Vec3Lanes};
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

/// [`offset_ray_origin`] for [`LANES`](crate::lanes::LANES) points at once, each lane bit for bit the
/// scalar origin (the same integer nudge of the bits, the same small absolute
/// offset near the world origin).
#[inline]
pub fn offset_ray_origins(point: &Vec3Lanes, normal: &Vec3Lanes) -> Vec3Lanes {
    let axis = |p: F32Lanes, n: F32Lanes| {
        // `as i32` per lane: truncation, NaN to 0, saturating.
        let o = (F32Lanes::splat(INT_SCALE) * n).trunc_int();
        let negative: I32Lanes = bytemuck::cast(lanes::lt(p, F32Lanes::ZERO));
        let o = negative.select(-o, o);
        let p_int: F32Lanes = bytemuck::cast(bytemuck::cast::<F32Lanes, I32Lanes>(p) + o);
        let near_origin = lanes::lt(p.abs(), F32Lanes::splat(ORIGIN));
        near_origin.select(p + F32Lanes::splat(FLOAT_SCALE) * n, p_int)
    };
    Vec3Lanes {
        x: axis(point.x, normal.x),
        y: axis(point.y, normal.y),
        z: axis(point.z, normal.z),
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
    use crate::lanes::LANES;

    #[test]
    fn origins_in_lanes_are_the_scalar_origins_bit_for_bit() {
        // Coordinates of every size and sign, zeros of both signs, values at the
        // near-origin threshold, and normals along and across the axes.
        let values = [
            0.0,
            -0.0,
            1e-30,
            -1e-30,
            0.03124,
            0.03125,
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
            let points: [Vec3; LANES] = std::array::from_fn(|k| {
                let v = |j: usize| values[(i + j * 3 + k) % values.len()];
                Vec3::new(v(0), v(1), v(2))
            });
            let ns: [Vec3; LANES] = std::array::from_fn(|k| normals[(i + k) % normals.len()]);
            let lanes =
                offset_ray_origins(&Vec3Lanes::from_lanes(points), &Vec3Lanes::from_lanes(ns));
            for k in 0..LANES {
                let scalar = offset_ray_origin(points[k], ns[k]);
                assert_eq!(
                    lanes.lane(k).to_array().map(f32::to_bits),
                    scalar.to_array().map(f32::to_bits),
                    "{} along {}",
                    points[k],
                    ns[k]
                );
                compared += 1;
            }
        }
        assert_eq!(compared, LANES * values.len());
    }

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
