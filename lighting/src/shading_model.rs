//! Which reflection model a scene is shaded with.

/// How lights and materials are interpreted.
///
/// | | `Phong` (the course, default) | `Physical` |
/// |---|---|---|
/// | point light `color` | a colour, no falloff | intensity `I` (W/sr per channel), falloff `1/r²` |
/// | area light `color` | a colour per light sample, no falloff | radiance `L_e` (W/(sr·m²)) of its front face |
/// | diffuse term | `kd · n·l` | Lambert's BRDF `kd/π` |
/// | specular term | `ks · lobe` | the normalised lobe, `ks·(s+2)/2π·cos^s α` (Phong) or `ks·(s+2)(s+4)/(8π(2^(−s/2)+s))·cos^s θh` (Blinn–Phong, Giesen 2009) |
/// | area lights | the average of N light samples | light and BRDF sampling with multiple importance sampling |
///
/// The environment is physically normalised in both models; a camera ray
/// that reaches a light's front face sees its `color` (its radiance) in both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ShadingModel {
    /// The course's model (assignment report, section 2.5).
    #[default]
    Phong,
    /// Radiometric units and energy-conserving BRDFs, comparable with other renderers.
    Physical,
}
