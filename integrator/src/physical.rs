//! Physical shading (`shading = "physical"`): radiometric lights and
//! energy-conserving BRDFs, estimated with multiple importance sampling.
//!
//! At a surface point `x` seen from direction `v`, the reflected radiance is
//!
//! `L(x, v) = ambient·kd + Σ_point f(l, v)·cos θ·I/r² · V + Σ_area ∫_Ω f·L_e·cos θ·V dω + L_env`
//!
//! with `f = kd/π + ks·(normalised lobe)` ([`glint_lighting::PhongMaterial::brdf_cos`]), `I`
//! a point light's intensity, `L_e` an area light's radiance (front side only)
//! and `V` the visibility. The environment term is the same as in Phong
//! shading (it is physical already).
//!
//! Each area light takes N light samples, drawn by area or solid angle
//! ([`AreaSampling`](glint_lighting::AreaSampling)). On a glossy material
//! (`ks ≠ 0`) it also takes N directions drawn from the specular lobe
//! ([`glint_lighting::PhongMaterial::sample_specular`]), each traced to see whether it reaches
//! the light, and the two are combined by multiple importance sampling with
//! the power heuristic (Veach and Guibas 1995; Veach's thesis 1997, §9.2):
//! a sample drawn by technique `a` with density `p_a`, where the other gives
//! `p_b`, is weighted `p_a² / (p_a² + p_b²)` (equal sample counts). The weights
//! of the two techniques sum to 1 for every direction, so the estimate is
//! unbiased (for randomised point sets: the `grid` pattern's fixed cell
//! centres make it a fixed quadrature, as for light samples alone); light samples carry the diffuse term and broad lobes, lobe samples
//! the sharp highlight of a large light, where light samples alone are noisy.
//! On a purely diffuse material only the light is sampled (weight 1).

use crate::shading_point::ShadingPoint;
use crate::trace::{Shadow, Skip};
use crate::ShadingCounters;
use glam::Vec3;
use glint_geometry::lanes::{self, F32Lanes, Float, Vec3Lanes};

/// Diffuse points in lanes (one point in every lane, or a point per lane):
/// their positions, geometric normals and unit shading normals on the
/// viewer's side, and diffuse reflectances.
pub(crate) struct DiffusePoints<'a> {
    pub(crate) point: &'a Vec3Lanes,
    pub(crate) ng: &'a Vec3Lanes,
    pub(crate) n: &'a Vec3Lanes,
    pub(crate) kd: &'a Vec3Lanes,
}

impl DiffusePoints<'_> {
    /// The light samples at `position` with solid-angle densities `pdf`, one
    /// a lane, in the lanes `used`, short of their shadow rays: each lane's
    /// `kd/π · cos θ / p` (`ShadingPoint::light_sample_unshadowed` at a
    /// diffuse point, bit for bit) and the lanes that need a shadow ray,
    /// the others counted as skipped.
    #[inline(always)]
    pub(crate) fn light_samples(
        &self,
        position: &Vec3Lanes,
        pdf: F32Lanes,
        used: u32,
        counters: &mut ShadingCounters,
    ) -> (Vec3Lanes, u32) {
        let s = self.unshadowed_by(position, pdf, used, counters, |l| {
            // `brdf_cos_diffuse`: kd/π · n·l, zero where n·l ≤ 0.
            let n_dot_l = l.dot(self.n);
            let f = (self.kd)
                .scale(F32Lanes::splat(std::f32::consts::FRAC_1_PI))
                .scale(n_dot_l);
            let zero = Vec3Lanes::default();
            Vec3Lanes::select(lanes::le(n_dot_l, F32Lanes::ZERO), &zero, &f)
        });
        (s.f_cos.scale(F32Lanes::ONE / pdf), s.reflects)
    }

    /// The part of [`Self::light_samples`] every BRDF shares: each lane's
    /// unit direction `l` towards `position` and its `f · cos θ` by
    /// `brdf_cos`, the lanes with a density and above the surface, and of
    /// those the lanes that reflect something and need a shadow ray; the
    /// others counted as skipped, the rays counted.
    #[inline(always)]
    pub(crate) fn unshadowed_by(
        &self,
        position: &Vec3Lanes,
        pdf: F32Lanes,
        used: u32,
        counters: &mut ShadingCounters,
        brdf_cos: impl FnOnce(&Vec3Lanes) -> Vec3Lanes,
    ) -> UnshadowedLanes {
        let dense = used & lanes::bits(lanes::gt(pdf, F32Lanes::ZERO) & pdf.is_finite());
        let (l, normalized) = (*position - *self.point).try_normalize();
        let above = lanes::bits(normalized & lanes::gt(l.dot(self.ng), F32Lanes::ZERO));
        let f_cos = brdf_cos(&l);
        let reflects = dense & above & !lanes::bits(f_cos.is_zero());
        let skips = &mut counters.light_skips;
        skips.zero_density += u64::from((used & !dense).count_ones());
        skips.below_surface += u64::from((dense & !above).count_ones());
        skips.zero_brdf += u64::from((dense & above & !reflects).count_ones());
        counters.light_shadow_rays += u64::from(reflects.count_ones());
        UnshadowedLanes {
            l,
            f_cos,
            evaluated: dense & above,
            reflects,
        }
    }
}

/// Light samples in lanes short of their shadow rays
/// ([`DiffusePoints::unshadowed_by`]).
pub(crate) struct UnshadowedLanes {
    /// Each lane's unit direction towards its light point.
    pub(crate) l: Vec3Lanes,
    /// Each lane's `f · cos θ`.
    pub(crate) f_cos: Vec3Lanes,
    /// The lanes whose BRDF was evaluated: with a density, above the surface.
    pub(crate) evaluated: u32,
    /// The lanes that need a shadow ray.
    pub(crate) reflects: u32,
}

/// Veach's power heuristic (β = 2) for a sample drawn with density `a` where
/// the other technique has density `b`: `a² / (a² + b²)`, written so that
/// neither square overflows.
/// In one lane or in many.
#[inline(always)]
pub(crate) fn power_heuristic<F: Float>(a: F, b: F) -> F {
    let ratio = b / a;
    F::select(a.le(F::ZERO), F::ZERO, F::ONE / (F::ONE + ratio * ratio))
}

impl ShadingPoint<'_> {
    /// Why [`Self::reflection_towards`] gave `None` for `l`.
    pub(crate) fn skip_reason(&self, l: Vec3) -> Shadow {
        Shadow::Skipped(if self.above_surface(l) {
            Skip::ZeroBrdf
        } else {
            Skip::BehindSurface
        })
    }
}
