//! One shape against [`LANES`] rays at once ([`RayLanes`]): the shadow rays of one
//! shading point, which all meet the same few shapes.
//!
//! [`SpherePacket`](super::SpherePacket) puts four shapes in lanes against one
//! ray; this puts [`LANES`] rays in lanes against one shape. As there, every lane
//! performs exactly the IEEE operations of the scalar test
//! ([`Sphere::hit_distance`], [`Parallelogram::hit_distance`]) in the same order,
//! so a lane's verdict is bit for bit the scalar test's.

use super::{Parallelogram, Sphere};
use crate::error_bounds::gamma;
use crate::lanes::{self, F32Lanes, Float, Mask, Vec3Lanes, LANES};
use crate::RayLanes;
use glam::{Vec2, Vec3};

impl Sphere {
    /// The lanes (bit k for lane k) whose ray [`Self::hit_distance`] finds a hit
    /// in (0, `t_max`): the same verdict, bit for bit, as the scalar test's.
    #[inline]
    pub fn hits_lanes(&self, rays: &RayLanes, t_max: f32) -> u32 {
        self.hit_distance_lanes(rays, t_max).0
    }

    /// [`Self::hit_distance`] for each lane's ray: the lanes with a hit in
    /// (0, `t_max`), and in those lanes its distance, bit for bit the scalar one.
    #[inline]
    pub fn hit_distance_lanes(&self, rays: &RayLanes, t_max: f32) -> (u32, F32Lanes) {
        let (hit, t) = super::sphere::sphere_hits(
            &Vec3Lanes::splat(self.center),
            F32Lanes::splat(self.radius * self.radius),
            &rays.origin,
            &rays.direction,
            F32Lanes::splat(t_max),
        );
        (hit.bits(), t)
    }
}

impl Parallelogram {
    /// The lanes whose ray [`Self::hit_distance`] finds a hit in (0, `t_max`),
    /// as [`Sphere::hits_lanes`] for spheres.
    #[inline]
    pub fn hits_lanes(&self, rays: &RayLanes, t_max: f32) -> u32 {
        self.hit_distance_lanes(rays, t_max).0
    }

    /// [`Self::hit_distance`] for each lane's ray, as
    /// [`Sphere::hit_distance_lanes`] for spheres.
    #[inline]
    pub fn hit_distance_lanes(&self, rays: &RayLanes, t_max: f32) -> (u32, F32Lanes) {
        let (hit, t) = self.constants::<F32Lanes>().hits(
            &rays.origin,
            &rays.direction,
            F32Lanes::splat(t_max),
        );
        (hit.bits(), t)
    }
}

/// The surface points of [`LANES`] rays' hits on one shape, in lanes: what
/// [`Sphere::surface_point`] and [`Parallelogram::surface_at`] give each lane,
/// bit for bit, without the derivatives.
#[derive(Clone, Copy, Debug, Default)]
pub struct SurfaceLanes {
    pub point: Vec3Lanes,
    /// The error bound of `point`, per axis ([`crate::Hit::error`]).
    pub error: Vec3Lanes,
    /// The geometric normal, which is also the shading normal on these shapes.
    pub normal: Vec3Lanes,
    pub u: F32Lanes,
    pub v: F32Lanes,
}

impl Sphere {
    /// [`Self::surface_point`] of each lane at its distance `t`, with the
    /// texture coordinates of the lanes `uv_lanes` (bit k for lane k; the
    /// others' are 0). The polar angles are taken one lane at a time, by the
    /// same `acos` and `atan2` as the scalar path.
    #[inline]
    pub fn surface_points_lanes(
        &self,
        rays: &RayLanes,
        t: F32Lanes,
        uv_lanes: u32,
    ) -> SurfaceLanes {
        let n = rays.at(t).sub_splat(self.center).normalize();
        let point = Vec3Lanes::splat_add(self.center, &n.scale(F32Lanes::splat(self.radius)));
        // As `point_error`: γ₂|c| + |n|·(γ₆·r).
        let error = Vec3Lanes::splat_add(
            gamma(2) * self.center.abs(),
            &n.abs().scale(F32Lanes::splat(gamma(6) * self.radius)),
        );
        let (ny, nz, nx) = (n.y.to_array(), n.z.to_array(), n.x.to_array());
        let mut u = [0.0; LANES];
        let mut v = [0.0; LANES];
        for k in lanes::each_set(uv_lanes) {
            let (uv, _, _) = Sphere::uv_of_normal(Vec3::new(nx[k], ny[k], nz[k]));
            (u[k], v[k]) = (uv.x, uv.y);
        }
        SurfaceLanes {
            point,
            error,
            normal: n,
            u: F32Lanes::new(u),
            v: F32Lanes::new(v),
        }
    }
}

/// A bound on the error of [`Sphere::uv_of_normals_approx`] in u and in v:
/// the polynomials' [`lanes::ATAN2_ERROR`] over 2π and [`lanes::ACOS_ERROR`]
/// over π, with room for the rounding of the divisions.
pub const SPHERE_UV_APPROX_ERROR: f32 = 1e-5;

impl Sphere {
    /// Each lane's texture coordinates as [`Sphere::uv_of_normal`] gives
    /// them from its unit normal `n`, within [`SPHERE_UV_APPROX_ERROR`] in u
    /// and in v, except across u's seam (a u near 0 may come out near 1, and
    /// the other way), by polynomial `acos` and `atan2` in lanes. u is NaN at
    /// the poles, where libm's `atan2(±0, ±0)` depends on the zeros' signs.
    #[inline]
    pub fn uv_of_normals_approx(n: &Vec3Lanes) -> (F32Lanes, F32Lanes) {
        use std::f32::consts::{PI, TAU};
        let y = n.y.max(F32Lanes::splat(-1.0)).min(F32Lanes::ONE);
        let theta = lanes::acos_approx(y);
        let pole = Float::eq(n.x, F32Lanes::ZERO) & Float::eq(n.z, F32Lanes::ZERO);
        let phi = lanes::atan2_approx(-n.z, n.x);
        let phi = F32Lanes::select(phi.lt(F32Lanes::ZERO), phi + F32Lanes::splat(TAU), phi);
        let phi = F32Lanes::select(pole, F32Lanes::splat(f32::NAN), phi);
        let u = phi / F32Lanes::splat(TAU);
        (u, F32Lanes::ONE - theta / F32Lanes::splat(PI))
    }
}

impl Parallelogram {
    /// [`Self::surface_at`] of each lane at its distance `t`, without the
    /// derivatives (the edges, the same in every lane).
    #[inline]
    pub fn surface_points_lanes(&self, rays: &RayLanes, t: F32Lanes) -> SurfaceLanes {
        let (alpha, beta) = self.constants::<F32Lanes>().coordinates(&rays.at(t));
        // Vec2::clamp: max with the lower bound, then min with the upper.
        let (zero, one) = (F32Lanes::ZERO, F32Lanes::ONE);
        let (u, v) = (alpha.max(zero).min(one), beta.max(zero).min(one));
        // The point at (α, β) kept off the edges, as `surface_at` clamps them,
        // then origin + α·edge1 + β·edge2, as `point_at` rounds it.
        let (low, high) = (self.pull, Vec2::ONE - self.pull);
        let alpha = u.max(F32Lanes::splat(low.x)).min(F32Lanes::splat(high.x));
        let beta = v.max(F32Lanes::splat(low.y)).min(F32Lanes::splat(high.y));
        let point = Vec3Lanes::splat_add(self.origin, &Vec3Lanes::scaled_splat(self.edge1, alpha))
            + Vec3Lanes::scaled_splat(self.edge2, beta);
        SurfaceLanes {
            point,
            error: Vec3Lanes::splat(self.error),
            normal: Vec3Lanes::splat(self.normal),
            u,
            v,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box's slab test in lanes is the scalar one, verdict and distance bit
    /// for bit: rays from inside, outside and on its faces, along the axes
    /// (parallel to two slabs, on their boundaries too) and off them, with a
    /// direction component so small its reciprocal overflows.
    #[test]
    fn box_tests_in_lanes_are_the_scalar_tests_bit_for_bit() {
        let aabox =
            crate::AaBox::new(Vec3::new(-1.0, -2.0, 0.5), Vec3::new(3.0, 1.0, 2.5)).unwrap();
        let origins = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(3.0, 1.0, 2.5),
            Vec3::new(-5.0, -0.5, 1.5),
            Vec3::new(1.0, 4.0, 0.5),
            Vec3::new(7.0, -3.0, -2.0),
            // On the top face: with the tiny y below, a slab distance 0·∞ = NaN.
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let directions = [
            Vec3::X,
            -Vec3::Y,
            Vec3::Z,
            Vec3::new(1.0, 0.0, -0.0),
            Vec3::new(1.0, 1e-39, 0.0),
            Vec3::new(0.3, -0.5, 0.8),
            Vec3::new(-0.6, 0.2, -0.1),
            Vec3::new(1.0, -1.0, 0.25),
        ];
        let rays: Vec<Ray> = origins
            .iter()
            .flat_map(|&o| directions.iter().map(move |&d| Ray::new(o, d)))
            .collect();
        let mut hits = 0;
        for chunk in rays.chunks(LANES) {
            let lanes = RayLanes::new(std::array::from_fn(|k| chunk[k.min(chunk.len() - 1)]));
            for t_max in [f32::INFINITY, 2.0] {
                let (hit, t) = aabox.hit_distance_lanes(&lanes, t_max);
                for (k, ray) in chunk.iter().enumerate() {
                    let scalar = aabox.hit_distance(ray, t_max);
                    let lane = (hit >> k & 1 == 1).then(|| t.to_array()[k]);
                    assert_eq!(lane.map(f32::to_bits), scalar.map(f32::to_bits), "{ray:?}");
                    hits += usize::from(scalar.is_some());
                }
            }
        }
        assert!(hits > 20, "{hits} hits");
    }
    use crate::bvh::test_support::XorShift;
    use crate::{Hit, Ray};

    fn rays_from(origin: Vec3, targets: [Vec3; LANES]) -> RayLanes {
        RayLanes::new(targets.map(|t| Ray::new(origin, t - origin)))
    }

    /// Every lane agrees with the scalar test and surface record, on random rays (origins inside
    /// and outside, grazing and tangent ones included by volume).
    #[test]
    fn lanes_agree_with_the_scalar_tests() {
        let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
        let mut hits = 0;
        for round in 0..3000 {
            let sphere = Sphere::new(rng.vec3(-3.0, 3.0), 0.2 + 2.0 * rng.unit()).unwrap();
            let wall = Parallelogram::new(
                rng.vec3(-3.0, 3.0),
                rng.vec3(-4.0, 4.0),
                rng.vec3(-4.0, 4.0),
                round % 2 == 0,
            )
            .unwrap();
            let origin = rng.vec3(-5.0, 5.0);
            let rays = rays_from(origin, std::array::from_fn(|_| rng.vec3(-3.0, 3.0)));
            let t_max = if rng.unit() < 0.5 {
                f32::INFINITY
            } else {
                2.0 * rng.unit()
            };
            let (spheres, sphere_t) = sphere.hit_distance_lanes(&rays, t_max);
            let (walls, wall_t) = wall.hit_distance_lanes(&rays, t_max);
            assert_eq!(spheres, sphere.hits_lanes(&rays, t_max));
            assert_eq!(walls, wall.hits_lanes(&rays, t_max));
            for k in 0..LANES {
                let ray = rays.lane(k);
                let lane = |bits: u32, t: F32Lanes| {
                    (bits >> k & 1 == 1).then(|| t.to_array()[k].to_bits())
                };
                let scalar = |t: Option<f32>| t.map(f32::to_bits);
                assert_eq!(
                    lane(spheres, sphere_t),
                    scalar(sphere.hit_distance(&ray, t_max))
                );
                assert_eq!(lane(walls, wall_t), scalar(wall.hit_distance(&ray, t_max)));
            }
            let sphere_points = sphere.surface_points_lanes(&rays, sphere_t, spheres);
            let wall_points = wall.surface_points_lanes(&rays, wall_t);
            for k in 0..LANES {
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                let lane = |s: &SurfaceLanes| {
                    let uv = [s.u.as_array()[k], s.v.as_array()[k]].map(f32::to_bits);
                    let point = (bits(s.point.lane(k)), bits(s.error.lane(k)));
                    (point, bits(s.normal.lane(k)), uv)
                };
                let scalar = |h: Hit| {
                    (
                        (bits(h.point), bits(h.error)),
                        bits(h.geometric_normal),
                        h.uv.to_array().map(f32::to_bits),
                    )
                };
                let ray = rays.lane(k);
                if spheres >> k & 1 == 1 {
                    let t = sphere_t.as_array()[k];
                    assert_eq!(lane(&sphere_points), scalar(sphere.surface_point(&ray, t)));
                }
                if walls >> k & 1 == 1 {
                    let t = wall_t.as_array()[k];
                    assert_eq!(lane(&wall_points), scalar(wall.surface_at(&ray, t)));
                }
            }
            hits += spheres.count_ones() + walls.count_ones();
        }
        assert!(hits > 3000, "the test rays hit something ({hits} hits)");
    }

    #[test]
    fn rays_from_a_sphere_s_centre_hit_it_and_nan_rays_nothing() {
        let sphere = Sphere::new(Vec3::ZERO, 2.0).unwrap();
        let rays = rays_from(
            Vec3::ZERO,
            std::array::from_fn(|k| Vec3::new(1.0, k as f32, 0.5)),
        );
        assert_eq!(
            sphere.hits_lanes(&rays, f32::INFINITY),
            crate::lanes::all_bits()
        );
        let nan = rays_from(Vec3::NAN, [Vec3::X; LANES]);
        assert_eq!(sphere.hits_lanes(&nan, f32::INFINITY), 0);
    }
}
