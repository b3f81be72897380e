use glam::Vec3;

/// A light at one point, shining equally in all directions with no falloff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    pub color: Vec3,
}
