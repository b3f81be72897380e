//! A surface point being shaded, as every shading model sees it.

use crate::trace::{Event, Shadow};
use glam::Vec3;
use glint_geometry::{Hit, Ray};
use glint_lighting::PhongMaterial;
use glint_texture::TexCoord;

/// A surface point being shaded: the hit, its material and reflectances, the
/// unit shading normal `n` (on the viewer's side), the geometric normal `ng` on the
/// same side, and the direction `v` towards the viewer.
pub(crate) struct ShadingPoint<'a> {
    pub(crate) hit: &'a Hit,
    pub(crate) material: &'a PhongMaterial,
    pub(crate) kd: Vec3,
    pub(crate) ks: Vec3,
    pub(crate) n: Vec3,
    pub(crate) ng: Vec3,
    pub(crate) v: Vec3,
    /// Whether `ks` is nonzero: without it the specular lobe is never evaluated.
    pub(crate) has_specular: bool,
}

impl<'a> ShadingPoint<'a> {
    /// The point `hit` of `material`, seen along `ray`, with its texture lookup `tc`.
    pub(crate) fn new(hit: &'a Hit, material: &'a PhongMaterial, ray: &Ray, tc: &TexCoord) -> Self {
        Self::with_reflectances(hit, material, ray, material.reflectances(tc))
    }

    /// [`Self::new`] with the reflectances `(kd, ks)` already looked up.
    pub(crate) fn with_reflectances(
        hit: &'a Hit,
        material: &'a PhongMaterial,
        ray: &Ray,
        (kd, ks): (Vec3, Vec3),
    ) -> Self {
        let n = hit.facing_normal(ray.direction);
        let ng = if hit.geometric_normal.dot(n) < 0.0 {
            -hit.geometric_normal
        } else {
            hit.geometric_normal
        };
        Self {
            hit,
            material,
            kd,
            ks,
            n,
            ng,
            v: -ray.direction.normalize(),
            has_specular: ks != Vec3::ZERO,
        }
    }

    /// Whether light from direction `l` can reach the surface at all: it must be
    /// above the *geometric* surface. With interpolated shading normals a light can
    /// be above the shading normal's horizon but below the triangle's; its shadow
    /// ray would leave into the surface and be blocked by the neighbouring
    /// triangles, leaving dark specks (the "shadow terminator" problem).
    #[inline]
    pub(crate) fn above_surface(&self, l: Vec3) -> bool {
        self.ng.dot(l) > 0.0
    }

    /// [`Self::brdf_cos`], uncounted.
    #[inline]
    pub(crate) fn f_cos(&self, l: Vec3) -> Vec3 {
        if self.has_specular {
            self.material.brdf_cos(self.kd, self.ks, self.n, l, self.v)
        } else {
            self.material.brdf_cos_diffuse(self.kd, self.n, l)
        }
    }
}

impl ShadingPoint<'_> {
    /// A light sample of the course's model at `position` (on the light), the
    /// direction to it `l`, as a tracer shows it: its shadow ray's verdict,
    /// what it adds (`value`), and the diffuse and specular parts recomputed
    /// apart (their sum is the reflection the integrator used, to rounding).
    pub(crate) fn light_sample_event(
        &self,
        (position, l): (Vec3, Vec3),
        shadow: Shadow,
        value: Vec3,
    ) -> Event {
        let n_dot_l = self.n.dot(l);
        let specular = match self.has_specular {
            true => (self.material).reflect(Vec3::ZERO, self.ks, self.n, l, self.v),
            false => Vec3::ZERO,
        };
        Event::LightSample {
            position,
            l,
            n_dot_l,
            reflection: 2.0 * n_dot_l * self.n - l,
            diffuse: self.material.reflect_diffuse(self.kd, self.n, l),
            specular,
            shadow,
            value,
        }
    }
}
