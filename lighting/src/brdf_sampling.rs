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

use crate::material::{PhongMaterial, SpecularLobe};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

impl PhongMaterial {
    /// A direction `l` drawn from the specular lobe of the surface with unit
    /// normal `n` seen from the unit direction `v`, for `u` ∈ [0, 1)²; `None`
    /// where the lobe has no sample (`v` below the surface, or a Blinn–Phong
    /// half vector facing away from `v`).
    pub fn sample_specular(&self, n: Vec3, v: Vec3, u: Vec2) -> Option<Vec3> {
        let n_dot_v = n.dot(v);
        if n_dot_v <= 0.0 {
            return None;
        }
        match self.lobe {
            SpecularLobe::Phong => {
                let r = 2.0 * n_dot_v * n - v;
                Some(power_cosine_direction(r.normalize(), self.shininess, u))
            }
            SpecularLobe::BlinnPhong => {
                let h = power_cosine_direction(n, self.shininess, u);
                let v_dot_h = v.dot(h);
                (v_dot_h > 0.0).then(|| 2.0 * v_dot_h * h - v)
            }
        }
    }

    /// The density in solid angle with which [`Self::sample_specular`] draws
    /// the unit direction `l`.
    pub fn specular_pdf(&self, n: Vec3, l: Vec3, v: Vec3) -> f32 {
        let n_dot_v = n.dot(v);
        if n_dot_v <= 0.0 {
            return 0.0;
        }
        let norm = (self.shininess + 1.0) * 0.5 * FRAC_1_PI;
        match self.lobe {
            SpecularLobe::Phong => {
                let r = (2.0 * n_dot_v * n - v).normalize();
                let cosine = r.dot(l);
                if cosine <= 0.0 {
                    0.0
                } else {
                    norm * cosine.powf(self.shininess)
                }
            }
            SpecularLobe::BlinnPhong => {
                let Some(h) = (l + v).try_normalize() else {
                    return 0.0;
                };
                let (cosine, v_dot_h) = (n.dot(h), v.dot(h));
                if cosine <= 0.0 || v_dot_h <= 0.0 {
                    0.0
                } else {
                    norm * cosine.powf(self.shininess) / (4.0 * v_dot_h)
                }
            }
        }
    }
}

/// A unit direction about the unit `axis` with density `(s + 1)/2π · cos^s θ`
/// (θ from the axis) for `u` ∈ [0, 1)².
fn power_cosine_direction(axis: Vec3, s: f32, u: Vec2) -> Vec3 {
    // 1 − u keeps cos θ = 0 out of reach (u < 1), and the peak at u = 0.
    let cos_theta = (1.0 - u.x).powf(1.0 / (s + 1.0));
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (2.0 * PI * u.y).sin_cos();
    let (t, b) = axis.any_orthonormal_pair();
    (sin_theta * cos_phi * t + sin_theta * sin_phi * b + cos_theta * axis).normalize()
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
}
