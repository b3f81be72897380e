//! What a render did, counted for `glint render --stats`: rays by kind, shadow
//! rays skipped and why, texture lookups by filter and MIP level, samples
//! dropped. The integrator's own counts are plain additions into its per-thread
//! [`SampleContext`](crate::SampleContext) (always kept: they cost less than the
//! timing noise); the texture histogram and the geometry crate's query counts
//! are only gathered when [`RenderSettings::stats`](crate::RenderSettings::stats)
//! asks for them.

use glint_lighting::PhongMaterial;
use glint_texture::{TexCoord, Texture};

/// The integrator's counts. Every sample drawn at a shading point either
/// sends one ray or is skipped for one reason, so each kind adds up:
/// `light_samples + point_light_samples = light_shadow_rays +
/// light_skips.total()`, `environment_samples = environment_shadow_rays +
/// environment_skips.total()` and `lobe_samples = brdf_rays +
/// lobe_skips.total()` (the tests check it on the shipped scenes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadingCounters {
    /// Shadow rays traced towards point, area and sphere lights.
    pub light_shadow_rays: u64,
    /// Shadow rays traced towards environment samples.
    pub environment_shadow_rays: u64,
    pub reflection_rays: u64,
    /// Rays that left the scene and read the environment map.
    pub environment_lookups: u64,
    /// Points sampled on area lights (and sphere lights, physical shading).
    pub light_samples: u64,
    /// Point lights evaluated at shading points: one sample each.
    pub point_light_samples: u64,
    /// Light samples (point lights' included) that sent no shadow ray, by why.
    pub light_skips: Skips,
    /// Directions drawn from the environment at shading points.
    pub environment_samples: u64,
    /// Environment samples that sent no shadow ray, by why.
    pub environment_skips: Skips,
    /// Directions drawn from specular lobes towards a light (physical
    /// shading's multiple importance sampling).
    pub lobe_samples: u64,
    /// Lobe samples that sent no ray, by why.
    pub lobe_skips: Skips,
    /// Rays towards directions drawn from a specular lobe, each checked for
    /// the light it reaches (physical shading's multiple importance sampling).
    pub brdf_rays: u64,
    /// Evaluations of a specular lobe (none for materials with ks = 0).
    pub specular_lobes: u64,
    /// Texture footprints computed from ray differentials (none for materials
    /// that filter nothing).
    pub footprints: u64,
    /// Camera samples whose radiance was NaN or infinite, left out of their pixel.
    pub nonfinite_samples: u64,
}

impl std::ops::AddAssign for ShadingCounters {
    fn add_assign(&mut self, o: Self) {
        self.light_shadow_rays += o.light_shadow_rays;
        self.environment_shadow_rays += o.environment_shadow_rays;
        self.reflection_rays += o.reflection_rays;
        self.environment_lookups += o.environment_lookups;
        self.light_samples += o.light_samples;
        self.point_light_samples += o.point_light_samples;
        self.light_skips += o.light_skips;
        self.environment_samples += o.environment_samples;
        self.environment_skips += o.environment_skips;
        self.lobe_samples += o.lobe_samples;
        self.lobe_skips += o.lobe_skips;
        self.brdf_rays += o.brdf_rays;
        self.specular_lobes += o.specular_lobes;
        self.footprints += o.footprints;
        self.nonfinite_samples += o.nonfinite_samples;
    }
}

/// Samples that sent no ray, by why: counting them shows that the skips are
/// taken (`glint render --stats`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Skips {
    /// The direction is below the surface's geometric horizon (or has no
    /// length: the sample lies on the point).
    pub below_surface: u64,
    /// The surface is behind the one-sided light, or inside a sphere light.
    pub behind_light: u64,
    /// The BRDF reflects nothing that way.
    pub zero_brdf: u64,
    /// The sample's density is zero or not finite, no direction could be
    /// drawn, or (environment) the map is black that way.
    pub zero_density: u64,
}

impl Skips {
    /// Every skipped sample.
    pub fn total(&self) -> u64 {
        self.below_surface + self.behind_light + self.zero_brdf + self.zero_density
    }
}

impl std::ops::AddAssign for Skips {
    fn add_assign(&mut self, o: Self) {
        self.below_surface += o.below_surface;
        self.behind_light += o.behind_light;
        self.zero_brdf += o.zero_brdf;
        self.zero_density += o.zero_density;
    }
}

/// How textures are looked up, in [`TextureCounters`] (in the order of
/// [`LookupKind::ALL`], which indexes its rows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LookupKind {
    Constant,
    Checkerboard,
    /// The checkerboard box-filtered exactly over the footprint.
    AnalyticCheckerboard,
    Nearest,
    Bilinear,
    Trilinear,
    Ewa,
}

impl LookupKind {
    pub const ALL: [LookupKind; 7] = [
        LookupKind::Constant,
        LookupKind::Checkerboard,
        LookupKind::AnalyticCheckerboard,
        LookupKind::Nearest,
        LookupKind::Bilinear,
        LookupKind::Trilinear,
        LookupKind::Ewa,
    ];

    pub fn name(self) -> &'static str {
        match self {
            LookupKind::Constant => "constant",
            LookupKind::Checkerboard => "checkerboard",
            LookupKind::AnalyticCheckerboard => "checkerboard (analytic)",
            LookupKind::Nearest => "nearest",
            LookupKind::Bilinear => "bilinear",
            LookupKind::Trilinear => "trilinear",
            LookupKind::Ewa => "ewa",
        }
    }

    fn of(texture: &Texture) -> Self {
        match texture {
            Texture::Constant(_) => LookupKind::Constant,
            Texture::Checkerboard(c) if c.analytic => LookupKind::AnalyticCheckerboard,
            Texture::Checkerboard(_) => LookupKind::Checkerboard,
            Texture::Image(i) => match i.filter {
                glint_texture::TextureFilter::Nearest => LookupKind::Nearest,
                glint_texture::TextureFilter::Bilinear => LookupKind::Bilinear,
                glint_texture::TextureFilter::Trilinear => LookupKind::Trilinear,
                glint_texture::TextureFilter::Ewa => LookupKind::Ewa,
            },
        }
    }
}

/// MIP levels told apart in [`TextureCounters`]; higher levels count in the last.
pub const MIP_LEVELS: usize = 16;

/// Texture lookups (diffuse and specular) by kind and by the MIP level read
/// (level ⌊l⌋ of the continuous level l; 0 for lookups without a pyramid).
/// Constant colours are not textures and are not counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TextureCounters {
    pub lookups: [[u64; MIP_LEVELS]; 7],
}

impl TextureCounters {
    /// Counts the lookups `material` makes at `tc`.
    pub fn record(&mut self, material: &PhongMaterial, tc: &TexCoord) {
        let tc = material.uv_transform.apply(tc);
        let textures = std::iter::once(&material.diffuse).chain(material.specular.as_ref());
        for texture in textures {
            if matches!(texture, Texture::Constant(_)) {
                continue;
            }
            let level = texture.mip_level(&tc);
            let bin = if level.is_finite() && level > 0.0 {
                (level as usize).min(MIP_LEVELS - 1)
            } else {
                0
            };
            self.lookups[LookupKind::of(texture) as usize][bin] += 1;
        }
    }

    /// All lookups of `kind`.
    pub fn total(&self, kind: LookupKind) -> u64 {
        self.lookups[kind as usize].iter().sum()
    }

    /// Every lookup.
    pub fn all(&self) -> u64 {
        self.lookups.iter().flatten().sum()
    }
}

impl std::ops::AddAssign for TextureCounters {
    fn add_assign(&mut self, o: Self) {
        for (a, b) in self.lookups.iter_mut().zip(o.lookups) {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
    }
}
