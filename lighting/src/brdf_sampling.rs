//! Importance sampling of a [`PhongMaterial`]'s specular lobe, for physical
//! shading's multiple importance sampling of area lights.
//!
//! The normalised lobes of [`PhongMaterial::brdf_cos`] are powers of a cosine
//! about an axis, and are sampled exactly in proportion to that power
//! (Lafortune and Willems, "Using the modified Phong reflectance model for
//! physically based rendering", 1994; pbrt-v3 §14.1 for the Blinn–Phong
//! half-vector change of variables):
//! - Phong: `cos^s α`, α the angle between `l` and the mirror direction of the
//!   viewer `r = 2(n·v)n − v` (`(r_l·v) = (l·r)`, so the lobe is symmetric).
//!   With `cos α = ξ₁^{1/(s+1)}`, `φ = 2πξ₂` about `r`, the density in solid angle
//!   is `p(l) = (s + 1)/2π · cos^s α`.
//! - Blinn–Phong: `cos^s θ_h`, θ_h between the half vector `h` and `n`. `h` is
//!   drawn as above about `n` and `l` is `v` mirrored about `h`; since
//!   `dω_h/dω_l = 1/(4 v·h)`, `p(l) = (s + 1)/2π · cos^s θ_h / (4 v·h)`.
//!
//! A sampled direction may fall below the surface; the caller's BRDF is zero
//! there (the sample is wasted, the estimate stays unbiased).
//!
//! Sample and density are one kernel over [`Float`] for one point and for
//! lanes of points, each lane with its own lobe; their powers `ξ^{1/(s+1)}`,
//! `cos^s` and angles are polynomial ([`powf_approx`], within 2·10⁻⁷·(1 +
//! |s·log₂ cos|) relative, and [`sin_cos_approx`]), the same in both, so the
//! density stays that of the sampled directions to that precision.

use crate::material::{PhongMaterial, SpecularLobe};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{powf_approx, sin_cos_approx, Float, Mask, Vector3};
use std::f32::consts::{FRAC_1_PI, PI};

/// A specular lobe in one lane or in many: each lane's exponent `s` and
/// whether its lobe is Blinn–Phong's (else Phong's).
#[derive(Clone, Copy, Debug)]
pub struct Lobes<F: Float> {
    pub shininess: F,
    pub blinn: F::Mask,
}

impl PhongMaterial {
    /// This material's lobe, for [`sample_specular_at`] and [`specular_pdf_at`].
    pub fn lobes(&self) -> Lobes<f32> {
        Lobes {
            shininess: self.shininess,
            blinn: self.lobe == SpecularLobe::BlinnPhong,
        }
    }

    /// A direction `l` drawn from the specular lobe of the surface with unit
    /// normal `n` seen from the unit direction `v`, for `u` ∈ [0, 1)²; `None`
    /// where the lobe has no sample (`v` below the surface, or a Blinn–Phong
    /// half vector facing away from `v`).
    pub fn sample_specular(&self, n: Vec3, v: Vec3, u: Vec2) -> Option<Vec3> {
        let (l, drawn) = sample_specular_at(self.lobes(), &n.into(), &v.into(), (u.x, u.y));
        drawn.then(|| l.into())
    }

    /// The density in solid angle with which [`Self::sample_specular`] draws
    /// the unit direction `l`.
    pub fn specular_pdf(&self, n: Vec3, l: Vec3, v: Vec3) -> f32 {
        specular_pdf_at(self.lobes(), &n.into(), &l.into(), &v.into())
    }
}

/// [`PhongMaterial::sample_specular`] in one lane or in many, each lane with
/// its own lobe, normal, viewer and `(ux, uy)`: the directions, and the
/// lanes that drew one. One kernel for both, so each lane is the scalar
/// sample bit for bit.
#[inline(always)]
pub fn sample_specular_at<F: Float>(
    lobes: Lobes<F>,
    n: &Vector3<F>,
    v: &Vector3<F>,
    u: (F, F),
) -> (Vector3<F>, F::Mask) {
    let n_dot_v = n.dot(v);
    let above = n_dot_v.gt(F::ZERO);
    let s = lobes.shininess;
    let phong = || {
        let r = n.scale(F::splat(2.0) * n_dot_v) - *v;
        power_cosine_direction(&r.normalize(), s, u)
    };
    let blinn = || {
        let h = power_cosine_direction(n, s, u);
        let v_dot_h = v.dot(&h);
        (h.scale(F::splat(2.0) * v_dot_h) - *v, v_dot_h)
    };
    if !lobes.blinn.any() {
        return (phong(), above);
    }
    let (reflected, v_dot_h) = blinn();
    let facing = v_dot_h.gt(F::ZERO);
    if lobes.blinn.all() {
        return (reflected, above & facing);
    }
    let l = Vector3::select(lobes.blinn, &reflected, &phong());
    (l, above & (!lobes.blinn | facing))
}

/// [`PhongMaterial::specular_pdf`] in one lane or in many, each lane with its
/// own lobe, normal, direction `l` and viewer.
#[inline(always)]
pub fn specular_pdf_at<F: Float>(
    lobes: Lobes<F>,
    n: &Vector3<F>,
    l: &Vector3<F>,
    v: &Vector3<F>,
) -> F {
    let n_dot_v = n.dot(v);
    let s = lobes.shininess;
    let norm = (s + F::ONE) * F::splat(0.5 * FRAC_1_PI);
    let phong = || {
        let r = (n.scale(F::splat(2.0) * n_dot_v) - *v).normalize();
        let cosine = r.dot(l);
        F::select(cosine.gt(F::ZERO), norm * powf_approx(cosine, s), F::ZERO)
    };
    let blinn = || {
        let (h, some) = (*l + *v).try_normalize();
        let (cosine, v_dot_h) = (n.dot(&h), v.dot(&h));
        let value = norm * powf_approx(cosine, s) / (F::splat(4.0) * v_dot_h);
        let counted = some & cosine.gt(F::ZERO) & v_dot_h.gt(F::ZERO);
        F::select(counted, value, F::ZERO)
    };
    let pdf = F::select_with(lobes.blinn, blinn, phong);
    F::select(n_dot_v.gt(F::ZERO), pdf, F::ZERO)
}

/// A unit direction about the unit `axis` with density `(s + 1)/2π · cos^s θ`
/// (θ from the axis) for `u` ∈ [0, 1)², in one lane or in many. The powers
/// and angles are polynomial ([`powf_approx`], [`sin_cos_approx`]), the same
/// in every lane.
#[inline(always)]
fn power_cosine_direction<F: Float>(axis: &Vector3<F>, s: F, (ux, uy): (F, F)) -> Vector3<F> {
    // 1 − u keeps cos θ = 0 out of reach (u < 1), and the peak at u = 0.
    let cos_theta = powf_approx(F::ONE - ux, F::ONE / (s + F::ONE));
    let sin_theta = (F::ONE - cos_theta * cos_theta).max(F::ZERO).sqrt();
    // φ = 2π·u.y, taken into [−π, π) for the polynomial.
    let phi = F::splat(2.0 * PI) * uy;
    let phi = F::select(phi.ge(F::splat(PI)), phi - F::splat(2.0 * PI), phi);
    let (sin_phi, cos_phi) = sin_cos_approx(phi);
    let (t, b) = axis.any_orthonormal_pair();
    (t.scale(sin_theta * cos_phi) + b.scale(sin_theta * sin_phi) + axis.scale(cos_theta))
        .normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material(lobe: SpecularLobe, shininess: f32) -> PhongMaterial {
        PhongMaterial {
            lobe,
            ..PhongMaterial::new(Vec3::ONE, shininess)
        }
    }

    /// Directions over the sphere by a midpoint rule in (cos θ, φ) about `n`,
    /// each with its solid angle.
    fn sphere_quadrature(n: Vec3, rings: usize) -> impl Iterator<Item = (Vec3, f32)> {
        let (t, b) = n.any_orthonormal_pair();
        let cell = 4.0 * PI / (rings * 2 * rings) as f32;
        (0..rings).flat_map(move |i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / rings as f32;
            let r = (1.0 - z * z).sqrt();
            (0..2 * rings).map(move |j| {
                let phi = PI * (j as f32 + 0.5) / rings as f32;
                ((r * phi.cos()) * t + (r * phi.sin()) * b + z * n, cell)
            })
        })
    }

    #[test]
    fn the_pdf_integrates_to_the_lobes_share_of_the_sphere() {
        let n = Vec3::new(0.1, 1.0, 0.2).normalize();
        for lobe in [SpecularLobe::Phong, SpecularLobe::BlinnPhong] {
            for s in [1.0, 10.0, 60.0] {
                let m = material(lobe, s);
                for v in [n, Vec3::new(0.8, 0.5, -0.1).normalize()] {
                    let total: f64 = sphere_quadrature(n, 1200)
                        .map(|(l, dw)| f64::from(m.specular_pdf(n, l, v) * dw))
                        .sum();
                    // The density integrates, over the sphere (directions
                    // below the surface included), to the probability that
                    // a direction is drawn at all: 1 for Phong; for
                    // Blinn–Phong, that of a half vector facing `v`.
                    let side = 512;
                    let drawn = (0..side * side)
                        .filter(|k| {
                            let u = Vec2::new((k % side) as f32 + 0.5, (k / side) as f32 + 0.5);
                            m.sample_specular(n, v, u / side as f32).is_some()
                        })
                        .count() as f64
                        / (side * side) as f64;
                    if lobe == SpecularLobe::Phong {
                        assert_eq!(drawn, 1.0);
                    }
                    assert!(
                        (total - drawn).abs() < 5e-3,
                        "{lobe:?} s={s}: {total} vs {drawn}"
                    );
                }
            }
        }
    }

    /// The estimator `f/p` over drawn directions equals the quadrature of `f`:
    /// the sampler draws with the density `specular_pdf` states.
    #[test]
    fn sampled_directions_follow_the_stated_pdf() {
        let n = Vec3::Y;
        let v = Vec3::new(0.6, 0.8, 0.0);
        // A smooth test function over the sphere.
        let g = |l: Vec3| 1.0 + l.x * l.x + 0.5 * l.z + l.y.max(0.0);
        for lobe in [SpecularLobe::Phong, SpecularLobe::BlinnPhong] {
            for s in [2.0, 20.0] {
                let m = material(lobe, s);
                let expected: f64 = sphere_quadrature(n, 1200)
                    .map(|(l, dw)| f64::from(g(l) * m.specular_pdf(n, l, v) * dw))
                    .sum();
                let side = 256;
                let (mut sum, mut sum2, mut count) = (0.0f64, 0.0f64, 0usize);
                for i in 0..side {
                    for j in 0..side {
                        let u = Vec2::new(
                            (i as f32 + 0.5) / side as f32,
                            (j as f32 + 0.5) / side as f32,
                        );
                        let value = m.sample_specular(n, v, u).map_or(0.0, |l| {
                            assert!((l.length() - 1.0).abs() < 1e-5);
                            assert!(m.specular_pdf(n, l, v) > 0.0, "{l}");
                            f64::from(g(l))
                        });
                        sum += value;
                        sum2 += value * value;
                        count += 1;
                    }
                }
                let mean = sum / count as f64;
                let stderr = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
                // A stratified grid: well within 4 standard errors of an
                // independent estimate, plus the quadrature's own error.
                assert!(
                    (mean - expected).abs() < 4.0 * stderr + 2e-3 * expected,
                    "{lobe:?} s={s}: {mean} vs {expected} (se {stderr})"
                );
            }
        }
    }

    #[test]
    fn the_phong_lobe_peaks_at_the_mirror_direction() {
        let n = Vec3::Y;
        let v = Vec3::new(0.6, 0.8, 0.0);
        let mirror = Vec3::new(-0.6, 0.8, 0.0);
        let m = material(SpecularLobe::Phong, 50.0);
        let peak = m.sample_specular(n, v, Vec2::ZERO).unwrap();
        assert!(peak.distance(mirror) < 1e-5, "{peak}");
        assert!((m.specular_pdf(n, mirror, v) - 51.0 / (2.0 * PI)).abs() < 1e-3);
        let blinn = material(SpecularLobe::BlinnPhong, 50.0);
        let peak = blinn.sample_specular(n, v, Vec2::ZERO).unwrap();
        assert!(peak.distance(mirror) < 1e-5, "{peak}");
        // Seen from below, nothing is drawn.
        assert!(m.sample_specular(n, -v, Vec2::splat(0.3)).is_none());
        assert_eq!(m.specular_pdf(n, mirror, -v), 0.0);
    }
    /// Lobe samples and densities in lanes, each lane with its own lobe
    /// kind, exponent, normal, viewer and point, are each lane's scalar
    /// sample and density bit for bit, the viewers below the surface and the
    /// half vectors facing away included.
    #[test]
    fn lobes_in_lanes_are_each_lanes_lobe() {
        use glint_geometry::lanes::{self, Vec3Lanes, LANES};
        let unit = |a: f32, b: f32| Vec3::new(a.sin() * b.cos(), a.cos(), a.sin() * b.sin());
        let exponents = [1.0, 7.5, 16.0, 120.0, 1000.0, 0.0, 3.0];
        let materials: [PhongMaterial; LANES] = std::array::from_fn(|k| {
            let lobe = [SpecularLobe::Phong, SpecularLobe::BlinnPhong][k % 2];
            material(lobe, exponents[k % exponents.len()])
        });
        let lobes = Lobes {
            shininess: lanes::from_fn(|k| materials[k].shininess),
            blinn: lanes::from_bits(0xaaaa_aaaa),
        };
        let (mut drawn_count, mut below) = (0, 0);
        // 1024 lobes whatever the lane width.
        for round in 0..1024 / LANES {
            let at = |k: usize, c: f32| (round * LANES + k) as f32 * c;
            let n: [Vec3; LANES] =
                std::array::from_fn(|k| unit(0.3 + 0.2 * at(k, 0.37).sin(), at(k, 1.3)));
            let v: [Vec3; LANES] =
                std::array::from_fn(|k| unit(1.4 * at(k, 0.71).cos().abs(), at(k, 2.1)));
            let u: [Vec2; LANES] = std::array::from_fn(|k| {
                Vec2::new(at(k, 0.618_034).fract(), at(k, 0.754_877_7).fract())
            });
            let (nl, vl) = (Vec3Lanes::from_lanes(n), Vec3Lanes::from_lanes(v));
            let ul = (lanes::from_fn(|k| u[k].x), lanes::from_fn(|k| u[k].y));
            let (l, drawn) = sample_specular_at(lobes, &nl, &vl, ul);
            let pdf = specular_pdf_at(lobes, &nl, &l, &vl).to_array();
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            for k in 0..LANES {
                let alone = materials[k].sample_specular(n[k], v[k], u[k]);
                assert_eq!(
                    drawn.bits() >> k & 1 == 1,
                    alone.is_some(),
                    "lane {k}, round {round}"
                );
                below += usize::from(n[k].dot(v[k]) <= 0.0);
                let Some(alone) = alone else { continue };
                drawn_count += 1;
                assert_eq!(bits(l.lane(k)), bits(alone), "lane {k}, round {round}");
                let want = materials[k].specular_pdf(n[k], alone, v[k]);
                assert_eq!(pdf[k].to_bits(), want.to_bits(), "lane {k}, round {round}");
            }
        }
        assert!(
            drawn_count > 500 && below > 20,
            "{drawn_count} drawn, {below} below"
        );
    }
}
