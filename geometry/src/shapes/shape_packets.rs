//! Four spheres or four parallelograms against one ray at once, in
//! structure-of-arrays form: the course's scenes (a handful of analytic shapes,
//! no BVH) test every shape for every ray, and a packet tests four for about the
//! price of one.
//!
//! As for [`TrianglePacket`](super::TrianglePacket), every lane performs exactly
//! the IEEE operations of the scalar test ([`Sphere::hit_distance`],
//! [`Parallelogram::hit_distance`]) in the same order, with products and sums
//! grouped as glam's `Vec3::dot` and `Vec3::cross` group them. Rust never
//! contracts `a * b + c` into a fused multiply-add, so each lane's verdict and
//! distance are bit for bit the scalar test's, and a caller may mix the two.

use super::{Parallelogram, Sphere};
use crate::counters::count;
use crate::error_bounds::gamma;
use crate::Ray;
use glam::{BVec4A, Vec3, Vec4};

/// Lane-wise `a · b` for vectors given as `[x, y, z]` lanes, summed as
/// `Vec3::dot` sums: `(x·x′ + y·y′) + z·z′`.
#[inline(always)]
fn dot(a: [Vec4; 3], b: [Vec4; 3]) -> Vec4 {
    (a[0] * b[0]) + (a[1] * b[1]) + (a[2] * b[2])
}

/// Lane-wise `a × b`, as `Vec3::cross` computes it.
#[inline(always)]
fn cross(a: [Vec4; 3], b: [Vec4; 3]) -> [Vec4; 3] {
    [
        a[1] * b[2] - b[1] * a[2],
        a[2] * b[0] - b[2] * a[0],
        a[0] * b[1] - b[0] * a[1],
    ]
}

/// `v` in every lane, one `Vec4` per axis.
#[inline(always)]
fn splat(v: Vec3) -> [Vec4; 3] {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}

/// Lane-wise square root (correctly rounded, as `f32::sqrt`; compiles to one `sqrtps`).
#[inline(always)]
fn sqrt(v: Vec4) -> Vec4 {
    Vec4::from_array(v.to_array().map(f32::sqrt))
}

#[inline(always)]
fn sub(a: [Vec4; 3], b: [Vec4; 3]) -> [Vec4; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Sets lane `lane` of the per-axis lanes `lanes` to `v`.
fn set(lanes: &mut [Vec4; 3], lane: usize, v: Vec3) {
    for (axis, value) in lanes.iter_mut().zip(v.to_array()) {
        axis[lane] = value;
    }
}

/// Up to four spheres, structure of arrays; unused lanes hold NaN and are never hit.
#[derive(Clone, Copy, Debug)]
pub struct SpherePacket {
    center: [Vec4; 3],
    /// `radius²`, rounded as the scalar test rounds it.
    radius2: Vec4,
    /// Lanes in use.
    used: u32,
}

impl SpherePacket {
    /// A packet with every lane unused.
    pub const EMPTY: SpherePacket = SpherePacket {
        center: [Vec4::NAN; 3],
        radius2: Vec4::NAN,
        used: 0,
    };

    /// Puts `sphere` in `lane` (0..4).
    pub fn set_lane(&mut self, lane: usize, sphere: &Sphere) {
        set(&mut self.center, lane, sphere.center);
        self.radius2[lane] = sphere.radius * sphere.radius;
        self.used = self.used.max(lane as u32 + 1);
    }

    /// The scalar test of each lane: bit k of the mask is set iff
    /// `sphere_k.hit_distance(ray, t_max)` is `Some(t)`, and lane k of the `Vec4` is
    /// then that `t`, bit for bit. Lanes not hit hold unspecified values.
    ///
    /// The math is [`Sphere::hit_distance`]'s (Haines et al. 2019): `f = o − c`,
    /// `b = f·d`, `c = |f|² − r²`, `disc = a·(r² − |f − (b/a)·d|²)`, the roots `c/q`
    /// and `q/a` with `q = −(b + sign(b)·√disc)`, the nearer one in (0, t_max) first.
    #[inline]
    pub fn hit4(&self, ray: &Ray, t_max: f32) -> (u32, Vec4) {
        count(|c| c.sphere_tests += u64::from(self.used));
        let d = splat(ray.direction);
        let f = sub(splat(ray.origin), self.center);
        let b = dot(f, d);
        let c = dot(f, f) - self.radius2;
        let zero = Vec4::ZERO;
        let receding = c.cmpgt(zero) & b.cmpgt(zero);
        let a = Vec4::splat(ray.direction.length_squared());
        let along = b / a;
        let perpendicular = [
            f[0] - along * d[0],
            f[1] - along * d[1],
            f[2] - along * d[2],
        ];
        let disc = a * (self.radius2 - dot(perpendicular, perpendicular));
        let missed = receding | disc.cmplt(zero);
        let q = -(b + b.signum() * sqrt(disc));
        // q = 0: the roots ±√(−c/a).
        let h = sqrt((-c / a).max(zero));
        let (x, y) = (c / q, q / a);
        let q_zero = q.cmpeq(zero);
        let t0 = Vec4::select(q_zero, -h, x.min(y));
        let t1 = Vec4::select(q_zero, h, x.max(y));
        let t_max = Vec4::splat(t_max);
        let in_range = |t: Vec4| t.cmpgt(zero) & t.cmplt(t_max);
        let near = in_range(t0);
        let far = in_range(t1) & !near;
        let hits = (near | far) & !missed;
        (hits.bitmask(), Vec4::select(near, t0, t1))
    }
}

/// Up to four parallelograms, structure of arrays; unused lanes hold NaN and are
/// never hit.
#[derive(Clone, Copy, Debug)]
pub struct ParallelogramPacket {
    origin: [Vec4; 3],
    edge1: [Vec4; 3],
    edge2: [Vec4; 3],
    normal: [Vec4; 3],
    w: [Vec4; 3],
    /// Each lane's `extent` and `coordinate_scale`, for its `edge_margin`.
    extent: Vec4,
    coordinate_scale: [Vec4; 2],
    /// Lanes seen from their front side only.
    one_sided: BVec4A,
    /// Lanes in use.
    used: u32,
}

impl ParallelogramPacket {
    /// A packet with every lane unused.
    pub const EMPTY: ParallelogramPacket = ParallelogramPacket {
        origin: [Vec4::NAN; 3],
        edge1: [Vec4::NAN; 3],
        edge2: [Vec4::NAN; 3],
        normal: [Vec4::NAN; 3],
        w: [Vec4::NAN; 3],
        extent: Vec4::NAN,
        coordinate_scale: [Vec4::NAN; 2],
        one_sided: BVec4A::FALSE,
        used: 0,
    };

    /// Puts `p` in `lane` (0..4).
    pub fn set_lane(&mut self, lane: usize, p: &Parallelogram) {
        set(&mut self.origin, lane, p.origin);
        set(&mut self.edge1, lane, p.edge1);
        set(&mut self.edge2, lane, p.edge2);
        set(&mut self.normal, lane, p.normal);
        set(&mut self.w, lane, p.w);
        self.extent[lane] = p.extent;
        self.coordinate_scale[0][lane] = p.coordinate_scale.x;
        self.coordinate_scale[1][lane] = p.coordinate_scale.y;
        self.one_sided.set(lane, !p.two_sided);
        self.used = self.used.max(lane as u32 + 1);
    }

    /// The scalar test of each lane, as [`SpherePacket::hit4`] for spheres: the
    /// plane's distance `t = n·(p₀ − o) / n·d`, then the hit point's edge
    /// coordinates `α = w·((p − p₀) × e₂)`, `β = w·(e₁ × (p − p₀))` in [0, 1].
    #[inline]
    pub fn hit4(&self, ray: &Ray, t_max: f32) -> (u32, Vec4) {
        count(|c| c.parallelogram_tests += u64::from(self.used));
        let zero = Vec4::ZERO;
        let one = Vec4::ONE;
        let d = splat(ray.direction);
        let o = splat(ray.origin);
        let denom = dot(self.normal, d);
        let facing_away = denom.cmpeq(zero) | (self.one_sided & denom.cmpgt(zero));
        let t = dot(self.normal, sub(self.origin, o)) / denom;
        let in_range = t.cmpgt(zero) & t.cmplt(Vec4::splat(t_max));
        // ray.at(t) = o + t·d
        let point = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        let local = sub(point, self.origin);
        let alpha = dot(self.w, cross(local, self.edge2));
        let beta = dot(self.w, cross(self.edge1, local));
        let unit = |x: Vec4| x.cmpge(zero) & x.cmple(one);
        let mut inside = unit(alpha) & unit(beta);
        // Within [0, 1] is within the margin too: the margin only decides lanes
        // outside [0, 1] (as in `Parallelogram::hit_distance_lanes`).
        if (in_range & !facing_away & !inside).any() {
            // Each lane's `edge_margin` for this ray.
            let length = Vec4::splat(gamma(16))
                * (Vec4::splat(ray.origin.abs().max_element()) + self.extent);
            let within = |x: Vec4, scale: Vec4| {
                let margin = length * scale;
                x.cmpge(-margin) & x.cmple(one + margin)
            };
            inside =
                within(alpha, self.coordinate_scale[0]) & within(beta, self.coordinate_scale[1]);
        }
        let hits = in_range & inside & !facing_away;
        (hits.bitmask(), t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::XorShift;

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
            let walls: Vec<Parallelogram> = (0..4)
                .map(|k| {
                    Parallelogram::new(
                        rng.vec3(-3.0, 3.0),
                        rng.vec3(-4.0, 4.0),
                        rng.vec3(-4.0, 4.0),
                        k % 2 == 0,
                    )
                    .unwrap()
                })
                .collect();
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
