use glam::{Vec2, Vec3};

/// Everything known about the closest point where a ray meets a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit, in multiples of the ray's direction.
    pub t: f32,
    pub point: Vec3,
    /// Bound on the rounding error of `point`, per axis: the exact surface point
    /// lies within `point ± error` ([`crate::error_bounds`]).
    pub error: Vec3,
    /// Unit normal of the surface as the shape defines it (outward or front side).
    pub geometric_normal: Vec3,
    /// Unit normal used for shading; equals the geometric normal for analytic shapes.
    pub shading_normal: Vec3,
    /// Surface parameterisation at the hit.
    pub uv: Vec2,
    /// ∂p/∂u: world-space change of the point per unit of u.
    pub dpdu: Vec3,
    /// ∂p/∂v: world-space change of the point per unit of v.
    pub dpdv: Vec3,
    /// ∂n/∂u: change of the shading normal per unit of u (zero on flat shapes).
    pub dndu: Vec3,
    /// ∂n/∂v: change of the shading normal per unit of v.
    pub dndv: Vec3,
    /// Whether the ray arrived on the side the geometric normal points to.
    pub front_face: bool,
    /// Index of the object (shape or mesh) in the collection that was queried.
    pub shape: u32,
    /// Index of the triangle within a mesh; 0 for analytic shapes.
    pub primitive: u32,
}

impl Hit {
    /// The shading normal turned, if need be, to the side the ray came from,
    /// that side decided by the *geometric* normal: at a silhouette an
    /// interpolated normal can face away while the surface itself faces the ray.
    /// (Shapes keep the shading normal on the geometric normal's side.)
    pub fn facing_normal(&self, direction: Vec3) -> Vec3 {
        if self.geometric_normal.dot(direction) > 0.0 {
            -self.shading_normal
        } else {
            self.shading_normal
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_facing_side_is_decided_by_the_geometric_normal() {
        // At a silhouette the interpolated normal can face away from the viewer
        // while the triangle faces it: the surface is still seen from the front.
        let hit = Hit {
            t: 1.0,
            point: Vec3::ZERO,
            error: Vec3::ZERO,
            geometric_normal: Vec3::Z,
            shading_normal: Vec3::new(0.0, 0.9, -0.1).normalize(),
            uv: Vec2::ZERO,
            dpdu: Vec3::X,
            dpdv: Vec3::Y,
            dndu: Vec3::ZERO,
            dndv: Vec3::ZERO,
            front_face: true,
            shape: 0,
            primitive: 0,
        };
        let towards_surface = -Vec3::Z;
        assert_eq!(hit.facing_normal(towards_surface), hit.shading_normal);
        assert_eq!(hit.facing_normal(Vec3::Z), -hit.shading_normal);
    }
}
