//! The lighting stage of Glint: Phong materials and the lights that illuminate them.
//!
//! # Conventions
//! - Colors and light intensities are **linear** RGB `f32`.
//! - Shading vectors are unit length and all point *away* from the surface point:
//!   `n` the normal on the viewer's side, `l` towards the light, `v` towards the viewer.
//! - Lights follow the course's model: a point light, or each sample on an area
//!   light, adds `color · (kd · n·l + ks · lobe)` with **no distance falloff**. An area
//!   light is a one-sided parallelogram that emits from its front side only.
//! - An environment's rotation about +y is in **radians** ([`EnvironmentLight::new`]).
//!
//! # Entry points
//! - [`PhongMaterial::new`] (or [`PhongMaterial::mirror`]); per shading point,
//!   [`PhongMaterial::reflectances`] gives `(kd, ks)` from the textures, then
//!   [`PhongMaterial::reflect`] the reflection of one light and
//!   [`PhongMaterial::brdf_cos`] the energy-normalised BRDF for the environment;
//!   [`PhongLanes`] reflects one light sample at each of 16 points at once.
//! - [`PointLight`], [`AreaLight::new`] (sampled with [`AreaLight::sample_point`]),
//!   both wrapped in [`Light`].
//! - [`EnvironmentLight::new`], with [`EnvironmentLight::radiance`],
//!   [`EnvironmentLight::sample`] (an [`EnvironmentSample`]) and
//!   [`EnvironmentLight::pdf`].
//! - [`distribution`]: the piecewise-constant 1D and 2D densities behind the
//!   environment's importance sampling.

mod area_light;
mod area_sampling;
mod brdf_sampling;
pub mod distribution;
mod environment_light;
mod material;
mod phong_lanes;
mod point_light;
mod shading_model;
mod sphere_light;
mod spherical_rectangle;

pub use area_light::AreaLight;
pub use area_sampling::{
    AreaLightSampler, AreaSampling, LightSample, AUTO_GEOMETRY_RATIO_FROM, AUTO_SOLID_ANGLE_FROM,
};
pub use brdf_sampling::{sample_specular_at, specular_pdf_at, Lobes};
pub use environment_light::{EnvironmentLight, EnvironmentSample, EnvironmentSampling};
pub use material::{blinn_phong_normalisation, PhongMaterial, SpecularLobe, UvTransform};
pub use phong_lanes::PhongLanes;
pub use point_light::PointLight;
pub use shading_model::ShadingModel;
pub use sphere_light::{SphereLight, SphereLightSample};
pub use spherical_rectangle::SphericalRectangle;

/// Round `i` of `rounds` of test points for lanes: x along the golden ratio's
/// sequence, y the round's, as points and as the two coordinates' lanes.
#[cfg(test)]
pub(crate) fn lane_points(
    i: usize,
    rounds: usize,
) -> (
    [glam::Vec2; glint_geometry::lanes::LANES],
    (
        glint_geometry::lanes::F32Lanes,
        glint_geometry::lanes::F32Lanes,
    ),
) {
    use glint_geometry::lanes::{self, LANES};
    let u: [glam::Vec2; LANES] = std::array::from_fn(|k| {
        let x = ((i * LANES + k) as f32 * 0.618_034).fract();
        glam::Vec2::new(x, (i as f32 + 0.5) / rounds as f32)
    });
    let us = (lanes::from_fn(|k| u[k].x), lanes::from_fn(|k| u[k].y));
    (u, us)
}

/// Every kind of light, as one enum (no virtual calls in the shading loop).
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    Point(PointLight),
    Area(AreaLight),
    /// A sphere of radiance (physical shading only).
    Sphere(SphereLight),
}

impl Light {
    /// The radiance a ray that meets the light's surface sees (a point
    /// light has none).
    pub fn emitted(&self) -> glam::Vec3 {
        match self {
            Light::Area(area) => area.color,
            Light::Sphere(sphere) => sphere.color,
            Light::Point(_) => glam::Vec3::ZERO,
        }
    }
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
