//! The texture coordinates a shading point looks its textures up with, shared
//! by shading (module `direct`) and the AOVs (module `aov`).

use crate::report_level::{pixel_height_on_surface, uv_unit_length};
use crate::scene::{Scene, TextureLevel};
use glam::Vec2;
use glint_geometry::{Hit, Ray, RayDifferential};
use glint_lighting::PhongMaterial;
use glint_texture::TexCoord;

/// The texture lookup at `hit` of `ray`, `depth` reflections deep: with the
/// pixel's footprint from the ray differentials if the material filters over
/// one, else just the point. At the report's level
/// ([`TextureLevel::Report`]), a camera ray's hit (`depth` 0; the report's
/// formula is for those) has the isotropic footprint whose trilinear level is
/// the report's, `log2(L/W)`: a side of `L/|J_T|` in the material's uv (`L`
/// the pixel's height on the surface, `|J_T|` the length one unit of that uv
/// covers), which a texture of `m` texels reads at `log2(m·L/|J_T|) =
/// log2(L/W)`.
pub(crate) fn texture_footprint(
    scene: &Scene,
    material: &PhongMaterial,
    (hit, depth): (&Hit, u32),
    ray: &Ray,
    diff: &RayDifferential,
) -> TexCoord {
    if !material.uses_footprint() {
        return TexCoord::point(hit.uv);
    }
    if scene.texture_level == TextureLevel::Report && depth == 0 {
        let side = pixel_height_on_surface(&scene.camera, ray, hit) / uv_unit_length(hit, material);
        let scale = material.uv_transform.scale;
        return TexCoord {
            uv: hit.uv,
            duvdx: Vec2::new(side / scale.x, 0.0),
            duvdy: Vec2::new(0.0, side / scale.y),
        };
    }
    let d = hit.differentials(diff);
    TexCoord {
        uv: hit.uv,
        duvdx: d.duvdx,
        duvdy: d.duvdy,
    }
}
