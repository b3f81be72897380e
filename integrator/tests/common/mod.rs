//! What the integrator's test files share: a diffuse material and the camera
//! they look through.

#![allow(dead_code)] // each test file uses its own part of this

use glam::{UVec2, Vec3};
use glint_camera::Camera;
use glint_lighting::PhongMaterial;
use glint_texture::Texture;

/// A Lambertian (Phong without a specular term) material of reflectance `kd`.
pub fn diffuse(kd: Vec3) -> PhongMaterial {
    PhongMaterial {
        specular: Some(Texture::Constant(Vec3::ZERO)),
        ..PhongMaterial::new(kd, 1.0)
    }
}

/// A camera at (0, 2, 4) looking at (0, 0, −2), 50° vertical field of view.
pub fn camera(resolution: UVec2) -> Camera {
    Camera::new(
        Vec3::new(0.0, 2.0, 4.0),
        Vec3::new(0.0, 0.0, -2.0),
        Vec3::Y,
        50.0,
        1.0,
        resolution,
    )
    .unwrap()
}
