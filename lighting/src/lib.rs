//! The lighting stage of Glint: Phong materials and the lights that illuminate them.
//!
//! # Conventions
//! - Colors and light intensities are **linear** RGB `f32`.
//! - Shading vectors are unit length and all point *away* from the surface point:
//!   `n` the normal on the viewer's side, `l` towards the light, `v` towards the viewer.
//! - Lights follow the course's model: a point light, or each sample on an area
//!   light, adds `color · (kd · n·l + ks · lobe)` with **no distance falloff**. An area
//!   light is a one-sided parallelogram that emits from its front side only.

mod area_light;
pub mod distribution;
mod environment_light;
mod material;
mod point_light;

pub use area_light::AreaLight;
pub use environment_light::{EnvironmentLight, EnvironmentSample};
pub use material::{PhongMaterial, SpecularLobe, UvTransform};
pub use point_light::PointLight;

/// Every kind of light, as one enum (no virtual calls in the shading loop).
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Point(PointLight),
    Area(AreaLight),
}
