//! Four spheres or four parallelograms against one ray at once, in
//! structure-of-arrays form: the course's scenes (a handful of analytic shapes,
//! no BVH) test every shape for every ray, and a packet tests four for about the
//! price of one.
//!
//! The tests are the scalar tests' kernels ([`Sphere::hit_distance`],
//! [`Parallelogram::hit_distance`]) run over four lanes of shapes with the ray
//! in every lane, so each lane's verdict and distance are bit for bit the
//! scalar test's, and a caller may mix the two.

use super::parallelogram::ParallelogramConstants;
use super::sphere::sphere_hits;
use super::{Parallelogram, Sphere};
use crate::counters::count;
use crate::Ray;
use glam::{Vec3, Vec4};
use glint_lanes::{Mask, Vector3};
use wide::f32x4;

/// Sets lane `lane` of `lanes` to `v`.
fn set(lanes: &mut Vector3<f32x4>, lane: usize, v: Vec3) {
    lanes.x.as_mut_array()[lane] = v.x;
    lanes.y.as_mut_array()[lane] = v.y;
    lanes.z.as_mut_array()[lane] = v.z;
}

/// The ray `ray` in all four lanes.
#[inline(always)]
fn splat(ray: &Ray) -> (Vector3<f32x4>, Vector3<f32x4>) {
    (Vector3::splat(ray.origin), Vector3::splat(ray.direction))
}

/// Up to four spheres, structure of arrays; unused lanes hold NaN and are never hit.
#[derive(Clone, Copy, Debug)]
pub struct SpherePacket {
    center: Vector3<f32x4>,
    /// `radius²`, rounded as the scalar test rounds it.
    radius2: f32x4,
    /// Lanes in use.
    used: u32,
}

impl SpherePacket {
    /// A packet with every lane unused.
    pub const EMPTY: SpherePacket = SpherePacket {
        center: Vector3 {
            x: f32x4::new([f32::NAN; 4]),
            y: f32x4::new([f32::NAN; 4]),
            z: f32x4::new([f32::NAN; 4]),
        },
        radius2: f32x4::new([f32::NAN; 4]),
        used: 0,
    };

    /// Puts `sphere` in `lane` (0..4).
    pub fn set_lane(&mut self, lane: usize, sphere: &Sphere) {
        set(&mut self.center, lane, sphere.center);
        self.radius2.as_mut_array()[lane] = sphere.radius * sphere.radius;
        self.used = self.used.max(lane as u32 + 1);
    }

    /// The scalar test of each lane: bit k of the mask is set iff
    /// `sphere_k.hit_distance(ray, t_max)` is `Some(t)`, and lane k of the `Vec4` is
    /// then that `t`, bit for bit (the same kernel). Lanes not hit hold
    /// unspecified values.
    #[inline]
    pub fn hit4(&self, ray: &Ray, t_max: f32) -> (u32, Vec4) {
        count(|c| c.sphere_tests += u64::from(self.used));
        let (origin, direction) = splat(ray);
        let (hits, t) = sphere_hits(
            &self.center,
            self.radius2,
            &origin,
            &direction,
            f32x4::splat(t_max),
        );
        (hits.bits(), Vec4::from_array(t.to_array()))
    }
}

/// Up to four parallelograms, structure of arrays; unused lanes hold NaN and are
/// never hit.
#[derive(Clone, Copy, Debug)]
pub struct ParallelogramPacket {
    shapes: ParallelogramConstants<f32x4>,
    /// Lanes in use.
    used: u32,
}

impl ParallelogramPacket {
    /// A packet with every lane unused.
    pub const EMPTY: ParallelogramPacket = {
        let nan = f32x4::new([f32::NAN; 4]);
        let nan3 = Vector3 {
            x: nan,
            y: nan,
            z: nan,
        };
        ParallelogramPacket {
            shapes: ParallelogramConstants {
                origin: nan3,
                edge1: nan3,
                edge2: nan3,
                normal: nan3,
                w: nan3,
                extent: nan,
                coordinate_scale: [nan; 2],
                one_sided: f32x4::ZERO,
            },
            used: 0,
        }
    };

    /// Puts `p` in `lane` (0..4).
    pub fn set_lane(&mut self, lane: usize, p: &Parallelogram) {
        let shapes = &mut self.shapes;
        set(&mut shapes.origin, lane, p.origin);
        set(&mut shapes.edge1, lane, p.edge1);
        set(&mut shapes.edge2, lane, p.edge2);
        set(&mut shapes.normal, lane, p.normal);
        set(&mut shapes.w, lane, p.w);
        shapes.extent.as_mut_array()[lane] = p.extent;
        shapes.coordinate_scale[0].as_mut_array()[lane] = p.coordinate_scale.x;
        shapes.coordinate_scale[1].as_mut_array()[lane] = p.coordinate_scale.y;
        shapes.one_sided.as_mut_array()[lane] = if p.two_sided {
            0.0
        } else {
            f32::from_bits(u32::MAX)
        };
        self.used = self.used.max(lane as u32 + 1);
    }

    /// The lanes (bit k for lane k) that no ray ending at any of `points` can
    /// hit: one-sided parallelograms with every point in front of their plane
    /// by more than `margin` (plus a rounding allowance of each lane's size).
    /// A ray is hit only on the front side, crossing the plane from front to
    /// back; a segment whose far end lies in front never does (if it starts
    /// in front it stays there, if behind it crosses from back to front). So
    /// shadow rays towards a light inside a room are never blocked by its
    /// one-sided walls, wherever they start.
    #[inline]
    pub fn facing_away_from(&self, points: &[Vec3; 4], margin: f32) -> u32 {
        let shapes = &self.shapes;
        let margin = f32x4::splat(margin) + f32x4::splat(1e-3) * shapes.extent;
        let mut in_front = shapes.one_sided;
        for point in points {
            let distance = shapes.normal.dot(&(Vector3::splat(*point) - shapes.origin));
            in_front &= distance.simd_gt(margin);
        }
        in_front.bits()
    }

    /// The scalar test of each lane, as [`SpherePacket::hit4`] for spheres.
    #[inline]
    pub fn hit4(&self, ray: &Ray, t_max: f32) -> (u32, Vec4) {
        count(|c| c.parallelogram_tests += u64::from(self.used));
        let (origin, direction) = splat(ray);
        let (hits, t) = self.shapes.hits(&origin, &direction, f32x4::splat(t_max));
        (hits.bits(), Vec4::from_array(t.to_array()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::XorShift;

    /// Four random parallelograms about the origin, wall `k` two-sided where
    /// `two_sided(k)`.
    fn random_walls(rng: &mut XorShift, two_sided: impl Fn(usize) -> bool) -> Vec<Parallelogram> {
        (0..4)
            .map(|k| {
                let (origin, e1, e2) = (
                    rng.vec3(-3.0, 3.0),
                    rng.vec3(-4.0, 4.0),
                    rng.vec3(-4.0, 4.0),
                );
                Parallelogram::new(origin, e1, e2, two_sided(k)).unwrap()
            })
            .collect()
    }

    /// Every lane agrees with the scalar test bit for bit, on random rays
    /// (origins inside and outside, grazing and tangent ones included by volume).
    #[test]
    fn packets_agree_with_the_scalar_tests_bit_for_bit() {
        let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
        let mut hits = 0;
        for _ in 0..2000 {
            let spheres: Vec<Sphere> = (0..3)
                .map(|_| Sphere::new(rng.vec3(-3.0, 3.0), 0.2 + 2.0 * rng.unit()).unwrap())
                .collect();
            let walls = random_walls(&mut rng, |k| k % 2 == 0);
            let mut sphere_packet = SpherePacket::EMPTY;
            for (lane, s) in spheres.iter().enumerate() {
                sphere_packet.set_lane(lane, s);
            }
            let mut wall_packet = ParallelogramPacket::EMPTY;
            for (lane, p) in walls.iter().enumerate() {
                wall_packet.set_lane(lane, p);
            }
            // From anywhere, towards the shapes' neighbourhood.
            let origin = rng.vec3(-5.0, 5.0);
            let ray = Ray::new(origin, rng.vec3(-3.0, 3.0) - origin);
            let t_max = if rng.unit() < 0.5 {
                f32::INFINITY
            } else {
                6.0 * rng.unit()
            };
            let (mask, t) = sphere_packet.hit4(&ray, t_max);
            for (lane, s) in spheres.iter().enumerate() {
                let packet = (mask >> lane & 1 == 1).then(|| t[lane].to_bits());
                assert_eq!(packet, s.hit_distance(&ray, t_max).map(f32::to_bits));
                hits += packet.is_some() as u32;
            }
            assert_eq!(mask >> 3, 0, "the unused lane is never hit");
            let (mask, t) = wall_packet.hit4(&ray, t_max);
            for (lane, p) in walls.iter().enumerate() {
                let packet = (mask >> lane & 1 == 1).then(|| t[lane].to_bits());
                assert_eq!(packet, p.hit_distance(&ray, t_max).map(f32::to_bits));
                hits += packet.is_some() as u32;
            }
        }
        assert!(hits > 1000, "the test rays hit something ({hits} hits)");
    }

    /// Walls dropped as facing away from a light are never hit by a segment
    /// from anywhere (in front of them, behind, grazing) to any point of it.
    #[test]
    fn walls_facing_away_from_a_light_block_no_segment_to_it() {
        let mut rng = XorShift(0x5851_f42d_4c95_7f2d);
        let (mut dropped, mut kept_and_hit) = (0, 0);
        for round in 0..3000 {
            let walls = random_walls(&mut rng, |k| (round + k) % 5 == 0);
            let mut packet = ParallelogramPacket::EMPTY;
            for (lane, p) in walls.iter().enumerate() {
                packet.set_lane(lane, p);
            }
            let corner = rng.vec3(-3.0, 3.0);
            let (e1, e2) = (rng.vec3(-1.0, 1.0), rng.vec3(-1.0, 1.0));
            let light = [corner, corner + e1, corner + e1 + e2, corner + e2];
            let away = packet.facing_away_from(&light, 1e-3);
            for (lane, wall) in walls.iter().enumerate() {
                let is_dropped = away >> lane & 1 == 1;
                dropped += is_dropped as u32;
                for _ in 0..8 {
                    let from = rng.vec3(-6.0, 6.0);
                    let to = corner + rng.unit() * e1 + rng.unit() * e2;
                    let hit = wall.hit_distance(&Ray::new(from, to - from), 1.0).is_some();
                    assert!(!(is_dropped && hit), "round {round}, lane {lane}");
                    kept_and_hit += hit as u32;
                }
            }
        }
        assert!(
            dropped > 1000 && kept_and_hit > 1000,
            "{dropped} dropped, {kept_and_hit} kept and hit"
        );
    }

    #[test]
    fn rays_from_inside_a_sphere_hit_its_far_side_and_nan_rays_nothing() {
        let mut packet = SpherePacket::EMPTY;
        packet.set_lane(2, &Sphere::new(Vec3::ZERO, 2.0).unwrap());
        let (mask, t) = packet.hit4(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY);
        assert_eq!((mask, t[2]), (0b100, 2.0));
        let nan = Ray::new(Vec3::NAN, Vec3::X);
        assert_eq!(packet.hit4(&nan, f32::INFINITY).0, 0);
    }
}
