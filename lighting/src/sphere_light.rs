//! Spherical area lights (physical shading), sampled uniformly over the cone
//! of directions they subtend.
//!
//! A sphere of radius `R` whose centre is at distance `d > R` from the shading
//! point `x` subtends the cone of half-angle θ_max, `sin θ_max = R/d`, and its
//! solid angle is `Ω = 2π(1 − cos θ_max)`. Drawing `cos θ = 1 − ξ₁(1 − cos θ_max)`
//! and `φ = 2πξ₂` about the direction to the centre gives directions uniform
//! over that cone, `p = 1/Ω` (pbrt-v4 §6.2.3, which also maps each direction to
//! the point it meets on the sphere, as [`SphereLight::sample`] does). For a
//! small or far sphere `1 − cos θ_max` is computed as
//! `sin²θ_max / (1 + cos θ_max)`, which keeps its digits.

use glam::{Vec2, Vec3};
use glint_geometry::{RayTarget, Sphere};
use std::f32::consts::TAU;

/// A sphere emitting radiance `color` (W/(sr·m²) per channel) outwards from
/// every point of its surface.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereLight {
    surface: Sphere,
    pub color: Vec3,
}

/// A direction drawn towards a [`SphereLight`]: the point it meets (as a
/// shadow ray's target) and the density per unit solid angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLightSample {
    pub target: RayTarget,
    pub pdf: f32,
}

impl SphereLight {
    /// `None` for a radius that is not positive and finite.
    pub fn new(center: Vec3, radius: f32, color: Vec3) -> Option<Self> {
        Some(Self {
            surface: Sphere::new(center, radius)?,
            color,
        })
    }

    /// The emitting surface, for intersection with camera and lobe rays.
    pub fn surface(&self) -> &Sphere {
        &self.surface
    }

    /// The unit direction to the centre, the distance to it, and `1 − cos θ_max`
    /// of the cone the light subtends from `x`; `None` when
    /// `x` is inside the sphere or on it (no cone: the light lights nothing
    /// there).
    #[inline]
    fn cone(&self, x: Vec3) -> Option<(Vec3, f32, f32)> {
        let to_centre = self.surface.center() - x;
        let d2 = to_centre.length_squared();
        let r = self.surface.radius();
        // Also refuses a NaN distance.
        if d2.partial_cmp(&(r * r)) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let sin2 = (r * r / d2).min(1.0);
        let cos_max = (1.0 - sin2).max(0.0).sqrt();
        let one_minus_cos = sin2 / (1.0 + cos_max);
        let d = d2.sqrt();
        Some((to_centre / d, d, one_minus_cos))
    }

    /// The density per unit solid angle with which [`Self::sample`] draws
    /// any direction towards the light from `x` (0 inside it).
    #[inline]
    pub fn pdf(&self, x: Vec3) -> f32 {
        match self.cone(x) {
            Some((_, _, one_minus_cos)) => 1.0 / (TAU * one_minus_cos),
            None => 0.0,
        }
    }

    /// A direction from `x` uniform over the light's cone for `u` ∈ [0, 1)²,
    /// as the point of the sphere it meets first; `None` inside the sphere.
    pub fn sample(&self, x: Vec3, u: Vec2) -> Option<SphereLightSample> {
        let (axis, d, one_minus_cos) = self.cone(x)?;
        // cos θ = 1 − u·(1 − cos θ_max), and sin²θ from 1 − cos θ without
        // cancellation: sin²θ = (1 − cos θ)(1 + cos θ).
        let one_minus_cos_theta = u.x * one_minus_cos;
        let cos_theta = 1.0 - one_minus_cos_theta;
        let sin2_theta = (one_minus_cos_theta * (2.0 - one_minus_cos_theta)).max(0.0);
        // Distance along the direction to the near side of the sphere.
        let r = self.surface.radius();
        let near = d * cos_theta - (r * r - d * d * sin2_theta).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (TAU * u.y).sin_cos();
        let (t, b) = axis.any_orthonormal_pair();
        let sin_theta = sin2_theta.sqrt();
        let direction = sin_theta * cos_phi * t + sin_theta * sin_phi * b + cos_theta * axis;
        let point = x + near * direction;
        // The normal of the point met, projected back onto the sphere; at the
        // cone's rim it faces across the direction, never away from `x`.
        let normal = (point - self.surface.center()).normalize();
        Some(SphereLightSample {
            target: self.surface.target_at(normal),
            pdf: 1.0 / (TAU * one_minus_cos),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_lie_on_the_near_side_and_integrate_the_solid_angle() {
        let light = SphereLight::new(Vec3::new(0.3, 2.0, -0.5), 0.7, Vec3::ONE).unwrap();
        let x = Vec3::new(0.0, 0.0, 0.0);
        let d = light.surface().center().distance(x);
        let exact_solid_angle = TAU * (1.0 - (1.0 - (0.7 / d).powi(2)).sqrt());
        let side = 64;
        let mut sum = 0.0f64;
        for i in 0..side {
            for j in 0..side {
                let u = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / side as f32;
                let s = light.sample(x, u).unwrap();
                let p = s.target.point;
                assert!((p.distance(light.surface().center()) - 0.7).abs() < 1e-5);
                // The near side: the normal faces the shading point.
                assert!(s.target.normal.dot(x - p) >= -1e-3, "{p}");
                sum += 1.0 / f64::from(s.pdf);
            }
        }
        let mean = sum / (side * side) as f64;
        assert!((mean - f64::from(exact_solid_angle)).abs() < 1e-5, "{mean}");
        assert_eq!(light.pdf(x), light.sample(x, Vec2::splat(0.3)).unwrap().pdf);
    }

    #[test]
    fn a_point_inside_gets_nothing_and_a_far_sphere_keeps_its_digits() {
        let light = SphereLight::new(Vec3::ZERO, 1.0, Vec3::ONE).unwrap();
        assert!(light
            .sample(Vec3::new(0.5, 0.0, 0.0), Vec2::splat(0.5))
            .is_none());
        assert_eq!(light.pdf(Vec3::new(0.0, 0.9, 0.0)), 0.0);
        // At 1e4 radii the cone's solid angle is π·1e-8: 1 − cos θ_max would
        // round to 0 in f32.
        let far = Vec3::new(0.0, 1e4, 0.0);
        let pdf = light.pdf(far);
        let expected = 1.0 / (std::f32::consts::PI * 1e-8);
        assert!((pdf / expected - 1.0).abs() < 1e-4, "{pdf} vs {expected}");
        let s = light.sample(far, Vec2::new(0.999, 0.25)).unwrap();
        assert!((s.target.point.length() - 1.0).abs() < 1e-5);
    }
}
