use glam::{Vec2, Vec3};
use glint_geometry::lanes::{F32Lanes, Float, Mask, Vec3Lanes, Vector3};
use glint_texture::{TexCoord, Texture};

/// A per-material change of texture coordinates: `uv' = uv · scale + offset`
/// (so `scale = [4, 4]` repeats a texture four times across a surface).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub scale: Vec2,
    pub offset: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        Self {
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        }
    }
}

impl UvTransform {
    /// `tc` in the transformed coordinates; derivatives scale with the uv.
    #[inline]
    pub fn apply(&self, tc: &TexCoord) -> TexCoord {
        TexCoord {
            uv: tc.uv * self.scale + self.offset,
            duvdx: tc.duvdx * self.scale,
            duvdy: tc.duvdy * self.scale,
        }
    }
}

/// Which specular lobe a [`PhongMaterial`] uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SpecularLobe {
    /// `max(0, r·v)^s` with `r = 2(n·l)n − l`, the mirror direction of `l` (Phong 1975).
    #[default]
    Phong,
    /// `max(0, n·h)^s` with `h = normalize(l + v)` (Blinn 1977).
    BlinnPhong,
}

/// The course's Phong material.
///
/// For one light of color `L` in direction `l` it reflects
/// `L · (kd · max(0, n·l) + ks · lobe(n, l, v))` towards `v`, and nothing at all
/// when `n·l ≤ 0` (the light is behind the surface). The ambient term
/// `ambient · kd` is added once by the integrator.
#[derive(Clone, Debug, PartialEq)]
pub struct PhongMaterial {
    /// Diffuse reflectance `kd`.
    pub diffuse: Texture,
    /// Specular reflectance `ks`; `None` means "the diffuse color", as in the course.
    pub specular: Option<Texture>,
    /// Phong exponent `s`.
    pub shininess: f32,
    pub lobe: SpecularLobe,
    /// Applied to the surface's uv before any texture lookup.
    pub uv_transform: UvTransform,
    /// Fraction of the result taken from the perfect mirror reflection:
    /// `L = (1 − r)·L_phong + r·tint·L_reflected`. 0 is plain Phong, 1 a mirror.
    pub reflectivity: f32,
    /// Color of the mirror reflection.
    pub mirror_tint: Vec3,
}

impl PhongMaterial {
    /// A material with the course's defaults: specular = diffuse, Phong lobe.
    pub fn new(diffuse: impl Into<Texture>, shininess: f32) -> Self {
        Self {
            diffuse: diffuse.into(),
            specular: None,
            shininess,
            lobe: SpecularLobe::Phong,
            uv_transform: UvTransform::default(),
            reflectivity: 0.0,
            mirror_tint: Vec3::ONE,
        }
    }

    /// A perfect mirror whose reflection is multiplied by `tint`.
    pub fn mirror(tint: Vec3) -> Self {
        Self {
            reflectivity: 1.0,
            mirror_tint: tint,
            ..Self::new(Vec3::ZERO, 1.0)
        }
    }

    /// Whether anything but the mirror term contributes.
    pub fn has_local_shading(&self) -> bool {
        self.reflectivity < 1.0
    }

    /// The BRDF times the cosine, `f(l, v)·(n·l)`, for light from a distribution of
    /// directions (the environment): Lambert's `kd/π` and the energy-normalised
    /// modified Phong lobe (Lafortune and Willems 1994), `ks·(s + 2)/2π·cos^s α`,
    /// or Blinn–Phong's `ks·`[`blinn_phong_normalisation`]`·cos^s θh`. Each lobe's
    /// albedo is `ks` at normal incidence and less elsewhere. A white diffuse
    /// surface under a white environment of radiance 1 reflects exactly 1.
    #[inline]
    pub fn brdf_cos(&self, kd: Vec3, ks: Vec3, n: Vec3, l: Vec3, v: Vec3) -> Vec3 {
        let n_dot_l = n.dot(l);
        if n_dot_l <= 0.0 {
            return Vec3::ZERO;
        }
        let norm = self.lobe_normalisation();
        (kd * std::f32::consts::FRAC_1_PI + ks * norm * self.specular_lobe(n, l, v, n_dot_l))
            * n_dot_l
    }

    /// The factor that makes the specular lobe conserve energy in
    /// [`Self::brdf_cos`]: `(s + 2)/2π` for Phong's, and
    /// [`blinn_phong_normalisation`] for Blinn–Phong's.
    #[inline]
    pub fn lobe_normalisation(&self) -> f32 {
        match self.lobe {
            SpecularLobe::Phong => (self.shininess + 2.0) / (2.0 * std::f32::consts::PI),
            SpecularLobe::BlinnPhong => blinn_phong_normalisation(self.shininess),
        }
    }

    /// [`Self::brdf_cos`] for `ks = 0`, without the specular lobe: the same value.
    #[inline]
    pub fn brdf_cos_diffuse(&self, kd: Vec3, n: Vec3, l: Vec3) -> Vec3 {
        let n_dot_l = n.dot(l);
        if n_dot_l <= 0.0 {
            return Vec3::ZERO;
        }
        kd * std::f32::consts::FRAC_1_PI * n_dot_l
    }

    /// `(kd, ks)` filtered over the footprint `tc` (surface uv and its derivatives).
    #[inline]
    pub fn reflectances(&self, tc: &TexCoord) -> (Vec3, Vec3) {
        let tc = self.uv_transform.apply(tc);
        let kd = self.diffuse.evaluate(&tc);
        let ks = match &self.specular {
            Some(t) => t.evaluate(&tc),
            None => kd,
        };
        (kd, ks)
    }

    /// [`Self::reflectances`] at the point `uv`, for a material whose textures
    /// use no footprint ([`Self::uses_footprint`] is false): the same values,
    /// without carrying the derivatives through the uv transform.
    #[inline]
    pub fn reflectances_at(&self, uv: Vec2) -> (Vec3, Vec3) {
        let uv = uv * self.uv_transform.scale + self.uv_transform.offset;
        let kd = self.diffuse.evaluate_at(uv);
        let ks = match &self.specular {
            Some(t) => t.evaluate_at(uv),
            None => kd,
        };
        (kd, ks)
    }

    /// Whether its reflectances vary over the surface (a diffuse or specular
    /// texture that is not a constant), so that shading needs each hit's
    /// texture coordinates.
    pub fn reads_uv(&self) -> bool {
        self.diffuse.as_constant().is_none()
            || self
                .specular
                .as_ref()
                .is_some_and(|t| t.as_constant().is_none())
    }

    /// Whether any of the material's textures filter over a footprint, so the
    /// integrator only computes ray differentials at hits that need them.
    pub fn uses_footprint(&self) -> bool {
        self.diffuse.uses_footprint() || self.specular.as_ref().is_some_and(Texture::uses_footprint)
    }

    /// The pyramid level the diffuse texture reads at `tc` (for the mip-level AOV).
    pub fn diffuse_mip_level(&self, tc: &TexCoord) -> f32 {
        self.diffuse.mip_level(&self.uv_transform.apply(tc))
    }

    /// The fraction of a light's color reflected towards `v`, per channel:
    /// `kd · n·l + ks · lobe`, or zero if the light is behind the surface.
    #[inline]
    pub fn reflect(&self, kd: Vec3, ks: Vec3, n: Vec3, l: Vec3, v: Vec3) -> Vec3 {
        let lobe = |n_dot_l| self.specular_lobe(n, l, v, n_dot_l);
        phong_reflection(&kd.into(), &ks.into(), true, &n.into(), &l.into(), lobe).into()
    }

    /// [`Self::reflect`] for `ks = 0`, without the specular lobe: the same value
    /// (`kd · n·l`; the lobe's `0 · lobe` adds nothing).
    #[inline]
    pub fn reflect_diffuse(&self, kd: Vec3, n: Vec3, l: Vec3) -> Vec3 {
        let (kd, n, l) = (kd.into(), n.into(), l.into());
        phong_reflection(&kd, &kd, false, &n, &l, |_| 0.0).into()
    }

    /// The scalar specular lobe for unit `n`, `l`, `v`.
    #[inline]
    pub fn specular_lobe(&self, n: Vec3, l: Vec3, v: Vec3, n_dot_l: f32) -> f32 {
        let cosine = match self.lobe {
            SpecularLobe::Phong => phong_cosine(&n.into(), &l.into(), &v.into(), n_dot_l),
            SpecularLobe::BlinnPhong => match (l + v).try_normalize() {
                Some(h) => n.dot(h),
                None => 0.0,
            },
        };
        lobe_of_cosine(cosine, |cosine| {
            if self.integral_exponent() {
                // Integral exponents (the usual case) by repeated squaring: several
                // times faster than powf, and as accurate to a few ULPs.
                powi(cosine, self.shininess as i32, 1.0)
            } else {
                cosine.powf(self.shininess)
            }
        })
    }

    /// Whether the exponent is taken by [`powi`] (integral, up to 1024) rather
    /// than `powf`.
    #[inline]
    pub(crate) fn integral_exponent(&self) -> bool {
        self.shininess.fract() == 0.0 && self.shininess <= 1024.0
    }

    /// [`Self::reflect`] (with `specular`) or [`Self::reflect_diffuse`] (without)
    /// for [`LANES`](glint_geometry::lanes::LANES) light directions `l` at once, each lane bit for bit the scalar
    /// value: the same operations in the same order, nothing fused.
    #[inline]
    pub fn reflect_lanes(
        &self,
        kd: Vec3,
        ks: Vec3,
        n: Vec3,
        l: &Vec3Lanes,
        v: Vec3,
        specular: bool,
    ) -> Vec3Lanes {
        let specular = if specular {
            F32Lanes::TRUE
        } else {
            F32Lanes::FALSE
        };
        let lobe = |n_dot_l| self.specular_lobe_lanes(n, l, v, n_dot_l);
        let (kd, ks, n) = (
            Vec3Lanes::splat(kd),
            Vec3Lanes::splat(ks),
            Vec3Lanes::splat(n),
        );
        phong_reflection(&kd, &ks, specular, &n, l, lobe)
    }

    /// [`Self::specular_lobe`] for [`LANES`](glint_geometry::lanes::LANES) directions at once.
    #[inline]
    fn specular_lobe_lanes(&self, n: Vec3, l: &Vec3Lanes, v: Vec3, n_dot_l: F32Lanes) -> F32Lanes {
        if self.lobe != SpecularLobe::Phong || !self.integral_exponent() {
            let n_dot_l = n_dot_l.as_array();
            return F32Lanes::new(std::array::from_fn(|k| {
                self.specular_lobe(n, l.lane(k), v, n_dot_l[k])
            }));
        }
        let cosine = phong_cosine(&Vec3Lanes::splat(n), l, &Vec3Lanes::splat(v), n_dot_l);
        lobe_of_cosine(cosine, |c| powi(c, self.shininess as i32, F32Lanes::ONE))
    }
}

/// Phong's reflection of a unit light from `l`, over any [`Float`]:
/// `kd·(n·l) + ks·lobe(n·l)` in the lanes of `specular`, `kd·(n·l)` in the
/// others, and zero where `n·l ≤ 0` (a NaN goes on). Phong, "Illumination for
/// computer generated pictures", CACM 18(6), 1975; the course report's eq. 3.
#[inline(always)]
pub fn phong_reflection<F: Float>(
    kd: &Vector3<F>,
    ks: &Vector3<F>,
    specular: F::Mask,
    n: &Vector3<F>,
    l: &Vector3<F>,
    lobe: impl FnOnce(F) -> F,
) -> Vector3<F> {
    let zero = Vector3::splat(Vec3::ZERO);
    let n_dot_l = n.dot(l);
    let behind = n_dot_l.le(F::ZERO);
    if behind.all() {
        return zero;
    }
    let diffuse = kd.scale(n_dot_l);
    let reflected = if specular.any() {
        let glossy = diffuse + ks.scale(lobe(n_dot_l));
        Vector3::select(specular, &glossy, &diffuse)
    } else {
        diffuse
    };
    Vector3::select(behind, &zero, &reflected)
}

/// The cosine of Phong's lobe: `r·v` with `r = (2(n·l))n − l`, the mirror
/// direction of `l` about `n`.
#[inline(always)]
pub fn phong_cosine<F: Float>(n: &Vector3<F>, l: &Vector3<F>, v: &Vector3<F>, n_dot_l: F) -> F {
    (n.scale(F::splat(2.0) * n_dot_l) - *l).dot(v)
}

/// A lobe's value from its cosine: `power(cosine)`, zero where `cosine ≤ 0`.
#[inline(always)]
pub fn lobe_of_cosine<F: Float>(cosine: F, power: impl FnOnce(F) -> F) -> F {
    let below = cosine.le(F::ZERO);
    if below.all() {
        return F::ZERO;
    }
    F::select(below, F::ZERO, power(cosine))
}

/// `base^exponent` by binary exponentiation, inlined: the multiplications of
/// `f32::powi` (the runtime's `__powisf2`, which the compiler calls out of line for
/// an exponent unknown at compile time) in the same order, so the same bits. For
/// `f32` or for lanes of them (`one` is 1 in the type).
#[inline]
pub(crate) fn powi<T>(mut base: T, exponent: i32, one: T) -> T
where
    T: Copy + std::ops::Mul<Output = T> + std::ops::Div<Output = T>,
{
    let mut n = exponent.unsigned_abs();
    let mut result = if n & 1 == 1 { base } else { one };
    while n > 1 {
        n >>= 1;
        base = base * base;
        if n & 1 == 1 {
            result = result * base;
        }
    }
    if exponent < 0 {
        one / result
    } else {
        result
    }
}

/// The factor that makes the Blinn–Phong lobe `N·cos^s θh` (times `n·l`)
/// reflect exactly all light at normal incidence,
/// `N = (s + 2)(s + 4) / (8π·(2^(−s/2) + s))` (F. Giesen, "The Blinn-Phong
/// normalization zoo", 2009). The common `(s + 8)/8π` approximates it from
/// above: its albedo reaches 1.075 at `s = 8`, so it does not conserve energy.
pub fn blinn_phong_normalisation(s: f32) -> f32 {
    (s + 2.0) * (s + 4.0) / (8.0 * std::f32::consts::PI * ((-0.5 * s).exp2() + s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_geometry::lanes::LANES;
    use glint_snapfmt::vec3;
    use glint_texture::Checkerboard;
    use std::fmt::Write;

    #[test]
    fn inline_powi_gives_the_bits_of_f32_powi() {
        for exponent in (-40..=1024).chain([i32::MAX, i32::MIN + 1]) {
            for k in 0..200 {
                let base = k as f32 / 199.0 * 1.25;
                let expected = std::hint::black_box(base).powi(std::hint::black_box(exponent));
                assert_eq!(
                    powi(base, exponent, 1.0).to_bits(),
                    expected.to_bits(),
                    "{base}^{exponent}"
                );
            }
        }
    }

    #[test]
    fn lanes_reflect_the_scalar_bits() {
        let n = Vec3::new(0.2, 0.9, -0.1).normalize();
        let v = Vec3::new(-0.3, 0.8, 0.6).normalize();
        let (kd, ks) = (Vec3::new(0.7, 0.5, 0.2), Vec3::new(0.3, 0.3, 0.9));
        // Directions around the horizon and the mirror peak, a zero and a NaN.
        let direction = |k: usize, batch: usize| match (batch, k) {
            (0, 0) => Vec3::ZERO,
            (0, 1) => Vec3::new(f32::NAN, 1.0, 0.0),
            _ => {
                let a = (k + LANES * batch) as f32 * 0.37 - 1.5;
                Vec3::new(a.sin(), a.cos(), 0.3 * a).normalize()
            }
        };
        for lobe in [SpecularLobe::Phong, SpecularLobe::BlinnPhong] {
            for shininess in [1.0, 16.0, 22.0, 120.0, 7.5, 2000.0] {
                let m = PhongMaterial {
                    lobe,
                    ..PhongMaterial::new(kd, shininess)
                };
                for batch in 0..4 {
                    let l: [Vec3; LANES] = std::array::from_fn(|k| direction(k, batch));
                    let lanes = Vec3Lanes {
                        x: F32Lanes::new(l.map(|l| l.x)),
                        y: F32Lanes::new(l.map(|l| l.y)),
                        z: F32Lanes::new(l.map(|l| l.z)),
                    };
                    for specular in [true, false] {
                        let out = m.reflect_lanes(kd, ks, n, &lanes, v, specular);
                        for (k, &l) in l.iter().enumerate() {
                            let scalar = if specular {
                                m.reflect(kd, ks, n, l, v)
                            } else {
                                m.reflect_diffuse(kd, n, l)
                            };
                            let lane = out.lane(k);
                            for axis in 0..3 {
                                assert!(
                                    lane[axis].to_bits() == scalar[axis].to_bits()
                                        || (lane[axis].is_nan() && scalar[axis].is_nan()),
                                    "{lobe:?} s={shininess} l={l} specular={specular}: \
                                     {lane} against {scalar}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn phong_values_for_fixed_geometry() {
        let n = Vec3::Y;
        let v = Vec3::new(0.0, 1.0, 1.0).normalize();
        let kd = Vec3::new(0.7, 0.5, 0.2);
        let ks = Vec3::new(0.3, 0.3, 0.3);
        let mut s = String::new();
        for lobe in [SpecularLobe::Phong, SpecularLobe::BlinnPhong] {
            for shininess in [1.0, 16.0, 120.0] {
                let m = PhongMaterial {
                    lobe,
                    shininess,
                    ..PhongMaterial::new(kd, shininess)
                };
                for deg in [-30.0f32, 0.0, 30.0, 45.0, 60.0, 89.0, 100.0] {
                    let a = deg.to_radians();
                    let l = Vec3::new(0.0, a.cos(), -a.sin());
                    let out = m.reflect(kd, ks, n, l, v);
                    writeln!(s, "{lobe:?} s={shininess} light at {deg}°: {}", vec3(out)).unwrap();
                }
            }
        }
        insta::assert_snapshot!(s);
    }

    #[test]
    fn mirror_direction_gives_the_full_specular_peak() {
        let m = PhongMaterial::new(Vec3::ZERO, 50.0);
        let n = Vec3::Y;
        let l = Vec3::new(1.0, 1.0, 0.0).normalize();
        let v = Vec3::new(-1.0, 1.0, 0.0).normalize();
        assert!((m.specular_lobe(n, l, v, n.dot(l)) - 1.0).abs() < 1e-5);
        let blinn = PhongMaterial {
            lobe: SpecularLobe::BlinnPhong,
            ..m.clone()
        };
        assert!((blinn.specular_lobe(n, l, v, n.dot(l)) - 1.0).abs() < 1e-5);
        // Away from the mirror direction the lobe falls off as cos^s.
        let v2 = Vec3::new(0.0, 1.0, 0.0);
        let expected = (45f32.to_radians().cos()).powf(50.0);
        assert!((m.specular_lobe(n, l, v2, n.dot(l)) - expected).abs() < 1e-6);
    }

    #[test]
    fn specular_defaults_to_the_diffuse_color_and_follows_textures() {
        let checker = Checkerboard::new(Vec3::X, Vec3::Y, 2);
        let m = PhongMaterial::new(checker, 10.0);
        let at = |u: f32, v: f32| TexCoord::point(Vec2::new(u, v));
        assert_eq!(m.reflectances(&at(0.1, 0.1)), (Vec3::X, Vec3::X));
        assert_eq!(m.reflectances(&at(0.6, 0.1)), (Vec3::Y, Vec3::Y));
        let m2 = PhongMaterial {
            specular: Some(Texture::Constant(Vec3::ZERO)),
            ..m.clone()
        };
        assert_eq!(m2.reflectances(&at(0.1, 0.1)), (Vec3::X, Vec3::ZERO));
        // uv scale 2 repeats the 2x2 checker: u = 0.3 lands in the second check.
        let tiled = PhongMaterial {
            uv_transform: UvTransform {
                scale: Vec2::splat(2.0),
                offset: Vec2::ZERO,
            },
            ..m.clone()
        };
        assert_eq!(tiled.reflectances(&at(0.3, 0.1)).0, Vec3::Y);
        let shifted = PhongMaterial {
            uv_transform: UvTransform {
                scale: Vec2::ONE,
                offset: Vec2::new(0.5, 0.0),
            },
            ..m
        };
        assert_eq!(shifted.reflectances(&at(0.1, 0.1)).0, Vec3::Y);
        assert!(!shifted.uses_footprint());
        // Looked up at a point without a footprint: the same values.
        for m in [&tiled, &shifted, &m2] {
            for k in 0..400 {
                let uv = Vec2::new((k % 20) as f32 * 0.071 - 0.3, (k / 20) as f32 * 0.063 - 0.2);
                assert_eq!(
                    m.reflectances_at(uv),
                    m.reflectances(&TexCoord::point(uv)),
                    "{uv}"
                );
            }
        }
    }

    #[test]
    fn light_behind_the_surface_adds_nothing() {
        let m = PhongMaterial::new(Vec3::ONE, 1.0);
        let out = m.reflect(Vec3::ONE, Vec3::ONE, Vec3::Y, -Vec3::Y, Vec3::Y);
        assert_eq!(out, Vec3::ZERO);
    }

    /// `∫ f(l, v)·(n·l) dl` over the hemisphere, by the midpoint rule in
    /// `(θ, φ)` (fine enough for `s ≤ 64`: the lobe spans many cells).
    fn albedo(m: &PhongMaterial, view_degrees: f32) -> f32 {
        let (n, a) = (Vec3::Z, view_degrees.to_radians());
        let v = Vec3::new(a.sin(), 0.0, a.cos());
        let (rows, columns) = (600, 1200);
        let (dt, dp) = (
            std::f32::consts::FRAC_PI_2 / rows as f32,
            std::f32::consts::TAU / columns as f32,
        );
        let mut sum = 0.0f64;
        for i in 0..rows {
            let t = (i as f32 + 0.5) * dt;
            for j in 0..columns {
                let p = (j as f32 + 0.5) * dp;
                let l = Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
                let f = m.brdf_cos(Vec3::ZERO, Vec3::ONE, n, l, v).x;
                sum += (f * t.sin() * dt * dp) as f64;
            }
        }
        sum as f32
    }

    #[test]
    fn normalised_lobes_reflect_at_most_all_light_and_all_of_it_head_on() {
        for lobe in [SpecularLobe::Phong, SpecularLobe::BlinnPhong] {
            for shininess in [1.0, 8.0, 64.0] {
                let m = PhongMaterial {
                    lobe,
                    ..PhongMaterial::new(Vec3::ONE, shininess)
                };
                let head_on = albedo(&m, 0.0);
                assert!(
                    (head_on - 1.0).abs() < 2e-3,
                    "{lobe:?} s={shininess}: {head_on}"
                );
                for view in [30.0, 60.0, 80.0] {
                    let a = albedo(&m, view);
                    assert!(a < head_on, "{lobe:?} s={shininess} at {view}°: {a}");
                }
            }
        }
        // The (s + 8)/8π approximation would give 1.075 at s = 8.
        let approximation = (8.0 + 8.0) / (8.0 * std::f32::consts::PI);
        assert!(approximation / blinn_phong_normalisation(8.0) > 1.07);
    }
}
