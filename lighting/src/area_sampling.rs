//! Sampling an area light as seen from one shading point, for physical
//! shading: by area, or uniformly in solid angle.
//!
//! Physical shading estimates the light an area light `A` of radiance `L_e`
//! sends to a point `x`,
//!
//! `L(x, v) = ∫_A f(l, v) · L_e · V(x, y) · cos θ · cos θ′ / ‖y − x‖² dA(y)`,
//!
//! with directions `l` drawn by a density `p(l)` in solid angle, as
//! `f · L_e · V · cos θ / p(l)` (pbrt-v4 §12.2, §13.3). Two densities:
//! - [`AreaSampling::Area`]: `y` uniform on the light, `p = 1/A` per unit
//!   area, `p(l) = ‖y − x‖² / (A · cos θ′)` per unit solid angle. Its variance
//!   grows where `cos θ′/‖y − x‖²` varies over the light: close to it, or seeing
//!   it edge on.
//! - [`AreaSampling::SolidAngle`]: `l` uniform over the solid angle `Ω` the
//!   light subtends, `p(l) = 1/Ω` ([`SphericalRectangle`]; Ureña, Fajardo and
//!   King 2013). The geometry term cancels; only `f · cos θ` is left to vary.
//!   For rectangles only: other parallelograms are sampled by area.

use crate::{AreaLight, SphericalRectangle};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{F32Lanes, Float, Mask, Vec3Lanes, Vector3};

/// The solid angles (steradians) sampled by solid angle; outside, by area.
/// Below about 3e-4 sr the f32 parametrisation's angles are too close together
/// to place samples evenly (measured: errors in u of 1e-3 at 3e-4 sr, 0.19 at
/// 1e-6 sr), and a light that small has little area-sampling variance anyway;
/// near 2π the light fills the hemisphere. pbrt-v4 bounds its spherical
/// sampling the same way.
const SOLID_ANGLE_RANGE: std::ops::RangeInclusive<f32> = 3e-4..=6.22;

/// From about this solid angle (steradians) on, [`AreaSampling::Auto`]
/// samples a rectangular light by solid angle. A solid-angle sample costs
/// about twice an area sample (the parametrisation's trigonometry; measured:
/// 1.5–1.8× the render time of the physical Cornell box and glossy-spheres
/// scenes), and gives no lower error where the light is small or far (the
/// same relMSE there); area sampling's extra variance grows with the
/// variation of `cos θ′/r²` over the light, that is with its solid angle.
pub const AUTO_SOLID_ANGLE_FROM: f32 = 1.0;

/// How a physical area light is sampled ([`AreaLightSampler`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AreaSampling {
    /// By solid angle where the light subtends more than
    /// [`AUTO_SOLID_ANGLE_FROM`] (estimated as `A·cos θ′/d²` from its centre),
    /// else by area.
    #[default]
    Auto,
    /// Uniformly in the solid angle the light subtends where it is a rectangle,
    /// else by area.
    SolidAngle,
    /// Uniformly by area.
    Area,
}

impl AreaSampling {
    pub const NAMES: [&'static str; 3] = ["auto", "solid-angle", "area"];

    pub fn name(self) -> &'static str {
        match self {
            AreaSampling::Auto => "auto",
            AreaSampling::SolidAngle => "solid-angle",
            AreaSampling::Area => "area",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(AreaSampling::Auto),
            "solid-angle" => Some(AreaSampling::SolidAngle),
            "area" => Some(AreaSampling::Area),
            _ => None,
        }
    }
}

/// A point drawn on an area light and the density, per unit solid angle at the
/// shading point, of the direction towards it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    pub point: Vec3,
    pub pdf: f32,
}

/// An area light's sampler for one shading point ([`AreaLight::sampler`]).
#[derive(Clone, Debug)]
pub enum AreaLightSampler<'a> {
    SolidAngle {
        light: &'a AreaLight,
        rectangle: SphericalRectangle,
    },
    Area {
        light: &'a AreaLight,
        reference: Vec3,
    },
}

impl AreaLight {
    /// The sampler of this light for the shading point `reference` by
    /// `strategy` (solid angle falls back to area for a parallelogram that is
    /// not a rectangle, a point in the light's plane, or a solid angle outside
    /// [`SOLID_ANGLE_RANGE`]).
    pub fn sampler(&self, reference: Vec3, strategy: AreaSampling) -> AreaLightSampler<'_> {
        let surface = self.surface();
        let (e1, e2) = surface.edges();
        let by_solid_angle = match strategy {
            AreaSampling::SolidAngle => true,
            AreaSampling::Area => false,
            AreaSampling::Auto => {
                let reference = Vector3::new(reference.x, reference.y, reference.z);
                self.subtends_enough(&reference)
            }
        };
        if by_solid_angle {
            if let Some(rectangle) = SphericalRectangle::new(reference, surface.origin(), e1, e2)
                .filter(|r| SOLID_ANGLE_RANGE.contains(&r.solid_angle()))
            {
                return AreaLightSampler::SolidAngle {
                    light: self,
                    rectangle,
                };
            }
        }
        AreaLightSampler::Area {
            light: self,
            reference,
        }
    }
}

impl AreaLightSampler<'_> {
    /// The point for `u` ∈ [0, 1)², and its density in solid angle (0 if the
    /// point is seen edge on).
    #[inline]
    pub fn sample(&self, u: Vec2) -> LightSample {
        match self {
            AreaLightSampler::SolidAngle { rectangle, .. } => LightSample {
                point: rectangle.sample(u),
                pdf: 1.0 / rectangle.solid_angle(),
            },
            AreaLightSampler::Area { light, reference } => {
                let point = light.sample_point(u);
                LightSample {
                    point,
                    pdf: area_pdf(light, *reference, point),
                }
            }
        }
    }

    /// The density in solid angle with which [`Self::sample`] draws the
    /// direction towards `point`, a point on the light.
    #[inline]
    pub fn pdf(&self, point: Vec3) -> f32 {
        match self {
            AreaLightSampler::SolidAngle { rectangle, .. } => 1.0 / rectangle.solid_angle(),
            AreaLightSampler::Area { light, reference } => area_pdf(light, *reference, point),
        }
    }

    pub fn light(&self) -> &AreaLight {
        match self {
            AreaLightSampler::SolidAngle { light, .. } | AreaLightSampler::Area { light, .. } => {
                light
            }
        }
    }
}

impl AreaLight {
    /// Whether [`AreaSampling::Auto`] would sample this light by solid angle
    /// from `reference`: its solid angle, estimated as `A·|cos θ′|/d²` from
    /// its centre, is at least [`AUTO_SOLID_ANGLE_FROM`]. In one lane or in
    /// many, the same answer in each.
    #[inline(always)]
    fn subtends_enough<F: Float>(&self, reference: &Vector3<F>) -> F::Mask {
        let surface = self.surface();
        let c = surface.center();
        let d = Vector3::new(
            F::splat(c.x) - reference.x,
            F::splat(c.y) - reference.y,
            F::splat(c.z) - reference.z,
        );
        let distance2 = d.dot(&d);
        let projected = F::splat(surface.area()) * d.dot_splat(surface.normal()).abs();
        projected.ge(F::splat(AUTO_SOLID_ANGLE_FROM) * distance2 * distance2.sqrt())
    }

    /// The lanes of the points `reference` (bit k for lane k) that `strategy`
    /// may sample by solid angle ([`Self::sampler`] still falls back to area
    /// where the rectangle's parametrisation does); the others it samples by
    /// area.
    #[inline]
    pub fn by_solid_angle_lanes(&self, reference: &Vec3Lanes, strategy: AreaSampling) -> u32 {
        match strategy {
            AreaSampling::SolidAngle => u32::MAX,
            AreaSampling::Area => 0,
            AreaSampling::Auto => self.subtends_enough(reference).bits(),
        }
    }

    /// [`AreaLightSampler::sample`] by area ([`AreaSampling::Area`]) for the
    /// shading points `x`, sixteen at a time: each lane's point on the light
    /// for its `(ux, uy)` and its density in solid angle, bit for bit the
    /// scalar sample's.
    #[inline]
    pub fn sample_by_area_lanes(
        &self,
        x: &Vec3Lanes,
        (ux, uy): (F32Lanes, F32Lanes),
    ) -> (Vec3Lanes, F32Lanes) {
        let y = self.sample_points(ux, uy);
        let pdf = area_pdf_of(self, x, &y);
        (y, pdf)
    }
}

/// `‖y − x‖² / (A · |cos θ′|)`: the area density `1/A` per unit solid angle at `x`.
#[inline]
fn area_pdf(light: &AreaLight, x: Vec3, y: Vec3) -> f32 {
    let at = |v: Vec3| Vector3::new(v.x, v.y, v.z);
    area_pdf_of(light, &at(x), &at(y))
}

/// [`area_pdf`] in one lane or in many, the same bits in each.
#[inline(always)]
fn area_pdf_of<F: Float>(light: &AreaLight, x: &Vector3<F>, y: &Vector3<F>) -> F {
    let d = Vector3::new(y.x - x.x, y.y - x.y, y.z - x.z);
    let distance2 = d.dot(&d);
    let cos_light = d.dot_splat(light.surface().normal()).abs() / distance2.sqrt();
    let denominator = F::splat(light.surface().area()) * cos_light;
    F::select(denominator.gt(F::ZERO), distance2 / denominator, F::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light() -> AreaLight {
        AreaLight::new(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::ONE,
        )
        .unwrap()
        .facing(-Vec3::Y)
    }

    /// Samples by area in lanes are each lane's scalar sample, bit for bit,
    /// from points near and far, oblique, and in the light's plane (density 0);
    /// so is `Auto`'s choice of solid angle.
    #[test]
    fn samples_by_area_in_lanes_are_each_lanes_sample() {
        use glint_geometry::lanes::LANES;
        let light = light();
        let points: [Vec3; LANES] = std::array::from_fn(|k| match k {
            0 => Vec3::new(0.1, 1.5, 0.2),
            1 => Vec3::new(5.0, 2.0, -1.0),
            2 => Vec3::new(0.5, 1.999, 1.0),
            3 => Vec3::new(0.3, 2.0, 0.5),
            _ => Vec3::new(
                0.7 * k as f32 - 4.0,
                -0.3 * k as f32,
                (1.3 * k as f32).sin(),
            ),
        });
        let x = Vec3Lanes::from_lanes(points);
        // Auto's choice in lanes is each lane's: a lane it leaves out is
        // sampled by area, one it keeps subtends at least the threshold.
        let solid = light.by_solid_angle_lanes(&x, AreaSampling::Auto);
        assert!(solid & 1 == 1 && solid & 2 == 0, "{solid:b}");
        for (k, &p) in points.iter().enumerate() {
            let by_area = matches!(
                light.sampler(p, AreaSampling::Auto),
                AreaLightSampler::Area { .. }
            );
            let kept = solid >> k & 1 == 1;
            assert_eq!(
                kept,
                light.subtends_enough(&Vector3::new(p.x, p.y, p.z)),
                "lane {k}"
            );
            assert!(kept || by_area, "lane {k}");
        }
        for i in 0..32 {
            let (u, us) = crate::lane_points(i, 32);
            let (y, pdf) = light.sample_by_area_lanes(&x, us);
            for k in 0..LANES {
                let s = light.sampler(points[k], AreaSampling::Area).sample(u[k]);
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                assert_eq!(bits(y.lane(k)), bits(s.point), "lane {k}, point {i}");
                assert_eq!(
                    pdf.to_array()[k].to_bits(),
                    s.pdf.to_bits(),
                    "lane {k}, point {i}"
                );
            }
        }
    }

    /// Both samplers estimate the solid angle the light subtends, `∫ 1 dω`,
    /// as the mean of `1/p`: exact for solid-angle sampling, within a small
    /// error of a stratified grid for area sampling.
    #[test]
    fn both_samplers_integrate_the_solid_angle() {
        let light = light();
        let x = Vec3::new(0.3, 0.0, -0.4);
        let exact = match light.sampler(x, AreaSampling::SolidAngle) {
            AreaLightSampler::SolidAngle { rectangle, .. } => rectangle.solid_angle(),
            AreaLightSampler::Area { .. } => panic!("a rectangle is sampled by solid angle"),
        };
        for strategy in [AreaSampling::SolidAngle, AreaSampling::Area] {
            let sampler = light.sampler(x, strategy);
            let side = 64;
            let mut sum = 0.0f64;
            for i in 0..side {
                for j in 0..side {
                    let u = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / side as f32;
                    let s = sampler.sample(u);
                    assert!((s.pdf - sampler.pdf(s.point)).abs() <= 1e-6 * s.pdf);
                    assert!((s.point.y - 2.0).abs() < 1e-5, "{strategy:?}: {}", s.point);
                    sum += 1.0 / f64::from(s.pdf);
                }
            }
            let estimate = sum / (side * side) as f64;
            assert!(
                (estimate - f64::from(exact)).abs() < 1e-4 * f64::from(exact),
                "{strategy:?}: {estimate} vs {exact}"
            );
        }
    }

    #[test]
    fn a_parallelogram_that_is_not_a_rectangle_or_is_tiny_is_sampled_by_area() {
        let skewed = AreaLight::new(Vec3::Y, Vec3::X, Vec3::new(0.5, 0.0, 1.0), Vec3::ONE).unwrap();
        assert!(matches!(
            skewed.sampler(Vec3::ZERO, AreaSampling::SolidAngle),
            AreaLightSampler::Area { .. }
        ));
        // Auto: by solid angle near the light only.
        let near = Vec3::new(0.3, 1.0, -0.4);
        assert!(matches!(
            light().sampler(near, AreaSampling::Auto),
            AreaLightSampler::SolidAngle { .. }
        ));
        assert!(matches!(
            light().sampler(near - 2.0 * Vec3::Y, AreaSampling::Auto),
            AreaLightSampler::Area { .. }
        ));
        // 1 x 2 at a distance of 100: about 2e-4 sr.
        let far = Vec3::new(0.0, -98.0, 0.0);
        assert!(matches!(
            light().sampler(far, AreaSampling::SolidAngle),
            AreaLightSampler::Area { .. }
        ));
        assert!(matches!(
            light().sampler(far + 90.0 * Vec3::Y, AreaSampling::SolidAngle),
            AreaLightSampler::SolidAngle { .. }
        ));
    }
}
