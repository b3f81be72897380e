//! The texture coordinates a shading point looks its textures up with, shared
//! by shading (module `direct`) and the AOVs (module `aov`).

use glint_geometry::{Hit, RayDifferential};
use glint_lighting::PhongMaterial;
use glint_texture::TexCoord;

/// The texture lookup at `hit`: with the pixel's footprint from the ray
/// differentials if the material filters over one, else just the point.
pub(crate) fn texture_footprint(
    material: &PhongMaterial,
    hit: &Hit,
    diff: &RayDifferential,
) -> TexCoord {
    if !material.uses_footprint() {
        return TexCoord::point(hit.uv);
    }
    let d = hit.differentials(diff);
    TexCoord {
        uv: hit.uv,
        duvdx: d.duvdx,
        duvdy: d.duvdy,
    }
}
