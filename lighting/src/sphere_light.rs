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
use glint_geometry::error_bounds::gamma;
use glint_geometry::lanes::{sin_cos_approx, F32Lanes, Float, Mask, Vec3Lanes, Vector3};
use glint_geometry::{RayTarget, Sphere};
use std::f32::consts::{PI, TAU};

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
        let (outside, axis, d, one_minus_cos) = self.cone_of(&Vector3::new(x.x, x.y, x.z));
        outside.then(|| (Vec3::new(axis.x, axis.y, axis.z), d, one_minus_cos))
    }

    /// [`Self::cone`] in one lane or in many, the same bits in each: whether
    /// `x` is outside the sphere (false for a NaN distance too), and the cone.
    #[inline(always)]
    fn cone_of<F: Float>(&self, x: &Vector3<F>) -> (F::Mask, Vector3<F>, F, F) {
        let c = self.surface.center();
        let to_centre = Vector3::new(
            F::splat(c.x) - x.x,
            F::splat(c.y) - x.y,
            F::splat(c.z) - x.z,
        );
        let d2 = to_centre.dot(&to_centre);
        let r = self.surface.radius();
        let r2 = F::splat(r * r);
        let sin2 = (r2 / d2).min(F::ONE);
        let cos_max = (F::ONE - sin2).max(F::ZERO).sqrt();
        let one_minus_cos = sin2 / (F::ONE + cos_max);
        let d = d2.sqrt();
        let axis = Vector3::new(to_centre.x / d, to_centre.y / d, to_centre.z / d);
        (d2.gt(r2), axis, d, one_minus_cos)
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
        let (outside, [point, error, normal], pdf) =
            self.sample_of(&Vector3::new(x.x, x.y, x.z), u.x, u.y);
        let at = |v: Vector3<f32>| Vec3::new(v.x, v.y, v.z);
        outside.then(|| SphereLightSample {
            target: RayTarget {
                point: at(point),
                error: at(error),
                normal: at(normal),
            },
            pdf,
        })
    }

    /// The lanes of the points `x` (bit k for lane k) outside the sphere,
    /// where [`Self::pdf`] is not 0: those the light lights.
    pub fn outside_lanes(&self, x: &Vec3Lanes) -> u32 {
        self.cone_of(x).0.bits()
    }

    /// [`Self::sample`] from each lane's point `x` at its `(u, v)`, each
    /// lane's bits the scalar sample's: the lanes outside the sphere (bit k
    /// for lane k; the others hold no sample), and the targets' points, error
    /// bounds and normals, and the densities.
    pub fn sample_lanes(
        &self,
        x: &Vec3Lanes,
        (u, v): (F32Lanes, F32Lanes),
    ) -> (u32, [Vec3Lanes; 3], F32Lanes) {
        let (outside, target, pdf) = self.sample_of(x, u, v);
        (outside.bits(), target, pdf)
    }

    /// [`Self::sample`] in one lane or in many: whether `x` is outside the
    /// sphere, the target's point, error bound and normal, and the density.
    /// φ is drawn as `2πv` through [`sin_cos_approx`] of `2πv − π`, negated.
    #[inline(always)]
    fn sample_of<F: Float>(&self, x: &Vector3<F>, u: F, v: F) -> (F::Mask, [Vector3<F>; 3], F) {
        let (outside, axis, d, one_minus_cos) = self.cone_of(x);
        // cos θ = 1 − u·(1 − cos θ_max), and sin²θ from 1 − cos θ without
        // cancellation: sin²θ = (1 − cos θ)(1 + cos θ).
        let one_minus_cos_theta = u * one_minus_cos;
        let cos_theta = F::ONE - one_minus_cos_theta;
        let sin2_theta = (one_minus_cos_theta * (F::splat(2.0) - one_minus_cos_theta)).max(F::ZERO);
        // Distance along the direction to the near side of the sphere.
        let r = self.surface.radius();
        let near = d * cos_theta - (F::splat(r * r) - d * d * sin2_theta).max(F::ZERO).sqrt();
        let (minus_sin_phi, minus_cos_phi) = sin_cos_approx(F::splat(TAU) * v - F::splat(PI));
        let (sin_phi, cos_phi) = (-minus_sin_phi, -minus_cos_phi);
        let (t, b) = axis.any_orthonormal_pair();
        let sin_theta = sin2_theta.sqrt();
        let (a, c) = (sin_theta * cos_phi, sin_theta * sin_phi);
        let direction = Vector3::new(
            a * t.x + c * b.x + cos_theta * axis.x,
            a * t.y + c * b.y + cos_theta * axis.y,
            a * t.z + c * b.z + cos_theta * axis.z,
        );
        let point = Vector3::new(
            x.x + near * direction.x,
            x.y + near * direction.y,
            x.z + near * direction.z,
        );
        // The normal of the point met, projected back onto the sphere; at the
        // cone's rim it faces across the direction, never away from `x`.
        let center = self.surface.center();
        let normal = point.sub_splat(center).normalize();
        let target = self.target_of(&normal);
        let pdf = F::ONE / (F::splat(TAU) * one_minus_cos);
        (outside, target, pdf)
    }

    /// The sphere's point with unit normal `n`, its error bound and `n`, as
    /// [`Sphere::target_at`] gives them, in one lane or in many.
    #[inline(always)]
    fn target_of<F: Float>(&self, n: &Vector3<F>) -> [Vector3<F>; 3] {
        let (c, r) = (self.surface.center(), self.surface.radius());
        let point = Vector3::new(
            F::splat(c.x) + F::splat(r) * n.x,
            F::splat(c.y) + F::splat(r) * n.y,
            F::splat(c.z) + F::splat(r) * n.z,
        );
        let (centre_error, r_error) = (gamma(2) * c.abs(), F::splat(gamma(6) * r));
        let error = Vector3::new(
            F::splat(centre_error.x) + n.x.abs() * r_error,
            F::splat(centre_error.y) + n.y.abs() * r_error,
            F::splat(centre_error.z) + n.z.abs() * r_error,
        );
        [point, error, *n]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples in lanes are each lane's scalar sample, bit for bit, from
    /// points near, far, on the axis and inside the sphere (no sample).
    #[test]
    fn samples_in_lanes_are_each_lanes_sample() {
        use glint_geometry::lanes::LANES;
        let light = SphereLight::new(Vec3::new(0.3, 2.0, -0.5), 0.7, Vec3::ONE).unwrap();
        let points: [Vec3; LANES] = std::array::from_fn(|k| match k {
            0 => Vec3::new(0.3, 2.1, -0.5),
            1 => Vec3::new(0.3, 0.0, -0.5),
            2 => Vec3::new(40.0, -3.0, 7.0),
            3 => Vec3::new(0.3, 2.0, 0.2000001),
            _ => Vec3::new(0.5 * k as f32 - 4.0, (0.7 * k as f32).sin(), 0.2 * k as f32),
        });
        let x = Vec3Lanes::from_lanes(points);
        for i in 0..32 {
            let (u, us) = crate::lane_points(i, 32);
            let (outside, [point, error, normal], pdf) = light.sample_lanes(&x, us);
            assert_eq!(outside & 1, 0, "inside the sphere");
            assert_eq!(light.outside_lanes(&x), outside);
            for k in 0..LANES {
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                match light.sample(points[k], u[k]) {
                    None => assert_eq!(outside >> k & 1, 0, "lane {k}"),
                    Some(s) => {
                        assert_eq!(outside >> k & 1, 1, "lane {k}");
                        assert_eq!(bits(point.lane(k)), bits(s.target.point), "lane {k}, {i}");
                        assert_eq!(bits(error.lane(k)), bits(s.target.error), "lane {k}, {i}");
                        assert_eq!(bits(normal.lane(k)), bits(s.target.normal), "lane {k}, {i}");
                        assert_eq!(pdf.to_array()[k].to_bits(), s.pdf.to_bits(), "lane {k}");
                    }
                }
            }
        }
    }

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
