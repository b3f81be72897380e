//! The TOML scene file, as read: one struct per table, unknown keys refused.
//! Defaults here are the documented defaults of the format (`docs/scene-format.md`).

use crate::values::*;
use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use toml::Spanned;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `"phong"` (the course's model) or `"physical"` (radiometric units).
    #[serde(default)]
    pub shading: Shading,
    /// Ambient light added as `ambient · kd` at every shaded point.
    #[serde(default = "black")]
    pub ambient: Color,
    pub camera: CameraTable,
    #[serde(default)]
    pub render: RenderTable,
    pub environment: Option<Spanned<EnvironmentTable>>,
    #[serde(default)]
    pub textures: BTreeMap<String, TextureTable>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialTable>>,
    #[serde(default)]
    pub sphere: Vec<SphereTable>,
    #[serde(default)]
    pub parallelogram: Vec<ParallelogramTable>,
    #[serde(default)]
    pub plane: Vec<PlaneTable>,
    #[serde(default, rename = "box")]
    pub boxes: Vec<BoxTable>,
    #[serde(default)]
    pub mesh: Vec<MeshTable>,
    #[serde(default)]
    pub point_light: Vec<Spanned<PointLightTable>>,
    #[serde(default)]
    pub area_light: Vec<Spanned<AreaLightTable>>,
    #[serde(default)]
    pub sphere_light: Vec<Spanned<SphereLightTable>>,
    /// Named rectangles of the image, `[x0, y0, x1, y1]` in pixels of the render
    /// resolution (x1, y1 excluded), for `glint bench --region NAME`.
    #[serde(default)]
    pub regions: BTreeMap<String, Spanned<Exactly<u32, 4>>>,
}

fn black() -> Color {
    Color(glam::Vec3::ZERO)
}
fn white() -> Color {
    Color(glam::Vec3::ONE)
}
fn y_up() -> Spanned<Direction> {
    Spanned::new(0..0, Direction(glam::Vec3::Y))
}
fn unit_focal_length() -> Positive {
    Positive(1.0)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraTable {
    pub position: Point,
    pub look_at: Spanned<Point>,
    #[serde(default = "y_up")]
    pub up: Spanned<Direction>,
    /// Vertical field of view in degrees.
    pub fov: FieldOfView,
    #[serde(default = "unit_focal_length")]
    pub focal_length: Positive,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderTable {
    pub resolution: Resolution,
    pub spp: Spanned<Count>,
    pub pixel_sampler: Spanned<Pattern>,
    pub light_samples: Spanned<Count>,
    pub light_sampler: Spanned<Pattern>,
    pub seed: u64,
    pub max_depth: Spanned<u32>,
    pub environment_samples: Spanned<u32>,
    pub environment_sampler: Spanned<Pattern>,
    /// How the environment's directions are drawn: by luminance or by the cosine.
    pub environment_sampling: EnvironmentSamplingName,
    /// Physical shading: how area lights are sampled.
    pub area_sampling: AreaSamplingName,
    /// Physical shading: multiple importance sampling of glossy lobes.
    pub mis: bool,
}

/// The environment: exactly one of `color`, `cube_map`, `latlong`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentTable {
    pub color: Option<Color>,
    /// Path template of the six faces, `{face}` standing for px nx py ny pz nz.
    pub cube_map: Option<Spanned<String>>,
    /// Path of an equirectangular image.
    pub latlong: Option<Spanned<String>>,
    /// Degrees about +y.
    #[serde(default = "no_rotation")]
    pub rotation: Real,
    #[serde(default = "unit_intensity")]
    pub intensity: NonNegative,
}

fn no_rotation() -> Real {
    Real(0.0)
}
fn unit_intensity() -> NonNegative {
    NonNegative(1.0)
}

impl Default for RenderTable {
    fn default() -> Self {
        let settings = glint_integrator::RenderSettings::default();
        Self {
            resolution: Resolution(glam::UVec2::new(512, 512)),
            spp: Spanned::new(0..0, Count(settings.spp)),
            pixel_sampler: Spanned::new(0..0, Pattern(settings.pixel_pattern)),
            light_samples: Spanned::new(0..0, Count(settings.light_samples)),
            light_sampler: Spanned::new(0..0, Pattern(settings.light_pattern)),
            seed: settings.seed,
            max_depth: Spanned::new(0..0, settings.max_depth),
            environment_samples: Spanned::new(0..0, settings.environment_samples),
            environment_sampler: Spanned::new(0..0, Pattern(settings.environment_pattern)),
            environment_sampling: EnvironmentSamplingName(settings.environment_sampling),
            area_sampling: AreaSamplingName(settings.area_sampling),
            mis: settings.mis,
        }
    }
}

/// A named texture: one key naming its kind, e.g. `checkerboard = { … }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum TextureTable {
    Checkerboard(CheckerboardTable),
    CheckerImage(CheckerImageTable),
    Image(ImageTable),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckerboardTable {
    /// The colors of even and odd checks.
    pub colors: Exactly<Color, 2>,
    /// Checks along each side of the uv square.
    pub checks: Count,
    #[serde(default = "point_filter")]
    pub filter: CheckerFilter,
}

fn point_filter() -> CheckerFilter {
    CheckerFilter(false)
}

/// The course's checkerboard as an image texture (so it is MIP-mapped).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckerImageTable {
    pub colors: Exactly<Color, 2>,
    pub checks: Spanned<Count>,
    #[serde(default = "course_pixels_per_check")]
    pub pixels_per_check: Spanned<Count>,
    #[serde(default = "repeat")]
    pub wrap: Wrap,
    #[serde(default = "trilinear")]
    pub filter: Filter,
}

fn course_pixels_per_check() -> Spanned<Count> {
    Spanned::new(0..0, Count(32))
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageTable {
    /// Path of the image, relative to the scene file.
    pub file: Spanned<String>,
    #[serde(default = "repeat")]
    pub wrap: Wrap,
    #[serde(default = "trilinear")]
    pub filter: Filter,
}

fn repeat() -> Wrap {
    Wrap(glint_texture::WrapMode::Repeat)
}
fn trilinear() -> Filter {
    Filter(glint_texture::TextureFilter::Trilinear)
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialTable {
    /// Required unless the material is a `mirror`.
    pub diffuse: Option<Spanned<ColorOrTexture>>,
    /// A perfect mirror of this tint (no other shading keys allowed).
    pub mirror: Option<Spanned<Color>>,
    /// Fraction of mirror reflection blended into the Phong result.
    #[serde(default = "no_reflection")]
    pub reflectivity: Fraction,
    #[serde(default = "white")]
    pub reflection_tint: Color,
    pub specular: Option<Spanned<ColorOrTexture>>,
    #[serde(default = "unit_shininess")]
    pub shininess: NonNegative,
    pub lobe: Option<Lobe>,
    #[serde(default = "unit_scale")]
    pub uv_scale: UvScale,
    #[serde(default = "zero_offset")]
    pub uv_offset: UvPair,
}

fn unit_scale() -> UvScale {
    UvScale(glam::Vec2::ONE)
}
fn zero_offset() -> UvPair {
    UvPair(glam::Vec2::ZERO)
}

fn no_reflection() -> Fraction {
    Fraction(0.0)
}

fn unit_shininess() -> NonNegative {
    NonNegative(1.0)
}

/// A material input: a constant `[r, g, b]` or the name of a texture.
#[derive(Debug)]
pub enum ColorOrTexture {
    Color(Color),
    Texture(String),
}

impl<'de> serde::Deserialize<'de> for ColorOrTexture {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ColorOrTexture;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a color [r, g, b] or the name of a texture")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
                Ok(ColorOrTexture::Texture(v.to_owned()))
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                Color::deserialize(de::value::SeqAccessDeserializer::new(seq))
                    .map(ColorOrTexture::Color)
            }
        }
        d.deserialize_any(V)
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereTable {
    pub center: Point,
    pub radius: Positive,
    pub material: Spanned<String>,
    /// What reports call the object ("left wall"); by default its table and
    /// index (`sphere[2]`).
    pub name: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParallelogramTable {
    pub origin: Point,
    pub edge1: Spanned<Point>,
    pub edge2: Point,
    /// Which side is the front; must be perpendicular to both edges.
    pub normal: Option<Spanned<Direction>>,
    #[serde(default)]
    pub two_sided: bool,
    pub material: Spanned<String>,
    /// What reports call the object ("left wall"); by default its table and
    /// index (`sphere[2]`).
    pub name: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneTable {
    pub point: Point,
    pub normal: Direction,
    /// World units spanned by one unit of uv.
    #[serde(default = "unit_focal_length")]
    pub tile_size: Positive,
    #[serde(default)]
    pub two_sided: bool,
    pub material: Spanned<String>,
    /// What reports call the object ("left wall"); by default its table and
    /// index (`sphere[2]`).
    pub name: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxTable {
    pub min: Point,
    pub max: Spanned<Point>,
    /// One material for the whole box…
    pub material: Option<Spanned<String>>,
    /// …or one per face, in `px nx py ny pz nz` order (the report's textured box).
    pub face_materials: Option<Spanned<Vec<Spanned<String>>>>,
    /// What reports call the object ("left wall"); by default its table and
    /// index (`sphere[2]`).
    pub name: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightTable {
    pub position: Point,
    /// The course's light colour (`shading = "phong"` only; default white).
    pub color: Option<Spanned<Color>>,
    /// Radiant intensity in W/sr per channel (`shading = "physical"` only).
    pub intensity: Option<Spanned<Color>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaLightTable {
    pub center: Point,
    pub edge1: Spanned<Point>,
    pub edge2: Point,
    /// Which side emits; must be perpendicular to both edges.
    pub normal: Option<Spanned<Direction>>,
    /// The course's light colour (`shading = "phong"` only; default white).
    pub color: Option<Spanned<Color>>,
    /// Emitted radiance of the front face, W/(sr·m²) per channel
    /// (`shading = "physical"` only).
    pub radiance: Option<Spanned<Color>>,
    /// What reports call the object ("left wall"); by default its table and
    /// index (`sphere[2]`).
    pub name: Option<Spanned<String>>,
}

/// A sphere emitting `radiance` from its surface (`shading = "physical"` only).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereLightTable {
    pub center: Point,
    pub radius: Positive,
    /// Emitted radiance, W/(sr·m²) per channel.
    pub radiance: Color,
    /// What reports call the object ("left wall"); by default its table and
    /// index (`sphere[2]`).
    pub name: Option<Spanned<String>>,
}

/// A triangle mesh read from an OBJ file, placed by a transform.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshTable {
    /// Path of the OBJ file, relative to the scene file.
    pub file: Spanned<String>,
    /// A material for every triangle (instead of the OBJ's MTL materials).
    pub material: Option<Spanned<String>>,
    #[serde(default = "origin")]
    pub translate: Point,
    /// Degrees about x, then y, then z.
    #[serde(default = "origin")]
    pub rotate: Point,
    #[serde(default = "unit_scale3")]
    pub scale: Scale3,
    /// What reports call the object ("left wall"); by default its table and
    /// index (`sphere[2]`).
    pub name: Option<Spanned<String>>,
}

fn origin() -> Point {
    Point(glam::Vec3::ZERO)
}
fn unit_scale3() -> Scale3 {
    Scale3(glam::Vec3::ONE)
}
