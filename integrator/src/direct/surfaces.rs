//! The reflectances of a wave's surface points, looked up lane by lane, and
//! the checks a sphere's texture coordinates take in lanes.

use crate::context::SampleContext;
use crate::trace::Tracer;
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, F32Lanes, I32Lanes, Vec3Lanes};
use glint_geometry::{Sphere, SurfaceLanes, SPHERE_UV_APPROX_ERROR};
use glint_lighting::{PhongMaterial, UvTransform};
use glint_texture::{Checkerboard, TexCoord, Texture};

/// `material`'s reflectances `(kd, ks)` at each lane's uv (the lanes of
/// `hit_lanes`; the others zero), as [`PhongMaterial::reflectances_at`] gives
/// them: constants in every lane at once, textures lane by lane.
pub(crate) fn reflectances_lanes<T: Tracer>(
    material: &PhongMaterial,
    surface: &SurfaceLanes,
    hit_lanes: u32,
    ctx: &mut SampleContext<T>,
) -> (Vec3Lanes, Vec3Lanes) {
    let (u, v) = (surface.u.to_array(), surface.v.to_array());
    let uv = |k: usize| Vec2::new(u[k], v[k]);
    if ctx.detailed {
        for k in lanes::each_set(hit_lanes) {
            ctx.textures.record(material, &TexCoord::point(uv(k)));
        }
    }
    let specular = material.specular.as_ref().map(Texture::as_constant);
    match (material.diffuse.as_constant(), specular) {
        (Some(kd), None) => (Vec3Lanes::splat(kd), Vec3Lanes::splat(kd)),
        (Some(kd), Some(Some(ks))) => (Vec3Lanes::splat(kd), Vec3Lanes::splat(ks)),
        _ => {
            let (mut kd, mut ks) = (Vec3Lanes::default(), Vec3Lanes::default());
            for k in lanes::each_set(hit_lanes) {
                let (d, s) = material.reflectances_at(uv(k));
                kd.set_lane(k, d);
                ks.set_lane(k, s);
            }
            (kd, ks)
        }
    }
}

/// A sphere's point-sampled checkerboard, read from each lane's normal: its
/// check found from polar angles in lanes ([`Sphere::uv_of_normals_approx`]),
/// and from libm's (the scalar path's texture coordinates) only in lanes
/// within the approximation's error of a check's edge. The check is then
/// the scalar path's, and so are the reflectances, bit for bit.
pub(crate) struct SphereChecks<'a> {
    pub(crate) board: &'a Checkerboard,
    /// The constant specular color, `None` where it is the diffuse one.
    pub(crate) ks: Option<Vec3>,
    /// The checks per unit of the sphere's u and v, at most.
    pub(crate) density: f32,
}

impl<'a> SphereChecks<'a> {
    /// The checks of `material`, if its diffuse color is a point-sampled
    /// checkerboard, its specular color none or a constant, and its checks
    /// few enough per unit of uv (at most [`Self::MAX_DENSITY`]) that the
    /// approximation's error stays far below a check.
    pub(crate) fn of(material: &'a PhongMaterial) -> Option<Self> {
        let Texture::Checkerboard(board) = &material.diffuse else {
            return None;
        };
        let ks = match &material.specular {
            None => None,
            Some(texture) => Some(texture.as_constant()?),
        };
        let density = board.checks as f32 * material.uv_transform.scale.abs().max_element();
        (!board.analytic && density <= Self::MAX_DENSITY).then_some(Self { board, ks, density })
    }

    const MAX_DENSITY: f32 = 64.0;

    /// `material.reflectances_at` each lane's uv on a sphere whose unit
    /// normals are `normal` (lanes of `hit_lanes`; the others' are any).
    pub(crate) fn reflectances_lanes(
        &self,
        material: &PhongMaterial,
        normal: &Vec3Lanes,
        hit_lanes: u32,
    ) -> (Vec3Lanes, Vec3Lanes) {
        let (u, v) = Sphere::uv_of_normals_approx(normal);
        let UvTransform { scale, offset } = material.uv_transform;
        let n = F32Lanes::splat(self.board.checks as f32);
        let cells = |c: F32Lanes, s: f32, o: f32| (c * F32Lanes::splat(s) + F32Lanes::splat(o)) * n;
        let (x, y) = (cells(u, scale.x, offset.x), cells(v, scale.y, offset.y));
        let error = F32Lanes::splat(2.0 * self.density * SPHERE_UV_APPROX_ERROR);
        // Away from every edge by more than the error (and the rounding of
        // `c`, a few of its ulps): the exact coordinate is in the same check.
        // A clear `c` has a fraction, so its floor is an exact `i32`.
        let clear = |c: F32Lanes| {
            let margin = error + c.abs() * F32Lanes::splat(1e-6);
            let f = c - c.floor();
            lanes::bits(lanes::gt(f, margin) & lanes::lt(f, F32Lanes::ONE - margin))
        };
        let parity = (x.floor().trunc_int() ^ y.floor().trunc_int()) & I32Lanes::splat(1);
        let odd = lanes::gt(parity.round_float(), F32Lanes::ZERO);
        let [even_color, odd_color] = self.board.colors.map(Vec3Lanes::splat);
        let mut kd = Vec3Lanes::select(odd, &odd_color, &even_color);
        let mut ks = self.ks.map_or(kd, Vec3Lanes::splat);
        for k in lanes::each_set(hit_lanes & !(clear(x) & clear(y))) {
            let (uv, _, _) = Sphere::uv_of_normal(normal.lane(k));
            let (d, s) = material.reflectances_at(uv);
            kd.set_lane(k, d);
            ks.set_lane(k, s);
        }
        (kd, ks)
    }
}
