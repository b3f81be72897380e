//! Infinite planes: the ray–plane test and the planar uv mapping that tiles
//! texture to the horizon.

use crate::error_bounds::gamma;
use crate::{Hit, Ray};
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
        let denom = self.normal.dot(ray.direction);
        if denom == 0.0 || (!self.two_sided && denom > 0.0) {
            return None;
        }
        let t = self.normal.dot(self.point - ray.origin) / denom;
        (t > 0.0 && t < t_max).then_some(t)
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
