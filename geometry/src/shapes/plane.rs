//! Infinite planes: the ray–plane test and the planar uv mapping that tiles
//! texture to the horizon.

use super::SurfaceLanes;
use crate::error_bounds::gamma;
use crate::lanes::{F32Lanes, Float, Mask, Vec3Lanes, Vector3};
use crate::{Hit, Ray, RayLanes};
use glam::{Vec2, Vec3};

/// An infinite plane through `point` with unit `normal` (its front side).
///
/// Planar uv: `u = (p − point)·tangent / tile`, `v = (p − point)·bitangent / tile`,
/// so one unit of uv spans `tile` world units, with the orthonormal tangent frame of
/// Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017). uv is not
/// wrapped to [0, 1]: textures repeat across the plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    point: Vec3,
    normal: Vec3,
    tangent: Vec3,
    bitangent: Vec3,
    tile: f32,
    two_sided: bool,
}

impl Plane {
    /// A plane with one uv unit per world unit. Returns `None` if `normal` is zero
    /// or not finite.
    pub fn new(point: Vec3, normal: Vec3, two_sided: bool) -> Option<Self> {
        let normal = normal.try_normalize()?;
        let (tangent, bitangent) = normal.any_orthonormal_pair();
        Some(Self {
            point,
            normal,
            tangent,
            bitangent,
            tile: 1.0,
            two_sided,
        })
    }

    /// The same plane with one uv unit spanning `tile` world units. `None` unless
    /// `tile` is positive and finite.
    pub fn with_tile_size(self, tile: f32) -> Option<Self> {
        (tile > 0.0 && tile.is_finite()).then_some(Self { tile, ..self })
    }

    /// A point on the plane.
    pub fn point(&self) -> Vec3 {
        self.point
    }
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// Whether `from` and the four `corners` lie strictly on one side of the
    /// plane, each more than `margin` from it: then no segment from within
    /// `margin` of `from` to a point of their convex hull crosses it.
    pub fn separates_none(&self, from: Vec3, corners: &[Vec3; 4], margin: f32) -> bool {
        let distance = |x: Vec3| self.normal.dot(x - self.point);
        let d = distance(from);
        let same_side = |c: &Vec3| {
            let dc = distance(*c);
            (d > 0.0 && dc > margin) || (d < 0.0 && dc < -margin)
        };
        d.abs() > margin && corners.iter().all(same_side)
    }

    pub fn hit_distance(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let (hit, t) = self.hits(&ray.origin.into(), &ray.direction.into(), t_max);
        hit.then_some(t)
    }

    /// [`Self::hit_distance`] for each lane's ray: the lanes that hit (bit k
    /// for lane k) and their distances.
    #[inline]
    pub fn hit_distance_lanes(&self, rays: &RayLanes, t_max: f32) -> (u32, F32Lanes) {
        let (hit, t) = self.hits(&rays.origin, &rays.direction, F32Lanes::splat(t_max));
        (hit.bits(), t)
    }

    /// The one kernel of both, for one ray or lanes of them: `t = n·(p − o) /
    /// n·d` where the ray meets the plane's front (either side if two-sided)
    /// in (0, `t_max`).
    #[inline(always)]
    fn hits<F: Float>(
        &self,
        origin: &Vector3<F>,
        direction: &Vector3<F>,
        t_max: F,
    ) -> (F::Mask, F) {
        let denom = direction.dot_splat(self.normal);
        let facing = if self.two_sided {
            F::Mask::TRUE
        } else {
            !denom.gt(F::ZERO)
        };
        let valid = !denom.eq(F::ZERO) & facing;
        if !valid.any() {
            return (F::Mask::FALSE, F::ZERO);
        }
        let t = Vector3::splat_sub(self.point, origin).dot_splat(self.normal) / denom;
        (valid & t.in_ray_range(t_max), t)
    }

    pub fn surface_at(&self, ray: &Ray, t: f32) -> Hit {
        let hit_point = ray.at(t);
        let local = hit_point - self.point;
        // Project onto the plane to remove the error of o + t·d along the normal.
        let point = hit_point - self.normal.dot(local) * self.normal;
        Hit {
            t,
            point,
            error: gamma(5) * (point.abs() + self.point.abs()),
            geometric_normal: self.normal,
            shading_normal: self.normal,
            uv: Vec2::new(local.dot(self.tangent), local.dot(self.bitangent)) / self.tile,
            dpdu: self.tangent * self.tile,
            dpdv: self.bitangent * self.tile,
            dndu: Vec3::ZERO,
            dndv: Vec3::ZERO,
            front_face: self.normal.dot(ray.direction) < 0.0,
            shape: 0,
            primitive: 0,
        }
    }
}

impl Plane {
    /// [`Self::surface_at`] of each lane at its distance `t`, without the
    /// derivatives (the tangents, the same in every lane).
    #[inline]
    pub fn surface_points_lanes(&self, rays: &RayLanes, t: F32Lanes) -> SurfaceLanes {
        let hit_point = rays.at(t);
        let local = hit_point.sub_splat(self.point);
        // Projected onto the plane, as `surface_at` removes the error along
        // the normal.
        let point = hit_point - Vec3Lanes::scaled_splat(self.normal, local.dot_splat(self.normal));
        let error =
            (point.abs() + Vec3Lanes::splat(self.point.abs())).scale(F32Lanes::splat(gamma(5)));
        let tile = F32Lanes::splat(self.tile);
        SurfaceLanes {
            point,
            error,
            normal: Vec3Lanes::splat(self.normal),
            u: local.dot_splat(self.tangent) / tile,
            v: local.dot_splat(self.bitangent) / tile,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::LANES;

    /// Every lane's surface point, error bound, normal and uv are the scalar
    /// `surface_at`'s, bit for bit, on tilted and tiled planes, from rays
    /// near and far, steep and grazing.
    #[test]
    fn surface_points_in_lanes_are_the_scalar_ones() {
        let planes = [
            Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(),
            Plane::new(Vec3::new(1.5, -2.0, 0.3), Vec3::new(0.3, 1.0, -0.2), true)
                .unwrap()
                .with_tile_size(2.5)
                .unwrap(),
        ];
        for plane in planes {
            let origin = plane.point + 3.0 * plane.normal + Vec3::new(0.4, 0.1, -0.2);
            let rays: [Ray; LANES] = std::array::from_fn(|k| {
                let a = 0.7 * k as f32;
                let spread = Vec3::new(a.cos(), 0.0, a.sin()) * (0.2 + k as f32);
                Ray::new(origin, spread - plane.normal)
            });
            let t: [f32; LANES] = std::array::from_fn(|k| {
                let ray = &rays[k];
                (plane.point - ray.origin).dot(plane.normal) / ray.direction.dot(plane.normal)
            });
            let lanes = plane.surface_points_lanes(&RayLanes::new(rays), F32Lanes::new(t));
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for k in 0..LANES {
                let hit = plane.surface_at(&rays[k], t[k]);
                assert_eq!(bits(lanes.point.lane(k)), bits(hit.point), "lane {k}");
                assert_eq!(bits(lanes.error.lane(k)), bits(hit.error), "lane {k}");
                assert_eq!(bits(lanes.normal.lane(k)), bits(hit.geometric_normal));
                let uv = Vec2::new(lanes.u.to_array()[k], lanes.v.to_array()[k]);
                assert_eq!(
                    uv.to_array().map(f32::to_bits),
                    hit.uv.to_array().map(f32::to_bits)
                );
            }
        }
    }
}
