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
use glint_geometry::lanes::{F32Lanes, Float, Mask, Vector3};

/// The solid angles (steradians) sampled by solid angle; outside, by area.
/// Below about 3e-4 sr the f32 parametrisation's angles are too close together
/// to place samples evenly (measured: errors in u of 1e-3 at 3e-4 sr, 0.19 at
/// 1e-6 sr), and a light that small has little area-sampling variance anyway;
/// near 2π the light fills the hemisphere. pbrt-v4 bounds its spherical
/// sampling the same way.
const SOLID_ANGLE_RANGE: std::ops::RangeInclusive<f32> = 3e-4..=6.22;

/// From about this solid angle (steradians) on, [`AreaSampling::Auto`]
/// samples a rectangular light by solid angle. A solid-angle sample costs
/// more than an area sample (the parametrisation's trigonometry; measured
/// on an Intel Xeon, both in lanes: 1.87× the render time of
/// `cornell-physical`, 1.26× that of `physical-glossy`, each sampled all one
/// way), and gives no lower error where `cos θ′/r²` hardly varies over the
/// light (the same relMSE there): area sampling's extra variance grows with
/// that variation, large where the light subtends much.
pub const AUTO_SOLID_ANGLE_FROM: f32 = 1.0;

/// [`AreaSampling::Auto`] also samples by solid angle where the light's
/// geometry term `|cos θ′|/r²` at one of its corners is this many times
/// that at another: seen obliquely, a light that subtends little still has
/// it vary across it. Measured against 1024-spp references at one thread
/// on an Intel Xeon (8 spp × 16 light samples, three seeds), against the
/// solid angle alone: `analytic-area-light`, a 2 × 2 light 1.5 above a
/// plane seen to the horizon, 2.5× the efficiency `1/(relMSE·time)` (4.6×
/// at 3, 4.0× always by solid angle); `cornell-physical` 0.95× (0.85× at 3,
/// 0.5× always); `physical-glossy` 0.98× (0.94× at 3, 0.73× always);
/// `physical-textured-ground` the same.
pub const AUTO_GEOMETRY_RATIO_FROM: f32 = 5.0;

/// How a physical area light is sampled ([`AreaLightSampler`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AreaSampling {
    /// By solid angle where the light subtends more than
    /// [`AUTO_SOLID_ANGLE_FROM`] (estimated as `A·cos θ′/d²` from its centre)
    /// or its `cos θ′/r²` varies over it by [`AUTO_GEOMETRY_RATIO_FROM`],
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

/// An area light's sampler for one shading point ([`AreaLight::sampler`]), or
/// for each lane's ([`AreaLight::sampler_from`]): by solid angle in the lanes
/// of `by_solid_angle`, by area in the others.
#[derive(Clone, Debug)]
pub struct AreaLightSampler<'a, F: Float = f32> {
    light: &'a AreaLight,
    reference: Vector3<F>,
    /// The rectangle as the lanes see it; `None` where no lane samples by
    /// solid angle.
    rectangle: Option<SphericalRectangle<F>>,
    by_solid_angle: F::Mask,
}

impl AreaLight {
    /// The sampler of this light for the shading point `reference` by
    /// `strategy` (solid angle falls back to area for a parallelogram that is
    /// not a rectangle, a point in the light's plane, or a solid angle outside
    /// `SOLID_ANGLE_RANGE`).
    pub fn sampler(&self, reference: Vec3, strategy: AreaSampling) -> AreaLightSampler<'_> {
        self.sampler_from(&reference.into(), strategy, true)
    }

    /// [`Self::sampler`] for each lane's shading point, each lane of `within`
    /// choosing and sampling as the scalar sampler does, to the same bits;
    /// the other lanes, whatever they hold, by area.
    #[inline(always)]
    pub fn sampler_from<F: Float>(
        &self,
        reference: &Vector3<F>,
        strategy: AreaSampling,
        within: F::Mask,
    ) -> AreaLightSampler<'_, F> {
        let asked = within
            & match strategy {
                AreaSampling::SolidAngle => F::Mask::TRUE,
                AreaSampling::Area => F::Mask::FALSE,
                AreaSampling::Auto => self.auto_by_solid_angle(reference),
            };
        let (mut rectangle, mut by_solid_angle) = (None, F::Mask::FALSE);
        if asked.any() {
            let surface = self.surface();
            let (e1, e2) = surface.edges();
            if let Some((seen, lanes)) =
                SphericalRectangle::seen_from(reference, surface.origin(), e1, e2)
            {
                let omega = seen.solid_angle();
                let (low, high) = SOLID_ANGLE_RANGE.into_inner();
                let in_range = omega.ge(F::splat(low)) & omega.le(F::splat(high));
                by_solid_angle = asked & lanes & in_range;
                rectangle = Some(seen);
            }
        }
        AreaLightSampler {
            light: self,
            reference: *reference,
            rectangle: rectangle.filter(|_| by_solid_angle.any()),
            by_solid_angle,
        }
    }
}

impl AreaLightSampler<'_> {
    /// The point for `u` ∈ [0, 1)², and its density in solid angle (0 if the
    /// point is seen edge on).
    #[inline]
    pub fn sample(&self, u: Vec2) -> LightSample {
        let (point, pdf) = self.sample_at(u.x, u.y);
        LightSample {
            point: point.into(),
            pdf,
        }
    }

    /// The density in solid angle with which [`Self::sample`] draws the
    /// direction towards `point`, a point on the light.
    #[inline]
    pub fn pdf(&self, point: Vec3) -> f32 {
        self.pdf_at(&point.into())
    }

    /// The rectangle as seen from the point, where it is sampled by solid angle.
    pub fn rectangle(&self) -> Option<&SphericalRectangle> {
        self.rectangle.as_ref()
    }
}

impl AreaLightSampler<'_, F32Lanes> {
    /// [`AreaLightSampler::pdf`] of lane `k`'s sampler for `point`.
    #[inline]
    pub fn pdf_in_lane(&self, k: usize, point: Vec3) -> f32 {
        match &self.rectangle {
            Some(rectangle) if self.by_solid_angle.bits() >> k & 1 == 1 => {
                1.0 / rectangle.solid_angle().to_array()[k]
            }
            _ => area_pdf(self.light, self.reference.lane(k), point),
        }
    }
}

impl<F: Float> AreaLightSampler<'_, F> {
    /// Each lane's point for `(ux, uy)` ∈ [0, 1)², and its density in solid
    /// angle: uniform in the solid angle the lanes of `by_solid_angle` see,
    /// uniform in area in the others.
    #[inline(always)]
    pub fn sample_at(&self, ux: F, uy: F) -> (Vector3<F>, F) {
        let by_area = || {
            let point = self.light.sample_points(ux, uy);
            let pdf = area_pdf_of(self.light, &self.reference, &point);
            (point, pdf)
        };
        let Some(rectangle) = &self.rectangle else {
            return by_area();
        };
        let by_solid_angle = (
            rectangle.sample_at(ux, uy),
            F::ONE / rectangle.solid_angle(),
        );
        if self.by_solid_angle.all() {
            return by_solid_angle;
        }
        let (point, pdf) = by_area();
        let mask = self.by_solid_angle;
        (
            Vector3::select(mask, &by_solid_angle.0, &point),
            F::select(mask, by_solid_angle.1, pdf),
        )
    }

    /// The density in solid angle with which [`Self::sample_at`] draws the
    /// direction towards each lane's `point`, a point on the light.
    #[inline(always)]
    pub fn pdf_at(&self, point: &Vector3<F>) -> F {
        let by_area = || area_pdf_of(self.light, &self.reference, point);
        match &self.rectangle {
            Some(rectangle) => F::select_with(
                self.by_solid_angle,
                || F::ONE / rectangle.solid_angle(),
                by_area,
            ),
            None => by_area(),
        }
    }

    /// The lanes sampled by solid angle.
    pub fn by_solid_angle(&self) -> F::Mask {
        self.by_solid_angle
    }
}

impl AreaLight {
    /// Whether [`AreaSampling::Auto`] would sample this light by solid angle
    /// from `reference`: its solid angle, estimated as `A·|cos θ′|/d²` from
    /// its centre, is at least [`AUTO_SOLID_ANGLE_FROM`], or `|cos θ′|/r²`
    /// at one corner is [`AUTO_GEOMETRY_RATIO_FROM`] times that at another.
    /// In one lane or in many, the same answer in each (NaN, from a point
    /// on a corner, compares false in both).
    #[inline(always)]
    fn auto_by_solid_angle<F: Float>(&self, reference: &Vector3<F>) -> F::Mask {
        let surface = self.surface();
        let d = Vector3::splat_sub(surface.center(), reference);
        let distance2 = d.dot(&d);
        let projected = F::splat(surface.area()) * d.dot_splat(surface.normal()).abs();
        let subtends = projected.ge(F::splat(AUTO_SOLID_ANGLE_FROM) * distance2 * distance2.sqrt());
        let (o, (e1, e2)) = (surface.origin(), surface.edges());
        let geometry = |corner: Vec3| {
            let d = Vector3::splat_sub(corner, reference);
            let r2 = d.dot(&d);
            d.dot_splat(surface.normal()).abs() / (r2 * r2.sqrt())
        };
        let g = [o, o + e1, o + e2, o + e1 + e2].map(geometry);
        // `a > b ? a : b` and its mirror: the same choice at every width.
        let max = |a: F, b: F| F::select(a.gt(b), a, b);
        let min = |a: F, b: F| F::select(a.lt(b), a, b);
        let most = max(max(g[0], g[1]), max(g[2], g[3]));
        let least = min(min(g[0], g[1]), min(g[2], g[3]));
        subtends | most.ge(F::splat(AUTO_GEOMETRY_RATIO_FROM) * least)
    }
}

/// `‖y − x‖² / (A · |cos θ′|)`: the area density `1/A` per unit solid angle at `x`.
#[inline]
fn area_pdf(light: &AreaLight, x: Vec3, y: Vec3) -> f32 {
    area_pdf_of(light, &x.into(), &y.into())
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

    /// Samples in lanes are each lane's scalar sample, bit for bit, by every
    /// strategy, from points near and far, oblique, behind the light, and in
    /// its plane (density 0; no solid angle), lanes by solid angle and by
    /// area side by side; so are the densities of points on the light.
    #[test]
    fn samples_in_lanes_are_each_lanes_sample() {
        use glint_geometry::lanes::{Vec3Lanes, LANES};
        let light = light();
        let points: [Vec3; LANES] = std::array::from_fn(|k| match k {
            0 => Vec3::new(0.1, 1.5, 0.2),
            1 => Vec3::new(5.0, 2.0, -1.0),
            2 => Vec3::new(0.5, 1.999, 1.0),
            3 => Vec3::new(0.3, 2.0, 0.5),
            4 => Vec3::new(0.0, -98.0, 0.0),
            5 => Vec3::new(0.2, 2.5, 0.9),
            _ => Vec3::new(
                0.7 * k as f32 - 4.0,
                -0.3 * k as f32,
                (1.3 * k as f32).sin(),
            ),
        });
        let x = Vec3Lanes::from_lanes(points);
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        let mut kinds = [0; 2];
        for strategy in [
            AreaSampling::Auto,
            AreaSampling::SolidAngle,
            AreaSampling::Area,
        ] {
            let lanes = light.sampler_from(&x, strategy, F32Lanes::TRUE);
            let scalar = points.map(|p| light.sampler(p, strategy));
            for (k, sampler) in scalar.iter().enumerate() {
                let solid = sampler.rectangle().is_some();
                assert_eq!(
                    solid,
                    lanes.by_solid_angle().bits() >> k & 1 == 1,
                    "lane {k}"
                );
                kinds[usize::from(solid)] += 1;
            }
            for i in 0..32 {
                let (u, (ux, uy)) = crate::lane_points(i, 32);
                let (y, pdf) = lanes.sample_at(ux, uy);
                for (k, sampler) in scalar.iter().enumerate() {
                    let s = sampler.sample(u[k]);
                    let at = format!("{strategy:?}, lane {k}, point {i}");
                    assert_eq!(bits(y.lane(k)), bits(s.point), "{at}");
                    assert_eq!(pdf.to_array()[k].to_bits(), s.pdf.to_bits(), "{at}");
                    let (p, on_light) = (sampler.pdf(s.point), lanes.pdf_in_lane(k, s.point));
                    assert_eq!(on_light.to_bits(), p.to_bits(), "{at}");
                }
                let pdfs = lanes.pdf_at(&y).to_array();
                for (k, sampler) in scalar.iter().enumerate() {
                    let want = sampler.pdf(y.lane(k)).to_bits();
                    assert_eq!(pdfs[k].to_bits(), want, "{strategy:?}, lane {k}");
                }
            }
        }
        // Each kind of lane is there: by solid angle and by area.
        assert!(kinds[0] > 0 && kinds[1] > 0, "{kinds:?}");
    }

    /// Both samplers estimate the solid angle the light subtends, `∫ 1 dω`,
    /// as the mean of `1/p`: exact for solid-angle sampling, within a small
    /// error of a stratified grid for area sampling.
    #[test]
    fn both_samplers_integrate_the_solid_angle() {
        let light = light();
        let x = Vec3::new(0.3, 0.0, -0.4);
        let sampler = light.sampler(x, AreaSampling::SolidAngle);
        let rectangle = sampler.rectangle();
        let exact = rectangle.expect("a rectangle is sampled by solid angle");
        let exact = exact.solid_angle();
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
        assert!(skewed
            .sampler(Vec3::ZERO, AreaSampling::SolidAngle)
            .rectangle()
            .is_none());
        // Auto: by solid angle near the light only.
        let near = Vec3::new(0.3, 1.0, -0.4);
        assert!(light()
            .sampler(near, AreaSampling::Auto)
            .rectangle()
            .is_some());
        assert!(light()
            .sampler(near - 2.0 * Vec3::Y, AreaSampling::Auto)
            .rectangle()
            .is_none());
        // 1 x 2 at a distance of 100: about 2e-4 sr.
        let far = Vec3::new(0.0, -98.0, 0.0);
        assert!(light()
            .sampler(far, AreaSampling::SolidAngle)
            .rectangle()
            .is_none());
        assert!(light()
            .sampler(far + 90.0 * Vec3::Y, AreaSampling::SolidAngle)
            .rectangle()
            .is_some());
    }
    /// `auto` samples by solid angle a light seen obliquely, though it
    /// subtends little (its `cos θ′/r²` varies 15-fold over it), and by area
    /// one far below it; the lanes choose the same.
    #[test]
    fn auto_samples_a_light_seen_obliquely_by_solid_angle() {
        use glint_geometry::lanes::{Vec3Lanes, LANES};
        let oblique = Vec3::new(0.7, 1.95, 2.5);
        let below = Vec3::new(0.0, -10.0, 0.0);
        let light = light();
        let sampler = light.sampler(oblique, AreaSampling::Auto);
        let omega = sampler.rectangle().map(|r| r.solid_angle());
        assert!(omega.is_some_and(|omega| omega < 0.01), "{omega:?}");
        assert!(light
            .sampler(below, AreaSampling::Auto)
            .rectangle()
            .is_none());
        let points = Vec3Lanes::from_lanes(std::array::from_fn(|k| [oblique, below][k % 2]));
        let lanes = light.sampler_from(&points, AreaSampling::Auto, F32Lanes::TRUE);
        let every_other = (0..LANES).step_by(2).fold(0u32, |bits, k| bits | 1 << k);
        assert_eq!(lanes.by_solid_angle().bits(), every_other);
    }
}
