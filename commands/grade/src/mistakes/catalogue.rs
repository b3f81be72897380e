//! The classic mistakes, each with the stage it belongs to and how Glint
//! renders it: a change to the scene (rendered as any scene is), a stage
//! swapped in the one-ray reference integrator, or a change to what the
//! file stores (applied to the references).

use super::edit;
use glint_integrator::mistakes::Mistake as Swap;
use serde::Serialize;

/// A classic mistake of a student's ray tracer.
#[derive(Clone, Copy, Debug)]
pub struct Mistake {
    /// Its name in reports and JSON (`light-centre`).
    pub id: &'static str,
    /// What the tracer does wrong, in one line.
    pub description: &'static str,
    pub stage: Stage,
    pub how: How,
}

impl Mistake {
    /// Whether how much of it shows depends on the tracer's arithmetic, not
    /// on the scene alone: how many shadow rays without an offset hit their
    /// own surface depends on how the hit point and the roots are rounded
    /// (measured on the course's spheres: Glint's `f32` blocks 20–35 % of
    /// the direct light, a tracer in doubles 25–60 %, in the same places).
    /// Its render is then fitted to the submission by an amount per object
    /// ([`super::scaled_per_object`]).
    pub fn amount_varies(&self) -> bool {
        matches!(self.how, How::Integrator(Swap::NoShadowOffset))
    }
}

/// The stage of the pipeline a mistake spoils.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    Camera,
    Intersection,
    Texture,
    Lighting,
    Shading,
    Environment,
    Film,
}

impl Stage {
    pub fn name(self) -> &'static str {
        match self {
            Stage::Camera => "camera",
            Stage::Intersection => "intersection",
            Stage::Texture => "texture",
            Stage::Lighting => "lighting",
            Stage::Shading => "shading",
            Stage::Environment => "environment",
            Stage::Film => "film",
        }
    }
}

/// How Glint renders a mistake.
#[derive(Clone, Copy, Debug)]
pub enum How {
    /// The scene file changed ([`edit`]), rendered as Glint renders any
    /// scene: the mistake is the correct render of another scene.
    Scene(edit::Edit),
    /// A change to the scene's lights that a student makes only in how
    /// light reaches surfaces: rendered as [`How::Scene`], with the pixels
    /// that see a light (and their neighbours) kept from the correct render.
    Lights(edit::Edit),
    /// A stage swapped for the wrong one in the one-ray reference
    /// integrator ([`glint_integrator::mistakes`]), which renders it.
    Integrator(Swap),
    /// What the file stores, changed after rendering.
    Film(FilmMistake),
    /// The expected image stays as it is, only the noise changes: no test
    /// of the mean can tell it.
    NoiseOnly,
}

impl How {
    /// The scene edit that renders it, for a mistake rendered as a scene.
    pub fn edit(&self) -> Option<super::edit::Edit> {
        match self {
            How::Scene(edit) | How::Lights(edit) => Some(*edit),
            _ => None,
        }
    }

    /// The stage the one-ray integrator swaps, for a mistake it renders.
    pub fn swap(&self) -> Option<Swap> {
        match self {
            How::Integrator(swap) => Some(*swap),
            _ => None,
        }
    }

    /// The word `glint grade --mistakes` shows for it.
    pub fn rendered_as(&self) -> &'static str {
        match self {
            How::Scene(_) => "scene",
            How::Lights(_) => "lights",
            How::Integrator(_) => "integrator",
            How::Film(_) => "film",
            How::NoiseOnly => "noise only",
        }
    }
}

/// A mistake in writing the film to its file, or in its pixel order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilmMistake {
    /// Rows upside down.
    FlipVertical,
    /// Linear values written as 8-bit codes.
    NoSrgb,
    /// `c^(1/2.2)` in place of the sRGB curve.
    Gamma22,
}

impl FilmMistake {
    /// What the grader decodes from a file holding `linear` written this
    /// way, for the mistakes in the encoding (the file is read as sRGB).
    pub fn decoded(self, linear: f32) -> f32 {
        let c = linear.clamp(0.0, 1.0);
        match self {
            FilmMistake::FlipVertical => linear,
            FilmMistake::NoSrgb => glint_camera::srgb_to_linear(c),
            FilmMistake::Gamma22 => glint_camera::srgb_to_linear(c.powf(1.0 / 2.2)),
        }
    }

    /// [`Self::decoded`] of each channel of `linear`.
    pub fn decoded_rgb(self, linear: glam::Vec3) -> glam::Vec3 {
        linear.to_array().map(|c| self.decoded(c)).into()
    }
}

const fn mistake(id: &'static str, stage: Stage, how: How, description: &'static str) -> Mistake {
    Mistake {
        id,
        description,
        stage,
        how,
    }
}

use How::{Film, Integrator, Lights, NoiseOnly, Scene};
use Stage::{Camera, Environment, Intersection, Lighting, Shading, Texture};

/// Every mistake Glint knows, in the order `glint grade --mistakes` lists
/// them.
#[rustfmt::skip]
pub const CATALOGUE: &[Mistake] = &[
    mistake("fov-horizontal", Camera, Scene(edit::fov_horizontal),
        "fov taken as the horizontal field of view (nothing changes on a square image)"),
    mistake("fov-not-halved", Camera, Scene(edit::fov_not_halved),
        "film half height f·tan(fov) instead of f·tan(fov/2): zoomed out"),
    mistake("pixel-corner", Camera, Integrator(Swap::PixelCorner),
        "rays through the pixels' corners (no +0.5)"),
    mistake("no-shadow-offset", Intersection, Integrator(Swap::NoShadowOffset),
        "shadow rays start exactly at the hit point: shadow acne"),
    mistake("normal-not-normalised", Intersection, Integrator(Swap::NormalNotNormalised),
        "sphere normal p − c not divided by the radius"),
    mistake("sphere-u-sign", Texture, Integrator(Swap::SphereUSign),
        "sphere u angle with the wrong sign (atan2(z, x) for atan2(−z, x))"),
    mistake("checker-double", Texture, Scene(edit::checker_double),
        "checkerboard frequency doubled (2N × 2N checks)"),
    mistake("uv-swapped", Texture, Integrator(Swap::UvSwapped),
        "u and v swapped in the texture lookup"),
    mistake("nearest-texel", Texture, Scene(edit::nearest_texel),
        "the nearest texel instead of a filtered lookup (bilinear, MIP-mapped)"),
    mistake("mip-level-ln", Texture, Integrator(Swap::MipLevelLn),
        "the MIP level from the natural logarithm of the footprint instead of log2"),
    mistake("no-ambient", Lighting, Scene(edit::no_ambient),
        "ambient term left out"),
    mistake("ambient-without-kd", Lighting, Integrator(Swap::AmbientWithoutKd),
        "the ambient colour alone, not ambient·kd"),
    mistake("no-shadows", Lighting, Integrator(Swap::NoShadows),
        "no shadow rays: every light sample counts as visible"),
    mistake("light-blocks-itself", Lighting, Integrator(Swap::LightBlocksItself),
        "shadow rays count the light's own surface as a blocker"),
    mistake("sum-light-samples", Lighting, Lights(edit::sum_light_samples),
        "light samples summed, not averaged"),
    mistake("light-centre", Lighting, Lights(edit::light_centre),
        "every light sample at the light's centre: hard shadows"),
    mistake("light-twice-size", Lighting, Lights(edit::light_twice_size),
        "light samples over centre ± edge instead of centre ± edge/2"),
    mistake("light-colour-ignored", Lighting, Lights(edit::light_colour_ignored),
        "the lights' colour left out of the light term (white lights)"),
    mistake("light-invisible", Lighting, Integrator(Swap::LightInvisible),
        "camera rays do not see area lights"),
    mistake("two-sided-light", Lighting, Scene(edit::two_sided_light),
        "area lights emit from both sides"),
    mistake("fixed-light-samples", Lighting, NoiseOnly,
        "the same light samples for every camera sample"),
    mistake("view-sign", Shading, Integrator(Swap::ViewSign),
        "view vector with its sign flipped in the specular term"),
    mistake("blinn", Shading, Scene(edit::blinn),
        "the half vector (Blinn–Phong n·h) instead of the reflection vector, same exponent"),
    mistake("ks-as-kd", Shading, Scene(edit::ks_as_kd),
        "the diffuse colour kd used as the specular colour ks"),
    mistake("specular-cosine", Shading, Integrator(Swap::SpecularCosine),
        "the specular term multiplied by n·l too"),
    mistake("no-lambert-cosine", Shading, Integrator(Swap::NoLambertCosine),
        "the diffuse term without n·l"),
    mistake("cube-face-swapped", Environment, Integrator(Swap::CubeFaceSwapped),
        "the cube map's +z and −z faces swapped"),
    mistake("cube-face-mirrored", Environment, Integrator(Swap::CubeFaceMirrored),
        "every cube-map face read mirrored left to right"),
    mistake("no-srgb", Stage::Film, Film(FilmMistake::NoSrgb),
        "linear values written to an 8-bit file without the sRGB curve"),
    mistake("gamma-2.2", Stage::Film, Film(FilmMistake::Gamma22),
        "pow(c, 1/2.2) instead of the sRGB curve"),
    mistake("flip-vertical", Stage::Film, Film(FilmMistake::FlipVertical),
        "the image written upside down"),
];

/// The mistake named `id`.
pub fn find(id: &str) -> Option<&'static Mistake> {
    CATALOGUE.iter().find(|m| m.id == id)
}
